"""The legs as lanes (``rpr3gen_derive.codegen.backends.c.lanes``): which statements may share
a loop, and that the committed kernels use it.

That a laned kernel gives the bits of the scalar statements is tested on every function by
``test_c_backend.py`` and ``test_planar_runtime.py`` (single call against the batch, whose
loops run the statements one leg after the other).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rpr3gen_derive.codegen.backends.c.lanes import LOOP, _groups, lanes, loop, width
from rpr3gen_derive.codegen.backends.c.order import Line

NONE: frozenset[str] = frozenset()


def load(name: str, index: int) -> Line:
    return Line("load", name, NONE, (f"params[{index}]",))


def assign(name: str, text: str, reads: str) -> Line:
    return Line("assign", name, frozenset(reads.split()), (text,))


def legs() -> list[Line]:
    """A leg parameter at params[0], [2], [4] and a shared one at params[1]."""
    return [load("xA1", 0), load("xB1", 2), load("xC1", 4), load("c", 1)]


def test_operands_swapped_by_an_addition_or_a_product_share_a_lane() -> None:
    lines = [
        *legs(),
        assign("u_A", "xA1*c + 1.0", "xA1 c"),
        assign("u_B", "1.0 + c*xB1", "xB1 c"),
        assign("u_C", "c*xC1 + 1.0", "xC1 c"),
    ]
    member = _groups(lines, 8, "ABC")
    assert {member[n][1] for n in ("u_A", "u_B", "u_C")} == {0, 1, 2}
    assert len({member[n][0] for n in ("u_A", "u_B", "u_C")}) == 1
    assert member["xA1"][0] == member["xC1"][0] != member["u_A"][0]


def test_a_reassociated_sum_does_not_share_a_lane() -> None:
    """(x + c) + 1 and x + (c + 1) round differently: the legs would lose their bits."""
    lines = [
        *legs(),
        assign("v_A", "(xA1 + c) + 1.0", "xA1 c"),
        assign("v_B", "xB1 + (c + 1.0)", "xB1 c"),
        assign("v_C", "(xC1 + c) + 1.0", "xC1 c"),
    ]
    member = _groups(lines, 8, "ABC")
    assert "v_A" not in member
    assert "v_B" not in member


def test_a_subtraction_keeps_its_order() -> None:
    lines = [
        *legs(),
        assign("w_A", "xA1 - c", "xA1 c"),
        assign("w_B", "c - xB1", "xB1 c"),
        assign("w_C", "xC1 - c", "xC1 c"),
    ]
    assert "w_A" not in _groups(lines, 8, "ABC")


def chain() -> list[Line]:
    """``legs()`` and three statements of one leg each, read as lanes: four lane groups, enough
    for :func:`lanes` to write its loops."""
    lines = legs()
    for name, before in (("a", "x@1"), ("b", "a_@"), ("c", "b_@")):
        lines += [
            assign(f"{name}_{leg}", f"2.0*{before.replace('@', leg)}", before.replace("@", leg))
            for leg in "ABC"
        ]
    return [*lines, Line("store", "", frozenset({"c_B"}), ("out", "0", "c_B"))]


def test_lane_3_never_reads_past_the_parameters() -> None:
    """params[0], [2], [4]: lane 3 reads params[6] inside a vector of 7; in a vector of 6 the
    loop reads the legs' copy, whose lane 3 is 0.0."""
    inside = "\n".join(lanes(chain(), 7, "ABC") or [])
    assert "const double xi1 = params[0 + 2*i];" in inside
    assert "params_by_leg" not in inside
    past = "\n".join(lanes(chain(), 6, "ABC") or [])
    assert "const double xi1 = params_by_leg[0 + i];" in past
    assert "params_by_leg[4*i + 0] = params[0 + i];" in past
    assert "params_by_leg[4*i + 2] = params[4 + i];" in past
    assert "params_by_leg[4*i + 3] = 0.0;" in past
    assert "params[6" not in past


def test_a_leg_block_of_a_large_stride_is_read_from_the_copy_by_leg() -> None:
    """The general format's stride (17) is a group gcc does not vectorise: every leg parameter
    at that stride is read from the copy, row k = params[k0 + k + 17*leg]; the copy's rows stay
    inside the vector."""
    lines = [
        load("mA", 9), load("mB", 26), load("mC", 43),
        load("JA", 16), load("JB", 33), load("JC", 50),
        *(assign(f"u_{leg}", f"m{leg}*J{leg}", f"m{leg} J{leg}") for leg in "ABC"),
        *(assign(f"v_{leg}", f"u_{leg}*u_{leg}", f"u_{leg}") for leg in "ABC"),
        Line("store", "", frozenset({"v_C"}), ("out", "0", "v_C")),
    ]  # fmt: skip
    code = "\n".join(lanes(lines, 60, "ABC") or [])
    assert "const double mi = params_by_leg[0 + i];" in code
    assert "const double Ji = params_by_leg[28 + i];" in code
    assert "double params_by_leg[32];" in code  # rows 9..16: 8, a whole number of vectors
    assert "params_by_leg[4*i + 2] = params[43 + i];" in code
    assert "for (i = 0; i < 8; ++i) {" in code


def test_a_statement_reading_two_legs_stays_scalar() -> None:
    lines = [
        *legs(),
        assign("s_A", "xA1*xB1", "xA1 xB1"),
        assign("s_B", "xB1*xC1", "xB1 xC1"),
        assign("s_C", "xC1*xA1", "xC1 xA1"),
    ]
    assert "s_A" not in _groups(lines, 8, "ABC")


def test_the_loop_reads_a_group_of_an_earlier_loop_from_its_array() -> None:
    lines = [
        *legs(),
        assign("a_A", "2.0*xA1", "xA1"),
        assign("a_B", "2.0*xB1", "xB1"),
        assign("a_C", "2.0*xC1", "xC1"),
        assign("sum", "a_A + a_B + a_C", "a_A a_B a_C"),
        assign("b_A", "a_A*sum", "a_A sum"),
        assign("b_B", "a_B*sum", "a_B sum"),
        assign("b_C", "a_C*sum", "a_C sum"),
        assign("d_A", "b_A + c", "b_A c"),
        assign("d_B", "b_B + c", "b_B c"),
        assign("d_C", "b_C + c", "b_C c"),
        Line("store", "", frozenset({"d_B"}), ("out", "0", "d_B")),
    ]
    code = "\n".join(lanes(lines, 8, "ABC") or [])
    assert code.count("for (i = 0; i < 4; ++i)") == 2
    assert "const double xi1 = params[0 + 2*i];" in code
    assert "const double a_i = 2.0*xi1;" in code
    assert "const double sum = a_A + a_B + a_C;" in code.replace("    ", "")
    assert "const double b_i = a_i_legs[i]*sum;" in code
    assert "const double d_B = d_i_legs[1];" in code
    assert code.index("const double d_B") < code.index("r_out[0] = d_B;")


@pytest.mark.parametrize("variant", ["revolute", "prismatic"])
@pytest.mark.parametrize("function", ["inverse_dynamics", "forward_dynamics"])
def test_the_dynamics_kernels_run_their_legs_as_lanes(
    repo_root: Path, variant: str, function: str
) -> None:
    source = (repo_root / "generated" / variant / "rpr3.c").read_text()
    start = source.index(f"static int rpr3_{function}_kernel(")
    body = source[start : source.index("\n}\n", start)]
    assert "for (i = 0; i < 4; ++i)" in body
    assert "rpr3_atan2(ry_i, rx_i)" in body or function == "forward_dynamics"


def test_a_loop_is_the_legs_rounded_up_to_a_power_of_two() -> None:
    assert [width(legs) for legs in ("AB", "ABC", "ABCD", "ABCDE", "ABCDEF")] == [2, 4, 4, 8, 8]
    assert loop("ABC") == "for (i = 0; i < 4; ++i) { /* legs A, B, C; lane 3 unused */"
    assert loop("ABCDEF") == (
        "for (i = 0; i < 8; ++i) { /* legs A, B, C, D, E, F; lanes 6, 7 unused */"
    )
    assert loop("ABCD") == "for (i = 0; i < 4; ++i) { /* legs A, B, C, D */"
    for legs in ("AB", "ABC", "ABCD", "ABCDE", "ABCDEF"):
        found = LOOP.fullmatch(loop(legs))
        assert found is not None
        assert found["legs"].split(", ") == list(legs)
        assert int(found["width"]) == width(legs)


SIX = "ABCDEF"


def six_legs(stride: int) -> list[Line]:
    """A parameter of each of six legs at params[stride*leg], a shared one at params[1], and
    four statements of each leg, alike but for the leg: four lane groups."""
    lines = [load(f"x{leg}1", stride * k) for k, leg in enumerate(SIX)] + [load("c", 1)]
    for name, before in (("a", "x@1"), ("b", "a_@"), ("d", "b_@")):
        for leg in SIX:
            operand = before.replace("@", leg)
            lines.append(assign(f"{name}_{leg}", f"c*{operand}", f"c {operand}"))
    return [*lines, Line("store", "", frozenset({"d_F"}), ("out", "0", "d_F"))]


def test_six_legs_run_as_eight_lanes() -> None:
    """A hexapod's legs: one loop of 8 lanes, lanes 6 and 7 padding. At stride 2 lane 7 reads
    params[14] inside a vector of 15; at a stride past MAX_STRIDE (a spatial leg's 32
    parameters), from the copy by leg, 8 lanes a row, lanes 6 and 7 0.0."""
    code = "\n".join(lanes(six_legs(2), 15, SIX) or [])
    assert loop(SIX) in code
    assert "const double xi1 = params[0 + 2*i];" in code
    assert "const double d_F = d_i_legs[5];" in code
    assert "double d_i_legs[8];" in code
    copied = "\n".join(lanes(six_legs(32), 6 * 32, SIX) or [])
    assert "const double xi1 = params_by_leg[0 + i];" in copied
    assert "params_by_leg[8*i + 5] = params[160 + i];" in copied
    assert "params_by_leg[8*i + 6] = 0.0;" in copied
    assert "params_by_leg[8*i + 7] = 0.0;" in copied
    assert "lanes 6, 7: 0.0" in copied


def test_a_statement_alike_in_some_legs_only_stays_scalar() -> None:
    """Six legs share a lane only when all six statements are one expression: three legs
    alike (as a loop over A, B, C would have taken them) are not a group."""
    lines = six_legs(2)
    lines += [assign(f"e_{leg}", f"d_{leg}*c", f"d_{leg} c") for leg in "ABC"]
    lines += [assign(f"e_{leg}", f"d_{leg} - c", f"d_{leg} c") for leg in "DEF"]
    member = _groups(lines, 15, SIX)
    assert {member[f"d_{leg}"][1] for leg in SIX} == set(range(6))
    assert not any(f"e_{leg}" in member for leg in SIX)
    assert "e_A" in _groups(lines, 15, "ABC")  # as three legs A, B, C, they are one group


def test_the_hexapods_kernels_run_six_legs_as_lanes(repo_root: Path) -> None:
    """The committed 6-UPS: every leg's statements in loops over A to F, none over A, B, C
    alone, and no leg's parameters loaded one by one where the lanes read them."""
    source = (repo_root / "generated" / "ups_2" / "rpr3.c").read_text()
    start = source.index("static int rpr3_inverse_dynamics_kernel(")
    body = source[start : source.index("\n}\n", start)]
    assert loop(SIX) in body
    assert "for (i = 0; i < 4; ++i)" not in body
    assert "double params_by_leg[256];" in body
    assert "params[96]" not in body  # leg D's first parameter: read by the lanes


@pytest.mark.slow
@pytest.mark.usefixtures("optimised_c_builds")
def test_the_hexapods_single_calls_give_the_batchs_bits(repo_root: Path) -> None:
    """The 6-UPS built with the runtime's flags (its legs as 8 lanes, which gcc vectorises):
    every function's single call, sample by sample, gives the bits of its batch (which runs the
    statements one leg after the other), along the gallery's trajectory."""
    import ctypes

    import numpy as np

    import rpr3gen
    from rpr3gen import cbackend, control, variants

    model = rpr3gen.load_model(repo_root / "models" / "tsai-ups.toml")
    traj = rpr3gen.read_trajectory_csv(
        repo_root / "models" / "tsai-ups.csv", pose=model.structure.pose
    )
    pick = np.linspace(0, len(traj.t) - 1, 48).astype(int)
    q, qd, qdd = traj.q[pick], traj.qd[pick], traj.qdd[pick]
    tau = control.actuator_efforts(model, q, qd, qdd)
    qa = control.actuator_coordinates(model, q)
    inputs = {"q": q, "qd": qd, "qdd": qdd, "tau": tau, "qa": qa, "q_near": q + 1e-3}
    variant = variants.load(model.structure, model.generated)
    assert variant.variant == "ups_2"
    library = cbackend.library(variant)
    params = np.ascontiguousarray(model.vector(variant.param_names))
    ptr = ctypes.c_void_p
    for fname, info in variant.functions.items():
        args = [np.ascontiguousarray(inputs[arg.name], dtype=float) for arg in info.inputs]
        batch, codes = rpr3gen.evaluate(model, fname, args, "c")
        assert not codes.any(), fname
        single = library.entries[fname].single
        for k in range(len(q)):
            ins = [np.ascontiguousarray(a[k]) for a in args]
            row = [np.empty(o.size) for o in info.public_outputs]
            code = single(ptr(params.ctypes.data), *(ptr(a.ctypes.data) for a in (*ins, *row)))
            assert code == 0, fname
            for got, want in zip(row, batch, strict=True):
                assert got.tobytes() == want[k].tobytes(), (fname, k)
