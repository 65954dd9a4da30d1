"""The NumPy lowering's folding passes: copies and negations substituted into their uses
(:func:`fold_copies`), values named by their opposite where that saves a call
(:func:`fold_signs`); :mod:`.lowering` explains why."""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.backends.python.emitter import _Lowering
from rpr3gen_derive.codegen.cse import StraightLine


def _is_copy_or_negation(expr: sp.Expr) -> bool:
    return expr.is_Symbol or (expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1
                              and expr.args[1].is_Symbol)  # fmt: skip


def fold_copies(
    code: StraightLine, scalars: set[sp.Symbol]
) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[tuple[str, sp.Expr]]]:
    """``code``'s assignments and outputs with every per-sample copy or negation of another
    value substituted into its uses (in order, so chains fold too)."""
    scalar = set(scalars)
    folded: dict[sp.Symbol, sp.Expr] = {}
    statements = []
    for lhs, rhs in code.assignments:
        rhs = rhs.xreplace(folded) if folded else rhs
        if rhs.free_symbols <= scalar:
            scalar.add(lhs)
        elif _is_copy_or_negation(rhs):
            folded[lhs] = rhs
            continue
        statements.append((lhs, rhs))
    outputs = [(name, expr.xreplace(folded)) for name, expr in code.outputs]
    return statements, outputs


class _Anywhere(dict):  # type: ignore[type-arg]
    """Locations for a dry run: every symbol lives in a row of its own name."""

    def __missing__(self, symbol: sp.Symbol) -> str:
        return str(symbol)


def _calls_of(expr: sp.Expr, scalars: set[sp.Symbol], output: bool = False) -> int:
    """The ufunc calls :meth:`_Lowering.emit` spends on ``expr`` (a dry run); an output that is
    a bare symbol costs none (it is computed in its row)."""
    if output and expr.is_Symbol:
        return 0
    state = _Lowering(scalars=scalars)
    state.location = _Anywhere()
    state.emit(expr, None if output else "dest")
    return sum(1 for line in state.lines if not line.startswith("numpy.copyto"))


def _sign_safe(expr: sp.Expr, symbol: sp.Symbol) -> bool:
    """``symbol`` occurs in ``expr`` only under sums, products, integer powers and ``Abs``:
    there ``-symbol`` is exactly the same value, its sign taken by SymPy's own folding
    (``a + -s`` is ``a - s``). Under ``sin``, ``atan2``, ``sqrt`` ... it is not."""
    if symbol not in expr.free_symbols:
        return True
    if expr.is_Symbol:
        return True
    if expr.is_Add or expr.is_Mul or isinstance(expr, sp.Abs):
        return all(_sign_safe(arg, symbol) for arg in expr.args)
    if expr.is_Pow and expr.args[1].is_Integer:
        return _sign_safe(expr.args[0], symbol)
    return False


def _negated(expr: sp.Expr) -> bool:
    """``expr`` costs a sign change of its own: ``-(a b)``, or a sum of negative terms only."""
    if expr.is_Mul:
        return expr.as_coeff_Mul()[0] == -1
    if expr.is_Add:
        return all(t.as_coeff_Mul()[0].is_negative for t in expr.args)
    return False


def fold_signs(
    statements: list[tuple[sp.Symbol, sp.Expr]],
    outputs: list[tuple[str, sp.Expr]],
    scalars: set[sp.Symbol],
) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[tuple[str, sp.Expr]]]:
    """Name the opposite of a value when that saves sign changes: ``t = -(a b)`` (two calls,
    the product and its sign) becomes ``t = a b`` with ``-t`` in its uses, where a sum or a
    product absorbs the sign at no cost (``c + t`` becomes ``c - t``), and an output ``-t``
    becomes ``t``, computed in its row. A statement is flipped, in program order, when a dry
    run of the lowering (:func:`_calls_of`) spends fewer calls on it and its uses; and only
    where every use is a sum, product, integer power or ``Abs`` of it (:func:`_sign_safe`), so
    the values are the same, bit for bit but for the order of a sum's terms."""
    statements = list(statements)
    outputs = list(outputs)
    users: dict[sp.Symbol, list[int]] = {}
    for index, (_, rhs) in enumerate(statements):
        for sym in rhs.free_symbols:
            users.setdefault(sym, []).append(index)
    readers: dict[sp.Symbol, list[int]] = {}
    for index, (_, expr) in enumerate(outputs):
        for sym in expr.free_symbols:
            readers.setdefault(sym, []).append(index)
    scalar = set(scalars)

    def cost(rhs: sp.Expr, uses: list[sp.Expr], outs: list[sp.Expr]) -> int:
        return (_calls_of(rhs, scalar) + sum(_calls_of(e, scalar) for e in uses)
                + sum(_calls_of(e, scalar, output=True) for e in outs))  # fmt: skip

    for index, (lhs, rhs) in enumerate(statements):
        if rhs.free_symbols <= scalar:
            scalar.add(lhs)
            continue
        read = readers.get(lhs, [])
        if not (_negated(rhs) or any(outputs[k][1] == -lhs for k in read)):
            continue
        used = users.get(lhs, [])
        uses = [statements[k][1] for k in used]
        outs = [outputs[k][1] for k in read]
        if not all(_sign_safe(e, lhs) for e in uses + outs):
            continue
        flip = {lhs: -lhs}
        new_rhs, new_uses = -rhs, [e.xreplace(flip) for e in uses]
        new_outs = [e.xreplace(flip) for e in outs]
        if cost(new_rhs, new_uses, new_outs) < cost(rhs, uses, outs):
            statements[index] = (lhs, new_rhs)
            for k, e in zip(used, new_uses, strict=True):
                statements[k] = (statements[k][0], e)
            for k, e in zip(read, new_outs, strict=True):
                outputs[k] = (outputs[k][0], e)
    return statements, outputs
