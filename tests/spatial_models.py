"""Model and motion generators for the tests of the spatial reference (hexapods and Deltas).

Everything here builds plain model dicts in the model-file format of ``docs/spatial-robots.md``
(world frame, z up, SI units) and checks them with :mod:`spatial_reference` only; it imports
nothing from ``rpr3gen``, ``derive/`` or ``generated/``.

- :func:`random_model` draws an unequal, well-conditioned robot of a leg type: every leg's
  points, axes, masses, centres of mass and full inertia tensors are perturbed independently;
  the U axes are perpendicular, the leg / rod perpendicular to the second U axis and well away
  from the first ("Assumption (the U)").
- :func:`random_motion` draws a smooth sinusoidal motion of small amplitude about home that
  stays well inside the workspace.
- :func:`tsai_ups`, :func:`delta`, :func:`linear_delta`, :func:`rus_hexapod`,
  :func:`pus_hexapod`: gallery-like example models (``symmetric = true``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

try:
    from . import spatial_reference as sr
except ImportError:
    import spatial_reference as sr

LEG_TYPES = sr.LEG_TYPES
MAX_COND_HOME = 12.0
"""Largest condition number of the normalised actuator Jacobian (:func:`conditioning`) of a
random model at home."""
MAX_COND_MOTION = 40.0
"""The same bound along a random motion."""
MIN_REACH = 0.3
"""Smallest ``|D| / (|S - E| |dE/dq1|)`` of a leg (RUS, PUS, Deltas) at home and along motions."""

_EZ = np.array([0.0, 0.0, 1.0])


# ------------------------------------------------------------------------------------------------
# Small helpers.


def _unit(v: Any) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _polar(r: float, deg: float, z: float) -> np.ndarray:
    t = math.radians(deg)
    return np.array([r * math.cos(t), r * math.sin(t), z])


def _random_rotation(rng: np.random.Generator, max_angle: float) -> np.ndarray:
    axis = _unit(rng.normal(size=3))
    return sr.rot(axis, float(rng.uniform(-max_angle, max_angle)))


def _frame_along(d: np.ndarray) -> np.ndarray:
    """A rotation whose third column is the unit ``d``."""
    z = _unit(d)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = _unit(np.cross(helper, z))
    return np.stack([x, np.cross(z, x), z], axis=1)


def _inertia(
    rng: np.random.Generator, mass: float, direction: np.ndarray, length: float, radius: float
) -> list[float]:
    """A full inertia tensor ``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`` of a slender-ish body along
    ``direction``: principal moments of a cylinder, each perturbed, axes tilted randomly."""
    axial = mass * radius**2 / 2 * rng.uniform(0.7, 1.4)
    t1 = mass * (length**2 / 12 + radius**2 / 4) * rng.uniform(0.8, 1.25)
    t2 = t1 + axial * rng.uniform(-0.6, 0.6)  # |t1 - t2| < axial: the triangle inequality
    Q = _frame_along(direction) @ _random_rotation(rng, 0.4)
    return sr.inertia_list(Q @ np.diag([t1, t2, axial]) @ Q.T)


def _plate_inertia(rng: np.random.Generator, mass: float, radius: float) -> list[float]:
    """A full inertia tensor of a plate of about ``radius`` (normal about z), tilted randomly."""
    a = mass * radius**2 / 4 * rng.uniform(0.8, 1.25)
    b = mass * radius**2 / 4 * rng.uniform(0.8, 1.25)
    c = (a + b) * rng.uniform(0.9, 0.98)
    Q = _random_rotation(rng, 0.3)
    return sr.inertia_list(Q @ np.diag([a, b, c]) @ Q.T)


def _u_axes(rng: np.random.Generator, e0: np.ndarray, max_tilt: float = 0.6) -> list[list[float]]:
    """U axes for a leg / rod along ``e0``: the second perpendicular to ``e0`` (horizontal-ish,
    turned randomly about ``e0``), the first perpendicular to it and at least
    ``90 deg - max_tilt`` from ``e0``."""
    e0 = _unit(e0)
    horiz = np.cross(e0, _EZ)
    if np.linalg.norm(horiz) < 1e-6:
        horiz = np.cross(e0, np.array([1.0, 0.0, 0.0]))
    u2 = sr.rot(e0, float(rng.uniform(-0.5, 0.5))) @ _unit(horiz)
    beta = float(rng.uniform(-max_tilt, max_tilt))
    u1 = math.cos(beta) * _unit(np.cross(u2, e0)) + math.sin(beta) * e0
    return [_unit(u1).tolist(), _unit(u2).tolist()]


def _jitter(rng: np.random.Generator, scale: float) -> np.ndarray:
    return rng.uniform(-scale, scale, 3)


def _l(v: Any) -> list[float]:
    return [float(x) for x in np.asarray(v, dtype=float)]


# ------------------------------------------------------------------------------------------------
# Legs of each type.


def _hexapod_layout(
    rng: np.random.Generator | None, rb: float, rp: float, zb: float, zp: float
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Base and platform points of six legs: base pairs at ``120 k -+ 15 deg``, platform pairs at
    ``120 k -+ 45 deg`` (the platform triangle turned by 60 deg), randomly perturbed."""
    out = []
    for i in range(6):
        k, sgn = divmod(i, 2)
        s = -1.0 if sgn == 0 else 1.0
        jb = rng.uniform(-4, 4) if rng is not None else 0.0
        jp = rng.uniform(-4, 4) if rng is not None else 0.0
        B = _polar(rb, 120 * k + s * 15 + jb, zb)
        P = _polar(rp, 120 * k + s * 45 + jp, zp)
        if rng is not None:
            B = B + _jitter(rng, 0.02 * rb)
            P = P + _jitter(rng, 0.02 * rp)
        out.append((B, P))
    return out


def _ups_leg(rng: np.random.Generator, B: np.ndarray, P: np.ndarray) -> dict[str, Any]:
    d = P - B
    length = float(np.linalg.norm(d))
    e0 = d / length
    m1, m2 = rng.uniform(0.5, 2.0), rng.uniform(0.2, 1.0)
    c1 = B + rng.uniform(0.2, 0.35) * d + _jitter(rng, 0.01)
    c2 = B + rng.uniform(0.6, 0.8) * d + _jitter(rng, 0.01)
    return {
        "base": _l(B),
        "u_axes": _u_axes(rng, e0),
        "platform": _l(P),
        "mass": [float(m1), float(m2)],
        "com": [_l(c1), _l(c2)],
        "inertia": [
            _inertia(rng, m1, e0, 0.5 * length, 0.04),
            _inertia(rng, m2, e0, 0.5 * length, 0.025),
        ],
    }


def _crank_leg(
    rng: np.random.Generator,
    kind: str,
    B: np.ndarray,
    axis: np.ndarray,
    E: np.ndarray,
    P: np.ndarray,
    delta: bool,
) -> dict[str, Any]:
    """An R or P leg: joint 1 at ``B`` along ``axis``, elbow ``E``, platform point ``P``."""
    rod = P - E
    L = float(np.linalg.norm(rod))
    if kind == "R":
        arm = E - B
        m1 = rng.uniform(0.3, 1.5)
        c1 = B + rng.uniform(0.35, 0.6) * arm + _jitter(rng, 0.01)
        I1 = _inertia(rng, m1, arm, float(np.linalg.norm(arm)), 0.03)
    else:
        m1 = rng.uniform(0.3, 1.5)
        c1 = E + _jitter(rng, 0.02)
        I1 = _inertia(rng, m1, axis, 0.1, 0.04)
    leg: dict[str, Any] = {"base": _l(B), "axis": _l(axis), "elbow": _l(E), "platform": _l(P)}
    if not delta:
        m2 = rng.uniform(0.1, 0.6)
        c2 = E + rng.uniform(0.4, 0.6) * rod + _jitter(rng, 0.01)
        leg["u_axes"] = _u_axes(rng, rod)
        leg["mass"] = [float(m1), float(m2)]
        leg["com"] = [_l(c1), _l(c2)]
        leg["inertia"] = [I1, _inertia(rng, m2, rod, L, 0.015)]
    else:
        rm = rng.uniform(0.08, 0.3)
        leg["mass"] = [float(m1)]
        leg["com"] = [_l(c1)]
        leg["inertia"] = [I1]
        leg["width"] = float(rng.uniform(0.06, 0.12))
        leg["rod_mass"] = float(rm)
        leg["rod_com"] = float(rng.uniform(0.4, 0.6))
        leg["rod_inertia"] = float(rm * L**2 / 12 * rng.uniform(0.8, 1.2))
    return leg


def _platform(rng: np.random.Generator, radius: float, z: float) -> dict[str, Any]:
    m = float(rng.uniform(0.5, 2.0))
    return {
        "mass": m,
        "com": _l(np.array([0.0, 0.0, z]) + _jitter(rng, 0.1 * radius)),
        "inertia": _plate_inertia(rng, m, radius),
    }


def _environment(rng: np.random.Generator, model: dict[str, Any]) -> dict[str, Any]:
    """Optionally an explicit gravity and a payload (else the defaults)."""
    if rng.uniform() < 0.5:
        model["environment"] = {"gravity": [0.0, 0.0, -9.80665]}
    if rng.uniform() < 0.7:
        model["payload"] = {
            "force": _l(rng.uniform(-5, 5, 3)),
            "moment": _l(rng.uniform(-0.5, 0.5, 3)),
        }
    return model


def random_model_unchecked(leg: str, rng: np.random.Generator) -> dict[str, Any]:
    """One random model of the leg type, without the conditioning checks of
    :func:`random_model`."""
    names = sr.leg_names(leg)
    legs: dict[str, Any] = {}
    if leg == "UPS":
        rb, rp, h = rng.uniform(0.45, 0.6), rng.uniform(0.25, 0.35), rng.uniform(0.6, 0.9)
        for name, (B, P) in zip(names, _hexapod_layout(rng, rb, rp, -h, 0.0), strict=True):
            legs[name] = _ups_leg(rng, B, P)
        plat = _platform(rng, rp, 0.02)
    elif leg == "RUS":
        rb, rp, h = rng.uniform(0.35, 0.45), rng.uniform(0.2, 0.3), rng.uniform(0.45, 0.6)
        for name, (B, P) in zip(names, _hexapod_layout(rng, rb, rp, -h, 0.0), strict=True):
            radial = _unit([B[0], B[1], 0.0])
            axis = _random_rotation(rng, 0.1) @ np.cross(_EZ, radial)
            crank = rng.uniform(0.12, 0.18) * _unit(radial - (radial @ axis) * axis)
            E = B + crank
            legs[name] = _crank_leg(rng, "R", B, axis, E, P, delta=False)
        plat = _platform(rng, rp, 0.02)
    elif leg == "PUS":
        rb, rp, h = rng.uniform(0.5, 0.6), rng.uniform(0.2, 0.3), rng.uniform(0.35, 0.45)
        for name, (B, P) in zip(names, _hexapod_layout(rng, rb, rp, -h, 0.0), strict=True):
            axis = _random_rotation(rng, 0.1) @ _EZ
            E = B + _jitter(rng, 0.02)
            legs[name] = _crank_leg(rng, "P", B, axis, E, P, delta=False)
        plat = _platform(rng, rp, 0.02)
    elif leg == "RSS2":
        zb = rng.uniform(0.8, 0.9)
        for k, name in enumerate(names):
            ang = 90.0 + 120.0 * k + rng.uniform(-3, 3)
            radial = _polar(1.0, ang, 0.0)
            B = _polar(rng.uniform(0.18, 0.22), ang, zb)
            axis = _random_rotation(rng, 0.05) @ np.cross(_EZ, radial)
            arm_dir = sr.rot(axis, float(rng.uniform(-0.3, 0.1))) @ _unit(
                radial - (radial @ axis) * axis
            )
            E = B + rng.uniform(0.36, 0.44) * arm_dir
            P = _polar(rng.uniform(0.045, 0.055), ang + rng.uniform(-3, 3), 0.0)
            P = P + _jitter(rng, 0.005)
            legs[name] = _crank_leg(rng, "R", B, axis, E, P, delta=True)
        plat = _platform(rng, 0.05, -0.02)
    elif leg == "PSS2":
        for k, name in enumerate(names):
            ang = 90.0 + 120.0 * k + rng.uniform(-3, 3)
            B = _polar(rng.uniform(0.28, 0.32), ang, rng.uniform(0.25, 0.35))
            axis = _random_rotation(rng, 0.1) @ _EZ
            E = B + _jitter(rng, 0.01)
            P = _polar(rng.uniform(0.045, 0.055), ang + rng.uniform(-3, 3), 0.0)
            P = P + _jitter(rng, 0.005)
            leg_d = _crank_leg(rng, "P", B, axis, E, P, delta=True)
            bar = _random_rotation(rng, 0.1) @ _polar(1.0, ang + 90.0, 0.0)
            leg_d["bar"] = _l(_unit(bar))
            legs[name] = leg_d
        plat = _platform(rng, 0.05, -0.02)
    else:
        raise ValueError(f"leg: expected one of {LEG_TYPES}, got {leg!r}")
    model = {
        "name": f"random-{leg.lower()}",
        "leg": leg,
        "actuated": sr.ACTUATED[leg],
        "legs": legs,
        "platform": plat,
    }
    return _environment(rng, model)


# ------------------------------------------------------------------------------------------------
# Conditioning.


def conditioning(robot: sr.RobotLike, q: Any) -> np.ndarray:
    """Condition numbers (n,) of the actuator Jacobian ``d qa / d q`` with each row normalised
    and the angle columns of hexapods divided by the platform radius (inf where unreachable)."""
    robot = sr.as_robot(robot)
    J = sr.actuator_jacobian(robot, q)
    if robot.dof == 6:
        J = J.copy()
        J[:, :, 3:] /= robot.platform_radius
    out = np.full(J.shape[0], np.inf)
    for i, Ji in enumerate(J):
        if np.all(np.isfinite(Ji)):
            Jn = Ji / np.linalg.norm(Ji, axis=1, keepdims=True)
            out[i] = np.linalg.cond(Jn)
    return out


def reach(robot: sr.RobotLike, q: Any) -> np.ndarray:
    """Smallest normalised ``|D| / (|S - E| |dE/dq1|)`` over the legs (n,); 1 for UPS."""
    robot = sr.as_robot(robot)
    q = sr._as_poses(robot, q)
    if robot.leg == "UPS":
        return np.ones(q.shape[0])
    out = np.zeros(q.shape[0])
    z = np.zeros(robot.dof)
    for i, qi in enumerate(q):
        plat = sr._platform_state(robot, qi, z, z)
        worst = np.inf
        for lg in robot.legs:
            S = plat.point(lg.platform)[0]
            _, E, J, _, D = sr._joint1(lg, robot.leg[0], S, lg.home_sign)
            val = abs(D) / (float(np.linalg.norm(S - E)) * float(np.linalg.norm(J)))
            worst = min(worst, val) if math.isfinite(val) else 0.0
        out[i] = worst
    return out


def model_ok(model: Mapping[str, Any], q: Any, max_cond: float) -> bool:
    """True if every pose of ``q`` is reachable, well conditioned and far from serial
    singularities."""
    try:
        robot = sr.parse_model(model)
    except ValueError:
        return False
    cond = conditioning(robot, q)
    return bool(np.all(cond < max_cond) and np.all(reach(robot, q) > MIN_REACH))


def random_model(leg: str, rng: np.random.Generator) -> dict[str, Any]:
    """A random, well-conditioned model of the leg type (UPS, RUS, PUS, RSS2, PSS2).

    Legs are unequal (every point, axis, mass, centre of mass and inertia tensor perturbed
    independently); the model may carry an explicit gravity and a payload. Redrawn until the
    home pose has a normalised actuator Jacobian conditioned below :data:`MAX_COND_HOME` and
    every leg's reach above :data:`MIN_REACH`.
    """
    for _ in range(200):
        model = random_model_unchecked(leg, rng)
        if model_ok(model, np.zeros(sr.dof(leg)), MAX_COND_HOME):
            return model
    raise RuntimeError(f"no well-conditioned random {leg} model found")


# ------------------------------------------------------------------------------------------------
# Motion.


@dataclass(frozen=True)
class Motion:
    """A smooth motion: per coordinate ``offset + sum_k amp_k sin(freq_k t + phase_k)``."""

    offset: np.ndarray
    amp: np.ndarray
    freq: np.ndarray
    phase: np.ndarray

    def __call__(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q, qd, qdd`` (n, dof) at times ``t`` (n,), analytic derivatives."""
        t = np.atleast_1d(np.asarray(t, dtype=float))[:, None, None]
        arg = self.freq * t + self.phase
        q = self.offset + np.sum(self.amp * np.sin(arg), axis=2)
        qd = np.sum(self.amp * self.freq * np.cos(arg), axis=2)
        qdd = -np.sum(self.amp * self.freq**2 * np.sin(arg), axis=2)
        return q, qd, qdd


def motion_amplitudes(robot: sr.RobotLike) -> np.ndarray:
    """Rough amplitude per pose coordinate: 3 % of the robot's size for translations (m),
    0.06 rad for angles."""
    robot = sr.as_robot(robot)
    amp = [0.03 * robot.scale] * 3
    if robot.dof == 6:
        amp += [0.06] * 3
    return np.array(amp)


def random_trajectory(
    robot: sr.RobotLike, rng: np.random.Generator, terms: int = 3, scale: float = 1.0
) -> Motion:
    """A random :class:`Motion` about home (amplitudes :func:`motion_amplitudes` x ``scale``,
    frequencies 0.5-4 rad/s), not checked."""
    amp0 = motion_amplitudes(robot) * scale
    k = amp0.size
    return Motion(
        offset=amp0 * rng.uniform(-0.3, 0.3, k),
        amp=(amp0[:, None] * rng.uniform(-1, 1, (k, terms)) / terms),
        freq=rng.uniform(0.5, 4.0, (k, terms)),
        phase=rng.uniform(0, 2 * math.pi, (k, terms)),
    )


def checked_trajectory(robot: sr.RobotLike, rng: np.random.Generator, t_end: float = 2.0) -> Motion:
    """A random :class:`Motion` that stays reachable and well conditioned (bound
    :data:`MAX_COND_MOTION`, reach above :data:`MIN_REACH`) on ``[0, t_end]``."""
    robot = sr.as_robot(robot)
    probe = np.linspace(0.0, t_end, 21)
    scale = 1.0
    for attempt in range(40):
        motion = random_trajectory(robot, rng, scale=scale)
        q = motion(probe)[0]
        c = conditioning(robot, q)
        if np.all(c < MAX_COND_MOTION) and np.all(reach(robot, q) > MIN_REACH):
            return motion
        if attempt % 5 == 4:
            scale *= 0.7
    raise RuntimeError("no well-conditioned motion found")


def random_motion(
    robot: sr.RobotLike,
    rng: np.random.Generator,
    n: int = 20,
    times: Sequence[float] | np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smooth random motion about home: ``q, qd, qdd`` (n, dof).

    Args:
        robot: a model dict or parsed robot.
        rng: random generator.
        n: number of samples on ``[0, 2] s`` (ignored if ``times`` is given).
        times: the sample times (s), e.g. ``t - h, t, t + h`` for central differences.

    Returns:
        Poses, rates and accelerations: translations within a few % of the robot's size, angles
        within about 0.1 rad, staying reachable and well conditioned.
    """
    robot = sr.as_robot(robot)
    t = np.linspace(0.0, 2.0, n) if times is None else np.asarray(times, dtype=float)
    t_end = max(2.0, float(np.max(t)) if t.size else 2.0)
    return checked_trajectory(robot, rng, t_end)(t)


def turn_model(model: Mapping[str, Any], deg: float) -> dict[str, Any]:
    """The whole model (legs, platform, gravity, payload) turned about world z by ``deg``."""
    Q = sr.rz(math.radians(deg))
    out = dict(model)
    out["legs"] = {name: sr.turn_leg(leg, deg) for name, leg in model["legs"].items()}
    pl = dict(model["platform"])
    pl["com"] = _l(Q @ np.asarray(pl["com"], dtype=float))
    pl["inertia"] = sr.inertia_list(Q @ sr.inertia_matrix(pl["inertia"]) @ Q.T)
    out["platform"] = pl
    if "environment" in model:
        out["environment"] = {"gravity": _l(Q @ np.asarray(model["environment"]["gravity"]))}
    if "payload" in model:
        pay = model["payload"]
        out["payload"] = {
            key: _l(Q @ np.asarray(pay.get(key, (0.0, 0.0, 0.0)), dtype=float))
            for key in ("force", "moment")
        }
    return out


# ------------------------------------------------------------------------------------------------
# Gallery-like examples (plain dicts, symmetric designs).


def _rod_tensor(mass: float, direction: np.ndarray, length: float, radius: float) -> list[float]:
    """The inertia tensor of a uniform cylinder along ``direction`` (no random tilt)."""
    Q = _frame_along(direction)
    t = mass * (length**2 / 12 + radius**2 / 4)
    return sr.inertia_list(Q @ np.diag([t, t, mass * radius**2 / 2]) @ Q.T)


def _symmetric_u_axes(e0: np.ndarray) -> list[list[float]]:
    """U axes for a leg along ``e0``: the first horizontal and perpendicular to the leg, the
    second perpendicular to both."""
    u1 = _unit(np.cross(_EZ, e0))
    u2 = _unit(np.cross(e0, u1))
    return [_l(u1), _l(u2)]


def tsai_ups() -> dict[str, Any]:
    """A Stewart-Gough hexapod of the size of Tsai's example (base radius about 2.5 m, platform
    radius about 0.62 m, 1 m high), legs A and B given, ``symmetric = true``."""
    legs = {}
    for name, (B, P) in {
        "A": (np.array([-2.12, 1.374, 0.0]), np.array([0.17, 0.595, 1.0])),
        "B": (np.array([-2.12, -1.374, 0.0]), np.array([0.17, -0.595, 1.0])),
    }.items():
        d = P - B
        e0 = _unit(d)
        length = float(np.linalg.norm(d))
        legs[name] = {
            "base": _l(B),
            "u_axes": _symmetric_u_axes(e0),
            "platform": _l(P),
            "mass": [0.1, 0.1],
            "com": [_l(B + 0.25 * d), _l(B + 0.75 * d)],
            "inertia": [
                _rod_tensor(0.1, e0, 0.5 * length, 0.03),
                _rod_tensor(0.1, e0, 0.5 * length, 0.02),
            ],
        }
    return {
        "name": "tsai-stewart",
        "leg": "UPS",
        "actuated": 2,
        "symmetric": True,
        "legs": legs,
        "platform": {
            "mass": 1.5,
            "com": [0.0, 0.0, 1.0],
            "inertia": [0.08, 0.08, 0.08, 0.0, 0.0, 0.0],
        },
        "environment": {"gravity": [0.0, 0.0, -9.80665]},
    }


def delta() -> dict[str, Any]:
    """An industrial Delta (RSS2): base radius 0.2 m, arm 0.4 m, rods 1 m, 0.1 m apart."""
    B = np.array([0.0, -0.2, 0.0])
    axis = np.array([1.0, 0.0, 0.0])
    E = B + np.array([0.0, -0.4, 0.0])
    P = np.array([0.0, -0.05, 0.0])
    horizontal = float(np.linalg.norm(E - P))
    P[2] = -math.sqrt(1.0 - horizontal**2)
    m_arm = 1.2
    arm = {
        "base": _l(B),
        "axis": _l(axis),
        "elbow": _l(E),
        "platform": _l(P),
        "mass": [m_arm],
        "com": [_l(B + 0.45 * (E - B))],
        "inertia": [_rod_tensor(m_arm, E - B, 0.4, 0.04)],
        "width": 0.1,
        "rod_mass": 0.15,
        "rod_com": 0.5,
        "rod_inertia": 0.15 / 12,
    }
    return {
        "name": "delta",
        "leg": "RSS2",
        "actuated": 1,
        "symmetric": True,
        "legs": {"A": arm},
        "platform": {
            "mass": 0.6,
            "com": [0.0, 0.0, float(P[2]) - 0.02],
            "inertia": [0.0006, 0.0006, 0.001, 0.0, 0.0, 0.0],
        },
        "payload": {"force": [0.0, 0.0, -9.81], "moment": [0.0, 0.0, 0.0]},
    }


def linear_delta() -> dict[str, Any]:
    """A linear Delta (PSS2): vertical rails at radius 0.3 m, rods 0.5 m."""
    B = np.array([0.0, -0.3, 0.0])
    axis = np.array([0.0, 0.0, 1.0])
    P = np.array([0.0, -0.05, 0.0])
    E = B.copy()
    E[2] = math.sqrt(0.5**2 - 0.25**2)
    leg = {
        "base": _l(B),
        "axis": _l(axis),
        "elbow": _l(E),
        "platform": _l(P),
        "mass": [0.8],
        "com": [_l(E + np.array([0.0, -0.02, 0.0]))],
        "inertia": [[0.002, 0.001, 0.002, 0.0, 0.0, 0.0]],
        "width": 0.08,
        "bar": [1.0, 0.0, 0.0],
        "rod_mass": 0.08,
        "rod_com": 0.5,
        "rod_inertia": 0.08 * 0.25 / 12,
    }
    return {
        "name": "linear-delta",
        "leg": "PSS2",
        "actuated": 1,
        "symmetric": True,
        "legs": {"A": leg},
        "platform": {
            "mass": 0.3,
            "com": [0.0, 0.0, -0.01],
            "inertia": [0.0003, 0.0003, 0.0005, 0.0, 0.0, 0.0],
        },
    }


def _symmetric_hexapod_legs(kind: str) -> dict[str, Any]:
    layout = _hexapod_layout(None, 0.4 if kind == "R" else 0.55, 0.25, -0.5, 0.0)
    legs = {}
    for name, (B, P) in zip(("A", "B"), layout[:2], strict=True):
        if kind == "R":
            radial = _unit([B[0], B[1], 0.0])
            axis = np.cross(_EZ, radial)
            E = B + 0.15 * radial
            m1 = 0.6
            c1, I1 = B + 0.5 * (E - B), _rod_tensor(m1, E - B, 0.15, 0.03)
        else:
            axis = _EZ.copy()
            B = B + np.array([0.0, 0.0, 0.1])
            E = B.copy()
            m1 = 0.8
            c1, I1 = E.copy(), _rod_tensor(m1, axis, 0.1, 0.04)
        rod = P - E
        L = float(np.linalg.norm(rod))
        legs[name] = {
            "base": _l(B),
            "axis": _l(axis),
            "u_axes": _symmetric_u_axes(_unit(rod)),
            "elbow": _l(E),
            "platform": _l(P),
            "mass": [m1, 0.25],
            "com": [_l(c1), _l(E + 0.5 * rod)],
            "inertia": [I1, _rod_tensor(0.25, rod, L, 0.012)],
        }
    return legs


def rus_hexapod() -> dict[str, Any]:
    """A 6-RUS hexapod: horizontal motor axes tangent to a 0.4 m circle, 0.15 m cranks."""
    return {
        "name": "rus-hexapod",
        "leg": "RUS",
        "actuated": 1,
        "symmetric": True,
        "legs": _symmetric_hexapod_legs("R"),
        "platform": {
            "mass": 1.2,
            "com": [0.0, 0.0, 0.02],
            "inertia": [0.02, 0.02, 0.035, 0.0, 0.0, 0.0],
        },
    }


def pus_hexapod() -> dict[str, Any]:
    """A 6-PUS hexapod: vertical rails on a 0.55 m circle."""
    return {
        "name": "pus-hexapod",
        "leg": "PUS",
        "actuated": 1,
        "symmetric": True,
        "legs": _symmetric_hexapod_legs("P"),
        "platform": {
            "mass": 1.2,
            "com": [0.0, 0.0, 0.02],
            "inertia": [0.02, 0.02, 0.035, 0.0, 0.0, 0.0],
        },
        "payload": {"force": [0.0, 0.0, -20.0], "moment": [0.0, 0.0, 0.0]},
    }


def gallery() -> dict[str, dict[str, Any]]:
    """The example models by leg type."""
    return {
        "UPS": tsai_ups(),
        "RUS": rus_hexapod(),
        "PUS": pus_hexapod(),
        "RSS2": delta(),
        "PSS2": linear_delta(),
    }
