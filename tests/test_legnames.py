"""Per-leg names of the CSE temporaries (``rpr3gen_derive.codegen.legnames``): three temporaries
that are one expression for the three legs get leg A's number and the leg's letter, so that the
printers list the legs' sums in one order; nothing else changes."""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.legnames import leg_names

xA1, xB1, xC1, c = sp.symbols("xA1 xB1 xC1 c", real=True)
x1, x5, x9, x2, x6, x10, x3, out_A = sp.symbols("x1 x5 x9 x2 x6 x10 x3 out_A", real=True)


def test_one_expression_of_three_legs_gets_leg_as_number_and_letters() -> None:
    lines = [
        (x1, xA1 * c),
        (x5, xB1 * c),
        (x9, xC1 * c),
        (x2, x1 + 1),  # reads a temporary of leg A: renamed once x1 is
        (x6, x5 + 1),
        (x10, x9 + 1),
        (x3, x1 * x5),  # two legs: stays
    ]
    outputs = [("out[0]", x2 + x6 + x10 + x3)]
    renamed, outs = leg_names(lines, outputs, {x1, x5, x9, x2, x6, x10, x3})
    names = [str(s) for s, _ in renamed]
    assert names == ["x1_A", "x1_B", "x1_C", "x2_A", "x2_B", "x2_C", "x3"]
    x1_A, x1_B = sp.Symbol("x1_A", real=True), sp.Symbol("x1_B", real=True)
    assert renamed[6][1] == x1_A * x1_B
    olds = [s for s, _ in lines]
    back = {sp.Symbol(n, real=True): o for n, o in zip(names, olds, strict=True)}
    for (_, new), (_, old) in zip(renamed, lines, strict=True):
        assert new.xreplace(back) == old
    assert outs[0][1].xreplace(back) == outputs[0][1]


def test_different_expressions_keep_their_names() -> None:
    lines = [(x1, xA1 * c), (x5, xB1 + c), (x9, xC1 * c)]
    renamed, _ = leg_names(lines, [("out[0]", x1 + x5 + x9)], {x1, x5, x9})
    assert [str(s) for s, _ in renamed] == ["x1", "x5", "x9"]


def test_program_symbols_are_never_renamed() -> None:
    lines = [(out_A, xA1 * c)]
    renamed, _ = leg_names(lines, [("out[0]", out_A)], set())
    assert renamed == lines


def test_a_parameter_name_is_never_taken() -> None:
    """The general PRR model has parameters ``x1_A``...: a temporary ``x1`` never takes one of
    their names, even where this function does not read them (the C backend finds parameters by
    name); the legs' names then join the letter with two underscores, or three."""
    lines = [(x1, xA1 * c), (x5, xB1 * c), (x9, xC1 * c)]
    outputs = [("out[0]", x1 + x5 + x9)]
    renamed, _ = leg_names(lines, outputs, {x1, x5, x9}, frozenset({"x1_B"}))
    assert [str(s) for s, _ in renamed] == ["x1__A", "x1__B", "x1__C"]
    renamed, _ = leg_names(lines, outputs, {x1, x5, x9}, frozenset({"x1_B", "x1__C"}))
    assert [str(s) for s, _ in renamed] == ["x1___A", "x1___B", "x1___C"]
    renamed, _ = leg_names(lines, outputs, {x1, x5, x9})
    assert [str(s) for s, _ in renamed] == ["x1_A", "x1_B", "x1_C"]
