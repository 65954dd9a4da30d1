"""``rpr3gen paper``: the paper's two examples (rotation and rectilinear motion of the paper's
robot), their CSV files and figures."""

from __future__ import annotations

import argparse
from pathlib import Path

from rpr3gen.commands import options
from rpr3gen.commands.reports import summary
from rpr3gen.model import load_model
from rpr3gen.simulation import simulate
from rpr3gen.trajectory import PAPER_TRAJECTORIES, paper_trajectory

NAME = "paper"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``paper`` subcommand's parser."""
    parser = sub.add_parser(NAME, help="run the paper's two examples: CSV and figures")
    options.add_out_folder(parser, "results")
    options.add_backend(parser)
    options.add_threads(parser)


def run(args: argparse.Namespace) -> int:
    """Simulate both paper trajectories into ``--out``; print their summaries."""
    model = load_model()
    root = Path(args.out)
    summaries = []  # printed once every file is written, so a closed stdout stops nothing
    for name in PAPER_TRAJECTORIES:
        traj = paper_trajectory(name)
        out, _ = simulate(
            model,
            name,
            traj,
            args.backend,
            str(root / f"{name}.csv"),
            str(root / "figures"),
            threads=args.threads,
        )
        summaries.append(summary(name, model, traj, out))
    print("\n".join(summaries))
    print(f"wrote {root / '*.csv'} and {root / 'figures'}/*.png")
    return 0
