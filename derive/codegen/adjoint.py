"""Exact derivatives of a program's outputs by reverse mode (adjoints), as a new program.

A program (:mod:`.program`) computes its outputs ``y`` from inputs ``x`` in named statements
``s = f(a, b, ...)``. After common subexpressions are eliminated, each statement is small. Reverse
mode carries, for every output ``y_i`` at once (one lane per output), the adjoint ``s_bar_i =
d y_i / d s`` backwards through the statements: when every use of ``s`` has been seen, its
adjoint is complete, and each argument ``a`` of ``f`` receives ``s_bar_i * df/da``. The
adjoints of the inputs are the Jacobian's columns: ``d y_i / d x_j = x_bar_j,i``.

The cost is one forward pass, the partials ``df/da`` (shared by the lanes) and, per lane, one
multiply-add per (statement, argument) edge: about ``1 + 2 k`` times the forward pass for ``k``
outputs, whatever the number of inputs (forward mode would cost a pass per input: ``3 k``
inputs for ``d tau / d(q, q', q'')``). The derivatives are those of the statements as written:
exact, with no step and no truncation.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp
from rpr3gen_derive.codegen.cse import _live
from rpr3gen_derive.codegen.program import Program


def _small(expr: sp.Expr) -> bool:
    """Whether ``expr`` is cheap enough to repeat in every lane rather than name once."""
    return bool(expr.is_Atom or (expr.is_Mul and len(expr.args) == 2 and expr.args[0].is_Number
                                 and expr.args[1].is_Atom))  # fmt: skip


def _partial(expr: sp.Expr, arg: sp.Symbol) -> sp.Expr:
    """``d expr / d arg``: sums and products taken apart here (most statements are), SymPy's
    ``diff`` for the rest (functions, powers)."""
    if expr == arg:
        return sp.Integer(1)
    if expr.is_Add:
        return sp.Add(*(_partial(t, arg) for t in expr.args if arg in t.free_symbols))
    if expr.is_Mul:
        where = [k for k, f in enumerate(expr.args) if arg in f.free_symbols]
        if len(where) == 1:
            k = where[0]
            rest = sp.Mul(*expr.args[:k], *expr.args[k + 1 :])
            return rest * _partial(expr.args[k], arg)
    return sp.diff(expr, arg)


def _small_statements(
    program: Program, wanted: Sequence[sp.Expr], prefix: str
) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr], Program, dict[sp.Symbol, sp.Expr]]:
    """The live statements of ``program`` for ``wanted`` after common subexpression
    elimination, in order (each after the temporaries it uses), ``wanted`` reduced, and a new
    program holding them as ``{prefix}v0, ...`` with the renaming of their symbols."""
    live = _live(program, [("", e) for e in wanted])
    exprs = [e for _, e in live] + list(wanted)
    temporaries, reduced = sp.cse(
        exprs, symbols=sp.numbered_symbols(f"{prefix}t", real=True), order="canonical"
    )
    temp_defs = dict(temporaries)
    temp_order = {sym: k for k, (sym, _) in enumerate(temporaries)}
    emitted: set[sp.Symbol] = set()
    statements: list[tuple[sp.Symbol, sp.Expr]] = []

    def emit_temps_of(expr: sp.Expr) -> None:
        for sym in sorted(expr.free_symbols & temp_defs.keys(), key=temp_order.__getitem__):
            if sym not in emitted:
                emit_temps_of(temp_defs[sym])
                emitted.add(sym)
                statements.append((sym, temp_defs[sym]))

    for (sym, _), expr in zip(live, reduced[: len(live)], strict=True):
        emit_temps_of(expr)
        statements.append((sym, expr))
    out_exprs = list(reduced[len(live) :])
    for expr in out_exprs:
        emit_temps_of(expr)
    prog = Program()
    rename: dict[sp.Symbol, sp.Expr] = {}
    for k, (sym, expr) in enumerate(statements):
        rename[sym] = prog.define(f"{prefix}v{k}", expr.xreplace(rename), "forward")
    return statements, out_exprs, prog, rename


def reverse_mode(
    program: Program,
    outputs: Sequence[sp.Expr],
    wrt: Sequence[sp.Symbol],
    extra: Sequence[sp.Expr] = (),
    prefix: str = "d",
) -> tuple[Program, list[sp.Expr], list[list[sp.Expr]]]:
    """The program of ``outputs`` and of their Jacobian by ``wrt``.

    Returns ``(prog, values, jacobian)``: ``prog`` holds the forward statements (after common
    subexpression elimination, named ``{prefix}v0, ...``), the partials (``{prefix}p0, ...``)
    and the adjoints (``{prefix}a0, ...``); ``values`` are ``outputs`` then ``extra`` (values
    wanted without derivatives, e.g. the guards of the failure checks) and ``jacobian[i][j] = d
    outputs[i] / d wrt[j]``, all in ``prog``'s symbols. Symbols that are neither statements of
    ``program`` nor in ``wrt`` (the parameters) are constants.
    """
    statements, out_exprs, prog, rename = _small_statements(program, [*outputs, *extra], prefix)
    values = [e.xreplace(rename) for e in out_exprs]
    forward = [(rename[sym], expr.xreplace(rename)) for sym, expr in statements]

    variables = {s for s, _ in forward} | set(wrt)
    lanes = len(outputs)
    # adjoint terms per symbol and lane
    bar: dict[sp.Symbol, list[list[sp.Expr]]] = {}
    counter = {"p": 0, "a": 0}

    def partial(expr: sp.Expr, arg: sp.Symbol) -> sp.Expr:
        d = _partial(expr, arg)
        if d == 0 or _small(d):
            return d
        name = f"{prefix}p{counter['p']}"
        counter["p"] += 1
        return prog.define(name, d, "partials")

    def spread(expr: sp.Expr, seeds: list[sp.Expr]) -> None:
        """Add ``seeds[i] * d expr / d a`` to the adjoint of each variable ``a`` in ``expr``."""
        for arg in sorted(expr.free_symbols & variables, key=str):
            d = partial(expr, arg)
            if d == 0:
                continue
            terms = bar.setdefault(arg, [[] for _ in range(lanes)])
            for i, seed in enumerate(seeds):
                if seed != 0:
                    terms[i].append(seed * d)

    for i, value in enumerate(values[:lanes]):
        spread(value, [sp.Integer(1) if j == i else sp.Integer(0) for j in range(lanes)])
    for sym, expr in reversed(forward):
        terms = bar.pop(sym, None)
        if terms is None:
            continue
        seeds = []
        for lane in terms:
            total = sp.Add(*lane)
            if total != 0 and not _small(total):
                total = prog.define(f"{prefix}a{counter['a']}", total, "adjoints")
                counter["a"] += 1
            seeds.append(total)
        spread(expr, seeds)
    jacobian = [
        [sp.Add(*bar[w][i]) if w in bar else sp.Integer(0) for w in wrt] for i in range(lanes)
    ]
    return prog, values, jacobian
