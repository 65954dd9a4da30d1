"""Model and motion generators for the tests of the general planar reference.

Everything here builds model dicts of the general explicit form (``shared/spec/interfaces.md``,
"Any planar 3-leg robot") and checks them with :mod:`planar_reference` only; it imports nothing
from ``rpr3gen``, ``derive/`` or ``generated/``. World frame x0 horizontal, y0 up; SI units.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

try:
    from . import planar_reference as pr
    from .newton_euler import sinusoid_motion  # a motion, not physics: shared by both references
except ImportError:
    import planar_reference as pr
    from newton_euler import sinusoid_motion

LEGS = pr.LEGS

SERIAL_MIN_HOME = 0.3
"""Smallest normalised serial determinant (:func:`planar_reference.normalised_determinant`) of
a random model's legs at home."""
PARALLEL_MAX_COND_HOME = 12.0
"""Largest condition number of the scaled actuator Jacobian
(:func:`planar_reference.scaled_actuator_jacobian`) of a random model at home."""
SERIAL_MIN_MOTION = 0.1
PARALLEL_MAX_COND_MOTION = 60.0
"""The same bounds along a random motion (:func:`random_motion`)."""


def all_structures() -> list[tuple[str, int]]:
    """The 21 ``(leg, actuated)`` structures: 7 leg types x 3 actuated joints."""
    return [(leg, a) for leg in pr.LEG_TYPES for a in (1, 2, 3)]


def nonsingular_structures() -> list[tuple[str, int]]:
    """The 18 structures that are not architecturally singular."""
    return [s for s in all_structures() if s not in pr.SINGULAR_STRUCTURES]


def _unit(angle: float) -> np.ndarray:
    return np.array([math.cos(angle), math.sin(angle)])


def _perp(v: np.ndarray) -> np.ndarray:
    return np.array([-v[1], v[0]])


def _draw_leg(rng: np.random.Generator, leg: str, base_deg: float, plat_deg: float) -> dict:
    """One random leg (explicit form, plain floats)."""
    P1 = rng.uniform(0.3, 0.45) * _unit(math.radians(base_deg + rng.uniform(-15, 15)))
    P3 = rng.uniform(0.12, 0.25) * _unit(math.radians(plat_deg + rng.uniform(-15, 15)))
    d = P3 - P1
    L = float(np.linalg.norm(d))
    n = _perp(d / L)
    if leg == "RRR":  # an elbow: the three joints must not be aligned
        side = rng.choice([-1.0, 1.0]) * rng.uniform(0.25, 0.5)
    else:
        side = rng.uniform(-0.2, 0.2)
    P2 = P1 + rng.uniform(0.35, 0.65) * d + side * L * n
    joints = np.array([P1, P2, P3])
    lines = (P2 - P1, P3 - P1, P3 - P2)  # the line a P joint "naturally" follows
    axes = np.zeros((3, 2))
    for j, kind in enumerate(leg):
        if kind == "P":
            if rng.uniform() < 0.5:
                ang = math.atan2(lines[j][1], lines[j][0]) + math.radians(rng.uniform(-20, 20))
            else:
                ang = rng.uniform(-math.pi, math.pi)
            # Any length: the model normalises.
            axes[j] = rng.uniform(0.5, 2.0) * _unit(ang)
    mass = rng.uniform(0.5, 3.0, 2)
    com = np.zeros((2, 2))
    inertia = np.zeros(2)
    for k in range(2):
        a, b = joints[k], joints[k + 1]
        seg = b - a
        length = max(float(np.linalg.norm(seg)), 0.05)
        off = rng.choice([-1.0, 1.0]) * rng.uniform(0.01, 0.04)  # off the joint line, m
        normal = _perp(seg / np.linalg.norm(seg)) if np.linalg.norm(seg) > 0 else _unit(0.0)
        com[k] = a + rng.uniform(0.2, 0.8) * seg + off * normal
        inertia[k] = mass[k] * length**2 / 12 * rng.uniform(0.5, 1.5)
    return {
        "joints": joints.tolist(),
        "axes": axes.tolist(),
        "mass": mass.tolist(),
        "com": com.tolist(),
        "inertia": inertia.tolist(),
    }


def _draw_model(rng: np.random.Generator, leg: str, actuated: int) -> dict:
    base_deg = (-30.0, 90.0, 210.0)
    plat_deg = (30.0, 150.0, 270.0)
    legs = {
        name: _draw_leg(rng, leg, b, p) for name, b, p in zip(LEGS, base_deg, plat_deg, strict=True)
    }
    rho = float(np.mean([np.linalg.norm(legs[name]["joints"][2]) for name in LEGS]))
    pm = float(rng.uniform(2.0, 8.0))
    gang = -math.pi / 2 + rng.choice([-1.0, 1.0]) * math.radians(rng.uniform(10, 35))
    return {
        "name": f"random-{leg}-{actuated}",
        "leg": leg,
        "actuated": actuated,
        "legs": legs,
        "platform": {
            "mass": pm,
            "com": (rng.uniform(0.01, 0.04) * _unit(rng.uniform(-math.pi, math.pi))).tolist(),
            "inertia": float(pm * rho**2 / 2 * rng.uniform(0.5, 1.5)),
        },
        "environment": {"gravity": (9.81 * _unit(gang)).tolist()},
        "payload": {
            "force": rng.uniform(-20.0, 20.0, 2).tolist(),
            "moment": float(rng.uniform(-3.0, 3.0)),
        },
    }


def _serial_ok(robot: pr.Robot, q: np.ndarray, bound: float) -> bool:
    D = pr.serial_determinant(robot, q)
    if not np.all(np.isfinite(D)):
        return False
    norm = np.stack([pr.normalised_determinant(robot, i, D[:, i]) for i in range(3)], axis=1)
    return bool(np.all(np.abs(norm) >= bound))


def _parallel_ok(robot: pr.Robot, q: np.ndarray, bound: float) -> bool:
    J = pr.scaled_actuator_jacobian(robot, q)
    return bool(np.all(np.isfinite(J)) and np.all(np.linalg.cond(J) <= bound))


def random_model_unchecked(
    rng: np.random.Generator, leg: str, actuated: int, attempts: int = 500
) -> dict:
    """A random model away from serial singularities at home, of any structure (singular ones
    included) and without the parallel-singularity check: for tests of singular structures."""
    for _ in range(attempts):
        model = _draw_model(rng, leg, actuated)
        try:
            robot = pr.parse_model(model)
        except ValueError:
            continue
        if _serial_ok(robot, np.zeros((1, 3)), SERIAL_MIN_HOME):
            return model
    raise RuntimeError(f"no random {leg} model after {attempts} draws")


def random_model(
    rng: np.random.Generator, leg: str, actuated: int, attempts: int = 500
) -> dict[str, Any]:
    """A random valid model dict (explicit form), roughly the size of the paper's robot.

    Legs from base points at radius 0.30-0.45 m (angles -30, 90, 210 deg, +-15 deg) to platform
    joints at radius 0.12-0.25 m (30, 150, 270 deg, +-15 deg); joint 2 between them at 35-65 %
    of the way, off the line by up to 20 % of the leg (25-50 % for RRR: an elbow); P axes along
    the line their joint naturally follows (joint 1: to joint 2; joint 2: joint 1 to 3; joint 3:
    joint 2 to 3) turned by up to 20 deg, or (half the time) in a random direction, with a random
    length (0.5-2). Bodies 1, 2: mass 0.5-3 kg, com 20-80 % along their joints' segment and
    1-4 cm off it, inertia ``m l^2 / 12`` times 0.5-1.5. Platform: 2-8 kg, com 1-4 cm off G,
    inertia ``m rho^2 / 2`` times 0.5-1.5. Gravity 9.81 m/s^2 tilted 10-35 deg from -y0; payload
    force up to 20 N per component, moment up to 3 N m.

    Redrawn until every leg's normalised serial determinant at home is at least
    :data:`SERIAL_MIN_HOME` and the scaled actuator Jacobian's condition number at home at most
    :data:`PARALLEL_MAX_COND_HOME`. Deterministic given ``rng``.

    Args:
        rng: random generator.
        leg: leg type, one of :data:`planar_reference.LEG_TYPES`.
        actuated: actuated joint, 1, 2 or 3.
        attempts: draws before giving up.

    Raises:
        ValueError: for an architecturally singular structure (naming why) or an unknown type.
    """
    if leg not in pr.LEG_TYPES or actuated not in (1, 2, 3):
        raise ValueError(f"unknown structure ({leg!r}, {actuated!r})")
    if (leg, actuated) in pr.SINGULAR_STRUCTURES:
        raise ValueError(
            f"({leg}, actuated {actuated}) is architecturally singular: "
            f"{pr.SINGULAR_STRUCTURES[(leg, actuated)]}, so every motor measures only the "
            "platform angle"
        )
    home = np.zeros((1, 3))
    for _ in range(attempts):
        model = _draw_model(rng, leg, actuated)
        try:
            robot = pr.parse_model(model)
        except ValueError:
            continue
        if _serial_ok(robot, home, SERIAL_MIN_HOME) and _parallel_ok(
            robot, home, PARALLEL_MAX_COND_HOME
        ):
            return model
    raise RuntimeError(f"no valid random ({leg}, {actuated}) model after {attempts} draws")


def motion_ok(robot: pr.RobotLike, q: np.ndarray) -> bool:
    """True when every sample is reachable in the working mode with normalised ``|D|`` at least
    :data:`SERIAL_MIN_MOTION` and the scaled actuator Jacobian's condition number at most
    :data:`PARALLEL_MAX_COND_MOTION`."""
    robot = pr.as_robot(robot)
    return _serial_ok(robot, q, SERIAL_MIN_MOTION) and _parallel_ok(
        robot, q, PARALLEL_MAX_COND_MOTION
    )


def random_motion(
    rng: np.random.Generator,
    robot: pr.RobotLike,
    t: np.ndarray,
    amp: tuple[float, float, float] = (0.04, 0.04, 0.3),
    attempts: int = 60,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A random smooth platform motion inside the workspace, away from singularities.

    Sums of three sinusoids per coordinate (:func:`sinusoids`, amplitudes ~``amp`` in m, m,
    rad); redrawn until :func:`motion_ok` holds at every sample, the amplitude shrinking by 20 %
    every 10 failed draws.

    Returns:
        q, qd, qdd (n, 3).
    """
    robot = pr.as_robot(robot)
    scale = 1.0
    for k in range(attempts):
        if k and k % 10 == 0:
            scale *= 0.8
        q, qd, qdd = sinusoid_motion(rng, t, tuple(scale * a for a in amp))
        if motion_ok(robot, q):
            return q, qd, qdd
    raise RuntimeError(f"no valid motion for {robot.name} after {attempts} draws")


# ------------------------------------------------------------------------------------------------
# The paper's 3-RPR robot in the general format.


PAPER_ACTUATED = {"revolute": 1, "prismatic": 2}


def make_twinnable(params: Mapping[str, float]) -> dict[str, float]:
    """Paper parameters whose base pivots are moved so that home is the central configuration:
    ``A1 = p - (l0 + l2)(cos alpha, sin alpha)`` (then phi10 = lambda21 = 0 at G = 0, phi = 0)."""
    p = dict(params)
    for leg in LEGS:
        a = p[f"alpha_{leg}"]
        p[f"x{leg}1"] = p[f"x{leg}3"] - (p["l0"] + p["l2"]) * math.cos(a)
        p[f"y{leg}1"] = p[f"y{leg}3"] - (p["l0"] + p["l2"]) * math.sin(a)
    return p


def paper_twin(paper_params: Mapping[str, float], actuation: str) -> dict[str, Any]:
    """The 3-RPR robot of ``tests/newton_euler.py`` written as a general model dict.

    Leg "RPR", actuated 1 (``"revolute"``) or 2 (``"prismatic"``); per leg joints
    ``[A1, A1 + l0 u, p]`` (``u`` the unit leg axis at home, ``p`` the platform joint), axes
    ``[-, u, -]``, body 1 (cylinder) com ``A1 + c1 u + c1_perp n``, body 2 (piston) com
    ``A2 + c2 u + c2_perp n`` (``n`` = ``u`` turned +90 deg), platform com at G.

    Args:
        paper_params: ``newton_euler.PARAM_NAMES`` -> value; home must be the central
            configuration (``|p - A1| = l0 + l2`` along ``alpha``; see :func:`make_twinnable`).
        actuation: ``"revolute"`` or ``"prismatic"``.

    Raises:
        ValueError: when home is not the central configuration of these parameters.
    """
    P = paper_params
    legs = {}
    for leg in LEGS:
        A1 = np.array([P[f"x{leg}1"], P[f"y{leg}1"]])
        p3 = np.array([P[f"x{leg}3"], P[f"y{leg}3"]])
        u = _unit(P[f"alpha_{leg}"])
        if np.linalg.norm(A1 + (P["l0"] + P["l2"]) * u - p3) > 1e-12:
            raise ValueError(f"leg {leg}: home is not the central configuration")
        n = _perp(u)
        A2 = A1 + P["l0"] * u
        legs[leg] = {
            "joints": [A1.tolist(), A2.tolist(), p3.tolist()],
            "axes": [[0.0, 0.0], u.tolist(), [0.0, 0.0]],
            "mass": [P["m1"], P["m2"]],
            "com": [
                (A1 + P["c1"] * u + P["c1_perp"] * n).tolist(),
                (A2 + P["c2"] * u + P["c2_perp"] * n).tolist(),
            ],
            "inertia": [P["J1"], P["J2"]],
        }
    return {
        "name": f"paper-twin-{actuation}",
        "leg": "RPR",
        "actuated": PAPER_ACTUATED[actuation],
        "legs": legs,
        "platform": {"mass": P["m3"], "com": [0.0, 0.0], "inertia": P["J3"]},
        "environment": {"gravity": [P["gx"], P["gy"]]},
        "payload": {"force": [P["fx"], P["fy"]], "moment": P["mz"]},
    }


def paper_outputs(
    general_outputs: Mapping[str, np.ndarray], robot: pr.RobotLike, q: Any
) -> dict[str, np.ndarray]:
    """The general outputs of a :func:`paper_twin` robot under the paper's names.

    ``phi10, lambda21, phi32 = q1, q2, q3`` (rates and accelerations likewise), ``m10 = m1``,
    ``f10x, f10y = fx1, fy1``, ``f21y = f2 . n``, ``f21z = f2 . e``, ``m21 = -m2`` (the paper's
    m21 is along ``x2 = -z0``), ``f32y = f3 . n``, ``f32z = f3 . e``, with ``e`` the current
    leg axis A1 -> A3 and ``n`` = ``e`` turned +90 deg.

    Args:
        general_outputs: :func:`planar_reference.solve`'s outputs.
        robot: the twin (parsed or its dict).
        q: (n, 3) the platform poses of the outputs.
    """
    o = general_outputs
    robot = pr.as_robot(robot)
    pts = pr.joint_points(robot, q)
    out: dict[str, np.ndarray] = {}
    for leg in LEGS:
        d = pts[leg][:, 2] - pts[leg][:, 0]
        e = d / np.linalg.norm(d, axis=1)[:, None]
        n = np.stack([-e[:, 1], e[:, 0]], axis=1)

        def g(name: str, leg: str = leg) -> np.ndarray:
            return np.asarray(o[f"{name}_{leg}"], dtype=float)

        f2 = np.stack([g("fx2"), g("fy2")], axis=1)
        f3 = np.stack([g("fx3"), g("fy3")], axis=1)
        names = {
            "phi10": g("q1"),
            "lambda21": g("q2"),
            "phi32": g("q3"),
            "omega10": g("qd1"),
            "v21": g("qd2"),
            "omega32": g("qd3"),
            "eps10": g("qdd1"),
            "gamma21": g("qdd2"),
            "eps32": g("qdd3"),
            "m10": g("m1"),
            "f10x": g("fx1"),
            "f10y": g("fy1"),
            "f21y": np.sum(f2 * n, axis=1),
            "f21z": np.sum(f2 * e, axis=1),
            "m21": -g("m2"),
            "f32y": np.sum(f3 * n, axis=1),
            "f32z": np.sum(f3 * e, axis=1),
        }
        for fam, value in names.items():
            out[f"{fam}_{leg}"] = value
    return out
