"""The parts of a program's outputs that are affine in some inputs, in one pass (forward mode).

Where a program's outputs are affine in inputs ``a`` (the efforts in the accelerations: ``tau =
T q'' + tau0``), both parts come from one pass over its statements. A statement ``s = f(x,
...)`` that does not read ``a``, directly or through earlier statements, is kept as it is: the
kinematics, the velocity terms, everything that depends on the other inputs alone, computed
once. A statement that does becomes its value at ``a = 0`` (under its own name: so ``s`` means
its value there in every later statement) and one tangent per input ``a_j``, ``s_j = sum_x
df/dx s_x_j`` (``x`` over the arguments that read ``a``; ``a_i``'s tangents are ``delta_ij``),
the partials taken at ``a = 0``. The outputs' values at ``a = 0`` are ``tau0``; their tangents
are ``d tau / d a``, which is ``T`` at every ``a`` since the outputs are affine in ``a``. The
statements are the program's own, before common subexpressions are eliminated, so that the
engine eliminates them across the whole (the tangents share the values' partials) and names
each leg's statements alike (:mod:`.legnames`): a tangent of ``s_A`` is named ``s_A{suffix}j``.

The tangents are exact (the statements' derivatives as written, no step); a tangent that is
an atom is no statement: zero (a statement that reads ``a_1`` alone has no other), a symbol or
a number.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp
from rpr3gen_derive.codegen.adjoint import _partial
from rpr3gen_derive.codegen.cse import _live
from rpr3gen_derive.codegen.program import Program


def affine_parts(
    program: Program,
    outputs: Sequence[sp.Expr],
    wrt: Sequence[sp.Symbol],
    extra: Sequence[sp.Expr] = (),
    suffix: str = "_t",
) -> tuple[Program, list[sp.Expr], list[list[sp.Expr]]]:
    """The program of ``outputs`` at ``wrt = 0`` and of their derivatives by ``wrt``.

    Returns ``(prog, values, tangents)``: ``values`` are ``outputs`` at ``wrt = 0`` then
    ``extra`` (values wanted without derivatives, e.g. the failure checks' guards; they must not
    read ``wrt``), ``tangents[i][j] = d outputs[i] / d wrt[j]`` at ``wrt = 0``, all in
    ``prog``'s symbols. ``prog`` holds the live statements of ``program`` in its order, each
    followed by its tangents (``{name}{suffix}{j}``).
    """
    zero = {w: sp.Integer(0) for w in wrt}
    # a symbol that reads wrt -> its tangents (one per input of wrt)
    tangents: dict[sp.Symbol, list[sp.Expr]] = {
        w: [sp.Integer(int(i == j)) for j in range(len(wrt))] for i, w in enumerate(wrt)
    }
    atoms: dict[sp.Symbol, sp.Expr] = {}  # statements whose value at wrt = 0 is an atom
    prog = Program()
    names = {a.symbol.name for a in program.assignments}
    steps = {a.symbol: a.step for a in program.assignments}

    def split(expr: sp.Expr) -> tuple[sp.Expr, list[sp.Expr]] | None:
        """``expr``'s value at ``wrt = 0`` and its tangents; None where it does not read
        ``wrt``."""
        args = sorted(expr.free_symbols & tangents.keys(), key=str)
        if not args:
            return None
        lanes: list[sp.Expr] = [sp.Integer(0)] * len(wrt)
        for arg in args:
            d = _partial(expr, arg)
            if d == 0:
                continue
            d = d.xreplace(zero).xreplace(atoms)
            for j, t in enumerate(tangents[arg]):
                if t != 0:
                    lanes[j] += d * t
        return expr.xreplace(zero).xreplace(atoms), lanes

    for sym, expr in _live(program, [("", e) for e in [*outputs, *extra]]):
        parts = split(expr)
        if parts is None:
            prog.define(sym.name, expr.xreplace(atoms), steps[sym])
            continue
        value, lanes = parts
        step = steps[sym]
        defined = prog.define(sym.name, value, step)
        if defined != sym:
            atoms[sym] = defined
        own: list[sp.Expr] = []
        for j, lane in enumerate(lanes):
            name = f"{sym.name}{suffix}{j}"
            if name in names:
                raise ValueError(f"tangent {name!r} is a statement's name")
            own.append(prog.define(name, lane, step))
        tangents[sym] = own
    values = []
    jacobian = []
    for expr in outputs:
        parts = split(expr)
        if parts is None:
            values.append(expr.xreplace(atoms))
            jacobian.append([sp.Integer(0)] * len(wrt))
        else:
            values.append(parts[0])
            jacobian.append(parts[1])
    for expr in extra:
        if split(expr) is not None:
            raise ValueError("an extra value reads the inputs of the tangents")
        values.append(expr.xreplace(atoms))
    return prog, values, jacobian
