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

The three legs' statements that are one expression (:func:`leg_groups`, as the C's lanes) run as
one call each operation on a (3, n) block of three consecutive work rows (``t12``: rows 12 to
14), the legs' parameters as a (3, 1) column; a group is placed where its first statement was,
after what it reads (:func:`_units`), and each leg's row is freed when that leg's value is dead.
The inverse dynamics makes ~40 % fewer calls (602 to 370, prismatic): 5 % less time at 10^4
samples, the same at 10^5 (docs/performance-log.md). The values are each leg's own, the terms of a
sum possibly in another order (round-off).

Last, each output row is summed into the function's ``sums`` argument right after the last line
that names it (:func:`add_sums`): the runtime's failure checks learn from these sums that every
output is finite without reading the block's outputs again, out of cache.
"""

from __future__ import annotations

import heapq
import re
from dataclasses import dataclass, field

import sympy as sp
from rpr3gen_derive.codegen.backends.python.printer import numpy_code
from rpr3gen_derive.codegen.cse import StraightLine
from rpr3gen_derive.codegen.functions import INV_TWO_PI, TWO_PI, wrap_angle
from rpr3gen_derive.codegen.legnames import LEGS, leg_family, shape

_UFUNC = {sp.cos: "cos", sp.sin: "sin", sp.Abs: "absolute"}


@dataclass
class LoweredNumpy:
    """Lines of the generated function body, the size of its work array, and whether it calls
    the module's ``_sincos`` and ``_atan2`` helpers."""

    scalar_lines: list[str]
    vector_lines: list[str]
    #: Work rows ``w0 ...``; three consecutive of them are also a (3, n) block (``triples``).
    buffers: int
    sincos: bool = False
    ufuncs: frozenset[str] = frozenset()
    atan2: bool = False
    #: Output rows whose sums the function writes into its ``sums`` argument (:func:`add_sums`).
    sums: int = 0
    #: The first rows of the (3, n) blocks ``tK`` (rows K to K + 2) the legs' statements use
    #: (:func:`leg_groups`).
    triples: tuple[int, ...] = ()


#: Work rows the module's ``_sincos(x, s, c, work)`` helper takes.
SINCOS_WORK = 4
#: Work rows the module's ``_atan2(y, x, out, work)`` helper takes.
ATAN2_WORK = 1


def trig_pairs(statements: list[tuple[sp.Symbol, sp.Expr]]) -> dict[sp.Symbol, sp.Symbol]:
    """``{first: second}`` for each ``s = sin(a)``, ``c = cos(a)`` pair of statements: evaluated
    together by ``_sincos`` (NumPy's ``sin`` and ``cos`` cost ~10 ns a value each; the pair,
    ~50 ufunc passes of the C kernels' reduction and polynomials, about half of that)."""
    found: dict[tuple[type, sp.Expr], sp.Symbol] = {}
    for lhs, rhs in statements:
        if isinstance(rhs, (sp.sin, sp.cos)):
            found.setdefault((type(rhs), rhs.args[0]), lhs)
    pairs = {}
    for (func, arg), lhs in found.items():
        if func is sp.sin and (sp.cos, arg) in found:
            other = found[(sp.cos, arg)]
            order = [s for s, _ in statements]
            first, second = sorted((lhs, other), key=order.index)
            pairs[first] = second
    return pairs


@dataclass
class _Lowering:
    """State of the lowering: where each symbol lives and which work rows are free.

    A work row holds either an anonymous temporary (freed when an operation consumes it) or the
    value of named symbols (freed when the last of them is dead: ``refs``).
    """

    scalars: set[sp.Symbol]
    #: The module's number constants, shared by its functions: text -> name (``_K0`` ...).
    constants: dict[str, str] = field(default_factory=dict)
    #: This function's scalar operands of parameters: text -> name (``_k0`` ...).
    hoisted: dict[str, str] = field(default_factory=dict)
    ufuncs: set[str] = field(default_factory=set)
    atan2: bool = False
    location: dict[sp.Symbol, str] = field(default_factory=dict)
    free: list[int] = field(default_factory=list)
    temps: set[str] = field(default_factory=set)
    refs: dict[str, int] = field(default_factory=dict)
    count: int = 0
    lines: list[str] = field(default_factory=list)
    #: Operand texts that hold the three legs: (3, n) blocks, (3, 1) parameter columns.
    stacked: set[str] = field(default_factory=set)
    #: Parameter-only symbols that hold the three legs' values as a (3, 1) column.
    stacked_scalars: set[sp.Symbol] = field(default_factory=set)
    #: The first rows of the (3, n) blocks used (``t12``: rows 12 to 14).
    triples: set[int] = field(default_factory=set)

    def is_scalar(self, expr: sp.Expr) -> bool:
        return expr.free_symbols <= self.scalars

    def is_stacked(self, operand: str) -> bool:
        return operand in self.stacked

    def new(self, stacked: bool = False) -> str:
        """A free work row ``wK``, or three consecutive ones ``tK`` (the legs' (3, n) block)."""
        if not stacked:
            if self.free:
                index = min(self.free)
                self.free.remove(index)
            else:
                index = self.count
                self.count += 1
            name = f"w{index}"
        else:
            free = set(self.free)
            found = next((k for k in sorted(free) if {k + 1, k + 2} <= free), None)
            if found is None:  # grow: the free rows at the end, then new ones
                found = self.count
                while found - 1 in free:
                    found -= 1
                self.count = max(self.count, found + 3)
            index = found
            for k in range(index, index + 3):
                if k in free:
                    self.free.remove(k)
            name = f"t{index}"
            self.stacked.add(name)
            self.triples.add(index)
        self.temps.add(name)
        return name

    def _free_row(self, name: str) -> None:
        first = int(name[1:])
        self.free.extend(range(first, first + 3) if name.startswith("t") else [first])

    def release(self, operand: str) -> None:
        """Free an anonymous temporary once it has been consumed."""
        if operand in self.temps:
            self.temps.discard(operand)
            self._free_row(operand)

    def bind(self, symbol: sp.Symbol, where: str) -> None:
        """Give ``symbol`` the value at ``where`` (a temporary becomes a named row)."""
        self.location[symbol] = where
        if where in self.temps:
            self.temps.discard(where)
            self.refs[where] = 0
        if where in self.refs:
            self.refs[where] += 1

    def bind_legs(self, symbols: list[sp.Symbol], block: str) -> None:
        """Give the three legs' symbols the rows of the (3, n) block ``block``: each row is
        freed when its own leg's value is dead."""
        self.temps.discard(block)
        first = int(block[1:])
        for leg, symbol in enumerate(symbols):
            self.refs[f"w{first + leg}"] = 0
            self.bind(symbol, f"w{first + leg}")

    def drop(self, symbol: sp.Symbol) -> None:
        """``symbol`` is dead: free its row when no other live symbol shares it."""
        where = self.location.get(symbol)
        if where in self.refs:
            self.refs[where] -= 1
            if self.refs[where] == 0:
                del self.refs[where]
                self._free_row(where)

    def call(self, ufunc: str, args: list[str], dest: str | None) -> str:
        for a in args:
            self.release(a)
        target = dest or self.new(any(self.is_stacked(a) for a in args))
        self.line(ufunc, args, target)
        return target

    def line(self, ufunc: str, args: list[str], target: str) -> None:
        """``_ufunc(*args, target)``: the call, its output by position."""
        self.ufuncs.add(ufunc)
        self.lines.append(f"_{ufunc}({', '.join(args)}, {target})")

    # -- expressions -------------------------------------------------------------------------

    def scalar(self, expr: sp.Expr) -> str:
        """The name of a scalar operand's 0-d array: a module constant for a number, else one
        computed at the head of the function."""
        text = numpy_code(expr)
        if expr.is_Number:
            return self.constant(text)
        name = self.hoisted.setdefault(text, f"_k{len(self.hoisted)}")
        if expr.free_symbols & self.stacked_scalars:
            self.stacked.add(name)
        return name

    def constant(self, value: str) -> str:
        """The module constant of a number's text (``"1.0"``, ``TWO_PI`` ...)."""
        return self.constants.setdefault(value, f"_K{len(self.constants)}")

    def emit(self, expr: sp.Expr, dest: str | None = None) -> str:
        """Operand text of ``expr``; written into ``dest`` when one is given."""
        if self.is_scalar(expr):
            text = self.scalar(expr)
            if dest:
                self.lines.append(f"numpy.copyto({dest}, {text})")
                return dest
            return text
        if expr.is_Symbol:
            where = self.location[expr]
            if dest:
                self.lines.append(f"numpy.copyto({dest}, {where})")
                return dest
            return where
        if expr.is_Add:
            return self.add(expr, dest)
        if expr.is_Mul:
            return self.mul(expr, dest)
        if expr.is_Pow:
            return self.power(expr, dest)
        if expr.func is wrap_angle:  # x - 2 pi rint(x / 2 pi)
            x = self.emit(expr.args[0])
            turns = self.new(self.is_stacked(x))
            self.line("multiply", [x, self.constant(INV_TWO_PI)], turns)
            self.line("rint", [turns], turns)
            self.line("multiply", [turns, self.constant(TWO_PI)], turns)
            return self.call("subtract", [x, turns], dest)
        if expr.func in (sp.Min, sp.Max):  # n-ary: folded pairwise
            ufunc = "fmin" if expr.func is sp.Min else "fmax"
            acc = self.emit(expr.args[0])
            for k, arg in enumerate(expr.args[1:]):
                final = k == len(expr.args) - 2
                acc = self.call(ufunc, [acc, self.emit(arg)], dest if final else None)
            return acc
        if expr.func is sp.atan2:
            return self.arctangent(expr, dest)
        if expr.func in _UFUNC:
            args = [self.emit(a) for a in expr.args]
            return self.call(_UFUNC[expr.func], args, dest)
        raise NotImplementedError(f"cannot lower {expr.func.__name__}: {expr}")

    def arctangent(self, expr: sp.Expr, dest: str | None) -> str:
        """``atan2(y, x)`` by the module's ``_atan2``, which reads ``y`` and ``x`` after writing
        its output: a row of their own until it returns."""
        operands = [self.emit(a) for a in expr.args]
        held = list(dict.fromkeys(a for a in operands if a in self.temps))
        self.temps.difference_update(held)
        stacked = any(self.is_stacked(a) for a in operands)
        target = dest or self.new(stacked)
        work = [self.new(stacked) for _ in range(ATAN2_WORK)]
        self.lines.append(f"_atan2({operands[0]}, {operands[1]}, {target}, ({', '.join(work)},))")
        self.atan2 = True
        for row in held:
            self._free_row(row)
        for row in work:
            self.release(row)
        return target

    def add(self, expr: sp.Expr, dest: str | None) -> str:
        scalar = [a for a in expr.args if self.is_scalar(a)]
        terms = [a for a in expr.args if not self.is_scalar(a)]
        signed = []
        for term in terms:
            coeff, rest = term.as_coeff_Mul()
            negative = coeff.is_negative
            signed.append((negative, -term if negative else term))
        signed.sort(key=lambda item: item[0])  # a positive term first when there is one
        negative, first = signed[0]
        rest = signed[1:]
        last = not rest and not scalar
        acc = self.emit(first, dest if last and not negative else None)
        if negative:
            acc = self.call("negative", [acc], dest if last else None)
        for k, (negative, term) in enumerate(rest):
            final = k == len(rest) - 1 and not scalar
            operand = self.emit(term)
            ufunc = "subtract" if negative else "add"
            acc = self.call(ufunc, [acc, operand], dest if final else None)
        if scalar:
            acc = self.call("add", [acc, self.scalar(sp.Add(*scalar))], dest)
        return acc

    def mul(self, expr: sp.Expr, dest: str | None) -> str:
        scalar = [a for a in expr.args if self.is_scalar(a)]
        numerator, denominator = [], []
        for factor in expr.args:
            if self.is_scalar(factor):
                continue
            base, exponent = factor.as_base_exp()
            if exponent.is_Integer and exponent < 0:
                denominator.append(base ** (-exponent))
            else:
                numerator.append(factor)
        factors = [self.emit(f) for f in numerator[:1]]
        steps: list[tuple[str, str]] = [("multiply", self.emit(f)) for f in numerator[1:]]
        coefficient = self.scalar(sp.Mul(*scalar)) if scalar else None
        if not numerator:  # c / x
            acc_text = coefficient or self.constant("1.0")
            divisor = self._product(denominator)
            return self.call("divide", [acc_text, divisor], dest)
        acc = factors[0]
        if coefficient is not None:
            steps.append(("multiply", coefficient))
        if denominator:
            steps.append(("divide", self._product(denominator)))
        if not steps:  # a lone factor (SymPy folds such a Mul away, but be safe)
            if dest is None:
                return acc
            self.lines.append(f"numpy.copyto({dest}, {acc})")
            self.release(acc)
            return dest
        for k, (ufunc, operand) in enumerate(steps):
            final = k == len(steps) - 1
            acc = self.call(ufunc, [acc, operand], dest if final else None)
        return acc

    def _product(self, factors: list[sp.Expr]) -> str:
        acc = self.emit(factors[0])
        for f in factors[1:]:
            acc = self.call("multiply", [acc, self.emit(f)], None)
        return acc

    def power(self, expr: sp.Expr, dest: str | None) -> str:
        base, exponent = expr.args
        if exponent == 2:
            b = self.emit(base)
            self.release(b)
            target = dest or self.new(self.is_stacked(b))
            self.line("multiply", [b, b], target)
            return target
        if exponent == -1:
            return self.call("divide", [self.constant("1.0"), self.emit(base)], dest)
        if exponent == sp.Rational(1, 2):
            return self.call("sqrt", [self.emit(base)], dest)
        if exponent == sp.Rational(-1, 2):
            root = self.call("sqrt", [self.emit(base)], None)
            return self.call("divide", [self.constant("1.0"), root], dest)
        if exponent.is_Integer and exponent > 2:
            b = self.emit(base)
            held = b in self.temps  # read by every product: its row is freed after the last
            self.temps.discard(b)
            acc = b
            for k in range(int(exponent) - 1):
                final = k == int(exponent) - 2
                acc = self.call("multiply", [acc, b], dest if final else None)
            if held:
                self._free_row(b)
            return acc
        if exponent.is_Integer and exponent < 0:  # 1/(x*x): numpy.power costs ~15 ns a value
            return self.call("divide", [self.constant("1.0"), self.emit(base**-exponent)],
                             dest)  # fmt: skip
        return self.call("power", [self.emit(base), self.scalar(exponent)], dest)


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


def add_sums(lines: list[str], rows: list[str]) -> list[str]:
    """``lines`` with ``sums[k] = _add.reduce(row)`` after the last line that names output row
    ``rows[k]`` (at the end for a row no line names).

    The runtime's failure checks must know whether every output is finite. Read again after the
    kernel, a block's outputs come from the outer caches or memory: ~50 ns a sample of the
    inverse dynamics. Each row summed right after its last write is still in cache, and one
    non-finite value makes its sum non-finite (an overflowing sum only sends the block to the
    per-sample checks): about half of that (``benchmarks/harness/numpy_parts.py``).
    """
    last: dict[str, int] = {}
    patterns = {row: re.compile(rf"(?<![\w.]){re.escape(row)}") for row in rows}
    for index, line in enumerate(lines):
        for row, pattern in patterns.items():
            if pattern.search(line):
                last[row] = index
        for name, start, stop in _SLICE.findall(line):  # the legs' rows at once: out[3:6]
            for k in range(int(start), int(stop)):
                if f"{name}[{k}]" in patterns:
                    last[f"{name}[{k}]"] = index
    after: dict[int, list[int]] = {}
    for k, row in enumerate(rows):
        after.setdefault(last.get(row, len(lines) - 1), []).append(k)
    found = []
    for index, line in enumerate(lines):
        found.append(line)
        found += _sum_lines(after.get(index, []), rows)
    if not lines:
        found += _sum_lines(list(range(len(rows))), rows)
    return found


_SLICE = re.compile(r"(?<![\w.])(\w+)\[(\d+):(\d+)\]")
_ROW = re.compile(r"^(\w+)\[(\d+)\]$")


def _sum_lines(ks: list[int], rows: list[str]) -> list[str]:
    """``sums[k] = _add.reduce(row)`` for each k; three consecutive rows of one array with
    consecutive ``k`` (a leg triple's) in one call along their rows."""
    lines, k = [], 0
    ks = sorted(ks)
    while k < len(ks):
        first = _ROW.match(rows[ks[k]])
        run = 1
        while first and k + run < len(ks) and ks[k + run] == ks[k] + run:
            nxt = _ROW.match(rows[ks[k + run]])
            if not nxt or nxt[1] != first[1] or int(nxt[2]) != int(first[2]) + run:
                break
            run += 1
        if run >= len(LEGS) and first:
            run = len(LEGS)
            rows_text = f"{first[1]}[{first[2]}:{int(first[2]) + run}]"
            lines.append(f"_add.reduce({rows_text}, 1, None, sums[{ks[k]}:{ks[k] + run}])")
        else:
            run = 1
            lines.append(f"sums[{ks[k]}] = _add.reduce({rows[ks[k]]})")
        k += run
    return lines


#: Fewest leg groups that make a function's statements worth lowering on (3, n) blocks.
MIN_GROUPS = 4


def _fits(three: dict[int, sp.Symbol], alias: dict[sp.Symbol, str]) -> bool:
    """A group's members are no outputs, or outputs in three consecutive rows of one array in
    the legs' order (written at once: ``out[3:6]``)."""
    rows = [alias.get(three[leg]) for leg in range(len(LEGS))]
    if all(r is None for r in rows):
        return True
    found = [_ROW.match(r) if r else None for r in rows]
    if not all(found):
        return False
    names = {m[1] for m in found if m}
    starts = [int(m[2]) for m in found if m]
    return len(names) == 1 and starts == list(range(starts[0], starts[0] + len(LEGS)))


def leg_groups(
    statements: list[tuple[sp.Symbol, sp.Expr]],
    scalars: set[sp.Symbol],
    alias: dict[sp.Symbol, str],
) -> dict[sp.Symbol, tuple[int, int, bool]]:
    """The legs' statements that one call can evaluate for the three legs at once: each
    member's symbol -> (its group, its leg, whether the group is per-sample).

    A group is three symbols, one per leg, named alike but for the leg's letter
    (:func:`~rpr3gen_derive.codegen.legnames.leg_family`): the legs' parameters, parameter-only
    statements, then, to a fixed point, per-sample statements whose right-hand sides are one
    expression once each member they read is read as its group (the same tree, as SymPy keeps
    it: the same operations on the same operands; compared by
    :func:`~rpr3gen_derive.codegen.legnames.shape`). Such statements give each leg the same bits
    as one statement each. None when there are fewer than :data:`MIN_GROUPS` per-sample
    groups."""
    names = {str(x): x for x in scalars} | {str(lhs): lhs for lhs, _ in statements}
    scalar = set(scalars)
    for lhs, rhs in statements:
        if rhs.free_symbols <= scalar:
            scalar.add(lhs)
    member: dict[sp.Symbol, tuple[int, int, bool]] = {}
    count = 0
    for name in sorted(names):
        family = leg_family(name, names.keys())
        if family is None:
            continue
        per_leg = [names[family[0] + leg + family[1]] for leg in LEGS]
        if all(x in scalar for x in per_leg):
            for leg, x in enumerate(per_leg):
                member[x] = (count, leg, False)
            count += 1
    # A candidate's key changes only when a symbol it reads joins a group: each pass computes
    # again the keys of those statements alone (the rest are kept), then collects the keys in
    # the statements' order, as one pass over them all would.
    candidates = [
        (lhs, rhs, rhs.free_symbols)
        for lhs, rhs in statements
        if lhs not in member and lhs not in scalar and not isinstance(rhs, (sp.sin, sp.cos))
    ]
    keys: dict[sp.Symbol, tuple[object, int] | None] = {}
    joined: set[sp.Symbol] | None = None  # None: every key is to compute
    groups = 0
    while True:
        found: dict[object, dict[int, sp.Symbol]] = {}
        for lhs, rhs, free in candidates:
            if lhs in member:
                continue
            if joined is None or not joined.isdisjoint(free):
                read = [x for x in free if x in member]
                legs = {member[x][1] for x in read}
                keys[lhs] = (
                    (shape(rhs, {x: member[x][0] for x in read}), legs.pop())
                    if len(legs) == 1
                    else None
                )
            entry = keys[lhs]
            if entry is not None:
                found.setdefault(entry[0], {}).setdefault(entry[1], lhs)
        complete = [t for t in found.values() if len(t) == len(LEGS) and _fits(t, alias)]
        if not complete:
            break
        joined = set()
        for three in complete:
            for leg, x in three.items():
                member[x] = (count, leg, True)
                joined.add(x)
            count += 1
            groups += 1
    return member if groups >= MIN_GROUPS else {}


def _units(
    statements: list[tuple[sp.Symbol, sp.Expr]], member: dict[sp.Symbol, tuple[int, int, bool]]
) -> list[list[tuple[sp.Symbol, sp.Expr]]]:
    """The statements as units: a per-sample group's three (in the legs' order) or one alone,
    each unit after those it reads, otherwise in the order of its first statement."""
    unit_of: dict[int, object] = {}
    members: dict[object, list[int]] = {}
    for index, (lhs, _) in enumerate(statements):
        key: object = ("g", member[lhs][0]) if lhs in member and member[lhs][2] else index
        unit_of[index] = key
        members.setdefault(key, []).append(index)
    defined = {lhs: unit_of[k] for k, (lhs, _) in enumerate(statements)}
    deps = {
        key: {defined[x] for k in ks for x in statements[k][1].free_symbols if x in defined} - {key}
        for key, ks in members.items()
    }
    readers: dict[object, list[object]] = {}
    for key, ds in deps.items():
        for d in ds:
            readers.setdefault(d, []).append(key)
    waiting = {key: len(ds) for key, ds in deps.items()}
    ready = [(min(ks), str(key), key) for key, ks in members.items() if not waiting[key]]
    heapq.heapify(ready)
    order: list[list[tuple[sp.Symbol, sp.Expr]]] = []
    while ready:
        _, _, key = heapq.heappop(ready)
        ks = sorted(members[key], key=lambda k: member.get(statements[k][0], (0, 0))[1])
        order.append([statements[k] for k in ks])
        for r in readers.get(key, []):
            waiting[r] -= 1
            if not waiting[r]:
                heapq.heappush(ready, (min(members[r]), str(r), r))
    assert len(order) == len(members), "the statements have a cycle"
    return order


def lower_numpy(
    code: StraightLine,
    inputs: dict[sp.Symbol, str],
    params: set[sp.Symbol],
    output_rows: dict[str, str],
    constants: dict[str, str] | None = None,
) -> LoweredNumpy:
    """Lower ``code`` given where inputs live (``{x: "x"}``) and each output's row text.

    ``constants``: the module's number constants so far (text -> name), added to in place, so
    that the module's functions share them."""
    statements, outputs = fold_copies(code, params)
    statements, outputs = fold_signs(statements, outputs, set(params))
    # Output rows: an output that is a named intermediate is computed in place.
    alias: dict[sp.Symbol, str] = {}
    for name, expr in outputs:
        if expr.is_Symbol and expr not in alias and expr not in inputs:
            alias[expr] = output_rows[name]
    member = leg_groups(statements, set(params), alias)
    units = _units(statements, member)
    uses: dict[sp.Symbol, int] = {}  # index of each symbol's last use (by unit)
    for index, unit in enumerate(units):
        for _, rhs in unit:
            for sym in rhs.free_symbols:
                uses[sym] = index
    for _, expr in outputs:  # read by an output: alive to the end
        for sym in expr.free_symbols:
            uses[sym] = len(units)
    state = _Lowering(scalars=set(params), constants={} if constants is None else constants)
    state.location.update(inputs)
    scalar_lines: list[str] = []
    rhs_of = dict(statements)
    pairs = {
        a: b
        for a, b in trig_pairs(statements).items()
        if a not in alias and b not in alias and not state.is_scalar(rhs_of[a])
    }
    stacked: dict[int, sp.Symbol] = {}  # a group -> the symbol of its three legs at once

    def group_symbol(x: sp.Symbol) -> sp.Symbol:
        g, _, per_sample = member[x]
        if g not in stacked:
            stacked[g] = sp.Symbol(f"_legs{g}", real=True)
            if not per_sample:  # the legs' parameters as a (3, 1) column
                three = sorted((y for y in member if member[y][0] == g), key=lambda y: member[y][1])
                column = ", ".join(f"[{y}]" for y in three)
                scalar_lines.append(f"{stacked[g]} = numpy.array([{column}], numpy.float64)")
                state.scalars.add(stacked[g])
                state.stacked_scalars.add(stacked[g])
        return stacked[g]

    for index, unit in enumerate(units):
        if len(unit) > 1:  # the three legs' statements, in one call each operation
            lhs, rhs = unit[0]
            read = sorted((x for x in rhs.free_symbols if x in member), key=str)
            rhs = rhs.xreplace({x: group_symbol(x) for x in read})
            first = _ROW.match(alias[lhs]) if lhs in alias else None  # the others follow it
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
        hoisted + add_sums(state.lines, summed),
        state.count,
        bool(pairs),
        frozenset(state.ufuncs | {"add"}),
        state.atan2,
        len(summed),
        tuple(sorted(state.triples)),
    )
