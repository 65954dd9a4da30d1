"""``rpr3gen identify`` and ``rpr3gen excite``: dynamic identification from the command line.

``identify`` reads a data CSV (a trajectory file plus the measured efforts ``m10_A..C`` or
``f21z_A..C``, by the model's actuation), fits the base parameters (docs/identification.md) and
prints them with their standard deviations, the fit's residual and the excitation's condition
number; ``--out`` writes them as TOML. ``excite`` writes an optimised exciting trajectory.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from rpr3gen.atomic import atomic_write
from rpr3gen.cli_args import integer, number
from rpr3gen.derivatives import MAX_SMOOTHING
from rpr3gen.model import LEGS, Model, load_model
from rpr3gen.paths import check_output

EFFORT = {"revolute": "m10", "prismatic": "f21z"}
UNIT = {"revolute": "N m", "prismatic": "N"}


def add_parsers(sub: argparse._SubParsersAction, paper_model: str) -> None:
    """The ``identify`` and ``excite`` subcommands."""
    from rpr3gen.identification import MAX_CONDITION, WARN_CONDITION

    ide = sub.add_parser(
        "identify",
        help="estimate the base inertial parameters (and friction) from measured data",
        description="Weighted least squares of the base parameters (docs/identification.md) on "
        "a data CSV: a trajectory file (t,x,y,phi and optionally the derivatives, which a "
        "smoothing spline estimates otherwise) plus the measured efforts m10_A,m10_B,m10_C "
        "(revolute actuation) or f21z_A,f21z_B,f21z_C (prismatic). Prints each estimate, its "
        "standard deviation, the model's value and the combination it stands for.",
    )
    ide.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")
    ide.add_argument("--data", metavar="FILE.csv", required=True, help="the measurements")
    ide.add_argument(
        "--friction", action="store_true", help="also estimate viscous and Coulomb friction"
    )
    ide.add_argument(
        "--identical-legs",
        action="store_true",
        help="the three legs share one set of parameters (9 base parameters instead of 19)",
    )
    ide.add_argument(
        "--smoothing",
        type=number(least=0.0, most=MAX_SMOOTHING),
        metavar="S",
        help="for a file of positions only: RMS deviation allowed to the smoothing spline "
        "(m, rad; default 0: through every sample; give the measurement noise)",
    )
    ide.add_argument(
        "--warn-condition",
        type=number(finite=False, greater=1.0),
        default=WARN_CONDITION,
        metavar="K",
        help="fit, with a warning naming the most inflated standard deviations, data whose "
        f"condition number exceeds K (default {WARN_CONDITION:g})",
    )
    ide.add_argument(
        "--max-condition",
        type=number(finite=False, greater=1.0),
        default=MAX_CONDITION,
        metavar="K",
        help=f"refuse data whose condition number exceeds K (default {MAX_CONDITION:g}: beyond "
        "it measured data cannot be told from data that leave a parameter undetermined)",
    )
    ide.add_argument("--out", metavar="FILE.toml", help="write the estimates as TOML")
    ide.add_argument(
        "--backend", choices=("numpy", "c"), default="numpy", help="generated code to evaluate"
    )

    exc = sub.add_parser(
        "excite",
        help="write an exciting trajectory for identification (optimised Fourier series)",
        description="Optimise a periodic Fourier-series platform motion that minimises the "
        "condition number of the base regressor, inside the workspace (stroke limits of the "
        "model, or |lambda21| <= l0/2; conditioning floor; acceleration bounds), and write one "
        "period as a trajectory CSV.",
    )
    exc.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")
    exc.add_argument("--out", metavar="FILE.csv", required=True, help="the trajectory CSV")
    exc.add_argument(
        "--harmonics",
        type=integer(1),
        default=5,
        help="per coordinate, at most (samples - 1) / 2 (5)",
    )
    exc.add_argument("--period", type=number(greater=0.0), default=10.0, help="s (default 10)")
    exc.add_argument("--samples", type=integer(10), default=201, help="per period (201)")
    exc.add_argument(
        "--min-conditioning",
        type=number(least=0.0, below=1.0),
        default=0.1,
        metavar="C",
        help="floor on the pose's conditioning along the motion (default 0.1)",
    )
    exc.add_argument("--identical-legs", action="store_true", help="optimise for 9 parameters")
    exc.add_argument("--friction", action="store_true", help="include the friction columns")
    exc.add_argument("--seed", type=integer(0), default=0, help="of the starting motion (0)")
    exc.add_argument(
        "--max-iterations", type=integer(1, 2**31 - 1), default=100, help="SLSQP (100)"
    )


def _toml_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(float(value)) if isinstance(value, float) else str(value)
    return json.dumps(str(value))


def fit_toml(fit, model: Model, data: str) -> str:
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


def _model_base(fit) -> np.ndarray:
    """The model file's base parameters, round-off (e.g. J1 + J2 - l2^2 m2 of the paper's
    robot, exactly 0) shown as 0."""
    from rpr3gen.identification import inertial_parameters

    values = fit.base.matrix @ inertial_parameters(fit.model, fit.identical_legs)
    values[np.abs(values) < 1e-12 * np.abs(values).max()] = 0.0
    return values


def cmd_identify(args: argparse.Namespace) -> int:
    from rpr3gen.identification import identify
    from rpr3gen.trajectory import read_trajectory_columns

    model = load_model(args.model)
    if args.out:
        check_output(args.out, "the estimates", argument="out")
    family = model.structure.effort
    columns = tuple(f"{family}_{leg}" for leg in LEGS)
    traj, tau = read_trajectory_columns(args.data, columns, smoothing=args.smoothing)
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
        f"{leg} {r:.4g}" for leg, r in zip(LEGS, fit.residual_rms_per_actuator, strict=True)
    )
    print(
        f"identify: {fit.samples} samples of {args.data}, model {model.name} "
        f"({what}), {len(fit.base.names)} base parameters ({legs})"
        + (" + 6 friction" if args.friction else "")
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


def cmd_excite(args: argparse.Namespace) -> int:
    from rpr3gen.excitation import excite
    from rpr3gen.trajectory import write_trajectory_csv

    model = load_model(args.model)
    out = check_output(args.out, "the trajectory", argument="out")
    found = excite(
        model,
        harmonics=args.harmonics,
        period=args.period,
        samples=args.samples,
        min_conditioning=args.min_conditioning,
        identical_legs=args.identical_legs,
        friction=args.friction,
        seed=args.seed,
        max_iterations=args.max_iterations,
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    write_trajectory_csv(out, found.trajectory)
    if model.structure.paper:
        lo, hi = found.stroke.min(), found.stroke.max()
        bounds = f"piston strokes within [{lo:.4g}, {hi:.4g}] m"
    else:
        bounds = f"min reach {found.min_reach:.3g}" + "".join(
            f", {name} in [{lo:.4g}, {hi:.4g}]" for name, (lo, hi) in found.ranges.items()
        )
    print(
        f"excite: {model.name}, {args.harmonics} harmonics, period {args.period:g} s: condition "
        f"number {found.initial_condition_number:.4g} -> {found.condition_number:.4g} "
        f"({found.iterations} iterations); min conditioning {found.min_conditioning:.3g}, "
        f"{bounds}"
    )
    print(f"wrote {args.out}")
    return 0
