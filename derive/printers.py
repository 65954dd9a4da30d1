"""Printers for the generated code: SymPy's NumPy and C99 printers, lightly subclassed.

Squares and small integer powers are expanded to products and half-integer powers to ``sqrt``
by SymPy's rewriting passes before printing, never by editing printed text.
"""

from __future__ import annotations

import sympy as sp
from sympy.codegen.rewriting import create_expand_pow_optimization, optimize
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

_expand_small_powers = create_expand_pow_optimization(3)


def prepare(expr: sp.Expr) -> sp.Expr:
    """Rewrite ``x**2``, ``x**3`` as products so that printers emit no ``pow`` for them."""
    return optimize(expr, [_expand_small_powers])


TWO_PI = "6.283185307179586"  # 2 pi, correctly rounded
INV_TWO_PI = "0.15915494309189535"  # 1 / (2 pi)


class NumpyPrinter(NumPyPrinter):
    """NumPy code over arrays of samples; names qualified as ``numpy.*``."""

    def __init__(self) -> None:
        super().__init__({"fully_qualified_modules": True, "inline": True})

    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        x = self._print(expr.args[0])
        return f"(({x}) - {TWO_PI}*numpy.rint(({x})*{INV_TWO_PI}))"


class CPrinter(C99CodePrinter):
    """C99 code on ``double``; no ``pow`` for small integer powers (see :func:`prepare`)."""

    def __init__(self) -> None:
        super().__init__({"math_macros": {}})

    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        # x - 2 pi round(x / 2 pi): a few flops, where glibc's remainder() costs ~40 ns.
        x = self._print(expr.args[0])
        return f"(({x}) - {TWO_PI}*nearbyint(({x})*{INV_TWO_PI}))"


def numpy_code(expr: sp.Expr) -> str:
    """One NumPy expression."""
    return NumpyPrinter().doprint(prepare(expr))


def c_code(expr: sp.Expr) -> str:
    """One C99 expression."""
    return CPrinter().doprint(prepare(expr))
