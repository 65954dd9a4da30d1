"""Common subexpression elimination over a program, deterministically ordered.

The program's right-hand sides and a function's outputs are passed to ``sympy.cse`` together,
in program order, with ``order="canonical"``; the result is a straight-line list of assignments
in which every temporary comes right before its first use. Assignments that no output needs are
dropped. The temporaries of one leg are then named after the first leg's (:mod:`.legnames`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp
from rpr3gen_derive.codegen.legnames import leg_names
from rpr3gen_derive.codegen.program import Program


@dataclass(frozen=True)
class StraightLine:
    """Code ready to print: ``assignments`` in order, then ``outputs`` (label, expression)."""

    assignments: tuple[tuple[sp.Symbol, sp.Expr], ...]
    outputs: tuple[tuple[str, sp.Expr], ...]
    ops_before: int
    ops_after: int


def count_ops(exprs: list[sp.Expr]) -> int:
    """Arithmetic and function operations, as ``sympy.count_ops`` counts them."""
    return sum(_ops(e) for e in exprs)


@lru_cache(maxsize=1 << 16)
def _ops(expr: sp.Expr) -> int:
    # Memoised: a variant's functions share most of the program they count (a fifth of its
    # generation time, uncached).
    return int(sp.count_ops(expr))


def _live(
    program: Program, outputs: Sequence[tuple[str, sp.Expr]]
) -> list[tuple[sp.Symbol, sp.Expr]]:
    """The program's assignments that some output depends on, in program order."""
    needed: set[sp.Symbol] = set()
    for _, expr in outputs:
        needed |= expr.free_symbols
    live = []
    for a in reversed(program.assignments):
        if a.symbol in needed:
            live.append((a.symbol, a.expr))
            needed |= a.expr.free_symbols
    live.reverse()
    return live


def straight_line(
    program: Program,
    outputs: Sequence[tuple[str, sp.Expr]],
    reserved: frozenset[str] = frozenset(),
    eliminate: bool = True,
    legs: str = "",
) -> StraightLine:
    """Eliminate common subexpressions across ``program`` and the ``(label, expr)`` outputs;
    ``reserved``: names a renamed temporary must not take (the parameters', the inputs');
    ``eliminate`` False: the program is already free of them (as :mod:`.adjoint` writes it),
    its live statements are kept as they are; ``legs``: the module's legs' letters, whose
    temporaries get per-leg names."""
    live = _live(program, outputs)
    exprs = [expr for _, expr in live] + [expr for _, expr in outputs]
    ops_before = count_ops(exprs)
    if eliminate:
        temporaries, reduced = sp.cse(
            exprs, symbols=sp.numbered_symbols("x", real=True), order="canonical"
        )
    else:
        temporaries, reduced = [], exprs
    temp_defs = dict(temporaries)
    temp_order = {sym: k for k, (sym, _) in enumerate(temporaries)}
    emitted: set[sp.Symbol] = set()
    lines: list[tuple[sp.Symbol, sp.Expr]] = []

    def emit_temps_of(expr: sp.Expr) -> None:
        for sym in sorted(expr.free_symbols & temp_defs.keys(), key=temp_order.__getitem__):
            if sym not in emitted:
                emit_temps_of(temp_defs[sym])
                emitted.add(sym)
                lines.append((sym, temp_defs[sym]))

    for (sym, _), expr in zip(live, reduced[: len(live)], strict=True):
        emit_temps_of(expr)
        lines.append((sym, expr))
    result = []
    for (name, _), expr in zip(outputs, reduced[len(live) :], strict=True):
        emit_temps_of(expr)
        result.append((name, expr))
    lines, result = leg_names(lines, result, set(temp_defs), reserved, legs=legs)
    ops_after = count_ops([expr for _, expr in lines] + [expr for _, expr in result])
    return StraightLine(tuple(lines), tuple(result), ops_before, ops_after)
