"""The CasADi bridge (rpr3gen.casadi, docs/bridges.md): every function the bridges offer of four
structures against the NumPy backend (a planar robot's forward kinematics, which NumPy does not
offer, against the poses it should find), the inverse dynamics' efforts against the
independent references, CasADi's own derivatives of them against central differences of the
references, the ``.casadi`` file's round trip, the C that ``Function.generate`` writes
compiled by gcc, and bad input.
"""

from __future__ import annotations

import shutil
import subprocess
import sys

import casadi
import numpy as np
import pytest

import rpr3gen
import rpr3gen.casadi as rc
from rpr3gen import bridge

try:
    from . import bridge_cases as bc
except ImportError:
    import bridge_cases as bc

RTOL = 1e-12  # of the output's largest |value|: the same program, another evaluation order
REFERENCE_RTOL = 1e-10  # the references solve each body's equations: a linear solve's round-off
FD_RTOL = 1e-6  # central differences with h = 1e-6: truncation and round-off ~1e-9


def _call(f: casadi.Function, params: np.ndarray, inputs: list[np.ndarray]) -> list[np.ndarray]:
    """``f`` on every sample: its outputs, (n, size) each."""
    rows = [f.call([params, *(a[s] for a in inputs)]) for s in range(len(inputs[0]))]
    return [np.array([np.asarray(r[k]).ravel() for r in rows]) for k in range(f.n_out())]


@pytest.mark.parametrize("name", bc.CASES)
def test_every_function_equals_the_numpy_backend(name: str) -> None:
    c = bc.case(name)
    variant = rpr3gen.manifest.load(c.model.structure.variant)
    params = rc.parameters(c.model)
    for function in bridge.names(variant):
        info = variant.function(function)
        f = rc.function(c.model, function)
        assert f.name_in() == ["params", *(a.name for a in info.inputs)]
        assert f.name_out() == [o.name for o in info.public_outputs]
        inputs = bc.inputs(c, info)
        want = bc.expected(c, function, inputs)
        tolerance = 1e-10 if function.startswith("forward_kinematics") else RTOL  # Newton's
        for got, expected in zip(_call(f, params, inputs), want, strict=True):
            bc.scale_close(got, expected, tolerance)


@pytest.mark.parametrize("name", bc.CASES)
def test_efforts_equal_the_reference(name: str) -> None:
    c = bc.case(name)
    f = rc.function(c.model, "inverse_dynamics")
    (out,) = _call(f, rc.parameters(c.model), [c.q, c.qd, c.qdd])
    got = out[:, bc.efforts_rows(c.model)]
    bc.scale_close(got, c.reference_efforts(c.q, c.qd, c.qdd), REFERENCE_RTOL)


@pytest.mark.parametrize("name", bc.CASES)
def test_casadi_derivatives_equal_differences_of_the_reference(name: str) -> None:
    """``casadi.jacobian`` of the efforts by q, qd and qdd, in CasADi's own AD, against central
    differences of the independent reference at one sample."""
    c = bc.case(name)
    f = rc.function(c.model, "inverse_dynamics")
    rows = bc.efforts_rows(c.model)
    params = casadi.SX.sym("p", f.size1_in(0))
    args = [casadi.SX.sym(a, f.size1_in(k + 1)) for k, a in enumerate(("q", "qd", "qdd"))]
    tau = f(params, *args)[rows]
    jac = casadi.Function("dtau", [params, *args], [casadi.jacobian(tau, a) for a in args])
    point = [c.q[1], c.qd[1], c.qdd[1]]
    found = jac(rc.parameters(c.model), *point)
    for k in range(3):

        def efforts(x: np.ndarray, k: int = k) -> np.ndarray:
            values = [p[np.newaxis] for p in point]
            values[k] = x[np.newaxis]
            return c.reference_efforts(*values)[0]

        want = bc.central_differences(efforts, point[k])
        bc.scale_close(np.asarray(found[k]), want, FD_RTOL)


def test_composed_forward_dynamics_inverts_the_inverse_dynamics() -> None:
    """A spatial robot's composed forward dynamics (``casadi.solve`` of ``T q'' = tau -
    tau0``) gives back the accelerations whose efforts it is given."""
    c = bc.case("rss2_1")
    params = rc.parameters(c.model)
    efforts = rc.function(c.model, "actuator_efforts")
    forward = rc.function(c.model, "forward_dynamics")
    for s in range(len(c.q)):
        tau = efforts(params, c.q[s], c.qd[s], c.qdd[s])
        qdd = forward(params, c.q[s], c.qd[s], tau)
        bc.scale_close(np.asarray(qdd).ravel(), c.qdd[s], 1e-11)


def test_save_and_load(tmp_path) -> None:
    c = bc.case("rss2_1")
    f = rc.function(c.model, "forward_dynamics")
    path = tmp_path / "forward_dynamics.casadi"
    f.save(str(path))
    g = casadi.Function.load(str(path))
    assert g.name_in() == f.name_in()
    assert g.name_out() == f.name_out()
    args = [rc.parameters(c.model), c.q[0], c.qd[0], c.qdd[0]]
    np.testing.assert_array_equal(np.asarray(g(*args)), np.asarray(f(*args)))


@pytest.mark.parametrize(("name", "function"), [("rrr_1", "inverse_dynamics"),
                                                ("rss2_1", "forward_dynamics")])  # fmt: skip
def test_generated_c_compiles(tmp_path, name: str, function: str) -> None:
    """``Function.generate`` writes C that gcc compiles without an error (into an object)."""
    f = rc.function(bc.case(name).model, function)
    source = f.generate(f"{function}.c", {"with_header": True})
    shutil.move(source, tmp_path / source)
    shutil.move(f"{function}.h", tmp_path / f"{function}.h")
    compiler = shutil.which("gcc") or shutil.which("cc")
    assert compiler is not None
    result = subprocess.run(
        [compiler, "-std=c99", "-c", "-O0", f"{function}.c", "-o", f"{function}.o"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert (tmp_path / f"{function}.o").stat().st_size > 0


def test_forward_kinematics_is_newton_from_near() -> None:
    """The bridges' forward kinematics (fixed Newton steps) finds the pose of the actuator
    coordinates from a start near it; a planar robot's Jacobian output is J at that pose."""
    c = bc.case("rrr_1")
    params = rc.parameters(c.model)
    qa = rc.function(c.model, "actuator_coordinates")(params, c.q[0])
    fk = rc.function(c.model, "forward_kinematics_jacobian")
    q, J = fk(params, qa, c.q[0] + 0.01)
    bc.scale_close(np.asarray(q).ravel(), c.q[0], 1e-12)
    J_at = rc.function(c.model, "actuator_jacobian")(params, c.q[0])
    bc.scale_close(np.asarray(J).ravel(), np.asarray(J_at).ravel(), 1e-9)


def test_parameters_are_the_models_numbers() -> None:
    model = rpr3gen.load_model()
    p = rc.parameters(model)
    assert p.dtype == np.float64
    assert p.tolist() == [model.params[n] for n in rpr3gen.manifest.load("revolute").param_names]


def test_unknown_function_is_one_error() -> None:
    with pytest.raises(rpr3gen.InputError, match=r"no function 'inverse_dynamic'.*did you mean"):
        rc.function(rpr3gen.load_model(), "inverse_dynamic")


def test_wrong_model_type_is_one_error() -> None:
    with pytest.raises(rpr3gen.InputTypeError, match="model"):
        rc.function("models/paper.toml", "inverse_dynamics")  # type: ignore[arg-type]
    with pytest.raises(rpr3gen.InputTypeError, match="name"):
        rc.function(rpr3gen.load_model(), 3)  # type: ignore[arg-type]
    with pytest.raises(rpr3gen.InputTypeError, match="model"):
        rc.parameters(None)  # type: ignore[arg-type]


def test_missing_casadi_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "casadi", None)  # import casadi now raises ImportError
    monkeypatch.setattr(rc, "_BUILT", {})
    with pytest.raises(rpr3gen.SetupError, match=r"pip install 'rpr3gen\[casadi\]'"):
        rc.function(rpr3gen.load_model(), "inverse_dynamics")
