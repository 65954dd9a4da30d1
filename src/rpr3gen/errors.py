"""Exceptions and warnings raised for bad user input (model files, trajectories, arrays) and
for an environment that cannot do what was asked (a damaged generated folder, no C compiler).

Each error carries a one-line, user-facing message that already names the file, the key or the
row and column at fault; the command line prints it as ``rpr3gen: error: <msg>`` and exits
with status 2, without a traceback.

Every error of the package derives from :class:`Rpr3genError`, and from one of three standard
families, so code written against the standard exceptions catches them too: a bad value is a
:class:`ValueError`, a value of the wrong type a :class:`TypeError`, and a failure of the
environment (files, installed packages, compiler, scheduler) an :class:`OSError`. The base
class itself is never raised::

    Rpr3genError(Exception)
    ├── ModelError(Rpr3genError, ValueError)        a model file or dictionary
    ├── TrajectoryError(Rpr3genError, ValueError)   a trajectory file or request, or a motion
    │                                               through an invalid pose
    ├── GridError(Rpr3genError, ValueError)         a design-study grid file or mapping
    ├── InputError(Rpr3genError, ValueError)        an array or argument of the Python API, or
    │                                               a setting (RPR3GEN_MAX_MEMORY)
    ├── IdentificationError(Rpr3genError, ValueError)  data that do not determine the fit
    ├── InputTypeError(Rpr3genError, TypeError)     an argument of the wrong type
    └── SetupError(Rpr3genError, OSError)           the environment: a missing optional extra
        │                                           or C compiler, a compiler that fails, an
        │                                           unreachable Dask scheduler, a folder in
        │                                           the way
        └── GeneratedCodeError(SetupError)          a generated folder that is damaged, stale,
                                                    of another version or lacks a variant

A :class:`SetupError` is not about an argument's value: the same call succeeds once the
environment is put right (the message says how: ``pip install 'rpr3gen[toppra]'``, ``rpr3gen
generate --out DIR``...). A missing optional package is a :class:`SetupError` rather than an
:class:`ImportError`: it is raised by a call, not by an ``import`` statement of the user's, and
it belongs with the other failures of the environment that one ``except OSError`` catches.

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
    "GeneratedCodeError",
    "GridError",
    "IdentificationError",
    "IdentificationWarning",
    "InputError",
    "InputTypeError",
    "ModelError",
    "Rpr3genError",
    "Rpr3genWarning",
    "SetupError",
    "TrajectoryError",
    "TrajectoryWarning",
    "did_you_mean",
]


class Rpr3genError(Exception):
    """Base class of every error the package raises on purpose; ``str(err)`` is one line.

    Never raised itself: every error is also a :class:`ValueError`, a :class:`TypeError` or an
    :class:`OSError` (the subclasses below).

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
    """A trajectory file or a trajectory request is malformed, or a motion passes through a pose
    that is singular, out of reach or beyond a joint limit."""


class GridError(Rpr3genError, ValueError):
    """A grid of designs (``rpr3gen sweep --grid``) names an unknown key or a bad value."""


class InputError(Rpr3genError, ValueError):
    """An array or argument given to the Python API has a bad shape or value (a reading the
    generated code refuses, too), or a setting (``RPR3GEN_MAX_MEMORY``) a bad value."""


class IdentificationError(Rpr3genError, ValueError):
    """Identification data cannot determine the parameters (too little excitation, too few
    samples)."""


class InputTypeError(Rpr3genError, TypeError):
    """An argument given to the Python API has the wrong type."""


class SetupError(Rpr3genError, OSError):
    """The environment cannot do what was asked, whatever the arguments: an optional extra or
    the C compiler is missing, the compiler fails, a Dask scheduler cannot be reached or its
    task fails, a folder is in the way. The message says how to put it right."""


class GeneratedCodeError(SetupError):
    """A folder of generated code (installed, cached or given as ``generated=DIR``) cannot be
    used: unreadable, damaged, of two generations, of another version, or without the variant
    or function asked for. The message names the file and how to regenerate it."""


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
