"""Self-checks of the independent spatial reference (tests/spatial_reference.py).

The reference judges the production code for hexapods (UPS, RUS, PUS) and Deltas (RSS2, PSS2), so
it is checked here against physics it was not built from: the power balance (finite-difference
dE/dt), the momentum and angular-momentum balances of the whole robot (finite-difference rates of
change against the base-joint loads), the joints' zero-load conditions read off the outputs, the
statics at rest, finite differences of the joint coordinates, joint coordinates 0 at home,
invariance under turning the whole model about the vertical, and the symmetric expansion.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

try:
    from . import spatial_models as sm
    from . import spatial_reference as sr
except ImportError:
    import spatial_models as sm
    import spatial_reference as sr

LEGS = sr.LEG_TYPES
T = np.linspace(0.0, 2.0, 6)
H = 1e-5  # time step of the central differences, s


@functools.cache
def _case(leg: str):
    """A random model of the leg type, a checked motion, and the outputs at T."""
    rng = np.random.default_rng(2024 + 17 * LEGS.index(leg))
    model = sm.random_model(leg, rng)
    robot = sr.parse_model(model)
    motion = sm.checked_trajectory(robot, rng)
    q, qd, qdd = motion(T)
    out = sr.solve(robot, q, qd, qdd)
    return model, robot, motion, out


def _vec(out, fam: str, j: int, name: str) -> np.ndarray:
    """The (n, 3) force (``fam = "f"``) or moment (``"m"``) of joint j of leg ``name``."""
    return np.stack([out[f"{fam}{c}{j}_{name}"] for c in "xyz"], axis=1)


def _scale(*arrays: np.ndarray) -> float:
    return 1.0 + max(float(np.max(np.abs(a))) for a in arrays)


def _joint1_point(robot: sr.Robot, out, i: int) -> np.ndarray:
    """Joint 1's point (n, 3) of leg i: ``base``, slid along the axis for a P joint."""
    lg, name = robot.legs[i], robot.leg_names[i]
    if robot.leg in ("PUS", "PSS2"):
        return lg.base + out[f"q1_{name}"][:, None] * lg.axis
    return np.broadcast_to(lg.base, (out[f"tau_{name}"].size, 3))


# ------------------------------------------------------------------------------------------------
# Names and shapes.


def test_output_names_order():
    names = sr.output_names("UPS")
    assert names[:7] == ("q1a_A", "q1a_B", "q1a_C", "q1a_D", "q1a_E", "q1a_F", "q1b_A")
    fams = sr.output_families("UPS")
    assert fams[:8] == ("q1a", "q1b", "q2", "qd2", "qdd2", "q3x", "q3y", "q3z")
    assert fams[8:14] == ("fx1", "fy1", "fz1", "mx1", "my1", "mz1")
    assert fams[-1] == "tau"
    assert len(fams) == 8 + 18 + 1
    assert sr.output_families("RUS")[:8] == ("q1", "qd1", "qdd1", "q2a", "q2b", "q3x", "q3y", "q3z")
    assert sr.output_families("PSS2")[:4] == ("q1", "qd1", "qdd1", "fx1")
    assert len(sr.output_families("RSS2")) == 3 + 30 + 1
    assert len(sr.output_names("RSS2")) == 3 * 34
    assert len(set(sr.output_names("PUS"))) == 6 * 27


@pytest.mark.parametrize("leg", LEGS)
def test_solve_shapes_and_single_sample(leg):
    _, robot, motion, out = _case(leg)
    assert tuple(out) == sr.output_names(leg)
    assert all(v.shape == (T.size,) and np.all(np.isfinite(v)) for v in out.values())
    q, qd, qdd = motion(T)
    one = sr.solve(robot, q[2], qd[2], qdd[2])
    for key, v in out.items():
        assert one[key].shape == (1,)
        assert one[key][0] == pytest.approx(v[2], rel=1e-12, abs=1e-12)
    assert np.all(sr.residuals(robot, q, qd, qdd) < 1e-11)


# ------------------------------------------------------------------------------------------------
# Energy and momentum.


@pytest.mark.parametrize("leg", LEGS)
def test_power_balance(leg):
    """sum tau qa' + payload power = dE/dt (central differences of the energy)."""
    _, robot, motion, out = _case(leg)
    q, qd, _ = motion(T)
    tau = sr.efforts(robot, out)
    qad = sr.actuator_rates(robot, q, qd)
    power = np.sum(tau * qad, axis=1) + sr.payload_power(robot, q, qd)
    kp, vp = sr.energy(robot, *motion(T + H)[:2])
    km, vm = sr.energy(robot, *motion(T - H)[:2])
    dE = ((kp + vp) - (km + vm)) / (2 * H)
    scale = _scale(tau * qad, power)
    np.testing.assert_allclose(power, dE, rtol=0, atol=1e-7 * scale)
    # the actuated rates are the outputs' rates
    fam = "qd2" if leg == "UPS" else "qd1"
    rates = np.stack([out[f"{fam}_{L}"] for L in robot.leg_names], axis=1)
    np.testing.assert_allclose(rates, qad, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("leg", LEGS)
def test_momentum_balances(leg):
    """Base-joint loads + gravity + payload = rate of change of the total (angular) momentum."""
    _, robot, motion, out = _case(leg)
    q, qd, _ = motion(T)
    plus = sr.totals(robot, *motion(T + H)[:2])
    minus = sr.totals(robot, *motion(T - H)[:2])
    now = sr.totals(robot, q, qd)
    dp = (plus["momentum"] - minus["momentum"]) / (2 * H)
    dL = (plus["angular_momentum"] - minus["angular_momentum"]) / (2 * H)
    g, F, M = robot.gravity, robot.payload_force, robot.payload_moment
    force = robot.total_mass * g + F
    moment = np.cross(now["first_moment"], g) + M + np.cross(q[:, :3], F)
    for i, name in enumerate(robot.leg_names):
        f1, m1 = _vec(out, "f", 1, name), _vec(out, "m", 1, name)
        force = force + f1
        moment = moment + m1 + np.cross(_joint1_point(robot, out, i), f1)
    np.testing.assert_allclose(force, dp, rtol=0, atol=1e-7 * _scale(force, dp))
    np.testing.assert_allclose(moment, dL, rtol=0, atol=1e-7 * _scale(moment, dL))


@pytest.mark.parametrize("leg", LEGS)
def test_coordinate_rates_by_finite_differences(leg):
    _, robot, motion, out = _case(leg)
    joint = "2" if leg == "UPS" else "1"
    up, _, _ = motion(T + H)
    dn, _, _ = motion(T - H)
    ik_p, ik_m = sr.inverse_kinematics(robot, up), sr.inverse_kinematics(robot, dn)
    sp = sr.solve(robot, *motion(T + H))
    sm_ = sr.solve(robot, *motion(T - H))
    for name in robot.leg_names:
        key = f"q{joint}_{name}"
        fd = (ik_p[key] - ik_m[key]) / (2 * H)
        np.testing.assert_allclose(out[f"qd{joint}_{name}"], fd, rtol=1e-6, atol=1e-8)
        fdd = (sp[f"qd{joint}_{name}"] - sm_[f"qd{joint}_{name}"]) / (2 * H)
        np.testing.assert_allclose(out[f"qdd{joint}_{name}"], fdd, rtol=1e-6, atol=1e-7)
    if sr.is_hexapod(leg):  # the S coordinates and U angles are smooth and small
        for key in ik_p:
            assert np.all(np.abs(ik_p[key] - ik_m[key]) < 1e-3)


def _body_momenta(robot: sr.Robot, q, qd) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per body (the reference's order: each leg's bodies, then the platform): COM, linear
    momentum, angular momentum about the COM (rods: ``J u x u'``), at one sample."""
    smp = sr.sample_state(robot, q, qd, np.zeros_like(q))
    out = []
    for bd in smp.bodies:
        if isinstance(bd, sr.RigidState):
            c, v, _ = bd.point(bd.com_home)
            out.append((c, bd.mass * v, bd.inertia @ bd.w))
        else:
            out.append((bd.c, bd.mass * bd.vc, bd.inertia * np.cross(bd.u, bd.du)))
    return out


def _doc_points(robot: sr.Robot, out, i: int, k: int, q) -> list[np.ndarray]:
    """The joints' points of leg i at sample k, as docs/spatial-robots.md defines them."""
    lg, name = robot.legs[i], robot.leg_names[i]
    S = (sr.euler_matrix(*q[3:]) if robot.dof == 6 else np.eye(3)) @ lg.platform + q[:3]
    if robot.leg == "UPS":
        e = (S - lg.base) / np.linalg.norm(S - lg.base)
        return [lg.base, lg.base + out[f"q2_{name}"][k] * e, S]
    q1 = out[f"q1_{name}"][k]
    if robot.leg[0] == "R":
        P1, E = lg.base, lg.base + sr.rot(lg.axis, q1) @ (lg.elbow - lg.base)
    else:
        P1, E = lg.base + q1 * lg.axis, lg.elbow + q1 * lg.axis
    if sr.is_hexapod(robot.leg):
        return [P1, E, S]
    half = 0.5 * lg.width * lg.bar
    return [P1, E + half, E - half, S + half, S - half]


@pytest.mark.parametrize("leg", LEGS)
def test_every_body_balanced_by_the_output_loads(leg):
    """Each body's Newton-Euler equations rebuilt from the outputs (loads at the documented
    points, earlier on later) with finite-difference rates of change of its momenta."""
    _, robot, motion, out = _case(leg)
    q, qd, _ = motion(T)
    qp, qdp, _ = motion(T + H)
    qm, qdm, _ = motion(T - H)
    # incidence: body index within the leg -> (incoming joints, outgoing joints), 1-based
    if sr.is_hexapod(leg):
        inc = [((1,), (2,)), ((2,), (3,))]
        plat_in = (3,)
    else:
        inc = [((1,), (2, 3)), ((2,), (4,)), ((3,), (5,))]
        plat_in = (4, 5)
    nb = len(inc)
    g = robot.gravity
    for k in range(T.size):
        now = _body_momenta(robot, q[k], qd[k])
        plus, minus = _body_momenta(robot, qp[k], qdp[k]), _body_momenta(robot, qm[k], qdm[k])
        smp = sr.sample_state(robot, q[k], qd[k], np.zeros_like(q[k]))
        masses = [bd.mass for bd in smp.bodies]
        plat_F = robot.payload_force + masses[-1] * g
        c_p = now[-1][0]
        plat_M = robot.payload_moment + np.cross(q[k, :3] - c_p, robot.payload_force)
        for i, name in enumerate(robot.leg_names):
            pts = _doc_points(robot, out, i, k, q[k])

            def wrench(j, c, name=name, pts=pts, k=k):
                f = _vec(out, "f", j, name)[k]
                m = _vec(out, "m", j, name)[k]
                return f, m + np.cross(pts[j - 1] - c, f)

            for b, (ins, outs) in enumerate(inc):
                ib = nb * i + b
                c = now[ib][0]
                F, M = masses[ib] * g, np.zeros(3)
                for j in ins:
                    f, m = wrench(j, c)
                    F, M = F + f, M + m
                for j in outs:
                    f, m = wrench(j, c)
                    F, M = F - f, M - m
                dp = (plus[ib][1] - minus[ib][1]) / (2 * H)
                dL = (plus[ib][2] - minus[ib][2]) / (2 * H)
                tol = 1e-7 * _scale(F, M, dp, masses[ib] * g)
                np.testing.assert_allclose(F, dp, rtol=0, atol=tol, err_msg=f"{name} body {b}")
                np.testing.assert_allclose(M, dL, rtol=0, atol=tol, err_msg=f"{name} body {b}")
            for j in plat_in:
                f, m = wrench(j, c_p)
                plat_F, plat_M = plat_F + f, plat_M + m
        dp = (plus[-1][1] - minus[-1][1]) / (2 * H)
        dL = (plus[-1][2] - minus[-1][2]) / (2 * H)
        tol = 1e-7 * _scale(plat_F, plat_M, dp)
        np.testing.assert_allclose(plat_F, dp, rtol=0, atol=tol)
        np.testing.assert_allclose(plat_M, dL, rtol=0, atol=tol)


# ------------------------------------------------------------------------------------------------
# Joint load conditions, statics.


@pytest.mark.parametrize("leg", LEGS)
def test_joint_load_conditions(leg):
    """S: no moment; U: no moment along its two current axes; actuated joint: tau along it."""
    _, robot, motion, out = _case(leg)
    q = motion(T)[0]
    n = T.size
    for name, lg in zip(robot.leg_names, robot.legs, strict=True):
        tau = out[f"tau_{name}"]
        scale_m = _scale(*(_vec(out, "m", j, name) for j in (1, 2)), tau)
        s_joints = (3,) if sr.is_hexapod(leg) else (2, 3, 4, 5)
        for j in s_joints:
            assert np.max(np.abs(_vec(out, "m", j, name))) < 1e-9 * scale_m
        if leg == "UPS":
            u1, u2 = lg.u_axes
            m1 = _vec(out, "m", 1, name)
            for k in range(n):
                u2c = sr.rot(u1, out[f"q1a_{name}"][k]) @ u2
                S = sr.euler_matrix(*q[k, 3:]) @ lg.platform + q[k, :3]
                e = (S - lg.base) / np.linalg.norm(S - lg.base)
                assert abs(m1[k] @ u1) < 1e-9 * scale_m
                assert abs(m1[k] @ u2c) < 1e-9 * scale_m
                f2 = _vec(out, "f", 2, name)[k]
                assert f2 @ e == pytest.approx(tau[k], abs=1e-9 * _scale(f2, tau))
            continue
        k_axis = lg.axis
        if leg in ("RUS", "RSS2"):
            along = _vec(out, "m", 1, name) @ k_axis
        else:
            along = _vec(out, "f", 1, name) @ k_axis
        np.testing.assert_allclose(along, tau, rtol=1e-10, atol=1e-10 * _scale(tau))
        if leg in ("RUS", "PUS"):
            u1, u2 = lg.u_axes
            m2 = _vec(out, "m", 2, name)
            for k in range(n):
                R1 = sr.rot(k_axis, out[f"q1_{name}"][k]) if leg == "RUS" else np.eye(3)
                u1c = R1 @ u1
                u2c = R1 @ sr.rot(u1, out[f"q2a_{name}"][k]) @ u2
                assert abs(m2[k] @ u1c) < 1e-9 * scale_m
                assert abs(m2[k] @ u2c) < 1e-9 * scale_m


@pytest.mark.parametrize("leg", LEGS)
def test_statics_at_rest(leg):
    """At rest under vertical gravity without payload the base-joint forces carry the weight."""
    model, _, motion, _ = _case(leg)
    model = {k: v for k, v in model.items() if k not in ("payload", "environment")}
    robot = sr.parse_model(model)
    q = motion(T[:3])[0]
    z = np.zeros_like(q)
    out = sr.solve(robot, q, z, z)
    weight = robot.total_mass * 9.81
    total = sum(_vec(out, "f", 1, name) for name in robot.leg_names)
    np.testing.assert_allclose(total[:, 2], weight, rtol=1e-10)
    np.testing.assert_allclose(total[:, :2], 0.0, atol=1e-10 * weight)
    # the efforts alone hold the platform by virtual work: J^T tau = dV/dq
    J = sr.actuator_jacobian(robot, q)
    tau = sr.efforts(robot, out)
    k = robot.dof
    h = 1e-6
    for s in range(q.shape[0]):
        grad = np.zeros(k)
        for c in range(k):
            dq = np.zeros(k)
            dq[c] = h
            grad[c] = (
                sr.energy(robot, q[s] + dq, np.zeros(k))[1][0]
                - sr.energy(robot, q[s] - dq, np.zeros(k))[1][0]
            ) / (2 * h)
        np.testing.assert_allclose(tau[s] @ J[s], grad, rtol=1e-6, atol=1e-6 * weight)


@pytest.mark.parametrize("leg", LEGS)
def test_no_gravity_at_rest_no_loads(leg):
    model, _, motion, _ = _case(leg)
    model = {k: v for k, v in model.items() if k != "payload"}
    model["environment"] = {"gravity": [0.0, 0.0, 0.0]}
    q = motion(T[:2])[0]
    z = np.zeros_like(q)
    out = sr.solve(model, q, z, z)
    for key, v in out.items():
        if key[0] in "fmt":
            assert np.max(np.abs(v)) < 1e-12, key


# ------------------------------------------------------------------------------------------------
# Home, invariance, symmetry.


@pytest.mark.parametrize("leg", LEGS)
def test_joint_coordinates_zero_at_home(leg):
    model, robot, _, _ = _case(leg)
    z = np.zeros((1, robot.dof))
    ik = sr.inverse_kinematics(robot, z)
    assert all(abs(v[0]) < 1e-12 for v in ik.values())
    out = sr.solve(model, z, z, z)
    for key, v in out.items():
        if key.startswith("q"):
            assert abs(v[0]) < 1e-12, key
    assert np.all(np.abs(sr.actuated_coordinates(robot, z)) < 1e-12)


@pytest.mark.parametrize("leg", LEGS)
def test_joint_coordinates_rebuild_the_pose(leg):
    """The outputs' coordinates, composed as the documentation defines them, put every body
    where the pose puts the platform: U angles turn the leg / rod onto its direction, the S
    rotation vector is the platform's rotation seen from the body before it, the rod has its
    home length, and the working mode keeps the sign of D."""
    _, robot, motion, out = _case(leg)
    q = motion(T)[0]
    for k in range(T.size):
        R = sr.euler_matrix(*q[k, 3:]) if robot.dof == 6 else np.eye(3)
        for lg, name in zip(robot.legs, robot.leg_names, strict=True):
            S = R @ lg.platform + q[k, :3]
            if leg == "UPS":
                R1, start, ua = np.eye(3), lg.base, "1"
                assert np.linalg.norm(S - lg.base) - np.linalg.norm(
                    lg.platform - lg.base
                ) == pytest.approx(out[f"q2_{name}"][k], abs=1e-12)
            else:
                q1 = out[f"q1_{name}"][k]
                if leg[0] == "R":
                    R1 = sr.rot(lg.axis, q1)
                    E = lg.base + R1 @ (lg.elbow - lg.base)
                    dE = np.cross(lg.axis, E - lg.base)
                else:
                    R1, E, dE = np.eye(3), lg.elbow + q1 * lg.axis, lg.axis
                assert np.linalg.norm(S - E) == pytest.approx(lg.length, rel=1e-12)
                assert np.sign((S - E) @ dE) == lg.home_sign
                if not sr.is_hexapod(leg):
                    continue
                start, ua = lg.elbow, "2"
            u1, u2 = lg.u_axes
            a, b = out[f"q{ua}a_{name}"][k], out[f"q{ua}b_{name}"][k]
            assert max(abs(a), abs(b)) < math.pi / 2
            Rl = R1 @ sr.rot(u1, a) @ sr.rot(u2, b)
            e0 = _unit(lg.platform - start)
            end = lg.base if leg == "UPS" else E
            np.testing.assert_allclose(Rl @ e0, _unit(S - end), atol=1e-12)
            rv = np.array([out[f"q3{c}_{name}"][k] for c in "xyz"])
            assert np.linalg.norm(rv) < math.pi
            np.testing.assert_allclose(Rotation.from_rotvec(rv).as_matrix(), Rl.T @ R, atol=1e-12)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _turned_motion(robot: sr.Robot, Q: np.ndarray, q, qd, qdd):
    """The pose trajectory of the turned robot that moves every point as ``Q`` times the
    original's (``x' = Q x``, ``R' = Q R Q^T``)."""
    q2, qd2, qdd2 = q.copy(), qd.copy(), qdd.copy()
    q2[:, :3], qd2[:, :3], qdd2[:, :3] = q[:, :3] @ Q.T, qd[:, :3] @ Q.T, qdd[:, :3] @ Q.T
    if robot.dof == 3:
        return q2, qd2, qdd2
    for k in range(q.shape[0]):
        R = sr.euler_matrix(*q[k, 3:])
        q2[k, 3:] = sr.euler_angles(Q @ R @ Q.T)
        E = sr.euler_rate_matrix(q2[k])
        w = Q @ sr.angular_velocity(q[k], qd[k])
        al = Q @ sr.angular_acceleration(q[k], qd[k], qdd[k])
        qd2[k, 3:] = np.linalg.solve(E, w)
        bias = sr.angular_acceleration(q2[k], qd2[k], np.zeros(6))
        qdd2[k, 3:] = np.linalg.solve(E, al - bias)
    return q2, qd2, qdd2


@pytest.mark.parametrize("leg", LEGS)
def test_turning_the_model_turns_the_loads(leg):
    model, robot, motion, out = _case(leg)
    deg = 37.0
    Q = sr.rz(math.radians(deg))
    turned = sr.parse_model(sm.turn_model(model, deg))
    out2 = sr.solve(turned, *_turned_motion(robot, Q, *motion(T)))
    for name in robot.leg_names:
        for fam in ("f", "m"):
            for j in range(1, sr.n_joints(leg) + 1):
                v, v2 = _vec(out, fam, j, name), _vec(out2, fam, j, name)
                np.testing.assert_allclose(v2, v @ Q.T, rtol=0, atol=1e-9 * _scale(v))
        if sr.is_hexapod(leg):
            s = np.stack([out[f"q3{c}_{name}"] for c in "xyz"], axis=1)
            s2 = np.stack([out2[f"q3{c}_{name}"] for c in "xyz"], axis=1)
            np.testing.assert_allclose(s2, s @ Q.T, atol=1e-10)
    for key, v in out.items():
        if key.startswith(("tau", "q1", "q2", "qd", "qdd")):
            np.testing.assert_allclose(out2[key], v, rtol=1e-9, atol=1e-9, err_msg=key)


@pytest.mark.parametrize("leg", LEGS)
def test_gallery_symmetric_expansion(leg):
    model = sm.gallery()[leg]
    assert model["symmetric"] is True
    explicit = dict(model, symmetric=False, legs=sr.expand_symmetric(leg, model["legs"]))
    robot = sr.parse_model(model)
    rng = np.random.default_rng(5)
    q, qd, qdd = sm.random_motion(model, rng, 4)
    a, b = sr.solve(model, q, qd, qdd), sr.solve(explicit, q, qd, qdd)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])
    # symmetric robot at home under vertical gravity, payload along z: equal efforts
    z = np.zeros((1, robot.dof))
    tau = sr.efforts(robot, sr.solve(robot, z, z, z))[0]
    np.testing.assert_allclose(tau, tau[0], rtol=1e-10, atol=1e-12)
    assert np.all(sm.conditioning(robot, q) < sm.MAX_COND_MOTION)


# ------------------------------------------------------------------------------------------------
# Model errors.


def test_model_errors():
    model = sm.tsai_ups()
    with pytest.raises(ValueError, match="unknown key 'colour'"):
        sr.parse_model(dict(model, colour="red"))
    with pytest.raises(ValueError, match="actuated"):
        sr.parse_model(dict(model, actuated=1))
    legs = dict(model["legs"])
    legs["A"] = dict(legs["A"], u_axes=[[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"legs\.A\.u_axes"):
        sr.parse_model(dict(model, legs=legs))
    legs = dict(model["legs"])
    legs["A"] = dict(legs["A"], axis=[0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="unknown key 'axis'"):
        sr.parse_model(dict(model, legs=legs))
    delta = sm.delta()
    with pytest.raises(ValueError, match="legs"):
        sr.parse_model(dict(delta, symmetric=False))


def test_unreachable_pose_gives_nan():
    robot = sr.parse_model(sm.delta())
    q = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -5.0]])
    out = sr.solve(robot, q, np.zeros_like(q), np.zeros_like(q))
    assert np.isfinite(out["tau_A"][0])
    assert np.isnan(out["tau_A"][1])
