"""Exceptions raised for bad user input (model files, trajectories).

Each carries a one-line, user-facing message that already names the file, the key or the
row and column at fault; the command line prints it as ``rpr3gen: error: <msg>`` and exits
with status 2, without a traceback.
"""

from __future__ import annotations

__all__ = ["InputError", "ModelError", "Rpr3genError", "TrajectoryError"]


class Rpr3genError(Exception):
    """Base class of every error caused by user input; ``str(err)`` is one line."""


class ModelError(Rpr3genError):
    """A model file (or dictionary) is missing, malformed or describes a degenerate robot."""


class TrajectoryError(Rpr3genError):
    """A trajectory file or a trajectory request is malformed."""


class InputError(Rpr3genError, ValueError):
    """An array or option passed to the Python API has a wrong shape or value."""
