"""Spatial robots: the generated inverse dynamics and control model against the independent
Newton–Euler reference (``tests/spatial_reference.py``), and against physics.

The reference is plain NumPy written from docs/spatial-robots.md alone: it solves every body's
Newton–Euler equations together for the joint wrenches. Here it judges every output of
``rpr3gen.inverse_dynamics`` for random models of the five structures (unequal legs, full
inertia tensors, payload) on both backends; the control model (J, M, c, forward dynamics) is
checked against finite differences of the actuator coordinates, the inverse dynamics' efforts and
its own identities.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rpr3gen
from rpr3gen.backends import evaluate, output_names

try:
    from . import spatial_models as sm
    from . import spatial_reference as sr
except ImportError:
    import spatial_models as sm
    import spatial_reference as sr

STRUCTURES = ("UPS", "RUS", "PUS", "RSS2", "PSS2")


@pytest.fixture(autouse=True)
def _quick(quick_c_builds: None) -> None:
    """The C backend at -O0 here: a spatial variant's C takes about a minute at -O3 and the
    values do not depend on the level (ISO C99, no contraction; docs/math-kernels.md)."""


RTOL = 1e-9  # relative to the largest |value| of the output's family over legs and samples
SAMPLES = 12


def _model(leg: str, seed: int) -> tuple[dict, rpr3gen.Model]:
    data = sm.random_model(leg, np.random.default_rng(seed))
    return data, rpr3gen.model_from_dict(data, source=f"random-{leg}-{seed}")


def _motion(data: dict, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q, qd, qdd = sm.random_motion(data, np.random.default_rng(1000 + seed), SAMPLES)
    return (np.ascontiguousarray(a) for a in (q, qd, qdd))  # type: ignore[return-value]


def _legs(data: dict) -> dict[str, dict]:
    if data.get("symmetric"):
        return sr.expand_symmetric(data["leg"], data["legs"])
    return {k: dict(v) for k, v in data["legs"].items()}


def rotate_model(data: dict, angle: float) -> dict:
    """The model turned about the world's vertical by ``angle`` (rad), gravity and payload
    with it."""
    Q = sr.rz(angle)
    turned = {k: v for k, v in data.items() if k not in ("legs", "symmetric")}
    turned["legs"] = {
        name: sr._turn_leg(leg, math.degrees(angle)) for name, leg in _legs(data).items()
    }
    platform = dict(data["platform"])
    platform["com"] = (Q @ np.asarray(platform["com"], dtype=float)).tolist()
    platform["inertia"] = sr.inertia_list(Q @ sr.inertia_matrix(platform["inertia"]) @ Q.T)
    turned["platform"] = platform
    gravity = data.get("environment", {}).get("gravity", (0.0, 0.0, -9.81))
    turned["environment"] = {"gravity": (Q @ np.asarray(gravity, dtype=float)).tolist()}
    if "payload" in data:
        turned["payload"] = {
            k: (Q @ np.asarray(v, dtype=float)).tolist() for k, v in data["payload"].items()
        }
    return turned


def total_mass(data: dict) -> float:
    """Every moving body's mass: the legs' bodies, the rods, the platform."""
    total = float(data["platform"]["mass"])
    for leg in _legs(data).values():
        total += float(np.sum(leg["mass"])) + 2.0 * float(leg.get("rod_mass", 0.0))
    return total


def _family(name: str) -> str:
    return name.rpartition("_")[0]


def _compare(mine: dict[str, np.ndarray], ref: dict[str, np.ndarray], what: str) -> None:
    assert set(ref) == set(mine) - {"conditioning"}, what
    scales: dict[str, float] = {}
    for name, value in ref.items():
        family = _family(name)
        scales[family] = max(scales.get(family, 0.0), float(np.max(np.abs(value))))
    for name, value in ref.items():
        scale = max(scales[_family(name)], 1e-3)
        err = float(np.max(np.abs(mine[name] - value)))
        assert err <= RTOL * scale, f"{what}: {name} off by {err:.3g} (scale {scale:.3g})"


@pytest.mark.slow
@pytest.mark.parametrize("leg", STRUCTURES)
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_every_output_matches_newton_euler(leg: str, backend: str) -> None:
    for seed in range(3):
        data, model = _model(leg, seed)
        q, qd, qdd = _motion(data, seed)
        mine = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend=backend)
        ref = sr.solve(data, q, qd, qdd)
        _compare(mine, ref, f"{leg} seed {seed} ({backend})")
        assert np.all((mine["conditioning"] > 0) & (mine["conditioning"] <= 1))


@pytest.mark.parametrize("leg", STRUCTURES)
def test_output_names_are_the_references(leg: str) -> None:
    _, model = _model(leg, 0)
    assert output_names(model) == (*sr.output_names(leg), "conditioning")


@pytest.mark.parametrize("leg", STRUCTURES)
def test_power_balance(leg: str) -> None:
    """The actuators' power plus the payload's is the rate of the energy (kinetic and
    potential) of every body, the latter by central differences along the motion."""
    data, model = _model(leg, 7)
    rng = np.random.default_rng(7)
    q0, qd0, qdd0 = (a[0] for a in sm.random_motion(data, rng, 1))
    h = 1e-5
    # a motion through (q0, qd0, qdd0): q(t) = q0 + qd0 t + qdd0 t^2 / 2
    ts = np.array([-h, h])
    q = q0 + np.outer(ts, qd0) + np.outer(ts**2 / 2, qdd0)
    qd = qd0 + np.outer(ts, qdd0)
    kinetic, potential = sr.energy(data, q, qd)
    dE = float((kinetic[1] + potential[1] - kinetic[0] - potential[0]) / (2 * h))
    out = rpr3gen.inverse_dynamics(model, q0, qd0, qdd0)
    tau = np.array([out[f"tau_{L}"][0] for L in model.structure.legs])
    rates = sr.actuator_rates(data, q0[np.newaxis], qd0[np.newaxis])[0]
    power = float(tau @ rates) + _payload_power(data, q0, qd0)
    assert power == pytest.approx(dE, rel=1e-6, abs=1e-6 * (abs(dE) + float(np.abs(tau).sum())))


def _payload_power(data: dict, q: np.ndarray, qd: np.ndarray) -> float:
    payload = data.get("payload", {})
    force = np.array(payload.get("force", (0.0, 0.0, 0.0)), dtype=float)
    moment = np.array(payload.get("moment", (0.0, 0.0, 0.0)), dtype=float)
    power = float(force @ qd[:3])
    if len(q) == 6:
        power += float(moment @ sr.angular_velocity(q, qd))
    return power


@pytest.mark.parametrize("leg", STRUCTURES)
def test_free_directions_carry_no_load(leg: str) -> None:
    """An S transmits no moment; a passive U none along its two axes (checked by the
    reference's agreement); the efforts are the loads along the actuated joint's axis."""
    data, model = _model(leg, 3)
    q, qd, qdd = _motion(data, 3)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    s_joints = (3,) if model.structure.dof == 6 else (2, 3, 4, 5)
    for L in model.structure.legs:
        for j in s_joints:
            for a in "xyz":
                assert np.all(out[f"m{a}{j}_{L}"] == 0.0)


@pytest.mark.parametrize("leg", STRUCTURES)
def test_rotating_the_scene_rotates_the_loads(leg: str) -> None:
    """Turning the whole robot and gravity about the vertical by 40 degrees turns every load
    (and the motion); joint coordinates and efforts stay."""
    data, model = _model(leg, 5)
    angle = math.radians(40.0)
    turned = rotate_model(data, angle)
    model_t = rpr3gen.model_from_dict(turned)
    q, qd, qdd = _motion(data, 5)
    Rz = np.array([[math.cos(angle), -math.sin(angle), 0], [math.sin(angle), math.cos(angle), 0],
                   [0, 0, 1.0]])  # fmt: skip
    qt, qdt, qddt = q.copy(), qd.copy(), qdd.copy()
    for a in (qt, qdt, qddt):
        a[:, :3] = a[:, :3] @ Rz.T
    if model.structure.dof == 6:
        # R' = Rz R Rz^T has the pose's angles only for a yaw Rz(c): tilts a = b = 0 here (the
        # reference's own test turns tilted poses)
        for a in (q, qd, qdd, qt, qdt, qddt):
            a[:, 3:5] = 0.0
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    out_t = rpr3gen.inverse_dynamics(model_t, qt, qdt, qddt)
    for L in model.structure.legs:
        assert np.allclose(out_t[f"tau_{L}"], out[f"tau_{L}"], rtol=1e-9, atol=1e-9)
        for j in range(1, 6 if model.structure.dof == 3 else 4):
            for kind in "fm":
                v = np.stack([out[f"{kind}{a}{j}_{L}"] for a in "xyz"], axis=1)
                vt = np.stack([out_t[f"{kind}{a}{j}_{L}"] for a in "xyz"], axis=1)
                assert np.allclose(vt, v @ Rz.T, rtol=1e-9, atol=1e-9 * np.abs(v).max())


@pytest.mark.parametrize("leg", STRUCTURES)
def test_jacobian_against_finite_differences(leg: str) -> None:
    data, model = _model(leg, 11)
    q, _, _ = _motion(data, 11)
    (J,), codes = evaluate(model, "actuator_jacobian", [q[:3]])
    assert not codes.any()
    k = model.structure.dof
    h = 1e-6
    for s in range(3):
        numeric = np.empty((k, k))
        for j in range(k):
            dq = np.zeros(k)
            dq[j] = h
            (plus,), _ = evaluate(model, "actuator_coordinates", [q[s] + dq])
            (minus,), _ = evaluate(model, "actuator_coordinates", [q[s] - dq])
            numeric[:, j] = (plus[0] - minus[0]) / (2 * h)
        assert np.allclose(J[s].reshape(k, k), numeric, rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("leg", STRUCTURES)
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_control_form_and_forward_dynamics(leg: str, backend: str) -> None:
    """M symmetric positive definite, M q'' + c = J^T tau with the inverse dynamics' tau, and
    the forward dynamics inverting the inverse dynamics."""
    data, model = _model(leg, 13)
    q, qd, qdd = _motion(data, 13)
    k = model.structure.dof
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend=backend)
    tau = np.stack([out[f"tau_{L}"] for L in model.structure.legs], axis=1)
    (J,), _ = evaluate(model, "actuator_jacobian", [q], backend)
    (M, c), codes = evaluate(model, "task_space_dynamics", [q, qd], backend)
    assert not codes.any()
    (acc,), codes = evaluate(model, "forward_dynamics", [q, qd, tau], backend)
    assert not codes.any()
    for s in range(len(q)):
        Ms = M[s].reshape(k, k)
        assert np.allclose(Ms, Ms.T, rtol=1e-10, atol=1e-12 * np.abs(Ms).max())
        assert np.all(np.linalg.eigvalsh((Ms + Ms.T) / 2) > 0)
        lhs = Ms @ qdd[s] + c[s]
        rhs = J[s].reshape(k, k).T @ tau[s]
        assert np.allclose(lhs, rhs, rtol=1e-9, atol=1e-9 * np.abs(rhs).max())
    assert np.allclose(acc, qdd, rtol=1e-8, atol=1e-8 * np.abs(qdd).max())


@pytest.mark.parametrize("leg", STRUCTURES)
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_efforts_matrix_is_the_references(leg: str, backend: str) -> None:
    """``efforts_matrix``: ``tau0`` the reference's efforts at ``q'' = 0``, column ``j`` of
    ``T`` the reference's at ``q'' = e_j`` less those (exact: the efforts are affine in
    ``q''``); and ``T q'' + tau0`` the reference's efforts at ``q''``."""
    data, model = _model(leg, 29)
    q, qd, qdd = _motion(data, 29)
    n, k = q.shape
    legs = model.structure.legs
    (T, tau0), codes = evaluate(model, "efforts_matrix", [q, qd], backend)
    assert not codes.any()

    def ref(acc: np.ndarray) -> np.ndarray:
        out = sr.solve(data, q, qd, acc)
        return np.column_stack([out[f"tau_{L}"] for L in legs])

    at_rest = ref(np.zeros_like(q))
    want = np.stack([ref(np.tile(np.eye(k)[j], (n, 1))) - at_rest for j in range(k)], axis=2)
    scale = np.abs(want).max()
    assert np.allclose(tau0, at_rest, rtol=1e-9, atol=1e-9 * np.abs(at_rest).max())
    assert np.allclose(T.reshape(n, k, k), want, rtol=1e-9, atol=1e-9 * scale)
    full = ref(qdd)
    got = (T.reshape(n, k, k) @ qdd[:, :, np.newaxis])[:, :, 0] + tau0
    assert np.allclose(got, full, rtol=1e-9, atol=1e-9 * np.abs(full).max())


@pytest.mark.parametrize("leg", STRUCTURES)
def test_numpy_equals_c(leg: str) -> None:
    data, model = _model(leg, 17)
    q, qd, qdd = _motion(data, 17)
    a = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend="numpy")
    b = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend="c")
    for name in a:
        scale = max(float(np.abs(a[name]).max()), 1.0)
        assert np.max(np.abs(a[name] - b[name])) <= 1e-12 * scale, name


@pytest.mark.parametrize("leg", STRUCTURES)
def test_at_rest_the_base_holds_the_weight(leg: str) -> None:
    data, model = _model(leg, 19)
    k = model.structure.dof
    zero = np.zeros((1, k))
    out = rpr3gen.inverse_dynamics(model, zero, zero, zero)
    weight = total_mass(data)
    g = np.array(data.get("environment", {}).get("gravity", (0.0, 0.0, -9.81)))
    payload = np.array(data.get("payload", {}).get("force", (0.0, 0.0, 0.0)), dtype=float)
    base = sum(np.array([out[f"f{a}1_{L}"][0] for a in "xyz"]) for L in model.structure.legs)
    assert np.allclose(base, -weight * g - payload, rtol=1e-10, atol=1e-9)


@pytest.mark.parametrize("leg", STRUCTURES)
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_payload_efforts_are_the_references_without_gravity(leg: str, backend: str) -> None:
    """The efforts holding the payload at rest: the reference's at rest with no gravity."""
    data, model = _model(leg, 23)
    data = {**data, "payload": {"force": [3.0, -2.0, 5.0], "moment": [0.4, -0.3, 0.2]}}
    model = rpr3gen.model_from_dict(data)
    q, _, _ = _motion(data, 23)
    tau = rpr3gen.payload_efforts(model, q, backend)
    rest = np.zeros_like(q)
    weightless = {**data, "environment": {"gravity": [0.0, 0.0, 0.0]}}
    ref = sr.solve(weightless, q, rest, rest)
    want = np.column_stack([ref[f"tau_{L}"] for L in model.structure.legs])
    assert np.allclose(tau, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())
    assert np.abs(want).max() > 0  # the payload does load the actuators
