"""The ``rpr3gen`` command: the top parser over the subcommands of :mod:`rpr3gen.commands`
(one module each), and the error handling they share.

Every failure is one line on stderr (``rpr3gen: error: ...``) and exit status 2; ``--debug``
shows the traceback instead. The package's warnings are one line each (``rpr3gen: warning:
...``). Output files are written atomically, and a reader of stdout that goes away ends the
command quietly.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Sequence

from rpr3gen import __version__
from rpr3gen.commands import COMMANDS
from rpr3gen.commands.args import EXIT_ERROR, Parser, as_option, subparser
from rpr3gen.commands.reports import warnings_as_lines
from rpr3gen.errors import Rpr3genError


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``rpr3gen``, with every command of :data:`rpr3gen.commands.COMMANDS`."""
    parser = Parser(
        prog="rpr3gen",
        description="Inverse dynamics with every joint load, control model, identification "
        "and design studies of planar 3-leg parallel robots (Staicu's method; the paper's "
        "3-RPR by default), from generated code. SI units throughout (m, rad, s, N, N·m).",
        epilog="Run 'rpr3gen COMMAND --help' for the options of a command.",
    )
    parser.add_argument("--version", action="version", version=f"rpr3gen {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rpr3gen`` command; returns the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # a usage error, its line printed: the status (--help exits 0)
        if exc.code in (0, None):
            raise
        return exc.code if isinstance(exc.code, int) else EXIT_ERROR
    if args.command is None:  # a bare `rpr3gen`: show what it can do
        parser.print_help(sys.stderr)
        return EXIT_ERROR
    run = {command.NAME: command.run for command in COMMANDS}[args.command]
    try:
        with warnings_as_lines():
            status = run(args)
        sys.stdout.flush()  # a reader that went away shows here, not at the interpreter's exit
        return status
    except BrokenPipeError:
        return _reader_went_away()
    except (Rpr3genError, OSError) as exc:
        if args.debug:
            raise
        if isinstance(exc, Rpr3genError):  # "samples: ..." of the Python API is "--samples: ..."
            message = as_option(exc, subparser(parser, args.command))
        else:
            message = _os_message(exc)
        print(f"rpr3gen: error: {message}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt as exc:
        detail = f"; {exc}" if str(exc) else ""
        print(f"rpr3gen: interrupted{detail}", file=sys.stderr)
        return 130


def _reader_went_away() -> int:
    """``rpr3gen ... | head -1``: the reader of stdout closed the pipe; stop quietly, status 0.

    Every output file is complete by then (stdout gets only the summary, printed last); what
    is lost is the text that the reader chose not to read.
    """
    # Python flushes stdout once more at exit and would report the pipe again: send the rest
    # of the buffer to /dev/null instead.
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    return 0


def _os_message(exc: OSError) -> str:
    where = f"{exc.filename}: " if exc.filename else ""
    return f"{where}{exc.strerror or exc}"


if __name__ == "__main__":
    sys.exit(main())
