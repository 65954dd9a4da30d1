"""``rpr3gen simulate``: the inverse dynamics over a trajectory (a paper motion or a CSV file),
screened for singular poses and stroke limits; prints the peaks, writes the CSV and figures."""

from __future__ import annotations

import argparse

from rpr3gen.commands import options
from rpr3gen.commands.reports import refused, summary, warn
from rpr3gen.model import load_model
from rpr3gen.simulation import simulate

NAME = "simulate"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``simulate`` subcommand's parser."""
    parser = sub.add_parser(NAME, help="evaluate the inverse dynamics over a trajectory")
    options.add_model(parser)
    options.add_trajectory(parser)
    options.add_backend(parser)
    options.add_threads(parser)
    parser.add_argument(
        "--out",
        metavar="FILE.csv",
        help="write t, the pose (x,y,phi; spatial robots: x,y,z[,a,b,c]) and every output as "
        "CSV, SI units (default: no file)",
    )
    parser.add_argument(
        "--plots",
        metavar="DIR",
        help="write the paper's figures into DIR as PNG (default: no figures)",
    )
    options.add_min_conditioning(
        parser,
        "refuse poses whose output 'conditioning' (dimensionless, 0 = singular, 1 = best) "
        "is below C, 0 <= C < 1",
    )
    parser.add_argument(
        "--allow-invalid",
        action="store_true",
        help="write rows at poses too close to a singularity or outside a stroke limit as NaN "
        "instead of refusing the trajectory (default: refuse)",
    )
    options.add_generated(parser)


def run(args: argparse.Namespace) -> int:
    """Simulate the trajectory, warn of the samples refused, print the summary."""
    model = load_model(args.model, generated=args.generated)
    name, traj = options.trajectory(args, model.structure.pose)
    out, invalid = simulate(
        model,
        name,
        traj,
        args.backend,
        args.out,
        args.plots,
        min_conditioning=args.min_conditioning,
        allow_invalid=args.allow_invalid,
        threads=args.threads,
    )
    if invalid is not None:
        warn(f"{name}: {refused(traj, invalid)}")
    print(summary(name, model, traj, out, invalid))
    return 0
