"""Grid keys of a spatial base model (a hexapod or a Delta, docs/spatial-robots.md): which keys
a grid may vary, their shapes, and the U joints that turn with a moved leg.

The keys are the model file's, with an index for each element of a vector or a list of vectors
(a grid value is always one number)::

    "platform.mass" = [0.5, 1.0]            # one number
    "platform.com[2]" = [-0.02, 0.0]        # z of a point; platform.inertia[k], k in 0..5
    "legs.A.base[1]" = [-0.2, -0.25]        # y of leg A's joint 1 point
    "legs.A.inertia[0][3]" = [0.0, 0.001]   # Ixy of the leg's body 1
    "legs.A.rod_mass" = [0.1, 0.2]          # a Delta's rods (width, rod_com, rod_inertia too)
    "environment.gravity[2]" = [-9.81, -1.62]   # payload.force[i], payload.moment[i]
    "limits.q2[1]" = [0.4, 0.5]             # a bound of a [limits] key the base model holds

With ``symmetric = true`` only the legs the file gives exist (a Delta's leg A, a hexapod's legs
A and B); the others are turned from them. ``name``, ``leg``, ``actuated`` (fixed by the leg
type) and ``symmetric`` are not design parameters.

**The U joints.** The leg or rod after a U must be perpendicular to the U's second axis at home
(docs/spatial-robots.md). A design that moves a U's leg (UPS: ``base`` or ``platform``; RUS,
PUS: ``elbow`` or ``platform``) and leaves that leg's ``u_axes`` alone turns the second axis
with the leg: ``u_axes[1] = s unit(u_axes[0] x leg)``, ``s`` the sign it has in the base model,
so that the U stays a Cardan joint holding its leg; ``u_axes[0]`` stays
(:func:`turn_u_axes`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from rpr3gen.design.grid_keys import check_index, split_key
from rpr3gen.errors import GridError, did_you_mean
from rpr3gen.model.spatial import DEFAULT_GRAVITY_3D, LEG_KEYS
from rpr3gen.structure import SPATIAL_LEG_TYPES

__all__ = [
    "SPATIAL_LIST_DEFAULTS",
    "check_spatial_key",
    "spatial_keys",
    "template_legs",
    "turn_u_axes",
]

#: Lists a spatial model may leave out, and the value they then have.
SPATIAL_LIST_DEFAULTS: Mapping[str, Any] = {
    "environment.gravity": list(DEFAULT_GRAVITY_3D),
    "payload.force": [0.0, 0.0, 0.0],
    "payload.moment": [0.0, 0.0, 0.0],
}
#: The keys of the whole robot, with their shapes (``()``: one number).
_ROBOT_SHAPES: Mapping[str, tuple[int, ...]] = {
    "platform.mass": (),
    "platform.com": (3,),
    "platform.inertia": (6,),
    "environment.gravity": (3,),
    "payload.force": (3,),
    "payload.moment": (3,),
}
_NOT_PARAMETERS = ("name", "leg", "symmetric")
_ALL_LEG_KEYS = tuple(dict.fromkeys(k for keys in LEG_KEYS.values() for k in keys))


def _leg_shapes(kind: str) -> dict[str, tuple[int, ...]]:
    """A leg's keys of the leg type ``kind`` and their shapes."""
    bodies = 1 if kind.endswith("SS2") else 2
    every: dict[str, tuple[int, ...]] = {
        "base": (3,),
        "axis": (3,),
        "u_axes": (2, 3),
        "elbow": (3,),
        "platform": (3,),
        "bar": (3,),
        "mass": (bodies,),
        "com": (bodies, 3),
        "inertia": (bodies, 6),
        "width": (),
        "rod_mass": (),
        "rod_com": (),
        "rod_inertia": (),
    }
    return {key: every[key] for key in LEG_KEYS[kind]}


def template_legs(base: Mapping[str, Any]) -> tuple[str, ...]:
    """The legs a spatial model file gives: every leg, or with ``symmetric = true`` a Delta's
    leg A and a hexapod's legs A and B (the others are turned from them)."""
    letters = SPATIAL_LEG_TYPES[base["leg"]][0]
    if base.get("symmetric") is not True:
        return tuple(letters)
    return tuple(letters[:2] if len(letters) == 6 else letters[:1])


def spatial_keys(base: Mapping[str, Any]) -> dict[str, tuple[int, ...]]:
    """Every key a grid may vary on the spatial base model ``base`` (without indices), with
    its shape: each given leg's keys (:func:`template_legs`), the platform's, gravity, the
    payload, and a bound of each ``[limits]`` key the base model holds."""
    shapes = _leg_shapes(base["leg"])
    keys = {f"legs.{leg}.{k}": s for leg in template_legs(base) for k, s in shapes.items()}
    keys.update(_ROBOT_SHAPES)
    limits = base.get("limits")
    if isinstance(limits, Mapping):
        keys.update({f"limits.{k}": (2,) for k in limits})
    return keys


def check_spatial_key(key: str, base: Mapping[str, Any], source: str) -> None:
    """Check one grid key against the spatial base model ``base`` (valid, parsed TOML).

    Raises:
        GridError: naming ``source`` and ``key``: not a design parameter, a leg that symmetry
            turns, a key of another leg type, an unknown key (with the close match), an index
            that does not address one element.
    """
    name, index = split_key(key)
    kind = base["leg"]
    if name in _NOT_PARAMETERS:
        raise GridError(f"{source}: {key}: not a design parameter")
    if name == "actuated":
        joint = SPATIAL_LEG_TYPES[kind][1]
        raise GridError(
            f"{source}: {key}: not a design parameter (a {kind} leg carries its motor on joint "
            f"{joint})"
        )
    known = spatial_keys(base)
    if name.startswith("limits.") and name not in known:
        raise GridError(
            f"{source}: {key}: the base model has no {name} to vary; set it in the model "
            "file's [limits]"
        )
    if name not in known:
        raise GridError(f"{source}: {key}: {_why_unknown(key, name, base, known)}")
    shape = known[name]
    if not shape:
        if index:
            raise GridError(f"{source}: {key}: {name} holds one value, not a list")
        return
    check_index(key, name, index, shape, source)


def _why_unknown(
    key: str, name: str, base: Mapping[str, Any], known: Mapping[str, tuple[int, ...]]
) -> str:
    """Why ``name`` is not a key of ``base``: a turned leg, another leg type's key, no such
    leg, or unknown (with the close match)."""
    kind = base["leg"]
    letters = SPATIAL_LEG_TYPES[kind][0]
    parts = name.split(".")
    if len(parts) == 3 and parts[0] == "legs":
        letter, leaf = parts[1], parts[2]
        given = template_legs(base)
        if letter in letters and letter not in given and leaf in LEG_KEYS[kind]:
            k = letters.index(letter)
            origin = given[k % len(given)]
            turned = 120 * (k // len(given))
            rest = key[len(f"legs.{letter}.") :]
            who = "leg A" if len(given) == 1 else f"legs {' and '.join(given)}"
            return (
                f"with symmetric = true only {who}'s keys exist (leg "
                f"{letter} is leg {origin} turned by {turned} degrees about z); vary "
                f"legs.{origin}.{rest}"
            )
        if letter in letters and leaf in _ALL_LEG_KEYS and leaf not in LEG_KEYS[kind]:
            users = ", ".join(n for n, keys in LEG_KEYS.items() if leaf in keys)
            return f"not a key of {kind} legs (only of {users} legs)"
        if letter not in letters:
            return f"unknown leg (a {len(letters)}-{kind} has legs {letters[0]} to {letters[-1]})"
    return f"unknown model key{did_you_mean(name, tuple(known))}"


def turn_u_axes(data: dict[str, Any], base: Mapping[str, Any], keys: Iterable[str]) -> None:
    """Turn the U's second axis of every leg whose U-to-S line the grid's ``keys`` move (and
    whose ``u_axes`` they leave alone) so that it stays perpendicular to it, in ``data`` (the
    design's model data, its legs' tables already copies): see the module. A leg whose line
    the design's values leave as in ``base`` keeps its U as given.

    A leg whose line lies along ``u_axes[0]`` is left as it is (the model then refuses it).
    """
    kind = data.get("leg")
    if kind not in ("UPS", "RUS", "PUS"):
        return
    start = "base" if kind == "UPS" else "elbow"
    moved, fixed = set(), set()
    for key in keys:
        parts = split_key(key)[0].split(".")
        if len(parts) == 3 and parts[0] == "legs":
            if parts[2] in (start, "platform"):
                moved.add(parts[1])
            elif parts[2] == "u_axes":
                fixed.add(parts[1])
    for letter in sorted(moved - fixed):
        was, leg = base["legs"][letter], data["legs"][letter]
        u1, u2 = (np.asarray(v, dtype=np.float64) for v in was["u_axes"])
        u1 = u1 / np.linalg.norm(u1)
        line = np.subtract(was["platform"], was[start], dtype=np.float64)
        moved_line = np.subtract(leg["platform"], leg[start], dtype=np.float64)
        if np.array_equal(line, moved_line):  # the base's values: the base's U
            continue
        home, now = np.cross(u1, line), np.cross(u1, moved_line)
        length = float(np.linalg.norm(now))
        if not length > 0.0:
            continue
        sign = 1.0 if float(u2 @ home) >= 0.0 else -1.0
        leg["u_axes"] = [list(was["u_axes"][0]), [float(v) for v in sign * now / length]]
