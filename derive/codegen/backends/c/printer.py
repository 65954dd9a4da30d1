"""The C99 printer: SymPy's, lightly subclassed.

Squares and small integer powers are expanded to products by SymPy's rewriting passes before
printing (:func:`rpr3gen_derive.codegen.backends.prepare`), so no ``pow`` is emitted for them.
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.backends import prepare
from rpr3gen_derive.codegen.functions import INV_TWO_PI, TWO_PI
from sympy.printing.c import C99CodePrinter


class CPrinter(C99CodePrinter):
    """C99 code on ``double``."""

    def __init__(self) -> None:
        super().__init__({"math_macros": {}})

    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        # x - 2 pi round(x / 2 pi): a few flops, where glibc's remainder() costs ~40 ns.
        x = self._print(expr.args[0])
        return f"(({x}) - {TWO_PI}*nearbyint(({x})*{INV_TWO_PI}))"


_PRINTER = CPrinter()  # stateless between calls; built once, it is most of a call's cost


def c_code(expr: sp.Expr) -> str:
    """One C99 expression."""
    return _PRINTER.doprint(prepare(expr))
