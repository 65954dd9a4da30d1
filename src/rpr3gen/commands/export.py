"""``rpr3gen export``: a spatial robot as a MuJoCo model (MJCF), loops closed by equality
constraints, the motors as actuators (:mod:`rpr3gen.export`)."""

from __future__ import annotations

import argparse

from rpr3gen.commands import options
from rpr3gen.export import write_mjcf
from rpr3gen.model import load_model
from rpr3gen.paths import check_output

NAME = "export"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``export`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="write a spatial robot as a MuJoCo model (MJCF)",
        description="Write a spatial robot (a hexapod or a Delta) as a MuJoCo model: its bodies "
        "with the model file's masses and inertias, every joint coordinate a MuJoCo joint "
        "(zero at home), the S joints at the platform as connect equalities, one motor per "
        "leg on the actuated joint (ctrl = tau). Contacts are off; the payload is not in the "
        "file (apply it with xfrc_applied).",
    )
    options.add_model(parser)
    parser.add_argument(
        "--format", choices=("mjcf",), default="mjcf", help="the file format (default: mjcf)"
    )
    parser.add_argument("--out", metavar="FILE.xml", required=True, help="the file to write")


def run(args: argparse.Namespace) -> int:
    """Write the model file."""
    check_output(args.out, "the MuJoCo model", argument="out")
    model = load_model(args.model)
    write_mjcf(model, args.out)
    print(f"wrote {args.out}: {model.name} ({model.structure.title}) as MJCF")
    return 0
