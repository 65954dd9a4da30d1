"""The options that several commands share, defined once: each ``add_*`` adds one option (or
one group) to a command's parser, with its type, default and help; :func:`trajectory` reads the
trajectory options back.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from rpr3gen import sizes
from rpr3gen.backends import BACKENDS
from rpr3gen.commands.args import integer, number
from rpr3gen.derivatives import MAX_SMOOTHING
from rpr3gen.errors import TrajectoryError, did_you_mean
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.trajectory import (
    DEFAULT_DURATION,
    DEFAULT_SAMPLES,
    DURATIONS,
    PAPER_TRAJECTORIES,
    PLANAR_POSE,
    Trajectory,
    paper_trajectory,
    read_trajectory_csv,
)

PAPER_MODEL = "default: the paper's robot, models/paper.toml"
"""What ``--model`` is when not given."""

TRAJECTORY = "NAME|FILE.csv"
"""Metavar of ``--trajectory``: a paper trajectory's name or a trajectory CSV file."""


def add_model(
    parser: argparse.ArgumentParser, metavar: str = "FILE", what: str = "model TOML file"
) -> None:
    """``--model FILE``: the model file, the paper's robot by default."""
    parser.add_argument("--model", metavar=metavar, help=f"{what} ({PAPER_MODEL})")


def add_trajectory(
    parser: argparse.ArgumentParser, samples: bool = True, smoothing: bool = True
) -> None:
    """``--trajectory`` (a paper trajectory or a CSV file), ``--samples`` and ``--duration`` of
    a paper trajectory, ``--smoothing`` of a CSV file (each of the two unless False);
    :func:`trajectory` reads them."""
    parser.add_argument(
        "--trajectory",
        default="rotation",
        metavar=TRAJECTORY,
        help="'rotation' or 'rectilinear' (the paper's motions, eq. 3), or a trajectory CSV "
        "file (default: rotation)",
    )
    if samples:
        add_samples(parser)
    else:
        parser.set_defaults(samples=None)
    add_duration(parser)
    if smoothing:
        add_smoothing(parser)
    else:
        parser.set_defaults(smoothing=None)


def add_samples(
    parser: argparse.ArgumentParser, which: str = "a paper trajectory", default: int | None = None
) -> None:
    """``--samples N`` of ``which`` paper trajectory (default: None, read as DEFAULT_SAMPLES)."""
    parser.add_argument(
        "--samples",
        type=integer(2),
        default=default,
        metavar="N",
        help=f"number of samples of {which}, both ends included (default: {DEFAULT_SAMPLES})",
    )


def add_duration(
    parser: argparse.ArgumentParser,
    which: str = "a paper trajectory",
    default: float | None = None,
) -> None:
    """``--duration T`` of ``which`` paper trajectory (default: None, read as
    DEFAULT_DURATION)."""
    parser.add_argument(
        "--duration",
        type=number(least=DURATIONS[0], most=DURATIONS[1], unit="s"),
        default=default,
        metavar="T",
        help=f"duration of {which}, s (default: {DEFAULT_DURATION:g})",
    )


def add_smoothing(parser: argparse.ArgumentParser) -> None:
    """``--smoothing S``: the smoothing spline of a CSV file of positions only."""
    parser.add_argument(
        "--smoothing",
        type=number(least=0.0, most=MAX_SMOOTHING),
        metavar="S",
        help="for a CSV file of positions only (t,x,y,phi): RMS deviation allowed between the "
        "quintic spline whose derivatives give the velocities and accelerations and the "
        "positions, m for x, y and rad for phi; give the noise level of measured positions "
        "(default: 0, through every sample)",
    )


def add_backend(parser: argparse.ArgumentParser) -> None:
    """``--backend numpy|c``: which generated code evaluates."""
    parser.add_argument(
        "--backend",
        choices=BACKENDS,
        default="numpy",
        help="evaluate the generated NumPy or C code (default: numpy)",
    )


def add_threads(parser: argparse.ArgumentParser) -> None:
    """``--threads N`` of the C backend."""
    parser.add_argument(
        "--threads",
        type=integer(1),
        metavar="N",
        help="threads of the c backend (default: every core this process may use); the "
        "results do not depend on it",
    )


def add_generated(parser: argparse.ArgumentParser) -> None:
    """``--generated DIR``: generated code that ``rpr3gen generate --out DIR`` wrote."""
    parser.add_argument(
        "--generated",
        metavar="DIR",
        help="evaluate with the generated code that `rpr3gen generate` wrote into DIR "
        "(default: the installed generated package)",
    )


def add_out_folder(parser: argparse.ArgumentParser, default: str) -> None:
    """``--out DIR``: the output folder, ``./default`` by default."""
    parser.add_argument(
        "--out", default=default, metavar="DIR", help=f"output folder (default: ./{default})"
    )


def add_min_conditioning(
    parser: argparse.ArgumentParser, meaning: str, default: float = DEFAULT_MIN_CONDITIONING
) -> None:
    """``--min-conditioning C`` in [0, 1) (1 would refuse every pose); ``meaning``: what the
    command does with a pose below it."""
    parser.add_argument(
        "--min-conditioning",
        type=number(least=0.0, below=1.0),
        default=default,
        metavar="C",
        help=f"{meaning} (default: {default:g})",
    )


def trajectory(
    args: argparse.Namespace, pose: tuple[str, ...] = PLANAR_POSE
) -> tuple[str, Trajectory]:
    """The trajectory that ``--trajectory``, ``--samples``, ``--duration`` and ``--smoothing``
    name, and its name (a paper trajectory's, or the CSV file's stem); ``pose``: the model's
    pose coordinates (a spatial robot's take no paper trajectory)."""
    given = {"samples": args.samples, "duration": args.duration}
    timing = {key: value for key, value in given.items() if value is not None}
    if args.trajectory in PAPER_TRAJECTORIES and pose != PLANAR_POSE:
        raise TrajectoryError(
            f"--trajectory: the paper's {args.trajectory!r} motion is planar; a spatial robot "
            f"(pose {', '.join(pose)}) needs a trajectory CSV file: --trajectory FILE.csv"
        )
    if args.trajectory in PAPER_TRAJECTORIES:
        if args.smoothing is not None:
            raise TrajectoryError(
                "--smoothing: only for a trajectory CSV file of positions; "
                f"{args.trajectory!r} has analytic derivatives"
            )
        sizes.check("samples", timing.get("samples", DEFAULT_SAMPLES),
                    lambda n: n * sizes.SIMULATED_SAMPLE, "the simulation, its CSV and figures",
                    least=2, argument="samples")  # fmt: skip
        return args.trajectory, paper_trajectory(args.trajectory, **timing)
    path = Path(args.trajectory)
    if path.suffix.lower() != ".csv" and not path.exists():
        names = ", ".join(PAPER_TRAJECTORIES)
        hint = did_you_mean(args.trajectory, PAPER_TRAJECTORIES)
        raise TrajectoryError(
            f"--trajectory: {args.trajectory!r} is neither {names} nor a CSV file{hint}"
        )
    if timing:
        options = " and ".join(f"--{key}" for key in timing)
        raise TrajectoryError(f"{options}: only for a paper trajectory; {path} has its own times")
    return path.stem, read_trajectory_csv(path, smoothing=args.smoothing, pose=pose)
