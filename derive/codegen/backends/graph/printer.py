"""The graph printer: plain scalar Python over a math namespace ``ops``.

SymPy's ``StrPrinter`` (whose text is valid Python with correct precedence), lightly
subclassed: every function is a call of ``ops`` (:data:`OPS`, the protocol the bridges
implement), an integer power of a compound base is ``ops.power(b, n)`` (squares and cubes of a
symbol are products already, :func:`rpr3gen_derive.codegen.backends.prepare`), a square root
``ops.sqrt``, a ``Piecewise`` nested ``ops.if_else``. Numbers are Python floats, exactly: a
``Float`` as its shortest round-trip ``repr``, a ``Rational`` as ``p/q`` (Python's division of
two integers is correctly rounded). Anything else is refused, so that no name the namespace
lacks is ever printed.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp
from rpr3gen_derive.codegen.backends import prepare
from rpr3gen_derive.codegen.functions import INV_TWO_PI, TWO_PI
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.str import StrPrinter

#: The names a generated graph function calls on its ``ops`` argument, and what each must do
#: on a scalar of the caller's kind (a CasADi ``SX``/``MX``, a JAX array): the protocol of
#: docs/bridges.md.
OPS: dict[str, str] = {
    "sin": "sine",
    "cos": "cosine",
    "atan2": "atan2(y, x), C99's",
    "sqrt": "square root",
    "fabs": "absolute value",
    "fmin": "the smaller of two values (C99 fmin)",
    "fmax": "the larger of two values (C99 fmax)",
    "rint": "the nearest integer (as a float)",
    "power": "power(x, n) for an integer n",
    "sign": "-1, 0 or 1",
    "if_else": "if_else(condition, a, b): a where the condition holds, else b",
}

_RELATIONS = (sp.StrictLessThan, sp.LessThan, sp.StrictGreaterThan, sp.GreaterThan)


class GraphPrinter(StrPrinter):
    """Scalar Python over ``ops``: the bridges' straight-line code."""

    def __init__(self) -> None:
        super().__init__({"full_prec": True})

    def _call(self, name: str, *args: sp.Expr) -> str:
        if name not in OPS:  # pragma: no cover - a printer bug, not an input's
            raise ValueError(f"ops.{name} is not in the graph protocol")
        return f"ops.{name}({', '.join(self._print(a) for a in args)})"

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_Integer(self, expr: sp.Integer) -> str:
        return repr(float(expr))

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        base, exp = expr.base, expr.exp
        if exp == sp.Rational(1, 2):
            return self._call("sqrt", base)
        if exp == -sp.Rational(1, 2):
            return f"1.0/{self._call('sqrt', base)}"
        if exp == -1:
            return f"1.0/{self.parenthesize(base, PRECEDENCE['Pow'])}"
        if exp.is_Integer:
            return f"ops.power({self._print(base)}, {int(exp)})"
        raise ValueError(f"the graph printer has no power {exp} (only integers and +-1/2)")

    def _print_Mul(self, expr: sp.Expr) -> str:
        """A product with reciprocals as one division, ``x*y/(a*b)`` (as the C printer)."""

        def reciprocal(f: sp.Expr) -> bool:
            return bool(f.is_Pow and f.exp == -1)

        below = [f.base for f in expr.args if reciprocal(f)]
        if not below:
            return str(super()._print_Mul(expr))
        above = [f for f in expr.args if not reciprocal(f)]
        numerator = self.parenthesize(sp.Mul(*above), PRECEDENCE["Mul"]) if above else "1.0"
        level = PRECEDENCE["Mul"]
        if len(below) == 1:
            return f"{numerator}/{self.parenthesize(below[0], level, strict=True)}"
        return f"{numerator}/({'*'.join(self.parenthesize(b, level) for b in below)})"

    def _print_sin(self, expr: sp.Expr) -> str:
        return self._call("sin", *expr.args)

    def _print_cos(self, expr: sp.Expr) -> str:
        return self._call("cos", *expr.args)

    def _print_atan2(self, expr: sp.Expr) -> str:
        return self._call("atan2", *expr.args)

    def _print_Abs(self, expr: sp.Expr) -> str:
        return self._call("fabs", *expr.args)

    def _print_sign(self, expr: sp.Expr) -> str:
        return self._call("sign", *expr.args)

    def _fold(self, name: str, args: tuple[sp.Expr, ...]) -> str:
        """``ops.fmin(a, ops.fmin(b, c))``: pairwise, as the C and the NumPy fold them."""
        text = self._print(args[-1])
        for arg in reversed(args[:-1]):
            text = f"ops.{name}({self._print(arg)}, {text})"
        return text

    def _print_Min(self, expr: sp.Expr) -> str:
        return self._fold("fmin", expr.args)

    def _print_Max(self, expr: sp.Expr) -> str:
        return self._fold("fmax", expr.args)

    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        x = self._print(expr.args[0])
        return f"(({x}) - {TWO_PI}*ops.rint(({x})*{INV_TWO_PI}))"

    def _print_Relational(self, expr: sp.Expr) -> str:
        if not isinstance(expr, _RELATIONS):
            raise ValueError(f"the graph printer has no relation {type(expr).__name__}")
        return f"({self._print(expr.lhs)}) {expr.rel_op} ({self._print(expr.rhs)})"

    def _print_Piecewise(self, expr: sp.Expr) -> str:
        *pieces, (last, cond) = expr.args
        if cond is not sp.true:
            raise ValueError("a Piecewise without an otherwise branch has no graph form")
        text = self._print(last)
        for value, condition in reversed(pieces):
            text = f"ops.if_else({self._print(condition)}, {self._print(value)}, {text})"
        return text

    def _print_Function(self, expr: sp.Expr) -> str:
        raise ValueError(f"the graph printer has no function {type(expr).__name__}")


_PRINTER = GraphPrinter()  # stateless between calls


@lru_cache(maxsize=1 << 16)
def graph_code(expr: sp.Expr) -> str:
    """One scalar expression over ``ops`` (memoised, as the other printers are)."""
    return _PRINTER.doprint(prepare(expr))
