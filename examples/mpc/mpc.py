"""Nonlinear MPC of a 3-RRR tracking a path within effort limits, on rpr3gen's CasADi bridge.

The controller's model is ``rpr3gen.casadi.function(model, "forward_dynamics")``; the plant is
rpr3gen's generated forward dynamics of the same robot with a payload and motor friction the
controller does not know (examples/mpc/README.md). Prints the solve time per step, the solver's
status, the tracking error and the efforts against their limits; writes ``mpc.csv`` and
``mpc.png`` into ``--out``. Exit status 1 if a solve failed or an effort exceeded its limit.

    python examples/mpc/mpc.py [--horizon N] [--steps K] [--effort-limit L] [--model FILE]
                               [--out DIR] [--dt S] [--payload KG] [--friction B]
                               [--laps N] [--reference-fraction F] [--solver rti|ipopt]
                               [--no-estimate]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from mpc_example import report
from mpc_example.controller import Mpc, Settings
from mpc_example.loop import MpcPolicy, closed_loop
from mpc_example.plant import Plant, with_payload
from mpc_example.reference import loop_reference

import rpr3gen

REPO = Path(__file__).resolve().parents[2]
HOLD = 0.2  # s of rest at the reference's end in the default run
SOLVERS = {
    "ipopt": "IPOPT to convergence",
    "rti": "real-time iteration (one SQP step, qrqp)",
}


def parse(argv: list[str] | None) -> argparse.Namespace:
    """The command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--horizon", type=int, default=20, metavar="N", help="periods predicted (default 20)"
    )
    parser.add_argument(
        "--steps",
        type=int,
        metavar="K",
        help="control periods to run (default: the reference and 0.2 s of rest)",
    )
    parser.add_argument(
        "--effort-limit",
        type=float,
        default=12.0,
        metavar="L",
        help="|tau_i| <= L for every motor, N m (default 12)",
    )
    parser.add_argument(
        "--model",
        type=Path,
        default=REPO / "models" / "rrr.toml",
        help="model file (default models/rrr.toml)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("mpc-out"),
        metavar="DIR",
        help="folder for mpc.csv and mpc.png (default mpc-out)",
    )
    parser.add_argument(
        "--dt", type=float, default=0.01, metavar="S", help="control period, s (default 0.01)"
    )
    parser.add_argument(
        "--payload",
        type=float,
        default=0.5,
        metavar="KG",
        help="unknown payload on the platform, kg (default 0.5)",
    )
    parser.add_argument(
        "--friction",
        type=float,
        default=0.05,
        metavar="B",
        help="unknown viscous friction at each motor, N m s/rad (default 0.05)",
    )
    parser.add_argument(
        "--path",
        type=Path,
        default=REPO / "models" / "loop-path.csv",
        help="path CSV to track (default models/loop-path.csv)",
    )
    parser.add_argument("--laps", type=int, default=2, help="times round the path (default 2)")
    parser.add_argument(
        "--reference-fraction",
        type=float,
        default=0.8,
        metavar="F",
        help="time the reference within F x L on the nominal model (default 0.8)",
    )
    parser.add_argument(
        "--solver",
        choices=["rti", "ipopt"],
        default="rti",
        help="rti: one Gauss-Newton SQP step a period, qrqp (default); "
        "ipopt: solved to convergence each period",
    )
    parser.add_argument(
        "--no-estimate",
        action="store_true",
        help="no estimate of the unmodelled effort (no offset correction)",
    )
    args = parser.parse_args(argv)  # fmt: skip
    if args.horizon < 1 or (args.steps is not None and args.steps < 1) or args.laps < 1:
        parser.error("--horizon, --steps and --laps must be positive")
    if not (args.effort_limit > 0 and args.dt > 0 and 0 < args.reference_fraction <= 1):
        parser.error("--effort-limit and --dt must be positive, --reference-fraction in (0, 1]")
    return args


def main(argv: list[str] | None = None) -> int:
    """Run the closed loop and report; 0 if every solve converged within the limits."""
    args = parse(argv)
    model = rpr3gen.load_model(args.model)
    reference = loop_reference(
        model, args.path, args.reference_fraction * args.effort_limit, laps=args.laps
    )
    k = reference.q.shape[1]
    limit = np.full(k, args.effort_limit)
    settings = Settings(
        horizon=args.horizon,
        dt=args.dt,
        effort_limit=limit,
        disturbance_gain=0.0 if args.no_estimate else Settings.disturbance_gain,
        solver=args.solver,
    )
    steps = args.steps or math.ceil((reference.duration + HOLD) / args.dt)
    mpc = Mpc(model, settings)
    plant = Plant(with_payload(model, args.payload), reference.q[0], friction=args.friction)
    run = closed_loop(MpcPolicy(mpc, reference), plant, reference, args.dt, steps, mpc=mpc)

    summary = report.summarise(run, limit)
    variant = model.structure.variant if hasattr(model.structure, "variant") else ""
    print(
        f"{model.name} ({args.model.name}{', ' + variant if variant else ''}): {steps} steps "
        f"of {args.dt * 1e3:g} ms, horizon {args.horizon} ({args.horizon * args.dt:g} s), "
        f"multiple shooting (RK4 of the CasADi bridge's forward_dynamics), "
        f"{SOLVERS[args.solver]}"
    )
    print(
        f"reference: {args.path.name} {args.laps} times round, {reference.duration:.3f} s, "
        f"timed within {args.reference_fraction * args.effort_limit:g} N m on the nominal model"
    )
    estimate = "off" if args.no_estimate else "on"
    print(
        f"plant: payload {args.payload:g} kg and motor friction {args.friction:g} N m s/rad "
        f"unknown to the controller (disturbance estimate {estimate}), RK4 at "
        f"{plant.substeps / args.dt:g} Hz"
    )
    success = "converged" if args.solver == "ipopt" else "SQP step taken, QP solved"
    for line in report.lines(summary, limit, steps, success):
        print(line)
    args.out.mkdir(parents=True, exist_ok=True)
    report.write_csv(run, args.out / "mpc.csv")
    report.plot(run, limit, args.out / "mpc.png",
                f"{model.name}: MPC within |tau| <= {args.effort_limit:g} N m, "
                f"horizon {args.horizon} x {args.dt * 1e3:g} ms")  # fmt: skip
    print(f"wrote {args.out / 'mpc.csv'} and {args.out / 'mpc.png'}")
    return 0 if summary.failed == 0 and summary.over_limit == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
