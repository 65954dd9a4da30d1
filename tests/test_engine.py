"""The generator engine: a new function is one registry entry, and every backend agrees on codes.

A toy function (the three leg lengths of a pose) is added to a temporary registry, rendered
into a temporary folder, compiled and imported there, and called through the runtime's
evaluators by name: nothing outside the registry entry below is written for it.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from rpr3gen_derive.codegen import Check, Component, FunctionSpec, Output, Program
from rpr3gen_derive.codegen.files import write_files
from rpr3gen_derive.planar import generate, paper, registry, structures
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.registry.arguments import POSE

import rpr3gen
from rpr3gen import manifest
from rpr3gen.evaluators import evaluator

ACTUATIONS = ("revolute", "prismatic")
#: The paper's two variants, by actuation.
S = {a: structures.from_variant(a) for a in ACTUATIONS}
#: The registry's functions kept beside the toy one: the toy's variant is rendered in this
#: process, and the whole registry (the committed variants' functions) takes 14 s.
KEPT = {name: registry.FUNCTIONS[name] for name in ("inverse_dynamics", "actuator_coordinates")}


def leg_lengths(structure: structures.Structure) -> FunctionSpec:
    """Toy spec: |A1 A3| of each leg at the pose q (eq. 5), and its smallest value."""
    prog = Program()
    cos_phi = prog.define("cos_phi", sp.cos(syms.phi), "pose")
    sin_phi = prog.define("sin_phi", sp.sin(syms.phi), "pose")
    lengths = []
    for leg in syms.LEGS:
        p, a1 = paper.platform_joint(leg), paper.base_pivot(leg)
        dx = syms.x + cos_phi * p[0] - sin_phi * p[1] - a1[0]
        dy = syms.y + sin_phi * p[0] + cos_phi * p[1] - a1[1]
        lengths.append(prog.define(f"L_{leg}", sp.sqrt(dx**2 + dy**2), "pose"))
    return FunctionSpec(
        name="leg_lengths",
        doc="Leg lengths |A1 A3| at the platform pose q (toy function of the engine's test).",
        inputs=(POSE,),
        outputs=(
            Output(
                "lengths",
                tuple(lengths),
                tuple(Component(f"L_{leg}", "m", f"|{leg}1 {leg}3|") for leg in syms.LEGS),
                "leg lengths",
            ),
        ),
        program=prog,
        checks=(
            Check("inputs_not_finite", "NOT_FINITE"),
            # a value tested, not returned: the engine keeps it inside the C (a hidden output)
            Check(
                "below",
                "SINGULAR",
                threshold="MIN_REACH",
                guard=(
                    "reach",
                    (sp.Min(*lengths) - paper.params["l2"]) / paper.params["l0"],
                ),
            ),
        ),
    )


@pytest.fixture(scope="module")
def toy_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    functions = {**KEPT, "leg_lengths": leg_lengths}
    out = tmp_path_factory.mktemp("generated")
    write_files(out, generate.render(tuple(S.values()), functions=functions))
    return out


def _model(actuation: str, folder: Path | None = None) -> rpr3gen.Model:
    paper = rpr3gen.load_model()
    return dataclasses.replace(
        paper, actuation=actuation, generated=None if folder is None else str(folder)
    )


def _reference_lengths(model: rpr3gen.Model, q: np.ndarray) -> np.ndarray:
    p = model.params
    c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
    columns = []
    for leg in "ABC":
        x3 = q[:, 0] + c * p[f"x{leg}3"] - s * p[f"y{leg}3"]
        y3 = q[:, 1] + s * p[f"x{leg}3"] + c * p[f"y{leg}3"]
        columns.append(np.hypot(x3 - p[f"x{leg}1"], y3 - p[f"y{leg}1"]))
    return np.stack(columns, axis=1)


@pytest.mark.usefixtures("quick_c_builds")
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_a_toy_spec_is_rendered_compiled_and_called_by_name(
    toy_folder: Path, actuation: str
) -> None:
    assert "leg_lengths" not in registry.FUNCTIONS  # the temporary registry only
    variant = manifest.load(actuation, toy_folder)
    assert set(variant.functions) == {*KEPT, "leg_lengths"}
    header = variant.path("c_header").read_text()
    assert "int rpr3_leg_lengths(const double *params, const double q[3], double lengths[3]);" in (
        header
    )
    assert [o.name for o in variant.function("leg_lengths").outputs] == ["lengths", "guards"]
    model = _model(actuation, toy_folder)
    rng = np.random.default_rng(7)
    q = rng.uniform([-0.03, -0.03, -0.1], [0.03, 0.03, 0.1], size=(40, 3))
    q[3, 1] = np.nan
    q[5] = (0.0, -0.3, 0.0)  # A3 on A1: the guard (reach) refuses it
    results = {}
    for backend in ("numpy", "c"):
        (lengths,), codes = rpr3gen.evaluate(model, "leg_lengths", (q,), backend=backend)
        results[backend] = lengths
        assert codes[3] == variant.return_codes["NOT_FINITE"]
        assert codes[5] == variant.return_codes["SINGULAR"]
        assert np.count_nonzero(codes) == 2
        assert np.isnan(lengths[[3, 5]]).all()
    np.testing.assert_allclose(results["c"], results["numpy"], rtol=1e-14, atol=0)
    ok = np.isfinite(results["numpy"]).all(axis=1)
    assert ok.sum() == len(q) - 2
    np.testing.assert_allclose(
        results["numpy"][ok], _reference_lengths(model, q[ok]), rtol=1e-13, atol=0
    )
    # The inverse dynamics of the same folder are the installed ones.
    packaged = rpr3gen.inverse_dynamics(
        _model(actuation), q[ok], np.zeros((ok.sum(), 3)), np.zeros((ok.sum(), 3))
    )
    here = rpr3gen.inverse_dynamics(model, q[ok], np.zeros((ok.sum(), 3)), np.zeros((ok.sum(), 3)))
    for name in rpr3gen.OUTPUT_NAMES:
        assert here[name].tobytes() == packaged[name].tobytes()


@pytest.mark.usefixtures("quick_c_builds")
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_toy_single_call_matches_batch(toy_folder: Path, actuation: str) -> None:
    model = _model(actuation, toy_folder)
    q = np.array([[0.01, -0.02, 0.1], [0.0, 0.0, 0.0]])
    (batch,), _ = rpr3gen.evaluate(model, "leg_lengths", (q,), backend="c")
    for backend in ("c", "numpy"):
        ev = rpr3gen.SampleEvaluator(model, backend=backend, function="leg_lengths")
        for i in range(len(q)):
            ev.q[:] = q[i]
            assert ev() == 0
            np.testing.assert_allclose(ev.lengths, batch[i], rtol=1e-15, atol=0)
        ev.q[:] = (0.0, np.inf, 0.0)
        before = ev.lengths.copy()
        assert ev() == 1
        assert np.array_equal(ev.lengths, before)


def _raw_conditioning(model: rpr3gen.Model, q: np.ndarray) -> np.ndarray:
    """The generated NumPy's conditioning output, before any failure policy is applied."""
    variant = manifest.load(model.actuation)
    info = variant.function("inverse_dynamics")
    ev = evaluator(variant, "numpy")
    zero = np.zeros_like(q)
    (out,) = ev.allocate(info, len(q))
    ev.run(info, model.vector(variant.param_names), [q, zero, zero], [out])
    return out[:, info.outputs[0].names.index("conditioning")]


def _nearly_singular_pose(model: rpr3gen.Model, floor: float) -> np.ndarray:
    """A pose with 0 < conditioning < floor: golden-section search along x across a parallel
    singularity of the paper robot (near x = -0.158, y = 0.432, phi = 0.7)."""
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    lo, hi = -0.17, -0.15

    def cond(x: float) -> float:
        return float(_raw_conditioning(model, np.array([[x, 0.432, 0.7]]))[0])

    for _ in range(200):
        a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        if cond(a) < cond(b):
            hi = b
        else:
            lo = a
        x = (lo + hi) / 2
        if 0.0 < cond(x) < floor:
            return np.array([x, 0.432, 0.7])
    raise AssertionError("no pose with 0 < conditioning < floor found")


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_numpy_and_c_agree_on_every_return_code(actuation: str) -> None:
    model = _model(actuation)
    variant = manifest.load(actuation)
    floor = variant.thresholds["MIN_CONDITIONING"]
    p = model.params
    nearly = _nearly_singular_pose(model, floor)
    assert 0.0 < _raw_conditioning(model, nearly[np.newaxis])[0] < floor
    q = np.array(
        [
            [0.01, -0.02, 0.1],  # ok
            [0.0, np.nan, 0.0],  # an input not finite
            [p["xB1"] - p["xB3"], p["yB1"] - p["yB3"], 0.0],  # leg B of zero length
            nearly,  # 0 < conditioning < MIN_CONDITIONING
        ]
    )
    expected = [0, variant.return_codes["NOT_FINITE"], *[variant.return_codes["SINGULAR"]] * 2]
    zero = np.zeros_like(q)
    for backend in ("numpy", "c"):
        _, codes = rpr3gen.evaluate(model, "inverse_dynamics", (q, zero, zero), backend=backend)
        assert codes.tolist() == expected, backend
        ev = rpr3gen.SampleEvaluator(model, backend=backend)
        single = []
        for i in range(len(q)):
            ev.q[:], ev.qd[:], ev.qdd[:] = q[i], zero[i], zero[i]
            single.append(ev())
        assert single == expected, backend


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_the_codes_short_cut_gives_the_per_sample_codes(
    actuation: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # failures.return_codes first asks whether any sample failed (one reduction per array) and
    # computes the per-sample codes only then, and the NumPy evaluator answers the same question
    # from the sums of the output rows: every kind of failure, alone in its block, must reach
    # the per-sample codes, and give what the per-sample pass alone gives.
    from rpr3gen import failures

    model = _model(actuation)
    variant = manifest.load(actuation)
    info = variant.function("inverse_dynamics")
    p = model.params
    ok = np.array([0.01, -0.02, 0.1])
    cases = {
        "none": (ok, 0.0, None),
        "an input not finite": (ok, np.inf, variant.return_codes["NOT_FINITE"]),
        "a leg of zero length": (
            np.array([p["xB1"] - p["xB3"], p["yB1"] - p["yB3"], 0.0]), 0.0,
            variant.return_codes["SINGULAR"],
        ),
        "an output overflowing": (ok, 1e308, variant.return_codes["SINGULAR"]),
    }  # fmt: skip
    for name, (pose, acceleration, code) in cases.items():
        q = np.tile(ok, (6, 1))
        qdd = np.zeros_like(q)
        q[4], qdd[4] = pose, acceleration
        ev = evaluator(variant, "numpy")
        outs = ev.allocate(info, len(q))
        ins = [q, np.zeros_like(q), qdd]
        # The evaluator's own short cut (the output rows' sums the generated code takes while
        # they are in cache): 0 only when no sample failed, else unknown (None).
        returned = ev.run(info, model.vector(variant.param_names), ins, outs)
        assert returned == (0 if code is None else None), name
        got = failures.return_codes(info, ins, outs)
        with monkeypatch.context() as patch:
            patch.setattr(failures, "none_failed", lambda *args: False)
            per_sample = failures.return_codes(info, ins, outs)
        assert got.tolist() == per_sample.tolist(), name
        assert got.tolist() == [0] * 4 + [code or 0] + [0], name


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_a_module_without_output_sums_gets_the_same_codes(
    actuation: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A NumPy module generated before the ``sums`` argument has no OUTPUT_ROWS: the evaluator
    # then calls it without sums and leaves the codes to the per-sample checks, which must give
    # what the short cut gives (here on a block with a failed sample and one without).
    model = _model(actuation)
    variant = manifest.load(actuation)
    p = model.params
    q = np.tile([0.01, -0.02, 0.1], (8, 1))
    q[5] = [p["xB1"] - p["xB3"], p["yB1"] - p["yB3"], 0.0]  # leg B of zero length: singular
    zeros = np.zeros_like(q)
    ev = evaluator(variant, "numpy")
    info = variant.function("inverse_dynamics")
    for n in (8, 4):
        ins = [q[:n], zeros[:n], zeros[:n]]
        with_sums = rpr3gen.evaluate(model, "inverse_dynamics", ins)
        with monkeypatch.context() as patch:
            patch.delattr(ev.module, "OUTPUT_ROWS")
            outs = ev.allocate(info, n)
            assert ev.run(info, model.vector(variant.param_names), ins, outs) is None
            without = rpr3gen.evaluate(model, "inverse_dynamics", ins)
        want = [0] * 5 + [variant.return_codes["SINGULAR"]] + [0] * 2
        assert with_sums[1].tolist() == without[1].tolist() == want[:n]
        np.testing.assert_array_equal(with_sums[0][0], without[0][0])


def test_a_modules_legs_are_distinct_capital_letters() -> None:
    """``ModuleSpec.legs`` names the legs the engine runs side by side: the planar modules'
    ``ABC``, a hexapod's ``ABCDEF``; none (the default) for a module of no legs."""
    from rpr3gen_derive.codegen.spec import Argument, ModuleSpec, ReturnCode

    x = sp.Symbol("x", real=True)
    params = Argument("params", (x,), (Component("x"),), "params", "param_names")
    ok = (ReturnCode("OK", 0, "ok"),)
    assert registry.module(S["revolute"], functions={}).legs == "ABC"
    assert ModuleSpec("p", "v", "doc", params, (), ok).legs == ""
    assert ModuleSpec("p", "v", "doc", params, (), ok, legs="ABCDEF").legs == "ABCDEF"
    for bad in ("ABA", "AbC", "A1"):
        with pytest.raises(ValueError, match="distinct capital letters"):
            ModuleSpec("p", "v", "doc", params, (), ok, legs=bad)


def test_affine_parts_are_the_value_at_zero_and_the_derivative() -> None:
    """``tangent.affine_parts`` on a toy program affine in ``a1, a2`` and not in ``x``: the
    values at ``a = 0`` and the tangents are the expanded outputs' own; a statement that does
    not read ``a`` is kept once, under its name, and a tangent that is an atom (zero, a symbol)
    is no statement."""
    from rpr3gen_derive.codegen.tangent import affine_parts

    x, a1, a2 = sp.symbols("x a1 a2", real=True)
    prog = Program()
    s = prog.define("s", sp.sin(x) * x, "kinematics")
    u = prog.define("u", s * a1 + x**2, "dynamics")
    v = prog.define("v", u * sp.cos(x) + s * a2 - a1, "dynamics")
    w = prog.define("w", v / s + u, "dynamics")
    outputs = [w, v * x]
    out, values, tangents = affine_parts(prog, outputs, [a1, a2], extra=[s + 1])
    names = [str(asg.symbol) for asg in out.assignments]
    # u's tangents are s and 0, v's second s, w's second 1: atoms, not statements
    assert names == ["s", "u", "v", "v_t0", "w", "w_t0"]
    zero = {a1: 0, a2: 0}
    for i, expr in enumerate(outputs):
        full = prog.expand(expr)
        assert sp.simplify(out.expand(values[i]) - full.xreplace(zero)) == 0
        for j, a in enumerate((a1, a2)):
            assert sp.simplify(out.expand(tangents[i][j]) - sp.diff(full, a)) == 0
    assert sp.simplify(out.expand(values[2]) - (sp.sin(x) * x + 1)) == 0
