"""Generated code of planar structures through the runtime, NumPy and C, against physics.

Cases: the gallery's symmetric 3-RRR (``models/rrr.toml``, the committed ``rrr_1``) and a random
3-RRR with base motors; the paper's robot as a general model (its twin, ``rpr_1``: lines); and
variants generated on first use into the session's cache: ``rpr_2`` (the prismatic twin:
circles, prismatic motors), ``prr_1`` (circles, prismatic), ``rpr_3`` (platform lines,
revolute), ``ppr_2`` (lines, prismatic); and a random robot of each of the other 12 structures
that are not architecturally singular (``rrr_2`` ... ``rpp_3``), so that the generated code of
all 18 meets the reference, not only their derivation (``tests/test_planar_derivation.py``).

Judged by the independent Newton-Euler reference (``tests/planar_reference.py``, its brute-force
assembly modes) and by ``tests/planar_checks.py``: the parameter vector of the general format,
every inverse-dynamics output, the control model (J, J'q', platform velocity, efforts, M and c,
forward dynamics), the regressor, every assembly mode mapping back to the actuator coordinates,
the true pose among them and their count within the structure's bound, the tracked forward
kinematics (C from a nearby reference, NumPy), NumPy against C for every generated function,
and the C ABI's single call against the batch, bit for bit.

``rrr_1`` runs the C the runtime builds for users (-O3). The other variants' C is built from a
private copy of their generated folder at -O0 (the same C source, a twentieth of the compile
time; the private folder keeps that library from every other test).

Measured (seeds below), on the first seven cases: inverse dynamics within 4.7e-15 of the
reference (NumPy and C, relative to the largest value of each unit); J, M, c within 1e-15,
forward dynamics 4.3e-14, regressor 1.4e-15; NumPy and C within 7.9e-14 on every function; 1 to
4 modes per pose, every mode of the reference's brute force among them (within 1.6e-12 m). On
all 19 (2026-11-25, NumPy): inverse dynamics within 4.7e-15, J 1.6e-15, M 1.3e-15, c 1.1e-15.
"""

from __future__ import annotations

import ctypes
import dataclasses
import functools
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen import cbackend, variants
from rpr3gen.model import Model, model_from_dict

try:
    from . import planar_checks as chk
    from . import planar_models as pm
    from . import planar_reference as pr
except ImportError:
    import planar_checks as chk
    import planar_models as pm
    import planar_reference as pr


ROOT = Path(__file__).resolve().parent.parent
LEGS = chk.LEGS
T = np.linspace(0.0, 1.5, 9)


def _gallery_rrr() -> dict:
    """``models/rrr.toml`` with legs B and C written out (the reference has no sugar)."""
    with (ROOT / "models" / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    assert data.pop("symmetric") is True
    data["legs"] = pr.expand_symmetric(data["legs"]["A"])
    return data


def _twin(actuation: str) -> dict:
    return pm.paper_twin(dict(rpr3gen.load_model().params), actuation)


def _random(leg: str, actuated: int, seed: int) -> dict:
    return pm.random_model(np.random.default_rng(seed), leg, actuated)


#: name -> (model dict, variant)
CASES = {
    "rrr-gallery": (_gallery_rrr, "rrr_1"),
    "rrr-random": (functools.partial(_random, "RRR", 1, 11), "rrr_1"),
    "paper-twin": (functools.partial(_twin, "revolute"), "rpr_1"),
    "paper-twin-prismatic": (functools.partial(_twin, "prismatic"), "rpr_2"),
    "prr1": (functools.partial(_random, "PRR", 1, 12), "prr_1"),
    "rpr3": (functools.partial(_random, "RPR", 3, 13), "rpr_3"),
    "ppr2": (functools.partial(_random, "PPR", 2, 14), "ppr_2"),
}
#: Every other structure that is not architecturally singular, a random robot each: the same
#: checks, so that the generated code of all 18 structures meets the reference.
CASES.update(
    {
        f"{leg.lower()}{held}": (
            functools.partial(_random, leg, held, 30 + k),
            f"{leg.lower()}_{held}",
        )
        for k, (leg, held) in enumerate(pm.nonsingular_structures())
        if f"{leg.lower()}_{held}" not in {variant for _, variant in CASES.values()}
    }
)
NAMES = list(CASES)


@dataclasses.dataclass(frozen=True)
class Case:
    data: dict
    robot: pr.Robot
    model: Model
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    ref: dict[str, np.ndarray]


@functools.cache
def _case(name: str) -> Case:
    build, variant = CASES[name]
    data = build()
    robot = pr.parse_model(data)
    model = model_from_dict(data, source=name)
    assert model.variant == variant
    rng = np.random.default_rng(sum(map(ord, name)))
    q, qd, qdd = pm.random_motion(rng, robot, T)
    return Case(data, robot, model, q, qd, qdd, pr.solve(robot, q, qd, qdd))


_PRIVATE: dict[str, Model] = {}


def _c_model(name: str, tmp_root: Path) -> Model:
    """The case's model for the c backend: itself for rrr_1 (the -O3 build users get); else
    evaluated from a private copy of its generated folder, compiled at -O0."""
    model = _case(name).model
    if model.variant == "rrr_1":
        return model
    if model.variant not in _PRIVATE:
        source = variants.load(model.structure).folder
        root = tmp_root / model.variant
        shutil.copytree(source, root / model.variant)
        private = dataclasses.replace(model, generated=str(root))
        quick = tuple("-O0" if flag == "-O3" else flag for flag in cbackend.CFLAGS)
        assert quick != cbackend.CFLAGS
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(cbackend, "CFLAGS", quick)
            cbackend.library(variants.load(private.structure, private.generated))
        _PRIVATE[model.variant] = private
    return dataclasses.replace(_PRIVATE[model.variant], params=model.params, name=model.name)


@pytest.fixture(scope="module")
def private_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("private-variants")


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))


def _stack(out, family: str) -> np.ndarray:
    return np.stack([out[f"{family}_{leg}"] for leg in LEGS], axis=1)


# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_the_reader_gives_the_general_parameter_vector(name: str) -> None:
    """The runtime's parameters of a general model dict: joint points, unit P axes, the working
    mode's sign, bodies, gravity and payload, as the spec defines them."""
    c = _case(name)
    expected = chk.param_values(c.data)
    assert list(c.model.params) == list(c.model.structure.param_names())
    assert set(c.model.params) == set(expected)
    for key, value in expected.items():
        assert c.model.params[key] == pytest.approx(value, rel=1e-15, abs=1e-15), key


@pytest.mark.parametrize("backend", ["numpy", "c"])
@pytest.mark.parametrize("name", NAMES)
def test_inverse_dynamics_matches_the_reference(name: str, backend: str, private_root) -> None:
    c = _case(name)
    model = c.model if backend == "numpy" else _c_model(name, private_root)
    out = rpr3gen.inverse_dynamics(model, c.q, c.qd, c.qdd, backend=backend)
    assert set(out) == {*c.ref, "conditioning", "reach"}
    err, where = chk.worst_error(out, c.ref, c.robot.leg, c.robot.actuated)
    assert err < 1e-11, f"{where}: {err:.2e}"
    assert np.all(out["reach"] > 0)
    assert np.all((out["conditioning"] > 0) & (out["conditioning"] <= 1))
    force, moment = chk.platform_residual(c.data, out, c.q, c.qd, c.qdd)
    assert max(force, moment) < 1e-12


@pytest.mark.parametrize("name", NAMES)
def test_control_model_matches_the_reference(name: str) -> None:
    """J, J' q', the platform velocity, the efforts, M and c, forward dynamics, the regressor
    and the inertial parameters, through the public API (NumPy)."""
    c = _case(name)
    m, q, qd, qdd = c.model, c.q, c.qd, c.qdd
    a = c.robot.actuated
    qa_ref = np.stack([x[:, a - 1] for x in pr.inverse_kinematics(c.robot, q)], axis=1)
    qa = rpr3gen.actuator_coordinates(m, q)
    d = qa - qa_ref
    assert np.max(np.abs(chk.wrap(d) if c.robot.leg[a - 1] == "R" else d)) < 1e-13
    J = rpr3gen.actuator_jacobian(m, q)
    assert _rel(J, pr.actuator_jacobian(c.robot, q)) < 1e-12
    qa_ddot = np.einsum("nij,nj->ni", J, qdd) + rpr3gen.jacobian_rate(m, q, qd)
    assert _rel(qa_ddot, _stack(c.ref, f"qdd{a}")) < 1e-12
    qa_dot = _stack(c.ref, f"qd{a}")
    assert _rel(rpr3gen.platform_velocity(m, q, qa_dot), qd) < 1e-12
    tau = pr.efforts(c.ref)
    assert _rel(rpr3gen.actuator_efforts(m, q, qd, qdd), tau) < 1e-12
    M, bias = rpr3gen.task_space_dynamics(m, q, qd)
    M_ref, c_ref = pr.task_space(c.robot, q, qd)
    assert _rel(M, M_ref) < 1e-12
    assert _rel(bias, c_ref) < 1e-12
    assert np.all(np.linalg.eigvalsh(M) > 0)
    assert _rel(rpr3gen.forward_dynamics(m, q, qd, tau), qdd) < 1e-11
    values = chk.inertial_values(c.data)
    pi = rpr3gen.inertial_parameters(m)
    assert np.allclose(pi, [values[n] for n in rpr3gen.INERTIAL_PARAMETER_NAMES], 0, 1e-15)
    Y = rpr3gen.regressor(m, q, qd, qdd)
    assert _rel(Y @ pi + rpr3gen.payload_efforts(m, q), tau) < 1e-12


def _distance(a: np.ndarray, b: np.ndarray, rho: float) -> np.ndarray:
    return np.hypot(
        np.hypot(a[..., 0] - b[..., 0], a[..., 1] - b[..., 1]),
        rho * chk.wrap(a[..., 2] - b[..., 2]),
    )


@pytest.mark.parametrize("name", NAMES)
def test_assembly_modes_round_trip(name: str) -> None:
    """For poses of the motion: every mode of ``qa(q)`` maps back to ``qa``, the pose is one of
    them, their count is within the structure's bound, and every mode the reference finds by
    brute force (Levenberg-Marquardt from 96 starts) is one of them. The tracked forward
    kinematics (NumPy) from a reference near the pose returns it."""
    c = _case(name)
    m = c.model
    rho = rpr3gen.platform_radius(m)
    angle = c.robot.leg[c.robot.actuated - 1] == "R"
    for i in (0, 4, 8):
        qa = rpr3gen.actuator_coordinates(m, c.q[i])[0]
        modes = rpr3gen.assembly_modes(m, qa)
        assert 1 <= len(modes) <= m.structure.max_modes
        back = rpr3gen.actuator_coordinates(m, modes) - qa
        assert np.max(np.abs(chk.wrap(back) if angle else back)) < 1e-10
        assert np.min(_distance(modes, c.q[i], rho)) < 1e-10 * rho
        brute = pr.assembly_modes_bruteforce(c.robot, qa)
        for mode in brute:
            assert np.min(_distance(modes, mode, rho)) < 1e-9 * rho, f"missed {mode}"
        near = c.q[i] + np.array([0.002, -0.003, 0.01])
        tracked = rpr3gen.forward_kinematics(m, qa, near)[0]
        assert _distance(tracked, c.q[i], rho) < 1e-10 * rho


@pytest.mark.parametrize("name", NAMES)
def test_c_tracked_forward_kinematics(name: str, private_root) -> None:
    """The generated C's tracked forward kinematics from references near the poses of the motion
    (a few mm and 0.6 degree off) returns the poses, with the angle next to the reference's;
    ``forward_kinematics_jacobian`` returns them too, with the actuator Jacobian there, bit for
    bit ``actuator_coordinates_jacobian``'s."""
    c = _case(name)
    m = _c_model(name, private_root)
    rho = rpr3gen.platform_radius(m)
    qa = rpr3gen.actuator_coordinates(m, c.q, backend="c")
    rng = np.random.default_rng(5)
    near = c.q + rng.uniform(-1, 1, c.q.shape) * [0.003, 0.003, 0.01]
    near[:, 2] += 2 * np.pi  # the angle is unwrapped next to the reference's
    found = rpr3gen.forward_kinematics(m, qa, near, backend="c")
    assert np.max(_distance(found, c.q, rho)) < 1e-10 * rho
    assert np.max(np.abs(found[:, 2] - 2 * np.pi - c.q[:, 2])) < 1e-10
    (q, J), codes = rpr3gen.evaluate(m, "forward_kinematics_jacobian", (qa, near), backend="c")
    assert (codes == 0).all()
    assert np.array_equal(q, found)
    (_, expected), _ = rpr3gen.evaluate(m, "actuator_coordinates_jacobian", (found,), "c")
    assert np.array_equal(J, expected)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    """The largest difference of two stacks of rows, relative to each row's largest value."""
    a, b = a.reshape(len(a), -1), b.reshape(len(b), -1)
    return float(np.max(np.abs(a - b) / np.max(np.abs(b), axis=1, keepdims=True)))


@pytest.mark.parametrize("name", NAMES)
def test_actuator_coordinates_jacobian_is_both_functions(name: str, private_root) -> None:
    """``actuator_coordinates_jacobian`` gives ``actuator_coordinates``' and
    ``actuator_jacobian``'s values to round-off, in C and in NumPy (one elimination of common
    subexpressions over both may group a sum differently; measured: the same bits but for the C
    of two structures, prp1's qa 6.0e-16 and rpp2's J 5.8e-17 relative); its ``J`` is the
    central difference of its own ``qa`` (a check independent of the derivation's
    differentiation; measured 1.5e-11 to 5.9e-10 relative, steps of 1e-6 m and 1e-6 m / rho)."""
    c = _case(name)
    cm = _c_model(name, private_root)
    for model, backend in ((cm, "c"), (c.model, "numpy")):
        (qa, J), codes = rpr3gen.evaluate(model, "actuator_coordinates_jacobian", (c.q,), backend)
        assert (codes == 0).all()
        alone = rpr3gen.actuator_coordinates(model, c.q, backend=backend)
        J_alone = rpr3gen.actuator_jacobian(model, c.q, backend=backend)
        assert _relative(qa, alone) < 1e-14, backend
        assert _relative(J, J_alone) < 1e-14, backend
    (qa, J), _ = rpr3gen.evaluate(cm, "actuator_coordinates_jacobian", (c.q,), "c")
    rho = rpr3gen.platform_radius(cm)
    J = J.reshape(-1, 3, 3)
    difference = np.empty_like(J)
    for j, step in enumerate((1e-6, 1e-6, 1e-6 / rho)):
        h = np.zeros(3)
        h[j] = step
        (up, _), _ = rpr3gen.evaluate(cm, "actuator_coordinates_jacobian", (c.q + h,), "c")
        (down, _), _ = rpr3gen.evaluate(cm, "actuator_coordinates_jacobian", (c.q - h,), "c")
        difference[:, :, j] = (up - down) / (2 * step)
    # columns in (x, y, rho phi): the angle's column scaled by 1/rho
    scaled = np.array([1.0, 1.0, 1.0 / rho])
    assert _relative(difference * scaled, J * scaled) < 1e-7


def _inputs(c: Case, qa: np.ndarray) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(9)
    phi = c.q[:, 2]
    return {
        "q": c.q,
        "qd": c.qd,
        "qdd": c.qdd,
        "tau": pr.efforts(c.ref) * (1 + 0.1 * rng.normal(size=c.q.shape)),
        "qa": qa,
        "qa_dot": _stack(c.ref, f"qd{c.robot.actuated}"),
        "q_near": c.q + 0.002,
        "angle": np.column_stack([np.cos(phi), np.sin(phi)]),
    }


@pytest.mark.parametrize("name", NAMES)
def test_c_agrees_with_numpy_on_every_function(name: str, private_root) -> None:
    """Every generated function with a NumPy version, the same samples: equal to round-off,
    NaN in the same places."""
    c = _case(name)
    cm = _c_model(name, private_root)
    qa = rpr3gen.actuator_coordinates(c.model, c.q)
    inputs = _inputs(c, qa)
    variant = variants.load(c.model.structure)
    checked = []
    for fname, info in variant.functions.items():
        if info.numpy_function is None:
            continue
        args = [inputs[arg.name] for arg in info.inputs]
        ours, codes = rpr3gen.evaluate(c.model, fname, args, "numpy")
        theirs, c_codes = rpr3gen.evaluate(cm, fname, args, "c")
        assert np.array_equal(codes, c_codes), fname
        for a, b, arg in zip(ours, theirs, info.public_outputs, strict=True):
            assert np.array_equal(np.isnan(a), np.isnan(b)), fname
            # Per component, relative to its largest value or to a thousandth of the array's
            # (a coordinate that is round-off around zero).
            column = np.nanmax(np.abs(a), axis=0, initial=0.0)
            scale = np.maximum(column, 1e-3 * np.max(column))
            err = np.nanmax(np.abs(a - b) / np.where(scale > 0, scale, 1.0), initial=0.0)
            assert err < 1e-12, f"{fname}.{arg.name}: {err:.2e}"
        checked.append(fname)
    assert {"inverse_dynamics", "forward_dynamics", "assembly_modes", "regressor"} <= set(checked)


def _single_calls(model: Model, fname: str, args: list[np.ndarray]) -> list[np.ndarray]:
    """The C ABI's single-sample function, called sample by sample through ctypes."""
    variant = variants.load(model.structure, model.generated)
    info = variant.function(fname)
    entry = cbackend.library(variant).entries[fname]
    params = np.ascontiguousarray(model.vector(variant.param_names))
    n = args[0].shape[0]
    outs = [np.full((n, o.size), np.nan) for o in info.public_outputs]
    ptr = ctypes.c_void_p
    for k in range(n):
        ins = [np.ascontiguousarray(a[k], dtype=float) for a in args]
        row = [np.empty(o.size) for o in info.public_outputs]
        code = entry.single(ptr(params.ctypes.data), *(ptr(a.ctypes.data) for a in (*ins, *row)))
        if code == 0:
            for o, r in zip(outs, row, strict=True):
                o[k] = r
    return outs


@pytest.mark.parametrize("name", ["rrr-gallery", "rrr-random", "prr1", "rpr3"])
def test_c_single_call_equals_the_batch(
    name: str, private_root, request: pytest.FixtureRequest
) -> None:
    """``rpr3_<f>`` per sample gives the bits of the runtime's batch, ``rpr3_<f>_batch``, for
    every function (the tracked forward kinematics included); NumPy on one sample gives what it
    gives in a batch, to round-off. The gallery's 3-RRR with the optimised flags (where gcc's
    vectorisers run), the others on the suite's quick builds."""
    if name == "rrr-gallery":
        request.getfixturevalue("optimised_c_builds")
    c = _case(name)
    cm = _c_model(name, private_root)
    qa = rpr3gen.actuator_coordinates(c.model, c.q)
    inputs = _inputs(c, qa)
    variant = variants.load(cm.structure, cm.generated)
    for fname, info in variant.functions.items():
        args = [np.ascontiguousarray(inputs[arg.name]) for arg in info.inputs]
        batch, _ = rpr3gen.evaluate(cm, fname, args, "c")
        for a, b in zip(_single_calls(cm, fname, args), batch, strict=True):
            assert np.array_equal(a, b, equal_nan=True), fname
        if info.numpy_function is not None:
            whole, _ = rpr3gen.evaluate(c.model, fname, args, "numpy")
            for k in (0, len(c.q) - 1):
                one, _ = rpr3gen.evaluate(c.model, fname, [a[k] for a in args], "numpy")
                for a, b in zip(one, whole, strict=True):
                    np.testing.assert_allclose(a[0], b[k], rtol=1e-14, atol=1e-300)
    single = rpr3gen.inverse_dynamics(cm, c.q[3], c.qd[3], c.qdd[3], backend="c")
    whole = rpr3gen.inverse_dynamics(cm, c.q, c.qd, c.qdd, backend="c")
    for key, value in single.items():
        assert np.array_equal(value, whole[key][3:4]), key
    assert math.isfinite(float(single["tau_A"][0]))
