"""The NumPy printer: SymPy's, lightly subclassed.

Squares and small integer powers are expanded to products by SymPy's rewriting passes before
printing (:func:`rpr3gen_derive.codegen.backends.prepare`), never by editing printed text.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp
from rpr3gen_derive.codegen.backends import prepare
from rpr3gen_derive.codegen.functions import INV_TWO_PI, TWO_PI
from sympy.printing.numpy import NumPyPrinter


class NumpyPrinter(NumPyPrinter):
    """NumPy code over arrays of samples; names qualified as ``numpy.*``."""

    def __init__(self) -> None:
        super().__init__({"fully_qualified_modules": True, "inline": True})

    def _print_Min(self, expr: sp.Expr) -> str:
        return self._fold("fmin", expr.args)

    def _print_Max(self, expr: sp.Expr) -> str:
        return self._fold("fmax", expr.args)

    def _fold(self, ufunc: str, args: tuple[sp.Expr, ...]) -> str:
        """``numpy.fmin(a, numpy.fmin(b, c))``: pairwise, as the lowering and the C fold them
        (a NaN argument is ignored, as C99's fmin does), needing no other import."""
        text = self._print(args[-1])
        for arg in reversed(args[:-1]):
            text = f"numpy.{ufunc}({self._print(arg)}, {text})"
        return text

    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        x = self._print(expr.args[0])
        return f"(({x}) - {TWO_PI}*numpy.rint(({x})*{INV_TWO_PI}))"


_PRINTER = NumpyPrinter()  # stateless between calls; built once, it is most of a call's cost


@lru_cache(maxsize=1 << 16)
def numpy_code(expr: sp.Expr) -> str:
    """One NumPy expression (memoised, as :func:`~rpr3gen_derive.codegen.backends.c.printer.c_code`
    is)."""
    return _PRINTER.doprint(prepare(expr))
