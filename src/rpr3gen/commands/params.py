"""``rpr3gen params``: a model's parameter vector as ``name value`` lines (for C users)."""

from __future__ import annotations

import argparse

from rpr3gen.commands import options
from rpr3gen.model import load_model

NAME = "params"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``params`` subcommand's parser."""
    parser = sub.add_parser(
        NAME, help="print a model's parameter vector as 'name value' lines (for C users)"
    )
    options.add_model(parser)


def run(args: argparse.Namespace) -> int:
    """Print every parameter, full precision."""
    model = load_model(args.model)
    lines = [f"{name} {value:.17g}" for name, value in model.params.items()]
    print("\n".join(lines))
    return 0
