"""Property-based tests (Hypothesis) over random valid robots and motions.

Each property is checked on a bounded number of derandomised examples, so CI is repeatable.
"""

from __future__ import annotations

import math

import newton_euler as ne
import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import rpr3gen
from rpr3gen.model import Model

SETTINGS = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
T = np.linspace(0.0, 1.5, 31)
LOADS = ("m10", "f10x", "f10y", "f21y", "f21z", "m21", "f32y", "f32z")
LEG_FRAME = ("phi10", "lambda21", "omega10", "v21", "omega32", "eps10", "gamma21", "eps32",
             "m10", "f21y", "f21z", "m21", "f32y", "f32z")  # fmt: skip

unit = st.floats(0.0, 1.0)


@st.composite
def robots(draw) -> dict[str, float]:
    """A robot shaped like the paper's: pivots and joints on jittered circles, any gravity."""
    p: dict[str, float] = {}
    lengths = []
    for leg, base_deg, plat_deg in zip("ABC", (-30, 90, 210), (30, 150, 270), strict=True):
        b = math.radians(base_deg + draw(st.floats(-15, 15)))
        a = math.radians(plat_deg + draw(st.floats(-15, 15)))
        rb, rp = draw(st.floats(0.25, 0.4)), draw(st.floats(0.12, 0.3))
        p[f"x{leg}1"], p[f"y{leg}1"] = rb * math.cos(b), rb * math.sin(b)
        p[f"x{leg}3"], p[f"y{leg}3"] = rp * math.cos(a), rp * math.sin(a)
        dx, dy = p[f"x{leg}3"] - p[f"x{leg}1"], p[f"y{leg}3"] - p[f"y{leg}1"]
        p[f"alpha_{leg}"] = math.atan2(dy, dx) + draw(st.floats(-0.2, 0.2))
        lengths.append(math.hypot(dx, dy))
    l2 = draw(st.floats(0.2, 0.6)) * min(lengths)
    l1 = draw(st.floats(0.1, 0.3))
    m1, m2, m3 = draw(st.floats(0.5, 5)), draw(st.floats(0.3, 3)), draw(st.floats(1, 10))
    g_angle = draw(st.floats(-math.pi, math.pi))
    p.update(
        l0=draw(st.floats(0.1, 0.4)) * min(lengths),
        l2=l2,
        c1=draw(st.floats(0.2, 0.8)) * l1,
        c2=draw(st.floats(0.2, 0.8)) * l2,
        m1=m1,
        m2=m2,
        m3=m3,
        J1=m1 * l1**2 / 12 * draw(st.floats(0.5, 1.5)),
        J2=m2 * l2**2 / 12 * draw(st.floats(0.5, 1.5)),
        J3=m3 * 0.02 * draw(st.floats(0.5, 1.5)),
        gx=9.81 * math.cos(g_angle),
        gy=9.81 * math.sin(g_angle),
        fx=draw(st.floats(-20, 20)),
        fy=draw(st.floats(-20, 20)),
        mz=draw(st.floats(-3, 3)),
        c1_perp=draw(st.floats(-0.2, 0.2)) * l1,
        c2_perp=draw(st.floats(-0.2, 0.2)) * l2,
    )
    return p


@st.composite
def motions(draw) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, y, phi as a sinusoid each, with analytic derivatives."""
    q, qd, qdd = (np.empty((len(T), 3)) for _ in range(3))
    for k, scale in enumerate((0.04, 0.04, 0.3)):
        amp, freq = draw(st.floats(0, scale)), draw(st.floats(0.2, 2.0))
        phase, offset = draw(st.floats(0, 2 * math.pi)), draw(st.floats(-scale, scale)) / 2
        w = 2 * math.pi * freq
        q[:, k] = offset + amp * np.sin(w * T + phase)
        qd[:, k] = amp * w * np.cos(w * T + phase)
        qdd[:, k] = -amp * w * w * np.sin(w * T + phase)
    return q, qd, qdd


def _accepted(params, q) -> bool:
    """Poses the reference solves well (legs longer than 0.05 m, cond <= 1e4) and rpr3gen does
    not refuse: every piston joint A2 ahead of its base pivot A1 (rpr3gen refuses |A1A2| under
    1e-9 l0, output ``reach``; kept here 1 % of l0 away from it)."""
    if not ne.well_conditioned(params, q, max_cond=1e4):
        return False
    kin = ne.kinematics(params, np.atleast_2d(q), np.zeros_like(np.atleast_2d(q)))
    return all(np.all(kin[leg]["length"] - params["l2"] > 0.01 * params["l0"]) for leg in "ABC")


def _run(params, actuation, q, qd, qdd):
    return rpr3gen.inverse_dynamics(Model("h", actuation, params, "<hypothesis>"), q, qd, qdd)


def _relative(a: np.ndarray, b: np.ndarray, scale: float) -> float:
    """Max |a - b| relative to ``scale``; a family that is zero throughout (say phi10 at a
    symmetric pose) is held to an absolute 1e-15 instead."""
    return float(np.max(np.abs(a - b))) / max(scale, 1e-6)


@SETTINGS
@given(robots(), motions(), st.sampled_from(["revolute", "prismatic"]))
def test_agrees_with_newton_euler(params, motion, actuation) -> None:
    assume(_accepted(params, motion[0]))
    out, ref = _run(params, actuation, *motion), ne.solve(params, actuation, *motion)
    for family in ne.FAMILIES:
        names = [f"{family}_{leg}" for leg in "ABC"]
        scale = max(np.max(np.abs(ref[n])) for n in names)
        for n in names:
            assert _relative(out[n], ref[n], scale) <= 1e-9, n


@SETTINGS
@given(robots(), motions())
def test_power_balance_and_same_power_in_both_schemes(params, motion) -> None:
    q, qd, qdd = motion
    assume(_accepted(params, q))
    rev, pri = _run(params, "revolute", *motion), _run(params, "prismatic", *motion)
    motor = sum(rev[f"m10_{g}"] * rev[f"omega10_{g}"] for g in "ABC")
    slide = sum(pri[f"f21z_{g}"] * pri[f"v21_{g}"] for g in "ABC")
    payload = params["fx"] * qd[:, 0] + params["fy"] * qd[:, 1] + params["mz"] * qd[:, 2]
    rate = ne.energy_rate(params, q, qd, qdd)
    scale = max(np.max(np.abs(rate)), np.max(np.abs(payload)), 1e-6)
    assert _relative(motor + payload, rate, scale) <= 1e-9
    assert _relative(slide + payload, rate, scale) <= 1e-9
    assert _relative(motor, slide, scale) <= 1e-9


def _rotated_robot(params: dict[str, float], angle: float) -> dict[str, float]:
    c, s = math.cos(angle), math.sin(angle)
    p = dict(params)
    for x, y in (("xA1", "yA1"), ("xB1", "yB1"), ("xC1", "yC1"), ("gx", "gy"), ("fx", "fy")):
        p[x], p[y] = c * params[x] - s * params[y], s * params[x] + c * params[y]
    for leg in "ABC":
        p[f"alpha_{leg}"] = params[f"alpha_{leg}"] + angle
    return p


@SETTINGS
@given(robots(), motions(), st.sampled_from(["revolute", "prismatic"]), st.floats(-3.0, 3.0))
def test_rotating_robot_and_gravity_rotates_the_loads(params, motion, actuation, angle) -> None:
    q, qd, qdd = motion
    assume(_accepted(params, q))
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    q2 = q @ turn.T
    q2[:, 2] += angle
    out = _run(params, actuation, q, qd, qdd)
    rot = _run(_rotated_robot(params, angle), actuation, q2, qd @ turn.T, qdd @ turn.T)
    for family in LEG_FRAME:
        scale = max(np.max(np.abs(out[f"{family}_{g}"])) for g in "ABC")
        for g in "ABC":
            assert _relative(rot[f"{family}_{g}"], out[f"{family}_{g}"], scale) <= 1e-9, family
    scale = max(np.max(np.abs(out[f"f10{a}_{g}"])) for a in "xy" for g in "ABC")
    for g in "ABC":
        fx, fy = out[f"f10x_{g}"], out[f"f10y_{g}"]
        assert _relative(rot[f"f10x_{g}"], c * fx - s * fy, scale) <= 1e-9
        assert _relative(rot[f"f10y_{g}"], s * fx + c * fy, scale) <= 1e-9
    np.testing.assert_allclose(rot["conditioning"], out["conditioning"], rtol=1e-9)


@SETTINGS
@given(robots(), motions(), st.sampled_from(["revolute", "prismatic"]))
def test_at_rest_the_loads_balance_gravity_and_payload(params, motion, actuation) -> None:
    q = motion[0]
    assume(_accepted(params, q))
    zero = np.zeros_like(q)
    out = _run(params, actuation, q, zero, zero)
    p = params
    g = np.array([p["gx"], p["gy"]])
    weights = {"m1": p["m1"] * g, "m2": p["m2"] * g, "m3": p["m3"] * g}
    force = sum(np.stack([out[f"f10x_{k}"], out[f"f10y_{k}"]], 1) for k in "ABC")
    total = force + 3 * weights["m1"] + 3 * weights["m2"] + weights["m3"] + [p["fx"], p["fy"]]
    scale = np.max(np.abs(force))
    assert np.max(np.abs(total)) <= 1e-9 * scale

    def cross(r, f):
        return r[:, 0] * f[1] - r[:, 1] * f[0]

    moment = p["mz"] + cross(q[:, :2], weights["m3"] + [p["fx"], p["fy"]])
    for k in "ABC":
        a1 = np.array([p[f"x{k}1"], p[f"y{k}1"]])
        theta = p[f"alpha_{k}"] + out[f"phi10_{k}"]
        e = np.stack([np.cos(theta), np.sin(theta)], 1)
        f10 = np.stack([out[f"f10x_{k}"], out[f"f10y_{k}"]], 1)
        moment += out[f"m10_{k}"] + a1[0] * f10[:, 1] - a1[1] * f10[:, 0]
        n = np.stack([-e[:, 1], e[:, 0]], 1)
        moment += cross(a1 + p["c1"] * e + p["c1_perp"] * n, weights["m1"])
        piston = a1 + (p["l0"] + out[f"lambda21_{k}"] + p["c2"])[:, None] * e + p["c2_perp"] * n
        moment += cross(piston, weights["m2"])
    assert np.max(np.abs(moment)) <= 1e-9 * max(scale, 1.0)
