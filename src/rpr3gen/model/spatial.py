"""The spatial model file: hexapods (UPS, RUS, PUS) and Deltas (RSS2, PSS2), everything given
at home (docs/spatial-robots.md).

A file whose top-level ``leg`` is a spatial leg type is read here::

    name = "tsai-stewart"
    leg = "UPS"                 # UPS RUS PUS (6 legs, A-F) or RSS2 PSS2 (Deltas, 3 legs, A-C)
    actuated = 2                # the leg type's motor joint: 2 for UPS, 1 for the others
    [legs.A]                    # ... every leg, or symmetric = true (see below)
    base = [x, y, z]            # joint 1's point (m, world frame, z up)
    axis = [x, y, z]            # joint 1's axis (not UPS)
    u_axes = [[x, y, z], [x, y, z]]  # the U's axes (UPS, RUS, PUS): perpendicular
    elbow = [x, y, z]           # the U centre (RUS, PUS); the upper S pair's midpoint (Deltas)
    platform = [x, y, z]        # the S centre; the lower S pair's midpoint (Deltas)
    bar = [x, y, z]             # PSS2: the direction joining a rod pair
    mass = [m1, m2]             # the leg's bodies (kg); Deltas: [m1], the arm or carriage
    com = [[x, y, z], ...]      # their centres of mass (m)
    inertia = [[Ixx, Iyy, Izz, Ixy, Ixz, Iyz], ...]  # about them, world axes (kg m^2)
    width = 0.1                 # Deltas: the rods' distance (m); rod_mass (kg), rod_com
    rod_mass = 0.2              # (fraction of the rod from its upper S) and rod_inertia
    rod_com = 0.5               # (kg m^2, about its centre of mass, across the rod)
    rod_inertia = 0.002
    [platform]                  # mass, com, inertia (as a leg's, one body)
    [environment]               # optional: gravity = [0.0, 0.0, -9.81]
    [payload]                   # optional: force = [fx, fy, fz], moment = [mx, my, mz]

``symmetric = true`` gives only ``[legs.A]`` (Deltas) or ``[legs.A]`` and ``[legs.B]``
(hexapods): legs B, C (Deltas) or C, D and E, F (hexapods) are the given ones turned about the
world z axis by 120 and 240 degrees, every point, axis, centre of mass and inertia tensor.

The reader checks every key and value, each leg at home (the U assumption, a serial
singularity) and all legs together (a parallel singularity), and returns the
:class:`~rpr3gen.model.Model` with the structure's parameter vector
(:meth:`rpr3gen.structure.Structure.param_names`). Geometry: :mod:`rpr3gen.model.spatial_home`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from rpr3gen.errors import ModelError, did_you_mean
from rpr3gen.model.reading import Reader, as_list, describe
from rpr3gen.model.spatial_home import (
    conditioning,
    inertia_entries,
    inertia_matrix,
    inertia_problem,
    turn_z,
    turned,
    unit,
)
from rpr3gen.model.types import Model
from rpr3gen.structure import SPATIAL_LEG_TYPES, SPATIAL_PLATFORM_PARAMS, Structure

__all__ = [
    "DEFAULT_GRAVITY_3D",
    "LEG_KEYS",
    "is_spatial",
    "read_spatial",
]

#: Each spatial leg type's keys (all required), in the model file's order.
_DELTA = ("width", "rod_mass", "rod_com", "rod_inertia")
LEG_KEYS: dict[str, tuple[str, ...]] = {
    "UPS": ("base", "u_axes", "platform", "mass", "com", "inertia"),
    "RUS": ("base", "axis", "u_axes", "elbow", "platform", "mass", "com", "inertia"),
    "PUS": ("base", "axis", "u_axes", "elbow", "platform", "mass", "com", "inertia"),
    "RSS2": ("base", "axis", "elbow", "platform", "mass", "com", "inertia", *_DELTA),
    "PSS2": ("base", "axis", "elbow", "platform", "bar", "mass", "com", "inertia", *_DELTA),
}
_ALL_LEG_KEYS = tuple(dict.fromkeys(k for keys in LEG_KEYS.values() for k in keys))
SCHEMA: dict[str, Any] = {
    "name": None,
    "leg": None,
    "actuated": None,
    "symmetric": None,
    "legs": None,  # checked by the reader: its legs depend on the leg type
    "platform": {"mass": None, "com": None, "inertia": None},
    "environment": {"gravity": None},
    "payload": {"force": None, "moment": None},
    "limits": None,  # keys "A.q2" or "q2": checked by the reader
}
_MOTOR = {"UPS": "the P", "RUS": "the R", "PUS": "the P", "RSS2": "the R", "PSS2": "the P"}
_BODIES = {"UPS": "cylinder, piston", "RUS": "crank, rod", "PUS": "carriage, rod",
           "RSS2": "arm", "PSS2": "carriage"}  # fmt: skip

#: Gravity when the file gives none (world frame, z up), m/s^2.
DEFAULT_GRAVITY_3D: tuple[float, float, float] = (0.0, 0.0, -9.81)
#: The U axes' ``|u1 . u2|`` and the leg's ``|l . u2|`` (unit vectors) above this: refused.
PERPENDICULAR_TOL = 1e-6
#: The leg's ``|l . (u1 x u2)|`` below this: along ``u_axes[0]``, the U at its singularity.
U_SINGULAR_TOL = 1e-3
#: A leg whose ``|D| / (|S - E| |dE/dq1|)`` at home is below this is in a serial singularity.
SERIAL_HOME_TOL = 1e-6
#: Legs whose constraint wrenches' conditioning at home is below this: a parallel singularity.
PARALLEL_HOME_TOL = 1e-6


def is_spatial(data: Mapping[str, Any]) -> bool:
    """True for a file of a spatial robot (its ``leg`` is UPS, RUS, PUS, RSS2 or PSS2)."""
    leg = data.get("leg")
    return isinstance(leg, str) and leg in SPATIAL_LEG_TYPES


class SpatialReader(Reader):
    """Validates a spatial model file; every failure names the file and the dotted key."""

    schema = SCHEMA

    def read(self, data: Any) -> Model:
        """The model of the parsed TOML ``data``."""
        if not isinstance(data, Mapping):
            raise ModelError(f"{self.source}: a model must be a table, got {describe(data)}")
        self.check_keys(data, SCHEMA, "")
        name = self.required(data, "name", "name")
        if not isinstance(name, str) or not name.strip():
            self.fail("name", f"must be a non-empty string, got {describe(name)}")
        structure = self.structure(data)
        symmetric = data.get("symmetric", False)
        if not isinstance(symmetric, bool):
            self.fail("symmetric", f"must be true or false, got {describe(symmetric)}")
        legs, origin = self.legs(data, structure, symmetric)
        platform = self.table(data, "platform", required=True)
        for key in ("mass", "com", "inertia"):
            self.required(platform, f"platform.{key}", key)
        environment = self.table(data, "environment", required=False)
        payload = self.table(data, "payload", required=False)
        zero = (0.0, 0.0, 0.0)
        rest = (
            self.number(platform, "platform.mass", "mass", positive=True),
            *self.vector(platform, "platform.com", "com", 3),
            *self.tensor(platform["inertia"], "platform.inertia"),
            *self.vector(environment, "environment.gravity", "gravity", 3, DEFAULT_GRAVITY_3D),
            *self.vector(payload, "payload.force", "force", 3, zero),
            *self.vector(payload, "payload.moment", "moment", 3, zero),
        )
        self.check_home(structure, legs, origin)  # adds each leg's sigma
        values: dict[str, float] = {}
        for letter, leg in legs.items():
            values.update({f"{k}_{letter}": v for k, v in self.leg_params(structure, leg)})
        values.update(zip(SPATIAL_PLATFORM_PARAMS, rest, strict=True))
        params = {n: values[n] for n in structure.param_names()}
        return Model(
            name=name,
            actuation=structure.actuation,
            params=params,
            source=self.source,
            structure=structure,
            limits=self.joint_limits(
                data.get("limits", {}),
                structure.legs,
                structure.limited_coordinates(),
                structure.leg,
            ),
        )

    def structure(self, data: Mapping[str, Any]) -> Structure:
        leg = self.required(data, "leg", "leg")
        if not isinstance(leg, str) or leg not in SPATIAL_LEG_TYPES:
            hint = did_you_mean(leg, SPATIAL_LEG_TYPES) if isinstance(leg, str) else ""
            self.fail(
                "leg", f"must be one of {', '.join(SPATIAL_LEG_TYPES)}, got {describe(leg)}{hint}"
            )
        actuated = self.required(data, "actuated", "actuated")
        joint = SPATIAL_LEG_TYPES[leg][1]
        if isinstance(actuated, bool) or actuated != joint:
            self.fail(
                "actuated",
                f"{leg} legs carry their motor on joint {joint} ({_MOTOR[leg]}), got "
                f"{describe(actuated)}",
            )
        return Structure(leg, joint)

    # -- the legs ----------------------------------------------------------------------------

    def legs(
        self, data: Mapping[str, Any], structure: Structure, symmetric: bool
    ) -> tuple[dict[str, dict[str, Any]], dict[str, str]]:
        """Every leg (turned from the given ones with ``symmetric``), and the given leg each
        comes from (for messages)."""
        table = self.table(data, "legs", required=True)
        letters = structure.legs
        if not isinstance(table, Mapping):
            self.fail("legs", f"must be a table [legs.A] ..., got {describe(table)}")
        for key in table:
            if key not in letters:
                self.fail(
                    f"legs.{key}",
                    f"unknown leg (a {structure.title.split(',')[0]} has legs "
                    f"{letters[0]} to {letters[-1]})",
                )
        given = letters[:2] if structure.dof == 6 else letters[:1]
        if symmetric:
            for letter in letters:
                if letter in table and letter not in given:
                    turned_ = ", ".join(letters[len(given) :])
                    self.fail(
                        f"legs.{letter}",
                        f"not allowed with symmetric = true (legs {turned_} are legs "
                        f"{', '.join(given)} turned by 120 and 240 degrees about the z axis)",
                    )
        required = given if symmetric else letters
        for letter in required:
            if letter not in table:
                why = "symmetric = true takes legs " + " and ".join(given)
                why = why if symmetric else "or symmetric = true"
                self.fail(f"legs.{letter}", f"missing required table [legs.{letter}] ({why})")
        read = {letter: self.leg(table[letter], structure.leg, letter) for letter in required}
        if not symmetric:
            return read, {letter: letter for letter in letters}
        legs: dict[str, dict[str, Any]] = {}
        origin: dict[str, str] = {}
        for k, letter in enumerate(letters):
            source = given[k % len(given)]
            legs[letter] = turned(read[source], turn_z(120 * (k // len(given))))
            origin[letter] = source
        return legs, origin

    def leg(self, t: Any, kind: str, letter: str) -> dict[str, Any]:
        """One leg's values: points ``(3,)``, directions (unit), ``u_axes`` ``(2, 3)``
        (orthonormal), ``com`` ``(n, 3)``, ``inertia`` ``(n, 3, 3)``, the Deltas' numbers."""
        key = f"legs.{letter}"
        if not isinstance(t, Mapping):
            self.fail(key, f"must be a table [{key}], got {describe(t)}")
        own = LEG_KEYS[kind]
        for k in t:
            if k in own:
                continue
            if k in _ALL_LEG_KEYS:
                users = ", ".join(n for n, keys in LEG_KEYS.items() if k in keys)
                self.fail(f"{key}.{k}", f"not a key of {kind} legs (only of {users} legs)")
            self.fail(f"{key}.{k}", f"unknown key{did_you_mean(str(k), own)}")
        for k in own:
            self.required(t, f"{key}.{k}", k)
        n = 1 if kind.endswith("SS2") else 2
        leg: dict[str, Any] = dict.fromkeys(("axis", "u_axes", "elbow", "bar"))
        leg["base"] = np.array(self.vector(t, f"{key}.base", "base", 3))
        leg["platform"] = np.array(self.vector(t, f"{key}.platform", "platform", 3))
        if "elbow" in own:
            leg["elbow"] = np.array(self.vector(t, f"{key}.elbow", "elbow", 3))
        for k in ("axis", "bar"):
            if k in own:
                leg[k] = self.direction(self.vector(t, f"{key}.{k}", k, 3), f"{key}.{k}")
        if "u_axes" in own:
            leg["u_axes"] = self.u_axes(t, f"{key}.u_axes")
        bodies = f"{n} number{'s' if n > 1 else ''} (the {_BODIES[kind]}, kg)"
        mass = self.vectors(t, f"{key}.mass", "mass", n, 0, f"a list of {bodies}")
        for i, m in enumerate(mass):
            if not m > 0.0:
                self.fail(f"{key}.mass[{i}]", f"must be a positive number, got {m!r}")
        leg["mass"] = np.array(mass)
        shape = f"a list of {n} point{'s' if n > 1 else ''} [[x, y, z]{', ...' * (n > 1)}]"
        leg["com"] = np.array(self.vectors(t, f"{key}.com", "com", n, 3, shape))
        shape = f"a list of {n} list{'s' if n > 1 else ''} [[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]...]"
        entries = self.vectors(t, f"{key}.inertia", "inertia", n, 6, shape)
        leg["inertia"] = np.array(
            [inertia_matrix(self.tensor(e, f"{key}.inertia[{i}]")) for i, e in enumerate(entries)]
        )
        if kind.endswith("SS2"):
            leg["width"] = self.number(t, f"{key}.width", "width", positive=True)
            leg["rod_mass"] = self.bounded(t, key, "rod_mass", 0.0, None, "kg")
            leg["rod_com"] = self.bounded(t, key, "rod_com", 0.0, 1.0, "of the rod")
            leg["rod_inertia"] = self.bounded(t, key, "rod_inertia", 0.0, None, "kg m^2")
            if kind == "RSS2":
                leg["bar"] = leg["axis"]
        return leg

    def u_axes(self, t: Mapping[str, Any], dotted: str) -> np.ndarray:
        shape = "a list of 2 directions [[x, y, z], [x, y, z]]"
        u1, u2 = (
            self.direction(v, f"{dotted}[{i}]")
            for i, v in enumerate(self.vectors(t, dotted, "u_axes", 2, 3, shape))
        )
        dot = float(u1 @ u2)
        if abs(dot) > PERPENDICULAR_TOL:
            self.fail(
                dotted,
                f"the U's two axes must be perpendicular, got an angle of "
                f"{math.degrees(math.acos(max(-1.0, min(1.0, dot)))):.6g} degrees",
            )
        u2 = self.direction(u2 - dot * u1, dotted)  # exactly perpendicular to u1
        return np.array([u1, u2])

    def vectors(
        self, t: Mapping[str, Any], dotted: str, key: str, count: int, length: int, shape: str
    ) -> list[Any]:
        """``t[key]``: a list of ``count`` numbers (``length`` 0) or of ``count`` lists of
        ``length`` numbers."""
        value = as_list(t[key])
        if not isinstance(value, list) or len(value) != count:
            self.fail(dotted, f"must be {shape}, got {describe(t[key])}")
        if length == 0:
            return [self.scalar(v, f"{dotted}[{i}]") for i, v in enumerate(value)]
        return [self.vector({"v": v}, f"{dotted}[{i}]", "v", length) for i, v in enumerate(value)]

    def direction(self, v: Any, dotted: str) -> np.ndarray:
        d = unit(v)
        if d is None:
            self.fail(dotted, "must be a non-zero direction, got [0, 0, 0]")
        return d

    def tensor(self, value: Any, dotted: str) -> tuple[float, ...]:
        entries = self.vector({"v": value}, dotted, "v", 6)
        problem = inertia_problem(inertia_matrix(entries))
        if problem:
            self.fail(
                dotted, f"not a body's inertia tensor [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]: {problem}"
            )
        return entries

    def bounded(
        self, t: Mapping[str, Any], key: str, k: str, lo: float, hi: float | None, unit_: str
    ) -> float:
        x = self.number(t, f"{key}.{k}", k)
        if x < lo or (hi is not None and x > hi):
            bound = f"in [{lo:g}, {hi:g}]" if hi is not None else f"at least {lo:g}"
            self.fail(f"{key}.{k}", f"must be {bound} ({unit_}), got {x!r}")
        return x

    # -- the parameters and the checks at home -----------------------------------------------

    def leg_params(self, structure: Structure, leg: Mapping[str, Any]) -> list[tuple[str, float]]:
        """One leg's parameters, unsuffixed (its ``sigma`` from :meth:`check_home`)."""
        out: list[tuple[str, float]] = []

        def put(prefix: str, v: Any, names: Sequence[str] = "xyz") -> None:
            out.extend((f"{prefix}{a}", float(x)) for a, x in zip(names, v, strict=True))

        put("b", leg["base"])
        if leg["axis"] is not None:
            put("a", leg["axis"])
        if leg["u_axes"] is not None:
            put("u1", leg["u_axes"][0])
            put("u2", leg["u_axes"][1])
        if leg["elbow"] is not None:
            put("e", leg["elbow"])
        put("p", leg["platform"])
        if structure.leg == "PSS2":
            put("bar", leg["bar"])
        if "sigma" in leg:
            out.append(("sigma", float(leg["sigma"])))
        for k, m in enumerate(leg["mass"], 1):
            out.append((f"m{k}", float(m)))
        for k, c in enumerate(leg["com"], 1):
            put(f"c{k}", c)
        for k, tensor in enumerate(leg["inertia"], 1):
            put(f"I{k}", inertia_entries(tensor), ("xx", "yy", "zz", "xy", "xz", "yz"))
        if structure.leg.endswith("SS2"):
            out += [("w", leg["width"]), ("mr", leg["rod_mass"])]
            out += [("fr", leg["rod_com"]), ("Ir", leg["rod_inertia"])]
        return out

    def check_home(
        self,
        structure: Structure,
        legs: dict[str, dict[str, Any]],
        origin: Mapping[str, str],
    ) -> None:
        """Each leg at home (the U assumption, a serial singularity), its ``sigma`` into the
        leg, then all legs (a parallel singularity): in a unit of length, a power of two, in
        which every coordinate is below 1 (the measures are dimensionless; no overflow)."""
        kind = structure.leg
        lengths = [np.abs(leg[k]).max() for leg in legs.values() for k in ("base", "platform")]
        lengths += [np.abs(leg["elbow"]).max() for leg in legs.values() if leg["elbow"] is not None]
        lengths += [leg["width"] for leg in legs.values() if "width" in leg]
        largest = float(max(lengths))
        scale = math.ldexp(1.0, -math.frexp(largest)[1]) if largest > 0.0 else 1.0
        points, directions = [], []
        for letter, leg in legs.items():
            key = f"legs.{origin[letter]}"
            b, p = leg["base"] * scale, leg["platform"] * scale
            e = None if leg["elbow"] is None else leg["elbow"] * scale
            lower = b if e is None else e
            rod = "leg (platform - base)" if e is None else "rod (platform - elbow)"
            w = unit(p - lower)
            if w is None:
                self.fail(f"{key}.platform", f"the {rod} has zero length at home")
            if leg["u_axes"] is not None:
                u1, u2 = leg["u_axes"]
                if abs(float(w @ u2)) > PERPENDICULAR_TOL:
                    self.fail(
                        f"{key}.u_axes",
                        f"the {rod} must be perpendicular to u_axes[1] at home (the U's "
                        f"assumption, docs/spatial-robots.md), got cosine {float(w @ u2):.3g}",
                    )
                if abs(float(w @ np.cross(u1, u2))) < U_SINGULAR_TOL:
                    self.fail(
                        f"{key}.u_axes",
                        f"the {rod} lies along u_axes[0] at home: the U is at its "
                        "singularity (its axes and the leg in one plane); turn the U",
                    )
            if e is not None:
                de = leg["axis"] if kind[0] == "P" else np.cross(leg["axis"], e - b)
                d_e = unit(de)
                D = float((p - e) @ de)
                reach = 0.0 if d_e is None else abs(float(w @ d_e))
                if not reach >= SERIAL_HOME_TOL:
                    self.fail(
                        key,
                        f"leg {origin[letter]} is in a serial singularity at home: the rod is "
                        "perpendicular to the elbow's path (D = (S - E) . dE/dq1 normalised "
                        f"{reach:.3g}); move the elbow or the axis",
                    )
                leg["sigma"] = 1.0 if D > 0.0 else -1.0
            if kind.endswith("SS2"):
                half = 0.5 * leg["width"] * scale * leg["bar"]
                points += [p + half, p - half]
                directions += [w, w]
            else:
                points.append(p)
                directions.append(w)
        cond = conditioning(np.array(points), np.array(directions))
        if not cond > PARALLEL_HOME_TOL:
            self.fail(
                "legs",
                f"the legs do not hold the platform at home (a parallel singularity: "
                f"conditioning {cond:.3g}); the platform could move with the motors locked",
            )


def read_spatial(data: Mapping[str, Any], source: str) -> Model:
    """Validate a spatial model (the parsed TOML) and build the :class:`~rpr3gen.model.Model`."""
    return SpatialReader(source).read(data)
