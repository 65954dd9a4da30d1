"""The control model's mathematics (derive/planar/control.py, tests/fk_reference.py), numerically.

The symbolic expressions are evaluated assignment by assignment (``program_eval``) and checked
against the independent Newton-Euler reference (``newton_euler``: inverse kinematics, joint loads,
energy), against finite differences, and against each other, on the paper's robot and on random
ones, for both actuations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import fk_reference as fk
import numpy as np
import pytest
import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import control, direct_kinematics, paper, registry, structures
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.derivation import derive

try:
    from . import newton_euler as ne
    from .program_eval import compile_program
except ImportError:
    import newton_euler as ne
    from program_eval import compile_program

ACTUATIONS = ("revolute", "prismatic")
EFFORT = {"revolute": "m10", "prismatic": "f21z"}
COORDINATE = {"revolute": "phi10", "prismatic": "lambda21"}
RATE = {"revolute": "omega10", "prismatic": "v21"}
ACCELERATION = {"revolute": "eps10", "prismatic": "gamma21"}
PARAM_NAMES = paper.PARAM_NAMES
PARAMS = [paper.params[name] for name in PARAM_NAMES]
#: The paper's two variants, by actuation.
S = {a: structures.from_variant(a) for a in ACTUATIONS}
T = np.linspace(0.0, 2.0, 41)
SEEDS = (1, 2, 3)
COS_IN, SIN_IN = sp.Symbol("cos_phi_in", real=True), sp.Symbol("sin_phi_in", real=True)


@dataclass
class Model:
    """The control model of one actuation, compiled to NumPy."""

    actuation: str
    program: Program
    dynamics: Callable  # params, q, qd, tau -> J (9), J'q' (3), M (9), c (3), qdd (3)
    fk: Callable  # params, qa (, cos_phi_in, sin_phi_in) -> modes or sextic and pose


def _build(actuation: str) -> Model:
    prog = Program()
    J = control.actuator_jacobian(prog, S[actuation])
    rate = control.jacobian_rate_term(prog, S[actuation])
    M, c = control.task_space_dynamics(prog, S[actuation])
    qdd = control.forward_dynamics(prog, S[actuation])
    outputs = [*J, *rate, *M, *c, *qdd]
    inputs = [*PARAMS, *syms.q, *syms.qd, *syms.tau]
    dynamics = compile_program(prog, inputs, outputs)
    robot = structures.robot(S[actuation])
    holds = direct_kinematics.locked_legs(robot, S[actuation])
    if actuation == "revolute":
        modes = direct_kinematics.line_modes(prog, robot, holds)
        fk_out = [getattr(m, name) for m in modes for name in ("x", "y", "phi", "margin")]
        fk_fn = compile_program(prog, [*PARAMS, *syms.qa], fk_out)
    else:
        coefficients = direct_kinematics.sextic_coefficients(prog, holds)
        x, y = direct_kinematics.pose_from_angle(prog, holds, COS_IN, SIN_IN)
        fk_fn = compile_program(prog, [*PARAMS, *syms.qa, COS_IN, SIN_IN], [*coefficients, x, y])
    return Model(actuation, prog, dynamics, fk_fn)


@pytest.fixture(scope="module")
def models() -> dict[str, Model]:
    """The control model of each actuation, derived and compiled once."""
    return {actuation: _build(actuation) for actuation in ACTUATIONS}


@pytest.fixture(params=ACTUATIONS)
def model(request: pytest.FixtureRequest, models: dict[str, Model]) -> Model:
    return models[request.param]


def _inputs(params: dict, q: np.ndarray, qd: np.ndarray, tau: np.ndarray | None = None) -> dict:
    values: dict = dict(params)
    for k, name in enumerate(syms.POSE_NAMES):
        values[name] = q[:, k]
    for k, name in enumerate(syms.VELOCITY_NAMES):
        values[name] = qd[:, k]
    tau = np.zeros_like(q) if tau is None else tau
    for k, name in enumerate([t.name for t in syms.tau]):
        values[name] = tau[:, k]
    return values


def _dynamics(model: Model, params: dict, q, qd, tau=None) -> dict[str, np.ndarray]:
    q, qd = np.atleast_2d(q), np.atleast_2d(qd)
    out = np.array(model.dynamics(**_inputs(params, q, qd, tau)))  # (27, n)
    n = q.shape[0]
    return {
        "J": out[0:9].T.reshape(n, 3, 3),
        "rate": out[9:12].T,
        "M": out[12:21].T.reshape(n, 3, 3),
        "c": out[21:24].T,
        "qdd": out[24:27].T,
    }


def _reference_qa(params: dict, actuation: str, q) -> np.ndarray:
    kin = ne.kinematics(params, np.atleast_2d(q), np.zeros_like(np.atleast_2d(q)))
    return np.stack([kin[leg][COORDINATE[actuation]] for leg in ne.LEGS], axis=1)


def _efforts(params: dict, actuation: str, q, qd, qdd) -> np.ndarray:
    out = ne.solve(params, actuation, q, qd, qdd)
    return np.stack([out[f"{EFFORT[actuation]}_{leg}"] for leg in ne.LEGS], axis=1)


def _cases():
    """The paper's robot on its two motions, then random robots on random motions."""
    params = ne.paper_params()
    for kind in ("rotation", "rectilinear"):
        _, q, qd, qdd = ne.paper_motion(kind, samples=31)
        yield params, q, qd, qdd
    for seed in SEEDS:
        robot, q, qd, qdd = ne.random_case(seed, T)
        yield robot["params"], q, qd, qdd


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


# ----------------------------------------------------------------------------------------------
# Structure


def test_the_program_extends_the_inverse_dynamics_unchanged(model: Model) -> None:
    reference = derive(S[model.actuation]).program
    prog = model.program
    n = len(reference.assignments)
    assert prog.assignments[:n] == reference.assignments
    # Calling the functions again, in another order, on the same program reuses what is there.
    size = len(prog.assignments)
    control.forward_dynamics(prog, S[model.actuation])
    control.task_space_dynamics(prog, S[model.actuation])
    control.jacobian_rate_term(prog, S[model.actuation])
    control.actuator_jacobian(prog, S[model.actuation])
    assert len(prog.assignments) == size


def test_names_never_shadow_parameters_or_inputs() -> None:
    for actuation in ACTUATIONS:
        for spec in registry.module(S[actuation]).functions:
            names = [a.symbol.name for a in spec.program.assignments]
            assert len(names) == len(set(names))
            assert not set(names) & control.reserved(S[actuation])


# ----------------------------------------------------------------------------------------------
# Jacobian and rate term


def test_jacobian_is_the_derivative_of_the_inverse_kinematics(model: Model) -> None:
    h = 1e-6
    for params, q, qd, _ in _cases():
        J = _dynamics(model, params, q, qd)["J"]
        fd = np.empty_like(J)
        for k in range(3):
            step = np.zeros(3)
            step[k] = h
            plus = _reference_qa(params, model.actuation, q + step)
            minus = _reference_qa(params, model.actuation, q - step)
            fd[:, :, k] = _wrap(plus - minus) / (2 * h)
        assert np.allclose(J, fd, rtol=0, atol=1e-7 * np.abs(J).max())
        kin = ne.kinematics(params, q, qd)
        rates = np.stack([kin[leg][RATE[model.actuation]] for leg in ne.LEGS], axis=1)
        assert np.allclose(np.einsum("nij,nj->ni", J, qd), rates, rtol=0, atol=1e-12)


def test_rate_term_is_the_derivative_of_the_jacobian_along_the_motion(model: Model) -> None:
    h = 1e-6
    for params, q, qd, qdd in _cases():
        out = _dynamics(model, params, q, qd)
        J_plus = _dynamics(model, params, q + h * qd, qd)["J"]
        J_minus = _dynamics(model, params, q - h * qd, qd)["J"]
        fd = np.einsum("nij,nj->ni", (J_plus - J_minus) / (2 * h), qd)
        scale = np.abs(out["J"]).max() * np.abs(qd).max() ** 2  # the size of J' q'
        assert np.allclose(out["rate"], fd, rtol=0, atol=1e-7 * scale)
        # qa'' = J q'' + J' q' is the actuator acceleration of the Newton-Euler kinematics.
        kin = ne.kinematics(params, q, qd, qdd)
        acc = np.stack([kin[leg][ACCELERATION[model.actuation]] for leg in ne.LEGS], axis=1)
        mine = np.einsum("nij,nj->ni", out["J"], qdd) + out["rate"]
        assert np.allclose(mine, acc, rtol=0, atol=1e-12 * max(1.0, np.abs(acc).max()))


# ----------------------------------------------------------------------------------------------
# Dynamics


def test_task_space_dynamics_matches_newton_euler(model: Model) -> None:
    for params, q, qd, qdd in _cases():
        out = _dynamics(model, params, q, qd)
        M, c, J = out["M"], out["c"], out["J"]
        assert np.array_equal(M, np.swapaxes(M, 1, 2))
        assert np.linalg.eigvalsh(M).min() > 0
        tau = _efforts(params, model.actuation, q, qd, qdd)
        lhs = np.einsum("nij,nj->ni", M, qdd) + c
        rhs = np.einsum("nji,nj->ni", J, tau)
        assert np.abs(lhs - rhs).max() <= 1e-9 * np.abs(rhs).max()


def test_both_methods_and_both_actuations_give_one_mass_matrix() -> None:
    """M, c are those of the mechanism, whatever joints are actuated; and the efforts route
    (``M = J^T A``, ``c = J^T b`` from the loads of eqs. 12-17) agrees with the virtual-power
    route to round-off."""
    robot, q, qd, _ = ne.random_case(7, T)
    params = robot["params"]
    results = []
    for actuation in ACTUATIONS:
        for method in ("virtual_power", "efforts"):
            prog = Program()
            M, c = control.task_space_dynamics(prog, S[actuation], method=method)
            f = compile_program(prog, [*PARAMS, *syms.q, *syms.qd], [*M, *c])
            results.append(np.array(f(**_inputs(params, q, qd))))
    for other in results[1:]:
        assert np.allclose(other, results[0], rtol=0, atol=1e-12 * np.abs(results[0]).max())


def test_forward_dynamics_inverts_the_inverse_dynamics(model: Model) -> None:
    for params, q, qd, qdd in _cases():
        tau = _efforts(params, model.actuation, q, qd, qdd)
        mine = _dynamics(model, params, q, qd, tau)["qdd"]
        assert np.abs(mine - qdd).max() <= 1e-9 * max(1.0, np.abs(qdd).max())


def test_free_motion_conserves_energy(model: Model) -> None:
    """Zero efforts, gravity only (no payload): RK4 of the forward dynamics for 0.2 s."""
    params = dict(ne.paper_params(), fx=0.0, fy=0.0, mz=0.0)
    robot = ne.random_case(4, T)[0]["params"]
    cases = [params, dict(robot, fx=0.0, fy=0.0, mz=0.0)]
    stacked = {k: np.array([p[k] for p in cases]) for k in PARAM_NAMES}
    q = np.array([[0.01, -0.02, 0.1], [0.0, 0.01, -0.05]])
    qd = np.array([[0.2, 0.6, -0.5], [-0.3, 0.5, 0.8]])

    def f(state: np.ndarray) -> np.ndarray:
        out = _dynamics(model, stacked, state[:, :3], state[:, 3:])
        return np.concatenate([state[:, 3:], out["qdd"]], axis=1)

    def energy(state: np.ndarray, gravity: bool = True) -> np.ndarray:
        return np.array(
            [
                ne.energy(p if gravity else dict(p, gx=0.0, gy=0.0), s[None, :3], s[None, 3:])[0]
                for p, s in zip(cases, state, strict=True)
            ]
        )

    dt, steps = 2e-3, 100
    state = np.concatenate([q, qd], axis=1)
    energies, kinetic = [energy(state)], [energy(state, gravity=False)]
    for _ in range(steps):
        k1 = f(state)
        k2 = f(state + dt / 2 * k1)
        k3 = f(state + dt / 2 * k2)
        k4 = f(state + dt * k3)
        state = state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        energies.append(energy(state))
        kinetic.append(energy(state, gravity=False))
        for p, s in zip(cases, state, strict=True):
            assert ne.well_conditioned(p, s[None, :3])
    drift = np.abs(np.array(energies) - energies[0]).max(axis=0)
    assert np.all(drift <= 1e-8 * np.array(kinetic).max(axis=0))  # per robot
    assert np.abs(state[:, :3] - q).max() > 0.02  # it did move


# ----------------------------------------------------------------------------------------------
# Forward kinematics: revolute actuation


def _qa_inputs(params: dict, qa: np.ndarray) -> dict:
    values: dict = dict(params)
    for k, name in enumerate([a.name for a in syms.qa]):
        values[name] = qa[..., k]
    return values


def _closes(params: dict, actuation: str, qa: np.ndarray, pose) -> bool:
    back = _reference_qa(params, actuation, np.asarray(pose, dtype=float))[0]
    diff = _wrap(back - qa) if actuation == "revolute" else back - qa
    return bool(np.abs(diff).max() < 1e-9)


def _near(geom: fk.Geometry, a, b, tol: float = 1e-8) -> bool:
    return fk.distance(geom, a, (b[0], b[1], fk.unwrap_near(b[2], a[2]))) < tol


def test_revolute_modes_round_trip(models: dict[str, Model]) -> None:
    model = models["revolute"]
    rng = np.random.default_rng(11)
    counts = []
    for params in fk.robots(rng, 12):
        geom = fk.Geometry.from_params(params)
        poses = fk.random_poses(rng, 10)
        qa = _reference_qa(params, "revolute", poses)
        out = np.array(model.fk(**_qa_inputs(params, qa)))  # (8, n): x, y, phi, margin per mode
        for n, (pose, qa_n) in enumerate(zip(poses, qa, strict=True)):
            # The candidates that exist (margin >= 0) and are modes: every leg in its working
            # mode there, the leg ahead of its pivot along the actuated axis (as the runtime and
            # the C check by the inverse kinematics).
            symbolic = [
                tuple(out[4 * m : 4 * m + 3, n])
                for m in range(2)
                if out[4 * m + 3, n] >= 0
                and min(fk.leg_lengths_along_axis(geom, qa_n, out[4 * m : 4 * m + 3, n]))
                > 1e-9 * geom.rho
            ]
            numeric = fk.revolute_modes(geom, qa_n)
            counts.append(len(numeric))
            assert len(symbolic) == len(numeric) <= 2
            for a, b in zip(sorted(symbolic, key=lambda m: m[2]), numeric, strict=True):
                assert _near(geom, a, b)
            for mode in numeric:
                assert -math.pi < mode[2] <= math.pi
                assert _closes(params, "revolute", qa_n, mode)
                assert min(fk.leg_lengths_along_axis(geom, qa_n, mode)) > 0
            assert any(_near(geom, m, pose) for m in numeric)
    assert set(counts) == {1, 2}


def test_revolute_degenerate_inputs_have_no_mode(models: dict[str, Model]) -> None:
    model = models["revolute"]
    params = ne.paper_params()
    geom = fk.Geometry.from_params(params)
    alpha = np.array(geom.alpha)
    parallel = np.array([0.3, 0.3, 0.3]) - alpha  # every leg along 0.3 rad: G is not fixed
    unreachable = np.array([0.0, 0.0, 0.0]) + np.array([2.0, -2.0, 0.5])
    qa = np.stack([parallel, unreachable])
    out = np.array(model.fk(**_qa_inputs(params, qa)))
    with np.errstate(all="ignore"):
        # Parallel legs: no candidate at all (both margins negative).
        assert not out[3, 0] >= 0
        assert not out[7, 0] >= 0
        # Unreachable: candidates exist, but each has a leg behind its pivot (another working
        # mode), so neither is a mode.
        for m in range(2):
            candidate = out[4 * m : 4 * m + 3, 1]
            lengths = fk.leg_lengths_along_axis(geom, qa[1], candidate)
            assert not (out[4 * m + 3, 1] >= 0 and min(lengths) > 0)
    for q in qa:
        assert fk.revolute_modes(geom, q) == []
    # The paper's congruent triangles: every leg has zero length at G = 0, phi = -pi/3 for any
    # leg angles; that pose solves the line conditions but is not a mode.
    qa = _reference_qa(params, "revolute", np.array([0.01, 0.02, 0.3]))[0]
    modes = fk.revolute_modes(geom, qa)
    assert all(abs(m[2] + math.pi / 3) > 1e-6 for m in modes)


# ----------------------------------------------------------------------------------------------
# Forward kinematics: prismatic actuation


def test_sextic_and_back_substitution_match_the_numeric_prototype(
    models: dict[str, Model],
) -> None:
    model = models["prismatic"]
    rng = np.random.default_rng(12)
    for params in fk.robots(rng, 6):
        geom = fk.Geometry.from_params(params)
        poses = fk.random_poses(rng, 8)
        qa = _reference_qa(params, "prismatic", poses)
        values = _qa_inputs(params, qa)
        values.update(cos_phi_in=np.cos(poses[:, 2]), sin_phi_in=np.sin(poses[:, 2]))
        out = np.array(model.fk(**values))
        for n, (pose, qa_n) in enumerate(zip(poses, qa, strict=True)):
            coefficients = fk.sextic_coefficients(geom, qa_n)
            scale = np.abs(coefficients).max()
            assert np.allclose(out[:7, n], coefficients, rtol=0, atol=1e-12 * scale)
            # The true angle is a root, and back substitution gives the true position.
            t = math.tan(pose[2] / 2)
            assert abs(np.polyval(out[6::-1, n], t)) <= 1e-9 * scale * (1 + t * t) ** 3
            assert np.allclose(out[7:9, n], pose[:2], rtol=0, atol=1e-10)


def test_prismatic_modes_round_trip(models: dict[str, Model]) -> None:
    model = models["prismatic"]
    rng = np.random.default_rng(13)
    counts = []
    for params in fk.robots(rng, 12):
        geom = fk.Geometry.from_params(params)
        for pose in fk.random_poses(rng, 8):
            qa = _reference_qa(params, "prismatic", pose)[0]
            values = _qa_inputs(params, qa)
            values.update(cos_phi_in=1.0, sin_phi_in=0.0)
            coefficients = np.array(model.fk(**values))[:7]
            modes = fk.prismatic_modes(geom, qa, coefficients)
            sampled = fk.prismatic_modes(geom, qa, coefficients, method="sampling")
            counts.append(len(modes))
            assert 1 <= len(modes) <= 6
            assert len(sampled) == len(modes)
            for a, b in zip(modes, sampled, strict=True):
                assert _near(geom, a, b)
            for mode in modes:
                assert -math.pi < mode[2] <= math.pi
                assert _closes(params, "prismatic", qa, mode)
            assert any(_near(geom, m, pose) for m in modes)
    assert max(counts) > 2  # configurations with four or six real modes exist, and are found


def test_six_real_modes_are_all_found() -> None:
    """A robot and leg lengths with six real assembly modes (found by search with a fixed seed):
    every one closes, and the two drivers agree."""
    rng = np.random.default_rng(0)
    for _ in range(400):
        params = ne.random_robot(rng)["params"]
        geom = fk.Geometry.from_params(params)
        pose = fk.random_poses(rng, 1)[0]
        qa = _reference_qa(params, "prismatic", pose)[0]
        modes = fk.prismatic_modes(geom, qa)
        if len(modes) == 6:
            break
    else:
        pytest.fail("no configuration with six modes among 400 random ones")
    assert len(fk.prismatic_modes(geom, qa, method="sampling")) == 6
    phis = sorted(m[2] for m in modes)
    assert min(np.diff(phis)) > 1e-6
    for mode in modes:
        assert _closes(params, "prismatic", qa, mode)


def test_prismatic_special_angles() -> None:
    """phi = pi (the degree drops), D = 0 (back substitution by line and circle), and the paper's
    congruent triangles (a spurious double root at phi = -pi/3 that is not a mode)."""
    rng = np.random.default_rng(14)
    for _ in range(50):  # a robot whose D(phi) has real zeros: mirrored platforms often do
        params = ne.random_robot(rng)["params"]
        params.update({f"y{leg}3": -params[f"y{leg}3"] for leg in ne.LEGS})
        geom = fk.Geometry.from_params(params)
        d0, dc, ds = fk._harmonics(geom, [0.0, 0.0, 0.0])["det"][0]
        if abs(d0) < 0.9 * math.hypot(dc, ds):
            break
    else:
        pytest.fail("no robot with a real zero of D")
    # phi = pi: the leading coefficient vanishes.
    pose = (0.02, -0.01, math.pi)
    qa = _reference_qa(params, "prismatic", np.array(pose))[0]
    a = fk.sextic_coefficients(geom, qa)
    assert abs(a[6]) <= 1e-12 * max(abs(v) for v in a)
    for method in ("roots", "sampling"):
        modes = fk.prismatic_modes(geom, qa, method=method)
        assert any(_near(geom, m, pose) for m in modes)
        assert all(_closes(params, "prismatic", qa, m) for m in modes)
    # D(phi) = D0 + Dc cos + Ds sin = 0: the two linear equations for u are parallel.
    phase = math.atan2(ds, dc)
    phi = phase + math.acos(-d0 / math.hypot(dc, ds))
    pose = (0.01, 0.015, fk.wrap(phi))
    qa = _reference_qa(params, "prismatic", np.array(pose))[0]
    candidates = fk.pose_candidates(geom, qa, pose[2])
    assert len(candidates) == 2
    assert any(_near(geom, c, pose, 1e-6) for c in candidates)
    for method in ("roots", "sampling"):
        assert any(_near(geom, m, pose) for m in fk.prismatic_modes(geom, qa, method=method))
    # The paper's robot: F(-pi/3) = 0 for any lengths, and it is no mode unless they are equal.
    params = ne.paper_params()
    geom = fk.Geometry.from_params(params)
    pose = (0.01, 0.02, 0.3)
    qa = _reference_qa(params, "prismatic", np.array(pose))[0]
    a = fk.sextic_coefficients(geom, qa)
    t = math.tan(-math.pi / 6)
    assert abs(np.polyval(a[::-1], t)) <= 1e-12 * max(abs(v) for v in a)
    assert fk.pose_candidates(geom, qa, -math.pi / 3) == []
    modes = fk.prismatic_modes(geom, qa)
    assert all(abs(m[2] + math.pi / 3) > 1e-6 for m in modes)
    assert any(_near(geom, m, pose) for m in modes)


def test_unreachable_lengths_have_no_mode() -> None:
    geom = fk.Geometry.from_params(ne.paper_params())
    assert fk.prismatic_modes(geom, [0.5, -0.25, -0.25]) == []
    assert fk.prismatic_modes(geom, [-geom.offset, 0.0, 0.0]) == []  # a leg of zero length
    result = fk.tracked_forward_kinematics(geom, "prismatic", [0.5, -0.25, -0.25], (0, 0, 0))
    assert result.status == "none"
    assert all(math.isnan(v) for v in result.q)


# ----------------------------------------------------------------------------------------------
# Tracked forward kinematics


def _track(geom: fk.Geometry, actuation: str, qa: np.ndarray, q0, predict: bool) -> tuple:
    """Track ``qa`` sample by sample from the pose ``q0``: the reference is the previous solution
    or the constant-velocity prediction ``2 q[k-1] - q[k-2]``. Returns the solutions (n, 3), the
    Newton steps (n,) and the statuses."""
    prev = prev2 = tuple(q0)
    out, steps, statuses = [], [], []
    for row in qa:
        near = tuple(2 * np.array(prev) - np.array(prev2)) if predict else prev
        result = fk.tracked_forward_kinematics(geom, actuation, row, near)
        out.append(result.q)
        steps.append(result.iterations)
        statuses.append(result.status)
        prev2, prev = prev, result.q
    return np.array(out), np.array(steps), statuses


@pytest.mark.parametrize("actuation", ACTUATIONS)
@pytest.mark.parametrize("predict", [False, True], ids=["previous", "predicted"])
def test_tracking_follows_the_paper_trajectories(actuation: str, predict: bool) -> None:
    """Encoders sampled every 1 ms; each solve starts from the previous one, or from the
    constant-velocity prediction."""
    params = ne.paper_params()
    geom = fk.Geometry.from_params(params)
    for kind in ("rotation", "rectilinear"):
        _, q, _, _ = ne.paper_motion(kind, samples=3001)
        qa = _reference_qa(params, actuation, q)
        found, steps, statuses = _track(geom, actuation, qa, q[0], predict)
        assert set(statuses) == {"newton"}
        assert np.abs(found - q).max() < 1e-10
        assert steps.max() <= (1 if predict else 2)


def test_tracking_through_a_parallel_singularity() -> None:
    """A random motion that crosses det J = 0 (revolute actuation): the two modes merge and part
    again; the prediction follows the robot into the other aspect."""
    t = np.arange(0.0, 2.0, 1e-3)
    robot, q, _, _ = ne.random_case(8, t)
    params = robot["params"]
    geom = fk.Geometry.from_params(params)
    dets = [fk.det3(fk.actuator_jacobian(geom, "revolute", row)) for row in q]
    assert min(dets) < 0 < max(dets)  # it does cross
    qa = _reference_qa(params, "revolute", q)
    found, _, _ = _track(geom, "revolute", qa, q[0], predict=True)
    assert np.abs(found - q).max() < 1e-7


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_tracking_converges_from_a_nearby_reference(actuation: str) -> None:
    rng = np.random.default_rng(21)
    for params in fk.robots(rng, 6):
        geom = fk.Geometry.from_params(params)
        for pose in fk.evaluable(geom, fk.random_poses(rng, 5)):
            if not ne.well_conditioned(params, pose[None, :], max_cond=1e3):
                continue
            qa = _reference_qa(params, actuation, pose)[0]
            near = pose + rng.normal(0, [0.003, 0.003, 0.02])
            result = fk.tracked_forward_kinematics(geom, actuation, qa, near)
            assert result.status == "newton"
            assert result.iterations <= 6
            assert fk.distance(geom, result.q, pose) < 1e-9


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_tracking_falls_back_to_the_nearest_mode(actuation: str) -> None:
    """Newton is cut short (one step from far away): the fallback returns the mode nearest the
    reference, with phi next to the reference's (unwrapped)."""
    rng = np.random.default_rng(22)
    used = 0
    for params in fk.robots(rng, 8):
        geom = fk.Geometry.from_params(params)
        pose = fk.random_poses(rng, 1)[0]
        qa = _reference_qa(params, actuation, pose)[0]
        near = (pose[0] + 0.08, pose[1] - 0.08, pose[2] + 2 * math.pi + 0.7)
        result = fk.tracked_forward_kinematics(geom, actuation, qa, near, max_iter=1)
        if result.status != "fallback":
            continue
        used += 1
        modes = fk.assembly_modes(geom, actuation, qa)
        unwrapped = [(m[0], m[1], fk.unwrap_near(m[2], near[2])) for m in modes]
        best = min(unwrapped, key=lambda m: fk.distance(geom, m, near))
        assert fk.distance(geom, result.q, best) < 1e-8
        assert abs(result.q[2] - near[2]) <= math.pi
        assert _closes(params, actuation, qa, result.q)
        off = fk.tracked_forward_kinematics(geom, actuation, qa, near, max_iter=1, fallback=False)
        assert off.status == "none"
    assert used >= 4
