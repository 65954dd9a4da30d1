"""A derivation written as a program: an ordered list of named assignments.

A derivation appends each intermediate it wants to keep (and show) as ``symbol = expr``; a later
right-hand side may use the inputs, the parameters and earlier symbols only. The notebooks show
each step of a program; the engine eliminates common subexpressions across all of it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass(frozen=True)
class Assignment:
    """One named intermediate of a derivation: ``symbol = expr``, tagged with its step."""

    symbol: sp.Symbol
    expr: sp.Expr
    step: str


@dataclass
class Program:
    """An ordered list of assignments; each right-hand side uses inputs and earlier symbols only."""

    assignments: list[Assignment] = field(default_factory=list)
    _names: set[str] = field(default_factory=set)

    def define(self, name: str, expr: sp.Expr, step: str) -> sp.Expr:
        """Name ``expr`` as ``name`` and return the symbol; atoms are returned as they are."""
        expr = sp.sympify(expr)
        if expr.is_Atom:
            return expr
        if name in self._names:
            raise ValueError(f"intermediate {name!r} defined twice")
        self._names.add(name)
        symbol = sp.Symbol(name, real=True)
        self.assignments.append(Assignment(symbol, expr, step))
        return symbol

    def define_vector(self, name: str, vector: sp.Matrix, step: str) -> sp.Matrix:
        """Name each non-trivial component of a 3-vector as ``{name}_x``, ``_y``, ``_z``."""
        return sp.Matrix(
            [self.define(f"{name}_{axis}", vector[k], step) for k, axis in enumerate("xyz")]
        )

    def definitions(self) -> dict[sp.Symbol, sp.Expr]:
        """Symbol → right-hand side, in program order."""
        return {a.symbol: a.expr for a in self.assignments}

    def expand(self, expr: sp.Expr) -> sp.Expr:
        """Substitute every intermediate back, down to inputs and parameters (for checks)."""
        for a in reversed(self.assignments):
            expr = expr.xreplace({a.symbol: a.expr})
        return expr
