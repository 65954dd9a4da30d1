"""Calculus on derivation programs: differentiate, zero and solve, assignment by assignment.

The control model and the identification are derived from the inverse-dynamics program (eqs.
5-17) without ever expanding it down to the inputs: :func:`differentiate_factored` carries
forward-mode derivatives through the program one assignment at a time, :func:`at_zero` copies
only the assignments that depend on the variables set to zero, and :class:`Builder` appends
assignments that may already exist. :func:`ldlt_solve` and :func:`cofactor_solve` solve 3 x 3
systems as named assignments.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp
from rpr3gen_derive.codegen.program import Program


class Builder:
    """Defines assignments in a program, reusing one that has the same right-hand side.

    An assignment of the same name and right-hand side is reused (so that the functions of this
    module can share a program in any order); with ``share``, so is one of another name (so that,
    e.g., the derivative of a velocity and of an acceleration by the same input is one symbol).
    """

    def __init__(self, prog: Program, reserved: frozenset[str] = frozenset()) -> None:
        self.prog = prog
        self.reserved = reserved
        self.existing = prog.definitions()
        self.by_expr: dict[sp.Expr, sp.Symbol] = {}
        for symbol, expr in self.existing.items():
            self.by_expr.setdefault(expr, symbol)

    def define(self, name: str, expr: sp.Expr, step: str, share: bool = True) -> sp.Expr:
        expr = sp.sympify(expr)
        if name in self.reserved:
            raise ValueError(f"{name!r} is an input or a parameter, not a name for an assignment")
        symbol = sp.Symbol(name, real=True)
        if symbol in self.existing:
            if self.existing[symbol] != expr:
                raise ValueError(f"{name} is already defined differently in the program")
            return symbol
        if share and expr in self.by_expr:
            return self.by_expr[expr]
        out = self.prog.define(name, expr, step)
        if out == symbol:
            self.existing[symbol] = expr
            self.by_expr.setdefault(expr, symbol)
        return out


def _needed(prog: Program, exprs: Sequence[sp.Expr]) -> set[sp.Symbol]:
    """The program symbols that ``exprs`` depend on, directly or through other assignments."""
    definitions = prog.definitions()
    needed: set[sp.Symbol] = set()
    stack = [s for e in exprs for s in sp.sympify(e).free_symbols]
    while stack:
        s = stack.pop()
        if s in needed or s not in definitions:
            continue
        needed.add(s)
        stack.extend(definitions[s].free_symbols)
    return needed


def _ordered(symbols: set[sp.Symbol]) -> list[sp.Symbol]:
    return sorted(symbols, key=lambda s: s.name)


#: A derivative in factored form: ``sum of coefficient * seed``, the seed a vector over ``wrt``.
Factored = list[tuple[sp.Expr, tuple[sp.Expr, ...]]]


def differentiate_factored(
    prog: Program, exprs: Sequence[sp.Expr], wrt: Sequence[sp.Symbol], step: str
) -> list[Factored]:
    """Forward-mode derivatives of ``exprs`` by ``wrt``, one assignment of ``prog`` at a time.

    The derivative of an assignment is kept as a sum over a few *seed* vectors with scalar
    coefficients: a seed is the vector of direct partial derivatives ``d_{name}_d_{var}`` of an
    assignment that uses ``wrt`` itself (e.g. the acceleration of A3 along a leg's normal, by
    ``q''``), and every later assignment only combines the coefficients of its arguments by the
    chain rule (``k_{name}__{seed}``, one scalar each, shared by all the variables). So a leg's
    whole chain of wrenches costs a few scalars, and its share of the mass matrix stays a rank-one
    product. Nothing is expanded down to the inputs.
    """
    wrt = list(wrt)
    needed = _needed(prog, exprs)
    bld = Builder(prog)
    seeds: list[tuple[str, tuple[sp.Expr, ...]]] = []
    seed_of: dict[tuple[sp.Expr, ...], int] = {}
    tangent: dict[sp.Symbol, dict[int, sp.Expr]] = {}

    def chain(expr: sp.Expr, name: str | None) -> dict[int, sp.Expr]:
        terms: dict[int, sp.Expr] = {}
        for a in _ordered(expr.free_symbols & tangent.keys()):
            partial = sp.diff(expr, a)
            for index, coeff in tangent[a].items():
                terms[index] = terms.get(index, sp.Integer(0)) + partial * coeff
        direct = [sp.diff(expr, var) for var in wrt]
        if any(d != 0 for d in direct):
            if name is None:
                vector = tuple(direct)
            else:
                vector = tuple(
                    bld.define(f"d_{name}_d_{var.name}", d, step)
                    for var, d in zip(wrt, direct, strict=True)
                )
            if vector not in seed_of:
                seed_of[vector] = len(seeds)
                seeds.append((name or f"seed{len(seeds)}", vector))
            index = seed_of[vector]
            terms[index] = terms.get(index, sp.Integer(0)) + 1
        return {i: c for i, c in terms.items() if c != 0}

    for a in list(prog.assignments):
        if a.symbol not in needed or not a.expr.free_symbols & (tangent.keys() | set(wrt)):
            continue
        terms = chain(a.expr, a.symbol.name)
        tangent[a.symbol] = {
            i: bld.define(f"k_{a.symbol.name}__{seeds[i][0]}", c, step) for i, c in terms.items()
        }
    out = []
    for expr in exprs:
        terms = chain(sp.sympify(expr), None)
        out.append([(c, seeds[i][1]) for i, c in sorted(terms.items())])
    return out


def expand_factored(factored: Factored, size: int) -> list[sp.Expr]:
    """The derivative vector ``sum_i coeff_i * seed_i`` of a factored derivative."""
    return [sum((c * seed[k] for c, seed in factored), sp.Integer(0)) for k in range(size)]


def differentiate(
    prog: Program, exprs: Sequence[sp.Expr], wrt: Sequence[sp.Symbol], step: str
) -> list[list[sp.Expr]]:
    """``d exprs[i] / d wrt[k]`` as a ``len(exprs) x len(wrt)`` table (see
    :func:`differentiate_factored`, which names the intermediate derivatives in ``prog``)."""
    factored = differentiate_factored(prog, exprs, wrt, step)
    return [expand_factored(f, len(wrt)) for f in factored]


def at_zero(
    prog: Program, exprs: Sequence[sp.Expr], variables: Sequence[sp.Symbol], suffix: str, step: str
) -> list[sp.Expr]:
    """``exprs`` with ``variables`` set to zero, as new assignments ``{name}{suffix}``.

    Only the assignments that depend on ``variables`` are copied; the rest are shared.
    """
    needed = _needed(prog, exprs)
    bld = Builder(prog)
    replace: dict[sp.Symbol, sp.Expr] = {v: sp.Integer(0) for v in variables}
    for a in list(prog.assignments):
        if a.symbol in needed and a.expr.free_symbols & replace.keys():
            replace[a.symbol] = bld.define(
                f"{a.symbol.name}{suffix}", a.expr.xreplace(replace), step
            )
    return [sp.sympify(e).xreplace(replace) for e in exprs]


def depends_on(prog: Program, expr: sp.Expr, variables: Sequence[sp.Symbol]) -> bool:
    """True when ``expr`` depends on ``variables``, directly or through assignments."""
    definitions = prog.definitions()
    targets = set(variables)
    seen: set[sp.Symbol] = set()
    stack = list(sp.sympify(expr).free_symbols)
    while stack:
        s = stack.pop()
        if s in targets:
            return True
        if s in seen or s not in definitions:
            continue
        seen.add(s)
        stack.extend(definitions[s].free_symbols)
    return False


def ldlt_solve(prog: Program, M: sp.Matrix, rhs: sp.Matrix, name: str, step: str) -> sp.Matrix:
    """Solve ``M x = rhs`` for a symmetric positive definite 3 x 3 ``M`` by ``M = L D L^T``.

    No square root; three divisions (the pivots ``D``). Every factor is a named assignment
    ``{name}_...``; only the upper triangle of ``M`` is read.
    """
    bld = Builder(prog)
    d1 = bld.define(f"{name}_d1", M[0, 0], step)
    inv_d1 = bld.define(f"{name}_inv_d1", 1 / d1, step)
    l21 = bld.define(f"{name}_l21", M[0, 1] * inv_d1, step)
    l31 = bld.define(f"{name}_l31", M[0, 2] * inv_d1, step)
    d2 = bld.define(f"{name}_d2", M[1, 1] - l21 * M[0, 1], step)
    inv_d2 = bld.define(f"{name}_inv_d2", 1 / d2, step)
    l32 = bld.define(f"{name}_l32", (M[1, 2] - l21 * M[0, 2]) * inv_d2, step)
    d3 = bld.define(f"{name}_d3", M[2, 2] - l31 * M[0, 2] - l32**2 * d2, step)
    inv_d3 = bld.define(f"{name}_inv_d3", 1 / d3, step)
    z1 = rhs[0]
    z2 = bld.define(f"{name}_z2", rhs[1] - l21 * z1, step)
    z3 = bld.define(f"{name}_z3", rhs[2] - l31 * z1 - l32 * z2, step)
    x3 = bld.define(f"{name}_x3", z3 * inv_d3, step)
    x2 = bld.define(f"{name}_x2", z2 * inv_d2 - l32 * x3, step)
    x1 = bld.define(f"{name}_x1", z1 * inv_d1 - l21 * x2 - l31 * x3, step)
    return sp.Matrix([x1, x2, x3])


def cofactor_solve(prog: Program, A: sp.Matrix, rhs: sp.Matrix, name: str, step: str) -> sp.Matrix:
    """Solve ``A x = rhs`` for a general 3 x 3 ``A`` by cofactors: ``x = adj(A) rhs / det A``.

    The entries of ``A`` are named first (``{name}_A11`` ...), so the adjugate multiplies names,
    and ``1 / det A`` is one division.
    """
    bld = Builder(prog)
    a = sp.Matrix(3, 3, lambda i, j: bld.define(f"{name}_A{i + 1}{j + 1}", A[i, j], step))
    adj = a.adjugate()
    det = bld.define(f"{name}_det", sum(a[0, j] * adj[j, 0] for j in range(3)), step)
    inv_det = bld.define(f"{name}_inv_det", 1 / det, step)
    return sp.Matrix(
        [
            bld.define(
                f"{name}_x{i + 1}", sum(adj[i, j] * rhs[j] for j in range(3)) * inv_det, step
            )
            for i in range(3)
        ]
    )
