"""Spatial robots: identification (regressor, base parameters, identify, excite) against the
independent Newton–Euler reference (``tests/spatial_reference.py``).

The regressor is judged by what it promises, ``tau = Y pi + tau_payload``, with the efforts
``tau`` of the reference, for several random inertial values on one geometry: ``Y`` must be the
same for all of them (it depends on the geometry and gravity only) and reproduce each. The
inertial parameters ``pi`` are computed here from the model file's numbers by the parallel axis
theorem, written apart from ``rpr3gen.spatial_inertia``.
"""

from __future__ import annotations

import copy
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.errors import InputError

try:
    from . import spatial_models as sm
    from . import spatial_reference as sr
except ImportError:
    import spatial_models as sm
    import spatial_reference as sr

STRUCTURES = ("UPS", "RUS", "PUS", "RSS2", "PSS2")
SAMPLES = 8
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _quick(quick_c_builds: None) -> None:
    """The C backend at -O0 here (the values do not depend on the level)."""


def _expanded(data: dict) -> dict:
    """The model with its legs written out (no ``symmetric`` sugar)."""
    out = copy.deepcopy(data)
    if out.pop("symmetric", False):
        out["legs"] = sr.expand_symmetric(data["leg"], data["legs"])
    return out


def _tensor(rng: np.random.Generator, size: float) -> list[float]:
    """A physical inertia tensor: principal moments within a factor two, turned at random."""
    moments = rng.uniform(0.5, 1.0, 3) * size
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return sr.inertia_list(Q @ np.diag(moments) @ Q.T)


def reweighed(data: dict, rng: np.random.Generator) -> dict:
    """The same geometry with random masses, centres of mass and inertias (payload kept)."""
    out = _expanded(data)
    for leg in out["legs"].values():
        bodies = len(leg["mass"])
        leg["mass"] = rng.uniform(0.05, 2.0, bodies).tolist()
        leg["com"] = [(np.asarray(c) + rng.normal(0, 0.05, 3)).tolist() for c in leg["com"]]
        leg["inertia"] = [_tensor(rng, 0.01) for _ in range(bodies)]
        if "rod_mass" in leg:
            leg["rod_mass"] = float(rng.uniform(0.05, 0.5))
            leg["rod_com"] = float(rng.uniform(0.2, 0.8))
            leg["rod_inertia"] = float(rng.uniform(0.001, 0.02))
    platform = out["platform"]
    platform["mass"] = float(rng.uniform(0.5, 3.0))
    platform["com"] = (np.asarray(platform["com"]) + rng.normal(0, 0.03, 3)).tolist()
    platform["inertia"] = _tensor(rng, 0.05)
    return out


def _first_points(data: dict) -> dict[str, list[np.ndarray]]:
    """Each leg's bodies' reference points (docs/spatial-robots.md): joint 1's point for
    body 1; the U centre for a hexapod's body 2 (UPS: the base U; RUS, PUS: the elbow)."""
    out = {}
    for name, leg in data["legs"].items():
        base = np.asarray(leg["base"], dtype=float)
        second = base if data["leg"] == "UPS" else np.asarray(leg.get("elbow", base), dtype=float)
        out[name] = [base, second]
    return out


def _body_pi(m: float, c: np.ndarray, inertia: list[float], ref: np.ndarray) -> list[float]:
    d = np.asarray(c, dtype=float) - ref
    I_ref = sr.inertia_matrix(inertia) + m * (d @ d * np.eye(3) - np.outer(d, d))
    return [m, *(m * d), *sr.inertia_list(I_ref)]


def inertial_parameters(data: dict) -> np.ndarray:
    """``pi`` of a model dict, in the order of docs/spatial-robots.md."""
    data = _expanded(data)
    out: list[float] = []
    refs = _first_points(data)
    for name in sr.leg_names(data["leg"]):
        leg = data["legs"][name]
        for k, (m, c, inertia) in enumerate(
            zip(leg["mass"], leg["com"], leg["inertia"], strict=True)
        ):
            out += _body_pi(m, c, inertia, refs[name][k])
        if "rod_mass" in leg:
            length = float(np.linalg.norm(np.subtract(leg["platform"], leg["elbow"])))
            m, arm = leg["rod_mass"], leg["rod_com"] * length
            out += [m, m * arm, leg["rod_inertia"] + m * arm**2]
    p = data["platform"]
    out += _body_pi(p["mass"], np.asarray(p["com"]), p["inertia"], np.zeros(3))
    return np.array(out)


def rich_samples(data: dict, rng: np.random.Generator, n: int) -> tuple[np.ndarray, ...]:
    """``n`` independent random samples: poses within three times the amplitudes of
    ``spatial_models.motion_amplitudes`` of home (reachable and well conditioned, by the
    reference), rates and accelerations of a few times those: rich enough to excite every
    base parameter, as sample-by-sample data may be."""
    amp = 3 * sm.motion_amplitudes(data)
    q = rng.uniform(-1, 1, (4 * n, amp.size)) * amp
    ok = (sm.conditioning(data, q) < sm.MAX_COND_MOTION) & (sm.reach(data, q) > sm.MIN_REACH)
    q = q[ok][:n]
    assert len(q) == n
    return q, rng.normal(0, 1, q.shape) * amp * 5, rng.normal(0, 1, q.shape) * amp * 25


def _reference_tau(data: dict, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    return sr.efforts(data, sr.solve(data, q, qd, qdd))


@pytest.mark.parametrize("backend", ["numpy", "c"])
@pytest.mark.parametrize("leg", STRUCTURES)
def test_regressor_reproduces_the_references_efforts(leg: str, backend: str) -> None:
    """One ``Y`` for three inertial sets on one geometry, each ``Y pi + tau_payload`` equal to
    the reference's efforts; ``rpr3gen.inertial_parameters`` equal to the parallel-axis ``pi``
    computed here."""
    rng = np.random.default_rng(71)
    data = sm.random_model(leg, rng)
    q, qd, qdd = (np.ascontiguousarray(a) for a in sm.random_motion(data, rng, SAMPLES))
    first = None
    for k in range(3):
        weighed = reweighed(data, np.random.default_rng(100 + k))
        model = rpr3gen.model_from_dict(weighed, source=f"reweighed-{leg}-{k}")
        Y = rpr3gen.regressor(model, q, qd, qdd, backend=backend)
        pi = inertial_parameters(weighed)
        assert len(rpr3gen.inertial_parameter_names(model)) == Y.shape[2] == len(pi)
        np.testing.assert_allclose(rpr3gen.inertial_parameters(model), pi, rtol=1e-12, atol=1e-15)
        if first is None:
            first = Y
        else:
            np.testing.assert_allclose(Y, first, rtol=0, atol=1e-9 * np.abs(first).max())
        tau = _reference_tau(weighed, q, qd, qdd)
        predicted = Y @ pi + rpr3gen.payload_efforts(model, q, backend=backend)
        np.testing.assert_allclose(predicted, tau, rtol=0, atol=1e-9 * np.abs(tau).max())


@pytest.mark.parametrize("leg", STRUCTURES)
def test_regressor_numpy_equals_c(leg: str) -> None:
    rng = np.random.default_rng(5)
    data = sm.random_model(leg, rng)
    model = rpr3gen.model_from_dict(data, source=f"random-{leg}")
    q, qd, qdd = sm.random_motion(data, rng, SAMPLES)
    a = rpr3gen.regressor(model, q, qd, qdd, backend="numpy")
    b = rpr3gen.regressor(model, q, qd, qdd, backend="c")
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(a).max())


@pytest.mark.parametrize("leg", STRUCTURES)
def test_base_parameters_span_the_regressor(leg: str) -> None:
    """``B`` is the rank of the stacked regressor on fresh samples, and ``Y pi == Yb (X pi)``
    for random ``pi`` (not only physical ones)."""
    rng = np.random.default_rng(9)
    data = sm.random_model(leg, rng)
    model = rpr3gen.model_from_dict(data, source=f"random-{leg}")
    base = rpr3gen.base_parameters(model)
    q, qd, qdd = sm.random_motion(data, rng, 60)
    Y = rpr3gen.regressor(model, q, qd, qdd)
    W = Y.reshape(-1, Y.shape[2])
    norms = np.linalg.norm(W, axis=0)
    W = W[:, norms > 1e-9 * norms.max()]  # not the columns of round-off (none of its own)
    s = np.linalg.svd(W / np.linalg.norm(W, axis=0), compute_uv=False)
    assert int(np.sum(s > 1e-12 * s[0])) == len(base.names)  # the gap: ~1e-8 to ~1e-15
    Yb = rpr3gen.base_regressor(model, q, qd, qdd)
    for pi in rng.normal(size=(3, Y.shape[2])):
        np.testing.assert_allclose(
            Yb @ (base.matrix @ pi), Y @ pi, rtol=0, atol=1e-8 * np.abs(Y @ pi).max()
        )


@pytest.mark.parametrize("leg", ["UPS", "RSS2"])
def test_identify_recovers_the_base_parameters(leg: str) -> None:
    """Noise-free efforts of the reference with friction added: the estimates are the model's
    base parameters and the friction given."""
    rng = np.random.default_rng(13)
    data = sm.random_model(leg, rng)
    model = rpr3gen.model_from_dict(data, source=f"random-{leg}")
    q, qd, qdd = rich_samples(data, rng, 150)
    tau = _reference_tau(data, q, qd, qdd)
    k = tau.shape[1]
    rates = sr.actuator_rates(data, q, qd)
    fv, fc = rng.uniform(0.1, 1.0, k), rng.uniform(0.1, 1.0, k)
    tau = tau + fv * rates + fc * np.sign(rates)
    # Noise-free data: a condition number of a few thousand (an arm's two first moments, seen
    # through arm angles within a few degrees) costs nothing here, so it does not warn.
    fit = rpr3gen.identify(model, q, qd, qdd, tau, friction=True, backend="c", warn_condition=1e5)
    expected = fit.base.matrix @ inertial_parameters(data)
    B = len(expected)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(fit.values[:B], expected, rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(fit.values[B:], np.concatenate([fv, fc]), rtol=1e-7)
    assert fit.names[B:] == tuple(f"fv_{n}" for n in sr.leg_names(leg)) + tuple(
        f"fc_{n}" for n in sr.leg_names(leg)
    )
    assert fit.residual_rms <= 1e-9 * np.abs(tau).max()


def test_identical_legs_refused_when_the_legs_differ() -> None:
    """The gallery Delta's legs are turned copies: their first moments differ in world axes."""
    model = rpr3gen.load_model(ROOT / "models" / "delta.toml")
    with pytest.raises(InputError, match="identical_legs: leg B"):
        rpr3gen.inertial_parameters(model, identical_legs=True)
    names = rpr3gen.inertial_parameter_names(model, identical_legs=True)
    assert names[:3] == ("m_1", "mcx_1", "mcy_1")
    assert names[-1] == "Iyz_3"
    assert len(names) == 13 + 10


def test_identify_refuses_a_motion_of_the_wrong_width() -> None:
    model = rpr3gen.load_model(ROOT / "models" / "delta.toml")
    q = np.zeros((20, 6))
    with pytest.raises(InputError, match=r"q: must have shape \(n, 3\)"):
        rpr3gen.identify(model, q, q, q, q)


def test_excite_a_delta_keeps_its_constraints() -> None:
    """A short optimisation lowers the condition number; along the motion the reference's
    conditioning-free check: every pose reachable, within the excursion and accelerations."""
    model = rpr3gen.load_model(ROOT / "models" / "delta.toml")
    found = rpr3gen.excite(
        model, harmonics=2, samples=41, max_iterations=8, max_excursion=(0.1, 0.3)
    )
    assert found.condition_number < found.initial_condition_number
    traj = found.trajectory
    assert np.abs(traj.q).max() <= 0.1 * (1 + 1e-6)
    assert np.abs(traj.qdd).max() <= 2.0 * (1 + 1e-6)
    data = tomllib.loads((ROOT / "models" / "delta.toml").read_text())
    out = sr.solve(data, traj.q, traj.qd, traj.qdd)
    assert np.isfinite(sr.efforts(data, out)).all()
    assert found.min_conditioning >= 0.1


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", *args], capture_output=True, text=True, check=False
    )


def test_identify_command_on_a_hexapod(tmp_path: Path) -> None:
    """``rpr3gen identify`` reads a hexapod's data CSV (its pose's columns and tau_A..F) and
    writes the estimates: the model's base parameters, from the reference's efforts."""
    source = ROOT / "models" / "tsai-ups.toml"
    data = tomllib.loads(source.read_text())
    model = rpr3gen.load_model(source)
    q, qd, qdd = rich_samples(data, np.random.default_rng(3), 120)
    tau = _reference_tau(data, q, qd, qdd)
    pose = model.structure.pose
    header = ["t", *pose, *(f"d{p}" for p in pose), *(f"dd{p}" for p in pose)]
    header += [f"tau_{leg}" for leg in model.structure.legs]
    csv = tmp_path / "data.csv"
    table = np.column_stack([np.arange(len(q)) * 0.01, q, qd, qdd, tau])
    np.savetxt(csv, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    out = tmp_path / "fit.toml"
    run = _cli("identify", "--model", str(source), "--data", str(csv), "--out", str(out))
    assert run.returncode == 0, run.stderr
    assert "6-UPS" in run.stdout
    fit = tomllib.loads(out.read_text())
    expected = rpr3gen.base_parameters(model).matrix @ inertial_parameters(data)
    got = np.array(list(fit["estimates"].values()))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-7 * np.abs(expected).max())


def test_identify_command_names_a_missing_effort_column(tmp_path: Path) -> None:
    source = ROOT / "models" / "tsai-ups.toml"
    csv = tmp_path / "data.csv"
    csv.write_text("t,x,y,z,a,b,c,tau_A,tau_B,tau_C\n0,0,0,0,0,0,0,1,2,3\n")
    run = _cli("identify", "--model", str(source), "--data", str(csv))
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert "tau_D" in lines[0]
    assert str(csv) in lines[0]
