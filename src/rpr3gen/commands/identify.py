"""``rpr3gen identify``: dynamic identification from the command line.

Reads a data CSV (a trajectory file plus the measured efforts ``m10_A..C`` or ``f21z_A..C``, by
the model's actuation), fits the base parameters (docs/identification.md) and prints them with
their standard deviations, the fit's residual and the excitation's condition number; ``--out``
writes them as TOML.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rpr3gen.atomic import atomic_write
from rpr3gen.commands import options
from rpr3gen.commands.args import number
from rpr3gen.model import Model, load_model
from rpr3gen.paths import check_output

if TYPE_CHECKING:  # imported when needed, as below: `import rpr3gen.cli` stays light
    from rpr3gen.identification import Fit

NAME = "identify"
UNIT = {"revolute": "N m", "prismatic": "N"}


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``identify`` subcommand's parser."""
    from rpr3gen.identification import MAX_CONDITION, WARN_CONDITION

    parser = sub.add_parser(
        NAME,
        help="estimate the base inertial parameters (and friction) from measured data",
        description="Weighted least squares of the base parameters (docs/identification.md) on "
        "a data CSV: a trajectory file (t,x,y,phi and optionally the derivatives, which a "
        "smoothing spline estimates otherwise) plus the measured efforts m10_A,m10_B,m10_C "
        "(revolute actuation) or f21z_A,f21z_B,f21z_C (prismatic); a general or spatial "
        "model's tau_A,tau_B,... (a spatial model's file has its pose's columns, e.g. "
        "t,x,y,z,a,b,c for a hexapod). Prints each estimate, its "
        "standard deviation, the model's value and the combination it stands for.",
    )
    options.add_model(parser)
    parser.add_argument("--data", metavar="FILE.csv", required=True, help="the measurements")
    parser.add_argument(
        "--friction", action="store_true", help="also estimate viscous and Coulomb friction"
    )
    parser.add_argument(
        "--identical-legs",
        action="store_true",
        help="the legs share one set of parameters (the paper's robot: 9 base parameters "
        "instead of 19)",
    )
    options.add_smoothing(parser)
    parser.add_argument(
        "--warn-condition",
        type=number(finite=False, greater=1.0),
        default=WARN_CONDITION,
        metavar="K",
        help="fit, with a warning naming the most inflated standard deviations, data whose "
        f"condition number exceeds K (default {WARN_CONDITION:g})",
    )
    parser.add_argument(
        "--max-condition",
        type=number(finite=False, greater=1.0),
        default=MAX_CONDITION,
        metavar="K",
        help=f"refuse data whose condition number exceeds K (default {MAX_CONDITION:g}: beyond "
        "it measured data cannot be told from data that leave a parameter undetermined)",
    )
    parser.add_argument("--out", metavar="FILE.toml", help="write the estimates as TOML")
    options.add_backend(parser)


def _toml_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(float(value)) if isinstance(value, float) else str(value)
    return json.dumps(str(value))


def fit_toml(fit: Fit, model: Model, data: str) -> str:
    """The estimates of ``fit`` as a TOML document."""
    base_values = _model_base(fit)
    lines = [
        f"# rpr3gen identify: base parameters of {json.dumps(model.name)} from {data}",
        "",
        "[fit]",
        f"model = {_toml_value(model.source)}",
        f"data = {_toml_value(data)}",
        f"actuation = {_toml_value(model.actuation)}",
        f"samples = {fit.samples}",
        f"friction = {_toml_value(fit.friction)}",
        f"identical_legs = {_toml_value(fit.identical_legs)}",
        f"condition_number = {_toml_value(float(fit.condition_number))}",
        f"residual_rms = {_toml_value(float(fit.residual_rms))}",
        "",
        "[estimates]",
        *(f"{n} = {float(v)!r}" for n, v in zip(fit.names, fit.values, strict=True)),
        "",
        "[std]",
        *(f"{n} = {float(s)!r}" for n, s in zip(fit.names, fit.std, strict=True)),
        "",
        "[model_values]  # the model file's base parameters, for comparison",
        *(f"{n} = {float(v)!r}" for n, v in zip(fit.base.names, base_values, strict=True)),
        "",
        "[definitions]  # what each base parameter stands for",
        *(
            f"{n} = {json.dumps(e)}"
            for n, e in zip(fit.base.names, fit.base.expressions(), strict=True)
        ),
    ]
    return "\n".join(lines) + "\n"


def _model_base(fit: Fit) -> np.ndarray:
    """The model file's base parameters, round-off (e.g. J1 + J2 - l2^2 m2 of the paper's
    robot, exactly 0) shown as 0."""
    from rpr3gen.parameters import inertial_parameters

    values = fit.base.matrix @ inertial_parameters(fit.model, fit.identical_legs)
    values[np.abs(values) < 1e-12 * np.abs(values).max()] = 0.0
    return values


def run(args: argparse.Namespace) -> int:
    """Fit the base parameters, print them (and write the TOML)."""
    from rpr3gen.identification import identify
    from rpr3gen.trajectory import read_trajectory_columns

    model = load_model(args.model)

    if args.out:
        check_output(args.out, "the estimates", argument="out")
    s = model.structure
    columns = tuple(f"{s.effort}_{leg}" for leg in s.legs)
    traj, tau = read_trajectory_columns(args.data, columns, smoothing=args.smoothing, pose=s.pose)
    fit = identify(
        model,
        traj.q,
        traj.qd,
        traj.qdd,
        tau,
        friction=args.friction,
        identical_legs=args.identical_legs,
        warn_condition=args.warn_condition,
        max_condition=args.max_condition,
        t=traj.t,
        backend=args.backend,
    )
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(args.out) as f:
            f.write(fit_toml(fit, model, args.data))
    unit = UNIT[model.actuation]
    what = f"{model.actuation} actuation" if model.structure.paper else model.structure.title
    legs = "identical legs" if args.identical_legs else "per leg"
    base_values = _model_base(fit)
    expressions = fit.base.expressions(4)
    per = ", ".join(
        f"{leg} {r:.4g}" for leg, r in zip(s.legs, fit.residual_rms_per_actuator, strict=True)
    )
    print(
        f"identify: {fit.samples} samples of {args.data}, model {model.name} "
        f"({what}), {len(fit.base.names)} base parameters ({legs})"
        + (f" + {2 * len(s.legs)} friction" if args.friction else "")
    )
    print(
        f"  condition number {fit.condition_number:.4g} (warns above {args.warn_condition:g}, "
        f"refuses above {args.max_condition:g}); "
        f"residual RMS {fit.residual_rms:.4g} {unit} ({per})"
    )
    print(f"  {'parameter':<10} {'estimate':>13} {'std':>11} {'model':>13}  stands for")
    for k, (name, value, std) in enumerate(zip(fit.names, fit.values, fit.std, strict=True)):
        model_value = f"{base_values[k]:13.6g}" if k < len(base_values) else f"{'':13}"
        meaning = expressions[k] if k < len(expressions) else "friction"
        print(f"  {name:<10} {value:13.6g} {std:11.3g} {model_value}  {meaning}")
    if args.out:
        print(f"wrote {args.out}")
    return 0
