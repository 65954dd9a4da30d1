"""The validation layer of the Python API: each argument's type and shape, checked once, by name.

Every public function declares what each of its arguments must be with :func:`checked`::

    @checked(q=Rows(3), qd=Rows(3), qdd=Rows(3), same_length=[("q", "qd", "qdd")])
    def inverse_dynamics(model, q, qd, qdd, backend="numpy", progress=False, threads=None): ...

and receives them converted (arrays as C-contiguous float64, integers as ``int``, numbers as
``float``). Arguments with a common meaning (``model``, ``backend``, ``threads``...) have their
check in :data:`COMMON`; a function with an argument that has none fails at import. A failure is
one line that starts with the argument's name, raised as:

- :class:`~rpr3gen.errors.InputTypeError` (a ``TypeError``) for a wrong type: a string where a
  number belongs, ``True`` where a count belongs, an array of text;
- :class:`~rpr3gen.errors.InputError` (a ``ValueError``) for a bad value or shape: a count
  below its least value or beyond the memory limit (:mod:`rpr3gen.sizes`), a number not
  finite, an array of shape (2, 2) where (n, 3) belongs, arrays of different lengths.

Batches: :class:`Rows` takes ``(n, size)`` (or ``(size,)``, one sample) where a function is
documented to take n samples; :class:`Reading` takes exactly ``(size,)``, one reading, and
refuses ``(2, size)`` rather than use its first row. NaN and infinity in :class:`Rows` are the
caller's to give (their rows come back NaN); elsewhere numbers must be finite unless said.
"""

from __future__ import annotations

import functools
import inspect
import math
import os
from collections.abc import Callable, Mapping, Sequence
from numbers import Integral
from numbers import Real as _Real
from typing import Any, TypeVar

import numpy as np

from rpr3gen import sizes
from rpr3gen.errors import InputError, InputTypeError, Rpr3genError, did_you_mean
from rpr3gen.evaluators import BACKENDS

__all__ = [
    "COMMON",
    "Check",
    "Choice",
    "Flag",
    "Instance",
    "Integer",
    "Number",
    "Optional",
    "PathArg",
    "PoseRows",
    "Reading",
    "Rows",
    "Sample",
    "check_same_length",
    "checked",
    "describe",
    "match_width",
    "numbers",
]

F = TypeVar("F", bound=Callable[..., Any])


def describe(value: Any) -> str:
    """A short description of a value for a message: ``'301' (str)``, ``an array (2, 3)``."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} ({value.dtype})"
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{text} ({type(value).__name__})"


def _type_error(name: str, expected: str, value: Any) -> InputTypeError:
    return InputTypeError(f"{name}: must be {expected}, got {describe(value)}", argument=name)


def _value_error(name: str, message: str, error: type[Rpr3genError] = InputError) -> Rpr3genError:
    return error(f"{name}: {message}", argument=name)


class Check:
    """What one argument must be: called with its name and value, returns it converted."""

    def __call__(self, name: str, value: Any) -> Any:  # pragma: no cover - interface
        raise NotImplementedError


class Integer(Check):
    """An ``int`` (or NumPy integer; not ``bool``, not ``3.0``) in ``[least, most]``.

    ``cost``: bytes the value makes the function allocate (:func:`rpr3gen.sizes.check`),
    described by ``what``. ``error``: the class of a bad value's error.
    """

    def __init__(
        self,
        least: int | None = None,
        most: int | None = None,
        *,
        cost: Callable[[int], float] | None = None,
        what: str = "",
        error: type[Rpr3genError] = InputError,
    ) -> None:
        self.least, self.most, self.cost, self.what = least, most, cost, what
        self.error = error

    def expected(self) -> str:
        if self.least is not None and self.most is not None:
            return f"an integer from {self.least} to {self.most}"
        if self.least is not None:
            return f"an integer >= {self.least}"
        return "an integer"

    def __call__(self, name: str, value: Any) -> int:
        if isinstance(value, bool | np.bool_) or not isinstance(value, Integral):
            raise _type_error(name, self.expected(), value)
        number = int(value)
        if (self.least is not None and number < self.least) or (
            self.most is not None and number > self.most
        ):
            raise _value_error(name, f"must be {self.expected()}, got {number}", self.error)
        if self.cost is not None:
            sizes.check(name, number, self.cost, self.what, least=self.least or 0,
                        argument=name, error=self.error)  # fmt: skip
        return number


class Number(Check):
    """A real number (``int``, ``float`` or NumPy's; not ``bool``) as a ``float``.

    Args:
        finite: refuse infinity (NaN is always refused).
        least, most: closed bounds; ``greater``, ``below``: open bounds.
        unit: said after the number in messages (``"s"``).
        error: the class of a bad value's error.
    """

    def __init__(
        self,
        *,
        finite: bool = True,
        least: float | None = None,
        most: float | None = None,
        greater: float | None = None,
        below: float | None = None,
        unit: str = "",
        error: type[Rpr3genError] = InputError,
    ) -> None:
        self.finite, self.unit, self.error = finite, unit, error
        self.least, self.most, self.greater, self.below = least, most, greater, below

    def expected(self) -> str:
        low = self.least if self.least is not None else self.greater
        high = self.most if self.most is not None else self.below
        bounded = low is not None and high is not None
        parts = ["a finite number" if self.finite and not bounded else "a number"]
        if bounded:
            left = "[" if self.least is not None else "("
            right = "]" if self.most is not None else ")"
            parts.append(f"in {left}{low:g}, {high:g}{right}")
        else:
            parts += [f"{op} {bound:g}" for op, bound in (
                (">=", self.least), (">", self.greater), ("<=", self.most), ("<", self.below)
            ) if bound is not None]  # fmt: skip
        if self.unit:
            parts.append(f"({self.unit})")
        return " ".join(parts)

    def __call__(self, name: str, value: Any) -> float:
        if isinstance(value, bool | np.bool_) or not isinstance(value, _Real):
            raise _type_error(name, self.expected(), value)
        try:
            number = float(value)
        except OverflowError:  # an integer beyond float64
            message = f"must be {self.expected()}, got {value!r}"
            raise _value_error(name, message, self.error) from None
        bad = math.isnan(number) or (self.finite and math.isinf(number))
        bad = bad or (self.least is not None and not number >= self.least)
        bad = bad or (self.most is not None and not number <= self.most)
        bad = bad or (self.greater is not None and not number > self.greater)
        bad = bad or (self.below is not None and not number < self.below)
        if bad:
            raise _value_error(name, f"must be {self.expected()}, got {value!r}", self.error)
        return number


class Flag(Check):
    """``True`` or ``False`` (or a NumPy bool); not ``"yes"``, not ``1``."""

    def __call__(self, name: str, value: Any) -> bool:
        if not isinstance(value, bool | np.bool_):
            raise _type_error(name, "True or False", value)
        return bool(value)


class Choice(Check):
    """One of the strings ``choices``; a close miss gets a "did you mean"."""

    def __init__(self, choices: Sequence[str]) -> None:
        self.choices = tuple(choices)

    def __call__(self, name: str, value: Any) -> str:
        listed = ", ".join(repr(c) for c in self.choices)
        if not isinstance(value, str):
            raise _type_error(name, f"one of {listed}", value)
        if value not in self.choices:
            hint = did_you_mean(value, self.choices)
            raise _value_error(name, f"unknown {name} {value!r}; choose one of {listed}{hint}")
        return value


class Instance(Check):
    """An instance of ``cls``, described as ``what`` in messages."""

    def __init__(self, cls: type | Callable[[], type], what: str) -> None:
        self._cls, self.what = cls, what

    def __call__(self, name: str, value: Any) -> Any:
        cls = self._cls if isinstance(self._cls, type) else self._cls()
        if not isinstance(value, cls):
            raise _type_error(name, self.what, value)
        return value


class Optional(Check):
    """None, or what ``check`` accepts."""

    def __init__(self, check: Check) -> None:
        self.check = check

    def __call__(self, name: str, value: Any) -> Any:
        return None if value is None else self.check(name, value)


class PathArg(Check):
    """A file or folder name: ``str`` or ``os.PathLike``, not empty, no NUL byte."""

    def __call__(self, name: str, value: Any) -> str:
        if not isinstance(value, str | os.PathLike):
            raise _type_error(name, "a path (str or os.PathLike)", value)
        try:
            text = os.fspath(value)
        except TypeError:  # a PathLike whose __fspath__ returns neither str nor bytes
            raise _type_error(name, "a path (str or os.PathLike)", value) from None
        if isinstance(text, bytes):
            raise _type_error(name, "a path as text (str or os.PathLike of str)", value)
        if not text:
            raise _value_error(name, "must name a file or folder, got an empty path")
        if "\0" in text:
            raise _value_error(name, f"a path cannot hold a NUL character, got {text!r}")
        return text


def numbers(name: str, value: Any, error: type[Rpr3genError] = InputError) -> np.ndarray:
    """``value`` as a float64 array, or the error of a value that is not numbers
    (``InputTypeError``; ``error`` for a ragged sequence or a number beyond float64)."""
    expected = "an array of numbers"
    if value is None or isinstance(value, str | bytes | Mapping | set | frozenset):
        raise _type_error(name, expected, value)
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        raise _type_error(name, "an array of numbers without masked values", value)
    try:
        array = np.asarray(value)
    except ValueError:  # ragged nested sequences
        message = "must be a regular array of numbers (rows of one length)"
        raise _value_error(name, message, error) from None
    except (TypeError, OverflowError, RecursionError):
        raise _type_error(name, expected, value) from None
    if array.dtype != np.float64 or not array.flags.c_contiguous:  # copied below, or later
        sizes.check(name, array.size, lambda k: k * 8, "a float64 copy of it", unit="values",
                    argument=name, error=error)  # fmt: skip
    kind = array.dtype.kind
    if kind in "iuf":
        return np.asarray(array, dtype=np.float64)
    if kind == "O" and all(
        isinstance(x, _Real) and not isinstance(x, bool | np.bool_) for x in array.flat
    ):
        try:
            return array.astype(np.float64)
        except OverflowError:
            raise _value_error(name, "holds a number beyond float64's range", error) from None
    raise InputTypeError(
        f"{name}: must be {expected}, got {describe(value)} holding {array.dtype} values",
        argument=name,
    )


class Rows(Check):
    """n samples of ``size`` numbers: ``(n, size)``, or ``(size,)`` for one sample (then
    ``(1, size)``). NaN and infinity pass (those rows come back NaN) unless ``finite``."""

    def __init__(self, size: int, *, finite: bool = False) -> None:
        self.size, self.finite = size, finite

    def __call__(self, name: str, value: Any) -> np.ndarray:
        array = numbers(name, value)
        if array.shape == (self.size,):
            array = array[np.newaxis, :]
        if array.ndim != 2 or array.shape[1] != self.size:
            raise _value_error(
                name,
                f"must have shape (n, {self.size}) (or ({self.size},) for one sample), "
                f"got {array.shape}",
            )
        if self.finite and not np.isfinite(array).all():
            row = int(np.flatnonzero(~np.isfinite(array).all(axis=1))[0])
            raise _value_error(name, f"row {row + 1}: a value is not finite")
        return np.ascontiguousarray(array)


class PoseRows(Check):
    """Rows of a platform quantity whose width is the model's (3: planar robots and Deltas;
    6: hexapods): ``(n, 3)`` or ``(n, 6)`` here, matched to the model by :func:`match_width`."""

    WIDTHS = (3, 6)

    def __init__(self, *, finite: bool = False) -> None:
        self.finite = finite

    def __call__(self, name: str, value: Any) -> np.ndarray:
        array = numbers(name, value)
        width = array.shape[-1] if array.ndim in (1, 2) else None
        if width not in self.WIDTHS:
            raise _value_error(
                name,
                "must have shape (n, 3) or (n, 6) (or (3,) or (6,) for one sample), got "
                f"{array.shape}",
            )
        return Rows(int(width), finite=self.finite)(name, array)


def match_width(width: int, title: str, **arrays: np.ndarray) -> None:
    """Refuse arrays of :class:`PoseRows` whose width is not the model's ``width``."""
    for name, array in arrays.items():
        if array.shape[1] != width:
            raise _value_error(
                name,
                f"must have shape (n, {width}) (or ({width},) for one sample) for the {title}, "
                f"got (n, {array.shape[1]})",
            )


class Reading(Check):
    """One reading of ``size`` numbers, shape ``(size,)`` exactly: ``(2, size)`` is refused, not
    cut to its first row (``size`` None: any length, matched to the model by the caller).
    ``finite``: no NaN or infinity; ``positive``: every value > 0."""

    def __init__(self, size: int | None, *, finite: bool = False, positive: bool = False) -> None:
        self.size, self.finite, self.positive = size, finite, positive

    def __call__(self, name: str, value: Any) -> np.ndarray:
        array = numbers(name, value)
        if self.size is None and array.ndim == 1:
            pass  # any length: the caller matches it to the model
        elif array.shape != (self.size,):
            several = "; several readings take one call each" if array.ndim == 2 else ""
            raise _value_error(name, f"must have shape ({self.size},), got {array.shape}{several}")
        if (self.finite or self.positive) and not np.isfinite(array).all():
            raise _value_error(name, f"must be finite, got {array.tolist()}")
        if self.positive and not (array > 0).all():
            raise _value_error(name, f"must be positive, got {array.tolist()}")
        return np.ascontiguousarray(array)


class Sample(Check):
    """The samples' times or weights: ``(n,)`` numbers (n checked by ``same_length``)."""

    def __init__(self, *, finite: bool = True) -> None:
        self.finite = finite

    def __call__(self, name: str, value: Any) -> np.ndarray:
        array = numbers(name, value)
        if array.ndim != 1:
            raise _value_error(name, f"must have shape (n,), got {array.shape}")
        if self.finite and not np.isfinite(array).all():
            k = int(np.flatnonzero(~np.isfinite(array))[0])
            raise _value_error(name, f"entry {k + 1} is not finite: {array[k]!r}")
        return np.ascontiguousarray(array)


def check_same_length(arrays: Mapping[str, np.ndarray], label: str = "") -> None:
    """Refuse arrays (already checked) whose first dimensions differ, naming each with its
    length: ``q, qd: must have the same number of samples, got q 2, qd 3`` (after ``label:``,
    the argument that holds them, when given)."""
    lengths = {name: len(a) for name, a in arrays.items() if a is not None}
    if len(set(lengths.values())) > 1:
        names = ", ".join(lengths)
        given = ", ".join(f"{name} {n}" for name, n in lengths.items())
        first = next(iter(lengths))
        odd = next(n for n in lengths if lengths[n] != lengths[first])
        where = f"{label}: " if label else ""
        raise InputError(
            f"{where}{names}: must have the same number of samples, got {given}",
            argument=label or odd,
        )


COMMON: dict[str, Check] = {
    "backend": Choice(BACKENDS),
    "progress": Flag(),
    "threads": Optional(Integer(1, cost=lambda n: n * sizes.THREAD, what="the threads' stacks")),
    "identical_legs": Flag(),
    "friction": Flag(),
    "min_conditioning": Number(least=0.0, below=1.0),
}
"""Checks of the arguments that mean the same in every function. The model package, above this
module, adds ``model`` (:class:`rpr3gen.model.IsModel`) when it is imported: every module with a
function that takes a ``model`` imports it first."""


def checked(
    table: Mapping[str, Check] | None = None,
    /,
    *,
    same_length: Sequence[Sequence[str]] = (),
    **checks: Check,
) -> Callable[[F], F]:
    """Decorate a public function so that each argument given is checked by name first.

    Args:
        table: checks by argument name, for a function with many (``**checks`` adds to it).
        same_length: groups of array arguments that must have as many samples (an
            argument not given, or None, is left out).
        **checks: the check of each argument not in :data:`COMMON` (or to override it).

    Raises:
        TypeError: at decoration, when an argument has no check.
    """

    checks = {**(table or {}), **checks}

    def decorate(function: F) -> F:
        signature = inspect.signature(function)
        parameters = list(signature.parameters.values())
        skip = 1 if parameters and parameters[0].name in ("self", "cls") else 0
        names = [p.name for p in parameters[skip:]]
        found = {name: checks.get(name) or COMMON.get(name) for name in names}
        missing = [name for name, check in found.items() if check is None]
        if missing:
            hint = " (import rpr3gen.model first)" if "model" in missing else ""
            raise TypeError(f"{function.__qualname__}: no check for {', '.join(missing)}{hint}")
        table: dict[str, Check] = {n: c for n, c in found.items() if c is not None}
        positional = [
            p.name
            for p in parameters[skip:]
            if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
        ]
        required = {p.name for p in parameters[skip:] if p.default is p.empty}
        label = function.__qualname__

        @functools.wraps(function)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            # Inlined binding (inspect's bind costs microseconds a call); anything unusual
            # goes to inspect for its message.
            given = dict(zip(positional, args[skip:], strict=False))
            if (
                len(args) - skip > len(positional)
                or not given.keys().isdisjoint(kwargs)
                or not all(name in table for name in kwargs)
                or not required <= given.keys() | kwargs.keys()
            ):
                try:
                    signature.bind(*args, **kwargs)
                except TypeError as exc:
                    raise InputTypeError(f"{label}: {exc}") from None
            given.update(kwargs)
            for name, value in given.items():
                given[name] = table[name](name, value)
            for group in same_length:
                check_same_length({n: given[n] for n in group if given.get(n) is not None})
            converted = [given[name] for name in positional[: len(args) - skip]]
            return function(*args[:skip], *converted, **{name: given[name] for name in kwargs})

        wrapper.checks = table  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate
