"""Lower a straight-line program to NumPy ufunc calls into preallocated buffers.

Each operation becomes one ufunc call with its output given, writing into a row of a work array
that is allocated once per call; a row is reused as soon as the value in it is dead, so the
working set of a block of samples stays in cache and no temporary array is allocated per
operation. Subexpressions of parameters only are computed once per call as Python scalars.
Outputs that are named intermediates are computed straight into their row of ``out``.

A call's fixed cost is most of a small block's time, so each call is the cheapest form of the
same operation (the same values, bit for bit): the ufunc through a module-level name
(``_multiply = numpy.multiply``), its output passed by position, and a scalar operand as a
0-d array (a Python or NumPy scalar is converted to one at every call, ~0.3 us): the module's
number constants once at import (:attr:`_Lowering.constants`), a function's parameter
expressions once per call, at the head of its body.

Every ufunc call costs a pass over the block and a fixed ~0.3 us of dispatch, so the lowering
first folds away the assignments that are only a copy or a negation of another value
(``x1 = -L``, ``omega = x6``): substituted into their uses, SymPy's own simplification turns
``-x1 - c`` into ``L - c``, one call instead of three. The C code keeps them (its compiler
folds them). Then a value whose own sign costs a call (``t = -(a b)``) is named by its opposite
where its uses take the sign for free (:func:`fold_signs`): 3-4 % fewer calls in the inverse
dynamics. ``atan2`` is the module's ``_atan2`` (``numpy.arctan`` of the quotient and the
quadrant's multiple of pi: ~12 ns a value where ``numpy.arctan2`` costs ~20), ``sin`` and ``cos``
of one argument its ``_sincos``.

The legs' statements that are one expression (:func:`leg_groups`, as the C's lanes) run as one
call each operation on a (legs, n) block of consecutive work rows (``t12``: rows 12 to 14 for
three legs, to 17 for six), the legs' parameters as a (legs, 1) column; the legs are the
module's (``legs``: ``ABC``, ``ABCDEF``). A group is placed where its first statement was,
after what it reads (:func:`_units`), and each leg's row is freed when that leg's value is dead.
The inverse dynamics makes ~40 % fewer calls (602 to 370, prismatic): 5 % less time at 10^4
samples, the same at 10^5 (docs/performance-log.md). The values are each leg's own, the terms of a
sum possibly in another order (round-off).

Last, each output row is summed into the function's ``sums`` argument right after the last line
that names it (:func:`add_sums`): the runtime's failure checks learn from these sums that every
output is finite without reading the block's outputs again, out of cache.
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.backends.python.emitter import (
    SINCOS_WORK,
    LoweredNumpy,
    _Lowering,
    trig_pairs,
)
from rpr3gen_derive.codegen.backends.python.folding import fold_copies, fold_signs
from rpr3gen_derive.codegen.backends.python.groups import _units, leg_groups
from rpr3gen_derive.codegen.backends.python.printer import numpy_code
from rpr3gen_derive.codegen.backends.python.sums import ROW_PATTERN, add_sums
from rpr3gen_derive.codegen.cse import StraightLine


def lower_numpy(
    code: StraightLine,
    inputs: dict[sp.Symbol, str],
    params: set[sp.Symbol],
    output_rows: dict[str, str],
    constants: dict[str, str] | None = None,
    legs: str = "",
) -> LoweredNumpy:
    """Lower ``code`` given where inputs live (``{x: "x"}``) and each output's row text.

    ``constants``: the module's number constants so far (text -> name), added to in place, so
    that the module's functions share them; ``legs``: the module's legs' letters."""
    statements, outputs = fold_copies(code, params)
    statements, outputs = fold_signs(statements, outputs, set(params))
    # Output rows: an output that is a named intermediate is computed in place.
    alias: dict[sp.Symbol, str] = {}
    for name, expr in outputs:
        if expr.is_Symbol and expr not in alias and expr not in inputs:
            alias[expr] = output_rows[name]
    member = leg_groups(statements, set(params), alias, legs)
    units = _units(statements, member)
    uses: dict[sp.Symbol, int] = {}  # index of each symbol's last use (by unit)
    for index, unit in enumerate(units):
        for _, rhs in unit:
            for sym in rhs.free_symbols:
                uses[sym] = index
    for _, expr in outputs:  # read by an output: alive to the end
        for sym in expr.free_symbols:
            uses[sym] = len(units)
    state = _Lowering(
        scalars=set(params), legs=len(legs), constants={} if constants is None else constants
    )
    state.location.update(inputs)
    scalar_lines: list[str] = []
    rhs_of = dict(statements)
    pairs = {
        a: b
        for a, b in trig_pairs(statements).items()
        if a not in alias and b not in alias and not state.is_scalar(rhs_of[a])
    }
    stacked: dict[int, sp.Symbol] = {}  # a group -> the symbol of its legs at once

    def group_symbol(x: sp.Symbol) -> sp.Symbol:
        g, _, per_sample = member[x]
        if g not in stacked:
            stacked[g] = sp.Symbol(f"_legs{g}", real=True)
            if not per_sample:  # the legs' parameters as a (legs, 1) column
                each = sorted((y for y in member if member[y][0] == g), key=lambda y: member[y][1])
                column = ", ".join(f"[{y}]" for y in each)
                scalar_lines.append(f"{stacked[g]} = numpy.array([{column}], numpy.float64)")
                state.scalars.add(stacked[g])
                state.stacked_scalars.add(stacked[g])
        return stacked[g]

    for index, unit in enumerate(units):
        if len(unit) > 1:  # the legs' statements, in one call each operation
            lhs, rhs = unit[0]
            read = sorted((x for x in rhs.free_symbols if x in member), key=str)
            rhs = rhs.xreplace({x: group_symbol(x) for x in read})
            first = ROW_PATTERN.match(alias[lhs]) if lhs in alias else None  # the others follow it
            dest = f"{first[1]}[{first[2]}:{int(first[2]) + len(unit)}]" if first else None
            if dest:
                state.stacked.add(dest)
            where = state.emit(rhs, dest)
            if not dest and where not in state.temps:  # never a bare copy, but be safe
                block = state.new(True)
                state.lines.append(f"numpy.copyto({block}, {where})")
                where = block
            state.location[group_symbol(lhs)] = where
            if dest:
                for x, _ in unit:
                    state.bind(x, alias[x])
            else:
                state.bind_legs([x for x, _ in unit], where)
            for sym in set().union(*(r.free_symbols for _, r in unit)):
                if uses.get(sym) == index:
                    state.drop(sym)
            for x, _ in unit:
                if x not in uses:
                    state.drop(x)
            continue
        ((lhs, rhs),) = unit
        if state.is_scalar(rhs):
            state.scalars.add(lhs)
            scalar_lines.append(f"{lhs} = {numpy_code(rhs)}")
            continue
        if lhs in pairs:  # sin and cos of one argument, both now
            second = pairs[lhs]
            x = state.emit(rhs.args[0])
            rows = {type(rhs): state.new(), type(rhs_of[second]): state.new()}
            work = [state.new() for _ in range(SINCOS_WORK)]
            state.lines.append(
                f"_sincos({x}, {rows[sp.sin]}, {rows[sp.cos]}, ({', '.join(work)},))"
            )
            for operand in (x, *work):
                state.release(operand)
            state.bind(lhs, rows[type(rhs)])
            state.bind(second, rows[type(rhs_of[second])])
        elif lhs not in pairs.values():
            target = alias.get(lhs)
            state.bind(lhs, state.emit(rhs, target))
        for sym in rhs.free_symbols:  # operands whose last use is this statement
            if uses.get(sym) == index:
                state.drop(sym)
        if lhs not in uses:
            state.drop(lhs)
    for name, expr in outputs:
        row = output_rows[name]
        # An aliased intermediate was computed in its row, unless it is a parameter-only
        # scalar (computed once as a Python number): that row is filled here.
        if expr.is_Symbol and alias.get(expr) == row and expr not in state.scalars:
            continue
        state.emit(expr, row)
    hoisted = [f"{name} = numpy.array({text}, numpy.float64)"
               for text, name in state.hoisted.items()]  # fmt: skip
    summed = list(dict.fromkeys(output_rows.values()))
    return LoweredNumpy(
        scalar_lines,
        hoisted + add_sums(state.lines, summed, len(legs)),
        state.count,
        bool(pairs),
        frozenset(state.ufuncs | {"add"}),
        state.atan2,
        len(summed),
        tuple(sorted(state.blocks)),
        len(legs),
    )
