"""``rpr3gen fk``: forward kinematics, every assembly mode of three actuator readings with its
conditioning."""

from __future__ import annotations

import argparse

import numpy as np

from rpr3gen.backends import inverse_dynamics
from rpr3gen.commands import options
from rpr3gen.commands.args import number
from rpr3gen.errors import InputError
from rpr3gen.model import load_model

NAME = "fk"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``fk`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="forward kinematics: every assembly mode of the actuator readings",
        description="Print every assembly mode of the actuator coordinates QA1 QA2 QA3 (legs A, "
        "B, C: phi10 in rad with revolute actuation, lambda21 in m with prismatic), one per "
        "line: x y (m) phi (rad, in (-pi, pi]) and the pose's conditioning (0 = singular, 1 = "
        "best). A spatial robot takes one reading per leg (a hexapod six, a Delta three) and "
        "prints x y z (m) and, for a hexapod, a b c (rad); a Delta's modes in closed form, a "
        "hexapod's those its documented search finds; a Delta's other sphere intersection, with "
        "legs in the other working mode, follows as a comment line (docs/spatial-robots.md).",
    )
    options.add_model(parser)
    options.add_generated(parser)
    parser.add_argument(
        "qa", nargs="+", type=number(), metavar="QA", help="actuator coordinate, one per leg"
    )


def run(args: argparse.Namespace) -> int:
    """Print a header line, then ``x y phi conditioning`` of each assembly mode."""
    from rpr3gen.control import assembly_modes

    model = load_model(args.model, generated=args.generated)
    legs = model.structure.legs
    if len(args.qa) != len(legs):
        raise InputError(
            f"QA: the {model.structure.title} takes {len(legs)} actuator coordinates (legs "
            f"{', '.join(legs)}), got {len(args.qa)}"
        )
    qa = np.array(args.qa)  # finite numbers (args.number)
    modes = assembly_modes(model, qa)
    zero = np.zeros_like(modes)
    conditioning = (
        inverse_dynamics(model, modes, zero, zero)["conditioning"] if len(modes) else zero
    )
    family = model.structure.actuator
    what = f"{model.actuation} actuation" if model.structure.paper else model.structure.title
    pose = " ".join(model.structure.pose)
    print(
        f"# {len(modes)} assembly mode(s) of {family} = {' '.join(f'{v:g}' for v in qa)} "
        f"({model.name}, {what}): {pose} conditioning"
    )
    for mode, c in zip(modes, conditioning, strict=True):
        print(" ".join(f"{v:.12g}" for v in mode) + f" {c:.6g}")
    if model.structure.spatial and model.structure.dof == 3:
        from rpr3gen.spatial_modes import delta_candidates

        others = [
            c for c in delta_candidates(model, qa) if not any(np.allclose(c, m) for m in modes)
        ]
        if others:
            print(
                f"# {len(others)} other assembly mode(s), with legs in the other working mode "
                "(not the model's; x y z):"
            )
        for c in others:
            print("# " + " ".join(f"{v:.12g}" for v in c))
    return 0
