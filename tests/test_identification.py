"""Dynamic identification through the runtime (issue 13): the generated regressor and payload
efforts against the independent Newton-Euler solver, base parameters, least squares, friction,
exciting trajectories and the ``identify`` / ``excite`` commands.

The reference efforts are always ``tests/newton_euler.py``'s (which never sees the regressor);
random robots have their leg centres of mass off the leg axis (``c1_perp``, ``c2_perp``), tilted
gravity and a payload.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
import tomllib
from pathlib import Path

import newton_euler as ne
import numpy as np
import pytest

import rpr3gen
from rpr3gen import identification as idn
from rpr3gen import parameters
from rpr3gen.cli import main
from rpr3gen.excitation import Excitation, FourierMotion
from rpr3gen.model import Model
from rpr3gen.trajectory import Trajectory

ACTUATIONS = ("revolute", "prismatic")
BACKENDS = ("numpy", "c")
LEGS = ("A", "B", "C")
EFFORT = {"revolute": "m10", "prismatic": "f21z"}
RATE = {"revolute": "omega10", "prismatic": "v21"}
MOTIONS: tuple[str | int, ...] = ("rotation", "rectilinear", 1, 2, 3)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def _legs(out: dict[str, np.ndarray], family: str) -> np.ndarray:
    return np.stack([out[f"{family}_{leg}"] for leg in LEGS], axis=1)


@functools.cache
def _case(motion: str | int, actuation: str) -> tuple[Model, np.ndarray, np.ndarray, np.ndarray]:
    """A model and a motion it accepts: a paper trajectory (paper robot) or a random case."""
    if isinstance(motion, str):
        _, q, qd, qdd = ne.paper_motion(motion, 61)
        params = ne.paper_params()
    else:
        robot, q, qd, qdd = ne.random_case(motion, np.linspace(0.0, 2.0, 41))
        params = robot["params"]
        assert params["c1_perp"] != 0.0
        assert params["c2_perp"] != 0.0
    model = Model(name="t", actuation=actuation, params=params, source="<test>")
    ok = np.isfinite(rpr3gen.actuator_efforts(model, q, qd, qdd)).all(axis=1)
    assert ok.sum() >= 0.8 * len(q)
    return model, q[ok], qd[ok], qdd[ok]


@functools.cache
def _exciting(actuation: str, robot: str | int, n: int = 150):
    """Random poses near the central configuration with random rates: a stack that excites
    every base parameter (the test's own sampler, not the runtime's)."""
    if robot == "paper":
        params = ne.paper_params()
    else:
        params = ne.random_robot(np.random.default_rng(int(robot)))["params"]
    model = Model(name="t", actuation=actuation, params=params, source="<test>")
    rng = np.random.default_rng(sum(map(ord, f"{actuation}{robot}")))
    q = rng.uniform([-0.03, -0.03, -0.25], [0.03, 0.03, 0.25], size=(3 * n, 3))
    q = q[np.array([ne.well_conditioned(params, row[None], 0.05, 1e3) for row in q])]
    zero = np.zeros_like(q)
    q = q[np.nan_to_num(rpr3gen.inverse_dynamics(model, q, zero, zero)["conditioning"]) > 0][:n]
    assert len(q) == n
    qd = rng.uniform([-0.3, -0.3, -1.0], [0.3, 0.3, 1.0], size=q.shape)
    qdd = rng.uniform([-2.0, -2.0, -6.0], [2.0, 2.0, 6.0], size=q.shape)
    tau = _legs(ne.solve(params, actuation, q, qd, qdd), EFFORT[actuation])
    return model, q, qd, qdd, tau


# ----------------------------------------------------------------------------------------------
# The regressor.


@pytest.mark.parametrize("motion", MOTIONS)
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_regressor_times_pi_is_the_newton_euler_efforts(
    actuation: str, backend: str, motion: str | int
) -> None:
    """``Y @ pi + tau_payload`` equals the independent solver's efforts; so does the shared
    (identical legs) form, and the base form ``Yb @ (matrix @ pi)``."""
    model, q, qd, qdd = _case(motion, actuation)
    want = _legs(ne.solve(model.params, actuation, q, qd, qdd), EFFORT[actuation])
    payload = rpr3gen.payload_efforts(model, q, backend)
    Y = rpr3gen.regressor(model, q, qd, qdd, backend=backend)
    assert Y.shape == (len(q), 3, 28)
    assert _relative(Y @ rpr3gen.inertial_parameters(model) + payload, want) < 1e-9
    shared = rpr3gen.regressor(model, q, qd, qdd, identical_legs=True, backend=backend)
    pi12 = rpr3gen.inertial_parameters(model, identical_legs=True)
    assert _relative(shared @ pi12 + payload, want) < 1e-9
    base = rpr3gen.base_parameters(model)
    Yb = rpr3gen.base_regressor(model, q, qd, qdd, backend=backend)
    assert _relative(Yb @ (base.matrix @ rpr3gen.inertial_parameters(model)) + payload, want) < 1e-9


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_payload_efforts_are_a_massless_robots_efforts(actuation: str) -> None:
    """With every mass and inertia zero, Newton-Euler's efforts are the payload's, at any rates."""
    model, q, qd, qdd = _case(1, actuation)
    massless = dict(model.params) | dict.fromkeys(("m1", "m2", "m3", "J1", "J2", "J3"), 0.0)
    want = _legs(ne.solve(massless, actuation, q, qd, qdd), EFFORT[actuation])
    assert np.abs(want).max() > 1.0  # the random robot carries a payload
    for backend in BACKENDS:
        assert _relative(rpr3gen.payload_efforts(model, q, backend), want) < 1e-9


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_regressor_is_linear_in_arbitrary_parameters(actuation: str) -> None:
    """For a pi no model file can state (every first moment, a platform centre of mass off
    G, but the leg parameters shared), ``Y @ pi`` is Newton-Euler's efforts of the robot whose
    platform centre is moved there: the regressor holds for any inertial parameters."""
    model, q, qd, qdd = _case(2, actuation)
    p = dict(model.params)
    c = np.array([0.02, -0.015])  # platform COM in the platform frame, from G
    m3, J3 = p["m3"], p["J3"]
    pi = rpr3gen.inertial_parameters(model)
    pi[-3:] = [m3 * c[0], m3 * c[1], J3 + m3 * c @ c]
    # The same robot described about its true centre G' = G + R c.
    moved = dict(p)
    for leg in LEGS:
        moved[f"x{leg}3"] -= c[0]
        moved[f"y{leg}3"] -= c[1]
    R = np.stack([np.cos(q[:, 2]), -np.sin(q[:, 2]), np.sin(q[:, 2]), np.cos(q[:, 2])], 1)
    R = R.reshape(-1, 2, 2)
    w, e = qd[:, 2], qdd[:, 2]
    Rc = R @ c
    perp = np.stack([-Rc[:, 1], Rc[:, 0]], 1)
    qm = np.column_stack([q[:, :2] + Rc, q[:, 2]])
    qdm = np.column_stack([qd[:, :2] + w[:, None] * perp, w])
    qddm = np.column_stack([qdd[:, :2] + e[:, None] * perp - (w**2)[:, None] * Rc, e])
    # The payload force acts at G, -R c from the new reference point: its moment there changes.
    mz = p["mz"] - (Rc[:, 0] * p["fy"] - Rc[:, 1] * p["fx"])
    want = np.empty_like(q)
    for k in range(len(q)):
        moved["mz"] = float(mz[k])
        one = slice(k, k + 1)
        out = ne.solve(moved, actuation, qm[one], qdm[one], qddm[one])
        want[k] = _legs(out, EFFORT[actuation])[0]
    got = rpr3gen.regressor(model, q, qd, qdd) @ pi + rpr3gen.payload_efforts(model, q)
    assert _relative(got, want) < 1e-9


# ----------------------------------------------------------------------------------------------
# Base parameters.


@pytest.mark.parametrize("identical", [False, True], ids=["per-leg", "identical-legs"])
@pytest.mark.parametrize("robot", ["paper", 1, 2])
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_rank_of_the_stacked_regressor_is_b(
    actuation: str, robot: str | int, identical: bool
) -> None:
    """The stack over the test's own exciting samples has rank B (19 per leg, 9 shared), and
    the base columns alone have that rank: they span the same space."""
    model, q, qd, qdd, _ = _exciting(actuation, robot)
    W = rpr3gen.regressor(model, q, qd, qdd, identical_legs=identical).reshape(
        -1, 12 if identical else 28
    )
    base = rpr3gen.base_parameters(model, identical_legs=identical)
    B = 9 if identical else 19
    assert len(base.names) == B
    s = np.linalg.svd(W / np.linalg.norm(W, axis=0).clip(1e-300), compute_uv=False)
    assert np.sum(s > 1e-9 * s[0]) == B
    Wb = W[:, list(base.columns)]
    sb = np.linalg.svd(Wb / np.linalg.norm(Wb, axis=0), compute_uv=False)
    assert sb[-1] > 1e-6 * sb[0]


@pytest.mark.parametrize("identical", [False, True], ids=["per-leg", "identical-legs"])
@pytest.mark.parametrize("robot", ["paper", 3])
def test_base_matrix_is_the_closed_form_regrouping(robot: str | int, identical: bool) -> None:
    """The runtime's numerical base parameters equal the derivation's closed-form regroupings
    (docs/identification.md) for the model's geometry."""
    from rpr3gen_derive.planar import identification as derived

    model, *_ = _exciting("revolute", robot)
    base = rpr3gen.base_parameters(model, identical_legs=identical)
    closed = derived.regrouping_matrix(model.params, identical)
    names = tuple(derived.regroupings(identical))
    order = [names.index(n) for n in base.names]
    assert base.names == tuple(n for n in derived.parameter_names(identical) if n in names)
    np.testing.assert_allclose(base.matrix, closed[order], atol=1e-9)
    assert set(base.unidentifiable) == {n for n in base.parameter_names if n.startswith("m_1")}


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_base_regressor_predicts_for_any_pi(actuation: str) -> None:
    """``Y @ pi == Yb @ (matrix @ pi)`` for random pi, at samples other than the runtime's."""
    model, q, qd, qdd, _ = _exciting(actuation, 2)
    base = rpr3gen.base_parameters(model)
    pi = np.random.default_rng(3).normal(size=28)
    Y = rpr3gen.regressor(model, q, qd, qdd)
    Yb = rpr3gen.base_regressor(model, q, qd, qdd)
    assert _relative(Yb @ (base.matrix @ pi), Y @ pi) < 1e-9


def test_the_literature_ten_parameters_have_rank_nine() -> None:
    """The ten minimal parameters listed for identical legs (docs/identification.md) have
    rank 9 in our regressor: the piston's mass regroups."""
    model, q, qd, qdd, _ = _exciting("revolute", 1)
    W = rpr3gen.regressor(model, q, qd, qdd, identical_legs=True).reshape(-1, 12)
    names = parameters.SHARED_PARAMETER_NAMES
    ten = ["Jzz_1", "mcx_1", "mcy_1", "mcx_2", "mcy_2", "m_2", "Jzz_3", "mcx_3", "mcy_3", "m_3"]
    cols = W[:, [names.index(n) for n in ten]]
    s = np.linalg.svd(cols / np.linalg.norm(cols, axis=0), compute_uv=False)
    assert np.sum(s > 1e-9 * s[0]) == 9


# ----------------------------------------------------------------------------------------------
# Least squares.


@pytest.mark.parametrize("identical", [False, True], ids=["per-leg", "identical-legs"])
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_noise_free_identification_recovers_the_base_parameters(
    actuation: str, backend: str, identical: bool
) -> None:
    model, q, qd, qdd, tau = _exciting(actuation, 1)
    fit = rpr3gen.identify(model, q, qd, qdd, tau, identical_legs=identical, backend=backend)
    base = rpr3gen.base_parameters(model, identical_legs=identical)
    want = base.matrix @ rpr3gen.inertial_parameters(model, identical_legs=identical)
    assert fit.names == base.names
    assert np.abs(fit.values - want).max() < 1e-9 * np.abs(want).max()
    assert fit.residual_rms < 1e-9 * np.abs(tau).max()
    assert fit.condition_number < idn.WARN_CONDITION
    assert _relative(fit.predict(q, qd, qdd), tau) < 1e-9


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_friction_is_recovered(actuation: str) -> None:
    """Efforts with viscous and Coulomb friction per actuator (rates from Newton-Euler's leg
    kinematics): the fit recovers the six friction values and the base parameters."""
    model, q, qd, qdd, tau = _exciting(actuation, 2)
    kin = ne.kinematics(model.params, q, qd, qdd)
    rate = np.stack([kin[leg][RATE[actuation]] for leg in LEGS], axis=1)
    fv = np.array([0.3, 0.5, 0.2])
    fc = np.array([0.4, 0.1, 0.25])
    measured = tau + fv * rate + fc * np.sign(rate)
    fit = rpr3gen.identify(model, q, qd, qdd, measured, friction=True)
    assert fit.names[-6:] == ("fv_A", "fv_B", "fv_C", "fc_A", "fc_B", "fc_C")
    np.testing.assert_allclose(fit.values[-6:], np.concatenate([fv, fc]), rtol=1e-8)
    without = rpr3gen.identify(model, q, qd, qdd, measured)
    assert without.residual_rms > 1e3 * fit.residual_rms


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_standard_deviations_match_the_scatter(actuation: str) -> None:
    """With Gaussian noise of known size on the efforts, the estimates' errors, in units of
    their standard deviations, have an RMS near 1 over 20 noise draws (fixed seeds)."""
    model, q, qd, qdd, tau = _exciting(actuation, 3, n=300)
    base = rpr3gen.base_parameters(model)
    want = base.matrix @ rpr3gen.inertial_parameters(model)
    rng = np.random.default_rng(11)
    z = []
    for _ in range(20):
        noisy = tau + rng.normal(size=tau.shape) * 0.01 * np.abs(tau).max(axis=0)
        fit = rpr3gen.identify(model, q, qd, qdd, noisy)
        z.append((fit.values - want) / fit.std)
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert 0.7 < rms < 1.4


def test_rank_deficient_data_name_the_parameters() -> None:
    """Along the paper's rotation the stack loses a rank: a clear error, no estimate."""
    model, q, qd, qdd = _case("rotation", "revolute")
    tau = rpr3gen.actuator_efforts(model, q, qd, qdd)
    with pytest.raises(rpr3gen.IdentificationError, match=r"rank 18 of 19.*Jzz_3"):
        rpr3gen.identify(model, q, qd, qdd, tau)


def _random_motion(seed: int, translation: float = 1.0, rotation: float = 1.0) -> Trajectory:
    """A random, not optimised, periodic motion about the central configuration (161 samples
    of 8 s, four harmonics): the paper robot identifies through it with condition numbers of
    1e3 to 4e3. ``translation`` and ``rotation`` scale the motion of G and of the angle."""
    rng = np.random.default_rng(seed)
    rho = rpr3gen.platform_radius(rpr3gen.load_model())
    w = 2 * math.pi / 8.0
    a, b = rng.uniform(-1.0, 1.0, (2, 3, 4)) * np.array([[rho / 10], [rho / 10], [0.2]]) * w
    gain = np.array([[translation], [translation], [rotation]])
    return FourierMotion(8.0, np.zeros(3), a * gain, b * gain).trajectory(161)


def _paper(actuation: str) -> Model:
    return dataclasses.replace(rpr3gen.load_model(), actuation=actuation)


def _undetermined(message: str) -> list[str]:
    """The combinations a refusal names, one per item."""
    pattern = r"\): (?:no effort changes with )?(.*?),? (?:left|practically) undetermined"
    m = re.search(pattern, message)
    assert m, message
    return m.group(1).split("; ")


@pytest.mark.parametrize("seed", [1, 14, 23])
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_random_motions_fit_and_warn(actuation: str, seed: int) -> None:
    """Condition numbers of 2e3 to 4e3, full rank: a fit that keeps to the truth within its
    standard deviations, and a warning naming the most inflated ones."""
    model = _paper(actuation)
    traj = _random_motion(seed)
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    rng = np.random.default_rng(seed)
    noisy = tau + 0.01 * np.sqrt(np.mean(tau**2, axis=0)) * rng.normal(size=tau.shape)
    with pytest.warns(rpr3gen.IdentificationWarning) as caught:
        fit = rpr3gen.identify(model, traj.q, traj.qd, traj.qdd, noisy)
    assert 2e3 < fit.condition_number < 4e3
    base = rpr3gen.base_parameters(model)
    want = base.matrix @ rpr3gen.inertial_parameters(model)
    assert np.abs((fit.values - want) / fit.std).max() < 5
    (warning,) = caught
    message = str(warning.message)
    assert message.startswith(f"condition number {fit.condition_number:.3g} > 1e+03: ")
    worst = int(np.argmax(fit.inflation))
    assert fit.inflation[worst] > 100  # the motion's doing, against 1 at best
    named = f"{fit.names[worst]} {fit.values[worst]:.4g} ± {fit.std[worst]:.3g} (std x"
    assert f"most of: {named}" in message


def test_inflation_is_the_variance_inflation_factor() -> None:
    """Each estimate's inflation is |c_j| / |c_j - projection of c_j on the other columns|:
    how much the other columns leave of its own (computed here by least squares, apart)."""
    model = rpr3gen.load_model()
    traj = _random_motion(1)
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    with pytest.warns(rpr3gen.IdentificationWarning):
        fit = rpr3gen.identify(model, traj.q, traj.qd, traj.qdd, tau, friction=True)
    W = idn._columns(model, traj.q, traj.qd, traj.qdd, fit.base, True, "numpy").reshape(
        -1, len(fit.names)
    )
    for j in range(W.shape[1]):
        others = np.delete(W, j, axis=1)
        rest = W[:, j] - others @ np.linalg.lstsq(others, W[:, j], rcond=None)[0]
        expected = np.linalg.norm(W[:, j]) / np.linalg.norm(rest)
        assert fit.inflation[j] == pytest.approx(expected, rel=1e-6), fit.names[j]
    assert (fit.inflation >= 1 - 1e-12).all()


def test_rank_deficient_motions_name_what_they_leave_undetermined() -> None:
    """A motion that never turns the platform leaves its inertia undetermined, and only it;
    at rest no inertia acts, nor friction, and the first moments of a leg's cylinder and
    piston along the leg act only through their sum."""
    model = rpr3gen.load_model()
    traj = _random_motion(1, rotation=0.0)
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    with pytest.raises(rpr3gen.IdentificationError, match="rank 18 of 19") as refused:
        rpr3gen.identify(model, traj.q, traj.qd, traj.qdd, tau)
    assert _undetermined(str(refused.value)) == ["Jzz_3"]

    q = _random_motion(1).q  # poses at rest, the platform turned this way and that
    zero = np.zeros_like(q)
    at_rest = rpr3gen.actuator_efforts(model, q, zero, zero)
    with pytest.raises(rpr3gen.IdentificationError, match="rank 9 of 25") as refused:
        rpr3gen.identify(model, q, zero, zero, at_rest, friction=True)
    named = _undetermined(str(refused.value))
    assert len(named) == 25 - 9
    inertias = ["Jzz_1A", "Jzz_1B", "Jzz_1C", "Jzz_3"]
    assert {*inertias, *idn.friction_names()} <= set(named)  # each alone
    pairs = {frozenset([f"{m}_1{leg}", f"{m}_2{leg}"]) for m in ("mcx", "mcy") for leg in LEGS}
    others = [c for c in named if c not in {*inertias, *idn.friction_names()}]
    assert {frozenset(c.split(" - ")) for c in others} == pairs
    assert not any("m_3" in c.split() for c in named)  # the weight is determined at rest


def test_beyond_the_hard_bound_refuses_naming_the_weak_combination() -> None:
    """The platform turning about G with a translation 1e-6 of the rotation's: full rank, but
    only by a hair; the combination the pure rotation leaves undetermined is named."""
    model = rpr3gen.load_model()
    traj = _random_motion(1, translation=1e-6)
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    with pytest.raises(rpr3gen.IdentificationError, match=r"condition number .* > 1e\+05") as e:
        rpr3gen.identify(model, traj.q, traj.qd, traj.qdd, tau)
    (combination,) = _undetermined(str(e.value))
    assert combination.split()[0] == "Jzz_3"
    assert set(combination.split()[3::3]) == {"Jzz_1A", "Jzz_1B", "Jzz_1C"}
    # The pure rotation leaves exactly that combination undetermined.
    pure = _random_motion(1, translation=0.0)
    with pytest.raises(rpr3gen.IdentificationError, match="rank 18 of 19") as exact:
        rpr3gen.identify(model, pure.q, pure.qd, pure.qdd, tau)
    assert _undetermined(str(exact.value)) == [combination]
    # A larger hard bound is the caller's to set: then the fit is made, and warns.
    with pytest.warns(rpr3gen.IdentificationWarning, match=r"most of: Jzz_"):
        fit = rpr3gen.identify(model, traj.q, traj.qd, traj.qdd, tau, max_condition=1e9)
    assert 1e5 < fit.condition_number < 1e9


def test_bad_samples_are_named() -> None:
    model, q, qd, qdd, tau = _exciting("revolute", 1)
    bad = tau.copy()
    bad[4, 1] = np.nan
    with pytest.raises(rpr3gen.InputError, match=r"sample 5 \(t = 0.4 s\)"):
        rpr3gen.identify(model, q, qd, qdd, bad, t=np.arange(len(q)) * 0.1)
    far = q.copy()
    p = model.params  # G where leg A's platform joint is on its base pivot: A2 behind A1
    far[7] = [p["xA1"] - p["xA3"], p["yA1"] - p["yA3"], 0.0]
    with pytest.raises(rpr3gen.InputError, match=r"sample 8: the pose is singular or out of reach"):
        rpr3gen.identify(model, far, qd, qdd, tau)
    with pytest.raises(rpr3gen.IdentificationError, match="equations for 19 unknowns"):
        rpr3gen.identify(model, q[:5], qd[:5], qdd[:5], tau[:5])


def _gallery_rrr(shared_offsets: bool) -> Model:
    """``models/rrr.toml`` with legs B and C written out: leg A turned by 120 and 240 degrees,
    and with ``shared_offsets`` their centres of mass moved so that each sits where leg A's
    does from its first joint point (world axes): then the legs' inertial parameters agree."""
    root = Path(__file__).resolve().parent.parent
    with (root / "models" / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    del data["symmetric"]
    a = data["legs"]["A"]
    for k, leg in ((1, "B"), (2, "C")):
        c, s = math.cos(2 * math.pi * k / 3), math.sin(2 * math.pi * k / 3)
        turn = np.array([[c, -s], [s, c]])
        joints = np.array(a["joints"]) @ turn.T
        com = np.array(a["com"]) @ turn.T
        if shared_offsets:
            com = joints[:2] + (np.array(a["com"]) - np.array(a["joints"])[:2])
        data["legs"][leg] = {**a, "joints": joints.tolist(), "com": com.tolist()}
    return rpr3gen.model_from_dict(data, source="rrr")


def test_identical_legs_is_refused_where_the_legs_differ() -> None:
    """A general model's legs turned by 120 degrees have other first moments in the world's
    axes: every function that would share the legs' parameters refuses (docs/interfaces.md),
    rather than fit or predict with a robot that is not the model's."""
    model = _gallery_rrr(shared_offsets=False)
    traj = rpr3gen.read_trajectory_csv(Path(__file__).resolve().parent.parent / "models/loop.csv")
    q, qd, qdd = traj.q[::10], traj.qd[::10], traj.qdd[::10]
    tau = rpr3gen.actuator_efforts(model, q, qd, qdd)
    calls = {
        "inertial_parameters": lambda: rpr3gen.inertial_parameters(model, identical_legs=True),
        "regressor": lambda: rpr3gen.regressor(model, q, qd, qdd, identical_legs=True),
        "base_regressor": lambda: rpr3gen.base_regressor(model, q, qd, qdd, identical_legs=True),
        "base_parameters": lambda: rpr3gen.base_parameters(model, identical_legs=True),
        "identify": lambda: rpr3gen.identify(
            model, q, qd, qdd, tau, identical_legs=True, max_condition=math.inf
        ),
        "excite": lambda: rpr3gen.excite(model, harmonics=1, samples=10, identical_legs=True),
    }
    for name, call in calls.items():
        with pytest.raises(rpr3gen.InputError, match=r"^identical_legs: leg B's .* differ") as info:
            call()
        assert info.value.argument == "identical_legs", name


def test_identical_legs_is_taken_where_the_legs_agree() -> None:
    """Legs of other geometry but equal inertial parameters (world axes) share them: the summed
    columns times the shared parameters are the model's efforts."""
    model = _gallery_rrr(shared_offsets=True)
    traj = rpr3gen.read_trajectory_csv(Path(__file__).resolve().parent.parent / "models/loop.csv")
    q, qd, qdd = traj.q[::10], traj.qd[::10], traj.qdd[::10]
    shared = rpr3gen.regressor(model, q, qd, qdd, identical_legs=True)
    pi = rpr3gen.inertial_parameters(model, identical_legs=True)
    tau = shared @ pi + rpr3gen.payload_efforts(model, q)
    assert _relative(tau, rpr3gen.actuator_efforts(model, q, qd, qdd)) < 1e-12
    assert len(rpr3gen.base_parameters(model, identical_legs=True).names) > 0


# ----------------------------------------------------------------------------------------------
# Exciting trajectories.


@functools.cache
def _excited(identical: bool = False) -> Excitation:
    """A short optimisation of an exciting motion for the paper robot (once per process: the
    commands' tests below take their data along it)."""
    model = rpr3gen.load_model()
    return rpr3gen.excite(
        model, harmonics=3, period=6.0, samples=61, max_iterations=25, identical_legs=identical
    )


@pytest.mark.parametrize("identical", [False, True], ids=["per-leg", "identical-legs"])
def test_excite_lowers_the_condition_number_inside_the_workspace(identical: bool) -> None:
    """The optimised motion is better conditioned than the start and than the limit, and keeps
    every constraint, checked with the inverse dynamics (not the optimiser's own values)."""
    model = rpr3gen.load_model()
    found = _excited(identical)
    assert found.condition_number < found.initial_condition_number / 3
    assert found.condition_number < idn.WARN_CONDITION
    traj = found.trajectory
    out = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    assert out["conditioning"].min() >= 0.1 - 1e-6
    lam = _legs(out, "lambda21")
    half = model.params["l0"] / 2
    assert np.abs(lam).max() <= half * (1 + 1e-6)
    assert np.abs(traj.qdd[:, :2]).max() <= 2.0 * (1 + 1e-6)
    # Periodic: the motion closes on itself.
    np.testing.assert_allclose(traj.q[0], traj.q[-1], atol=1e-12)
    # And the identification it was made for works on it.
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    fit = rpr3gen.identify(model, traj.q, traj.qd, traj.qdd, tau, identical_legs=identical)
    assert math.isclose(fit.condition_number, found.condition_number, rel_tol=1e-6)


# ----------------------------------------------------------------------------------------------
# The commands.


def _write_data(path: Path, t, q, tau, family: str = "m10") -> Path:
    header = "t,x,y,phi," + ",".join(f"{family}_{leg}" for leg in LEGS)
    rows = [
        ",".join(repr(float(v)) for v in (ti, *qi, *ti_))
        for ti, qi, ti_ in zip(t, q, tau, strict=True)
    ]
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    return path


def _measured(tmp_path: Path) -> tuple[Path, Model, np.ndarray]:
    """Positions and efforts of a heavier robot along an exciting motion (noise-free)."""
    model = rpr3gen.load_model()
    motion = _excited().motion
    t = np.linspace(0.0, 2 * motion.period, 241)
    q, qd, qdd = motion.at(t)
    true = dataclasses.replace(model, params=dict(model.params) | {"m3": 6.5, "c1_perp": 0.01})
    tau = rpr3gen.actuator_efforts(true, q, qd, qdd)
    return _write_data(tmp_path / "measured.csv", t, q, tau), true, (q, qd, qdd)


def test_cli_identify_prints_estimates_and_writes_toml(tmp_path: Path, capsys) -> None:
    data, true, _ = _measured(tmp_path)
    out = tmp_path / "est.toml"
    assert main(["identify", "--data", str(data), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "19 base parameters" in text
    assert "condition number" in text
    doc = tomllib.loads(out.read_text())
    base = rpr3gen.base_parameters(true)
    want = dict(zip(base.names, base.matrix @ rpr3gen.inertial_parameters(true), strict=True))
    # Velocities and accelerations come from a spline of the positions: close, not exact.
    assert abs(doc["estimates"]["m_3"] - want["m_3"]) < 0.02 * want["m_3"]
    assert abs(doc["estimates"]["mcy_1A"] - want["mcy_1A"]) < 0.1 * want["mcy_1A"]
    assert set(doc["std"]) == set(base.names)
    assert doc["definitions"]["m_3"] == "m_3 + m_2A + m_2B + m_2C"
    line = next(x for x in text.splitlines() if x.split()[:1] == ["m_3"])
    assert float(line.split()[1]) == pytest.approx(doc["estimates"]["m_3"], rel=1e-5)


def _spoil_row_2(text: str) -> str:
    lines = text.split("\n")
    cells = lines[2].split(",")
    lines[2] = ",".join([cells[0], "nope", *cells[2:]])
    return "\n".join(lines)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda s: s.replace("m10_B", "m10_b"), "missing column 'm10_B' (found 'm10_b')"),
        (_spoil_row_2, "line 3 (data row 2), column 'x': not a number: 'nope'"),
    ],
    ids=["missing-column", "not-a-number"],
)
def test_cli_identify_bad_data_is_one_line(tmp_path: Path, capsys, edit, message: str) -> None:
    data, _, _ = _measured(tmp_path)
    data.write_text(edit(data.read_text()))
    out = tmp_path / "est.toml"
    assert main(["identify", "--data", str(data), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("rpr3gen: error: ")
    assert message in err
    assert "Traceback" not in err
    assert not out.exists()


def test_cli_identify_refuses_unexciting_data(tmp_path: Path, capsys) -> None:
    traj = rpr3gen.paper_trajectory("rotation")
    model = rpr3gen.load_model()
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    data = _write_data(tmp_path / "rotation.csv", traj.t, traj.q, tau)
    out = tmp_path / "est.toml"
    assert main(["identify", "--data", str(data), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "do not excite" in err
    assert "rank 18 of 19" in err
    assert err.count("\n") == 1
    assert not out.exists()


def test_cli_identify_warns_in_one_line(tmp_path: Path, capsys) -> None:
    """A random motion: the estimates, and one line on stderr with the condition number and
    the most inflated standard deviations; the bounds are options."""
    traj = _random_motion(14)
    model = rpr3gen.load_model()
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    data = _write_data(tmp_path / "random.csv", traj.t, traj.q, tau)
    assert main(["identify", "--data", str(data)]) == 0
    out, err = capsys.readouterr()
    assert "19 base parameters" in out
    cond = float(re.search(r"condition number (\S+) \(warns above 1000, refuses", out).group(1))
    assert 2e3 < cond < 4e3
    assert err.count("\n") == 1
    assert err.startswith(f"rpr3gen: warning: condition number {cond:.3g} > 1e+03: ")
    assert "standard deviations are inflated, most of: " in err
    assert main(["identify", "--data", str(data), "--warn-condition", "1e4"]) == 0
    assert capsys.readouterr().err == ""
    assert main(["identify", "--data", str(data), "--max-condition", "2000"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rpr3gen: error: the data do not excite every parameter (condition")
    assert err.count("\n") == 1


def test_cli_identify_prismatic_needs_f21z_columns(tmp_path: Path, capsys) -> None:
    data, _, _ = _measured(tmp_path)
    model_file = tmp_path / "prismatic.toml"
    paper = Path(rpr3gen.load_model().source).read_text()
    model_file.write_text(paper.replace('actuation = "revolute"', 'actuation = "prismatic"'))
    assert main(["identify", "--model", str(model_file), "--data", str(data)]) == 2
    assert "missing column 'f21z_A'" in capsys.readouterr().err


def test_cli_excite_writes_a_trajectory(tmp_path: Path, capsys) -> None:
    out = tmp_path / "exc.csv"
    args = ["excite", "--out", str(out), "--harmonics", "3", "--period", "6", "--samples", "61"]
    assert main([*args, "--max-iterations", "25"]) == 0
    text = capsys.readouterr().out
    assert "condition number" in text
    assert "->" in text
    traj = rpr3gen.read_trajectory_csv(out)
    assert len(traj) == 61


@pytest.mark.slow
def test_the_example_writes_data_that_identify_reads(tmp_path: Path, capsys) -> None:
    """examples/identification: the script's data recover its true platform mass."""
    import runpy
    import sys

    script = Path(__file__).resolve().parent.parent / "examples/identification"
    out = tmp_path / "measured.csv"
    argv = sys.argv
    sys.argv = ["simulate_measurements.py", "--out", str(out)]
    try:
        namespace = runpy.run_path(str(script / "simulate_measurements.py"), run_name="__main__")
    finally:
        sys.argv = argv
    model_file = Path(rpr3gen.load_model().source)
    args = ["identify", "--model", str(model_file), "--data", str(out), "--friction"]
    assert main([*args, "--smoothing", "2e-5"]) == 0
    text = capsys.readouterr().out
    true = dataclasses.replace(
        rpr3gen.load_model(), params=dict(rpr3gen.load_model().params) | namespace["TRUE_PARAMS"]
    )
    base = rpr3gen.base_parameters(true)
    want = dict(zip(base.names, base.matrix @ rpr3gen.inertial_parameters(true), strict=True))
    row = next(x.split() for x in text.splitlines() if x.split()[:1] == ["m_3"])
    estimate, std = float(row[1]), float(row[2])
    assert abs(estimate - want["m_3"]) < 4 * std
    assert std < 0.01 * want["m_3"]
