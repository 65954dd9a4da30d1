"""The generated control model through the runtime API (issue 12), both actuations, both backends.

Forward kinematics (every assembly mode, the tracked one), the actuator Jacobian and its rate,
the task-space and forward dynamics, checked against what does not share their derivation:
finite differences, the independent Newton-Euler solver of the seven bodies
(``tests/newton_euler.py``: leg rates, efforts, energy), a scan of the closure equations over
``phi`` written here, and each other (NumPy and C). On the paper's robot and on random robots
(``newton_euler.random_robot``), at poses rpr3gen accepts (every piston joint in front of its base
pivot, conditioning above the floor) near the central configuration.

``forward_kinematics(..., backend="c")`` is not tested here: its C body is being written.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

import rpr3gen
from rpr3gen import manifest
from rpr3gen.cli import main
from rpr3gen.model import Model

try:
    from . import newton_euler as ne
except ImportError:
    import newton_euler as ne

ACTUATIONS = ("revolute", "prismatic")
BACKENDS = ("numpy", "c")
LEGS = ("A", "B", "C")
COORDINATE = {"revolute": "phi10", "prismatic": "lambda21"}
RATE = {"revolute": "omega10", "prismatic": "v21"}
ACCELERATION = {"revolute": "eps10", "prismatic": "gamma21"}
EFFORT = {"revolute": "m10", "prismatic": "f21z"}
MAX_MODES = {"revolute": 2, "prismatic": 6}
#: The paper's robot and three random ones (seeds of ``newton_euler.random_robot``).
ROBOTS: tuple[str | int, ...] = ("paper", 1, 2, 3)


def _cases() -> list[object]:
    """Every (actuation, backend) pair."""
    return [
        pytest.param(actuation, backend, id=f"{actuation}-{backend}")
        for actuation in ACTUATIONS
        for backend in BACKENDS
    ]


def _model(actuation: str, robot: str | int, payload: bool = True) -> Model:
    """The paper's robot (``"paper"``) or ``newton_euler.random_robot`` of a seed."""
    if robot == "paper":
        return dataclasses.replace(rpr3gen.load_model(), actuation=actuation)
    params = dict(ne.random_robot(np.random.default_rng(int(robot)))["params"])
    if not payload:
        params.update(fx=0.0, fy=0.0, mz=0.0)
    return Model(name="t", actuation=actuation, params=params, source="<test>")


class Motion(NamedTuple):
    model: Model
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray


@functools.cache
def _motion(actuation: str, robot: str | int, n: int = 40) -> Motion:
    """n poses near the central configuration that rpr3gen accepts with a margin
    (conditioning >= 1e-3, as ``rpr3gen simulate`` asks by default), random rates."""
    model = _model(actuation, robot)
    rng = np.random.default_rng(sum(map(ord, f"{actuation}{robot}")))
    q = rng.uniform([-0.03, -0.03, -0.25], [0.03, 0.03, 0.25], size=(4 * n, 3))
    zero = np.zeros_like(q)
    conditioning = rpr3gen.inverse_dynamics(model, q, zero, zero)["conditioning"]
    q = q[np.nan_to_num(conditioning) >= 1e-3][:n]
    assert len(q) == n
    qd = rng.uniform([-0.3, -0.3, -1.0], [0.3, 0.3, 1.0], size=q.shape)
    qdd = rng.uniform([-2.0, -2.0, -6.0], [2.0, 2.0, 6.0], size=q.shape)
    return Motion(model, q, qd, qdd)


def _legs(out: dict[str, np.ndarray], family: str) -> np.ndarray:
    return np.stack([out[f"{family}_{leg}"] for leg in LEGS], axis=1)


def _leg_values(model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict:
    """Newton-Euler's leg kinematics: ``family -> (n, 3)`` for legs A, B, C."""
    kin = ne.kinematics(model.params, q, qd, qdd)
    return {
        family: np.stack([kin[leg][family] for leg in LEGS], axis=1)
        for family in ("phi10", "lambda21", "omega10", "v21", "eps10", "gamma21")
    }


def _wrap(angle: np.ndarray) -> np.ndarray:
    """Into (-pi, pi]."""
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def _qa_error(model: Model, qa: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """|qa - expected| per component, angles compared wrapped (rad or m)."""
    d = qa - expected
    return np.abs(_wrap(d) if model.actuation == "revolute" else d)


def _rho(model: Model) -> float:
    """The platform's RMS joint radius (m): ``phi`` times it is a distance."""
    p = model.params
    return float(np.sqrt(np.mean([p[f"x{leg}3"] ** 2 + p[f"y{leg}3"] ** 2 for leg in LEGS])))


def _distance(model: Model, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance in (x, y, rho phi) between poses (broadcast), phi compared wrapped."""
    rho = _rho(model)
    d = a - b
    return np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2 + (rho * _wrap(d[..., 2])) ** 2)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a - b| per sample over the sample's largest |b| (rows of (n, ...) arrays)."""
    n = a.shape[0]
    diff = np.abs(a - b).reshape(n, -1).max(axis=1)
    scale = np.abs(b).reshape(n, -1).max(axis=1)
    return float(np.max(diff / scale))


def _accepted(model: Model, q: np.ndarray) -> np.ndarray:
    """(n,) bool: rpr3gen evaluates these poses (not refused as singular)."""
    return np.isfinite(rpr3gen.actuator_coordinates(model, q)).all(axis=1)


# -- an independent count of the assembly modes ----------------------------------------------


def _points(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    p = model.params
    base = np.array([[p[f"x{leg}1"], p[f"y{leg}1"]] for leg in LEGS])
    platform = np.array([[p[f"x{leg}3"], p[f"y{leg}3"]] for leg in LEGS])
    alpha = np.array([p[f"alpha_{leg}"] for leg in LEGS])
    return base, platform, alpha


def _scanned_modes(model: Model, qa: np.ndarray, points: int = 4001) -> np.ndarray:
    """The assembly modes of ``qa`` whose ``phi`` is a sign change of the closure's eliminant on
    a grid of ``points`` angles (refined by bisection): every mode but double roots and pairs
    closer than the grid step. Written from the conventions, not from rpr3gen's closed forms.

    Revolute: the lines ``n_i . (G + R p_i - A1_i) = 0`` have a common ``G`` where
    ``det [n_i^T, n_i . (R p_i - A1_i)] = 0``. Prismatic: the circles
    ``|G + R p_i - A1_i| = L_i``; the differences of their equations are linear in ``G``
    (``K G = b``), and ``G = adj(K) b / det K`` on the first circle gives
    ``|adj(K) b + det(K) d_A|^2 - L_A^2 det(K)^2 = 0``, continuous in ``phi``. A mode has every
    piston joint in front of its base pivot (rpr3gen's rule: ``|A1A3| - l2 > 0`` along ``e``).
    """
    base, platform, alpha = _points(model)
    l0, l2 = model.params["l0"], model.params["l2"]

    def arms(phi: np.ndarray) -> np.ndarray:  # R(phi) p_i - A1_i, (k, 3, 2)
        c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
        px, py = platform[:, 0], platform[:, 1]
        turned = np.stack([c * px - s * py, s * px + c * py], axis=-1)
        return turned - base

    if model.actuation == "revolute":
        theta = alpha + qa
        e = np.stack([np.cos(theta), np.sin(theta)], axis=1)
        n = np.stack([-e[:, 1], e[:, 0]], axis=1)

        def eliminant(phi: np.ndarray) -> np.ndarray:
            g = np.sum(n * arms(phi), axis=-1)
            rows = np.concatenate([np.broadcast_to(n, (len(phi), 3, 2)), g[..., None]], axis=-1)
            return np.linalg.det(rows)

        def pose(phi: np.ndarray) -> np.ndarray:
            g = np.sum(n * arms(phi), axis=-1)
            G = np.linalg.lstsq(n, -g.T, rcond=None)[0].T
            return np.column_stack([G, phi])

    else:
        lengths = l0 + l2 + qa

        def solve(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            d = arms(phi)
            K = 2 * (d[:, 1:] - d[:, :1])
            b = lengths[1:] ** 2 - lengths[0] ** 2 - np.sum(d[:, 1:] ** 2, -1)
            b = b + np.sum(d[:, :1] ** 2, -1)
            det = K[:, 0, 0] * K[:, 1, 1] - K[:, 0, 1] * K[:, 1, 0]
            adj_b = np.stack(
                [
                    K[:, 1, 1] * b[:, 0] - K[:, 0, 1] * b[:, 1],
                    K[:, 0, 0] * b[:, 1] - K[:, 1, 0] * b[:, 0],
                ],
                axis=-1,
            )
            return adj_b, det, d

        def eliminant(phi: np.ndarray) -> np.ndarray:
            adj_b, det, d = solve(phi)
            return np.sum((adj_b + det[:, None] * d[:, 0]) ** 2, -1) - (lengths[0] * det) ** 2

        def pose(phi: np.ndarray) -> np.ndarray:
            adj_b, det, _ = solve(phi)
            return np.column_stack([adj_b / det[:, None], phi])

    grid = np.linspace(-np.pi, np.pi, points)
    f = eliminant(grid)
    brackets = np.nonzero(np.sign(f[:-1]) * np.sign(f[1:]) < 0)[0]
    lo, hi = grid[brackets], grid[brackets + 1]
    f_lo = f[brackets]
    for _ in range(60):
        mid = (lo + hi) / 2
        same = np.sign(eliminant(mid)) == np.sign(f_lo)
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    candidates = pose((lo + hi) / 2)
    arm = arms(candidates[:, 2]) + candidates[:, None, :2]  # A3_i - A1_i
    if model.actuation == "revolute":
        along = np.sum(arm * e, axis=-1)
        closes = np.abs(np.sum(arm * n, axis=-1)).max(axis=1) < 1e-9
    else:
        along = np.linalg.norm(arm, axis=-1)
        closes = np.abs(along - lengths).max(axis=1) < 1e-9
    keep = closes & ((along - l2).min(axis=1) > 1e-9 * l0)
    return candidates[keep]


# -- 1. forward kinematics ----------------------------------------------------------------------


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_assembly_modes_round_trip(actuation: str, backend: str, robot: str | int) -> None:
    """Every mode maps back to qa; the true pose and every scanned mode are among them; at most
    2 or 6 modes, distinct, phi in (-pi, pi], each a pose rpr3gen accepts."""
    motion = _motion(actuation, robot)
    model = motion.model
    q = motion.q[:20]
    qa = rpr3gen.actuator_coordinates(model, q, backend)
    true = np.column_stack([q[:, :2], _wrap(q[:, 2])])
    for k in range(len(q)):
        modes = rpr3gen.assembly_modes(model, qa[k], backend)
        assert 1 <= len(modes) <= MAX_MODES[actuation]
        assert np.all((modes[:, 2] > -np.pi) & (modes[:, 2] <= np.pi))
        # Round-off of the closed form (revolute); Newton's stopping test, 1e-11 (prismatic).
        # (NaN, a mode rpr3gen refuses, fails it too.)
        back = rpr3gen.actuator_coordinates(model, modes, backend)
        assert _qa_error(model, back, qa[k]).max() < 1e-10
        assert _distance(model, modes, true[k]).min() < 1e-9
        pairs = _distance(model, modes[:, None], modes[None])
        assert np.all(pairs[~np.eye(len(modes), dtype=bool)] > 1e-6)
        scanned = _scanned_modes(model, qa[k])
        assert len(scanned) >= 1
        for mode in scanned:
            assert _distance(model, modes, mode).min() < 1e-8, (k, mode, modes)


def test_prismatic_robots_have_four_and_six_modes_all_found() -> None:
    """Among random robots, lengths with 2, 4 and 6 real modes occur; each time the scan's modes
    are all among rpr3gen's, and rpr3gen has no more than the scan (no double roots here)."""
    counts: dict[int, int] = {}
    for robot in (1, 15, 28):  # seeds with 6-mode poses (robots 15 and 28: 12 and 11 of 40)
        model = _model("prismatic", robot)
        rng = np.random.default_rng(robot)
        q = rng.uniform([-0.05, -0.05, -0.6], [0.05, 0.05, 0.6], size=(40, 3))
        q = q[_accepted(model, q)]
        qa = rpr3gen.actuator_coordinates(model, q)
        for k in range(len(q)):
            modes = rpr3gen.assembly_modes(model, qa[k])
            scanned = _scanned_modes(model, qa[k])
            assert len(modes) == len(scanned), (robot, k, modes, scanned)
            for mode in scanned:
                assert _distance(model, modes, mode).min() < 1e-8
            counts[len(modes)] = counts.get(len(modes), 0) + 1
    assert {2, 4, 6} <= set(counts), counts
    assert counts[6] >= 10


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_forward_kinematics_returns_the_mode_nearest_the_reference(
    actuation: str, robot: str | int
) -> None:
    motion = _motion(actuation, robot)
    model = motion.model
    q = motion.q[:20]
    qa = rpr3gen.actuator_coordinates(model, q)
    rng = np.random.default_rng(4)
    # A nearby reference (2 mm, 0.02 rad): the true pose, phi unwrapped next to the reference's.
    near = q + rng.uniform(-1, 1, q.shape) * [2e-3, 2e-3, 0.02]
    for turns in (0, 1, -2):
        shifted = near + np.array([0.0, 0.0, 2 * np.pi * turns])
        found = rpr3gen.forward_kinematics(model, qa, shifted, backend="numpy")
        np.testing.assert_allclose(found[:, :2], q[:, :2], rtol=0, atol=1e-9)
        np.testing.assert_allclose(found[:, 2], q[:, 2] + 2 * np.pi * turns, rtol=0, atol=1e-9)
    # Any reference: the nearest mode, in (x, y, rho phi) with phi unwrapped next to it.
    far = rng.uniform([-0.3, -0.3, -4.0], [0.3, 0.3, 4.0], size=q.shape)
    found = rpr3gen.forward_kinematics(model, qa, far, backend="numpy")
    rho = _rho(model)
    assert rpr3gen.platform_radius(model) == pytest.approx(rho, rel=1e-15)
    for k in range(len(q)):
        modes = rpr3gen.assembly_modes(model, qa[k])
        modes[:, 2] = far[k, 2] + _wrap(modes[:, 2] - far[k, 2])
        d = np.linalg.norm((modes - far[k]) * [1.0, 1.0, rho], axis=1)
        np.testing.assert_allclose(found[k], modes[np.argmin(d)], rtol=0, atol=1e-12)
        assert abs(found[k, 2] - far[k, 2]) <= np.pi


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_no_mode_is_a_nan_row(actuation: str) -> None:
    model = _model(actuation, "paper")
    base, platform, alpha = _points(model)
    p = model.params
    if actuation == "prismatic":
        # Leg B longer than leg A plus both triangles' sides A-B: the loop cannot close.
        reach_b = p["l0"] + p["l2"] + np.linalg.norm(base[0] - base[1])
        reach_b += np.linalg.norm(platform[0] - platform[1]) + 0.1
        impossible = [[0.0, reach_b - p["l0"] - p["l2"], 0.0], [-0.5, -0.5, -0.5]]  # too long; < 0
    else:
        # Every leg along one direction: G is not fixed (no isolated mode).
        parallel = _wrap(0.3 - alpha)
        # Leg A turned half a turn: no pose closes the loops with every piston joint in front
        # of its pivot (the scan agrees).
        away = [np.pi, 0.0, 0.0]
        impossible = [parallel.tolist(), away]
    for qa in impossible:
        assert rpr3gen.assembly_modes(model, qa).shape == (0, 3), qa
        assert len(_scanned_modes(model, np.array(qa))) == 0
    good = rpr3gen.actuator_coordinates(model, [[0.01, -0.02, 0.1]])[0]
    qa = np.array([*impossible, [np.nan, 0.0, 0.0], good])
    near = np.zeros_like(qa)
    found = rpr3gen.forward_kinematics(model, qa, near, backend="numpy")
    assert np.isnan(found[:-1]).all()
    np.testing.assert_allclose(found[-1], [0.01, -0.02, 0.1], rtol=0, atol=1e-9)


def _printed_modes(text: str) -> tuple[int, np.ndarray]:
    lines = text.strip().splitlines()
    assert lines[0].startswith("# ")
    count = int(lines[0].split()[1])
    rows = np.array([[float(v) for v in line.split()] for line in lines[1:]]).reshape(-1, 4)
    return count, rows


@pytest.mark.parametrize(
    ("actuation", "qa"),
    [("revolute", (0.1, -0.2, 0.05)), ("prismatic", (0.02, -0.03, 0.01))],
)
def test_cli_fk_prints_every_mode(
    actuation: str,
    qa: tuple[float, float, float],
    tmp_path: Path,
    repo_root: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    args = []
    if actuation == "prismatic":
        text = (repo_root / "models" / "paper.toml").read_text(encoding="utf-8")
        model_file = tmp_path / "prismatic.toml"
        model_file.write_text(text.replace('"revolute"', '"prismatic"', 1), encoding="utf-8")
        args = ["--model", str(model_file)]
    model = _model(actuation, "paper")
    assert main(["fk", *args, *map(str, qa)]) == 0
    count, rows = _printed_modes(capsys.readouterr().out)
    assert count == len(rows) == len(rpr3gen.assembly_modes(model, qa)) >= 1
    # 12 significant digits are printed: the modes map back to qa to ~1e-12.
    back = rpr3gen.actuator_coordinates(model, rows[:, :3])
    assert _qa_error(model, back, np.array(qa)).max() < 1e-9
    assert np.all((rows[:, 3] > 0) & (rows[:, 3] <= 1))  # the conditioning of accepted poses


# -- 2. the actuator Jacobian -------------------------------------------------------------------


def _central_difference(f, q: np.ndarray, direction: np.ndarray, h: float) -> np.ndarray:
    return (f(q + h * direction) - f(q - h * direction)) / (2 * h)


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_jacobian_is_the_derivative_of_the_actuator_coordinates(
    actuation: str, backend: str, robot: str | int
) -> None:
    """J against central differences of ``actuator_coordinates`` (h = 1e-6: truncation
    ~h^2 |qa'''| ~ 1e-12, round-off ~1e-16 |qa| / h ~ 1e-10), and J q' against the leg rates of
    Newton-Euler's kinematics (round-off)."""
    motion = _motion(actuation, robot)
    model, q, qd = motion.model, motion.q, motion.qd
    J = rpr3gen.actuator_jacobian(model, q, backend)
    assert J.shape == (len(q), 3, 3)
    assert np.isfinite(J).all()

    def qa(x: np.ndarray) -> np.ndarray:
        return rpr3gen.actuator_coordinates(model, x, backend)

    numeric = np.stack([_central_difference(qa, q, np.eye(3)[k], 1e-6) for k in range(3)], axis=2)
    assert _relative(J, numeric) < 1e-8
    legs = _leg_values(model, q, qd, motion.qdd)
    assert _relative(np.einsum("nij,nj->ni", J, qd), legs[RATE[actuation]]) < 1e-12


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_jacobian_rate_is_the_derivative_of_the_jacobian_along_the_motion(
    actuation: str, backend: str, robot: str | int
) -> None:
    """J' q' against central differences of J along q' (h = 1e-6), and qa'' = J q'' + J' q'
    against Newton-Euler's leg accelerations."""
    motion = _motion(actuation, robot)
    model, q, qd, qdd = motion
    rate = rpr3gen.jacobian_rate(model, q, qd, backend)
    h = 1e-6
    dJ = (
        rpr3gen.actuator_jacobian(model, q + h * qd, backend)
        - rpr3gen.actuator_jacobian(model, q - h * qd, backend)
    ) / (2 * h)
    assert _relative(rate, np.einsum("nij,nj->ni", dJ, qd)) < 1e-7
    J = rpr3gen.actuator_jacobian(model, q, backend)
    legs = _leg_values(model, q, qd, qdd)
    qa_dd = np.einsum("nij,nj->ni", J, qdd) + rate
    assert _relative(qa_dd, legs[ACCELERATION[actuation]]) < 1e-12


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_actuator_hessian_is_the_derivative_of_the_jacobian(
    actuation: str, backend: str, robot: str | int
) -> None:
    """H = d2 qa / dq2 against central differences of J (h = 1e-6) along each coordinate; H
    symmetric; H[q', q'] = J' q' (jacobian_rate, another program) and against Newton-Euler's leg
    accelerations at q'' = 0; qa and J those of actuator_coordinates_jacobian to round-off."""
    motion = _motion(actuation, robot)
    model, q, qd = motion.model, motion.q, motion.qd
    qa, J, H = rpr3gen.actuator_coordinates_hessian(model, q, backend)
    assert H.shape == (len(q), 3, 3, 3)
    assert np.array_equal(H, H.transpose(0, 1, 3, 2))
    h = 1e-6
    for k in range(3):
        step = h * np.eye(3)[k]
        dJ = (
            rpr3gen.actuator_jacobian(model, q + step, backend)
            - rpr3gen.actuator_jacobian(model, q - step, backend)
        ) / (2 * h)
        assert _relative(H[:, :, :, k], dJ) < 1e-7
    quadratic = np.einsum("nijk,nj,nk->ni", H, qd, qd)
    assert _relative(quadratic, rpr3gen.jacobian_rate(model, q, qd, backend)) < 1e-12
    legs = _leg_values(model, q, qd, np.zeros_like(q))
    assert _relative(quadratic, legs[ACCELERATION[actuation]]) < 1e-12
    qa_other, J_other = rpr3gen.actuator_coordinates_jacobian(model, q, backend)
    assert _relative(qa, qa_other) < 1e-14
    assert _relative(J, J_other) < 1e-14


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_jacobian_rate_is_the_leg_acceleration_at_rest_platform_acceleration(
    actuation: str, backend: str, robot: str | int
) -> None:
    """J' q' = qa'' at q'' = 0 (Newton-Euler's eps10 or gamma21), without J: this one also
    covers the NumPy revolute code, whose J is wrong."""
    motion = _motion(actuation, robot)
    model, q, qd = motion.model, motion.q, motion.qd
    rate = rpr3gen.jacobian_rate(model, q, qd, backend)
    legs = _leg_values(model, q, qd, np.zeros_like(q))
    assert _relative(rate, legs[ACCELERATION[actuation]]) < 1e-12


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_platform_velocity_inverts_the_jacobian(
    actuation: str, backend: str, robot: str | int
) -> None:
    """q' from the actuator rates of Newton-Euler's kinematics (and J q' = qa' back)."""
    motion = _motion(actuation, robot)
    model, q, qd = motion.model, motion.q, motion.qd
    rates = _leg_values(model, q, qd, motion.qdd)[RATE[actuation]]
    found = rpr3gen.platform_velocity(model, q, rates, backend)
    assert _relative(found, qd) < 1e-12
    J = rpr3gen.actuator_jacobian(model, q, backend)
    assert _relative(np.einsum("nij,nj->ni", J, found), rates) < 1e-12


# -- 3. task-space dynamics against Newton-Euler ------------------------------------------------


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_mass_matrix_is_the_kinetic_energy_and_positive_definite(
    actuation: str, backend: str, robot: str | int
) -> None:
    """M symmetric with positive eigenvalues, and ``q'^T M q' / 2`` is the kinetic energy of the
    seven bodies (Newton-Euler's ``energy(q, q') - energy(q, 0)``) for six velocities per pose,
    which fix all six entries of M."""
    motion = _motion(actuation, robot)
    model, q = motion.model, motion.q
    M, c = rpr3gen.task_space_dynamics(model, q, motion.qd, backend)
    assert M.shape == (len(q), 3, 3)
    assert c.shape == (len(q), 3)
    assert np.isfinite(M).all()
    assert np.isfinite(c).all()
    assert _relative(M.transpose(0, 2, 1), M) < 1e-15
    assert np.linalg.eigvalsh(M).min() > 0
    unit = np.array([1.0, 1.0, 1.0 / _rho(model)])  # ~1 m/s at the joints
    velocities = unit * np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1], [0, 1, 1]])
    for v in velocities:
        qd = np.broadcast_to(v, q.shape)
        kinetic = ne.energy(model.params, q, qd) - ne.energy(model.params, q, np.zeros_like(q))
        quadratic = 0.5 * np.einsum("ni,nij,nj->n", qd, M, qd)
        np.testing.assert_allclose(quadratic, kinetic, rtol=1e-12, atol=0)


def _newton_euler_motion(
    motion: str | int,
) -> tuple[Model, Model, np.ndarray, np.ndarray, np.ndarray]:
    """(revolute model, prismatic model, q, qd, qdd): the paper's trajectory of that name, or
    ``newton_euler.random_case`` of that seed (2 s, 41 samples), at the poses rpr3gen accepts."""
    if isinstance(motion, str):
        _, q, qd, qdd = ne.paper_motion(motion, 61)
        params = ne.paper_params()
    else:
        robot, q, qd, qdd = ne.random_case(motion, np.linspace(0.0, 2.0, 41))
        params = robot["params"]
    models = [Model(name="t", actuation=a, params=params, source="<test>") for a in ACTUATIONS]
    ok = _accepted(models[0], q) & _accepted(models[1], q)
    assert ok.sum() >= 0.8 * len(q)
    return models[0], models[1], q[ok], qd[ok], qdd[ok]


NE_MOTIONS: tuple[str | int, ...] = ("rotation", "rectilinear", 1, 2, 3)


@pytest.mark.parametrize("motion", NE_MOTIONS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_task_space_dynamics_balances_newton_euler_efforts(
    actuation: str, backend: str, motion: str | int
) -> None:
    """``M q'' + c = J^T tau`` with tau the efforts of the independent Newton-Euler solver."""
    *models, q, qd, qdd = _newton_euler_motion(motion)
    model = models[ACTUATIONS.index(actuation)]
    tau = _legs(ne.solve(model.params, actuation, q, qd, qdd), EFFORT[actuation])
    M, c = rpr3gen.task_space_dynamics(model, q, qd, backend)
    J = rpr3gen.actuator_jacobian(model, q, backend)
    left = np.einsum("nij,nj->ni", M, qdd) + c
    assert _relative(left, np.einsum("nji,nj->ni", J, tau)) < 1e-9


@pytest.mark.parametrize("motion", NE_MOTIONS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_actuator_efforts_are_the_newton_euler_efforts(
    actuation: str, backend: str, motion: str | int
) -> None:
    """The generated ``actuator_efforts`` (the computed-torque law's efforts) against the
    independent solver, and against ``J^-T (M q'' + c)`` of the task-space dynamics."""
    *models, q, qd, qdd = _newton_euler_motion(motion)
    model = models[ACTUATIONS.index(actuation)]
    tau = rpr3gen.actuator_efforts(model, q, qd, qdd, backend)
    assert (
        _relative(tau, _legs(ne.solve(model.params, actuation, q, qd, qdd), EFFORT[actuation]))
        < 1e-9
    )
    M, c = rpr3gen.task_space_dynamics(model, q, qd, backend)
    J = rpr3gen.actuator_jacobian(model, q, backend)
    law = np.linalg.solve(np.swapaxes(J, 1, 2), (np.einsum("nij,nj->ni", M, qdd) + c)[..., None])
    assert _relative(tau, law[..., 0]) < 1e-9


@pytest.mark.parametrize("motion", NE_MOTIONS)
@pytest.mark.parametrize("backend", BACKENDS)
def test_mechanism_dynamics_do_not_depend_on_the_actuation(backend: str, motion: str | int) -> None:
    """M and c belong to the mechanism: the same for both actuations (only J and tau differ)."""
    revolute, prismatic, q, qd, _ = _newton_euler_motion(motion)
    M_r, c_r = rpr3gen.task_space_dynamics(revolute, q, qd, backend)
    M_p, c_p = rpr3gen.task_space_dynamics(prismatic, q, qd, backend)
    assert _relative(M_r, M_p) < 1e-13
    assert _relative(c_r, c_p) < 1e-13


# -- 4. forward dynamics ----------------------------------------------------------------------


def _acceleration_error(found: np.ndarray, expected: np.ndarray) -> float:
    """Largest error over the largest |q''| of the motion (q'' crosses zero along a motion)."""
    return float(np.abs(found - expected).max() / np.abs(expected).max())


@pytest.mark.parametrize("motion", NE_MOTIONS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_forward_dynamics_of_newton_euler_efforts(
    actuation: str, backend: str, motion: str | int
) -> None:
    *models, q, qd, qdd = _newton_euler_motion(motion)
    model = models[ACTUATIONS.index(actuation)]
    tau = _legs(ne.solve(model.params, actuation, q, qd, qdd), EFFORT[actuation])
    assert _acceleration_error(rpr3gen.forward_dynamics(model, q, qd, tau, backend), qdd) < 1e-9


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_forward_dynamics_inverts_inverse_dynamics(
    actuation: str, backend: str, robot: str | int
) -> None:
    model, q, qd, qdd = _motion(actuation, robot)
    tau = _legs(rpr3gen.inverse_dynamics(model, q, qd, qdd, backend), EFFORT[actuation])
    found = rpr3gen.forward_dynamics(model, q, qd, tau, backend)
    assert _relative(found, qdd) < 1e-9


# -- 5. energy ------------------------------------------------------------------------------------


def _rk4(model: Model, start: np.ndarray, duration: float, dt: float, backend: str) -> np.ndarray:
    """States (steps + 1, n, 6) of rows of poses starting at rest, zero efforts, classic RK4."""
    state = np.concatenate([start, np.zeros_like(start)], axis=1)
    zero = np.zeros_like(start)

    def rate(s: np.ndarray) -> np.ndarray:
        qdd = rpr3gen.forward_dynamics(model, s[:, :3], s[:, 3:], zero, backend)
        return np.concatenate([s[:, 3:], qdd], axis=1)

    states = [state]
    for _ in range(round(duration / dt)):
        k1 = rate(state)
        k2 = rate(state + dt / 2 * k1)
        k3 = rate(state + dt / 2 * k2)
        k4 = rate(state + dt * k3)
        state = state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(state)
    return np.stack(states)


# (robot, start poses, duration): the robot falls freely, legs swinging, until a piston joint
# reaches its base pivot (rpr3gen refuses the pose): 0.24 s for the paper's robot from 0.2 m up.
ENERGY_RUNS = [
    ("paper", ((0.0, 0.2, 0.0), (0.02, 0.2, 0.1)), 0.2),
    (1, ((0.0, 0.05, 0.0), (-0.02, 0.03, -0.1)), 0.3),
]


@pytest.mark.parametrize(("robot", "starts", "duration"), ENERGY_RUNS)
@pytest.mark.parametrize(("actuation", "backend"), _cases())
def test_gravity_alone_conserves_energy(
    actuation: str,
    backend: str,
    robot: str | int,
    starts: tuple[tuple[float, float, float], ...],
    duration: float,
) -> None:
    """Zero efforts, no payload: Newton-Euler's energy stays constant along RK4 runs of the
    generated forward dynamics, to RK4's error.

    RK4's global error is O(dt^4): halving the step divides the drift by ~16 (measured 15.9 and
    16.0), so what is left is the integrator's; a model error (a term of M or c off by a fraction
    d) would leave a drift of ~d times the energy exchanged whatever the step. At dt = 2 ms the
    measured drift is at most 5e-11 of the energy exchanged (the kinetic energy gained in the
    fall: 24 J for the paper's robot, 41 J for the other); the bound is 1e-9.
    """
    model = _model(actuation, robot, payload=False)
    start = np.array(starts, dtype=float)
    drifts = []
    for dt in (4e-3, 2e-3):
        states = _rk4(model, start, duration, dt, backend)
        assert np.isfinite(states).all()
        q, qd = states[..., :3].reshape(-1, 3), states[..., 3:].reshape(-1, 3)
        energy = ne.energy(model.params, q, qd).reshape(states.shape[:2])
        kinetic = energy - ne.energy(model.params, q, np.zeros_like(qd)).reshape(energy.shape)
        exchanged = kinetic.max(axis=0)
        assert np.all(exchanged > 10.0)  # the run goes somewhere: tens of joules
        drifts.append(np.max(np.abs(energy - energy[0]).max(axis=0) / exchanged))
    assert drifts[1] < 1e-9
    assert 10 < drifts[0] / drifts[1] < 25  # fourth order


# -- 6. NumPy and C -------------------------------------------------------------------------------


def _evaluate(function: str, motion: Motion, backend: str) -> list[np.ndarray]:
    model, q, qd, qdd = motion
    if function == "actuator_coordinates":
        return [rpr3gen.actuator_coordinates(model, q, backend)]
    if function == "actuator_jacobian":
        return [rpr3gen.actuator_jacobian(model, q, backend)]
    if function == "actuator_coordinates_jacobian":
        return list(rpr3gen.actuator_coordinates_jacobian(model, q, backend))
    if function == "actuator_coordinates_hessian":
        return list(rpr3gen.actuator_coordinates_hessian(model, q, backend))
    if function == "jacobian_rate":
        return [rpr3gen.jacobian_rate(model, q, qd, backend)]
    if function == "platform_velocity":
        return [rpr3gen.platform_velocity(model, q, qd, backend)]
    if function == "task_space_dynamics":
        return list(rpr3gen.task_space_dynamics(model, q, qd, backend))
    if function == "forward_dynamics":
        return [rpr3gen.forward_dynamics(model, q, qd, 10 * qdd, backend)]
    if function == "actuator_efforts":
        return [rpr3gen.actuator_efforts(model, q, qd, qdd, backend)]
    assert function == "assembly_modes"
    qa = rpr3gen.actuator_coordinates(model, q[:10])
    return [rpr3gen.assembly_modes(model, row, backend) for row in qa]


FUNCTIONS = (
    "actuator_coordinates",
    "actuator_jacobian",
    "actuator_coordinates_jacobian",
    "actuator_coordinates_hessian",
    "jacobian_rate",
    "platform_velocity",
    "task_space_dynamics",
    "forward_dynamics",
    "actuator_efforts",
    "assembly_modes",
)


def _functions() -> list[object]:
    return [
        pytest.param(actuation, function, id=f"{actuation}-{function}")
        for actuation in ACTUATIONS
        for function in FUNCTIONS
    ]


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize(("actuation", "function"), _functions())
def test_numpy_and_c_agree(actuation: str, function: str, robot: str | int) -> None:
    """To 1e-12 relative; prismatic assembly modes to 1e-10: they are Newton-polished until the
    actuator residual is under 1e-11 (rpr3gen.control), and the backends may stop a step apart
    (measured 9e-12); the other functions are straight-line code (measured <= 8e-15)."""
    motion = _motion(actuation, robot)
    numpy_results = _evaluate(function, motion, "numpy")
    c_results = _evaluate(function, motion, "c")
    polished = function == "assembly_modes" and actuation == "prismatic"
    for a, b in zip(numpy_results, c_results, strict=True):
        assert a.shape == b.shape
        assert len(a)
        assert np.isfinite(b).all()
        assert _relative(a, b) < (1e-10 if polished else 1e-12)


# -- 7. refusal at a parallel singularity ------------------------------------------------------


def _jacobian_determinant(model: Model, q: np.ndarray) -> np.ndarray:
    """det J from Newton-Euler's kinematics (conventions.md): rows ``(n_x, n_y, e . s) / L``
    (revolute) or ``(e_x, e_y, s x e)`` (prismatic), ``s = A3 - G``."""
    kin = ne.kinematics(model.params, q, np.zeros_like(q))
    rows = []
    for leg in LEGS:
        k = kin[leg]
        s = k["A3"] - kin["platform"]["G"]
        e, n = k["e"], k["n"]
        if model.actuation == "revolute":
            rows.append(np.column_stack([n, np.sum(e * s, axis=1)]) / k["length"][:, None])
        else:
            rows.append(np.column_stack([e, s[:, 0] * e[:, 1] - s[:, 1] * e[:, 0]]))
    return np.linalg.det(np.stack(rows, axis=1))


@functools.cache
def _parallel_singularities(actuation: str, robot: str | int, lines: int = 60) -> np.ndarray:
    """Poses where det J changes sign (to round-off, by bisection along x) on random lines
    ``y, phi = const``, with every piston joint well in front of its base pivot."""
    model = _model(actuation, robot)
    rng = np.random.default_rng(11)
    y, phi = rng.uniform([-0.2, -1.0], [0.45, 1.0], size=(lines, 2)).T
    x = np.linspace(-0.4, 0.4, 401)

    def det(xs: np.ndarray, y: np.ndarray, phi: np.ndarray) -> np.ndarray:
        xs, y, phi = np.broadcast_arrays(xs, y, phi)
        poses = np.stack([xs, y, phi], axis=-1)
        return _jacobian_determinant(model, poses.reshape(-1, 3)).reshape(xs.shape)

    d = det(x, y[:, None], phi[:, None])  # (lines, 401)
    line, cell = np.nonzero(np.sign(d[:, :-1]) * np.sign(d[:, 1:]) < 0)
    lo, hi, sign = x[cell], x[cell + 1], np.sign(d[line, cell])
    for _ in range(60):
        mid = (lo + hi) / 2
        same = np.sign(det(mid, y[line], phi[line])) == sign
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    poses = np.column_stack([(lo + hi) / 2, y[line], phi[line]])
    legs = _leg_values(model, poses, np.zeros_like(poses), np.zeros_like(poses))
    reach = (legs["lambda21"] + model.params["l0"]).min(axis=1) / model.params["l0"]
    return poses[reach > 0.2]


@pytest.mark.parametrize("robot", ["paper", 1])
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_a_parallel_singularity_is_refused(actuation: str, backend: str, robot: str | int) -> None:
    """NaN rows (no exception) at a parallel singularity, like inverse_dynamics; a pose 1 cm
    away is evaluated: the refusal is the singularity's, not the neighbourhood's."""
    model = _model(actuation, robot)
    singular = _parallel_singularities(actuation, robot)
    assert len(singular) >= 5
    floor = manifest.load(actuation).thresholds["MIN_CONDITIONING"]
    nearby = singular + np.array([0.01, 0.0, 0.0])
    q = np.concatenate([singular, nearby])
    n = len(singular)
    zero = np.zeros_like(q)
    conditioning = rpr3gen.inverse_dynamics(model, nearby, zero[:n], zero[:n])["conditioning"]
    assert np.all(conditioning > floor)
    results = [
        rpr3gen.actuator_coordinates(model, q, backend),
        rpr3gen.actuator_jacobian(model, q, backend),
        rpr3gen.jacobian_rate(model, q, np.ones_like(q), backend),
        rpr3gen.platform_velocity(model, q, np.ones_like(q), backend),
        *rpr3gen.task_space_dynamics(model, q, np.ones_like(q), backend),
        rpr3gen.forward_dynamics(model, q, np.ones_like(q), np.ones_like(q), backend),
    ]
    for result in results:
        rows = result.reshape(len(q), -1)
        assert np.isnan(rows[:n]).all()
        assert np.isfinite(rows[n:]).all()


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_forward_kinematics_never_returns_a_refused_pose(actuation: str, robot: str | int) -> None:
    """The actuator coordinates of a parallel singularity: assembly_modes and forward_kinematics
    return only poses rpr3gen accepts (the singular one, a double mode, is refused as
    inverse_dynamics refuses it; a regular mode may remain), each mapping back to qa."""
    model = _model(actuation, robot)
    singular = _parallel_singularities(actuation, robot)
    qa = _leg_values(model, singular, np.zeros_like(singular), np.zeros_like(singular))
    qa = qa[COORDINATE[actuation]]
    found = rpr3gen.forward_kinematics(model, qa, singular, backend="numpy")
    returned = found[np.isfinite(found).all(axis=1)]
    assert _accepted(model, returned).all()
    for k in range(len(qa)):
        modes = rpr3gen.assembly_modes(model, qa[k])
        assert _accepted(model, modes).all()
        back = rpr3gen.actuator_coordinates(model, modes)
        assert _qa_error(model, back, qa[k]).max(initial=0) < 1e-9
