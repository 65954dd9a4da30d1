"""The NumPy lowering's emitter: one ufunc call per operation, into rows of a work array
(:mod:`.lowering` explains the whole; :class:`_Lowering` is the per-function state)."""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp
from rpr3gen_derive.codegen.backends.python.printer import numpy_code
from rpr3gen_derive.codegen.functions import INV_TWO_PI, TWO_PI, wrap_angle

_UFUNC = {sp.cos: "cos", sp.sin: "sin", sp.Abs: "absolute"}


@dataclass
class LoweredNumpy:
    """Lines of the generated function body, the size of its work array, and whether it calls
    the module's ``_sincos`` and ``_atan2`` helpers."""

    scalar_lines: list[str]
    vector_lines: list[str]
    #: Work rows ``w0 ...``; ``legs`` consecutive of them are also a (legs, n) block
    #: (``blocks``).
    buffers: int
    sincos: bool = False
    ufuncs: frozenset[str] = frozenset()
    atan2: bool = False
    #: Output rows whose sums the function writes into its ``sums`` argument (:func:`add_sums`).
    sums: int = 0
    #: The first rows of the (legs, n) blocks ``tK`` (rows K to K + legs - 1) the legs'
    #: statements use (:func:`leg_groups`).
    blocks: tuple[int, ...] = ()
    #: The module's count of legs: the rows of a block.
    legs: int = 0


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
    #: The module's count of legs: the rows of a (legs, n) block.
    legs: int = 0
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
    #: Operand texts that hold every leg: (legs, n) blocks, (legs, 1) parameter columns.
    stacked: set[str] = field(default_factory=set)
    #: Parameter-only symbols that hold the legs' values as a (legs, 1) column.
    stacked_scalars: set[sp.Symbol] = field(default_factory=set)
    #: The first rows of the (legs, n) blocks used (``t12``: rows 12 to 14 for three legs).
    blocks: set[int] = field(default_factory=set)

    def is_scalar(self, expr: sp.Expr) -> bool:
        return expr.free_symbols <= self.scalars

    def is_stacked(self, operand: str) -> bool:
        return operand in self.stacked

    def new(self, stacked: bool = False) -> str:
        """A free work row ``wK``, or :attr:`legs` consecutive ones ``tK`` (the legs' block)."""
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
            rest = range(1, self.legs)
            found = next((k for k in sorted(free) if all(k + j in free for j in rest)), None)
            if found is None:  # grow: the free rows at the end, then new ones
                found = self.count
                while found - 1 in free:
                    found -= 1
                self.count = max(self.count, found + self.legs)
            index = found
            for k in range(index, index + self.legs):
                if k in free:
                    self.free.remove(k)
            name = f"t{index}"
            self.stacked.add(name)
            self.blocks.add(index)
        self.temps.add(name)
        return name

    def _free_row(self, name: str) -> None:
        first = int(name[1:])
        self.free.extend(range(first, first + self.legs) if name.startswith("t") else [first])

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
        """Give the legs' symbols the rows of the (legs, n) block ``block``: each row is freed
        when its own leg's value is dead."""
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
