"""``rpr3gen excite``: an exciting trajectory for identification, a periodic Fourier-series
motion optimised for the base regressor's condition number, written as a trajectory CSV."""

from __future__ import annotations

import argparse
import math

from rpr3gen.commands import options
from rpr3gen.commands.args import integer, number
from rpr3gen.model import Model, load_model
from rpr3gen.paths import check_output

NAME = "excite"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``excite`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="write an exciting trajectory for identification (optimised Fourier series)",
        description="Optimise a periodic Fourier-series platform motion that minimises the "
        "condition number of the base regressor, inside the workspace (joint limits or stroke "
        "limits of the model, or |lambda21| <= l0/2; conditioning floor; acceleration bounds; "
        "the platform within --max-translation and --max-angle of home, by default for a "
        "spatial robot), and write one period as a trajectory CSV (with the pose's columns).",
    )
    options.add_model(parser)
    parser.add_argument("--out", metavar="FILE.csv", required=True, help="the trajectory CSV")
    parser.add_argument(
        "--harmonics",
        type=integer(1),
        default=5,
        help="per coordinate, at most (samples - 1) / 2 (5)",
    )
    parser.add_argument("--period", type=number(greater=0.0), default=10.0, help="s (default 10)")
    parser.add_argument("--samples", type=integer(10), default=201, help="per period (201)")
    options.add_min_conditioning(
        parser, "floor on the pose's conditioning along the motion", default=0.1
    )
    parser.add_argument(
        "--max-translation",
        type=number(greater=0.0),
        metavar="M",
        help="bound on each platform translation from home, m (a spatial robot's default: a "
        "fifth of its shortest leg)",
    )
    parser.add_argument(
        "--max-angle",
        type=number(greater=0.0),
        metavar="RAD",
        help="bound on each platform angle from home, rad (a spatial robot's default: 0.3)",
    )
    parser.add_argument(
        "--identical-legs",
        action="store_true",
        help="optimise for the legs' shared parameters (the paper's robot: 9)",
    )
    parser.add_argument("--friction", action="store_true", help="include the friction columns")
    parser.add_argument("--seed", type=integer(0), default=0, help="of the starting motion (0)")
    parser.add_argument(
        "--max-iterations", type=integer(1, 2**31 - 1), default=100, help="SLSQP (100)"
    )
    options.add_backend(parser)


def _excursion(
    model: Model, translation: float | None, angle: float | None
) -> tuple[float, float] | None:
    """``max_excursion`` from the two options (the other the default), or None for neither."""
    if translation is None and angle is None:
        return None
    from rpr3gen.excitation import default_excursion

    default = default_excursion(model) if model.structure.spatial else (math.inf, math.inf)
    return (
        translation if translation is not None else default[0],
        angle if angle is not None else default[1],
    )


def run(args: argparse.Namespace) -> int:
    """Optimise the motion, write one period, print the condition numbers."""
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
        max_excursion=_excursion(model, args.max_translation, args.max_angle),
        backend=args.backend,
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    write_trajectory_csv(out, found.trajectory, model.structure.pose)
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
