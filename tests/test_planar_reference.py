"""Self-checks of the independent planar reference (tests/planar_reference.py).

The reference judges the production code for every planar 3-leg structure, so it is checked here
against physics it was not built from: the existing 3-RPR Newton-Euler reference (paper twin),
energy (power balance with finite-difference dE/dt), statics of the whole robot, Newton-Euler
residuals rebuilt from the outputs with finite-difference accelerations, finite differences of
the inverse kinematics, the kinetic-energy mass matrix, symmetry, and brute-force assembly modes.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

try:
    from . import mujoco_planar as mp
    from . import newton_euler as ne
    from . import planar_models as pm
    from . import planar_reference as pr
except ImportError:
    import mujoco_planar as mp
    import newton_euler as ne
    import planar_models as pm
    import planar_reference as pr

STRUCTURES = pm.nonsingular_structures()
IDS = [f"{leg}{a}" for leg, a in STRUCTURES]
T = np.linspace(0.0, 2.0, 25)
H = 1e-5  # time step of the central differences, s


@functools.cache
def _case(leg: str, actuated: int):
    """A random robot of the structure and a random motion sampled at T - H, T, T + H."""
    seed = 1000 + 10 * pr.LEG_TYPES.index(leg) + actuated
    rng = np.random.default_rng(seed)
    model = pm.random_model(rng, leg, actuated)
    robot = pr.parse_model(model)
    times = np.concatenate([T - H, T, T + H])
    q, qd, qdd = pm.random_motion(rng, robot, times)
    return model, robot, q, qd, qdd


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(before, at, after) samples of an array over ``[T - H, T, T + H]``."""
    n = T.size
    return a[:n], a[n : 2 * n], a[2 * n :]


def _central(a: np.ndarray) -> np.ndarray:
    before, _, after = _split(a)
    return (after - before) / (2 * H)


def _angle_central(a: np.ndarray) -> np.ndarray:
    before, _, after = _split(a)
    return pr.wrap_to_pi(after - before) / (2 * H)


def _scale(out, families) -> float:
    return max(float(np.max(np.abs(out[f"{f}_{leg}"]))) for f in families for leg in pr.LEGS) or 1.0


LOAD_FAMILIES = ("fx1", "fy1", "m1", "fx2", "fy2", "m2", "fx3", "fy3", "m3", "tau")


# -- model parsing and generators -----------------------------------------------------------------


def test_structure_lists() -> None:
    assert len(pm.all_structures()) == 21
    assert len(STRUCTURES) == 18
    assert set(pm.all_structures()) - set(STRUCTURES) == set(pr.SINGULAR_STRUCTURES)


def test_random_model_is_deterministic_and_valid() -> None:
    a = pm.random_model(np.random.default_rng(3), "PRR", 2)
    b = pm.random_model(np.random.default_rng(3), "PRR", 2)
    assert a == b
    robot = pr.parse_model(a)
    # Everything positive, centres of mass off their joint lines, platform com off G.
    for leg in robot.legs:
        assert np.all(leg.mass > 0)
        assert np.all(leg.inertia > 0)
        for k in range(2):
            seg = leg.joints[k + 1] - leg.joints[k]
            off = abs(pr._cross(seg, leg.com[k] - leg.joints[k])) / np.linalg.norm(seg)
            assert off > 5e-3
    assert np.linalg.norm(robot.platform_com) > 5e-3
    assert abs(robot.gravity[0]) > 1.0
    assert robot.gravity[1] < -5.0
    assert np.all(robot.payload_force != 0.0)


@pytest.mark.parametrize(("leg", "actuated"), list(pr.SINGULAR_STRUCTURES))
def test_random_model_refuses_singular_structures(leg: str, actuated: int) -> None:
    with pytest.raises(ValueError, match="architecturally singular"):
        pm.random_model(np.random.default_rng(0), leg, actuated)


def test_parse_model_errors() -> None:
    model = pm.random_model(np.random.default_rng(4), "RPR", 2)
    with pytest.raises(ValueError, match="'colour'"):
        pr.parse_model({**model, "colour": "red"})
    with pytest.raises(ValueError, match="leg"):
        pr.parse_model({**model, "leg": "PPP"})
    with pytest.raises(ValueError, match="actuated"):
        pr.parse_model({**model, "actuated": 4})
    legs = {k: dict(v) for k, v in model["legs"].items()}
    legs["B"]["axes"] = [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    with pytest.raises(ValueError, match=r"legs\.B\.axes\[1\]"):
        pr.parse_model({**model, "legs": legs})
    # An RPR leg whose slider is normal to joint 1 -> joint 3 has D = 0 at home.
    legs = {k: dict(v) for k, v in model["legs"].items()}
    d = np.subtract(legs["C"]["joints"][2], legs["C"]["joints"][0])
    legs["C"]["axes"] = [[0.0, 0.0], [-d[1], d[0]], [0.0, 0.0]]
    with pytest.raises(ValueError, match=r"legs\.C: serial determinant D = 0"):
        pr.parse_model({**model, "legs": legs})
    # Optional tables take their defaults.
    robot = pr.parse_model({k: v for k, v in model.items() if k not in ("environment", "payload")})
    assert robot.gravity.tolist() == [0.0, -9.81]
    assert robot.payload_force.tolist() == [0.0, 0.0]
    assert robot.payload_moment == 0.0


def test_output_names() -> None:
    _, robot, q, qd, qdd = _case("RRR", 1)
    out = pr.solve(robot, q[:5], qd[:5], qdd[:5])
    assert set(out) == {f"{f}_{leg}" for f in pr.OUTPUT_FAMILIES for leg in pr.LEGS}
    assert len(out) == 57
    assert all(v.shape == (5,) for v in out.values())


# -- (a) the paper's robot ------------------------------------------------------------------------


def _paper_cases():
    p = ne.paper_params()
    cases = [(kind, p, *ne.paper_motion(kind, 31)[1:]) for kind in ("rotation", "rectilinear")]
    rng = np.random.default_rng(2024)
    while len(cases) < 5:
        params = pm.make_twinnable(ne.random_robot(rng)["params"])
        q, qd, qdd = ne.sinusoid_motion(rng, np.linspace(0.0, 2.0, 31))
        if ne.well_conditioned(params, q):
            cases.append((f"random{len(cases) - 2}", params, q, qd, qdd))
    return cases


PAPER_CASES = _paper_cases()


@pytest.mark.parametrize("actuation", ne.ACTUATIONS)
@pytest.mark.parametrize(
    ("name", "params", "q", "qd", "qdd"), PAPER_CASES, ids=[c[0] for c in PAPER_CASES]
)
def test_paper_twin_matches_newton_euler(name, params, q, qd, qdd, actuation) -> None:
    """The 3-RPR through the general reference gives tests/newton_euler.py's outputs.

    Measured: 4e-14 relative (loads up to 190 N).
    """
    robot = pr.parse_model(pm.paper_twin(params, actuation))
    assert robot.leg == "RPR"
    assert robot.actuated == pm.PAPER_ACTUATED[actuation]
    expected = ne.solve(params, actuation, q, qd, qdd)
    got = pm.paper_outputs(pr.solve(robot, q, qd, qdd), robot, q)
    assert set(got) == set(expected)
    for key, value in expected.items():
        diff = got[key] - value
        if key.startswith(("phi10", "phi32")):
            diff = pr.wrap_to_pi(diff)
        scale = max(float(np.max(np.abs(value))), 1.0)
        assert np.max(np.abs(diff)) <= 1e-9 * scale, key


def test_paper_twin_refuses_a_home_off_the_central_configuration() -> None:
    params = ne.random_robot(np.random.default_rng(1))["params"]
    with pytest.raises(ValueError, match="central configuration"):
        pm.paper_twin(params, "revolute")


# -- (b) power balance ----------------------------------------------------------------------------


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_power_balance(leg: str, actuated: int) -> None:
    """sum tau qd_actuated + payload power = dE/dt, dE/dt by central differences of E along the
    exact motion. Measured: 3e-9 of the power's peak (the difference's truncation)."""
    _, robot, q, qd, qdd = _case(leg, actuated)
    _, q0, _ = _split(q)
    out = pr.solve(robot, q0, _split(qd)[1], _split(qdd)[1])
    P = pr.input_power(robot, out, _split(qd)[1])
    dE = _central(pr.energy(robot, q, qd))
    scale = float(np.max(np.abs(P)))
    assert scale > 0.5  # the motion does work
    assert np.max(np.abs(P - dE)) <= 1e-7 * scale
    # The analytic rate agrees to round-off.
    rate = pr.energy_rate(robot, q0, _split(qd)[1], _split(qdd)[1])
    assert np.max(np.abs(P - rate)) <= 1e-12 * scale


# -- (c) statics and momentum of the whole robot --------------------------------------------------


def _coms(robot: pr.Robot, q: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """(mass, com position (n, 2)) of the seven bodies at the poses q."""
    motion = pr.leg_motion(robot, q, np.zeros_like(q))
    out = []
    for i, leg in enumerate(robot.legs):
        for k in (1, 2):
            out.append((leg.mass[k - 1], motion.chains[i].bodies[k].point(leg.com[k - 1])[0]))
    out.append((robot.platform_mass, q[:, :2] + pr._rotate(q[:, 2], robot.platform_com)))
    return out


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_statics_whole_robot(leg: str, actuated: int) -> None:
    """At rest, the base's loads on the three legs balance gravity and the payload: forces, and
    moments about the world origin. Measured: 6e-16 of the largest load."""
    _, robot, q, _, _ = _case(leg, actuated)
    q = _split(q)[1]
    zero = np.zeros_like(q)
    out = pr.solve(robot, q, zero, zero)
    pts = pr.joint_points(robot, q)
    force = np.broadcast_to(robot.payload_force, (q.shape[0], 2)).copy()
    moment = robot.payload_moment + pr._cross(q[:, :2], force)
    for m, c in _coms(robot, q):
        force += m * robot.gravity
        moment += pr._cross(c, m * np.broadcast_to(robot.gravity, c.shape))
    for name in pr.LEGS:
        f1 = np.stack([out[f"fx1_{name}"], out[f"fy1_{name}"]], axis=1)
        force += f1
        moment += out[f"m1_{name}"] + pr._cross(pts[name][:, 0], f1)
    scale = _scale(out, LOAD_FAMILIES)
    assert np.max(np.abs(force)) <= 1e-12 * scale
    assert np.max(np.abs(moment)) <= 1e-12 * scale


# -- Newton-Euler rebuilt from the outputs --------------------------------------------------------


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_body_equations_from_outputs(leg: str, actuated: int) -> None:
    """Each body's loads, summed from the outputs alone (joint points from the positions, the
    earlier body receiving the opposite of each joint load), equal m a and J alpha, with a and
    alpha by second central differences of the com positions and body angles along the exact
    motion. Measured: 1.2e-7 of the largest load (the differences' truncation, round-off)."""
    _, robot, q, qd, qdd = _case(leg, actuated)
    q0, qd0, qdd0 = (_split(a)[1] for a in (q, qd, qdd))
    out = pr.solve(robot, q0, qd0, qdd0)
    pts = pr.joint_points(robot, q0)
    coms = [_split(c) for _, c in _coms(robot, q)]
    qlegs = pr.inverse_kinematics(robot, q)
    n = q0.shape[0]
    g = robot.gravity
    h2 = H**2
    scale = _scale(out, LOAD_FAMILIES)
    plat_f = np.broadcast_to(robot.payload_force + robot.platform_mass * g, (n, 2)).copy()
    C3 = coms[6][1]
    plat_m = robot.payload_moment + pr._cross(q0[:, :2] - C3, plat_f - robot.platform_mass * g)
    for i, name in enumerate(pr.LEGS):
        f = [np.stack([out[f"fx{j}_{name}"], out[f"fy{j}_{name}"]], axis=1) for j in (1, 2, 3)]
        m = [out[f"m{j}_{name}"] for j in (1, 2, 3)]
        X = [pts[name][:, j] for j in range(3)]
        # Body angles: sums of the R coordinates up to the body.
        angles = [np.zeros(3 * n)]
        for j in range(2):
            step = qlegs[i][:, j] if robot.leg[j] == "R" else 0.0
            angles.append(angles[-1] + step)
        for k in (1, 2):
            body = robot.legs[i]
            before, C, after = coms[2 * i + k - 1]
            acc = (after - 2 * C + before) / h2
            a0, a1, a2 = _split(angles[k])
            alpha = (pr.wrap_to_pi(a2 - a1) - pr.wrap_to_pi(a1 - a0)) / h2
            F = f[k - 1] - f[k] + body.mass[k - 1] * (g - acc)
            M = (
                m[k - 1]
                + pr._cross(X[k - 1] - C, f[k - 1])
                - m[k]
                - pr._cross(X[k] - C, f[k])
                - body.inertia[k - 1] * alpha
            )
            assert np.max(np.abs(F)) <= 2e-6 * scale, (name, k)
            assert np.max(np.abs(M)) <= 2e-6 * scale, (name, k)
        plat_f += f[2]
        plat_m += m[2] + pr._cross(X[2] - C3, f[2])
    before, C3, after = coms[6]
    a3 = (after - 2 * C3 + before) / h2
    p0, p1, p2 = _split(q[:, 2])
    plat_f -= robot.platform_mass * a3
    plat_m -= robot.platform_inertia * (p2 - 2 * p1 + p0) / h2
    assert np.max(np.abs(plat_f)) <= 2e-6 * scale
    assert np.max(np.abs(plat_m)) <= 2e-6 * scale


# -- (d) free directions and efforts --------------------------------------------------------------


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_free_directions_carry_no_load(leg: str, actuated: int) -> None:
    """A passive R joint has m = 0, a passive P joint no force along its current axis (the home
    axis turned by the R coordinates before it); tau is the actuated joint's m or axial force."""
    _, robot, q, qd, qdd = _case(leg, actuated)
    q0, qd0, qdd0 = (_split(a)[1] for a in (q, qd, qdd))
    out = pr.solve(robot, q0, qd0, qdd0)
    scale = _scale(out, LOAD_FAMILIES)
    for i, name in enumerate(pr.LEGS):
        theta = np.zeros(q0.shape[0])
        for j, kind in enumerate(robot.leg, start=1):
            if kind == "R":
                load = out[f"m{j}_{name}"]
                theta = theta + out[f"q{j}_{name}"]
            else:
                axis = pr._rotate(theta, robot.legs[i].axes[j - 1])
                load = out[f"fx{j}_{name}"] * axis[:, 0] + out[f"fy{j}_{name}"] * axis[:, 1]
            if j == actuated:
                assert np.max(np.abs(load - out[f"tau_{name}"])) <= 1e-13 * scale
                assert np.max(np.abs(load)) > 1e-3 * scale
            else:
                assert np.max(np.abs(load)) <= 1e-13 * scale


# -- (e) kinematics -------------------------------------------------------------------------------


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_inverse_kinematics(leg: str, actuated: int) -> None:
    """The chain's forward kinematics of the IK gives the pose back; D has its home sign; home
    gives zero joint coordinates; rates and accelerations are the central differences of the
    coordinates and rates. Measured: pose 3e-16, rates and accelerations 2e-9 relative."""
    _, robot, q, qd, qdd = _case(leg, actuated)
    home = pr.inverse_kinematics(robot, np.zeros((1, 3)))
    assert all(np.max(np.abs(h)) <= 1e-14 for h in home)
    qlegs = pr.inverse_kinematics(robot, q)
    for i in range(3):
        pose = pr.forward_chain_pose(robot, i, qlegs[i])
        assert np.max(np.abs(pose[:, :2] - q[:, :2])) <= 1e-13
        assert np.max(np.abs(pr.wrap_to_pi(pose[:, 2] - q[:, 2]))) <= 1e-13
    D = pr.serial_determinant(robot, q)
    assert np.all(np.sign(D) == robot.home_sign)
    motion = pr.leg_motion(robot, q, qd, qdd)
    for i in range(3):
        for j, kind in enumerate(robot.leg):
            diff = _angle_central if kind == "R" else _central
            rate = _split(motion.qd[i][:, j])[1]
            acc = _split(motion.qdd[i][:, j])[1]
            scale_v = max(float(np.max(np.abs(rate))), 1e-3)
            scale_a = max(float(np.max(np.abs(acc))), 1e-3)
            assert np.max(np.abs(diff(qlegs[i][:, j]) - rate)) <= 1e-7 * scale_v
            assert np.max(np.abs(_central(motion.qd[i][:, j]) - acc)) <= 1e-7 * scale_a


def test_joint_points_match_the_model_at_home() -> None:
    model, robot, *_ = _case("PRP", 1)
    pts = pr.joint_points(robot, np.zeros((1, 3)))
    for name in pr.LEGS:
        np.testing.assert_allclose(pts[name][0], model["legs"][name]["joints"], atol=1e-15)


def test_unreachable_pose_gives_nan() -> None:
    _, robot, *_ = _case("RRR", 2)
    far = np.array([[5.0, 0.0, 0.0]])
    assert all(np.all(np.isnan(x)) for x in pr.inverse_kinematics(robot, far))
    out = pr.solve(robot, far, np.zeros((1, 3)), np.zeros((1, 3)))
    assert np.isnan(out["tau_A"][0])


# -- (f), (g) control form ------------------------------------------------------------------------


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_task_space_dynamics(leg: str, actuated: int) -> None:
    """M is symmetric positive definite and equals the kinetic-energy mass matrix;
    M qdd + c = J^T tau; the forward dynamics inverts solve. Measured: 2e-15 relative (M),
    3e-13 (the forward dynamics)."""
    _, robot, q, qd, qdd = _case(leg, actuated)
    q0, qd0, qdd0 = (_split(a)[1][::3] for a in (q, qd, qdd))
    M, c = pr.task_space(robot, q0, qd0)
    scale_m = float(np.max(np.abs(M)))
    assert np.max(np.abs(M - np.swapaxes(M, 1, 2))) <= 1e-12 * scale_m
    assert np.all(np.linalg.eigvalsh(M) > 0)
    assert np.max(np.abs(M - pr.mass_matrix_from_energy(robot, q0))) <= 1e-12 * scale_m
    tau = pr.efforts(pr.solve(robot, q0, qd0, qdd0))
    J = pr.actuator_jacobian(robot, q0)
    lhs = np.einsum("nij,nj->ni", M, qdd0) + c
    rhs = np.einsum("nji,nj->ni", J, tau)
    assert np.max(np.abs(lhs - rhs)) <= 1e-12 * float(np.max(np.abs(rhs)))
    back = pr.forward_dynamics(robot, q0, qd0, tau)
    assert np.max(np.abs(back - qdd0)) <= 1e-10 * float(np.max(np.abs(qdd0)))


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_actuator_jacobian_is_the_derivative_of_the_inverse_kinematics(
    leg: str, actuated: int
) -> None:
    """J = d qa / d q against central differences of the IK (step 1e-6).

    Measured: 9e-10 relative."""
    _, robot, q, _, _ = _case(leg, actuated)
    q0 = _split(q)[1][::4]
    J = pr.actuator_jacobian(robot, q0)
    step = 1e-6
    for k in range(3):
        dq = np.zeros(3)
        dq[k] = step
        plus = pr.inverse_kinematics(robot, q0 + dq)
        minus = pr.inverse_kinematics(robot, q0 - dq)
        for i in range(3):
            d = plus[i][:, actuated - 1] - minus[i][:, actuated - 1]
            if leg[actuated - 1] == "R":
                d = pr.wrap_to_pi(d)
            assert np.max(np.abs(d / (2 * step) - J[:, i, k])) <= 1e-7 * np.max(np.abs(J))


# -- (h) assembly modes ---------------------------------------------------------------------------


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_assembly_modes_contain_the_true_pose(leg: str, actuated: int) -> None:
    _, robot, q, _, _ = _case(leg, actuated)
    pose = _split(q)[1][7]
    qa = np.array([x[0, actuated - 1] for x in pr.inverse_kinematics(robot, pose[None])])
    modes = pr.assembly_modes_bruteforce(robot, qa)
    assert len(modes) >= 1
    dist = np.hypot(modes[:, 0] - pose[0], modes[:, 1] - pose[1])
    dist = np.hypot(dist, pr.wrap_to_pi(modes[:, 2] - pose[2]))
    assert np.min(dist) <= 1e-10
    # Every mode has these actuated coordinates, legs in the working mode.
    for mode in modes:
        got = np.array([x[0, actuated - 1] for x in pr.inverse_kinematics(robot, mode[None])])
        diff = got - qa
        if leg[actuated - 1] == "R":
            diff = pr.wrap_to_pi(diff)
        assert np.max(np.abs(diff)) <= 1e-9
    assert np.all(np.abs(modes[:, 2]) <= math.pi)


# -- (i) singular structures ----------------------------------------------------------------------


def _relative_smallest_singular_value(robot: pr.Robot, q: np.ndarray) -> np.ndarray:
    A, _, _ = pr.newton_euler_system(robot, q, np.zeros_like(q), np.zeros_like(q))
    s = np.linalg.svd(A, compute_uv=False)
    return s[:, -1] / s[:, 0]


@pytest.mark.parametrize(("leg", "actuated"), list(pr.SINGULAR_STRUCTURES))
def test_singular_structures_give_a_singular_system(leg: str, actuated: int) -> None:
    """The 21 x 21 system is singular at every pose for the three singular structures (smallest
    singular value relative to the largest: measured 1e-16), while the same robot with another
    motor gives a regular one (measured 0.04 to 0.06)."""
    rng = np.random.default_rng(7)
    model = pm.random_model_unchecked(rng, leg, actuated)
    robot = pr.parse_model(model)
    assert robot.singular_structure
    poses = np.array([[0.0, 0.0, 0.0], [0.01, -0.02, 0.05], [-0.02, 0.01, -0.1]])
    assert np.all(_relative_smallest_singular_value(robot, poses) < 1e-14)
    with pytest.raises(ValueError, match="architecturally singular"):
        pr.solve(robot, poses, np.zeros_like(poses), np.zeros_like(poses))
    other = next(a for a in (1, 2, 3) if a != actuated)
    regular = pr.parse_model({**model, "actuated": other})
    assert np.all(_relative_smallest_singular_value(regular, poses) > 1e-3)


# -- symmetry -------------------------------------------------------------------------------------


def test_symmetric_robot_turns_with_the_scene() -> None:
    """A robot made by expand_symmetric: turning motion, gravity and payload by 120 deg about the
    origin gives leg B the outputs leg A had (forces turned, scalars equal)."""
    base = pm.random_model(np.random.default_rng(11), "RRP", 1)
    # The platform's com at G: any other point would not turn into itself.
    platform = {**base["platform"], "com": [0.0, 0.0]}
    model = {**base, "legs": pr.expand_symmetric(base["legs"]["A"]), "platform": platform}
    robot = pr.parse_model(model)
    th = 2 * math.pi / 3
    R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    turned = pr.parse_model(
        {
            **model,
            "environment": {"gravity": (R @ robot.gravity).tolist()},
            "payload": {
                "force": (R @ robot.payload_force).tolist(),
                "moment": robot.payload_moment,
            },
        }
    )
    rng = np.random.default_rng(5)
    q, qd, qdd = ne.sinusoid_motion(rng, np.linspace(0, 1, 9), (0.02, 0.02, 0.1))
    out = pr.solve(robot, q, qd, qdd)
    qt, qdt, qddt = (np.concatenate([a[:, :2] @ R.T, a[:, 2:]], axis=1) for a in (q, qd, qdd))
    out_t = pr.solve(turned, qt, qdt, qddt)
    scale = _scale(out, LOAD_FAMILIES)
    for src, dst in (("A", "B"), ("B", "C"), ("C", "A")):
        for fam in pr.OUTPUT_FAMILIES:
            if fam.startswith(("fx", "fy")):
                continue
            diff = out_t[f"{fam}_{dst}"] - out[f"{fam}_{src}"]
            if fam[0] == "q" and fam[-1] in "12":  # R coordinates: modulo 2 pi
                diff = pr.wrap_to_pi(diff)
            tol = 1e-12 * (scale if fam[0] in "mt" else 1.0)
            assert np.max(np.abs(diff)) <= tol, (fam, src)
        for j in (1, 2, 3):
            f = np.stack([out[f"fx{j}_{src}"], out[f"fy{j}_{src}"]], axis=1) @ R.T
            ft = np.stack([out_t[f"fx{j}_{dst}"], out_t[f"fy{j}_{dst}"]], axis=1)
            assert np.max(np.abs(ft - f)) <= 1e-12 * scale


# -- MuJoCo peer (optional: the ``peers`` extra) -------------------------------------------------

MUJOCO_STRUCTURES = [(leg, a) for leg, a in STRUCTURES if leg in mp.SUPPORTED_LEGS]
MUJOCO_IDS = [f"{leg}{a}" for leg, a in MUJOCO_STRUCTURES]


def test_mujoco_peer_refuses_a_prismatic_joint_3() -> None:
    _, robot, *_ = _case("RRP", 1)
    with pytest.raises(ValueError, match="joint 3 must be revolute"):
        mp.build_mjcf(robot)


@pytest.mark.parametrize(("leg", "actuated"), MUJOCO_STRUCTURES, ids=MUJOCO_IDS)
def test_mujoco_rigid_inverse_dynamics_matches(leg: str, actuated: int) -> None:
    """MuJoCo's open-tree inverse dynamics with the loops solved as rigid constraints gives the
    reference's efforts and joint-3 forces: this pins the MJCF (geometry, axes, masses, coms,
    inertias, gravity, payload, motor signs) to the model. Measured: 7e-16 of the largest load."""
    mujoco = pytest.importorskip("mujoco")
    _, robot, q, qd, qdd = _case(leg, actuated)
    model, data = mp.compile_model(robot)
    assert (model.nq, model.nv, model.neq, model.nu) == (9, 9, 3, 3)
    mujoco.mj_forward(model, data)
    assert mp.closure_error(model, data) < 1e-15  # qpos0 is home
    q0, qd0, qdd0 = (_split(a)[1][::6] for a in (q, qd, qdd))
    out = pr.solve(robot, q0, qd0, qdd0)
    scale = _scale(out, LOAD_FAMILIES)
    for k in range(q0.shape[0]):
        tau, force = mp.rigid_inverse_dynamics(robot, model, data, q0[k], qd0[k], qdd0[k])
        assert mp.closure_error(model, data) < 1e-14
        assert np.max(np.abs(data.efc_vel)) < 1e-13  # closed to first order too
        f3 = np.array([[out[f"fx3_{L}"][k], out[f"fy3_{L}"][k]] for L in pr.LEGS])
        assert np.max(np.abs(tau - pr.efforts(out)[k])) <= 1e-12 * scale
        assert np.max(np.abs(force - f3)) <= 1e-12 * scale


def _drive(robot: pr.Robot, q0: np.ndarray, qd0: np.ndarray, tau: np.ndarray, duration: float):
    """MuJoCo (RK4, dt = 1 ms, stiff closures) and RK4 of the reference's forward dynamics
    (step 10 ms) from the same state under the same constant efforts.

    Returns the largest distance between the two platforms' G (m) and angles (rad) at the
    reference's steps, the largest loop-closure error of MuJoCo (m), and the reference's states
    (steps, 6): pose and rate.
    """
    import mujoco

    model, data = mp.compile_model(robot)
    mp.set_state(robot, model, data, q0, qd0)
    data.ctrl[:] = tau
    step = 10e-3
    per_step = round(step / model.opt.timestep)

    def rate(state: np.ndarray) -> np.ndarray:
        qdd = pr.forward_dynamics(robot, state[:3], state[3:], tau)[0]
        return np.concatenate([state[3:], qdd])

    state = np.concatenate([q0, qd0])
    states = [state]
    position = angle = closure = 0.0
    for _ in range(round(duration / step)):
        k1 = rate(state)
        k2 = rate(state + step / 2 * k1)
        k3 = rate(state + step / 2 * k2)
        k4 = rate(state + step * k3)
        state = state + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        for _ in range(per_step):
            mujoco.mj_step(model, data)
        pose = mp.platform_state(model, data)[0]
        position = max(position, math.hypot(*(pose[:2] - state[:2])))
        angle = max(angle, abs(pose[2] - state[2]))
        closure = max(closure, mp.closure_error(model, data))
        states.append(state)
    return position, angle, closure, np.array(states)


@pytest.mark.parametrize(
    ("leg", "actuated"), [("RRR", 1), ("RRR", 2), ("RRR", 3), ("PRR", 1), ("PRR", 2), ("PRR", 3)]
)
def test_mujoco_moves_like_the_reference_forward_dynamics(leg: str, actuated: int) -> None:
    """0.3 s under constant efforts (the static ones of the start pose plus 2 % of their peak,
    random signs) from a slowly moving start: MuJoCo's platform follows the reference's forward
    dynamics. Measured: at most 1.2e-7 m and 8e-7 rad (RRR, actuated 2), while the platform
    moves 6e-3 to 8e-2 (m or rad); loop closures within 2.1e-8 m.

    The residual is both integrations' discretisation: with MuJoCo at dt = 0.1 ms (solref 0.2 ms)
    and the reference at 5 ms it drops to 4e-9 m and 3e-8 rad (RRR, 2), 2e-9 m (PRR, 1).
    """
    pytest.importorskip("mujoco")
    _, robot, q, qd, _ = _case(leg, actuated)
    rng = np.random.default_rng(17)
    q0, qd0 = _split(q)[1][3], 0.05 * _split(qd)[1][3]
    zero = np.zeros((1, 3))
    tau = pr.efforts(pr.solve(robot, q0[None], zero, zero))[0]
    tau = tau + 0.02 * np.max(np.abs(tau)) * rng.choice([-1.0, 1.0], 3) * rng.uniform(0.5, 1, 3)
    position, angle, closure, states = _drive(robot, q0, qd0, tau, 0.3)
    # The reference stays in the working mode, away from singularities, all the way.
    assert np.all(np.isfinite(states))
    assert pm.motion_ok(robot, states[:, :3])
    assert position < 1e-6
    assert angle < 4e-6
    assert closure < 1e-7
    assert np.max(np.abs(states[:, :3] - q0)) > 3e-3  # a real motion, far beyond the bounds
