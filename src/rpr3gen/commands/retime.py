"""``rpr3gen retime``: the time-optimal motion along a path of platform poses within the
actuators' effort (and rate) limits, TOPP-RA (:func:`rpr3gen.retime`); writes a trajectory CSV
that ``rpr3gen simulate --trajectory`` reads."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rpr3gen.commands import options
from rpr3gen.commands.args import integer, number
from rpr3gen.control import actuator_efforts, actuator_jacobian
from rpr3gen.model import Model, load_model
from rpr3gen.paths import check_output
from rpr3gen.retiming import DEFAULT_GRID_POINTS, DEFAULT_SAMPLES, retime
from rpr3gen.trajectory import Trajectory, write_trajectory_csv

NAME = "retime"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``retime`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="time-optimal motion along a path within the actuators' limits (TOPP-RA)",
        description="Write the fastest motion along a path of platform poses, rest to rest, "
        "that keeps every actuator effort (and, if given, every actuator rate) within its limit: "
        "TOPP-RA on the cubic spline through the waypoints, the efforts from the generated "
        "inverse dynamics (friction not modelled). The output is a trajectory CSV file "
        "(t, the pose, its rates and accelerations) for `rpr3gen simulate --trajectory`. Needs "
        "the extra 'toppra': pip install 'rpr3gen[toppra]'.",
    )
    options.add_model(parser)
    parser.add_argument(
        "--path",
        required=True,
        metavar="FILE.csv",
        help="the waypoints: a CSV file with the pose's columns (x,y,phi; spatial robots: "
        "x,y,z[,a,b,c]), one waypoint a row, at least 2; other columns (a trajectory file's t "
        "and derivatives) are ignored",
    )
    parser.add_argument(
        "--effort-limit",
        required=True,
        nargs="+",
        type=number(greater=0.0),
        metavar="L",
        help="the largest |effort| of the actuators, N m (motors that turn) or N (that push): "
        "one value for all, or one per actuator (legs A, B, C...)",
    )
    parser.add_argument(
        "--velocity-limit",
        nargs="+",
        type=number(greater=0.0),
        metavar="V",
        help="the largest |rate| of the actuators, rad/s or m/s: one value for all, or one per "
        "actuator (default: no rate limit)",
    )
    parser.add_argument(
        "--out", required=True, metavar="FILE.csv", help="the trajectory CSV file to write"
    )
    parser.add_argument(
        "--samples",
        type=integer(2),
        default=DEFAULT_SAMPLES,
        metavar="N",
        help="samples of the trajectory, equally spaced in time, both ends included (default: "
        f"{DEFAULT_SAMPLES})",
    )
    parser.add_argument(
        "--grid-points",
        type=integer(3),
        default=DEFAULT_GRID_POINTS,
        metavar="N",
        help="the least number of TOPP-RA's grid points along the path, every waypoint one; "
        "more holds the limits more closely between them (default: "
        f"{DEFAULT_GRID_POINTS})",
    )
    options.add_min_conditioning(
        parser,
        "refuse a path through poses whose output 'conditioning' (0 = singular, 1 = best) is "
        "below C, 0 <= C < 1",
    )
    options.add_backend(parser)
    options.add_generated(parser)


def _peaks(label: str, values: np.ndarray, limit: np.ndarray, model: Model) -> str:
    ratios = np.abs(values).max(axis=0) / np.broadcast_to(limit, values.shape[1:])
    legs = model.structure.legs
    return f"  peak |{label}| / limit: " + ", ".join(
        f"leg {leg} {r:.4f}" for leg, r in zip(legs, ratios, strict=True)
    )


def summary(args: argparse.Namespace, model: Model, traj: Trajectory, effort: np.ndarray) -> str:
    """What was written: the motion's duration and each actuator's peak against its limit."""
    lines = [
        f"wrote {args.out}: {args.path} retimed for {model.name} ({model.structure.title}): "
        f"{traj.t[-1]:.6g} s, {len(traj.t)} samples, at rest at both ends",
        _peaks("effort", actuator_efforts(model, traj.q, traj.qd, traj.qdd, args.backend),
               effort, model),
    ]  # fmt: skip
    if args.velocity_limit:
        J = actuator_jacobian(model, traj.q, args.backend)
        rate = np.einsum("nij,nj->ni", J, traj.qd)
        lines.append(_peaks("rate", rate, np.array(args.velocity_limit), model))
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Retime the path, write the trajectory, print the summary."""
    check_output(args.out, "the trajectory CSV", argument="out")
    model = load_model(args.model, generated=args.generated)
    effort = np.array(args.effort_limit)
    traj = retime(
        model,
        args.path,
        effort,
        None if args.velocity_limit is None else np.array(args.velocity_limit),
        samples=args.samples,
        grid_points=args.grid_points,
        min_conditioning=args.min_conditioning,
        backend=args.backend,
    )
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_trajectory_csv(args.out, traj, pose=model.structure.pose)
    print(summary(args, model, traj, effort))
    return 0
