"""Independent Newton-Euler reference for ANY planar 3-leg parallel robot (general model format).

Written only from the specification (``shared/spec/interfaces.md``, section "Any planar 3-leg
robot", and ``conventions.md``) with NumPy and SciPy: it imports nothing from ``rpr3gen``,
``derive/`` or ``generated/``, so tests comparing the production code with it check the symbolic
derivation against plain mechanics.

Frames and units: world frame x0 horizontal, y0 up, z0 out of the plane; SI units, radians. Every
vector below is given by its world (x0, y0) components; every moment and angle is about +z0.

The robot. Each leg L in A, B, C is a serial chain ``base -> joint 1 -> body 1 -> joint 2 ->
body 2 -> joint 3 -> platform`` whose joints are R (revolute) or P (prismatic), the same string
``leg`` for the three legs. Everything is given at HOME: platform pose ``(x, y, phi) = (0, 0, 0)``
and every joint coordinate 0. A body's configuration is a planar rigid motion ``g`` taking a
point's home position ``p`` to its current one; at home every ``g`` is the identity and

- R joint j at home point ``P_j``: ``g_j = g_{j-1} o Rot(P_j, q_j)`` (turn about ``P_j``);
- P joint j along the unit home axis ``u_j``: ``g_j = g_{j-1} o Trans(q_j u_j)``: the axis is
  fixed in the earlier body and turns with it (current axis ``R(theta_{j-1}) u_j``).

Joint j's current point is ``g_j(P_j)`` (fixed in the later body; for an R joint it is also fixed
in the earlier one). The platform's motion ``g_3`` is its pose: ``g_3(p) = R(phi) p + (x, y)``.

Loads. ``f_j`` (world components) and ``m_j`` (about joint j's current point) are the force and
moment that the earlier body exerts on the later one through joint j. A passive R joint has
``m_j = 0``; a passive P joint has ``f_j . axis_j = 0``. The actuated joint adds the effort
``tau``: the moment of an R motor, the force along the current axis of a P motor, applied on the
later body (the reaction on the earlier one), positive along the joint's coordinate.

Newton-Euler: seven bodies (two per leg and the platform), three equations each (force x0, y0 and
moment about the centre of mass), 21 unknowns (two constraint components per joint: ``fx, fy``
for R, the normal force and the moment for P; and the three efforts), one dense 21 x 21 solve
per sample.

Choices where the specification leaves room:

- Angle branches: a leg's R coordinates but its last one are in ``(-pi, pi]``; the last is
  ``phi`` minus the others, so they sum to ``phi`` exactly. Compare angles modulo 2 pi
  (:func:`wrap_to_pi`).
- Inverse kinematics in closed form per leg type (circle intersection, quadratic, or 2 x 2
  linear system); of the (at most two) solutions the one whose serial determinant has its home
  sign. A pose a leg cannot reach that way gives NaN rows (no exception).
- Joint rates and accelerations from the serial Jacobian of the chain (no finite differences).
- Architecturally singular structures parse, but :func:`solve`, :func:`task_space` and
  :func:`forward_dynamics` refuse them (ValueError); :func:`newton_euler_system` still builds
  their (singular) system.
- The control form (:func:`task_space`, :func:`forward_dynamics`) comes from the Newton-Euler
  solve (``tau`` is affine in ``qdd``); :func:`mass_matrix_from_energy` is an independent check.
- Functions taking a robot accept a parsed :class:`Robot` or a model dict.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

LEGS: tuple[str, ...] = ("A", "B", "C")
LEG_TYPES: tuple[str, ...] = ("RRR", "RPR", "RRP", "PRR", "PPR", "PRP", "RPP")
SINGULAR_STRUCTURES: dict[tuple[str, int], str] = {
    ("PPR", 3): "the only revolute joint (3) is actuated",
    ("PRP", 2): "the only revolute joint (2) is actuated",
    ("RPP", 1): "the only revolute joint (1) is actuated",
}
"""Architecturally singular ``(leg, actuated)`` pairs: every motor measures only the platform
angle (the leg's only R coordinate equals ``phi``), the platform's translation is uncontrolled
and the loads are not unique."""

DEFAULT_GRAVITY: tuple[float, float] = (0.0, -9.81)
OUTPUT_FAMILIES: tuple[str, ...] = (
    *(f"{fam}{j}" for fam in ("q", "qd", "qdd", "fx", "fy", "m") for j in (1, 2, 3)),
    "tau",
)
"""Families of :func:`solve`'s outputs; the output names are ``f"{family}_{leg}"``."""

_MODEL_KEYS = {"name", "leg", "actuated", "legs", "platform", "environment", "payload", "limits"}
_LEG_KEYS = {"joints", "axes", "mass", "com", "inertia"}
_PLATFORM_KEYS = {"mass", "com", "inertia"}


# ------------------------------------------------------------------------------------------------
# Small planar helpers.


def wrap_to_pi(angle: Any) -> np.ndarray:
    """Angle(s) wrapped into ``(-pi, pi]``, rad."""
    return np.pi - np.mod(np.pi - np.asarray(angle, dtype=float), 2 * np.pi)


def _perp(a: np.ndarray) -> np.ndarray:
    """``a`` turned by +90 deg about z0 (``z0 x a``), last axis = (x0, y0)."""
    out = np.empty(np.shape(a))
    out[..., 0] = -a[..., 1]
    out[..., 1] = a[..., 0]
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z0 component of ``a x b`` for in-plane vectors (last axis)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.sum(a * b, axis=-1)


def _rotate(theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R(theta) v`` for angles (n,) and vectors (2,) or (n, 2) -> (n, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    v = np.asarray(v, dtype=float)
    out = np.empty((*np.shape(theta), 2))
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    return out


def _angle(v: np.ndarray) -> np.ndarray:
    return np.arctan2(v[..., 1], v[..., 0])


# ------------------------------------------------------------------------------------------------
# The model.


@dataclass(frozen=True)
class Leg:
    """One leg at home (world frame, SI units).

    Attributes:
        joints: (3, 2) points of joints 1, 2, 3.
        axes: (3, 2) unit axes of the P joints (rows of R joints are zero).
        mass: (2,) masses of bodies 1, 2.
        com: (2, 2) their centres of mass.
        inertia: (2,) their moments of inertia about their centres of mass, axis z0.
    """

    joints: np.ndarray
    axes: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class Robot:
    """A parsed, validated general model (see :func:`parse_model`).

    Attributes:
        name: model name.
        leg: joint types from base to platform, e.g. ``"RPR"``.
        actuated: the actuated joint of every leg, 1, 2 or 3.
        legs: legs A, B, C.
        platform_mass, platform_com, platform_inertia: the platform (com in the platform frame,
            inertia about the com).
        gravity: (2,) m/s^2, world.
        payload_force: (2,) N, world, applied at G.
        payload_moment: N m about z0.
        home_sign: (3,) sign of each leg's serial determinant at home (the working mode).
    """

    name: str
    leg: str
    actuated: int
    legs: tuple[Leg, Leg, Leg]
    platform_mass: float
    platform_com: np.ndarray
    platform_inertia: float
    gravity: np.ndarray
    payload_force: np.ndarray
    payload_moment: float
    home_sign: np.ndarray

    @property
    def singular_structure(self) -> str | None:
        """Why ``(leg, actuated)`` is architecturally singular, or None."""
        return SINGULAR_STRUCTURES.get((self.leg, self.actuated))

    @property
    def revolute(self) -> tuple[bool, bool, bool]:
        """Per joint 1, 2, 3: True for R."""
        return tuple(c == "R" for c in self.leg)  # type: ignore[return-value]

    @property
    def scale(self) -> float:
        """A characteristic length, m: mean distance from joint 1 to joint 3 at home."""
        return float(np.mean([np.linalg.norm(lg.joints[2] - lg.joints[0]) for lg in self.legs]))

    @property
    def platform_radius(self) -> float:
        """RMS distance of the platform joints (joint 3 points at home) from G, m."""
        return float(np.sqrt(np.mean([np.sum(lg.joints[2] ** 2) for lg in self.legs])))


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


def _check_keys(d: Mapping[str, Any], allowed: set[str], where: str) -> None:
    if not isinstance(d, Mapping):
        raise ValueError(f"{where}: expected a table")
    unknown = sorted(set(d) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown key {unknown[0]!r}")


def expand_symmetric(
    leg_dict: Mapping[str, Any], rotations_deg: Sequence[float] = (0.0, 120.0, 240.0)
) -> dict[str, dict[str, Any]]:
    """Legs A, B, C made from one leg turned about the world origin.

    Args:
        leg_dict: one leg in the explicit form (``joints``, ``axes``, ``mass``, ``com``,
            ``inertia``; world frame at home).
        rotations_deg: rotation of legs A, B, C about +z0 through the origin, degrees.

    Returns:
        ``{"A": ..., "B": ..., "C": ...}``: points, axes and centres of mass turned, masses and
        inertias copied (plain lists of floats).
    """
    if len(rotations_deg) != 3:
        raise ValueError("rotations_deg: expected three angles")
    out: dict[str, dict[str, Any]] = {}
    for name, deg in zip(LEGS, rotations_deg, strict=True):
        th = math.radians(float(deg))
        R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        new: dict[str, Any] = {}
        for key, value in leg_dict.items():
            if key in ("joints", "axes", "com"):
                new[key] = (np.asarray(value, dtype=float) @ R.T).tolist()
            else:
                new[key] = np.asarray(value, dtype=float).tolist()
        out[name] = new
    return out


def parse_model(model: Mapping[str, Any]) -> Robot:
    """Validate a general model dict (parsed TOML, explicit legs) into a :class:`Robot`.

    Args:
        model: keys ``name`` (optional), ``leg``, ``actuated``, ``legs`` (``A``, ``B``, ``C``),
            ``platform``, ``environment`` (optional, ``gravity``), ``payload`` (optional,
            ``force``, ``moment``), ``limits`` (optional, ignored here). Any other key is an error.

    Returns:
        The robot. Architecturally singular structures are accepted (see
        :attr:`Robot.singular_structure`; :func:`solve` refuses them).

    Raises:
        ValueError: naming the offending key, for a malformed model or a serial determinant
            ``D = 0`` at home.
    """
    _check_keys(model, _MODEL_KEYS, "model")
    leg = model.get("leg")
    if leg not in LEG_TYPES:
        raise ValueError(f"leg: expected one of {LEG_TYPES}, got {leg!r}")
    actuated = model.get("actuated")
    if isinstance(actuated, bool) or actuated not in (1, 2, 3):
        raise ValueError(f"actuated: expected 1, 2 or 3, got {actuated!r}")
    legs_d = model.get("legs")
    if not isinstance(legs_d, Mapping) or set(legs_d) != set(LEGS):
        raise ValueError("legs: expected exactly the tables A, B, C")
    legs = []
    for name in LEGS:
        d = legs_d[name]
        where = f"legs.{name}"
        _check_keys(d, _LEG_KEYS, where)
        for key in ("joints", "mass", "com", "inertia"):
            if key not in d:
                raise ValueError(f"{where}.{key}: missing")
        joints = _array(d["joints"], (3, 2), f"{where}.joints")
        axes = np.zeros((3, 2))
        if "P" in leg:
            if "axes" not in d:
                raise ValueError(f"{where}.axes: missing (the leg has a prismatic joint)")
            raw = np.asarray(d["axes"], dtype=object)
            if raw.shape[:1] != (3,):
                raise ValueError(f"{where}.axes: expected three entries")
            for j, kind in enumerate(leg):
                if kind == "P":
                    u = _array(d["axes"][j], (2,), f"{where}.axes[{j}]")
                    norm = float(np.hypot(*u))
                    if norm == 0.0:
                        raise ValueError(f"{where}.axes[{j}]: zero axis of a prismatic joint")
                    axes[j] = u / norm
        mass = _array(d["mass"], (2,), f"{where}.mass")
        inertia = _array(d["inertia"], (2,), f"{where}.inertia")
        if np.any(mass <= 0):
            raise ValueError(f"{where}.mass: must be positive")
        if np.any(inertia <= 0):
            raise ValueError(f"{where}.inertia: must be positive")
        com = _array(d["com"], (2, 2), f"{where}.com")
        legs.append(Leg(joints=joints, axes=axes, mass=mass, com=com, inertia=inertia))
    plat = model.get("platform")
    if plat is None:
        raise ValueError("platform: missing")
    _check_keys(plat, _PLATFORM_KEYS, "platform")
    for key in _PLATFORM_KEYS:
        if key not in plat:
            raise ValueError(f"platform.{key}: missing")
    pm = float(_array(plat["mass"], (), "platform.mass"))
    pj = float(_array(plat["inertia"], (), "platform.inertia"))
    if pm <= 0 or pj <= 0:
        raise ValueError("platform: mass and inertia must be positive")
    pc = _array(plat["com"], (2,), "platform.com")
    env = model.get("environment", {})
    _check_keys(env, {"gravity"}, "environment")
    gravity = _array(env.get("gravity", DEFAULT_GRAVITY), (2,), "environment.gravity")
    pay = model.get("payload", {})
    _check_keys(pay, {"force", "moment"}, "payload")
    force = _array(pay.get("force", (0.0, 0.0)), (2,), "payload.force")
    moment = float(_array(pay.get("moment", 0.0), (), "payload.moment"))
    robot = Robot(
        name=str(model.get("name", "")),
        leg=leg,
        actuated=int(actuated),
        legs=(legs[0], legs[1], legs[2]),
        platform_mass=pm,
        platform_com=pc,
        platform_inertia=pj,
        gravity=gravity,
        payload_force=force,
        payload_moment=moment,
        home_sign=np.zeros(3),
    )
    D = serial_determinant_at(robot, [np.zeros((1, 3))] * 3)[0]
    norm = np.array([normalised_determinant(robot, i, D[i]) for i in range(3)])
    for i, name in enumerate(LEGS):
        if not abs(norm[i]) > 1e-9:
            raise ValueError(f"legs.{name}: serial determinant D = 0 at home (singular leg)")
    return replace(robot, home_sign=np.sign(D))


RobotLike = Robot | Mapping[str, Any]
"""A parsed :class:`Robot` or a model dict (parsed on use)."""


def as_robot(robot: RobotLike) -> Robot:
    """``robot`` itself if already parsed, else :func:`parse_model` of the dict."""
    return robot if isinstance(robot, Robot) else parse_model(robot)


# ------------------------------------------------------------------------------------------------
# Chain kinematics.


@dataclass(frozen=True)
class BodyState:
    """Motion of one body of a leg chain, vectorised over n samples (world frame).

    The body is located by an anchor: the material point whose home position is ``home``, at
    ``X`` with velocity ``V`` and acceleration ``A`` (n, 2); ``theta, omega, alpha`` (n,) are its
    orientation from home and its angular velocity and acceleration about z0.
    """

    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    home: np.ndarray
    X: np.ndarray
    V: np.ndarray
    A: np.ndarray

    def point(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration (n, 2) of the body's point whose home position is
        ``p`` (2,)."""
        r = _rotate(self.theta, np.asarray(p, dtype=float) - self.home)
        x = self.X + r
        v = self.V + self.omega[:, None] * _perp(r)
        a = self.A + self.alpha[:, None] * _perp(r) - (self.omega**2)[:, None] * r
        return x, v, a


@dataclass(frozen=True)
class Chain:
    """One leg's chain state: ``bodies[0]`` is the base, ``bodies[3]`` the platform.

    Attributes:
        bodies: four :class:`BodyState`.
        points: (3, n, 2) current points of joints 1, 2, 3 (world).
        axes: (3, n, 2) current unit axes of the joints (rows of R joints: zeros).
    """

    bodies: tuple[BodyState, ...]
    points: np.ndarray
    axes: np.ndarray


def chain(
    robot: Robot,
    i: int,
    qj: np.ndarray,
    qdj: np.ndarray | None = None,
    qddj: np.ndarray | None = None,
) -> Chain:
    """Forward kinematics of leg ``i`` (0, 1, 2 for A, B, C) from its joint coordinates.

    Args:
        robot: the robot.
        i: leg index.
        qj, qdj, qddj: (n, 3) joint coordinates, rates and accelerations (None = zeros).

    Returns:
        The chain's bodies (positions, velocities, accelerations) and joint points and axes.
    """
    qj = np.atleast_2d(np.asarray(qj, dtype=float))
    n = qj.shape[0]
    qdj = np.zeros_like(qj) if qdj is None else np.atleast_2d(np.asarray(qdj, dtype=float))
    qddj = np.zeros_like(qj) if qddj is None else np.atleast_2d(np.asarray(qddj, dtype=float))
    leg = robot.legs[i]
    zero, zero2 = np.zeros(n), np.zeros((n, 2))
    body = BodyState(zero, zero, zero, np.zeros(2), zero2, zero2, zero2)
    bodies = [body]
    points, axes = [], []
    for j, kind in enumerate(robot.leg):
        P = leg.joints[j]
        q, qd, qdd = qj[:, j], qdj[:, j], qddj[:, j]
        xs, vs, as_ = body.point(P)
        if kind == "R":
            body = BodyState(
                body.theta + q, body.omega + qd, body.alpha + qdd, P.copy(), xs, vs, as_
            )
            axes.append(zero2)
        else:
            u = _rotate(body.theta, leg.axes[j])
            nu = _perp(u)
            w, al = body.omega[:, None], body.alpha[:, None]
            q_, qd_, qdd_ = q[:, None], qd[:, None], qdd[:, None]
            X = xs + q_ * u
            V = vs + qd_ * u + q_ * w * nu
            A = as_ + qdd_ * u + 2 * qd_ * w * nu + q_ * al * nu - q_ * w**2 * u
            body = BodyState(body.theta, body.omega, body.alpha, P.copy(), X, V, A)
            axes.append(u)
        bodies.append(body)
        points.append(body.X)
    return Chain(tuple(bodies), np.stack(points), np.stack(axes))


def serial_jacobian(robot: Robot, i: int, qj: np.ndarray) -> np.ndarray:
    """Leg ``i``'s serial Jacobian ``d(x3, y3, theta3)/d(q1, q2, q3)``, (n, 3, 3).

    ``(x3, y3)`` is joint 3's current point, ``theta3`` the platform angle given by the chain.
    Column j: ``(z0 x (X3 - Xj), 1)`` for an R joint, ``(axis_j, 0)`` for a P joint.
    """
    ch = chain(robot, i, qj)
    X3 = ch.points[2]
    cols = []
    for j, kind in enumerate(robot.leg):
        if kind == "R":
            top = _perp(X3 - ch.points[j])
            cols.append(np.concatenate([top, np.ones((X3.shape[0], 1))], axis=1))
        else:
            cols.append(np.concatenate([ch.axes[j], np.zeros((X3.shape[0], 1))], axis=1))
    return np.stack(cols, axis=2)


def serial_determinant_at(robot: Robot, qlegs: Sequence[np.ndarray]) -> np.ndarray:
    """Serial determinants (n, 3) of the legs at given joint coordinates (one (n, 3) per leg)."""
    cols = []
    for i in range(3):
        qj = np.atleast_2d(np.asarray(qlegs[i], dtype=float))
        ok = np.all(np.isfinite(qj), axis=1)
        D = np.full(qj.shape[0], np.nan)
        if np.any(ok):
            D[ok] = np.linalg.det(serial_jacobian(robot, i, qj[ok]))
        cols.append(D)
    return np.stack(cols, axis=1)


def normalised_determinant(robot: Robot, i: int, D: Any) -> np.ndarray:
    """``D / L^(nR - 1)``: leg ``i``'s serial determinant made dimensionless.

    ``D`` has the unit m^(nR - 1) (nR = number of R joints); ``L`` is the leg's home distance from
    joint 1 to joint 3 (or 1 m if that is zero). For two unit P axes it is the sine of the angle
    between them.
    """
    leg = robot.legs[i]
    L = float(np.linalg.norm(leg.joints[2] - leg.joints[0])) or 1.0
    return np.asarray(D, dtype=float) / L ** (robot.leg.count("R") - 1)


# ------------------------------------------------------------------------------------------------
# Inverse kinematics (closed form per leg type, from the chain definition above).


def _as_pose(q: Any) -> np.ndarray:
    q = np.atleast_2d(np.asarray(q, dtype=float))
    if q.ndim != 2 or q.shape[1] != 3:
        raise ValueError("q must have shape (n, 3): (x, y, phi)")
    return q


def _quadratic_roots(b_half: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Roots of ``s^2 + 2 b_half s + c = 0`` (NaN where not real)."""
    disc = b_half**2 - c
    with np.errstate(invalid="ignore"):
        root = np.sqrt(np.where(disc >= 0, disc, np.nan))
    return -b_half + root, -b_half - root


def _leg_candidates(robot: Robot, i: int, q: np.ndarray) -> np.ndarray:
    """The (at most two) joint-coordinate solutions of leg ``i``: (n, 2, 3), NaN if not real.

    ``W`` is joint 3's target point ``(x, y) + R(phi) P3``; with the R coordinates summing to
    ``phi`` each type reduces to a circle intersection, a quadratic or a 2 x 2 linear system.
    """
    leg = robot.legs[i]
    P1, P2, P3 = leg.joints
    u1, u2, u3 = leg.axes
    G, phi = q[:, :2], q[:, 2]
    n = q.shape[0]
    W = G + _rotate(phi, P3)
    out = np.full((n, 2, 3), np.nan)
    kind = robot.leg
    if kind == "RRR":
        # Joint 2 at distance a from P1 and b from W: circle intersection.
        a, b = np.linalg.norm(P2 - P1), np.linalg.norm(P3 - P2)
        d_vec = W - P1
        d = np.linalg.norm(d_vec, axis=1)
        e = d_vec / np.where(d > 0, d, np.nan)[:, None]
        ell = (a**2 - b**2 + d**2) / (2 * d)
        with np.errstate(invalid="ignore"):
            h = np.sqrt(np.where(a**2 - ell**2 >= 0, a**2 - ell**2, np.nan))
        for k, sgn in enumerate((1.0, -1.0)):
            X2 = P1 + ell[:, None] * e + sgn * h[:, None] * _perp(e)
            q1 = wrap_to_pi(_angle(X2 - P1) - _angle(P2 - P1))
            th2 = _angle(W - X2) - _angle(P3 - P2)
            q2 = wrap_to_pi(th2 - q1)
            out[:, k] = np.stack([q1, q2, phi - q1 - q2], axis=1)
    elif kind == "RPR":
        # W - P1 = R(q1) (P3 - P1 + q2 u2).
        d = P3 - P1
        r2 = _dot(W - P1, W - P1)
        for k, q2 in enumerate(_quadratic_roots(np.full(n, d @ u2), d @ d - r2)):
            q1 = wrap_to_pi(_angle(W - P1) - _angle(d + q2[:, None] * u2))
            out[:, k] = np.stack([q1, q2, phi - q1], axis=1)
    elif kind == "RRP":
        # W = P1 + R(q1)(P2 - P1) + R(phi)(P3 - P2) + q3 R(phi) u3.
        V = W - P1 - _rotate(phi, P3 - P2)
        w = _rotate(phi, u3)
        a2 = (P2 - P1) @ (P2 - P1)
        for k, q3 in enumerate(_quadratic_roots(-_dot(V, w), _dot(V, V) - a2)):
            q1 = wrap_to_pi(_angle(V - q3[:, None] * w) - _angle(P2 - P1))
            out[:, k] = np.stack([q1, phi - q1, q3], axis=1)
    elif kind == "PRR":
        # W = q1 u1 + P2 + R(q2)(P3 - P2).
        V = W - P2
        b2 = (P3 - P2) @ (P3 - P2)
        for k, q1 in enumerate(_quadratic_roots(-(V @ u1), _dot(V, V) - b2)):
            q2 = wrap_to_pi(_angle(V - q1[:, None] * u1) - _angle(P3 - P2))
            out[:, k] = np.stack([q1, q2, phi - q2], axis=1)
    else:
        # One R joint, whose coordinate is phi; the two P coordinates solve a 2 x 2 system.
        if kind == "PPR":  # W = P3 + q1 u1 + q2 u2
            cols = (np.broadcast_to(u1, (n, 2)), np.broadcast_to(u2, (n, 2)))
            rhs = W - P3
        elif kind == "PRP":  # W = q1 u1 + P2 + R(phi)(P3 + q3 u3 - P2)
            cols = (np.broadcast_to(u1, (n, 2)), _rotate(phi, u3))
            rhs = W - P2 - _rotate(phi, P3 - P2)
        else:  # RPP: W = P1 + R(phi)(P3 - P1 + q2 u2 + q3 u3)
            cols = (np.broadcast_to(u2, (n, 2)), np.broadcast_to(u3, (n, 2)))
            rhs = _rotate(-phi, W - P1) - (P3 - P1)
        det = _cross(cols[0], cols[1])
        with np.errstate(divide="ignore", invalid="ignore"):
            s = _cross(rhs, cols[1]) / det
            t = _cross(cols[0], rhs) / det
        sol = {"PPR": (s, t, phi), "PRP": (s, phi, t), "RPP": (phi, s, t)}[kind]
        out[:, 0] = out[:, 1] = np.stack(sol, axis=1)
    return out


def inverse_kinematics(robot: RobotLike, q: Any) -> list[np.ndarray]:
    """Joint coordinates of each leg in the model's working mode.

    Convention for angles: every R coordinate of a leg but its last one is in ``(-pi, pi]``; the
    last R coordinate is ``phi`` minus the others, so a leg's R coordinates sum to ``phi``
    exactly (a leg with one R joint has that coordinate equal to ``phi``).

    Args:
        robot: the robot.
        q: (n, 3) platform poses ``(x, y, phi)`` (m, m, rad).

    Returns:
        Legs A, B, C: (n, 3) joint coordinates (rad for R, m for P); NaN rows where the leg cannot
        reach the pose in its working mode (no real solution, or ``D`` of the wrong sign/zero).
    """
    robot = as_robot(robot)
    q = _as_pose(q)
    out = []
    for i in range(3):
        cand = _leg_candidates(robot, i, q)
        n = q.shape[0]
        flat = cand.reshape(2 * n, 3)
        ok = np.all(np.isfinite(flat), axis=1)
        D = np.full(2 * n, np.nan)
        if np.any(ok):
            D[ok] = np.linalg.det(serial_jacobian(robot, i, flat[ok]))
        D = D.reshape(n, 2)
        good = np.sign(D) == robot.home_sign[i]
        pick = np.where(good[:, 0], 0, 1)
        sol = cand[np.arange(n), pick]
        sol[~np.any(good, axis=1)] = np.nan
        out.append(sol)
    return out


def wrap_joint_coordinates(robot: Robot, qj: np.ndarray) -> np.ndarray:
    """``qj`` (n, 3) with its R coordinates wrapped into ``(-pi, pi]`` (P coordinates kept)."""
    qj = np.array(qj, dtype=float)
    for j, kind in enumerate(robot.leg):
        if kind == "R":
            qj[..., j] = wrap_to_pi(qj[..., j])
    return qj


def forward_chain_pose(robot: Robot, i: int, qj: np.ndarray) -> np.ndarray:
    """Platform pose (n, 3) ``(x, y, theta3)`` given by leg ``i``'s chain: G's position (the
    platform point at the world origin at home) and the platform angle (unwrapped sum of R
    coordinates)."""
    ch = chain(robot, i, qj)
    G = ch.bodies[3].point(np.zeros(2))[0]
    return np.concatenate([G, ch.bodies[3].theta[:, None]], axis=1)


def joint_points(robot: RobotLike, q: Any) -> dict[str, np.ndarray]:
    """Current world points of joints 1, 2, 3 of each leg in the working mode.

    Args:
        robot: the robot.
        q: (n, 3) platform poses.

    Returns:
        ``{"A": (n, 3, 2), "B": ..., "C": ...}`` (NaN where unreachable).
    """
    robot = as_robot(robot)
    qlegs = inverse_kinematics(robot, q)
    return {
        name: np.swapaxes(chain(robot, i, qlegs[i]).points, 0, 1) for i, name in enumerate(LEGS)
    }


def serial_determinant(robot: RobotLike, q: Any) -> np.ndarray:
    """Serial determinant ``D = det d(x3, y3, phi)/d(q1, q2, q3)`` of each leg in the working
    mode, (n, 3) (legs A, B, C; NaN where unreachable)."""
    robot = as_robot(robot)
    return serial_determinant_at(robot, inverse_kinematics(robot, q))


@dataclass(frozen=True)
class LegMotion:
    """Joint motion of the three legs for a platform motion (lists over legs A, B, C).

    Attributes:
        q, qd, qdd: per leg (n, 3) joint coordinates, rates and accelerations.
        chains: per leg the :class:`Chain` at that motion.
        serial: per leg the serial Jacobian (n, 3, 3) (:func:`serial_jacobian`).
    """

    q: list[np.ndarray]
    qd: list[np.ndarray]
    qdd: list[np.ndarray]
    chains: list[Chain]
    serial: list[np.ndarray]


def _platform_point_motion(q, qd, qdd, p):
    """Position, velocity, acceleration (n, 2) of the platform point whose home position is p."""
    r = _rotate(q[:, 2], p)
    x = q[:, :2] + r
    v = qd[:, :2] + qd[:, 2:3] * _perp(r)
    a = qdd[:, :2] + qdd[:, 2:3] * _perp(r) - qd[:, 2:3] ** 2 * r
    return x, v, a


def leg_motion(
    robot: RobotLike, q: Any, qd: Any, qdd: Any = None, qlegs: list[np.ndarray] | None = None
) -> LegMotion:
    """Inverse kinematics to second order: joint coordinates, rates and accelerations.

    With ``Js`` the serial Jacobian (:func:`serial_jacobian`) and ``X3`` joint 3's point:
    ``Js qd_leg = (dX3/dt, dphi/dt)`` and ``Js qdd_leg = (d2X3/dt2 - a_bias, d2phi/dt2)``, where
    ``a_bias`` is the acceleration of X3 given by the chain with the leg's rates and zero joint
    accelerations.

    Args:
        robot: the robot.
        q, qd, qdd: (n, 3) platform pose, velocity, acceleration (qdd None = zeros).
        qlegs: the legs' working-mode joint coordinates at ``q`` if already known
            (:func:`inverse_kinematics`), else None.

    Returns:
        The legs' joint motion and chains (chains evaluated with the computed rates and
        accelerations).
    """
    robot = as_robot(robot)
    q = _as_pose(q)
    qd = np.broadcast_to(np.asarray(qd, dtype=float), q.shape)
    qdd = np.zeros_like(q) if qdd is None else np.broadcast_to(np.asarray(qdd, float), q.shape)
    if qlegs is None:
        qlegs = inverse_kinematics(robot, q)
    out = LegMotion([], [], [], [], [])
    for i in range(3):
        qj = qlegs[i]
        bad = ~np.all(np.isfinite(qj), axis=1)
        qj_safe = np.where(bad[:, None], 0.0, qj)
        Js = serial_jacobian(robot, i, qj_safe)
        _, v3, a3 = _platform_point_motion(q, qd, qdd, robot.legs[i].joints[2])
        qdj = np.linalg.solve(Js, np.concatenate([v3, qd[:, 2:3]], axis=1)[..., None])[..., 0]
        bias = chain(robot, i, qj_safe, qdj).bodies[3].point(robot.legs[i].joints[2])[2]
        rhs = np.concatenate([a3 - bias, qdd[:, 2:3]], axis=1)
        qddj = np.linalg.solve(Js, rhs[..., None])[..., 0]
        qdj[bad] = np.nan
        qddj[bad] = np.nan
        out.q.append(qj)
        out.qd.append(qdj)
        out.qdd.append(qddj)
        out.chains.append(chain(robot, i, qj, qdj, qddj))
        out.serial.append(Js)
    return out


# ------------------------------------------------------------------------------------------------
# Newton-Euler.


def _wrench_rows(f: np.ndarray, m: np.ndarray, X: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Force and moment about ``C`` (n, 3) of a force ``f`` at ``X`` plus a couple ``m``."""
    return np.concatenate([f, (m + _cross(X - C, f))[:, None]], axis=1)


def newton_euler_system(
    robot: RobotLike, q: Any, qd: Any, qdd: Any, qlegs: list[np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray, LegMotion]:
    """The 21 x 21 Newton-Euler system ``A x = b`` of the seven bodies.

    Rows: per leg (A, B, C) body 1 then body 2 (force x0, force y0, moment about the body's com),
    then the platform (rows 18-20). Columns: per leg seven unknowns, per joint j two constraint
    components (R: ``fx, fy``; P: the force along ``z0 x axis_j`` and the moment), then the
    actuator effort ``tau`` (column ``7 i + 6``). Each unknown is a load of the earlier body on the
    later one at joint j's current point; the earlier body (unless the base) receives the opposite.
    ``b`` holds ``m (a_com - g)`` and ``J alpha``, minus the payload wrench on the platform.

    Args:
        robot: the robot.
        q, qd, qdd: (n, 3) platform motion.
        qlegs: the legs' joint coordinates at ``q`` if already known, else None.

    Returns:
        ``A`` (n, 21, 21), ``b`` (n, 21) and the legs' motion.
    """
    robot = as_robot(robot)
    q = _as_pose(q)
    qd = np.broadcast_to(np.asarray(qd, dtype=float), q.shape)
    qdd = np.broadcast_to(np.asarray(qdd, dtype=float), q.shape)
    n = q.shape[0]
    motion = leg_motion(robot, q, qd, qdd, qlegs)
    A = np.zeros((n, 21, 21))
    b = np.zeros((n, 21))
    g = robot.gravity
    # Platform rows and its com.
    C3, _, a3 = _platform_point_motion(q, qd, qdd, robot.platform_com)
    prow = 18
    b[:, prow : prow + 2] = robot.platform_mass * (a3 - g) - robot.payload_force
    b[:, prow + 2] = (
        robot.platform_inertia * qdd[:, 2]
        - robot.payload_moment
        - _cross(q[:, :2] - C3, np.broadcast_to(robot.payload_force, (n, 2)))
    )
    ones, zeros = np.ones(n), np.zeros(n)
    ex = np.broadcast_to([1.0, 0.0], (n, 2))
    ey = np.broadcast_to([0.0, 1.0], (n, 2))
    z2 = np.zeros((n, 2))
    for i in range(3):
        leg = robot.legs[i]
        ch = motion.chains[i]
        coms = []
        for k in (1, 2):
            body = ch.bodies[k]
            C, _, aC = body.point(leg.com[k - 1])
            coms.append(C)
            r = 6 * i + 3 * (k - 1)
            b[:, r : r + 2] = leg.mass[k - 1] * (aC - g)
            b[:, r + 2] = leg.inertia[k - 1] * body.alpha
        coms.append(C3)
        rows = (6 * i, 6 * i + 3, prow)  # rows of bodies 1, 2, platform

        def put(col, f, m, j, rows=rows, coms=coms, ch=ch):
            X = ch.points[j]
            A[:, rows[j] : rows[j] + 3, col] += _wrench_rows(f, m, X, coms[j])
            if j > 0:  # reaction on the earlier body
                A[:, rows[j - 1] : rows[j - 1] + 3, col] -= _wrench_rows(f, m, X, coms[j - 1])

        for j, kind in enumerate(robot.leg):
            c0 = 7 * i + 2 * j
            if kind == "R":
                put(c0, ex, zeros, j)
                put(c0 + 1, ey, zeros, j)
            else:
                put(c0, _perp(ch.axes[j]), zeros, j)
                put(c0 + 1, z2, ones, j)
        ja = robot.actuated - 1
        if robot.leg[ja] == "R":
            put(7 * i + 6, z2, ones, ja)
        else:
            put(7 * i + 6, ch.axes[ja], zeros, ja)
    return A, b, motion


def _solve_system(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Batched ``A^-1 b`` (b: (n, 21) or (n, 21, k)); NaN for samples with non-finite A or b."""
    vec = b.ndim == 2
    B = b[..., None] if vec else b
    ok = np.all(np.isfinite(A), axis=(1, 2)) & np.all(np.isfinite(B), axis=(1, 2))
    x = np.full(B.shape, np.nan)
    if np.any(ok):
        x[ok] = np.linalg.solve(A[ok], B[ok])
    return x[..., 0] if vec else x


def _outputs(robot: Robot, x: np.ndarray, motion: LegMotion) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    ja = robot.actuated - 1
    for i, name in enumerate(LEGS):
        xs = x[:, 7 * i : 7 * i + 7]
        tau = xs[:, 6]
        ch = motion.chains[i]
        for j, kind in enumerate(robot.leg):
            a, c = xs[:, 2 * j], xs[:, 2 * j + 1]
            if kind == "R":
                f = np.stack([a, c], axis=1)
                m = tau.copy() if j == ja else np.zeros_like(a)
            else:
                f = a[:, None] * _perp(ch.axes[j])
                if j == ja:
                    f = f + tau[:, None] * ch.axes[j]
                m = c
            out[f"q{j + 1}_{name}"] = motion.q[i][:, j].copy()
            out[f"qd{j + 1}_{name}"] = motion.qd[i][:, j].copy()
            out[f"qdd{j + 1}_{name}"] = motion.qdd[i][:, j].copy()
            out[f"fx{j + 1}_{name}"] = f[:, 0].copy()
            out[f"fy{j + 1}_{name}"] = f[:, 1].copy()
            out[f"m{j + 1}_{name}"] = np.asarray(m, dtype=float)
        out[f"tau_{name}"] = tau.copy()
    return out


def _refuse_singular(robot: Robot) -> None:
    if robot.singular_structure:
        raise ValueError(
            f"structure ({robot.leg}, actuated {robot.actuated}) is architecturally singular: "
            f"{robot.singular_structure}"
        )


def solve(robot: RobotLike, q: Any, qd: Any, qdd: Any) -> dict[str, np.ndarray]:
    """Inverse dynamics by Newton-Euler on the seven bodies.

    Args:
        robot: the robot (not an architecturally singular structure).
        q, qd, qdd: (n, 3) platform pose ``(x, y, phi)``, velocity and acceleration.

    Returns:
        Every output ``f"{family}_{leg}"`` (families :data:`OUTPUT_FAMILIES`) -> (n,) array:
        ``qj, qdj, qddj`` joint coordinate, rate and acceleration; ``fxj, fyj`` (N, world) and
        ``mj`` (N m about joint j's current point): the load of the earlier body on the later
        one through joint j; ``tau`` the actuator effort. NaN rows where a leg cannot reach.

    Raises:
        ValueError: for an architecturally singular structure.
    """
    robot = as_robot(robot)
    _refuse_singular(robot)
    A, b, motion = newton_euler_system(robot, q, qd, qdd)
    return _outputs(robot, _solve_system(A, b), motion)


def efforts(out: Mapping[str, np.ndarray]) -> np.ndarray:
    """(n, 3) actuator efforts ``tau_A, tau_B, tau_C`` from :func:`solve`'s outputs."""
    return np.stack([out[f"tau_{name}"] for name in LEGS], axis=1)


def actuated_rates(robot: Robot, out: Mapping[str, np.ndarray]) -> np.ndarray:
    """(n, 3) rates of the actuated joints of legs A, B, C from :func:`solve`'s outputs."""
    return np.stack([out[f"qd{robot.actuated}_{name}"] for name in LEGS], axis=1)


# ------------------------------------------------------------------------------------------------
# Energy and power.


def _bodies(robot: Robot, motion: LegMotion, q, qd, qdd=None):
    """Yield (mass, inertia, com position, com velocity, com acceleration, omega, alpha)."""
    for i in range(3):
        leg = robot.legs[i]
        for k in (1, 2):
            body = motion.chains[i].bodies[k]
            x, v, a = body.point(leg.com[k - 1])
            yield leg.mass[k - 1], leg.inertia[k - 1], x, v, a, body.omega, body.alpha
    qdd = np.zeros_like(q) if qdd is None else qdd
    x, v, a = _platform_point_motion(q, qd, qdd, robot.platform_com)
    yield robot.platform_mass, robot.platform_inertia, x, v, a, qd[:, 2], qdd[:, 2]


def energy(robot: RobotLike, q: Any, qd: Any) -> np.ndarray:
    """Kinetic plus potential energy of the seven bodies, (n,) J.

    Kinetic: ``m |v_com|^2 / 2 + J omega^2 / 2`` per body; potential ``-m g . r_com`` (zero at
    the world origin).
    """
    robot = as_robot(robot)
    q = _as_pose(q)
    qd = np.broadcast_to(np.asarray(qd, dtype=float), q.shape)
    motion = leg_motion(robot, q, qd)
    E = np.zeros(q.shape[0])
    for m, J, x, v, _, w, _ in _bodies(robot, motion, q, qd):
        E = E + 0.5 * m * _dot(v, v) + 0.5 * J * w**2 - m * (x @ robot.gravity)
    return E


def energy_rate(robot: RobotLike, q: Any, qd: Any, qdd: Any) -> np.ndarray:
    """dE/dt analytically: ``sum m (a - g) . v + J alpha omega`` over the bodies, (n,) W."""
    robot = as_robot(robot)
    q = _as_pose(q)
    qd = np.broadcast_to(np.asarray(qd, dtype=float), q.shape)
    qdd = np.broadcast_to(np.asarray(qdd, dtype=float), q.shape)
    motion = leg_motion(robot, q, qd, qdd)
    P = np.zeros(q.shape[0])
    for m, J, _, v, a, w, al in _bodies(robot, motion, q, qd, qdd):
        P = P + m * _dot(a - robot.gravity, v) + J * al * w
    return P


def input_power(robot: RobotLike, out: Mapping[str, np.ndarray], qd: Any) -> np.ndarray:
    """Power of the actuators and of the payload wrench at G, (n,) W.

    ``sum_L tau_L qd_actuated_L + F . v_G + mz dphi/dt``: equals dE/dt for correct loads.
    """
    robot = as_robot(robot)
    qd = np.atleast_2d(np.asarray(qd, dtype=float))
    P = qd[:, :2] @ robot.payload_force + robot.payload_moment * qd[:, 2]
    return P + np.sum(efforts(out) * actuated_rates(robot, out), axis=1)


# ------------------------------------------------------------------------------------------------
# Control form: actuator Jacobian, task-space dynamics, forward dynamics.


def actuator_jacobian(robot: RobotLike, q: Any) -> np.ndarray:
    """``J = d qa / d q`` (n, 3, 3): row L is leg L's actuated joint rate per platform rate.

    From ``Js qd_leg = K qd`` with ``K = [[1, 0, -r_y], [0, 1, r_x], [0, 0, 1]]``, ``r`` from G to
    joint 3's point: ``J[L] = (Js^-1 K)[actuated - 1]``.
    """
    robot = as_robot(robot)
    q = _as_pose(q)
    return _actuator_jacobian(robot, q, inverse_kinematics(robot, q))


def _actuator_jacobian(
    robot: Robot,
    q: np.ndarray,
    qlegs: list[np.ndarray],
    serial: list[np.ndarray] | None = None,
) -> np.ndarray:
    rows = []
    for i in range(3):
        if serial is None:
            Js = serial_jacobian(robot, i, np.where(np.isfinite(qlegs[i]), qlegs[i], 0.0))
        else:
            Js = serial[i]
        r = _rotate(q[:, 2], robot.legs[i].joints[2])
        K = np.zeros((q.shape[0], 3, 3))
        K[:, 0, 0] = K[:, 1, 1] = K[:, 2, 2] = 1.0
        K[:, 0, 2] = -r[:, 1]
        K[:, 1, 2] = r[:, 0]
        row = np.linalg.solve(Js, K)[:, robot.actuated - 1]
        row[~np.all(np.isfinite(qlegs[i]), axis=1)] = np.nan
        rows.append(row)
    return np.stack(rows, axis=1)


def scaled_actuator_jacobian(robot: RobotLike, q: Any) -> np.ndarray:
    """:func:`actuator_jacobian` made dimensionless: the phi column times ``1/rho`` (platform
    radius) and, for R motors, every row times :attr:`Robot.scale`. Used for conditioning checks
    of random models (not the project's documented measure)."""
    robot = as_robot(robot)
    J = actuator_jacobian(robot, q).copy()
    J[:, :, 2] /= robot.platform_radius
    if robot.leg[robot.actuated - 1] == "R":
        J *= robot.scale
    return J


def task_space(robot: RobotLike, q: Any, qd: Any) -> tuple[np.ndarray, np.ndarray]:
    """Dynamics in platform coordinates: ``M qdd + c = J^T tau``.

    ``tau`` from :func:`solve` is affine in ``qdd``: ``tau = T qdd + tau0``; then ``M = J^T T`` and
    ``c = J^T tau0`` (Coriolis/centrifugal, gravity and payload).

    Returns:
        ``M`` (n, 3, 3) and ``c`` (n, 3).
    """
    robot = as_robot(robot)
    M, c, _ = _task_space(robot, _as_pose(q), qd)
    return M, c


def _task_space(robot: Robot, q: np.ndarray, qd: Any) -> tuple[np.ndarray, ...]:
    """M, c and J at (q, qd): one Newton-Euler system of 4 n samples (qdd = 0, e1, e2, e3)."""
    _refuse_singular(robot)
    qd = np.broadcast_to(np.asarray(qd, dtype=float), q.shape)
    n = q.shape[0]
    qlegs = inverse_kinematics(robot, q)
    qdd = np.zeros((4, n, 3))
    for k in range(3):
        qdd[k + 1, :, k] = 1.0
    A, b, motion = newton_euler_system(
        robot,
        np.tile(q, (4, 1)),
        np.tile(qd, (4, 1)),
        qdd.reshape(4 * n, 3),
        [np.tile(x, (4, 1)) for x in qlegs],
    )
    b = b.reshape(4, n, 21)
    rhs = np.stack([b[0], b[1] - b[0], b[2] - b[0], b[3] - b[0]], axis=2)  # (n, 21, 4)
    x = _solve_system(A[:n], rhs)
    tau = x[:, [6, 13, 20], :]  # (n, 3 legs, 4)
    J = _actuator_jacobian(robot, q, qlegs, [Js[:n] for Js in motion.serial])
    Jt = np.swapaxes(J, 1, 2)
    M = Jt @ tau[:, :, 1:]
    c = (Jt @ tau[:, :, :1])[..., 0]
    return M, c, J


def mass_matrix_from_energy(robot: RobotLike, q: Any) -> np.ndarray:
    """``M`` (n, 3, 3) from the kinetic energy alone: ``sum m Jv^T Jv + J Jw^T Jw`` over bodies,
    with each body's com-velocity and angular-velocity Jacobians (w.r.t. the platform rate) from
    the legs' velocity kinematics. Independent of the Newton-Euler solve."""
    robot = as_robot(robot)
    q = _as_pose(q)
    n = q.shape[0]
    cols: list[list[tuple[float, float, np.ndarray, np.ndarray]]] = []
    for k in range(3):
        e = np.zeros_like(q)
        e[:, k] = 1.0
        motion = leg_motion(robot, q, e)
        cols.append([(m, J, v, w) for m, J, _, v, _, w, _ in _bodies(robot, motion, q, e)])
    M = np.zeros((n, 3, 3))
    for b in range(len(cols[0])):
        m, J = cols[0][b][0], cols[0][b][1]
        Jv = np.stack([cols[k][b][2] for k in range(3)], axis=2)  # (n, 2, 3)
        Jw = np.stack([cols[k][b][3] for k in range(3)], axis=1)  # (n, 3)
        M += m * np.swapaxes(Jv, 1, 2) @ Jv + J * Jw[:, :, None] * Jw[:, None, :]
    return M


def forward_dynamics(robot: RobotLike, q: Any, qd: Any, tau: Any) -> np.ndarray:
    """Platform acceleration ``qdd = M^-1 (J^T tau - c)``, (n, 3)."""
    robot = as_robot(robot)
    q = _as_pose(q)
    tau = np.broadcast_to(np.asarray(tau, dtype=float), q.shape)
    M, c, J = _task_space(robot, q, qd)
    rhs = (np.swapaxes(J, 1, 2) @ tau[..., None])[..., 0] - c
    return np.linalg.solve(M, rhs[..., None])[..., 0]


# ------------------------------------------------------------------------------------------------
# Assembly modes by brute force.


def _closure(robot: Robot, qa: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Loop-closure residuals (s, 9) and Jacobians (s, 9, 9) for s candidate unknowns
    ``z = (x, y, phi, passive joints of A, B, C)`` (s, 9) at actuated coordinates ``qa`` (3,).

    Per leg: the chain's G minus ``(x, y)``, and the chain's platform angle minus ``phi``.
    """
    s = z.shape[0]
    ja = robot.actuated - 1
    passive = [j for j in range(3) if j != ja]
    res = np.zeros((s, 9))
    jac = np.zeros((s, 9, 9))
    for i in range(3):
        qj = np.zeros((s, 3))
        qj[:, ja] = qa[i]
        qj[:, passive] = z[:, 3 + 2 * i : 5 + 2 * i]
        ch = chain(robot, i, qj)
        G = ch.bodies[3].point(np.zeros(2))[0]
        res[:, 3 * i : 3 * i + 2] = G - z[:, :2]
        res[:, 3 * i + 2] = ch.bodies[3].theta - z[:, 2]
        jac[:, 3 * i : 3 * i + 3, :3] = -np.eye(3)
        for k, j in enumerate(passive):
            col = 3 + 2 * i + k
            if robot.leg[j] == "R":
                jac[:, 3 * i : 3 * i + 2, col] = _perp(G - ch.points[j])
                jac[:, 3 * i + 2, col] = 1.0
            else:
                jac[:, 3 * i : 3 * i + 2, col] = ch.axes[j]
    return res, jac


def assembly_modes_bruteforce(
    robot: RobotLike,
    qa: Any,
    *,
    starts: int = 96,
    seed: int = 0,
    iterations: int = 100,
    tol: float = 1e-7,
) -> np.ndarray:
    """Every platform pose whose legs, each in the working mode, have these actuated coordinates.

    Multi-start Levenberg-Marquardt (vectorised over the starts, analytic Jacobian) on the nine
    loop-closure equations in nine unknowns: the pose and the six passive joint coordinates.
    Starts: home with its joint coordinates, then poses uniform in a box of half-width
    ``1.5 *`` :attr:`Robot.scale` around home and all platform angles, with passive coordinates
    from the working-mode inverse kinematics of that pose (every other start, where it exists)
    or random (R uniform in ``(-pi, pi]``, P normal with that scale). A converged solution
    (residual < 1e-10) is kept when the inverse kinematics (working mode) at its pose reproduces
    ``qa`` (R coordinates modulo 2 pi) within ``tol``; duplicates (distance < ``tol`` in
    ``(x, y, rho phi)``, phi modulo 2 pi, ``rho`` the platform radius) are merged.

    Args:
        robot: the robot.
        qa: (3,) actuated joint coordinates of legs A, B, C.
        starts: number of starting points.
        seed: seed of the starting points.
        iterations: Levenberg-Marquardt iterations.
        tol: acceptance and de-duplication tolerance.

    Returns:
        (k, 3) poses ``(x, y, phi)``, phi in ``(-pi, pi]``, sorted by phi then x.
    """
    robot = as_robot(robot)
    qa = np.asarray(qa, dtype=float).reshape(3)
    rng = np.random.default_rng(seed)
    ja = robot.actuated - 1
    passive = [j for j in range(3) if j != ja]
    span = 1.5 * robot.scale
    rho = robot.platform_radius
    poses = np.concatenate(
        [rng.uniform(-span, span, (starts, 2)), rng.uniform(-np.pi, np.pi, (starts, 1))], axis=1
    )
    poses[0] = 0.0
    z = np.zeros((starts, 9))
    z[:, :3] = poses
    qlegs = inverse_kinematics(robot, poses)
    use_ik = np.arange(starts) % 2 == 0
    for i in range(3):
        for k, j in enumerate(passive):
            rand = (
                rng.uniform(-np.pi, np.pi, starts)
                if robot.leg[j] == "R"
                else rng.normal(0.0, span, starts)
            )
            ik = qlegs[i][:, j]
            z[:, 3 + 2 * i + k] = np.where(use_ik & np.isfinite(ik), ik, rand)
    lam = np.full(starts, 1e-3)
    r, J = _closure(robot, qa, z)
    cost = np.sum(r**2, axis=1)
    eye = np.eye(9)
    for _ in range(iterations):
        JtJ = np.swapaxes(J, 1, 2) @ J
        g = (np.swapaxes(J, 1, 2) @ r[..., None])[..., 0]
        H = JtJ + lam[:, None, None] * (
            eye + np.eye(9) * np.diagonal(JtJ, axis1=1, axis2=2)[:, None]
        )
        step = -np.linalg.solve(H, g[..., None])[..., 0]
        r_new, J_new = _closure(robot, qa, z + step)
        cost_new = np.sum(r_new**2, axis=1)
        better = cost_new < cost
        z = np.where(better[:, None], z + step, z)
        r = np.where(better[:, None], r_new, r)
        J = np.where(better[:, None, None], J_new, J)
        cost = np.where(better, cost_new, cost)
        lam = np.clip(np.where(better, lam / 3, lam * 4), 1e-12, 1e12)
        if np.all(cost < 1e-26):
            break
    found: list[np.ndarray] = []
    for k in np.flatnonzero(np.all(np.abs(r) < 1e-10, axis=1)):
        pose = z[k, :3].copy()
        pose[2] = wrap_to_pi(pose[2])
        if any(
            math.hypot(f[0] - pose[0], f[1] - pose[1], rho * wrap_to_pi(f[2] - pose[2])) < tol
            for f in found
        ):
            continue
        qlegs = inverse_kinematics(robot, pose[None])
        diff = np.array([qlegs[i][0, ja] for i in range(3)]) - qa
        if robot.leg[ja] == "R":
            diff = wrap_to_pi(diff)
        if not np.all(np.abs(diff) < tol):
            continue  # some leg is not in the working mode there
        found.append(pose)
    if not found:
        return np.zeros((0, 3))
    modes = np.array(found)
    return modes[np.lexsort((modes[:, 0], modes[:, 2]))]
