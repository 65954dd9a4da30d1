"""The checks of a :class:`rpr3gen.Model` built directly (``Model(name, actuation, params, ...)``
or ``dataclasses.replace``): each field's type and value, and its generated folder.

A model read from a file is checked key by key first (:mod:`rpr3gen.model.paper`,
:mod:`rpr3gen.model.general`); these checks make a model built in code just as safe: a wrong
type is an :class:`~rpr3gen.errors.InputTypeError`, a bad value a
:class:`~rpr3gen.errors.ModelError` naming the field, and a generated folder that is damaged or
of another version a :class:`~rpr3gen.errors.GeneratedCodeError` (:mod:`rpr3gen.loader`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from numbers import Real
from typing import Any

import numpy as np

from rpr3gen.errors import InputTypeError, ModelError, did_you_mean
from rpr3gen.loader import check_folder
from rpr3gen.structure import Structure
from rpr3gen.validation import PathArg, describe

__all__ = ["check_fields"]


def check_fields(model: Any, actuations: Sequence[str]) -> dict:
    """The fields of ``model`` checked and converted: its ``structure`` (the paper's of its
    ``actuation`` when it has none or a paper one), ``params`` as floats in the order of the
    structure's parameter names, ``stroke`` as float pairs, ``limits`` as float pairs by joint
    coordinate (``"A.q2"``), ``generated`` as a checked folder name."""
    source = model.source if isinstance(model.source, str) else "<model>"
    if not isinstance(model.source, str):
        raise InputTypeError(f"source: must be a str, got {describe(model.source)}")
    if not isinstance(model.name, str):
        raise InputTypeError(f"{source}: name: must be a str, got {describe(model.name)}")
    choices = " or ".join(f'"{a}"' for a in actuations)
    if not isinstance(model.actuation, str):
        raise InputTypeError(f"{source}: actuation: must be {choices}, got "
                             f"{describe(model.actuation)}")  # fmt: skip
    structure = model.structure
    if structure is not None and not isinstance(structure, Structure):
        raise InputTypeError(f"{source}: structure: must be a Structure, got {describe(structure)}")
    if structure is None or structure.paper:
        # The paper's format: its actuation picks the variant (replacing it switches it).
        if model.actuation not in actuations:
            raise ModelError(
                f"{source}: actuation: must be {choices}, got {describe(model.actuation)}"
            )
        structure = Structure.of_variant(model.actuation)
    elif model.actuation != structure.actuation:
        raise ModelError(
            f"{source}: actuation: a {structure.title} has {structure.actuation} motors, not "
            f"{describe(model.actuation)}"
        )
    param_names = structure.param_names()
    # Built by hand without a structure, a general model's params are not the paper's.
    hint = "; structure=None means the paper's format" if model.structure is None else ""
    params = _params(model.params, source, param_names, hint)
    stroke = None if model.stroke is None else _stroke(model.stroke, source)
    limits = None if model.limits is None else _limits(model.limits, source, structure)
    generated = None
    if model.generated is not None:
        generated = PathArg()("generated", model.generated)
        check_folder(structure.variant, generated, tuple(param_names))
    return {
        "structure": structure,
        "params": params,
        "stroke": stroke,
        "limits": limits,
        "generated": generated,
    }


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool | np.bool_) or not isinstance(value, Real):
        raise InputTypeError(f"{where}: must be a number, got {describe(value)}")
    try:
        number = float(value)
    except OverflowError:  # an integer beyond float64
        raise ModelError(f"{where}: must be a finite number, got {describe(value)}") from None
    if not math.isfinite(number):
        raise ModelError(f"{where}: must be a finite number, got {number!r}")
    return number


def _params(params: Any, source: str, names: Sequence[str], hint: str = "") -> dict[str, float]:
    if not isinstance(params, Mapping):
        raise InputTypeError(f"{source}: params: must be a mapping name -> number, got "
                             f"{describe(params)}")  # fmt: skip
    if set(params) != set(names):
        missing = [n for n in names if n not in params]
        extra = sorted(map(str, set(params) - set(names)))
        raise ModelError(
            f"{source}: params: missing {_some(missing)}, unexpected {_some(extra)}{hint}"
        )
    return {n: _number(params[n], f"{source}: params[{n!r}]") for n in names}


def _some(names: Sequence[str], shown: int = 6) -> str:
    """A list of names for a message: the first few, and how many more."""
    if len(names) <= shown:
        return repr(list(names))
    return f"{list(names[:shown])!r} and {len(names) - shown} more"


def _stroke(stroke: Any, source: str) -> tuple[tuple[float, float], ...]:
    shape = "three pairs (lo, hi) of legs A, B, C (m)"
    if isinstance(stroke, str) or not isinstance(stroke, Sequence | np.ndarray):
        raise InputTypeError(f"{source}: stroke: must be {shape}, got {describe(stroke)}")
    pairs = list(stroke)
    if len(pairs) != 3 or any(
        isinstance(p, str) or not isinstance(p, Sequence | np.ndarray) or len(p) != 2 for p in pairs
    ):
        raise ModelError(f"{source}: stroke: must be {shape}, got {describe(stroke)}")
    out = []
    for k, (lo, hi) in enumerate(pairs):
        lo_, hi_ = (_number(v, f"{source}: stroke[{k}]") for v in (lo, hi))
        if not lo_ < hi_:
            raise ModelError(f"{source}: stroke[{k}]: the lower bound must be below the upper, "
                             f"got ({lo_:g}, {hi_:g})")  # fmt: skip
        out.append((lo_, hi_))
    return tuple(out)


def _limits(limits: Any, source: str, structure: Structure) -> dict[str, tuple[float, float]]:
    """The general format's joint-coordinate bounds ``{"A.q2": (lo, hi), ...}`` (the paper's
    bounds its pistons with ``stroke``, not these)."""
    shape = 'a mapping "A.q2" -> (lo, hi) of joint coordinates (m or rad)'
    if not isinstance(limits, Mapping):
        raise InputTypeError(f"{source}: limits: must be {shape}, got {describe(limits)}")
    if structure.paper and limits:
        raise ModelError(
            f"{source}: limits: the paper's format bounds its pistons with stroke, not limits"
        )
    names = [f"{leg}.{q}" for leg in structure.legs for q in structure.limited_coordinates()]
    out = {}
    for key, pair in limits.items():
        if key not in names:
            hint = did_you_mean(str(key), names)
            raise ModelError(f"{source}: limits[{key!r}]: unknown joint coordinate{hint} "
                             f'("{names[0]}" to "{names[-1]}")')  # fmt: skip
        where = f"{source}: limits[{key!r}]"
        if isinstance(pair, str) or not isinstance(pair, Sequence | np.ndarray) or len(pair) != 2:
            raise ModelError(f"{where}: must be a pair (lo, hi), got {describe(pair)}")
        lo, hi = (_number(v, where) for v in pair)
        if not lo < hi:
            raise ModelError(f"{where}: the lower bound must be below the upper, "
                             f"got ({lo:g}, {hi:g})")  # fmt: skip
        out[key] = (lo, hi)
    return out
