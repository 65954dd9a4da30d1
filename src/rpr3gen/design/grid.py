"""Grids of designs: which model keys a sweep varies, and the designs they enumerate.

A grid file (TOML) sets dotted model keys to their values, a list or a range with a count::

    "geometry.r" = [0.25, 0.3, 0.35]
    "mass.m3" = { start = 2.0, stop = 8.0, num = 4 }     # numpy.linspace: both ends included
    "geometry.alpha_deg[0]" = [80.0, 90.0]               # one element of a list-valued key
    actuation = ["revolute", "prismatic"]

Tables are dotted keys too (``[mass]`` then ``m3 = [...]`` is ``"mass.m3"``). The designs are
every combination, in the order of the keys, the last key fastest (``itertools.product``).

A base model of the general format (any leg type) has its own keys::

    "platform.mass" = [2.0, 4.0]                # platform.inertia, payload.moment
    "legs.A.mass[1]" = [0.5, 1.0]               # one element of a leg's list
    "legs.A.joints[1][0]" = [0.15, 0.2]         # one coordinate of a point (joint 2's x)
    "legs.B.axes[0][1]" = [0.0, 0.1]            # a prismatic joint's axis
    "environment.gravity[1]" = [-9.81, -1.62]   # platform.com[i], payload.force[i]
    "limits.q2[1]" = [0.2, 0.3]                 # a bound the base model's [limits] holds
    actuated = [1, 2]                           # the motors' joint

With ``symmetric = true`` only leg A's keys exist (legs B and C are leg A turned).

A spatial base model (a hexapod or a Delta) has its file's keys, indexed the same way
(``"legs.A.base[2]"``, ``"platform.inertia[0]"``, ``"legs.A.rod_mass"``):
:mod:`rpr3gen.design.spatial_grid`.

Every key and every value is checked before any work: an unknown key (with the close match), a
value that is not a list or a range, or a value that makes the base model invalid is a
:class:`~rpr3gen.errors.GridError` naming the file and the key.
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rpr3gen import sizes
from rpr3gen.design.grid_keys import check_index, get_value, set_value, show, split_key
from rpr3gen.design.spatial_grid import SPATIAL_LIST_DEFAULTS, check_spatial_key, turn_u_axes
from rpr3gen.errors import GridError, ModelError, did_you_mean
from rpr3gen.model import ACTUATIONS, DEFAULT_GRAVITY, MODEL_KEYS, Model, model_from_dict
from rpr3gen.model.general import LEG_KEYS, is_general
from rpr3gen.model.spatial import is_spatial
from rpr3gen.structure import LEGS

__all__ = ["Grid", "read_grid"]

#: Model keys that hold a list, with its shape: vary one element, ``key[i]`` or ``key[i][j]``.
LIST_SHAPES: Mapping[str, tuple[int, ...]] = {
    "geometry.alpha_deg": (3,),
    "geometry.base": (3, 2),
    "geometry.platform": (3, 2),
    "environment.gravity": (2,),
    "payload.force": (2,),
    "limits.stroke": (3, 2),
}
#: The general format's keys that hold a list, with its shape (``L``: a leg).
GENERAL_LIST_SHAPES: Mapping[str, tuple[int, ...]] = {
    "legs.L.joints": (3, 2),
    "legs.L.axes": (3, 2),
    "legs.L.mass": (2,),
    "legs.L.com": (2, 2),
    "legs.L.inertia": (2,),
    "platform.com": (2,),
    "environment.gravity": (2,),
    "payload.force": (2,),
}
#: The general format's keys that hold one number.
GENERAL_SCALARS: tuple[str, ...] = ("platform.mass", "platform.inertia", "payload.moment")
#: Lists a model may leave out, and the value they then have.
_LIST_DEFAULTS: Mapping[str, Any] = {
    "environment.gravity": list(DEFAULT_GRAVITY),
    "payload.force": [0.0, 0.0],
    "platform.com": [0.0, 0.0],
}
#: Model keys that are not design parameters.
_NOT_PARAMETERS = ("name", "leg", "symmetric")
_TEXT_KEYS = ("actuation",)
_INTEGER_KEYS = ("actuated",)
_RANGE_KEYS = ("start", "stop", "num")


@dataclass(frozen=True)
class Grid:
    """The designs of a sweep: the keys varied and the values of each.

    Attributes:
        keys: dotted model keys, as named in the grid (e.g. ``"geometry.r"``,
            ``"geometry.alpha_deg[0]"``), in the grid's order.
        values: per key, its values: floats, or strings for ``actuation``.
        source: the grid's file name (or ``"<grid>"``), for messages.
    """

    keys: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]
    source: str = "<grid>"

    @property
    def shape(self) -> tuple[int, ...]:
        """Values per key."""
        return tuple(len(v) for v in self.values)

    def __len__(self) -> int:
        """Number of designs."""
        return math.prod(self.shape)

    def design(self, index: int) -> tuple[Any, ...]:
        """The values of design ``index`` (0-based, the grid's order), one per key."""
        where = np.unravel_index(index, self.shape)
        return tuple(v[int(k)] for v, k in zip(self.values, where, strict=True))

    def columns(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """The key columns of designs ``start`` to ``stop - 1``: float64, or object (text)."""
        where = np.unravel_index(np.arange(start, stop), self.shape)
        columns = {}
        for key, values, k in zip(self.keys, self.values, where, strict=True):
            kind = object if key in _TEXT_KEYS else np.int64 if key in _INTEGER_KEYS else np.float64
            columns[key] = np.array(values, dtype=kind)[k]
        return columns

    def apply(self, base: Mapping[str, Any], values: Sequence[Any]) -> dict[str, Any]:
        """A copy of the model data ``base`` with the keys set to ``values``."""
        # Tables are copied; leaves are replaced, never changed in place (lists by _set).
        data = {k: dict(v) if isinstance(v, Mapping) else v for k, v in base.items()}
        spatial = is_spatial(base)
        defaults = SPATIAL_LIST_DEFAULTS if spatial else _LIST_DEFAULTS
        for key, value in zip(self.keys, values, strict=True):
            set_value(data, key, value, defaults)
        if spatial:  # a moved leg turns its U (rpr3gen.design.spatial_grid)
            turn_u_axes(data, base, self.keys)
        return data

    def as_dict(self) -> dict[str, list[Any]]:
        """``{key: values}``: the grid as a mapping :func:`read_grid` reads back."""
        return {key: list(values) for key, values in zip(self.keys, self.values, strict=True)}


def read_grid(grid: str | os.PathLike[str] | Mapping[str, Any], base: Mapping[str, Any]) -> Grid:
    """Read and check a grid against the base model data (parsed TOML, see
    :func:`rpr3gen.model.read_model_data`).

    Args:
        grid: a grid file (TOML), or the same content as a mapping.
        base: the base model's data; every value is checked on it, one key at a time.

    Raises:
        GridError: naming the grid and the key at fault.
    """
    if isinstance(grid, Mapping):
        source, data = "<grid>", grid
    else:
        source, data = os.fspath(grid), _read(os.fspath(grid))
    flat: dict[str, Any] = {}
    _flatten(data, "", flat, source)
    if not flat:
        raise GridError(
            f'{source}: no keys; set model keys to values, e.g. "geometry.r" = [0.25, 0.3]'
        )
    keys, values = [], []
    check = (
        check_spatial_key
        if is_spatial(base)
        else _check_general_key
        if is_general(base)
        else _check_key
    )
    for key, given in flat.items():
        check(key, base, source)
        keys.append(key)
        values.append(_values(key, given, source))
    grid_ = Grid(keys=tuple(keys), values=tuple(values), source=source)
    for key, vals in zip(grid_.keys, grid_.values, strict=True):
        for value in vals:
            try:
                data_ = Grid((key,), ((value,),)).apply(base, (value,))
                model_from_dict(data_, source=f"{source}: {key} = {show(value)}")
            except ModelError as exc:
                raise GridError(str(exc)) from None
    return grid_


def design_model(grid: Grid, base: Mapping[str, Any], index: int, source: str) -> Model:
    """The model of design ``index``.

    Raises:
        ModelError: when the combination of values makes an invalid model (each value alone
            was valid, :func:`read_grid` checked that).
    """
    return model_from_dict(grid.apply(base, grid.design(index)), source=source)


def _read(path: str) -> dict[str, Any]:
    try:
        text = Path(path).read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise GridError(f"{path}: grid file not found") from None
    except IsADirectoryError:
        raise GridError(f"{path}: is a directory, not a grid file") from None
    except OSError as exc:
        raise GridError(f"{path}: cannot read grid file: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise GridError(f"{path}: not UTF-8 text (bad byte at offset {exc.start})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise GridError(f"{path}: invalid TOML: {' '.join(str(exc).splitlines())}") from None


def _is_range(value: Any) -> bool:
    return isinstance(value, Mapping) and any(k in value for k in _RANGE_KEYS)


def _flatten(table: Mapping[str, Any], prefix: str, flat: dict[str, Any], source: str) -> None:
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, Mapping) and not _is_range(value):
            if not value:
                raise GridError(f"{source}: {dotted}: an empty table; give values")
            _flatten(value, f"{dotted}.", flat, source)
        elif dotted in flat:
            raise GridError(f"{source}: {dotted}: given twice")
        else:
            flat[dotted] = value


def _check_key(key: str, base: Mapping[str, Any], source: str) -> None:
    name, index = split_key(key)
    if name not in MODEL_KEYS:
        hint = did_you_mean(name, MODEL_KEYS)
        raise GridError(f"{source}: {key}: unknown model key{hint}")
    if name in _NOT_PARAMETERS:
        raise GridError(f"{source}: {key}: not a design parameter")
    shape = LIST_SHAPES.get(name)
    if shape is None:
        if index:
            raise GridError(f"{source}: {key}: {name} holds one value, not a list")
        return
    check_index(key, name, index, shape, source)
    if get_value(base, name) is None and name not in _LIST_DEFAULTS:
        raise GridError(
            f"{source}: {key}: the base model has no {name} to vary; set it in the model file"
        )


def general_keys(base: Mapping[str, Any]) -> tuple[str, ...]:
    """Every key a grid may vary on a base model of the general format (without indices):
    those of :data:`GENERAL_LIST_SHAPES` (leg A's alone with ``symmetric = true``),
    :data:`GENERAL_SCALARS`, ``actuated`` and each ``limits`` key the base model holds."""
    legs = ("A",) if base.get("symmetric") is True else LEGS
    keys = [k.replace("L", leg, 1) for k in GENERAL_LIST_SHAPES if k.startswith("legs.")
            for leg in legs]  # fmt: skip
    keys += [k for k in GENERAL_LIST_SHAPES if not k.startswith("legs.")]
    keys += [*GENERAL_SCALARS, "actuated"]
    limits = base.get("limits")
    if isinstance(limits, Mapping):
        keys += [f"limits.{k}" for k in limits]
    return tuple(keys)


def _general_shape(name: str) -> tuple[int, ...] | None:
    parts = name.split(".")
    if name.startswith("limits."):
        return (2,)
    if len(parts) == 3 and parts[0] == "legs":
        return GENERAL_LIST_SHAPES.get(f"legs.L.{parts[2]}")
    return GENERAL_LIST_SHAPES.get(name)


def _check_general_key(key: str, base: Mapping[str, Any], source: str) -> None:
    name, index = split_key(key)
    if name in _NOT_PARAMETERS:
        raise GridError(f"{source}: {key}: not a design parameter")
    known = general_keys(base)
    if name not in known:
        parts = name.split(".")
        if len(parts) == 3 and parts[0] == "legs" and parts[1] in LEGS and parts[2] in LEG_KEYS:
            raise GridError(
                f"{source}: {key}: with symmetric = true only leg A's keys exist (legs B and C "
                f"are leg A turned by 120 and 240 degrees); vary legs.A.{parts[2]}"
            )
        if parts[0] == "limits" and len(parts) > 1:
            raise GridError(
                f"{source}: {key}: the base model has no {name} to vary; set it in the "
                f"model file's [limits]"
            )
        hint = did_you_mean(name, known)
        raise GridError(f"{source}: {key}: unknown model key{hint}")
    shape = _general_shape(name)
    if shape is None:
        if index:
            raise GridError(f"{source}: {key}: {name} holds one value, not a list")
        return
    check_index(key, name, index, shape, source)
    if name.endswith(".axes"):
        leg = base.get("leg")
        if isinstance(leg, str) and len(leg) == 3 and leg[index[0]] == "R":
            raise GridError(
                f"{source}: {key}: joint {index[0] + 1} of a 3-{leg} is revolute; its axis "
                "is ignored"
            )
    if get_value(base, name) is None and name not in _LIST_DEFAULTS:
        raise GridError(
            f"{source}: {key}: the base model has no {name} to vary; set it in the model file"
        )


def _values(key: str, given: Any, source: str) -> tuple[Any, ...]:
    text = key in _TEXT_KEYS
    if _is_range(given):
        if text or key in _INTEGER_KEYS:
            what = "numbers" if text else "numbers; actuated takes joints 1, 2 or 3"
            raise GridError(f"{source}: {key}: a range needs {what}; give a list of values")
        return _range(key, given, source)
    if not isinstance(given, list):
        raise GridError(
            f"{source}: {key}: must be a list of values or a range "
            f"{{ start = ..., stop = ..., num = ... }}, got {show(given)}"
        )
    if not given:
        raise GridError(f"{source}: {key}: an empty list; give at least one value")
    out: list[Any] = []
    for i, value in enumerate(given):
        if text:
            if not isinstance(value, str):
                raise GridError(f"{source}: {key}[{i}]: must be text, got {show(value)}")
            if value not in ACTUATIONS:
                hint = did_you_mean(value, ACTUATIONS)
                raise GridError(
                    f"{source}: {key}[{i}]: must be one of {', '.join(ACTUATIONS)}, "
                    f"got {show(value)}{hint}"
                )
            out.append(value)
        elif key in _INTEGER_KEYS:
            if isinstance(value, bool) or value not in (1, 2, 3):
                raise GridError(
                    f"{source}: {key}[{i}]: must be the joint 1, 2 or 3, got {show(value)}"
                )
            out.append(int(value))
        else:
            out.append(_number(f"{key}[{i}]", value, source))
    return tuple(out)


def _range(key: str, given: Mapping[str, Any], source: str) -> tuple[float, ...]:
    for name in given:
        if name not in _RANGE_KEYS:
            hint = did_you_mean(str(name), _RANGE_KEYS)
            raise GridError(f"{source}: {key}: unknown range key {name!r}{hint}")
    missing = [name for name in _RANGE_KEYS if name not in given]
    if missing:
        raise GridError(
            f"{source}: {key}: a range needs start, stop and num; missing {', '.join(missing)}"
        )
    start = _number(f"{key}.start", given["start"], source)
    stop = _number(f"{key}.stop", given["stop"], source)
    num = given["num"]
    if isinstance(num, bool) or not isinstance(num, int) or num < 1:
        raise GridError(f"{source}: {key}.num: must be an integer >= 1, got {show(num)}")
    sizes.check(f"{source}: {key}.num", num, lambda n: n * sizes.DESIGN_ROW,
                "the grid's designs", least=1, error=GridError)  # fmt: skip
    return tuple(float(v) for v in np.linspace(start, stop, num))


def _number(where: str, value: Any, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise GridError(f"{source}: {where}: must be a number, got {show(value)}")
    try:
        number = float(value)
    except OverflowError:  # a TOML integer beyond float64
        number = math.inf
    if not math.isfinite(number):
        raise GridError(f"{source}: {where}: must be a finite number, got {show(value)}")
    return number
