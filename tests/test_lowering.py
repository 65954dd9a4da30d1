"""The NumPy lowering (derive/codegen/backends/python/lowering.py) against SymPy, by branch."""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp
from rpr3gen_derive.codegen.backends.python.lowering import lower_numpy
from rpr3gen_derive.codegen.cse import StraightLine
from rpr3gen_derive.codegen.functions import wrap_angle

a, b = sp.symbols("a b", real=True)  # per-sample inputs
k, m = sp.symbols("k m", real=True, positive=True)  # parameters
t1, t2, t3 = sp.symbols("t1 t2 t3", real=True)  # named intermediates

CASES = {
    "negative first term": -a * b - a + 3,
    "subtractions and a scalar": a - b * k + m * a - 2,
    "division by a product": k * a / (b**2 + 1) / (a**2 + 2),
    "reciprocal and square": 1 / (a**2 + 1) + b**2,
    "square root and its inverse": sp.sqrt(a**2 + 1) - 1 / sp.sqrt(b**2 + 2),
    "cube and general power": a**3 + (b**2 + 1) ** sp.Rational(3, 2),
    "negative integer powers alone": (a**2 + 1) ** -2 + (b**2 + 2) ** -3,
    "functions": sp.cos(a) * sp.sin(b) + sp.atan2(a, b) - sp.Abs(a - b),
    "wrapped angle": wrap_angle(5 * a - k),
    "parameters only, inside": (k + m**2) * a + sp.cos(k),
    "lone negation": -a,
    "minimum of three": sp.Min(a, b * k, a - b),
}


def _run(code: StraightLine, values: dict[sp.Symbol, np.ndarray], n: int) -> np.ndarray:
    rows = {name: f"out[{i}]" for i, (name, _) in enumerate(code.outputs)}
    constants: dict[str, str] = {}
    lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, rows, constants)
    out = np.full((len(code.outputs), n), np.nan)
    scope = {"numpy": np, "out": out, "a": values[a], "b": values[b], "k": values[k],
             "m": values[m], **_module_names(lowered, constants)}  # fmt: skip
    work = np.empty((max(lowered.buffers, 1), n))
    for i in range(lowered.buffers):
        scope[f"w{i}"] = work[i]
    exec("\n".join(lowered.scalar_lines + lowered.vector_lines), scope)
    return out


@pytest.mark.parametrize("name", CASES)
def test_each_form_evaluates_like_sympy(name: str) -> None:
    rng = np.random.default_rng(1)
    n = 64
    values = {a: rng.uniform(-2, 2, n), b: rng.uniform(-2, 2, n), k: 0.7, m: 1.3}
    expr = CASES[name]
    code = StraightLine(assignments=((t1, expr),), outputs=(("y", t1),), ops_before=0, ops_after=0)
    want = sp.lambdify((a, b, k, m), expr.replace(wrap_angle, _wrap), "numpy")(
        values[a], values[b], values[k], values[m]
    )
    np.testing.assert_allclose(_run(code, values, n)[0], want, rtol=1e-13, atol=1e-13)


def test_integer_powers_are_products_not_numpy_power() -> None:
    # numpy.power costs ~15 ns a value, a product or a division ~0.4: an integer exponent, of
    # either sign, is lowered to multiplications and one division (the C's 1.0/(x*x) too).
    for expr in ((a**2 + 1) ** -2, (b**2 + 2) ** -3, (a - b) ** 4, 1 / (a + 1) ** 5):
        code = StraightLine(assignments=((t1, expr),), outputs=(("y", t1),), ops_before=0,
                            ops_after=0)  # fmt: skip
        lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, {"y": "out[0]"}, {})
        assert "power" not in lowered.ufuncs, (expr, lowered.vector_lines)
        assert _calls(lowered).count("_divide") <= 1, (expr, lowered.vector_lines)


def _module_names(lowered, constants: dict[str, str]) -> dict[str, object]:
    """What the module template defines for the lowered lines: the ufuncs by name
    (``_multiply``) and the number constants as 0-d arrays (``_K0``)."""
    names: dict[str, object] = {f"_{ufunc}": getattr(np, ufunc) for ufunc in lowered.ufuncs}
    names["sums"] = np.full(lowered.sums, np.nan)  # the function's ``sums`` argument
    if lowered.atan2:
        names["_atan2"] = _generated_numpy()._atan2
    names.update({name: np.array(eval(text), np.float64) for text, name in constants.items()})
    return names


def _calls(lowered) -> list[str]:
    """The ufunc of each vector line that is a call (not a scalar operand's 0-d array)."""
    return [line.split("(")[0] for line in lowered.vector_lines if " = " not in line]


def _wrap(x: sp.Expr) -> sp.Expr:
    return x - 2 * sp.pi * sp.floor(x / (2 * sp.pi) + sp.Rational(1, 2))


def test_buffers_are_reused_and_aliases_and_constants_are_written() -> None:
    rng = np.random.default_rng(2)
    n = 16
    values = {a: rng.uniform(-1, 1, n), b: rng.uniform(-1, 1, n), k: 2.0, m: 3.0}
    code = StraightLine(
        assignments=((t1, a * b + k), (t2, t1 * a - b), (t3, t2 / t1)),
        outputs=(("first", t1), ("ratio", t3), ("zero", sp.Integer(0)), ("again", t2)),
        ops_before=0,
        ops_after=0,
    )
    out = _run(code, values, n)
    x1 = values[a] * values[b] + 2.0
    x2 = x1 * values[a] - values[b]
    np.testing.assert_allclose(out[0], x1, rtol=1e-15)
    np.testing.assert_allclose(out[1], x2 / x1, rtol=1e-15)
    np.testing.assert_array_equal(out[2], 0.0)
    np.testing.assert_allclose(out[3], x2, rtol=1e-15)
    rows = {name: f"out[{i}]" for i, (name, _) in enumerate(code.outputs)}
    lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, rows)
    assert lowered.buffers <= 3  # three live values at most, never one buffer per operation


def test_each_output_row_is_summed_after_its_last_use() -> None:
    # The runtime's failure checks read the outputs' finiteness from these sums, taken while
    # each row is in cache: a row summed before its last write (here "first" is t1's row and
    # t1 is still read by t2 and t3 after it is final) would miss what that write puts in it.
    rng = np.random.default_rng(8)
    n = 16
    values = {a: rng.uniform(-1, 1, n), b: rng.uniform(1, 2, n), k: 2.0, m: 3.0}
    code = StraightLine(
        assignments=((t1, a * b + k), (t2, t1 * a - b), (t3, t2 / t1)),
        outputs=(("first", t1), ("ratio", t3), ("zero", sp.Integer(0)), ("again", t2)),
        ops_before=0,
        ops_after=0,
    )
    rows = {name: f"out[{i}]" for i, (name, _) in enumerate(code.outputs)}
    constants: dict[str, str] = {}
    lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, rows, constants)
    assert lowered.sums == 4
    lines = lowered.vector_lines
    for i, row in enumerate(rows.values()):
        at = lines.index(f"sums[{i}] = _add.reduce({row})")
        assert not any(row in line for line in lines[at + 1 :]), row  # never touched again
        assert any(row in line for line in lines[:at]), row  # written before
    for blank in (None, 3):  # all finite; then a NaN input in sample 3
        a_values = values[a].copy()
        if blank is not None:
            a_values[blank] = np.nan
        out = np.full((4, n), np.nan)
        scope = {"numpy": np, "out": out, "a": a_values, "b": values[b], "k": 2.0, "m": 3.0,
                 **_module_names(lowered, constants)}  # fmt: skip
        for i in range(lowered.buffers):
            scope[f"w{i}"] = np.empty(n)
        exec("\n".join(lowered.scalar_lines + lines), scope)
        sums = scope["sums"]
        np.testing.assert_array_equal(sums, np.add.reduce(out, axis=1))  # the same sums
        assert np.isfinite(sums).tolist() == np.isfinite(out).all(axis=1).tolist()
        assert np.isfinite(sums).all() == (blank is None)


def test_a_value_read_only_by_an_output_keeps_its_buffer() -> None:
    # t1 is last read by a statement (t2), then by an output expression; the buffers freed after
    # t2 are reused by t3, which must not overwrite t1 (the bug the derivation notebook found in
    # the generated Jacobian: outputs were not counted as uses).
    rng = np.random.default_rng(3)
    n = 16
    values = {a: rng.uniform(1, 2, n), b: rng.uniform(1, 2, n), k: 2.0, m: 3.0}
    t4 = sp.Symbol("t4", real=True)
    code = StraightLine(
        assignments=((t1, a * b), (t2, t1 + a), (t3, a - 2 * b), (t4, b * b * a)),
        outputs=(("t1 twice", 2 * t1), ("t2", t2 * k), ("t3", t3), ("t4 over t1", t4 / t1)),
        ops_before=0,
        ops_after=0,
    )
    out = _run(code, values, n)
    x1 = values[a] * values[b]
    np.testing.assert_allclose(out[0], 2 * x1, rtol=1e-15)
    np.testing.assert_allclose(out[1], (x1 + values[a]) * 2.0, rtol=1e-15)
    np.testing.assert_allclose(out[2], values[a] - 2 * values[b], rtol=1e-15)
    np.testing.assert_allclose(out[3], values[b] ** 2 * values[a] / x1, rtol=1e-14)


def test_copies_and_negations_fold_into_their_uses() -> None:
    rng = np.random.default_rng(4)
    n = 16
    values = {a: rng.uniform(-1, 1, n), b: rng.uniform(-1, 1, n), k: 2.0, m: 3.0}
    t4 = sp.Symbol("t4", real=True)
    code = StraightLine(  # t2 = -t1, t3 = t2 (copy): -t3 - k is t1 - k, one subtraction
        assignments=((t1, a * b), (t2, -t1), (t3, t2), (t4, -t3 - k)),
        outputs=(("t4", t4), ("t3", t3)),
        ops_before=0,
        ops_after=0,
    )
    out = _run(code, values, n)
    np.testing.assert_allclose(out[0], values[a] * values[b] - 2.0, rtol=1e-15)
    np.testing.assert_allclose(out[1], -values[a] * values[b], rtol=1e-15)
    lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, {"t4": "out[0]", "t3": "out[1]"})
    assert _calls(lowered) == ["_multiply", "_add", "_multiply"]  # t1 - k, then -t1


def test_a_negated_value_is_named_by_its_opposite_when_that_saves_calls() -> None:
    # t1 = -(a b) costs a product and a sign change; its uses absorb the sign for free
    # (t2 = b + t1 is b - a b; the output -t1 is a b, computed in its row): flipped, the
    # program saves the sign change and the output's. t3 = atan2(t1, b) is no sum or product:
    # a value read there keeps its sign, and its product keeps its call to -1.
    rng = np.random.default_rng(8)
    n = 64
    values = {a: rng.uniform(-1, 1, n), b: rng.uniform(-1, 1, n), k: 2.0, m: 3.0}
    values[a][:4] = 0.0  # products of zero: the signs of zeros hold too
    t4 = sp.Symbol("t4", real=True)
    flipped = StraightLine(
        assignments=((t1, -a * b), (t2, b + t1 * k)),
        outputs=(("minus t1", -t1), ("t2", t2)),
        ops_before=0,
        ops_after=0,
    )
    rows = {"minus t1": "out[0]", "t2": "out[1]"}
    lowered = lower_numpy(flipped, {a: "a", b: "b"}, {k, m}, rows, {})
    assert _calls(lowered) == ["_multiply", "_multiply", "_subtract"], lowered.vector_lines
    out = _run(flipped, values, n)
    ab = values[a] * values[b]
    np.testing.assert_array_equal(out[0], ab)
    np.testing.assert_array_equal(out[1], values[b] - ab * 2.0)
    kept = StraightLine(
        assignments=((t1, -a * b), (t3, sp.atan2(t1, b)), (t4, t3 + t1)),
        outputs=(("t4", t4),),
        ops_before=0,
        ops_after=0,
    )
    lowered = lower_numpy(kept, {a: "a", b: "b"}, {k, m}, {"t4": "out[0]"}, {})
    assert lowered.atan2
    assert "_K0" in lowered.vector_lines[1]  # -(a b) computed, its sign too
    want = np.arctan2(-ab, values[b]) + -ab
    np.testing.assert_allclose(_run(kept, values, n)[0], want, rtol=1e-15, atol=0)


def _generated_numpy():
    from rpr3gen import manifest
    from rpr3gen.evaluators import numpy_module

    return numpy_module(manifest.load("revolute"))


def test_sin_and_cos_of_one_argument_are_one_sincos_call() -> None:
    rng = np.random.default_rng(5)
    n = 64
    values = {a: rng.uniform(-4, 4, n), b: rng.uniform(-1, 1, n), k: 2.0, m: 3.0}
    code = StraightLine(
        assignments=((t1, sp.cos(a)), (t2, sp.sin(a)), (t3, t1 * t2 + b * t1)),
        outputs=(("y", t3), ("s", 2 * t2)),
        ops_before=0,
        ops_after=0,
    )
    rows = {"y": "out[0]", "s": "out[1]"}
    constants: dict[str, str] = {}
    lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, rows, constants)
    assert lowered.sincos
    assert sum("_sincos(" in line for line in lowered.vector_lines) == 1
    assert not any(call in ("_sin", "_cos") for call in _calls(lowered))
    out = np.full((2, n), np.nan)
    scope = {"numpy": np, "out": out, "a": values[a], "b": values[b], "k": 2.0, "m": 3.0,
             "_sincos": _generated_numpy()._sincos,
             **_module_names(lowered, constants)}  # fmt: skip
    for i in range(lowered.buffers):
        scope[f"w{i}"] = np.empty(n)
    exec("\n".join(lowered.scalar_lines + lowered.vector_lines), scope)
    c, s = np.cos(values[a]), np.sin(values[a])
    np.testing.assert_allclose(out[0], c * s + values[b] * c, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(out[1], 2 * s, rtol=1e-15)


def test_generated_sincos_is_within_two_ulp() -> None:
    sincos = _generated_numpy()._sincos
    rng = np.random.default_rng(6)
    turns = np.arange(1, 600_000, 7.0) * (np.pi / 2)
    for x in (
        np.linspace(-50.0, 50.0, 400_001),
        rng.uniform(-(2.0**20), 2.0**20, 200_000),
        np.concatenate([turns, np.nextafter(turns, 0.0), np.nextafter(turns, np.inf)]),
        np.array([1e7, 3.0]),  # an argument past 2^20: the whole array goes to numpy
    ):
        s, c = np.empty_like(x), np.empty_like(x)
        sincos(x, s, c, [np.empty_like(x) for _ in range(4)])
        for got, want in ((s, np.sin(x)), (c, np.cos(x))):
            assert np.max(np.abs(got - want) / np.spacing(np.abs(want))) <= 2.0
    x = np.array([np.nan, 0.5])
    s, c = np.empty(2), np.empty(2)
    with np.errstate(invalid="ignore"):
        sincos(x, s, c, [np.empty(2) for _ in range(4)])
    assert np.isnan([s[0], c[0]]).all()
    assert s[1] == np.sin(0.5)


def _ulps(got: np.ndarray, want: np.ndarray) -> float:
    return float(np.max(np.abs(got - want) / np.spacing(np.abs(want)), initial=0.0))


def test_generated_atan2_is_numpys_within_two_ulp() -> None:
    atan2 = _generated_numpy()._atan2
    rng = np.random.default_rng(9)
    n = 400_000
    angle = rng.uniform(-np.pi, np.pi, n)
    radius = 10.0 ** rng.uniform(-6, 6, n)
    quadrants = (radius * np.sin(angle), radius * np.cos(angle))
    axes = np.array([0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, -1e300, np.inf, -np.inf])
    y_axes, x_axes = (a.ravel() for a in np.meshgrid(axes, axes))
    for y, x in (quadrants, (y_axes, x_axes), (np.array([np.nan, 1.0]), np.array([1.0, np.nan]))):
        out = np.empty_like(y)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            atan2(y, x, out, (np.empty_like(y),))
        want = np.arctan2(y, x)
        finite = np.isfinite(want) & (want != 0)
        assert _ulps(out[finite], want[finite]) <= 2.0
        zeros = want == 0  # the signs of zeros (pi against -pi: the ulps above)
        np.testing.assert_array_equal(np.signbit(out[zeros]), np.signbit(want[zeros]))
        np.testing.assert_array_equal(np.isnan(out), np.isnan(want))
    out = np.empty(3)  # a scalar operand (a 0-d array, as the lowering passes a parameter)
    with np.errstate(divide="ignore", invalid="ignore"):
        atan2(np.array(0.0), np.array([0.0, -1.0, 2.0]), out, (np.empty(3),))
    np.testing.assert_array_equal(out, np.arctan2(0.0, [0.0, -1.0, 2.0]))


def test_scratch_rows_passed_in_give_the_same_bits() -> None:
    import rpr3gen

    module = _generated_numpy()
    traj = rpr3gen.paper_trajectory("rotation", samples=50)
    params = rpr3gen.load_model().vector(rpr3gen.PARAM_NAMES)
    rows = module.WORK_ROWS["rpr3_inverse_dynamics"]
    fresh, reused = np.empty((module.NUM_OUTPUTS, 50)), np.empty((module.NUM_OUTPUTS, 50))
    module.rpr3_inverse_dynamics(params, traj.q, traj.qd, traj.qdd, fresh)
    work = np.full((rows + 3, 80), np.nan)  # larger than needed, and dirty
    module.rpr3_inverse_dynamics(params, traj.q, traj.qd, traj.qdd, reused, work=work)
    assert fresh.tobytes() == reused.tobytes()


def test_operands_are_arrays_and_outputs_positional_with_the_scalars_values() -> None:
    # A call's cheapest form: every operand an array (a number as a module constant, a parameter
    # expression computed once per call, both 0-d), the output by position. The values are
    # those of the same calls on Python scalars, bit for bit.
    rng = np.random.default_rng(7)
    n = 64
    values = {a: rng.uniform(-2, 2, n), b: rng.uniform(-2, 2, n), k: 0.7, m: 1.3}
    expr = (k + m) * a - 3 * b + (k + m) * b**2 - sp.Rational(1, 3) * a * b + k / (a**2 + 1)
    code = StraightLine(assignments=((t1, expr),), outputs=(("y", t1),), ops_before=0, ops_after=0)
    constants: dict[str, str] = {}
    lowered = lower_numpy(code, {a: "a", b: "b"}, {k, m}, {"y": "out[0]"}, constants)
    hoisted = [line for line in lowered.vector_lines if " = " in line]
    assert len(hoisted) == len({line.split(" = ", 1)[1] for line in hoisted})  # each once
    operand = re.compile(r"^(w\d+|out\[\d+\]|a|b|_K\d+|_k\d+)$")
    for line in lowered.vector_lines:
        if " = " in line:
            continue
        assert "out=" not in line
        args = line[line.index("(") + 1 : -1].split(", ")
        assert all(operand.match(arg) for arg in args), line

    def run(as_arrays: bool) -> np.ndarray:
        out = np.full((1, n), np.nan)
        scope = {"numpy": np, "out": out, "a": values[a], "b": values[b],
                 "k": np.float64(values[k]), "m": np.float64(values[m])}  # fmt: skip
        scope.update({f"_{u}": getattr(np, u) for u in lowered.ufuncs})
        scope["sums"] = np.empty(lowered.sums)
        for text, name in constants.items():
            scope[name] = np.array(eval(text), np.float64) if as_arrays else eval(text)
        for i in range(lowered.buffers):
            scope[f"w{i}"] = np.empty(n)
        lines = lowered.vector_lines
        if not as_arrays:  # the hoisted parameter expressions as the scalars they are
            lines = [line.replace("numpy.array(", "(").replace(", numpy.float64)", ")")
                     for line in lines]  # fmt: skip
        exec("\n".join(lowered.scalar_lines + lines), scope)
        return out[0]

    got, scalars = run(True), run(False)
    np.testing.assert_array_equal(got.view(np.int64), scalars.view(np.int64))
    x, y = values[a], values[b]
    want = 2.0 * x - 3 * y + 2.0 * y**2 - x * y / 3 + 0.7 / (x**2 + 1)
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13)


def _legs_program() -> tuple[StraightLine, dict[str, sp.Symbol]]:
    """Three legs' statements named alike (``r_A``, ``r_B``, ``r_C``), their parameters
    (``pA`` ...), a platform value reading each leg, then more leg statements reading it."""
    s = {name: sp.Symbol(name, real=True) for name in
         ["pA", "pB", "pC", "c", "u", "v", "z", "h"]
         + [f"{x}_{leg}" for x in "rsqpyg" for leg in "ABC"]}  # fmt: skip
    lines = []
    for leg in "ABC":
        lines += [(s[f"r_{leg}"], s["u"] + s[f"p{leg}"]), (s[f"s_{leg}"], s[f"r_{leg}"] * s["v"])]
    for leg in "ABC":
        lines += [
            (s[f"q_{leg}"], s[f"s_{leg}"] ** 2 + s["c"]),
            (s[f"p_{leg}"], sp.sqrt(s[f"q_{leg}"])),
        ]
    lines.append((s["z"], s["p_A"] + s["p_B"] * s["u"] - s["p_C"]))
    for leg in "ABC":
        lines += [(s[f"y_{leg}"], s["z"] * s[f"s_{leg}"] - s["c"]),
                  (s[f"g_{leg}"], s[f"y_{leg}"] / s[f"q_{leg}"])]  # fmt: skip
    lines.append((s["h"], s["r_A"] * s["r_C"]))  # r_B is dead long before r_A and r_C
    outputs = [("p_A", s["p_A"]), ("p_B", s["p_B"]), ("p_C", s["p_C"]), ("z", s["z"]),
               ("y_A", s["y_A"]), ("y_C", s["y_C"]), ("y_B", s["y_B"]),  # not in the legs' order
               ("g_A", s["g_A"]), ("g_B", s["g_B"]), ("g_C", s["g_C"]), ("h", s["h"])]  # fmt: skip
    return StraightLine(tuple(lines), tuple(outputs), 0, 0), s


def _run_legs(lowered, constants, s, values, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The lowered lines run as the module runs them: rows ``wK`` of one work array, and the
    (3, n) blocks ``tK`` over three of its rows."""
    out = np.full((11, n), np.nan)
    scope = {"numpy": np, "out": out, **{str(x): values[str(x)] for x in
             (s["pA"], s["pB"], s["pC"], s["c"], s["u"], s["v"])},
             **_module_names(lowered, constants)}  # fmt: skip
    work = np.full((max(lowered.buffers, 1), n), np.nan)
    for i in range(lowered.buffers):
        scope[f"w{i}"] = work[i]
    for first in lowered.blocks:
        scope[f"t{first}"] = work[first : first + lowered.legs]
    exec("\n".join(lowered.scalar_lines + lowered.vector_lines), scope)
    return out, scope["sums"]


def test_the_legs_statements_run_as_one_call_for_three_legs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The three legs' statements that are one expression run on (3, n) blocks: fewer calls, the
    # same values as each leg computed alone (here by NumPy directly), the legs' consecutive
    # output rows written at once and summed; a block of three rows is only ever three free
    # rows, and the row of a leg whose value is dead is free while the other legs' rows of its
    # block are still read (r_B dies at s, r_A and r_C live to h).
    from rpr3gen_derive.codegen.backends.python import groups

    code, s = _legs_program()
    rng = np.random.default_rng(5)
    n = 32
    values = {"pA": 0.3, "pB": -0.2, "pC": 0.5, "c": 1.5,
              "u": rng.uniform(-1, 1, n), "v": rng.uniform(-1, 1, n)}  # fmt: skip
    inputs = {s["u"]: "u", s["v"]: "v"}
    params = {s["pA"], s["pB"], s["pC"], s["c"]}
    rows = {name: f"out[{i}]" for i, (name, _) in enumerate(code.outputs)}
    constants: dict[str, str] = {}
    stacked = lower_numpy(code, inputs, params, rows, constants, "ABC")
    assert stacked.blocks, stacked.vector_lines
    assert any("out[0:3]" in line for line in stacked.vector_lines)  # p_A, p_B, p_C at once
    assert not any("out[4:7]" in line for line in stacked.vector_lines)  # y: another order
    got, sums = _run_legs(stacked, constants, s, values, n)

    u, v, c = values["u"], values["v"], values["c"]
    r = {leg: u + values[f"p{leg}"] for leg in "ABC"}
    sv = {leg: r[leg] * v for leg in "ABC"}
    q = {leg: sv[leg] ** 2 + c for leg in "ABC"}
    p = {leg: np.sqrt(q[leg]) for leg in "ABC"}
    z = p["A"] + p["B"] * u - p["C"]
    y = {leg: z * sv[leg] - c for leg in "ABC"}
    want = np.array([p["A"], p["B"], p["C"], z, y["A"], y["C"], y["B"],
                     *(y[leg] / q[leg] for leg in "ABC"), r["A"] * r["C"]])  # fmt: skip
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(sums, np.add.reduce(got, axis=1))

    monkeypatch.setattr(groups, "MIN_GROUPS", 10**6)  # the same program, leg by leg
    alone = lower_numpy(code, inputs, params, rows, {}, "ABC")
    assert not alone.blocks
    # r, s, q (two operations) and p: five operations, each one call for three legs
    assert len(_calls(stacked)) == len(_calls(alone)) - 2 * 5


def test_six_legs_run_on_six_row_blocks() -> None:
    """A hexapod's legs (``ABCDEF``): each operation of their alike statements is one call on a
    (6, n) block, the legs' output rows written and summed at once, each leg's values those of
    its own statements, bit for bit."""
    legs = "ABCDEF"
    s = {name: sp.Symbol(name, real=True) for name in
         ["u", "v", "c"] + [f"p{leg}" for leg in legs]
         + [f"{x}_{leg}" for x in "rstq" for leg in legs]}  # fmt: skip
    lines = []
    for leg in legs:
        lines += [
            (s[f"r_{leg}"], s["u"] + s[f"p{leg}"]),
            (s[f"s_{leg}"], s[f"r_{leg}"] * s["v"] - s["c"]),
            (s[f"t_{leg}"], s[f"s_{leg}"] ** 2 + s["c"]),
            (s[f"q_{leg}"], sp.sqrt(s[f"t_{leg}"])),
        ]
    outputs = [(f"q_{leg}", s[f"q_{leg}"]) for leg in legs]
    code = StraightLine(tuple(lines), tuple(outputs), 0, 0)
    rng = np.random.default_rng(6)
    n = 24
    values = {"u": rng.uniform(-1, 1, n), "v": rng.uniform(-1, 1, n), "c": 1.5}
    values.update({f"p{leg}": 0.1 * k - 0.2 for k, leg in enumerate(legs)})
    params = {s["c"], *(s[f"p{leg}"] for leg in legs)}
    rows = {name: f"out[{i}]" for i, (name, _) in enumerate(outputs)}
    constants: dict[str, str] = {}
    lowered = lower_numpy(code, {s["u"]: "u", s["v"]: "v"}, params, rows, constants, legs)
    assert lowered.legs == 6
    assert lowered.blocks, lowered.vector_lines
    assert any("out[0:6]" in line for line in lowered.vector_lines)
    assert any("sums[0:6]" in line for line in lowered.vector_lines)
    out = np.full((6, n), np.nan)
    scope = {"numpy": np, "out": out, **values, **_module_names(lowered, constants)}
    work = np.full((max(lowered.buffers, 1), n), np.nan)
    for i in range(lowered.buffers):
        scope[f"w{i}"] = work[i]
    for first in lowered.blocks:
        scope[f"t{first}"] = work[first : first + 6]
    exec("\n".join(lowered.scalar_lines + lowered.vector_lines), scope)
    u, v, c = values["u"], values["v"], values["c"]
    for k, leg in enumerate(legs):
        want = np.sqrt((((u + values[f"p{leg}"]) * v) - c) ** 2 + c)
        np.testing.assert_array_equal(out[k], want)
    three = lower_numpy(code, {s["u"]: "u", s["v"]: "v"}, params, rows, {}, "ABC")
    assert three.legs == 3  # as three legs (as before): A, B, C in blocks, D, E, F one by one
    assert len(_calls(three)) > len(_calls(lowered))
