"""Partition a straight-line program for the C batch loop, so that the compiler can vectorise it.

A call into libm keeps a loop scalar. The generated C has kernels of its own for everything the
derivations use (``sin``, ``cos``, ``atan2``, ``Min``, ``Max``, the rounding of ``wrap_angle``:
:mod:`rpr3gen_derive.codegen.mathkernels`; ``sqrt`` and ``fabs`` are instructions), so with
them every statement vectorises; any other call (``exp``, ``pow``...) would not. The batch
function therefore evaluates a block of samples in three passes:

A. scalar, per sample: the inputs, and the statements that call libm early and what they depend
   on (none, with the kernels); their results go to block arrays;
B. per sample, no libm calls: everything else, in a loop that the compiler vectorises across
   samples (structure of arrays, no aliasing);
C. scalar, per sample: the late libm calls, the validity checks and the row-major stores.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.cse import StraightLine
from rpr3gen_derive.codegen.functions import wrap_angle

#: A call whose dependencies number more than this is late (pass C), not early (pass A).
EARLY_LIMIT = 20


#: Functions printed as instructions or as the generated C's own kernels: they vectorise.
VECTORISABLE = (sp.Abs, sp.sin, sp.cos, sp.atan2, sp.Min, sp.Max, wrap_angle)


def calls_libm(expr: sp.Expr) -> bool:
    """True if printing ``expr`` in C calls a math function that blocks vectorisation.

    ``sqrt`` vectorises where ``errno`` is off (``-fno-math-errno``, as the runtime builds);
    other powers that are not products become ``pow``.
    """
    for node in sp.preorder_traversal(expr):
        if isinstance(node, sp.Function) and not isinstance(node, VECTORISABLE):
            return True
        small = node.is_Pow and node.exp.is_Integer and abs(node.exp) <= 3
        if node.is_Pow and not (small or abs(node.exp) == sp.Rational(1, 2)):
            return True
    return False


class NotSplittableError(ValueError):
    """The program does not fit the three passes: its batch calls the single-sample kernel."""


@dataclass(frozen=True)
class BatchPlan:
    """Which statement runs in which pass, and which values cross between passes."""

    constants: tuple[tuple[sp.Symbol, sp.Expr], ...]  # parameters only: once per batch call
    pass_a: tuple[tuple[sp.Symbol, sp.Expr], ...]
    pass_b: tuple[tuple[sp.Symbol, sp.Expr], ...]
    pass_c: tuple[tuple[sp.Symbol, sp.Expr], ...]
    a_to_b: tuple[sp.Symbol, ...]  # pass-A values (and inputs) read by pass B
    a_to_c: tuple[sp.Symbol, ...]  # pass-A values (and inputs) read by pass C
    b_to_c: tuple[sp.Symbol, ...]  # pass-B values read by pass C
    outputs_b: tuple[tuple[int, sp.Expr], ...]  # outputs computed in pass B
    outputs_c: tuple[tuple[int, sp.Expr], ...]  # outputs computed in pass C


def plan(code: StraightLine, inputs: set[sp.Symbol], params: set[sp.Symbol]) -> BatchPlan:
    """Split ``code`` into passes; ``inputs`` are per-sample, ``params`` per call."""
    statements = list(code.assignments)
    rhs_of = dict(statements)
    scalar = set(params)
    constants = []
    for lhs, rhs in statements:
        if rhs.free_symbols <= scalar:
            scalar.add(lhs)
            constants.append((lhs, rhs))

    def closure(sym: sp.Symbol) -> set[sp.Symbol]:
        seen: set[sp.Symbol] = set()
        stack = [sym]
        while stack:
            s = stack.pop()
            if s in seen or s not in rhs_of or s in scalar:
                continue
            seen.add(s)
            stack.extend(rhs_of[s].free_symbols)
        return seen

    early: set[sp.Symbol] = set()
    late: set[sp.Symbol] = set()
    for lhs, rhs in statements:
        if lhs in scalar or not calls_libm(rhs):
            continue
        deps = closure(lhs)
        if len(deps) <= EARLY_LIMIT:
            early |= deps
        else:
            late.add(lhs)
    users: dict[sp.Symbol, set[sp.Symbol]] = {}
    for lhs, rhs in statements:
        for s in rhs.free_symbols:
            users.setdefault(s, set()).add(lhs)
    for s in late:
        if users.get(s):
            raise NotSplittableError(
                f"late call {s} is used by other statements: {sorted(map(str, users[s]))}"
            )
    order = [lhs for lhs, _ in statements if lhs not in scalar]
    pass_a = tuple((s, rhs_of[s]) for s in order if s in early)
    pass_c = tuple((s, rhs_of[s]) for s in order if s in late)
    pass_b = tuple((s, rhs_of[s]) for s in order if s not in early and s not in late)
    b_names = {s for s, _ in pass_b}

    outputs_b: list[tuple[int, sp.Expr]] = []
    outputs_c: list[tuple[int, sp.Expr]] = []
    for k, (_, expr) in enumerate(code.outputs):
        (outputs_c if expr.free_symbols & late else outputs_b).append((k, expr))

    def reads(exprs) -> set[sp.Symbol]:
        return set().union(*(e.free_symbols for e in exprs)) if exprs else set()

    b_exprs = [e for _, e in pass_b] + [e for _, e in outputs_b]
    c_exprs = [e for _, e in pass_c] + [e for _, e in outputs_c]
    a_names = early | inputs
    order_of = {s: k for k, s in enumerate([*sorted(inputs, key=str), *order])}
    a_to_b = tuple(sorted(reads(b_exprs) & a_names, key=order_of.__getitem__))
    a_to_c = tuple(sorted(reads(c_exprs) & a_names, key=order_of.__getitem__))
    b_to_c = tuple(sorted(reads(c_exprs) & b_names, key=order_of.__getitem__))
    return BatchPlan(
        tuple(constants),
        pass_a,
        pass_b,
        pass_c,
        a_to_b,
        a_to_c,
        b_to_c,
        tuple(outputs_b),
        tuple(outputs_c),
    )
