"""The legs as lanes (``rpr3gen_derive.codegen.backends.c.lanes``): which statements may share
a loop, and that the committed kernels use it.

That a laned kernel gives the bits of the scalar statements is tested on every function by
``test_c_backend.py`` and ``test_planar_runtime.py`` (single call against the batch, whose
loops run the statements one leg after the other).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rpr3gen_derive.codegen.backends.c.lanes import _groups, lanes
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
    member = _groups(lines, 8)
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
    member = _groups(lines, 8)
    assert "v_A" not in member
    assert "v_B" not in member


def test_a_subtraction_keeps_its_order() -> None:
    lines = [
        *legs(),
        assign("w_A", "xA1 - c", "xA1 c"),
        assign("w_B", "c - xB1", "xB1 c"),
        assign("w_C", "xC1 - c", "xC1 c"),
    ]
    assert "w_A" not in _groups(lines, 8)


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
    inside = "\n".join(lanes(chain(), 7) or [])
    assert "const double xi1 = params[0 + 2*i];" in inside
    assert "params_by_leg" not in inside
    past = "\n".join(lanes(chain(), 6) or [])
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
    code = "\n".join(lanes(lines, 60) or [])
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
    assert "s_A" not in _groups(lines, 8)


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
    code = "\n".join(lanes(lines, 8) or [])
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
