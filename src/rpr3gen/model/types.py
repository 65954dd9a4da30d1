"""The :class:`Model` dataclass: a validated robot, of the paper's format, the general planar one
or a spatial robot's (a hexapod or a Delta, docs/spatial-robots.md).

A model read from a file (:mod:`rpr3gen.model.load`) is checked key by key first; one built in
code (``Model(name, actuation, params, ...)`` or ``dataclasses.replace``) is checked field by
field on construction (:mod:`rpr3gen.model.checks`). This module also gives the ``model``
argument of every public function its check (:class:`IsModel`, in
:data:`rpr3gen.validation.COMMON`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from rpr3gen.model.checks import check_fields
from rpr3gen.structure import PAPER_PARAM_NAMES, Structure
from rpr3gen.validation import COMMON, Instance

__all__ = ["ACTUATIONS", "DEFAULT_GRAVITY", "LEGS", "PARAM_NAMES", "IsModel", "Model"]

ACTUATIONS: tuple[str, ...] = ("revolute", "prismatic")
"""Which joint of each leg is driven: the base revolute (the paper) or the prismatic joint."""

PARAM_NAMES: tuple[str, ...] = PAPER_PARAM_NAMES
"""Names of the paper format's model parameters, in the order of the generated code's
``params`` array (a general model's are its structure's, :meth:`Structure.param_names`)."""

LEGS: tuple[str, ...] = ("A", "B", "C")

DEFAULT_GRAVITY: tuple[float, float] = (0.0, -9.81)
"""Gravity in the world frame (y0 up) when the model file has no ``environment.gravity``, m/s²."""


_V = TypeVar("_V")


class _ReadOnly(Mapping[str, _V]):
    """An immutable, hashable mapping over ``self._data`` (a dict its subclass builds)."""

    _data: dict[str, _V]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __hash__(self) -> int:
        return hash(tuple(self._data.items()))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Mapping) and dict(self.items()) == dict(other.items())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._data!r})"


class _ReadOnlyParams(_ReadOnly[float]):
    """An immutable, hashable, picklable ``str -> float`` mapping that keeps its key order."""

    def __init__(self, items: Mapping[str, float]) -> None:
        self._data = dict(items)

    def __getitem__(self, key: str) -> float:
        return self._data[key]


@dataclass(frozen=True)
class Model:
    """A validated robot, of the paper's format, the general planar one or a spatial one.

    Attributes:
        name: The model's name (``name`` in the file).
        actuation: ``"revolute"`` (motors on revolute joints: the paper's base motors) or
            ``"prismatic"``: the kind of the actuated joint.
        params: Read-only mapping with exactly the structure's parameter names
            (:meth:`Structure.param_names`), in that order, as floats in SI units. The paper's
            format: base pivots ``xA1..yC1`` (m, world frame), platform joints ``xA3..yC3``
            (m, platform frame), ``alpha_A..alpha_C`` (rad), lengths (m), masses (kg),
            inertias (kg m², about the COM, axis z), gravity ``gx, gy`` (m/s²) and the payload
            wrench at G ``fx, fy`` (N), ``mz`` (N m). The general format: docs/interfaces.md.
            A spatial robot (a hexapod or a Delta): per leg ``L`` its points, unit axes, the
            working mode ``sigma_L``, masses, centres of mass and inertia tensors (world frame,
            z up, at home), then the platform's, gravity ``gx, gy, gz`` and the payload
            ``fx, fy, fz, mx, my, mz``: docs/spatial-robots.md.
        source: Where the model came from (a file path or ``"<dict>"``), for messages.
        stroke: The paper's format: optional piston displacement bounds ``((lo, hi), ...)``
            for legs A, B, C (m, bounds on lambda21), from ``[limits] stroke``; else None.
        generated: The folder of generated code that evaluates this model (written by
            ``rpr3gen generate --out DIR``), or None for the installed package (and the cache
            of variants generated on first use).
        structure: The leg type and actuated joint (and the format); None (only when built by
            hand) means the paper's of ``actuation``.
        limits: The general format: joint coordinate bounds ``{"A.q2": (lo, hi), ...}`` (m or
            rad) from ``[limits]``; None when the file sets none (always for spatial models,
            whose files take no ``[limits]`` yet).
    """

    name: str
    actuation: str
    params: Mapping[str, float]
    source: str
    stroke: tuple[tuple[float, float], ...] | None = None
    generated: str | None = None
    # Always a Structure after construction (None at construction means the paper's).
    structure: Structure = None  # type: ignore[assignment]
    limits: Mapping[str, tuple[float, float]] | None = None

    def __post_init__(self) -> None:
        fields = check_fields(self, ACTUATIONS)  # rpr3gen.model.checks
        object.__setattr__(self, "structure", fields["structure"])
        object.__setattr__(self, "params", _ReadOnlyParams(fields["params"]))
        object.__setattr__(self, "stroke", fields["stroke"])
        object.__setattr__(self, "generated", fields["generated"])
        if fields["limits"] is not None:
            object.__setattr__(self, "limits", _ReadOnlyLimits(fields["limits"]))

    @property
    def variant(self) -> str:
        """The generated variant that evaluates this model (a folder name: ``revolute``,
        ``rrr_1``, ...)."""
        return self.structure.variant

    @property
    def param_names(self) -> tuple[str, ...]:
        """The model's parameter names, in the generated code's order."""
        return tuple(self.params)

    def vector(self, names: Sequence[str] | None = None) -> np.ndarray:
        """Return the parameters ``names`` (default: all, in order) as a new float64 array.

        Raises:
            KeyError: If a name is not one of the model's parameters.
        """
        names = tuple(self.params) if names is None else names
        return np.array([self.params[n] for n in names], dtype=np.float64)


class _ReadOnlyLimits(_ReadOnly[tuple[float, float]]):
    """An immutable, hashable ``"A.q2" -> (lo, hi)`` mapping in sorted key order."""

    def __init__(self, items: Mapping[str, tuple[float, float]]) -> None:
        self._data = {k: (float(v[0]), float(v[1])) for k, v in sorted(items.items())}

    def __getitem__(self, key: str) -> tuple[float, float]:
        return self._data[key]


class IsModel(Instance):
    """A :class:`Model` (from :func:`rpr3gen.load_model`), not a file name."""

    def __init__(self) -> None:
        super().__init__(Model, "a Model (rpr3gen.load_model(...))")


# Every public function's ``model`` argument: registered here, below the functions that take one
# (each of their modules imports this package first), so the validation layer never imports it.
COMMON.setdefault("model", IsModel())
