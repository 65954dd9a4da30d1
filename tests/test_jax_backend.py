"""The JAX backend (rpr3gen.jax, ``backend="jax"``; docs/bridges.md): the usual calls on it
against the NumPy backend, with the same refusals (NaN rows, the same codes), the pure
functions under ``jit``, ``vmap``, ``grad`` and ``jacfwd`` (against central differences of the
independent references), and bad input.

JAX compiles each function once per padded length (about a second for a planar robot's, a few
for a Delta's), so each structure is tested on a few functions: the planar 3-RRR on its dynamics
and kinematics, the Delta on a composed function and its derivatives, the hexapod on one.
"""

from __future__ import annotations

import sys

import jax
import numpy as np
import pytest

import rpr3gen
import rpr3gen.jax as rj
from rpr3gen import bridge

try:
    from . import bridge_cases as bc
except ImportError:
    import bridge_cases as bc

RTOL = 1e-12
FD_RTOL = 1e-6

USUAL = [
    ("revolute", "inverse_dynamics"),
    ("rrr_1", "inverse_dynamics"),
    ("rrr_1", "forward_dynamics"),
    ("rrr_1", "actuator_coordinates_jacobian"),
    ("rss2_1", "actuator_efforts"),  # composed from the inverse dynamics, as composed.py
    ("ups_2", "actuator_coordinates_jacobian"),
]


@pytest.mark.parametrize(("name", "function"), USUAL)
def test_usual_calls_equal_the_numpy_backend(name: str, function: str) -> None:
    c = bc.case(name)
    inputs = bc.inputs(c, _info(c, function))
    got, codes = rpr3gen.evaluate(c.model, function, inputs, backend="jax")
    assert not codes.any()
    for g, w in zip(got, bc.expected(c, function, inputs), strict=True):
        bc.scale_close(g, w, RTOL)


def _info(c: bc.Case, function: str) -> rpr3gen.manifest.FunctionInfo:
    return rpr3gen.manifest.load(c.model.structure.variant).function(function)


def test_inverse_dynamics_call_on_jax() -> None:
    c = bc.case("revolute")
    got = rpr3gen.inverse_dynamics(c.model, c.q, c.qd, c.qdd, backend="jax")
    want = rpr3gen.inverse_dynamics(c.model, c.q, c.qd, c.qdd)
    assert list(got) == list(want)
    for key, value in want.items():
        bc.scale_close(got[key], value, RTOL)


def _refused_rows(c: bc.Case) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The case's motion with a non-finite pose and a pose out of reach added."""
    q = np.vstack([c.q, c.q[:1], c.q[:1]])
    q[-2, 0] = np.nan
    q[-1, 0] = 10.0  # metres: no leg reaches
    extend = [np.vstack([a, a[:1], a[:1]]) for a in (c.qd, c.qdd)]
    return q, *extend


@pytest.mark.parametrize(("name", "function"), [("rrr_1", "inverse_dynamics"),
                                                ("rss2_1", "actuator_efforts")])  # fmt: skip
def test_refusals_are_the_numpy_backends(name: str, function: str) -> None:
    """A refused sample is a NaN row with the NumPy backend's code: the runtime's checks
    after a generated function, the composition's guards for a composed one."""
    c = bc.case(name)
    inputs = list(_refused_rows(c))
    got, codes = rpr3gen.evaluate(c.model, function, inputs, backend="jax")
    want, want_codes = rpr3gen.evaluate(c.model, function, inputs)
    np.testing.assert_array_equal(codes, want_codes)
    assert (codes[-2:] != 0).all()
    assert not codes[:-2].any()
    for g, w in zip(got, want, strict=True):
        assert np.isnan(g[-2:]).all()
        bc.scale_close(g[:-2], w[:-2], RTOL)


@pytest.mark.slow
def test_pure_function_jit_vmap_and_eager_agree() -> None:
    c = bc.case("rrr_1")
    g = rj.function(c.model, "inverse_dynamics")
    params = rj.parameters(c.model)
    jitted = jax.jit(g, compiler_options=rj.COMPILER_OPTIONS)
    one = np.asarray(jitted(params, c.q[0], c.qd[0], c.qdd[0]))
    mapped = jax.jit(jax.vmap(g, in_axes=(None, 0, 0, 0)), compiler_options=rj.COMPILER_OPTIONS)
    many = np.asarray(mapped(params, c.q, c.qd, c.qdd))
    eager = np.asarray(g(params, c.q[0], c.qd[0], c.qdd[0]))
    np.testing.assert_allclose(many[0], one, rtol=0, atol=1e-13 * np.abs(one).max())
    np.testing.assert_allclose(eager, one, rtol=0, atol=1e-13 * np.abs(one).max())
    (want,), _ = rpr3gen.evaluate(c.model, "inverse_dynamics", [c.q, c.qd, c.qdd])
    bc.scale_close(many, want, RTOL)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["rrr_1", "rss2_1"])
def test_jacfwd_equals_differences_of_the_reference(name: str) -> None:
    """``jax.jacfwd`` of the efforts by q, qd and qdd against central differences of the
    independent reference; ``jax.grad`` of their sum is the jacobian's column sums."""
    c = bc.case(name)
    g = rj.function(c.model, "inverse_dynamics")
    rows = np.array(bc.efforts_rows(c.model))
    params = rj.parameters(c.model)
    point = [c.q[1], c.qd[1], c.qdd[1]]

    def efforts(q, qd, qdd):
        return g(params, q, qd, qdd)[rows]

    jacobian = jax.jit(jax.jacfwd(efforts, argnums=(0, 1, 2)), compiler_options=rj.COMPILER_OPTIONS)
    found = jacobian(*point)
    for k in range(3):

        def reference(x: np.ndarray, k: int = k) -> np.ndarray:
            values = [p[np.newaxis] for p in point]
            values[k] = x[np.newaxis]
            return c.reference_efforts(*values)[0]

        bc.scale_close(np.asarray(found[k]), bc.central_differences(reference, point[k]), FD_RTOL)
    if name == "rrr_1":
        gradient = jax.jit(
            jax.grad(lambda q: efforts(q, point[1], point[2]).sum()),
            compiler_options=rj.COMPILER_OPTIONS,
        )(point[0])
        bc.scale_close(np.asarray(gradient), np.asarray(found[0]).sum(axis=0), 1e-12)


def test_unknown_function_and_wrong_types_are_one_error() -> None:
    model = rpr3gen.load_model()
    with pytest.raises(rpr3gen.InputError, match=r"no function 'forward_dynamic'.*did you mean"):
        rj.function(model, "forward_dynamic")
    with pytest.raises(rpr3gen.InputTypeError, match="model"):
        rj.function({"name": "x"}, "inverse_dynamics")  # type: ignore[arg-type]
    with pytest.raises(rpr3gen.InputTypeError, match="model"):
        rj.parameters(3)  # type: ignore[arg-type]
    with pytest.raises(rpr3gen.InputError, match="backend"):
        rpr3gen.inverse_dynamics(model, np.zeros(3), np.zeros(3), np.zeros(3), backend="jaxx")


def test_missing_jax_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "jax", None)  # import jax now raises ImportError
    with pytest.raises(rpr3gen.SetupError, match=r"pip install 'rpr3gen\[jax\]'"):
        rj.function(rpr3gen.load_model(), "inverse_dynamics")


def test_float64_is_on() -> None:
    rj.function(rpr3gen.load_model(), "actuator_coordinates")
    assert jax.config.read("jax_enable_x64")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["rrr_1", "rss2_1"])
def test_every_function_equals_the_numpy_backend(name: str) -> None:
    """Every function the bridges offer, as a pure function mapped over the samples, run op by
    op (``jax.disable_jit``: the values are the compiled ones, within round-off, without
    compiling each function; a spatial robot's graph functions are the CasADi test's, its
    compositions, which map calls with ``vmap`` and solve with JAX's, are tested here)."""
    c = bc.case(name)
    variant = rpr3gen.manifest.load(c.model.structure.variant)
    params = rj.parameters(c.model)
    for function in bridge.names(variant):
        if c.model.structure.spatial and variant.function(function).numpy_function:
            continue
        info = variant.function(function)
        inputs = bc.inputs(c, info)
        g = rj.function(c.model, function)
        with jax.disable_jit():
            found = jax.vmap(g, in_axes=(None,) + (0,) * len(inputs))(params, *inputs)
        found = found if isinstance(found, tuple) else (found,)
        tolerance = 1e-10 if function.startswith("forward_kinematics") else RTOL
        for got, want in zip(found, bc.expected(c, function, inputs), strict=True):
            bc.scale_close(np.asarray(got), want, tolerance)
