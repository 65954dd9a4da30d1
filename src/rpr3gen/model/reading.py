"""What both model file readers share: the :class:`Reader` of one file's keys and values, and
the one-line descriptions of what the user wrote.

Every failure is a :class:`~rpr3gen.errors.ModelError` whose one-line message names the file and
the dotted key, e.g. ``my.toml: geometry.l0: must be a positive number, got -0.1``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from numbers import Real
from typing import Any, ClassVar, NoReturn

import numpy as np

from rpr3gen.errors import ModelError, did_you_mean

__all__ = ["Reader", "as_list", "describe", "one_line", "point", "quoted"]


class Reader:
    """Validates one model description; every failure names ``source`` and a dotted key.

    A format's reader sets :attr:`schema` (allowed keys per table; None marks a leaf value, a
    dict a sub-table) and reads its sections with these helpers.
    """

    schema: ClassVar[Mapping[str, Any]] = {}

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, key: str, message: str) -> NoReturn:
        """Raise the :class:`~rpr3gen.errors.ModelError` of ``key``."""
        raise ModelError(one_line(f"{self.source}: {key}: {message}"))

    # -- structure -------------------------------------------------------------------------

    def check_keys(self, table: Mapping[Any, Any], schema: Mapping[str, Any], prefix: str) -> None:
        """Refuse a key of ``table`` that ``schema`` does not allow, recursively."""
        for key in table:
            dotted = f"{prefix}{key}"
            if key not in schema:
                hint = did_you_mean(str(key), schema) or self.elsewhere(str(key), prefix)
                self.fail(dotted, f"unknown key{hint}")
            sub = schema[key]
            if isinstance(sub, dict):
                value = table[key]
                if not isinstance(value, Mapping):
                    self.fail(dotted, f"must be a table [{dotted}], got {describe(value)}")
                self.check_keys(value, sub, f"{dotted}.")

    def elsewhere(self, key: str, prefix: str) -> str:
        """Hint for a key that belongs in another table (e.g. ``l0`` at the top level)."""
        for section, sub in self.schema.items():
            if isinstance(sub, dict) and key in sub and prefix != f"{section}.":
                return f"; it belongs in [{section}]"
        return ""

    def required(self, table: Mapping[str, Any], dotted: str, key: str) -> Any:
        """``table[key]``, or the failure of a missing required key."""
        if key not in table:
            self.fail(dotted, "missing required key")
        return table[key]

    def table(self, data: Mapping[str, Any], key: str, *, required: bool) -> Mapping[str, Any]:
        """The sub-table ``key`` (its type checked by :meth:`check_keys`), ``{}`` if absent."""
        if key not in data:
            if required:
                self.fail(key, f"missing required table [{key}]")
            return {}
        return data[key]  # type checked by check_keys

    # -- values ----------------------------------------------------------------------------

    def number(
        self,
        table: Mapping[str, Any],
        dotted: str,
        key: str,
        *,
        default: float | None = None,
        positive: bool = False,
        why_required: str = "",
    ) -> float:
        """The number ``table[key]``, or ``default`` (required when None)."""
        if key not in table:
            if default is None:
                self.fail(dotted, f"missing required key{why_required}")
            return float(default)
        return self.scalar(table[key], dotted, positive=positive)

    def scalar(self, value: Any, dotted: str, *, positive: bool = False) -> float:
        """``value`` as a finite float (``positive``: > 0)."""
        kind = "a positive number" if positive else "a number"
        if isinstance(value, bool | np.bool_) or not isinstance(value, Real):
            self.fail(dotted, f"must be {kind}, got {describe(value)}")
        try:
            x = float(value)
        except OverflowError:  # an integer beyond float64 (TOML integers have no bound)
            self.fail(dotted, f"must be a finite number, got {describe(value)}")
        if not math.isfinite(x):
            self.fail(dotted, f"must be a finite number, got {describe(value)}")
        if positive and x <= 0.0:
            self.fail(dotted, f"must be {kind}, got {describe(value)}")
        return x

    def joint_limits(
        self, table: Any, legs: Sequence[str], coordinates: Sequence[str], leg_type: str
    ) -> dict[str, tuple[float, float]] | None:
        """``[limits]``: ``"A.q2" = [lo, hi]`` (m or rad) bounds one leg's joint coordinate,
        ``"q2"`` every leg's; ``coordinates`` are those a ``leg_type`` leg may bound."""
        if not table:
            return None
        if not isinstance(table, Mapping):
            self.fail("limits", f"must be a table [limits], got {describe(table)}")
        names = [f"{leg}.{q}" for leg in legs for q in coordinates] + list(coordinates)
        out: dict[str, tuple[float, float]] = {}
        for key in table:
            if key not in names:
                hint = did_you_mean(str(key), names)
                self.fail(
                    f"limits.{key}",
                    f"unknown key{hint} (a joint coordinate of this {leg_type} leg: "
                    f'{", ".join(repr(c) for c in coordinates)}, as "A.{coordinates[-1]}" for '
                    "one leg or alone for every leg)",
                )
            lo, hi = self.vector(table, f"limits.{key}", key, 2)
            if not lo < hi:
                self.fail(
                    f"limits.{key}",
                    f"the lower bound must be below the upper, got [{lo:g}, {hi:g}]",
                )
            for leg in (key.split(".")[0],) if "." in key else legs:
                out[f"{leg}.{key.split('.')[-1]}"] = (lo, hi)
        return dict(sorted(out.items()))

    def vector(
        self,
        table: Mapping[str, Any],
        dotted: str,
        key: str,
        length: int,
        default: Sequence[float] | None = None,
    ) -> tuple[float, ...]:
        """The list of ``length`` numbers ``table[key]``, or ``default`` (required when None)."""
        if key not in table:
            if default is None:
                self.fail(dotted, "missing required key")
            return tuple(float(v) for v in default)
        value = as_list(table[key])
        if not isinstance(value, list) or len(value) != length:
            self.fail(dotted, f"must be a list of {length} numbers, got {describe(table[key])}")
        return tuple(self.scalar(v, f"{dotted}[{i}]") for i, v in enumerate(value))

    def points(
        self,
        table: Mapping[str, Any],
        dotted: str,
        key: str,
        shape: str = "a list of 3 points [[x, y], [x, y], [x, y]]",
        count: int = 3,
    ) -> list[tuple[float, ...]]:
        """The list of ``count`` points ``[x, y]`` ``table[key]``."""
        value = as_list(table[key])
        if not isinstance(value, list) or len(value) != count:
            self.fail(dotted, f"must be {shape}, got {describe(table[key])}")
        return [self.vector({"p": p}, f"{dotted}[{i}]", "p", 2) for i, p in enumerate(value)]


def as_list(value: Any) -> Any:
    """Lists, tuples and numpy arrays become lists; anything else is returned unchanged."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return list(value)
    return value


def describe(value: Any) -> str:
    """Short, one-line description of a value as the user wrote it (TOML spelling)."""
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, str):
        text = json.dumps(value, ensure_ascii=False)
        return text if len(text) <= 40 else text[:36] + '..."'
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, list | tuple | np.ndarray):
        n = len(value)
        return f"a list of {n} item{'s' if n != 1 else ''}"
    if isinstance(value, int | np.integer):
        return _integer(int(value))
    if isinstance(value, Real):
        return repr(float(value))
    return f"a value of type {type(value).__name__}"


def _integer(value: int) -> str:
    """An integer as written, or its first digits and its size when it is too long to show
    (TOML integers have no bound: ``10**400`` is a valid one)."""
    text = repr(value)
    if len(text) <= 24:
        return text
    return f"{text[:12]}... (an integer of {len(text.lstrip('-'))} digits)"


def quoted(words: Sequence[str]) -> str:
    """``"a" or "b"``."""
    return " or ".join(f'"{w}"' for w in words)


def point(p: Sequence[float]) -> str:
    """``(x, y)`` to 6 significant digits."""
    return f"({p[0]:.6g}, {p[1]:.6g})"


def one_line(text: str) -> str:
    """``text`` with its line breaks as spaces."""
    return " ".join(text.splitlines())
