"""Per-leg names of the CSE temporaries (``rpr3gen_derive.codegen.legnames``): three temporaries
that are one expression for the three legs get leg A's number and the leg's letter, so that the
printers list the legs' sums in one order; nothing else changes."""

from __future__ import annotations

import random

import sympy as sp
from rpr3gen_derive.codegen.legnames import leg_names, shape

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
    renamed, outs = leg_names(lines, outputs, {x1, x5, x9, x2, x6, x10, x3}, legs="ABC")
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
    renamed, _ = leg_names(lines, [("out[0]", x1 + x5 + x9)], {x1, x5, x9}, legs="ABC")
    assert [str(s) for s, _ in renamed] == ["x1", "x5", "x9"]


def test_program_symbols_are_never_renamed() -> None:
    lines = [(out_A, xA1 * c)]
    renamed, _ = leg_names(lines, [("out[0]", out_A)], set(), legs="ABC")
    assert renamed == lines


def test_a_parameter_name_is_never_taken() -> None:
    """The general PRR model has parameters ``x1_A``...: a temporary ``x1`` never takes one of
    their names, even where this function does not read them (the C backend finds parameters by
    name); the legs' names then join the letter with two underscores, or three."""
    lines = [(x1, xA1 * c), (x5, xB1 * c), (x9, xC1 * c)]
    outputs = [("out[0]", x1 + x5 + x9)]
    renamed, _ = leg_names(lines, outputs, {x1, x5, x9}, frozenset({"x1_B"}), legs="ABC")
    assert [str(s) for s, _ in renamed] == ["x1__A", "x1__B", "x1__C"]
    renamed, _ = leg_names(lines, outputs, {x1, x5, x9}, frozenset({"x1_B", "x1__C"}), legs="ABC")
    assert [str(s) for s, _ in renamed] == ["x1___A", "x1___B", "x1___C"]
    renamed, _ = leg_names(lines, outputs, {x1, x5, x9}, legs="ABC")
    assert [str(s) for s, _ in renamed] == ["x1_A", "x1_B", "x1_C"]


def test_six_legs_are_renamed_when_all_six_are_alike() -> None:
    """A hexapod's legs, ``ABCDEF``: six temporaries, one expression per leg, get the first
    one's number and each leg's letter; the same six read as legs ``ABC`` keep their names for
    D, E, F (no family of theirs), and where only three legs are alike no name changes."""
    legs = "ABCDEF"
    p = {leg: sp.Symbol(f"x{leg}1", real=True) for leg in legs}
    t = {leg: sp.Symbol(f"x{k * 4 + 1}", real=True) for k, leg in enumerate(legs)}
    lines = [(t[leg], p[leg] * c) for leg in legs]
    outputs = [("out[0]", sum(t.values()))]
    renamed, _ = leg_names(lines, outputs, set(t.values()), legs=legs)
    assert [str(x) for x, _ in renamed] == [f"x1_{leg}" for leg in legs]
    renamed, _ = leg_names(lines, outputs, set(t.values()), legs="ABC")
    assert [str(x) for x, _ in renamed] == ["x1_A", "x1_B", "x1_C", "x13", "x17", "x21"]
    mixed = [(t[leg], p[leg] * c if leg in "ABC" else p[leg] + c) for leg in legs]
    renamed, _ = leg_names(mixed, outputs, set(t.values()), legs=legs)
    assert renamed == mixed


def test_no_legs_no_names() -> None:
    lines = [(x1, xA1 * c), (x5, xB1 * c), (x9, xC1 * c)]
    outputs = [("out[0]", x1 + x5 + x9)]
    assert leg_names(lines, outputs, {x1, x5, x9}, legs="") == (lines, outputs)


def _tree(rng: random.Random, leaves: list[sp.Expr], depth: int) -> sp.Expr:
    """A random expression over ``leaves``: sums, products, powers, quotients, functions; not
    ``sin`` or ``cos``, whose argument SymPy puts in a sign that depends on the names (below)."""
    if depth == 0 or rng.random() < 0.25:
        return rng.choice(leaves)
    kind = rng.randrange(7)
    a = _tree(rng, leaves, depth - 1)
    b = _tree(rng, leaves, depth - 1)
    if kind == 0:
        return a + b + _tree(rng, leaves, depth - 1)
    if kind == 1:
        return a * b
    if kind == 2:
        return a - 2 * b
    if kind == 3:
        return a / (b + 3)
    if kind == 4:
        return a ** rng.choice((2, 3, -1))
    if kind == 5:
        return sp.atan2(a, b)
    return sp.exp(a) * sp.sqrt(b**2 + 1)


def test_shape_is_one_exactly_when_the_expressions_read_as_families_are_one() -> None:
    """``shape`` (the key by which both the renaming here and the NumPy lowering's leg groups
    compare two legs' expressions) against what it stands for: SymPy's equality after putting
    one symbol per family in place of each leg's (how both compared them before 2026-11-28, at
    ten times the cost). Each leg's copy of a random expression, and a copy with one leaf
    swapped, over symbols whose names sort differently from leg to leg (so SymPy orders the
    legs' terms differently): equal keys exactly for equal substitutes. As a check on the test,
    a key that takes a sum's terms in their order fails it."""
    rng = random.Random(20261128)
    shared = list(sp.symbols("c d", real=True))
    names = {"A": ("zA", "bA", "x1_A"), "B": ("aB", "yB", "x7_B"), "C": ("kC", "eC", "x4_C")}
    per_leg = {leg: list(sp.symbols(" ".join(n), real=True)) for leg, n in names.items()}
    family = {s: k for syms in per_leg.values() for k, s in enumerate(syms)}
    stand_in = {s: sp.Symbol(f"@{k}", real=True) for s, k in family.items()}
    pairs = 0
    for _ in range(150):
        template = _tree(rng, [sp.Symbol(f"t{k}", real=True) for k in range(3)] + shared, 4)
        copies = {
            leg: template.xreplace({sp.Symbol(f"t{k}", real=True): s for k, s in enumerate(syms)})
            for leg, syms in per_leg.items()
        }
        c0, c1 = per_leg["C"][:2]
        other = copies["C"].xreplace({c0: c1})
        swapped = copies["C"].xreplace({c0: c1, c1: c0})
        exprs = [copies["A"], copies["B"], copies["C"], other, swapped, copies["B"] + 1]
        keys = [shape(e, {s: family[s] for s in e.free_symbols if s in family}) for e in exprs]
        for i in range(len(exprs)):
            for j in range(i):
                same = exprs[i].xreplace(stand_in) == exprs[j].xreplace(stand_in)
                assert (keys[i] == keys[j]) == same, (exprs[i], exprs[j])
                pairs += same
    assert pairs > 300  # most pairs are one expression, so both answers were tested


def test_shape_keeps_apart_what_only_sympys_sign_rule_makes_one() -> None:
    """Where the legs' arguments of ``cos`` came out in opposite signs (SymPy writes ``cos(-u)``
    as ``cos(u)``, choosing the sign by the names), the substitutes are one expression but the
    trees are not: ``shape`` keeps them apart, as the lowering's rule (the same tree, the same
    operations on the same operands) asks; the old comparison took them as one."""
    zA, bA, aB, yB = sp.symbols("zA bA aB yB", real=True)
    a, b = sp.cos(bA - 2 * zA), sp.cos(2 * aB - yB)
    family = {zA: 0, aB: 0, bA: 1, yB: 1}
    stand_in = {s: sp.Symbol(f"@{k}", real=True) for s, k in family.items()}
    assert a.args[0] != b.args[0].xreplace({aB: zA, yB: bA})  # opposite signs
    assert a.xreplace(stand_in) == b.xreplace(stand_in)
    assert shape(a, family) != shape(b, family)


def test_shape_keeps_the_order_of_a_functions_operands() -> None:
    """A sum's and a product's terms are a multiset; ``atan2``'s and a power's operands are in
    order. (As a check on the test, a key with every operation's operands as a multiset fails
    it.)"""
    zA, bA, aB, yB = sp.symbols("zA bA aB yB", real=True)
    family = {zA: 0, aB: 0, bA: 1, yB: 1}
    assert shape(sp.atan2(zA, bA), family) == shape(sp.atan2(aB, yB), family)
    assert shape(sp.atan2(zA, bA), family) != shape(sp.atan2(yB, aB), family)
    assert shape(zA**bA, family) == shape(aB**yB, family)
    assert shape(zA**bA, family) != shape(yB**aB, family)
    assert shape(zA * bA + bA, family) == shape(yB + aB * yB, family)
