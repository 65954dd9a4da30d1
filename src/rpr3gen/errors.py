"""Exceptions and warnings raised for bad user input (model files, trajectories, arrays).

Each error carries a one-line, user-facing message that already names the file, the key or the
row and column at fault; the command line prints it as ``rpr3gen: error: <msg>`` and exits
with status 2, without a traceback.

Every error of the package derives from :class:`Rpr3genError`. Those about a bad value also
derive from :class:`ValueError`, and those about a value of the wrong type from
:class:`TypeError`, so code written against the standard exceptions catches them too::

    Rpr3genError(Exception)
    ├── ModelError(Rpr3genError, ValueError)        a model file or dictionary
    ├── TrajectoryError(Rpr3genError, ValueError)   a trajectory file or request
    ├── GridError(Rpr3genError, ValueError)         a design-study grid file or mapping
    ├── InputError(Rpr3genError, ValueError)        an array or argument of the Python API
    ├── IdentificationError(Rpr3genError, ValueError)  data that do not determine the fit
    └── InputTypeError(Rpr3genError, TypeError)     an argument of the wrong type

Warnings (``warnings.warn``) derive from :class:`Rpr3genWarning`, a :class:`UserWarning`; the
command line prints each as one line ``rpr3gen: warning: <msg>`` on stderr::

    Rpr3genWarning(UserWarning)
    ├── TrajectoryWarning       a trajectory file's derivatives disagree with its positions
    └── IdentificationWarning   identification data excite some parameters only weakly
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = [
    "GridError",
    "IdentificationError",
    "IdentificationWarning",
    "InputError",
    "InputTypeError",
    "ModelError",
    "Rpr3genError",
    "Rpr3genWarning",
    "TrajectoryError",
    "TrajectoryWarning",
    "did_you_mean",
]


class Rpr3genError(Exception):
    """Base class of every error the package raises on purpose; ``str(err)`` is one line.

    Attributes:
        argument: the name of the Python argument at fault when the message starts with it
            (``"samples: ..."``), else None; the command line shows it as its option
            (``--samples: ...``).
    """

    def __init__(self, *args: object, argument: str | None = None) -> None:
        super().__init__(*args)
        self.argument = argument


class ModelError(Rpr3genError, ValueError):
    """A model file (or dictionary) is missing, malformed or describes a degenerate robot."""


class TrajectoryError(Rpr3genError, ValueError):
    """A trajectory file or a trajectory request is malformed."""


class GridError(Rpr3genError, ValueError):
    """A grid of designs (``rpr3gen sweep --grid``) names an unknown key or a bad value."""


class InputError(Rpr3genError, ValueError):
    """An array or argument given to the Python API has a bad shape or value."""


class IdentificationError(Rpr3genError, ValueError):
    """Identification data cannot determine the parameters (too little excitation, too few
    samples)."""


class InputTypeError(Rpr3genError, TypeError):
    """An argument given to the Python API has the wrong type."""


class Rpr3genWarning(UserWarning):
    """Base class of the package's warnings: the input is usable but likely not what was meant."""


class TrajectoryWarning(Rpr3genWarning):
    """A trajectory's velocities or accelerations disagree with its positions, or its spline
    could not be fitted as asked."""


class IdentificationWarning(Rpr3genWarning):
    """Identification data whose condition number is above the documented bound: the fit is
    kept, with standard deviations that the motion inflates (rpr3gen.identifiability)."""


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` for the choice closest to ``word``, ``""`` if none is close."""
    match = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f"; did you mean '{match[0]}'?" if match else ""
