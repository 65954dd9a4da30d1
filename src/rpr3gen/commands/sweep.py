"""``rpr3gen sweep``: every design of a grid of model keys evaluated over trajectories (on Dask),
one Parquet row per design: feasibility, peak and RMS efforts, joint loads, conditioning, and
the workspace area (planar robots) or volume (spatial robots)."""

from __future__ import annotations

import argparse

from rpr3gen.commands import options
from rpr3gen.commands.args import integer
from rpr3gen.design.sweeps import (
    DEFAULT_AREA_RESOLUTION,
    DEFAULT_CHUNK_SIZE,
    DEFAULT_TRAJECTORIES,
    DEFAULT_VOLUME_RESOLUTION,
)
from rpr3gen.trajectory import DEFAULT_DURATION, DEFAULT_SAMPLES

NAME = "sweep"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``sweep`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="evaluate every design of a grid of model keys over trajectories (Dask), as Parquet",
        description="For every design of GRID.toml (dotted model keys set to lists or "
        "{start, stop, num} ranges, applied to BASE.toml): feasible or not and why, peak and "
        "RMS actuator efforts, peak joint loads, least conditioning and the workspace area at "
        "phi = 0 (a spatial robot, hexapod or Delta: its workspace volume at the home "
        "orientation); one row per design, in the grid's order. A spatial robot needs its own "
        "trajectory: --trajectory FILE.csv.",
    )
    options.add_model(parser, metavar="BASE.toml", what="base model")
    parser.add_argument("--grid", required=True, metavar="GRID.toml", help="the designs (required)")
    parser.add_argument(
        "--trajectory",
        action="append",
        dest="trajectories",
        metavar=options.TRAJECTORY,
        help="'rotation', 'rectilinear' or a trajectory CSV file; repeat for several "
        "(default: rotation and rectilinear, the paper's planar motions; a spatial robot "
        "needs a CSV file of its pose)",
    )
    options.add_samples(parser, "each paper trajectory", default=DEFAULT_SAMPLES)
    options.add_duration(parser, "each paper trajectory", default=DEFAULT_DURATION)
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on the Dask scheduler at ADDRESS, e.g. tcp://host:8786 (default: a local "
        "cluster on this machine's cores)",
    )
    parser.add_argument(
        "--workers",
        type=integer(0),
        metavar="N",
        help="processes of the local cluster (default: one per core); 0 runs in this process "
        "without Dask",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="continue an interrupted sweep from the chunks in FILE.parquet.parts",
    )
    parser.add_argument(
        "--out",
        default="sweep.parquet",
        metavar="FILE.parquet",
        help="output file (default: ./sweep.parquet)",
    )
    parser.add_argument(
        "--chunk-size",
        type=integer(1),
        default=DEFAULT_CHUNK_SIZE,
        metavar="N",
        help=f"designs per task and per part file (default: {DEFAULT_CHUNK_SIZE})",
    )
    parser.add_argument(
        "--area-resolution",
        type=integer(0),
        default=DEFAULT_AREA_RESOLUTION,
        metavar="N",
        help="planar robots: grid points per axis of each design's workspace area; 0: no area "
        f"(default: {DEFAULT_AREA_RESOLUTION})",
    )
    parser.add_argument(
        "--volume-resolution",
        type=integer(0),
        default=DEFAULT_VOLUME_RESOLUTION,
        metavar="N",
        help="spatial robots: grid points per axis (x, y and z) of each design's workspace "
        "volume at the home orientation, over the box of 'rpr3gen workspace'; 0: no volume "
        f"(default: {DEFAULT_VOLUME_RESOLUTION})",
    )
    parser.add_argument(
        "--backend",
        choices=("numpy", "c"),
        default="numpy",
        help="spatial robots: evaluate the generated NumPy code (designs x samples in each "
        "call) or the C code (one batch call per design, compiled on first use in each "
        "worker); a planar robot's sweep is NumPy's (default: numpy)",
    )
    options.add_min_conditioning(parser, "a pose below this conditioning makes a design infeasible")


def run(args: argparse.Namespace) -> int:
    """Run the sweep with a progress bar; print how many designs are feasible."""
    from rpr3gen.design import sweep
    from rpr3gen.design.sweeps import SweepInterrupted

    try:
        table = sweep(
            args.model,
            args.grid,
            args.trajectories or DEFAULT_TRAJECTORIES,
            out=args.out,
            scheduler=args.scheduler,
            workers=args.workers,
            resume=args.resume,
            chunk_size=args.chunk_size,
            min_conditioning=args.min_conditioning,
            area_resolution=args.area_resolution,
            samples=args.samples,
            duration=args.duration,
            progress=True,
            volume_resolution=args.volume_resolution,
            backend=args.backend,
        )
    except SweepInterrupted as exc:  # main prints it as one line: what is kept, how to go on
        raise KeyboardInterrupt(
            f"{exc.kept} of {exc.chunks} chunks done, kept in {exc.folder}: rerun with --resume "
            "to compute only the others"
        ) from None
    feasible = table.column("feasible").to_numpy(zero_copy_only=False)
    print(f"{table.num_rows} designs, {int(feasible.sum())} feasible; wrote {args.out}")
    return 0
