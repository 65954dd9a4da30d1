"""The C99 printer: SymPy's, lightly subclassed.

Squares and cubes of a symbol are expanded to products by SymPy's rewriting passes before
printing (:func:`rpr3gen_derive.codegen.backends.prepare`). A compound base keeps its power:
``pow(a + b, 2)``, which compilers make the product ``(a + b)*(a + b)`` from -O1 on (gcc 12;
the same value: both are the exactly rounded square); at -O0 it is a call of libm's ``pow``.
``sin``, ``cos``, ``atan2``, ``Min``, ``Max`` and the rounding of ``wrap_angle`` are printed as
calls of the generated C's own inline kernels (:mod:`rpr3gen_derive.codegen.mathkernels`),
``{prefix}_sin`` etc., so that loops over samples vectorise. In the batch loops
(``fast=True``) ``sin`` and ``cos`` are the kernels' fast path (``{prefix}_sin_fast``), valid
below ``mathkernels.FAST_LIMIT``; the batch flags larger arguments
(:func:`fast_trig_arguments`). A product with several reciprocals, ``x/a/b/c``, is printed as
one division ``x/(a*b*c)`` (SymPy prints ``x*1.0/a*1.0/b*1.0/c``): divisions and square roots
share one unit of the processor, slow and long, so one division in place of three shortens
both the throughput and the dependency chain (the conditioning of every function has one).
"""

from __future__ import annotations

from functools import cache, lru_cache

import sympy as sp
from rpr3gen_derive.codegen.backends import prepare
from rpr3gen_derive.codegen.functions import INV_TWO_PI, TWO_PI
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import precedence


class CPrinter(C99CodePrinter):
    """C99 code on ``double``, with the module's math kernels named ``{prefix}_*``."""

    def __init__(self, prefix: str, fast: bool = False) -> None:
        trig = "_fast" if fast else ""
        super().__init__(
            {
                "math_macros": {},
                "user_functions": {
                    "sin": f"{prefix}_sin{trig}",
                    "cos": f"{prefix}_cos{trig}",
                    "atan2": f"{prefix}_atan2",
                },
            }
        )
        self.prefix = prefix

    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        # x - 2 pi round(x / 2 pi): a few flops, where glibc's remainder() costs ~40 ns.
        x = self._print(expr.args[0])
        return f"(({x}) - {TWO_PI}*{self.prefix}_rint(({x})*{INV_TWO_PI}))"

    def _print_Mul(self, expr: sp.Expr) -> str:
        def reciprocal(f: sp.Expr) -> bool:
            return bool(f.is_Pow and f.exp == -1)

        below = [f.base for f in expr.args if reciprocal(f)]
        if len(below) < 2:
            return str(super()._print_Mul(expr))
        above = [f for f in expr.args if not reciprocal(f)]
        numerator = self._print(sp.Mul(*above)) if above else "1.0"
        denominator = "*".join(self.parenthesize(b, precedence(expr)) for b in below)
        return f"{numerator}/({denominator})"

    def _fold(self, name: str, expr: sp.Expr) -> str:
        args = [self._print(a) for a in expr.args]
        text = args[-1]
        for arg in reversed(args[:-1]):
            text = f"{self.prefix}_{name}({arg}, {text})"
        return text

    def _print_Min(self, expr: sp.Expr) -> str:
        return self._fold("fmin", expr)

    def _print_Max(self, expr: sp.Expr) -> str:
        return self._fold("fmax", expr)


@cache
def _printer(prefix: str, fast: bool) -> CPrinter:
    # Stateless between calls; built once per prefix, it is most of a call's cost.
    return CPrinter(prefix, fast)


def c_code(expr: sp.Expr, prefix: str, fast: bool = False) -> str:
    """One C99 expression; ``fast``: the batch loops' form (see the module docstring).

    Memoised: a variant prints most statements several times (the single-sample kernel, the
    values-only kernels, the batch's passes), and printing is a third of its generation time.
    SymPy's equality is structural, so an equal expression prints the same text. The fast form
    of an expression without ``sin`` or ``cos`` is its plain form, printed once for both."""
    return _c_code(expr, prefix, fast and expr.has(sp.sin, sp.cos))


@lru_cache(maxsize=1 << 16)
def _c_code(expr: sp.Expr, prefix: str, fast: bool) -> str:
    return _printer(prefix, fast).doprint(prepare(expr))


def fast_trig_arguments(exprs: list[sp.Expr]) -> list[sp.Expr]:
    """The distinct arguments of ``sin`` and ``cos`` in ``exprs``, in order of appearance."""
    found: list[sp.Expr] = []
    for expr in exprs:
        for node in sp.preorder_traversal(expr):
            if isinstance(node, (sp.sin, sp.cos)) and node.args[0] not in found:
                found.append(node.args[0])
    return found
