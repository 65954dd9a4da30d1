"""The kinds of argument the hostile battery knows, each with its own oracle.

A :class:`Kind` says what a function's argument must be, independently of rpr3gen's
validation layer: values of the wrong type (to be refused with ``InputTypeError``), bad values
(the function's value error: ``InputError`` unless said), good values, and :meth:`Kind.classify`,
which tells for any value Hypothesis draws whether it is ``"ok"``, of the wrong ``"type"`` or a
bad ``"value"`` (None: the oracle does not know, the example is skipped). The tables of
``test_hostile_api.py`` and ``test_hostile_cli.py`` are rows of these kinds: a new function or
command joins the battery by adding its row.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rpr3gen.errors import InputError

HUGE = 10**12
"""A size beyond any memory limit (10^12 of anything is refused: docs/errors.md, "Sizes")."""


@dataclass(frozen=True)
class Where:
    """A value that needs the test's temporary folder: ``make(tmp)`` builds it."""

    label: str
    make: Callable[[Path], Any]

    def __repr__(self) -> str:
        return self.label


def resolve(value: Any, tmp: Path) -> Any:
    """``value``, or what a :class:`Where` builds in ``tmp``."""
    return value.make(tmp) if isinstance(value, Where) else value


@dataclass(frozen=True)
class Kind:
    """What one argument must be; see the module docstring."""

    label: str
    classify: Callable[[Any], str | None]
    wrong_types: tuple[Any, ...] = ()
    bad_values: tuple[Any, ...] = ()
    good_values: tuple[Any, ...] = ()
    value_error: type[Exception] | tuple[type[Exception], ...] = InputError
    rows: int | None = None  # the array's size per sample (rows and readings)
    one_reading: bool = False


def _is_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def numeric_array(value: Any) -> tuple[str, np.ndarray | None]:
    """("ok", array of float64) for an array of numbers of any shape, or ("type"|"value", None)."""
    if value is None or isinstance(value, str | bytes | Mapping | set | frozenset):
        return "type", None
    try:
        array = np.asarray(value)
    except ValueError:
        return "value", None  # ragged
    except (TypeError, OverflowError):
        return "type", None
    if array.dtype.kind in "iuf":
        return "ok", array.astype(float)
    if array.dtype.kind == "O" and all(_is_number(x) for x in array.flat):
        try:
            return "ok", array.astype(float)
        except OverflowError:
            return "value", None
    return "type", None


WRONG_ARRAYS: tuple[Any, ...] = (
    None,
    "0 0 0",
    {"x": 0.0},
    [["a", "b", "c"]],
    np.array([[True, False, True]]),
    np.zeros((1, 3), dtype=complex),
    [[0.0, None, 0.0]],
    object(),
)


def rows(size: int = 3, *, value_error: type[Exception] = InputError) -> Kind:
    """n samples: ``(n, size)``, or ``(size,)`` for one; NaN allowed (their rows are NaN)."""

    def classify(value: Any) -> str | None:
        verdict, array = numeric_array(value)
        if array is None:
            return verdict
        ok = array.shape == (size,) or (array.ndim == 2 and array.shape[1] == size)
        return "ok" if ok else "value"

    return Kind(
        f"rows({size})",
        classify,
        wrong_types=WRONG_ARRAYS,
        bad_values=(
            np.zeros((2, size - 1)),
            np.zeros((2, size, 1)),
            np.zeros(size + 1),
            np.float64(0.0),
            [[0.0] * size, [0.0] * (size - 1)],
        ),
        value_error=value_error,
        rows=size,
    )


def reading(size: int = 3, *, positive: bool = False, finite: bool = False) -> Kind:
    """One reading, shape ``(size,)`` exactly: ``(2, size)`` is refused, not cut."""

    def classify(value: Any) -> str | None:
        verdict, array = numeric_array(value)
        if array is None:
            return verdict
        if array.shape != (size,):
            return "value"
        if (finite or positive) and not np.isfinite(array).all():
            return "value"
        if positive and not (array > 0).all():
            return "value"
        return "ok"

    bad: tuple[Any, ...] = (np.zeros((2, size)), np.zeros((1, size)), np.zeros(size + 1), 0.5)
    if positive:
        bad += ([-1.0] * size, [math.nan] * size, [math.inf] * size)
    return Kind(
        f"reading({size})",
        classify,
        wrong_types=WRONG_ARRAYS,
        bad_values=bad,
        rows=size,
        one_reading=True,
    )


def count(
    least: int,
    quick: int,
    *,
    most: int | None = None,
    huge_refused: bool = True,
    value_error: type[Exception] = InputError,
) -> Kind:
    """An integer >= ``least`` (``<= most``); ``quick``: the largest the battery runs; with
    ``huge_refused``, 10^12 is beyond the memory limit."""

    def classify(value: Any) -> str | None:
        if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
            return "type"
        if value < least or (most is not None and value > most):
            return "value"
        if huge_refused and value >= HUGE:
            return "value"
        return "ok" if value <= quick else None

    bad = [least - 1, -(2**70)]
    if huge_refused:
        bad += [HUGE, 2**64, 10**30]
    if most is not None:
        bad.append(most + 1)
    return Kind(
        f"count(>= {least})",
        classify,
        wrong_types=("3", float(least), True, None, [least], np.float64(least)),
        bad_values=tuple(bad),
        good_values=(least, np.int64(least)),
        value_error=value_error,
    )


def number(
    *,
    least: float | None = None,
    greater: float | None = None,
    below: float | None = None,
    most: float | None = None,
    finite: bool = True,
    good: tuple[float, ...] = (),
    value_error: type[Exception] = InputError,
) -> Kind:
    """A real number, not bool; NaN never; infinity only when not ``finite``."""

    def fits(x: float) -> bool:
        return not (
            math.isnan(x)
            or (finite and math.isinf(x))
            or (least is not None and not x >= least)
            or (greater is not None and not x > greater)
            or (below is not None and not x < below)
            or (most is not None and not x <= most)
        )

    def classify(value: Any) -> str | None:
        if not _is_number(value):
            return "type"
        try:
            x = float(value)
        except OverflowError:
            return "value"
        return "ok" if fits(x) else "value"

    bad = [math.nan, 10**400]
    if finite:
        bad += [math.inf, -math.inf]
    for bound in (least, greater):
        if bound is not None:
            bad.append(bound - 1.0)
    if below is not None:
        bad.append(below)
    if most is not None:
        bad.append(most * 10)
    return Kind(
        "number",
        classify,
        wrong_types=("1.0", None, True, [1.0], 1j, np.array([1.0, 2.0])),
        bad_values=tuple(bad),
        good_values=good,
        value_error=value_error,
    )


def flag() -> Kind:
    return Kind(
        "flag",
        lambda v: "ok" if isinstance(v, bool | np.bool_) else "type",
        wrong_types=("yes", "False", 1, 0, None, [True]),
        good_values=(True, False, np.True_),
    )


def choice(*choices: str) -> Kind:
    def classify(value: Any) -> str | None:
        if not isinstance(value, str):
            return "type"
        return "ok" if value in choices else "value"

    return Kind(
        f"choice{choices}",
        classify,
        wrong_types=(1, None, b"numpy", [choices[0]]),
        bad_values=("", choices[0].upper() + "x", "gpu"),
        good_values=choices,
    )


def instance(cls: type, *good: Any) -> Kind:
    return Kind(
        cls.__name__,
        lambda v: "ok" if isinstance(v, cls) else "type",
        wrong_types=("paper.toml", None, {}, 5, Path("models/paper.toml")),
        good_values=good,
    )


def optional(kind: Kind) -> Kind:
    return Kind(
        f"optional({kind.label})",
        lambda v: "ok" if v is None else kind.classify(v),
        wrong_types=tuple(v for v in kind.wrong_types if v is not None),
        bad_values=kind.bad_values,
        good_values=(None, *kind.good_values),
        value_error=kind.value_error,
        rows=kind.rows,
        one_reading=kind.one_reading,
    )


def _path_type(value: Any) -> str | None:
    return None if isinstance(value, str | os.PathLike) else "type"


PATH_WRONG_TYPES: tuple[Any, ...] = (5, b"file", ["file"], True)


def input_file(suffix: str, *, value_error: type[Exception], good: Where) -> Kind:
    """A file to read: missing, a folder, unreadable (``/proc/self/mem``: EIO, even for root),
    empty, or an empty name are refused with ``value_error`` (naming the file)."""
    return Kind(
        f"input file {suffix}",
        _path_type,
        wrong_types=PATH_WRONG_TYPES,
        bad_values=(
            Where("missing", lambda tmp: str(tmp / f"missing{suffix}")),
            Where("a folder", lambda tmp: str(tmp)),
            Where("unreadable", lambda tmp: "/proc/self/mem"),
            Where("empty", lambda tmp: str(_written(tmp / f"empty{suffix}", ""))),
            Where("NUL", lambda tmp: "a\0b"),
        ),
        good_values=(good,),
        value_error=(value_error, InputError),  # an empty name or a NUL: not a path at all
    )


def output_path(*, folder: bool) -> Kind:
    """A file (or folder) to write: below a regular file, the other kind of thing, where no
    file can be created (``/proc``), a device, an empty name."""
    bad: list[Any] = [
        Where("below a file", lambda tmp: str(_written(tmp / "blocker", "x") / "out")),
        Where("in /proc", lambda tmp: "/proc/rpr3gen-hostile/out"),
        Where("empty name", lambda tmp: ""),
        Where("NUL", lambda tmp: "a\0b"),
    ]
    if folder:
        bad.append(Where("a file", lambda tmp: str(_written(tmp / "a-file", "x"))))
    else:
        bad += [Where("a folder", lambda tmp: str(tmp)), Where("a device", lambda tmp: "/dev/null")]
    return Kind(f"output {'folder' if folder else 'file'}", _path_type, PATH_WRONG_TYPES,
                tuple(bad))  # fmt: skip


def _written(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@dataclass(frozen=True)
class Api:
    """A row of the API battery: a public function, valid arguments and each argument's kind.

    Attributes:
        name: as in ``rpr3gen.__all__`` (``"Fit.predict"`` for a method).
        call: calls it with keyword arguments.
        good: valid keyword arguments, fast to evaluate (``tmp``: a temporary folder).
        kinds: the kind of each argument the battery varies.
        same_length: groups of array arguments that must have as many rows.
        nan_rows: arrays with a NaN row give a NaN row (else they are refused).
        costly: a call that succeeds takes long (Hypothesis then draws only refused values).
        scene_free: takes no model: runs once (on the paper's scene of the API battery), not
            on every robot.
    """

    name: str
    call: Callable[..., Any]
    good: Callable[[Path], dict[str, Any]]
    kinds: dict[str, Kind]
    same_length: tuple[tuple[str, ...], ...] = ()
    nan_rows: bool = True
    costly: bool = False
    scene_free: bool = False
    notes: str = field(default="", compare=False)

    def __repr__(self) -> str:
        return self.name
