"""The general model file: any planar 3-leg robot, everything given at home (docs/interfaces.md).

A file with a top-level ``leg`` key is read here; one without it is the paper's format
(:mod:`rpr3gen.model.paper`). Home is the platform pose ``(0, 0, 0)`` (the platform frame on the
world frame) with every joint coordinate 0::

    name = "my-3rrr"
    leg = "RRR"                 # joint types from base to platform: RRR RPR RRP PRR PPR PRP RPP
    actuated = 1                # the joint of every leg that carries its motor: 1, 2 or 3
    [legs.A]                    # then [legs.B], [legs.C] (or symmetric = true: see below)
    joints = [[x, y], [x, y], [x, y]]    # points of joints 1, 2, 3 at home (world, m)
    axes = [[0, 0], [1, 0], [0, 0]]      # direction of each P joint at home (R entries ignored)
    mass = [m1, m2]                      # bodies 1 and 2 (kg)
    com = [[x, y], [x, y]]               # their centres of mass at home (world, m)
    inertia = [J1, J2]                   # about their centres of mass (kg m^2)
    [platform]
    mass = 5.0                           # kg
    com = [0.0, 0.0]                     # at home (= in the platform frame), m
    inertia = 0.375                      # about its centre of mass, kg m^2
    [environment]                        # optional: gravity = [0.0, -9.81]
    [payload]                            # optional: force = [fx, fy] at G, moment = mz
    [limits]                             # optional: "A.q2" = [lo, hi] (m or rad); "q2" = all legs

Sugar for symmetric designs: ``symmetric = true`` with ``[legs.A]`` alone places legs B and C by
turning leg A about the origin (G at home) by 120 and 240 degrees.

The reader checks every key and value, the structure (three structures are architecturally
singular: both passive joints prismatic), each leg at home (its serial determinant not zero)
and the three legs together at home (not a parallel singularity), and returns the
:class:`~rpr3gen.model.Model` with the general parameter vector (:mod:`rpr3gen.structure`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from rpr3gen.errors import ModelError, did_you_mean
from rpr3gen.model.reading import Reader, describe
from rpr3gen.model.types import DEFAULT_GRAVITY, Model
from rpr3gen.structure import LEG_TYPES, LEGS, SPATIAL_LEG_TYPES, Structure

#: Allowed keys per table (None: a value; a dict: a sub-table).
LEG_KEYS: tuple[str, ...] = ("joints", "axes", "mass", "com", "inertia")
SCHEMA: dict[str, Any] = {
    "name": None,
    "leg": None,
    "actuated": None,
    "symmetric": None,
    "legs": {leg: dict.fromkeys(LEG_KEYS) for leg in LEGS},
    "platform": {"mass": None, "com": None, "inertia": None},
    "environment": {"gravity": None},
    "payload": {"force": None, "moment": None},
    "limits": None,  # keys "A.q2" or "q2": checked by the reader
}

#: A leg whose serial determinant at home, normalised (its columns scaled to unit length in
#: ``(x, y, rho phi)``), is below this is in a serial singularity at home: a model error.
SERIAL_HOME_TOL = 1e-6
#: Three legs whose closure at home has a conditioning (the generated code's measure) below
#: this do not hold the platform there (a parallel singularity at home): a model error.
PARALLEL_HOME_TOL = 1e-6
#: Points closer than this (m) coincide.
COINCIDE_TOL = 1e-9


def is_general(data: Mapping[str, Any]) -> bool:
    """True for a file of the general format (it has a ``leg`` key)."""
    return "leg" in data


def _perp(v: np.ndarray) -> np.ndarray:
    return np.array([-v[1], v[0]])


def serial_columns(leg: str, joints: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """The leg's serial Jacobian at home, columns ``(perp(P3 - Pj), 1)`` (R) or ``(u_j, 0)``
    (P): joint 3's point's velocity and the platform's rate per unit joint rate."""
    columns = []
    for j in range(3):
        if leg[j] == "R":
            arm = _perp(joints[2] - joints[j])
            columns.append([arm[0], arm[1], 1.0])
        else:
            columns.append([axes[j][0], axes[j][1], 0.0])
    return np.array(columns).T


def home_conditioning(structure: Structure, legs: Mapping[str, Mapping[str, np.ndarray]]) -> float:
    """The closure's conditioning at home (docs/conventions.md, ``conditioning``): each leg's
    passive columns ``c1, c2`` leave the constraint ``n = c1 x c2`` on joint 3's point's twist,
    the three rows ``(n_x, n_y, n . (perp(P3), 1))`` form W, and its Hadamard ratio, rotation
    scaled by the platform's RMS radius, is 1 at best and 0 at a parallel singularity."""
    rho2 = float(np.mean([np.dot(legs[k]["joints"][2], legs[k]["joints"][2]) for k in LEGS]))
    rows = []
    for leg in LEGS:
        S = serial_columns(structure.leg, legs[leg]["joints"], legs[leg]["axes"])
        c1, c2 = (S[:, j - 1] for j in (1, 2, 3) if j != structure.actuated)
        n = np.cross(c1, c2)
        turn = _perp(legs[leg]["joints"][2])
        rows.append([n[0], n[1], n[0] * turn[0] + n[1] * turn[1] + n[2]])
    W = np.array(rows)
    norms = [math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2 / rho2) for r in rows]
    if min(norms) == 0.0:
        return 0.0
    return abs(float(np.linalg.det(W))) / math.sqrt(rho2) / math.prod(norms)


class GeneralReader(Reader):
    """Validates a general model file; every failure names the file and the dotted key."""

    schema = SCHEMA

    def read(self, data: Any) -> Model:
        """The model of the parsed TOML ``data``."""
        if not isinstance(data, Mapping):
            raise ModelError(f"{self.source}: a model must be a table, got {describe(data)}")
        self.check_keys({k: v for k, v in data.items() if k != "limits"}, SCHEMA, "")
        name = self.required(data, "name", "name")
        if not isinstance(name, str) or not name.strip():
            self.fail("name", f"must be a non-empty string, got {describe(name)}")
        structure = self.structure(data)
        legs_table = self.table(data, "legs", required=True)
        symmetric = data.get("symmetric", False)
        if not isinstance(symmetric, bool):
            self.fail("symmetric", f"must be true or false, got {describe(symmetric)}")
        legs = self.legs(legs_table, structure, symmetric)
        platform = self.platform(self.table(data, "platform", required=True))
        params: dict[str, float] = {}
        unit = _unit_scaled(legs)  # the home checks' arithmetic, free of overflow
        for leg in LEGS:
            self.leg_params(structure, leg, legs[leg], params, unit[leg]["joints"])
        self.check_home(structure, legs, unit)
        params["m3"], params["J3"] = platform["mass"], platform["inertia"]
        params["cx3"], params["cy3"] = platform["com"]
        environment = self.table(data, "environment", required=False)
        payload = self.table(data, "payload", required=False)
        params["gx"], params["gy"] = self.vector(
            environment, "environment.gravity", "gravity", 2, DEFAULT_GRAVITY
        )
        params["fx"], params["fy"] = self.vector(payload, "payload.force", "force", 2, (0.0, 0.0))
        params["mz"] = self.number(payload, "payload.moment", "moment", default=0.0)
        limits = self.joint_limits(
            data.get("limits", {}), LEGS, structure.limited_coordinates(), structure.leg
        )
        return Model(
            name=name,
            actuation=structure.actuation,
            params=params,
            source=self.source,
            structure=structure,
            limits=limits,
        )

    def structure(self, data: Mapping[str, Any]) -> Structure:
        leg = self.required(data, "leg", "leg")
        if leg not in LEG_TYPES:
            every = (*LEG_TYPES, *SPATIAL_LEG_TYPES)
            hint = did_you_mean(leg, every) if isinstance(leg, str) else ""
            self.fail(
                "leg",
                f"must be one of {', '.join(LEG_TYPES)} (planar: joint types from base to "
                f"platform; PPP cannot turn the platform) or {', '.join(SPATIAL_LEG_TYPES)} "
                f"(spatial), got {describe(leg)}{hint}",
            )
        actuated = self.required(data, "actuated", "actuated")
        if isinstance(actuated, bool) or actuated not in (1, 2, 3):
            self.fail(
                "actuated", f"must be 1, 2 or 3 (the motor's joint), got {describe(actuated)}"
            )
        structure = Structure(leg, int(actuated))
        if structure.singular:
            passive = " and ".join(str(j) for j in (1, 2, 3) if j != structure.actuated)
            self.fail(
                "actuated",
                f"a 3-{leg} with its motors on joint {actuated} cannot move: its passive joints "
                f"{passive} are both prismatic, so every motor measures only the platform's "
                "angle and nothing controls its position (an architecturally singular "
                "structure); put the motors on another joint",
            )
        return structure

    def legs(
        self, table: Mapping[str, Any], structure: Structure, symmetric: bool
    ) -> dict[str, dict[str, np.ndarray]]:
        given = [leg for leg in LEGS if leg in table]
        if symmetric:
            extra = [leg for leg in given if leg != "A"]
            if extra:
                self.fail(
                    f"legs.{extra[0]}",
                    "not allowed with symmetric = true (legs B and C are leg A turned by 120 "
                    "and 240 degrees about the origin)",
                )
            if "A" not in table:
                self.fail("legs.A", "missing required table [legs.A]")
            a = self.leg(table["A"], structure, "A")
            return {leg: _turned(a, 120.0 * k) for k, leg in enumerate(LEGS)}
        for leg in LEGS:
            if leg not in table:
                self.fail(
                    f"legs.{leg}", f"missing required table [legs.{leg}] (or symmetric = true)"
                )
        return {leg: self.leg(table[leg], structure, leg) for leg in LEGS}

    def leg(self, t: Mapping[str, Any], structure: Structure, leg: str) -> dict[str, np.ndarray]:
        key = f"legs.{leg}"
        for k in ("joints", "mass", "com", "inertia"):
            self.required(t, f"{key}.{k}", k)
        joints = np.array(self.points(t, f"{key}.joints", "joints"))
        prismatic = [j for j in (1, 2, 3) if structure.leg[j - 1] == "P"]
        if "axes" in t:
            axes = np.array(
                self.points(t, f"{key}.axes", "axes", "a list of 3 directions [[x, y], ...]")
            )
        elif prismatic:
            self.fail(f"{key}.axes", f"missing required key (joint {prismatic[0]} is prismatic)")
        else:
            axes = np.zeros((3, 2))
        for j in prismatic:
            norm = math.hypot(*axes[j - 1])
            if norm == 0.0:
                self.fail(
                    f"{key}.axes[{j - 1}]",
                    f"joint {j} is prismatic: its axis must be a non-zero direction, got [0, 0]",
                )
            axes[j - 1] = axes[j - 1] / norm
        for j in (1, 2, 3):
            if structure.leg[j - 1] == "R":
                axes[j - 1] = 0.0
        mass = self.vector(t, f"{key}.mass", "mass", 2)
        inertia = self.vector(t, f"{key}.inertia", "inertia", 2)
        for body in range(2):
            if mass[body] < 0.0:
                self.fail(f"{key}.mass[{body}]", f"must not be negative, got {mass[body]!r}")
            if inertia[body] < 0.0:
                self.fail(f"{key}.inertia[{body}]", f"must not be negative, got {inertia[body]!r}")
        com = np.array(
            self.points(t, f"{key}.com", "com", "a list of 2 points [[x, y], [x, y]]", 2)
        )
        return {
            "joints": joints,
            "axes": axes,
            "mass": np.array(mass),
            "com": com,
            "inertia": np.array(inertia),
        }

    def platform(self, t: Mapping[str, Any]) -> dict[str, Any]:
        mass = self.number(t, "platform.mass", "mass", positive=True)
        inertia = self.number(t, "platform.inertia", "inertia", positive=True)
        com = self.vector(t, "platform.com", "com", 2, (0.0, 0.0))
        return {"mass": mass, "inertia": inertia, "com": com}

    def leg_params(
        self,
        structure: Structure,
        leg: str,
        data: Mapping[str, np.ndarray],
        params: dict,
        unit_joints: np.ndarray,
    ) -> None:
        """The leg's parameters into ``params``, after its check at home, which is computed
        from ``unit_joints`` (its joints in the unit of :func:`_unit_scaled`: the normalised
        determinant and its sign do not depend on the unit)."""
        joints, axes = data["joints"], data["axes"]
        for j in range(3):
            params[f"x{j + 1}_{leg}"], params[f"y{j + 1}_{leg}"] = (float(v) for v in joints[j])
            if structure.leg[j] == "P":
                params[f"ux{j + 1}_{leg}"], params[f"uy{j + 1}_{leg}"] = (float(v) for v in axes[j])
        joints = unit_joints
        S = serial_columns(structure.leg, joints, axes)
        scale = max(np.linalg.norm(joints[2]), *(np.linalg.norm(joints[2] - p) for p in joints))
        scaled = S * np.array([[1.0], [1.0], [scale]])
        normalised = abs(np.linalg.det(scaled)) / np.prod(np.linalg.norm(scaled, axis=0))
        if not normalised > SERIAL_HOME_TOL:
            self.fail(
                f"legs.{leg}",
                f"leg {leg} is in a serial singularity at home (its joints' motions are "
                f"dependent there: normalised determinant {normalised:.3g}); move a joint or "
                "an axis",
            )
        params[f"sigma_{leg}"] = 1.0 if np.linalg.det(S) > 0 else -1.0
        for k in range(2):
            params[f"m{k + 1}_{leg}"] = float(data["mass"][k])
            params[f"J{k + 1}_{leg}"] = float(data["inertia"][k])
            params[f"cx{k + 1}_{leg}"], params[f"cy{k + 1}_{leg}"] = (
                float(v) for v in data["com"][k]
            )

    def check_home(
        self,
        structure: Structure,
        legs: Mapping[str, Mapping[str, np.ndarray]],
        unit: Mapping[str, Mapping[str, np.ndarray]],
    ) -> None:
        """The three legs at home: their platform joints apart (``legs``), and holding the
        platform (computed from ``unit``, the legs in the unit of :func:`_unit_scaled`)."""
        for i in range(3):
            for j in range(i + 1, 3):
                a, b = (legs[LEGS[k]]["joints"][2] for k in (i, j))
                if math.dist(a, b) <= COINCIDE_TOL:
                    self.fail(
                        f"legs.{LEGS[j]}.joints",
                        f"legs {LEGS[i]} and {LEGS[j]} meet the platform at one point "
                        f"({a[0]:.6g}, {a[1]:.6g}): the platform could turn about it",
                    )
        conditioning = home_conditioning(structure, unit)
        if not conditioning > PARALLEL_HOME_TOL:
            self.fail(
                "legs",
                "the three legs do not hold the platform at home (a parallel singularity: "
                f"conditioning {conditioning:.3g}); the platform could move with the motors "
                "locked",
            )


def _unit_scaled(
    legs: Mapping[str, Mapping[str, np.ndarray]],
) -> dict[str, dict[str, np.ndarray]]:
    """The legs with their joints in a unit of length, a power of two, in which the largest
    coordinate is in ``[0.5, 1)``: the home checks square and multiply coordinates, which
    overflow (or underflow to zero) for finite but huge (or tiny) numbers in a model file,
    while their measures are dimensionless. Exact (powers of two) but where a coordinate
    smaller than ``2**-1022`` of the largest becomes subnormal."""
    largest = max(float(np.abs(legs[leg]["joints"]).max()) for leg in LEGS)
    factor = math.ldexp(1.0, -math.frexp(largest)[1]) if largest > 0.0 else 1.0
    return {leg: {**legs[leg], "joints": legs[leg]["joints"] * factor} for leg in LEGS}


def _turned(leg: Mapping[str, np.ndarray], degrees: float) -> dict[str, np.ndarray]:
    """A leg turned about the origin: its points, axes and centres of mass."""
    angle = math.radians(degrees)
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, -s], [s, c]])
    return {
        "joints": leg["joints"] @ R.T,
        "axes": leg["axes"] @ R.T,
        "mass": leg["mass"].copy(),
        "com": leg["com"] @ R.T,
        "inertia": leg["inertia"].copy(),
    }


def read_general(data: Mapping[str, Any], source: str) -> Model:
    """Validate a general model (the parsed TOML) and build the :class:`~rpr3gen.model.Model`."""
    return GeneralReader(source).read(data)
