"""Backends of the engine: one folder per target language, each with its printer, its lowering
and its templates (``python/``: NumPy; ``c/``: C99).

Each backend exposes ``render(module, context) -> {file name: text}`` for one generated module.
"""

from __future__ import annotations

import sympy as sp
from sympy.codegen.rewriting import create_expand_pow_optimization, optimize

_expand_small_powers = create_expand_pow_optimization(3)


def prepare(expr: sp.Expr) -> sp.Expr:
    """Rewrite ``x**2``, ``x**3`` of a symbol ``x`` as products so that printers emit no
    ``pow`` for them (a compound base keeps its power: :mod:`.c.printer`)."""
    return optimize(expr, [_expand_small_powers])
