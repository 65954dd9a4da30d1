"""The production inverse dynamics (rpr3gen) against the independent Newton-Euler reference.

The reference (tests/newton_euler.py) is plain NumPy written from conventions.md alone; here it
judges the outputs of ``rpr3gen.inverse_dynamics`` on the paper robot, its two trajectories and
24 random robots loaded from model files, and the production outputs are also checked on their
own against energy, the free-body equations of every body and the robot's 120 deg symmetry.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import rpr3gen

try:
    from . import newton_euler as ne
except ImportError:
    import newton_euler as ne

RTOL = 1e-9  # per output family, relative to the family's largest |value| over legs and samples
N_RANDOM = 24
T_RANDOM = np.linspace(0.0, 2.0, 101)
ROT = 2 * math.pi / 3
NEXT_LEG = {"A": "B", "B": "C", "C": "A"}  # a +120 deg turn takes each leg to the next
LOAD_FAMILIES = ("m10", "f10x", "f10y", "f21y", "f21z", "m21", "f32y", "f32z")


# ----------------------------------------------------------------------------------------------
# Helpers


def _f(x) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return "[" + ", ".join(_f(x) for x in v) + "]"


def write_model(
    path: Path,
    *,
    name: str,
    actuation: str,
    l0: float,
    l1: float,
    l2: float,
    alpha_deg,
    base,
    platform,
    mass: dict[str, float],
    gravity,
    force=(0.0, 0.0),
    moment: float = 0.0,
) -> Path:
    """Write a model file in the explicit-points form of interfaces.md."""
    lines = [
        f'name = "{name}"',
        f'actuation = "{actuation}"',
        "",
        "[geometry]",
        f"l0 = {_f(l0)}",
        f"l1 = {_f(l1)}",
        f"l2 = {_f(l2)}",
        f"alpha_deg = {_vec(alpha_deg)}",
        "base = [" + ", ".join(_vec(b) for b in base) + "]",
        "platform = [" + ", ".join(_vec(p) for p in platform) + "]",
        "",
        "[mass]",
        *(f"{k} = {_f(v)}" for k, v in mass.items()),
        "",
        "[environment]",
        f"gravity = {_vec(gravity)}",
        "",
        "[payload]",
        f"force = {_vec(force)}",
        f"moment = {_f(moment)}",
        "",
    ]
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def _points(params, which: str) -> list[tuple[float, float]]:
    return [(params[f"x{leg}{which}"], params[f"y{leg}{which}"]) for leg in ne.LEGS]


def write_paper_explicit(path: Path, *, actuation: str, gravity, defaults: bool = True) -> Path:
    """The paper robot in explicit-points form (J3 given, the other mass keys defaulted unless
    ``defaults`` is False), with the given gravity."""
    p = ne.paper_params()
    mass = {"m1": p["m1"], "m2": p["m2"], "m3": p["m3"], "J3": p["J3"]}
    if not defaults:
        mass.update(c1=p["c1"], c2=p["c2"], J1=p["J1"], J2=p["J2"])
    return write_model(
        path,
        name="paper_explicit",
        actuation=actuation,
        l0=0.1,
        l1=0.2,
        l2=0.2,
        alpha_deg=(90.0, -150.0, -30.0),
        base=_points(p, "1"),
        platform=_points(p, "3"),
        mass=mass,
        gravity=gravity,
    )


def write_paper_symmetric(path: Path, *, actuation: str) -> Path:
    """The paper's model file (symmetric form) with another actuation."""
    text = (
        f'name = "paper_{actuation}"\n'
        f'actuation = "{actuation}"\n\n'
        "[geometry]\nl0 = 0.1\nl1 = 0.2\nl2 = 0.2\nr = 0.3\n"
        "alpha_deg = [90.0, -150.0, -30.0]\nbeta_deg = 30.0\n\n"
        "[mass]\nm1 = 3.0\nm2 = 1.5\nm3 = 5.0\n\n"
        "[environment]\ngravity = [0.0, -9.81]\n\n"
        "[payload]\nforce = [0.0, 0.0]\nmoment = 0.0\n"
    )
    path.write_text(text, encoding="utf-8")
    return path


BACKENDS = ("numpy", "c")


def run(model, q, qd, qdd, backend: str = "numpy") -> dict[str, np.ndarray]:
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend=backend)
    expected = {f"{fam}_{leg}" for fam in ne.FAMILIES for leg in ne.LEGS} | {
        "conditioning",
        "reach",
    }
    assert set(out) == expected, (
        f"missing {sorted(expected - set(out))}, unexpected {sorted(set(out) - expected)}"
    )
    n = np.asarray(q).shape[0]
    res = {}
    for key, value in out.items():
        arr = np.asarray(value, dtype=float)
        assert arr.shape == (n,), f"{key} has shape {arr.shape}, expected ({n},)"
        res[key] = arr
    return res


def family_errors(out, ref) -> list[tuple[float, str, float, float]]:
    """Per output, max |out - ref| relative to the reference family's largest |value| (over legs
    and samples, floored at 1e-300); non-finite values count as infinitely wrong.

    Returns:
        [(relative error, output name, absolute error, family scale)], worst first.
    """
    errs = []
    for fam in ne.FAMILIES:
        scale = max(max(float(np.max(np.abs(ref[f"{fam}_{leg}"]))) for leg in ne.LEGS), 1e-300)
        for leg in ne.LEGS:
            key = f"{fam}_{leg}"
            diff = np.abs(out[key] - ref[key])
            err = float(np.max(diff)) if np.all(np.isfinite(diff)) else math.inf
            errs.append((err / scale, key, err, scale))
    return sorted(errs, reverse=True)


def assert_agree(out, ref, what: str, rtol: float = RTOL) -> None:
    errs = family_errors(out, ref)
    bad = [e for e in errs if not e[0] <= rtol]
    shown = [e for e in errs[:6] if e[0] > 0] or errs[:1]
    detail = "; ".join(f"{k}: rel {r:.3e} (abs {a:.3e}, scale {s:.3e})" for r, k, a, s in shown)
    assert not bad, f"{what}: {len(bad)} outputs differ beyond {rtol:g}; worst: {detail}"


def param_differences(got, want, tol: float = 1e-12) -> dict[str, tuple[float, float]]:
    """Parameters whose values differ by more than ``tol``: name -> (got, want)."""
    return {k: (got[k], want[k]) for k in ne.PARAM_NAMES if not abs(got[k] - want[k]) <= tol}


def load_scale(out) -> float:
    return max(float(np.max(np.abs(out[f"{f}_{leg}"]))) for f in LOAD_FAMILIES for leg in ne.LEGS)


def assert_power_balance(params, out, q, qd, qdd, what: str) -> None:
    p_in = ne.input_power(params, out, qd)
    rate = ne.energy_rate(params, q, qd, qdd)
    terms = (
        sum(np.abs(out[f"m10_{leg}"] * out[f"omega10_{leg}"]) for leg in ne.LEGS)
        + sum(np.abs(out[f"f21z_{leg}"] * out[f"v21_{leg}"]) for leg in ne.LEGS)
        + np.abs(rate)
    )
    scale = max(float(np.max(terms)), 1e-12)
    err = float(np.max(np.abs(p_in - rate)))
    assert err <= RTOL * scale, (
        f"{what}: power balance off by {err:.3e} W (scale {scale:.3e} W, "
        f"worst at sample {int(np.argmax(np.abs(p_in - rate)))})"
    )


def assert_free_body(params, actuation, out, q, qdd, what: str) -> None:
    """Every body's equations, rebuilt from the production outputs (and the platform motion),
    hold with no moment at A3 and nothing along the idle joint's free direction."""
    res = ne.body_residuals(params, out, q, qdd)
    scale = load_scale(out)
    worst = []
    for key, r in res.items():
        if key.startswith("closure"):
            err, tol = float(np.max(np.abs(r))), 1e-12  # metres
        else:
            # force rows in N, moment row in N m: the robot spans < 1 m, so use the same scale
            err, tol = float(np.max(np.abs(r))), RTOL * scale
        if not np.isfinite(err) or err > tol:
            worst.append(f"{key}: {err:.3e} (tol {tol:.3e})")
    idle = "f21z" if actuation == "revolute" else "m10"
    for leg in ne.LEGS:
        err = float(np.max(np.abs(out[f"{idle}_{leg}"])))
        if not err <= 1e-12 * scale:
            worst.append(f"{idle}_{leg} of the passive joint is {err:.3e}, not 0")
    assert not worst, f"{what}: " + "; ".join(worst)


# ----------------------------------------------------------------------------------------------
# The paper robot


def test_load_model_is_the_paper_robot():
    model = rpr3gen.load_model()
    assert model.actuation == "revolute"
    assert set(model.params) == set(ne.PARAM_NAMES)
    ref = ne.paper_params()
    bad = param_differences(model.params, ref)
    assert not bad, f"load_model() parameters differ from conventions.md: {bad}"


@pytest.mark.parametrize("kind", ["rotation", "rectilinear"])
def test_paper_trajectory_is_eq3(kind):
    traj = rpr3gen.paper_trajectory(kind, samples=301, duration=3.0)
    t = np.asarray(traj.t, dtype=float)
    assert t.shape == (301,)
    np.testing.assert_allclose(t, np.linspace(0.0, 3.0, 301), rtol=0, atol=1e-14)
    amp = {"rotation": (0.0, 0.0, math.pi / 6), "rectilinear": (0.05, -0.05, 0.0)}[kind]
    for got, want in zip((traj.q, traj.qd, traj.qdd), ne.cosine_motion(t, amp, 3.0), strict=True):
        np.testing.assert_allclose(np.asarray(got, dtype=float), want, rtol=0, atol=1e-14)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("kind", ["rotation", "rectilinear"])
def test_paper_trajectories_agree_with_newton_euler(kind, backend):
    model = rpr3gen.load_model()
    traj = rpr3gen.paper_trajectory(kind, samples=301, duration=3.0)
    q, qd, qdd = (np.asarray(a, dtype=float) for a in (traj.q, traj.qd, traj.qdd))
    out = run(model, q, qd, qdd, backend)
    ref = ne.solve(ne.paper_params(), "revolute", q, qd, qdd)
    assert_agree(out, ref, f"paper robot, {kind}, {backend}")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("kind", ["rotation", "rectilinear"])
def test_paper_prismatic_agrees_with_newton_euler(kind, backend, tmp_path):
    model = rpr3gen.load_model(write_paper_symmetric(tmp_path / "p.toml", actuation="prismatic"))
    assert model.actuation == "prismatic"
    _, q, qd, qdd = ne.paper_motion(kind, 301, 3.0)
    out = run(model, q, qd, qdd, backend)
    ref = ne.solve(ne.paper_params(), "prismatic", q, qd, qdd)
    assert_agree(out, ref, f"paper robot, prismatic, {kind}, {backend}")


@pytest.mark.parametrize("actuation", ne.ACTUATIONS)
@pytest.mark.parametrize("kind", ["rotation", "rectilinear"])
def test_paper_power_balance_and_free_body(kind, actuation, tmp_path):
    model = rpr3gen.load_model(write_paper_symmetric(tmp_path / "p.toml", actuation=actuation))
    _, q, qd, qdd = ne.paper_motion(kind, 301, 3.0)
    out = run(model, q, qd, qdd)
    p = ne.paper_params()
    assert_power_balance(p, out, q, qd, qdd, f"paper {actuation} {kind}")
    assert_free_body(p, actuation, out, q, qdd, f"paper {actuation} {kind}")


# ----------------------------------------------------------------------------------------------
# Random robots from model files


@pytest.fixture(scope="module")
def random_run(tmp_path_factory):
    """seed -> (params, actuation, model, q, qd, qdd, production outputs), computed once."""
    cache: dict[int, tuple] = {}
    folder = tmp_path_factory.mktemp("random_models")

    def get(seed: int):
        if seed not in cache:
            robot, q, qd, qdd = ne.random_case(seed, T_RANDOM)
            p = robot["params"]
            actuation = ne.ACTUATIONS[seed % 2]
            path = write_model(
                folder / f"random_{seed}.toml",
                name=f"random_{seed}",
                actuation=actuation,
                l0=p["l0"],
                l1=robot["l1"],
                l2=p["l2"],
                alpha_deg=robot["alpha_deg"],
                base=robot["base"],
                platform=robot["platform"],
                mass={
                    k: p[k]
                    for k in ("m1", "m2", "m3", "c1", "c2", "c1_perp", "c2_perp", "J1", "J2", "J3")
                },
                gravity=(p["gx"], p["gy"]),
                force=(p["fx"], p["fy"]),
                moment=p["mz"],
            )
            model = rpr3gen.load_model(path)
            out = run(model, q, qd, qdd)
            cache[seed] = (p, actuation, model, q, qd, qdd, out)
        return cache[seed]

    return get


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_model_is_loaded_as_written(seed, random_run):
    p, actuation, model, *_ = random_run(seed)
    assert model.actuation == actuation
    assert set(model.params) == set(ne.PARAM_NAMES)
    bad = param_differences(model.params, p)
    assert not bad, f"seed {seed}: parameters differ from the model file: {bad}"


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_models_agree_with_newton_euler(seed, random_run):
    p, actuation, _, q, qd, qdd, out = random_run(seed)
    ref = ne.solve(p, actuation, q, qd, qdd)
    assert_agree(out, ref, f"random model seed {seed} ({actuation})")


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_models_c_backend_agrees_with_newton_euler(seed, random_run):
    p, actuation, model, q, qd, qdd, _ = random_run(seed)
    out = run(model, q, qd, qdd, "c")
    ref = ne.solve(p, actuation, q, qd, qdd)
    assert_agree(out, ref, f"random model seed {seed} ({actuation}), c backend")


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_models_power_balance(seed, random_run):
    p, actuation, _, q, qd, qdd, out = random_run(seed)
    assert_power_balance(p, out, q, qd, qdd, f"random model seed {seed} ({actuation})")


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_models_free_body(seed, random_run):
    p, actuation, _, q, _, qdd, out = random_run(seed)
    assert_free_body(p, actuation, out, q, qdd, f"random model seed {seed} ({actuation})")


# ----------------------------------------------------------------------------------------------
# Symmetry of the production code


def check_symmetry(out, out_rot, what: str, rtol: float = RTOL) -> None:
    """Leg NEXT_LEG[L] of the motion turned by +120 deg equals leg L of the original motion,
    with the base force f10 turned by 120 deg."""
    R = ne.rotation(ROT)
    turned = {}
    for leg in ne.LEGS:
        nxt = NEXT_LEG[leg]
        for fam in ne.FAMILIES:
            turned[f"{fam}_{leg}"] = out_rot[f"{fam}_{nxt}"]
        f10 = np.stack([out_rot[f"f10x_{nxt}"], out_rot[f"f10y_{nxt}"]], axis=-1) @ R  # R^T f
        turned[f"f10x_{leg}"], turned[f"f10y_{leg}"] = f10[:, 0], f10[:, 1]
    assert_agree(turned, out, what, rtol)


@pytest.mark.parametrize("actuation", ne.ACTUATIONS)
@pytest.mark.parametrize("gravity", ["rotated", "zero"])
def test_symmetry_120(actuation, gravity, tmp_path):
    g = np.array([0.0, -9.81]) if gravity == "rotated" else np.zeros(2)
    g_rot = ne.rotation(ROT) @ g
    model = rpr3gen.load_model(
        write_paper_explicit(tmp_path / "a.toml", actuation=actuation, gravity=g, defaults=False)
    )
    model_rot = rpr3gen.load_model(
        write_paper_explicit(tmp_path / "b.toml", actuation=actuation, gravity=g_rot)
    )
    q, qd, qdd = ne.sinusoid_motion(np.random.default_rng(11), T_RANDOM)
    out = run(model, q, qd, qdd)
    out_rot = run(model_rot, *ne.rotate_motion(ROT, q, qd, qdd))
    check_symmetry(out, out_rot, f"{actuation}, {gravity} gravity")


def test_paper_explicit_form_loads_like_the_paper(tmp_path):
    """Explicit points with defaulted c1, c2, J1, J2 give the paper's parameters."""
    model = rpr3gen.load_model(
        write_paper_explicit(tmp_path / "e.toml", actuation="revolute", gravity=(0.0, -9.81))
    )
    ref = ne.paper_params()
    bad = param_differences(model.params, ref)
    assert not bad, f"explicit-points paper model differs from conventions.md: {bad}"
