"""Dotted model keys as a grid names them: split, checked, read and set in a model's data.

A grid key is a dotted path into the model file's tables (``"platform.mass"``, ``"legs.A.base"``)
with, for a list-valued key, the index of one element (``"legs.A.base[2]"``,
``"legs.A.inertia[1][0]"``). A ``[limits]`` key keeps its dot (``"limits.A.q2"``). These helpers
serve every model format's grid (:mod:`rpr3gen.design.grid`, :mod:`rpr3gen.design.spatial_grid`).
"""

from __future__ import annotations

import copy
import re
from collections.abc import Mapping
from typing import Any

from rpr3gen.errors import GridError

__all__ = ["check_index", "get_value", "key_path", "set_value", "show", "split_key"]

_KEY = re.compile(r"^(?P<key>[A-Za-z_][A-Za-z0-9_.]*?)(?P<index>(\[\d+\])*)$")


def split_key(key: str) -> tuple[str, tuple[int, ...]]:
    """``"geometry.base[1][0]"`` -> ``("geometry.base", (1, 0))``."""
    found = _KEY.match(key)
    if found is None:
        return key, ()
    index = tuple(int(i) for i in re.findall(r"\[(\d+)\]", found["index"]))
    return found["key"], index


def check_index(
    key: str, name: str, index: tuple[int, ...], shape: tuple[int, ...], source: str
) -> None:
    """The index of ``key`` (``name`` and ``index`` split) addresses one element of a list of
    ``shape``.

    Raises:
        GridError: no index or too few (vary one element), or an index out of range.
    """
    if len(index) != len(shape):
        example = name + "".join("[0]" for _ in shape)
        raise GridError(f'{source}: {key}: {name} holds a list; vary one element, e.g. "{example}"')
    for i, n in zip(index, shape, strict=True):
        if i >= n:
            raise GridError(f"{source}: {key}: index {i} out of range (0 to {n - 1})")


def show(value: Any) -> str:
    """A value of a grid file as a message shows it (TOML's spelling, long numbers cut)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    text = repr(value)  # a TOML integer may have hundreds of digits
    return text if len(text) <= 40 else f"{text[:37]}..."


def key_path(name: str) -> list[str]:
    """The tables and the key of a dotted model key: ``"legs.A.mass"`` -> ``["legs", "A",
    "mass"]``; a ``[limits]`` key keeps its dot (``"limits.A.q2"`` -> ``["limits", "A.q2"]``)."""
    if name.startswith("limits."):
        return ["limits", name[len("limits.") :]]
    return name.split(".")


def get_value(data: Mapping[str, Any], name: str) -> Any:
    """The value of the dotted key ``name`` (no index) in ``data``, or None."""
    inner: Any = data
    for part in key_path(name):
        if not isinstance(inner, Mapping):
            return None
        inner = inner.get(part)
    return inner


def set_value(
    data: dict[str, Any], key: str, value: Any, defaults: Mapping[str, Any] | None = None
) -> None:
    """Set ``key`` (with its index, if any) to ``value`` in ``data``, in place.

    The tables on the way and the list changed are copied first: what ``data`` shares with
    another model's data is never changed. A list the data leaves out takes its value in
    ``defaults`` (by key name) before its element is set.
    """
    name, index = split_key(key)
    *tables, leaf = key_path(name)
    inner = data
    for table in tables:  # copied on the way: the base model's tables are never changed
        child = inner.get(table)
        inner[table] = dict(child) if isinstance(child, Mapping) else {}
        inner = inner[table]
    if not index:
        inner[leaf] = value
        return
    current = inner.get(leaf)
    if current is None:
        current = copy.deepcopy((defaults or {})[name])
    current = copy.deepcopy(list(current))
    inner[leaf] = current
    for i in index[:-1]:
        current[i] = list(current[i])
        current = current[i]
    current[index[-1]] = value
