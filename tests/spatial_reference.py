"""Independent Newton-Euler reference for the spatial parallel robots (hexapods and Deltas).

Written only from the user contract ``docs/spatial-robots.md`` (and ``shared/spec/interfaces.md``,
section "Spatial parallel robots (hexapods and Deltas)") with NumPy and SciPy: it imports nothing
from ``rpr3gen``, ``rpr3gen_derive``, ``derive/`` or ``generated/``, so tests comparing the
production code (derived by virtual work) with it check the symbolic derivation against plain
mechanics.

Frames and units: world frame, z up, SI units, radians. Every vector is given by its world
components. Everything in a model is given at HOME (platform pose 0, every joint coordinate 0).

The robots. Leg types ``UPS``, ``RUS``, ``PUS`` (hexapods: legs A-F, pose
``q = (x, y, z, a, b, c)``, platform rotation ``R = Rz(c) Ry(b) Rx(a)``) and ``RSS2``, ``PSS2``
(Deltas: legs A-C, pose ``q = (x, y, z)``, ``R = I``). A platform point at ``p`` at home is at
``R p + (x, y, z)``. The bodies of a leg, base to platform:

- ``UPS``: cylinder (after the U at ``base``), piston (after the P; same rotation as the
  cylinder, slid by ``q2`` along the leg axis); the piston carries the S at ``platform``.
- ``RUS`` / ``PUS``: crank turning about ``axis`` through ``base`` / carriage sliding along
  ``axis``; it carries the U at ``elbow``; the rod joins the U to the S at ``platform``.
- ``RSS2`` / ``PSS2``: arm (R) / carriage (P) carrying the upper S points
  ``elbow + s (width/2) bar`` (``s = +1`` rod 1, ``-1`` rod 2; ``bar = axis`` for RSS2); rod k
  joins them to the lower S points ``platform + s (width/2) bar``; rods have mass, a transverse
  inertia ``rod_inertia`` about their centre of mass and none about their own axis.

Joint coordinates (all 0 at home). R: angle about the home axis; P: displacement along the axis
(UPS: ``q2 = |S - base| - |S_home - base|``); U: ``(a, b)`` with ``Re^T Rl = Rot(u1, a)
Rot(u2, b)`` (``u1``, ``u2`` the normalised home axes, ``|a|, |b| < pi/2``); S of a hexapod: the
rotation vector of ``Re^T Rl`` (angle in ``[0, pi)``, components in the earlier body's axes),
``Re``, ``Rl`` the earlier and later bodies' rotations from home. UPS: cylinder and piston both
have the U's rotation.

Method (plain mechanics, no virtual work):

1. Inverse kinematics per leg in closed form: UPS the leg vector; RUS/RSS2 the circle-sphere
   intersection ``A cos t + B sin t = C``; PUS/PSS2 a quadratic. Of the two solutions, the one
   whose ``D = (S - E) . dE/dq1`` has its home sign (the working mode). The U angles from the rod
   direction seen in the earlier body. Unreachable poses give NaN (no exception).
2. Rates and accelerations in closed form: ``q1'`` and ``q1''`` from the time derivatives of
   ``|S - E|^2 = L^2``; the U rates and accelerations from the linear equations
   ``e' = w_l x e`` and ``e'' = alpha_l x e + w_l x (w_l x e)`` (``e`` the rod / leg direction,
   fixed in the later body) solved by least squares (consistent, 3 equations, 2 unknowns).
   No finite differences.
3. Newton-Euler for every body (force, and moment about the centre of mass, world axes; rods:
   ``d/dt (J u x u') = J u x u''``), the unknowns the joint wrenches (force and moment about the
   joint's point, exerted by the earlier body on the later) and the efforts ``tau``, plus the
   joint constraints: an S transmits no moment, a U none along its two current axes, a passive R
   or P nothing along its free direction, an actuated one exactly ``tau`` there. One dense
   least-squares solve per sample; the residual is checked (the Delta rods give one ``0 = 0``
   moment equation each, the solution is still unique).

Choices where the documents leave room:

- Functions take a parsed :class:`Robot` or a model dict. A pose array of shape (k,) is one
  sample; outputs are always (n,) arrays.
- ``symmetric = true`` with more legs than the first (hexapods: A, B; Deltas: A) is an error;
  ``limits`` is accepted and ignored.
- The U check: the leg or rod must be perpendicular to ``u_axes[1]`` and the two U axes
  perpendicular to each other within ``1e-6`` (cosines), the leg not within 1e-3 of ``u_axes[0]``.
- The working mode is only the sign of ``D``; no ``MIN_REACH`` bound is applied here.
- The dense solves run with BLAS limited to one thread (``threadpoolctl``, a project dependency,
  if importable): many threads make these 100 x 100 systems ten times slower.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
from scipy.spatial.transform import Rotation

try:  # a project dependency; BLAS threads only slow these small dense solves down
    from threadpoolctl import threadpool_limits
except ImportError:  # pragma: no cover
    threadpool_limits = None

HEXAPOD_LEGS: tuple[str, ...] = ("A", "B", "C", "D", "E", "F")
DELTA_LEGS: tuple[str, ...] = ("A", "B", "C")
LEG_TYPES: tuple[str, ...] = ("UPS", "RUS", "PUS", "RSS2", "PSS2")
ACTUATED: dict[str, int] = {"UPS": 2, "RUS": 1, "PUS": 1, "RSS2": 1, "PSS2": 1}
"""The actuated joint of each leg type."""
DEFAULT_GRAVITY: tuple[float, float, float] = (0.0, 0.0, -9.81)
RESIDUAL_TOL = 1e-9
"""Largest accepted residual of the Newton-Euler solve, relative to the right-hand side."""
U_TOL = 1e-6

_MODEL_KEYS = {
    "name",
    "leg",
    "actuated",
    "symmetric",
    "legs",
    "platform",
    "environment",
    "payload",
    "limits",
}
_LEG_KEYS: dict[str, set[str]] = {
    "UPS": {"base", "u_axes", "platform", "mass", "com", "inertia"},
    "RUS": {"base", "axis", "u_axes", "elbow", "platform", "mass", "com", "inertia"},
    "PUS": {"base", "axis", "u_axes", "elbow", "platform", "mass", "com", "inertia"},
    "RSS2": {
        "base",
        "axis",
        "elbow",
        "platform",
        "mass",
        "com",
        "inertia",
        "width",
        "rod_mass",
        "rod_com",
        "rod_inertia",
    },
    "PSS2": {
        "base",
        "axis",
        "elbow",
        "platform",
        "mass",
        "com",
        "inertia",
        "width",
        "bar",
        "rod_mass",
        "rod_com",
        "rod_inertia",
    },
}
_VECTOR_KEYS = {"base", "axis", "elbow", "platform", "bar"}
_PLATFORM_KEYS = {"mass", "com", "inertia"}


def is_hexapod(leg: str) -> bool:
    """True for the six-legged types (UPS, RUS, PUS)."""
    return leg in ("UPS", "RUS", "PUS")


def leg_names(leg: str) -> tuple[str, ...]:
    """The legs' names: A-F for hexapods, A-C for Deltas."""
    return HEXAPOD_LEGS if is_hexapod(leg) else DELTA_LEGS


def dof(leg: str) -> int:
    """The platform's degrees of freedom: 6 (hexapods) or 3 (Deltas)."""
    return 6 if is_hexapod(leg) else 3


def n_joints(leg: str) -> int:
    """Joints per leg carrying a load output: 3 (hexapods) or 5 (Deltas)."""
    return 3 if is_hexapod(leg) else 5


def coordinate_families(leg: str) -> tuple[str, ...]:
    """The joint-coordinate families of a leg type, in output order (joint by joint)."""
    if leg == "UPS":
        return ("q1a", "q1b", "q2", "qd2", "qdd2", "q3x", "q3y", "q3z")
    if leg in ("RUS", "PUS"):
        return ("q1", "qd1", "qdd1", "q2a", "q2b", "q3x", "q3y", "q3z")
    if leg in ("RSS2", "PSS2"):
        return ("q1", "qd1", "qdd1")
    raise ValueError(f"leg: expected one of {LEG_TYPES}, got {leg!r}")


def output_families(leg: str) -> tuple[str, ...]:
    """Every output family of :func:`solve` (coordinates, loads per joint, ``tau``)."""
    loads = tuple(
        f"{c}{j}" for j in range(1, n_joints(leg) + 1) for c in ("fx", "fy", "fz", "mx", "my", "mz")
    )
    return (*coordinate_families(leg), *loads, "tau")


def output_names(leg: str) -> tuple[str, ...]:
    """The output names of :func:`solve`, family-major: ``f"{family}_{L}"`` for every family of
    :func:`output_families` and, within a family, every leg."""
    return tuple(f"{fam}_{L}" for fam in output_families(leg) for L in leg_names(leg))


# ------------------------------------------------------------------------------------------------
# Small 3-D helpers.


def _unit(v: Any) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` of two 3-vectors (faster than ``np.cross`` for single vectors)."""
    a0, a1, a2 = a
    b0, b1, b2 = b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def skew(v: np.ndarray) -> np.ndarray:
    """The matrix of ``v x .``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def rot(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues)."""
    K = skew(axis)
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def rz(t: float) -> np.ndarray:
    """Rotation about world z."""
    return rot(np.array([0.0, 0.0, 1.0]), t)


def euler_matrix(a: float, b: float, c: float) -> np.ndarray:
    """``Rz(c) Ry(b) Rx(a)``."""
    ex, ey, ez = np.eye(3)
    return rot(ez, c) @ rot(ey, b) @ rot(ex, a)


def euler_angles(R: np.ndarray) -> tuple[float, float, float]:
    """``(a, b, c)`` with ``R = Rz(c) Ry(b) Rx(a)``, ``|b| < pi/2``."""
    b = -math.asin(max(-1.0, min(1.0, float(R[2, 0]))))
    return math.atan2(float(R[2, 1]), float(R[2, 2])), b, math.atan2(float(R[1, 0]), float(R[0, 0]))


def angular_velocity(q: Sequence[float], qd: Sequence[float]) -> np.ndarray:
    """World angular velocity (3,) of ``Rz(c) Ry(b) Rx(a)`` for one hexapod pose and its rates."""
    b, c = float(q[4]), float(q[5])
    _, _, _, da, db, dc = (float(v) for v in qd)
    ex, ey, ez = np.eye(3)
    Rz, Ry = rot(ez, c), rot(ey, b)
    return dc * ez + db * (Rz @ ey) + da * (Rz @ Ry @ ex)


def angular_acceleration(
    q: Sequence[float], qd: Sequence[float], qdd: Sequence[float]
) -> np.ndarray:
    """World angular acceleration (3,) of ``Rz(c) Ry(b) Rx(a)`` (closed form)."""
    b, c = float(q[4]), float(q[5])
    _, _, _, da, db, dc = (float(v) for v in qd)
    _, _, _, dda, ddb, ddc = (float(v) for v in qdd)
    ex, ey, ez = np.eye(3)
    Rz, Ry = rot(ez, c), rot(ey, b)
    yc, xc = Rz @ ey, Rz @ Ry @ ex
    w_zy = dc * ez + db * yc
    return ddc * ez + ddb * yc + dda * xc + db * _cross(dc * ez, yc) + da * _cross(w_zy, xc)


def euler_rate_matrix(q: Sequence[float]) -> np.ndarray:
    """``E`` (3, 3) with ``omega = E (da, db, dc)`` for the pose ``q`` of a hexapod."""
    b, c = float(q[4]), float(q[5])
    ex, ey, ez = np.eye(3)
    Rz, Ry = rot(ez, c), rot(ey, b)
    return np.stack([Rz @ Ry @ ex, Rz @ ey, ez], axis=1)


def inertia_matrix(values: Sequence[float]) -> np.ndarray:
    """``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`` -> the symmetric tensor (3, 3)."""
    Ixx, Iyy, Izz, Ixy, Ixz, Iyz = (float(v) for v in values)
    return np.array([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])


def inertia_list(matrix: np.ndarray) -> list[float]:
    """The tensor (3, 3) -> ``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`` (plain floats)."""
    M = np.asarray(matrix, dtype=float)
    return [
        float(M[0, 0]),
        float(M[1, 1]),
        float(M[2, 2]),
        float(M[0, 1]),
        float(M[0, 2]),
        float(M[1, 2]),
    ]


def _rotvec(R: np.ndarray) -> np.ndarray:
    """The rotation vector of ``R`` (angle in ``[0, pi]``); SciPy near ``pi``."""
    v = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    c = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    if c < -0.9:
        return Rotation.from_matrix(R).as_rotvec()
    s = float(np.linalg.norm(v))
    theta = math.atan2(s, c)
    factor = theta / s if s > 1e-8 else 1.0 + theta * theta / 6.0
    return factor * v


# ------------------------------------------------------------------------------------------------
# The model.


@dataclass(frozen=True)
class Leg:
    """One leg at home (world frame, SI units; unused attributes are None).

    Attributes:
        base: joint 1's point (U centre for UPS; a point on the R / P axis otherwise).
        axis: joint 1's unit axis (RUS, PUS, RSS2, PSS2).
        u_axes: (2, 3) the U's unit axes (UPS, RUS, PUS).
        elbow: the U centre (RUS, PUS); the upper S pair's midpoint (Deltas).
        platform: the S centre (hexapods); the lower S pair's midpoint (Deltas).
        mass: (nb,) the leg's moving bodies (Deltas: the arm / carriage only).
        com: (nb, 3) their centres of mass at home.
        inertia: (nb, 3, 3) their inertia tensors about the COM, world axes at home.
        width, bar, rod_mass, rod_com, rod_inertia: Deltas (``bar`` unit; RSS2: the axis).
        length: the leg (UPS) or rod length at home.
        home_sign: sign of ``D = (S - E) . dE/dq1`` at home (not UPS: 0).
    """

    base: np.ndarray
    axis: np.ndarray | None
    u_axes: np.ndarray | None
    elbow: np.ndarray | None
    platform: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    width: float = 0.0
    bar: np.ndarray | None = None
    rod_mass: float = 0.0
    rod_com: float = 0.0
    rod_inertia: float = 0.0
    length: float = 0.0
    home_sign: float = 0.0


@dataclass(frozen=True)
class Robot:
    """A parsed, validated spatial model (see :func:`parse_model`).

    Attributes:
        name: model name.
        leg: the leg type (UPS, RUS, PUS, RSS2, PSS2).
        actuated: the actuated joint (2 for UPS, 1 otherwise).
        legs: the legs, A-F or A-C.
        platform_mass, platform_com, platform_inertia: the platform (COM at home, inertia tensor
            (3, 3) about the COM, world axes at home).
        gravity: (3,) m/s^2.
        payload_force: (3,) N, applied at the platform frame's origin.
        payload_moment: (3,) N m.
    """

    name: str
    leg: str
    actuated: int
    legs: tuple[Leg, ...]
    platform_mass: float
    platform_com: np.ndarray
    platform_inertia: np.ndarray
    gravity: np.ndarray
    payload_force: np.ndarray
    payload_moment: np.ndarray
    leg_names: tuple[str, ...] = field(default=())

    @property
    def dof(self) -> int:
        """6 for hexapods, 3 for Deltas."""
        return dof(self.leg)

    @property
    def scale(self) -> float:
        """A characteristic length, m: the mean distance from ``base`` to ``platform`` at home."""
        return float(np.mean([np.linalg.norm(lg.platform - lg.base) for lg in self.legs]))

    @property
    def platform_radius(self) -> float:
        """RMS distance of the platform points from the platform origin at home, m."""
        return float(np.sqrt(np.mean([np.sum(lg.platform**2) for lg in self.legs])))

    @property
    def total_mass(self) -> float:
        """The mass of every moving body, kg."""
        m = self.platform_mass
        for lg in self.legs:
            m += float(np.sum(lg.mass)) + 2.0 * lg.rod_mass
        return m


def _array(value: Any, shape: tuple[int, ...], where: str) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: expected numbers of shape {shape}") from exc
    if arr.shape != shape:
        raise ValueError(f"{where}: expected shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{where}: not finite")
    return arr


def _check_keys(d: Any, allowed: set[str], where: str) -> None:
    if not isinstance(d, Mapping):
        raise ValueError(f"{where}: expected a table")
    unknown = sorted(set(d) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown key {unknown[0]!r}")


def _inertia_tensor(value: Any, where: str) -> np.ndarray:
    M = inertia_matrix(_array(value, (6,), where))
    ev = np.linalg.eigvalsh(M)
    if ev[0] <= 0:
        raise ValueError(f"{where}: not positive definite")
    if ev[0] + ev[1] < ev[2] * (1 - 1e-9):
        raise ValueError(f"{where}: principal moments break the triangle inequality")
    return M


def turn_leg(leg_d: Mapping[str, Any], angle_deg: float) -> dict[str, Any]:
    """One leg's table turned about world z by ``angle_deg`` (points, axes, COMs, tensors)."""
    Q = rz(math.radians(angle_deg))
    out: dict[str, Any] = {}
    for key, value in leg_d.items():
        if key in _VECTOR_KEYS:
            out[key] = (Q @ np.asarray(value, dtype=float)).tolist()
        elif key in ("u_axes", "com"):
            arr = np.asarray(value, dtype=float)
            out[key] = (arr @ Q.T).tolist()
        elif key == "inertia":
            arr = np.asarray(value, dtype=float)
            if arr.ndim == 1:
                out[key] = inertia_list(Q @ inertia_matrix(arr) @ Q.T)
            else:
                out[key] = [inertia_list(Q @ inertia_matrix(r) @ Q.T) for r in arr]
        else:
            out[key] = value
    return out


_turn_leg = turn_leg  # the earlier private name, kept for existing callers


def expand_symmetric(leg: str, legs: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The full set of legs of a ``symmetric = true`` model.

    Hexapods: ``legs`` holds A and B; C, D are A, B turned about world z by 120 deg, E, F by
    240 deg. Deltas: ``legs`` holds A; B and C are A turned by 120 and 240 deg.
    """
    given = ("A", "B") if is_hexapod(leg) else ("A",)
    if not isinstance(legs, Mapping) or set(legs) != set(given):
        raise ValueError(f"legs: a symmetric {leg} model gives exactly the tables {given}")
    out: dict[str, dict[str, Any]] = {}
    names = leg_names(leg)
    for k, name in enumerate(names):
        src = given[k % len(given)]
        turn = 120.0 * (k // len(given))
        out[name] = turn_leg(legs[src], turn)
    return out


def _check_u(u_axes: np.ndarray, e0: np.ndarray, where: str) -> np.ndarray:
    u = np.array([_unit(u_axes[0]), _unit(u_axes[1])])
    if abs(u[0] @ u[1]) > U_TOL:
        raise ValueError(f"{where}.u_axes: the two axes are not perpendicular")
    if abs(u[1] @ e0) > U_TOL:
        raise ValueError(f"{where}.u_axes: the leg / rod is not perpendicular to the second axis")
    if np.linalg.norm(_cross(u[0], e0)) < 1e-3:
        raise ValueError(f"{where}.u_axes: the leg / rod is along the first axis")
    return u


def parse_model(model: Mapping[str, Any]) -> Robot:
    """Validate a spatial model dict (parsed TOML, the format of ``docs/spatial-robots.md``).

    Args:
        model: keys ``name`` (optional), ``leg``, ``actuated``, ``symmetric`` (optional),
            ``legs``, ``platform``, ``environment`` (optional, ``gravity``), ``payload``
            (optional, ``force``, ``moment``), ``limits`` (optional, ignored).

    Returns:
        The robot, with ``symmetric`` legs expanded and defaults filled in.

    Raises:
        ValueError: naming the offending key, for a malformed model (unknown key, wrong shape,
            a U that breaks the documented assumption, ``D = 0`` at home, ...).
    """
    _check_keys(model, _MODEL_KEYS, "model")
    leg = model.get("leg")
    if leg not in LEG_TYPES:
        raise ValueError(f"leg: expected one of {LEG_TYPES}, got {leg!r}")
    actuated = model.get("actuated")
    if isinstance(actuated, bool) or actuated != ACTUATED[leg]:
        raise ValueError(f"actuated: {leg} takes {ACTUATED[leg]}, got {actuated!r}")
    legs_d = model.get("legs")
    symmetric = model.get("symmetric", False)
    if not isinstance(symmetric, bool):
        raise ValueError("symmetric: expected true or false")
    if symmetric:
        legs_d = expand_symmetric(leg, legs_d)  # type: ignore[arg-type]
    names = leg_names(leg)
    if not isinstance(legs_d, Mapping) or set(legs_d) != set(names):
        raise ValueError(f"legs: expected exactly the tables {names}")
    nb = 2 if is_hexapod(leg) else 1
    legs = []
    for name in names:
        d = legs_d[name]
        where = f"legs.{name}"
        _check_keys(d, _LEG_KEYS[leg], where)
        for key in _LEG_KEYS[leg]:
            if key not in d:
                raise ValueError(f"{where}.{key}: missing")
        base = _array(d["base"], (3,), f"{where}.base")
        plat = _array(d["platform"], (3,), f"{where}.platform")
        mass = _array(np.atleast_1d(np.asarray(d["mass"], dtype=float)), (nb,), f"{where}.mass")
        if np.any(mass <= 0):
            raise ValueError(f"{where}.mass: must be positive")
        com = _array(
            np.reshape(np.asarray(d["com"], dtype=float), (-1, 3)), (nb, 3), f"{where}.com"
        )
        inert_raw = np.reshape(np.asarray(d["inertia"], dtype=float), (-1, 6))
        if inert_raw.shape[0] != nb:
            raise ValueError(f"{where}.inertia: expected {nb} tensors")
        inertia = np.stack(
            [_inertia_tensor(inert_raw[k], f"{where}.inertia[{k}]") for k in range(nb)]
        )
        axis = _unit(_array(d["axis"], (3,), f"{where}.axis")) if "axis" in d else None
        elbow = _array(d["elbow"], (3,), f"{where}.elbow") if "elbow" in d else None
        extra: dict[str, Any] = {}
        if leg == "UPS":
            length = float(np.linalg.norm(plat - base))
            if length <= 0:
                raise ValueError(f"{where}: zero leg length")
            u = _check_u(
                _array(d["u_axes"], (2, 3), f"{where}.u_axes"), (plat - base) / length, where
            )
        else:
            assert elbow is not None
            assert axis is not None
            length = float(np.linalg.norm(plat - elbow))
            if length <= 0:
                raise ValueError(f"{where}: zero rod length")
            u = None
            if leg in ("RUS", "PUS"):
                e0 = (plat - elbow) / length
                u = _check_u(_array(d["u_axes"], (2, 3), f"{where}.u_axes"), e0, where)
            else:
                width = float(_array(d["width"], (), f"{where}.width"))
                rod_mass = float(_array(d["rod_mass"], (), f"{where}.rod_mass"))
                rod_com = float(_array(d["rod_com"], (), f"{where}.rod_com"))
                rod_inertia = float(_array(d["rod_inertia"], (), f"{where}.rod_inertia"))
                if width <= 0 or rod_mass <= 0 or rod_inertia <= 0:
                    raise ValueError(f"{where}: width, rod_mass, rod_inertia must be positive")
                bar = axis if leg == "RSS2" else _unit(_array(d["bar"], (3,), f"{where}.bar"))
                extra = {
                    "width": width,
                    "bar": bar,
                    "rod_mass": rod_mass,
                    "rod_com": rod_com,
                    "rod_inertia": rod_inertia,
                }
        lg = Leg(
            base=base,
            axis=axis,
            u_axes=u,
            elbow=elbow,
            platform=plat,
            mass=mass,
            com=com,
            inertia=inertia,
            length=length,
            **extra,
        )
        if leg != "UPS":
            assert elbow is not None
            assert axis is not None
            J = _cross(axis, elbow - base) if leg in ("RUS", "RSS2") else axis
            D = float((plat - elbow) @ J)
            if abs(D) <= 1e-9 * length * max(float(np.linalg.norm(J)), 1e-300):
                raise ValueError(f"{where}: D = (S - E) . dE/dq1 = 0 at home (singular leg)")
            lg = Leg(**{**lg.__dict__, "home_sign": math.copysign(1.0, D)})
        legs.append(lg)
    pl = model.get("platform")
    if pl is None:
        raise ValueError("platform: missing")
    _check_keys(pl, _PLATFORM_KEYS, "platform")
    for key in _PLATFORM_KEYS:
        if key not in pl:
            raise ValueError(f"platform.{key}: missing")
    pm = float(_array(pl["mass"], (), "platform.mass"))
    if pm <= 0:
        raise ValueError("platform.mass: must be positive")
    env = model.get("environment", {})
    _check_keys(env, {"gravity"}, "environment")
    pay = model.get("payload", {})
    _check_keys(pay, {"force", "moment"}, "payload")
    return Robot(
        name=str(model.get("name", "")),
        leg=leg,
        actuated=int(actuated),
        legs=tuple(legs),
        platform_mass=pm,
        platform_com=_array(pl["com"], (3,), "platform.com"),
        platform_inertia=_inertia_tensor(pl["inertia"], "platform.inertia"),
        gravity=_array(env.get("gravity", DEFAULT_GRAVITY), (3,), "environment.gravity"),
        payload_force=_array(pay.get("force", (0.0, 0.0, 0.0)), (3,), "payload.force"),
        payload_moment=_array(pay.get("moment", (0.0, 0.0, 0.0)), (3,), "payload.moment"),
        leg_names=names,
    )


RobotLike = Robot | Mapping[str, Any]
"""A parsed :class:`Robot` or a model dict (parsed on use)."""


def as_robot(robot: RobotLike) -> Robot:
    """``robot`` itself if already parsed, else :func:`parse_model` of the dict."""
    return robot if isinstance(robot, Robot) else parse_model(robot)


# ------------------------------------------------------------------------------------------------
# Body and joint states of one sample.


@dataclass
class RigidState:
    """A rigid body's motion at one sample: rotation from home ``R``, angular velocity ``w`` and
    acceleration ``al`` (world), and the material point whose home position is ``h`` at ``X``
    with velocity ``V`` and acceleration ``A``."""

    mass: float
    com_home: np.ndarray
    inertia_home: np.ndarray
    R: np.ndarray
    w: np.ndarray
    al: np.ndarray
    h: np.ndarray
    X: np.ndarray
    V: np.ndarray
    A: np.ndarray

    def point(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration of the body's point at ``p`` at home."""
        r = self.R @ (np.asarray(p, dtype=float) - self.h)
        return (
            self.X + r,
            self.V + _cross(self.w, r),
            self.A + _cross(self.al, r) + _cross(self.w, _cross(self.w, r)),
        )

    @property
    def inertia(self) -> np.ndarray:
        """Current inertia tensor about the COM, world axes."""
        return self.R @ self.inertia_home @ self.R.T


@dataclass
class RodState:
    """A Delta rod at one sample: centre of mass motion and unit direction ``u`` (upper to lower
    S) with its first two derivatives."""

    mass: float
    inertia: float
    c: np.ndarray
    vc: np.ndarray
    ac: np.ndarray
    u: np.ndarray
    du: np.ndarray
    ddu: np.ndarray


@dataclass
class JointState:
    """A joint at one sample: ``earlier`` / ``later`` body indices (-1 = the fixed base), kind
    ``S``, ``U``, ``R`` or ``P``, the current point, the current axes (U: two, R/P: one) and
    whether it is actuated."""

    earlier: int
    later: int
    kind: str
    point: np.ndarray
    axes: tuple[np.ndarray, ...]
    actuated: bool


@dataclass
class Sample:
    """Everything of one sample: bodies (the platform last), joints per leg, the joint
    coordinates (by output name), the actuated coordinates and rates (one per leg)."""

    bodies: list[RigidState | RodState]
    joints: list[list[JointState]]
    coords: dict[str, float]
    qa: np.ndarray
    qad: np.ndarray
    ok: bool


_NAN3 = np.full(3, np.nan)
_EYE3 = np.eye(3)


def _u_angles(u: np.ndarray, e0: np.ndarray, e: np.ndarray) -> tuple[float, float]:
    """U angles (a, b) with ``Rot(u1, a) Rot(u2, b) e0 = e`` (``e0 . u2 = 0``; ``e`` in the
    earlier body's home axes)."""
    u1, u2 = u
    w = _cross(u1, u2)
    gamma = math.atan2(float(e0 @ w), float(e0 @ u1))
    sigma = math.copysign(1.0, float(e0 @ w))
    e1, e2, e3 = float(e @ u1), float(e @ u2), float(e @ w)
    s = sigma * math.hypot(e2, e3)
    a = math.atan2(-e2 / s, e3 / s)
    b = gamma - math.atan2(s, e1)
    b = math.pi - (math.pi - b) % (2 * math.pi)
    return a, b


def _u_rates(
    u1c: np.ndarray, u2c: np.ndarray, e: np.ndarray, rhs: np.ndarray
) -> tuple[float, float]:
    """``(x1, x2)`` with ``x1 u1c x e + x2 u2c x e = rhs`` (consistent, 3 equations: solved by
    the 2 x 2 normal equations, which are well conditioned under the U assumption)."""
    c1, c2 = _cross(u1c, e), _cross(u2c, e)
    a11, a12, a22 = float(c1 @ c1), float(c1 @ c2), float(c2 @ c2)
    b1, b2 = float(c1 @ rhs), float(c2 @ rhs)
    det = a11 * a22 - a12 * a12
    return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det


def _platform_state(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> RigidState:
    if robot.dof == 6:
        R = euler_matrix(q[3], q[4], q[5])
        w = angular_velocity(q, qd)
        al = angular_acceleration(q, qd, qdd)
    else:
        R, w, al = np.eye(3), np.zeros(3), np.zeros(3)
    return RigidState(
        robot.platform_mass,
        robot.platform_com,
        robot.platform_inertia,
        R,
        w,
        al,
        np.zeros(3),
        q[:3].copy(),
        qd[:3].copy(),
        qdd[:3].copy(),
    )


def _joint1(
    leg: Leg, kind: str, S: np.ndarray, home_sign: float
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, float]:
    """Joint 1 of an R / P leg reaching ``S`` with its elbow: ``(q1, E, J, H, D)``, ``J, H`` the
    first and second derivatives of the elbow ``E`` with respect to ``q1``. NaN if unreachable."""
    assert leg.axis is not None
    assert leg.elbow is not None
    k, L = leg.axis, leg.length
    if kind == "R":
        r0 = leg.elbow - leg.base
        rpar = float(r0 @ k)
        rperp = r0 - rpar * k
        w = S - leg.base - rpar * k
        A = 2.0 * float(w @ rperp)
        B = 2.0 * float(w @ _cross(k, rperp))
        C = float(w @ w + rperp @ rperp - L * L)
        rho = math.hypot(A, B)
        if rho == 0.0 or abs(C) > rho:
            return math.nan, _NAN3, _NAN3, _NAN3, math.nan
        phi0, dphi = math.atan2(B, A), math.acos(C / rho)
        for t in (phi0 + dphi, phi0 - dphi):
            t = math.pi - (math.pi - t) % (2 * math.pi)
            E = leg.base + rot(k, t) @ r0
            J = _cross(k, E - leg.base)
            D = float((S - E) @ J)
            if D * home_sign > 0:
                return t, E, J, _cross(k, J), D
        return math.nan, _NAN3, _NAN3, _NAN3, math.nan
    w = S - leg.elbow
    kw = float(k @ w)
    disc = kw * kw - float(w @ w) + L * L
    if disc < 0:
        return math.nan, _NAN3, _NAN3, _NAN3, math.nan
    s = kw - home_sign * math.sqrt(disc)
    E = leg.elbow + s * k
    return s, E, k.copy(), np.zeros(3), float((S - E) @ k)


def sample_state(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> Sample:
    """Kinematics of every body and joint at one sample (pose, rates, accelerations)."""
    plat = _platform_state(robot, q, qd, qdd)
    bodies: list[RigidState | RodState] = []
    joints: list[list[JointState]] = []
    coords: dict[str, float] = {}
    qa, qad = [], []
    ok = True
    ground = -1
    for name, lg in zip(robot.leg_names, robot.legs, strict=True):
        S, Sd, Sdd = plat.point(lg.platform)
        i0 = len(bodies)
        if robot.leg == "UPS":
            assert lg.u_axes is not None
            B = lg.base
            d = S - B
            l_ = float(np.linalg.norm(d))
            e0 = (lg.platform - B) / lg.length
            e = d / l_
            ld = float(e @ Sd)
            ed = (Sd - ld * e) / l_
            ldd = float(e @ Sdd) + (float(Sd @ Sd) - ld * ld) / l_
            edd = (Sdd - ldd * e - 2.0 * ld * ed) / l_
            a, b = _u_angles(lg.u_axes, e0, e)
            u1, u2 = lg.u_axes
            u2c = rot(u1, a) @ u2
            Rc = rot(u1, a) @ rot(u2, b)
            da, db = _u_rates(u1, u2c, e, ed)
            wc = da * u1 + db * u2c
            bias = db * da * _cross(u1, u2c)
            rhs = edd - _cross(wc, _cross(wc, e)) - _cross(bias, e)
            dda, ddb = _u_rates(u1, u2c, e, rhs)
            alc = dda * u1 + ddb * u2c + bias
            q2 = l_ - lg.length
            cyl = RigidState(
                lg.mass[0], lg.com[0], lg.inertia[0], Rc, wc, alc, B, B, np.zeros(3), np.zeros(3)
            )
            pis = RigidState(
                lg.mass[1],
                lg.com[1],
                lg.inertia[1],
                Rc,
                wc,
                alc,
                B,
                B + q2 * e,
                ld * e + q2 * ed,
                ldd * e + 2.0 * ld * ed + q2 * edd,
            )
            bodies += [cyl, pis]
            joints.append(
                [
                    JointState(ground, i0, "U", B.copy(), (u1.copy(), u2c), False),
                    JointState(i0, i0 + 1, "P", B + q2 * e, (e,), True),
                    JointState(i0 + 1, -2, "S", S, (), False),
                ]
            )
            rv = _rotvec(Rc.T @ plat.R)
            coords.update(
                {
                    f"q1a_{name}": a,
                    f"q1b_{name}": b,
                    f"q2_{name}": q2,
                    f"qd2_{name}": ld,
                    f"qdd2_{name}": ldd,
                    f"q3x_{name}": rv[0],
                    f"q3y_{name}": rv[1],
                    f"q3z_{name}": rv[2],
                }
            )
            qa.append(q2)
            qad.append(ld)
            continue

        kind = robot.leg[0]
        assert lg.axis is not None
        assert lg.elbow is not None
        k = lg.axis
        q1, E, J, H, D = _joint1(lg, kind, S, lg.home_sign)
        if not math.isfinite(q1):
            ok = False
        rel = S - E
        qd1 = float(rel @ Sd) / D
        Ed = qd1 * J
        qdd1 = (float((Sd - Ed) @ (Sd - Ed)) + float(rel @ Sdd) - qd1 * qd1 * float(rel @ H)) / D
        Edd = qdd1 * J + qd1 * qd1 * H
        if kind == "R":
            R1 = rot(k, q1) if math.isfinite(q1) else np.full((3, 3), np.nan)
            body1 = RigidState(
                lg.mass[0],
                lg.com[0],
                lg.inertia[0],
                R1,
                qd1 * k,
                qdd1 * k,
                lg.base,
                lg.base.copy(),
                np.zeros(3),
                np.zeros(3),
            )
            j1 = JointState(ground, i0, "R", lg.base.copy(), (k,), True)
        else:
            body1 = RigidState(
                lg.mass[0],
                lg.com[0],
                lg.inertia[0],
                np.eye(3),
                np.zeros(3),
                np.zeros(3),
                lg.base,
                lg.base + q1 * k,
                qd1 * k,
                qdd1 * k,
            )
            j1 = JointState(ground, i0, "P", lg.base + q1 * k, (k,), True)
        bodies.append(body1)
        coords.update({f"q1_{name}": q1, f"qd1_{name}": qd1, f"qdd1_{name}": qdd1})
        qa.append(q1)
        qad.append(qd1)
        L = lg.length
        e, ed, edd = rel / L, (Sd - Ed) / L, (Sdd - Edd) / L
        if robot.leg in ("RUS", "PUS"):
            assert lg.u_axes is not None
            u1, u2 = lg.u_axes
            R1, w1, al1 = body1.R, body1.w, body1.al
            e0 = (lg.platform - lg.elbow) / L
            a, b = _u_angles(lg.u_axes, e0, R1.T @ e)
            u1c = R1 @ u1
            u2c = R1 @ rot(u1, a) @ u2
            Rr = R1 @ rot(u1, a) @ rot(u2, b)
            da, db = _u_rates(u1c, u2c, e, ed - _cross(w1, e))
            wr = w1 + da * u1c + db * u2c
            bias = al1 + da * _cross(w1, u1c) + db * _cross(w1 + da * u1c, u2c)
            rhs = edd - _cross(wr, _cross(wr, e)) - _cross(bias, e)
            dda, ddb = _u_rates(u1c, u2c, e, rhs)
            alr = bias + dda * u1c + ddb * u2c
            rod = RigidState(
                lg.mass[1], lg.com[1], lg.inertia[1], Rr, wr, alr, lg.elbow, E, Ed, Edd
            )
            bodies.append(rod)
            joints.append(
                [
                    j1,
                    JointState(i0, i0 + 1, "U", E.copy(), (u1c, u2c), False),
                    JointState(i0 + 1, -2, "S", S, (), False),
                ]
            )
            rv = _rotvec(Rr.T @ plat.R) if ok else _NAN3
            coords.update(
                {
                    f"q2a_{name}": a,
                    f"q2b_{name}": b,
                    f"q3x_{name}": rv[0],
                    f"q3y_{name}": rv[1],
                    f"q3z_{name}": rv[2],
                }
            )
            continue
        # Deltas: two rods, upper S on the arm / carriage, lower S on the platform.
        assert lg.bar is not None
        bar = lg.bar
        half = 0.5 * lg.width
        rods_j: list[JointState] = []
        low_j: list[JointState] = []
        for s in (1.0, -1.0):
            U_ = E + s * half * bar  # bar fixed: the arm turns about it / the carriage translates
            Lo = S + s * half * bar
            f = lg.rod_com
            idx = len(bodies)
            bodies.append(
                RodState(
                    lg.rod_mass,
                    lg.rod_inertia,
                    U_ + f * (Lo - U_),
                    Ed + f * (Sd - Ed),
                    Edd + f * (Sdd - Edd),
                    e,
                    ed,
                    edd,
                )
            )
            rods_j.append(JointState(i0, idx, "S", U_, (), False))
            low_j.append(JointState(idx, -2, "S", Lo, (), False))
        joints.append([j1, *rods_j, *low_j])
    bodies.append(plat)
    ip = len(bodies) - 1
    for leg_joints in joints:
        for j in leg_joints:
            if j.later == -2:
                j.later = ip
    return Sample(bodies, joints, coords, np.array(qa), np.array(qad), ok)


# ------------------------------------------------------------------------------------------------
# Newton-Euler.


def _as_poses(robot: Robot, q: Any) -> np.ndarray:
    k = robot.dof
    arr = np.asarray(q, dtype=float)
    arr = arr.reshape(1, -1) if arr.ndim == 1 else arr
    if arr.ndim != 2 or arr.shape[1] != k:
        raise ValueError(f"expected poses of shape (n, {k}) or ({k},), got {np.shape(q)}")
    return arr


def newton_euler_system(robot: Robot, smp: Sample) -> tuple[np.ndarray, np.ndarray]:
    """The linear system ``A x = b`` of one sample.

    Unknowns ``x``: per leg and joint (leg-major) the force and moment ``(f, m)`` exerted by the
    earlier body on the later one (world components, moment about the joint's point), then one
    effort per leg. Rows: per body the force and moment (about its COM) equations, then the
    joint constraints (S: ``m = 0``; U: ``m . axis = 0`` for both current axes; R: ``m . axis``,
    P: ``f . axis`` equal to ``tau`` if actuated, else 0).
    """
    nb = len(smp.bodies)
    flat = [(li, j) for li, leg_joints in enumerate(smp.joints) for j in leg_joints]
    nj = len(flat)
    nu = 6 * nj + len(smp.joints)
    ncon = sum({"S": 3, "U": 2}.get(j.kind, 1) for _, j in flat)
    A = np.zeros((6 * nb + ncon, nu))
    b = np.zeros(6 * nb + ncon)
    coms = []
    g = robot.gravity
    for ib, bd in enumerate(smp.bodies):
        if isinstance(bd, RigidState):
            c, _, ac = bd.point(bd.com_home)
            Iw = bd.inertia
            fr = bd.mass * (ac - g)
            mr = Iw @ bd.al + _cross(bd.w, Iw @ bd.w)
            if ib == nb - 1:  # the platform: the payload wrench (force at the frame origin)
                fr = fr - robot.payload_force
                mr = mr - robot.payload_moment - _cross(bd.X - c, robot.payload_force)
        else:
            c, ac = bd.c, bd.ac
            fr = bd.mass * (ac - g)
            mr = bd.inertia * _cross(bd.u, bd.ddu)
        b[6 * ib : 6 * ib + 3] = fr
        b[6 * ib + 3 : 6 * ib + 6] = mr
        coms.append(c)
    row = 6 * nb
    for jj, (li, jt) in enumerate(flat):
        cf, cm = 6 * jj, 6 * jj + 3
        for body, sign in ((jt.later, 1.0), (jt.earlier, -1.0)):
            if body < 0:
                continue
            r0 = 6 * body
            A[r0 : r0 + 3, cf : cf + 3] += sign * _EYE3
            A[r0 + 3 : r0 + 6, cm : cm + 3] += sign * _EYE3
            A[r0 + 3 : r0 + 6, cf : cf + 3] += sign * skew(jt.point - coms[body])
        if jt.kind in ("S", "U"):
            for ax in _EYE3 if jt.kind == "S" else jt.axes:
                A[row, cm : cm + 3] = ax
                row += 1
        else:
            start = cm if jt.kind == "R" else cf
            A[row, start : start + 3] = jt.axes[0]
            if jt.actuated:
                A[row, 6 * nj + li] = -1.0
            row += 1
    return A, b


def _one_thread() -> contextlib.AbstractContextManager[Any]:
    """A context limiting BLAS to one thread (much faster for these small systems)."""
    if threadpool_limits is None:  # pragma: no cover
        return contextlib.nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def _solve_sample(robot: Robot, smp: Sample) -> tuple[np.ndarray, float]:
    A, b = newton_euler_system(robot, smp)
    x, _, rank, _ = scipy.linalg.lstsq(A, b, lapack_driver="gelsy")
    if rank < A.shape[1]:
        raise ValueError(f"Newton-Euler system of rank {rank} < {A.shape[1]} (singular pose)")
    res = float(np.linalg.norm(A @ x - b)) / max(float(np.linalg.norm(b)), 1.0)
    return x, res


def solve(
    robot: RobotLike, q: Any, qd: Any, qdd: Any, *, check: bool = True
) -> dict[str, np.ndarray]:
    """Inverse dynamics with every joint load, by Newton-Euler.

    Args:
        robot: a :class:`Robot` or model dict.
        q, qd, qdd: poses, rates, accelerations, (n, 6) (hexapods) or (n, 3) (Deltas), or one
            sample of shape (6,) / (3,).
        check: raise RuntimeError if a sample's relative residual exceeds :data:`RESIDUAL_TOL`.

    Returns:
        Every name of :func:`output_names` -> (n,) array. A pose some leg cannot reach gives NaN
        in every output of that sample.
    """
    robot = as_robot(robot)
    q, qd, qdd = (_as_poses(robot, v) for v in (q, qd, qdd))
    n = q.shape[0]
    names = output_names(robot.leg)
    out = {nm: np.full(n, np.nan) for nm in names}
    with _one_thread():
        for i in range(n):
            smp = sample_state(robot, q[i], qd[i], qdd[i])
            if not smp.ok:
                continue
            x, res = _solve_sample(robot, smp)
            if check and not res <= RESIDUAL_TOL:
                raise RuntimeError(f"Newton-Euler residual {res:.3g} at sample {i}")
            for key, val in smp.coords.items():
                out[key][i] = val
            nj = sum(len(leg_joints) for leg_joints in smp.joints)
            jj = 0
            for li, name in enumerate(robot.leg_names):
                for j in range(1, len(smp.joints[li]) + 1):
                    w = x[6 * jj : 6 * jj + 6]
                    for c, v in zip(("fx", "fy", "fz", "mx", "my", "mz"), w, strict=True):
                        out[f"{c}{j}_{name}"][i] = v
                    jj += 1
                out[f"tau_{name}"][i] = x[6 * nj + li]
    return out


def residuals(robot: RobotLike, q: Any, qd: Any, qdd: Any) -> np.ndarray:
    """Relative residual (n,) of each sample's Newton-Euler least-squares solve."""
    robot = as_robot(robot)
    q, qd, qdd = (_as_poses(robot, v) for v in (q, qd, qdd))
    out = np.full(q.shape[0], np.nan)
    with _one_thread():
        for i in range(q.shape[0]):
            smp = sample_state(robot, q[i], qd[i], qdd[i])
            if smp.ok:
                out[i] = _solve_sample(robot, smp)[1]
    return out


def efforts(robot: RobotLike, out: Mapping[str, np.ndarray]) -> np.ndarray:
    """The efforts ``tau`` (n, legs) from :func:`solve`'s outputs, legs in order."""
    robot = as_robot(robot)
    return np.stack([out[f"tau_{L}"] for L in robot.leg_names], axis=1)


# ------------------------------------------------------------------------------------------------
# Kinematics, energy.


def inverse_kinematics(robot: RobotLike, q: Any) -> dict[str, np.ndarray]:
    """Joint coordinates at poses ``q``: every coordinate output name (``q...``, no rates) ->
    (n,) array (NaN where a leg cannot reach)."""
    robot = as_robot(robot)
    q = _as_poses(robot, q)
    z = np.zeros(robot.dof)
    names = [
        f"{fam}_{L}"
        for fam in coordinate_families(robot.leg)
        if not fam.startswith("qd")
        for L in robot.leg_names
    ]
    out = {nm: np.full(q.shape[0], np.nan) for nm in names}
    for i in range(q.shape[0]):
        smp = sample_state(robot, q[i], z, z)
        for nm in names:
            out[nm][i] = smp.coords[nm]
    return out


def actuated_coordinates(robot: RobotLike, q: Any) -> np.ndarray:
    """The actuated joint coordinates (n, legs): UPS ``q2``, the others ``q1``."""
    robot = as_robot(robot)
    q = _as_poses(robot, q)
    z = np.zeros(robot.dof)
    return np.stack([sample_state(robot, qi, z, z).qa for qi in q])


def actuator_rates(robot: RobotLike, q: Any, qd: Any) -> np.ndarray:
    """The actuated coordinates' rates (n, legs) at poses ``q`` with rates ``qd``."""
    robot = as_robot(robot)
    q, qd = _as_poses(robot, q), _as_poses(robot, qd)
    z = np.zeros(robot.dof)
    return np.stack([sample_state(robot, q[i], qd[i], z).qad for i in range(q.shape[0])])


def actuator_jacobian(robot: RobotLike, q: Any) -> np.ndarray:
    """``d qa / d q`` (n, legs, dof) at poses ``q`` (exact: the rates are linear in ``qd``)."""
    robot = as_robot(robot)
    q = _as_poses(robot, q)
    k = robot.dof
    eye = np.eye(k)
    return np.stack([actuator_rates(robot, np.repeat(qi[None], k, 0), eye).T for qi in q])


def energy(robot: RobotLike, q: Any, qd: Any) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy (n,), (n,) of every moving body (legs, rods, platform).

    Kinetic: ``1/2 m v^2 + 1/2 w^T I w`` (rods: ``1/2 J |u'|^2``); potential: ``-m g . c``.
    """
    robot = as_robot(robot)
    q, qd = _as_poses(robot, q), _as_poses(robot, qd)
    z = np.zeros(robot.dof)
    n = q.shape[0]
    kin, pot = np.full(n, np.nan), np.full(n, np.nan)
    g = robot.gravity
    for i in range(n):
        smp = sample_state(robot, q[i], qd[i], z)
        if not smp.ok:
            continue
        T = V = 0.0
        for bd in smp.bodies:
            if isinstance(bd, RigidState):
                c, v, _ = bd.point(bd.com_home)
                T += 0.5 * bd.mass * float(v @ v) + 0.5 * float(bd.w @ bd.inertia @ bd.w)
            else:
                c, v = bd.c, bd.vc
                T += 0.5 * bd.mass * float(v @ v) + 0.5 * bd.inertia * float(bd.du @ bd.du)
            V -= bd.mass * float(g @ c)
        kin[i], pot[i] = T, V
    return kin, pot


def totals(robot: RobotLike, q: Any, qd: Any) -> dict[str, np.ndarray]:
    """Whole-robot sums over every moving body (n, 3) each: ``first_moment`` ``sum m c``,
    ``momentum`` ``sum m v_c`` and ``angular_momentum`` about the world origin
    ``sum (m c x v_c + I w)`` (rods: ``J u x u'``)."""
    robot = as_robot(robot)
    q, qd = _as_poses(robot, q), _as_poses(robot, qd)
    z = np.zeros(robot.dof)
    n = q.shape[0]
    out = {k: np.full((n, 3), np.nan) for k in ("first_moment", "momentum", "angular_momentum")}
    for i in range(n):
        smp = sample_state(robot, q[i], qd[i], z)
        if not smp.ok:
            continue
        fm, p, L = np.zeros(3), np.zeros(3), np.zeros(3)
        for bd in smp.bodies:
            if isinstance(bd, RigidState):
                c, v, _ = bd.point(bd.com_home)
                spin = bd.inertia @ bd.w
            else:
                c, v = bd.c, bd.vc
                spin = bd.inertia * _cross(bd.u, bd.du)
            fm += bd.mass * c
            p += bd.mass * v
            L += bd.mass * _cross(c, v) + spin
        out["first_moment"][i], out["momentum"][i], out["angular_momentum"][i] = fm, p, L
    return out


def payload_power(robot: RobotLike, q: Any, qd: Any) -> np.ndarray:
    """Power (n,) of the payload wrench: ``F . (x, y, z)' + M . omega``."""
    robot = as_robot(robot)
    q, qd = _as_poses(robot, q), _as_poses(robot, qd)
    p = qd[:, :3] @ robot.payload_force
    if robot.dof == 6:
        p = p + np.array(
            [angular_velocity(a, b) @ robot.payload_moment for a, b in zip(q, qd, strict=True)]
        )
    return p
