"""A numeric evaluator of a derivation ``Program``: its assignments, in order, with NumPy.

The program's live assignments (those the requested outputs need) are printed once by SymPy's
NumPy printer into the body of one Python function, which then evaluates them in order on arrays
(every input broadcast), without ever substituting the program into one expression.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import sympy as sp
from rpr3gen_derive.codegen.program import Program
from sympy.printing.numpy import NumPyPrinter


def _wrap_angle(x):
    return x - 2 * np.pi * np.rint(x / (2 * np.pi))


class _Printer(NumPyPrinter):
    def _print_wrap_angle(self, expr: sp.Expr) -> str:
        return f"wrap_angle({self._print(expr.args[0])})"


def _live(prog: Program, outputs: Sequence[sp.Expr]) -> list[tuple[sp.Symbol, sp.Expr]]:
    needed: set[sp.Symbol] = set()
    for expr in outputs:
        needed |= sp.sympify(expr).free_symbols
    live = []
    for a in reversed(prog.assignments):
        if a.symbol in needed:
            live.append((a.symbol, a.expr))
            needed |= a.expr.free_symbols
    live.reverse()
    return live


def compile_program(
    prog: Program, inputs: Sequence[sp.Symbol], outputs: Sequence[sp.Expr]
) -> Callable[..., list[np.ndarray]]:
    """``f(**values) -> [output arrays]``; ``values`` maps every input name to a number or array.

    Outputs are broadcast against each other, so constant outputs come back as arrays too.
    """
    # order="none": terms printed as SymPy holds them, not sorted (the sort is most of the
    # printing time of long sums; only the order of floating-point additions changes).
    printer = _Printer({"fully_qualified_modules": False, "inline": True, "order": "none"})
    names = [s.name for s in inputs]
    lines = [f"def _program({', '.join(names)}):"]
    for symbol, expr in _live(prog, outputs):
        lines.append(f"    {symbol.name} = {printer.doprint(expr)}")
    lines.append(f"    return [{', '.join(printer.doprint(sp.sympify(e)) for e in outputs)}]")
    namespace: dict = {"wrap_angle": _wrap_angle, "numpy": np}
    for module in sorted(printer.module_imports):
        for name in sorted(printer.module_imports[module]):
            namespace[name] = getattr(importlib.import_module(module), name)
    exec("\n".join(lines), namespace)
    function = namespace["_program"]

    def evaluate(**values: object) -> list[np.ndarray]:
        args = [np.asarray(values[name], dtype=float) for name in names]
        results = [np.asarray(r) for r in function(*args)]
        shape = np.broadcast_shapes(*(r.shape for r in results), *(a.shape for a in args))
        return [np.broadcast_to(r, shape).copy() for r in results]

    return evaluate


def values_of(params: Mapping[str, float], **arrays: np.ndarray) -> dict[str, object]:
    """Model parameters and named input arrays, as the keyword arguments of ``evaluate``."""
    out: dict[str, object] = dict(params)
    out.update(arrays)
    return out
