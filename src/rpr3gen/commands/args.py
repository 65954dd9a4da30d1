"""Argument parsing shared by every command: the parser, number types, options in messages.

- :class:`Parser` prints a usage error as one line, and reads a negative number in any
  notation (``-1e-3``, ``-.5``, ``-inf``) as a value, never as an option.
- :func:`integer` and :func:`number` are the ``type=`` of every numeric option and argument:
  the checks of :mod:`rpr3gen.validation`, so the command line refuses what the Python API
  refuses, with the same words (``--samples: must be an integer >= 2, got 1``).
- :func:`as_option` shows an error of the Python API about an argument (``samples: ...``) as
  one about the command's option (``--samples: ...``).
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable
from typing import Any, NoReturn

from rpr3gen.errors import Rpr3genError
from rpr3gen.validation import Integer, Number

__all__ = ["EXIT_ERROR", "NEGATIVE_NUMBER", "Parser", "as_option", "integer", "number"]

EXIT_ERROR = 2

NEGATIVE_NUMBER = re.compile(
    r"^-(?:\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|inf|infinity|nan)$", re.IGNORECASE
)
"""What argparse must take for a negative number, not an option: ``-1``, ``-0.5``, ``-.5``,
``-1e-3``, ``-1E+3``, ``-inf``, ``-nan`` (argparse's own pattern misses the exponent)."""


class Parser(argparse.ArgumentParser):
    """Usage errors as one line, like every other error of the command; negative numbers in
    any notation are values."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_ERROR, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _argument_type(check: Callable[[str, Any], Any], parse: Callable[[str], Any]) -> Callable:
    def convert(text: str) -> Any:
        try:
            value = parse(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        try:
            return check("value", value)
        except Rpr3genError as exc:  # "value: must be ..." -> "must be ..."
            raise argparse.ArgumentTypeError(str(exc).removeprefix("value: ")) from None

    return convert


def _int(text: str) -> int:
    """An integer, also written ``1e6`` (a whole number in exponent notation)."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"not an integer: {text!r}") from None
    if not (math.isfinite(value) and value.is_integer()):
        raise ValueError(f"not an integer: {text!r}")
    return int(value)


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"not a number: {text!r}") from None


def integer(least: int | None = None, most: int | None = None) -> Callable[[str], int]:
    """``type=`` of an integer option in ``[least, most]``."""
    return _argument_type(Integer(least, most), _int)


def number(**bounds: Any) -> Callable[[str], float]:
    """``type=`` of a number option; ``bounds`` as :class:`rpr3gen.validation.Number`'s
    (``finite``, ``least``, ``most``, ``greater``, ``below``, ``unit``)."""
    return _argument_type(Number(**bounds), _float)


def as_option(exc: Rpr3genError, parser: argparse.ArgumentParser | None) -> str:
    """The message of ``exc`` with its argument named as the command's option (``--samples``,
    or the metavar of a positional), when it starts with the argument and the command has it."""
    message = str(exc)
    name = exc.argument
    if not name or parser is None or message[len(name) : len(name) + 1] not in (":", " ", "["):
        return message
    if not message.startswith(name):
        return message
    for action in parser._actions:
        if action.dest == name:
            shown = action.option_strings[-1] if action.option_strings else action.metavar
            return f"{shown or name}{message[len(name) :]}"
    return message


def subparser(
    parser: argparse.ArgumentParser, command: str | None
) -> argparse.ArgumentParser | None:
    """The parser of ``command`` among ``parser``'s subcommands."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            return action.choices[command]
    return None
