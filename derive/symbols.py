"""Symbols of the derivation: inputs, model parameters, and the program of named intermediates.

Every symbol is created once, here, with its assumptions. Names follow the paper where it has
one (``phi10``, ``lambda21``, ``omega32``); the leg letter is a suffix (``phi10_A``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

LEGS: tuple[str, ...] = ("A", "B", "C")

#: Platform pose, velocity and acceleration (paper: x0G, y0G, phi and their derivatives).
POSE_NAMES: tuple[str, ...] = ("x", "y", "phi")
VELOCITY_NAMES: tuple[str, ...] = ("dx", "dy", "dphi")
ACCELERATION_NAMES: tuple[str, ...] = ("ddx", "ddy", "ddphi")

#: Model parameters, in the order of the generated parameter vector (interfaces.md).
PARAM_NAMES: tuple[str, ...] = (
    "xA1", "yA1", "xB1", "yB1", "xC1", "yC1",
    "xA3", "yA3", "xB3", "yB3", "xC3", "yC3",
    "alpha_A", "alpha_B", "alpha_C",
    "l0", "l2", "c1", "c2", "m1", "m2", "m3", "J1", "J2", "J3",
    "gx", "gy", "fx", "fy", "mz",
)  # fmt: skip

_POSITIVE = {"l0", "l2", "m1", "m2", "m3", "J1", "J2", "J3"}

q = sp.Matrix([sp.Symbol(n, real=True) for n in POSE_NAMES])
qd = sp.Matrix([sp.Symbol(n, real=True) for n in VELOCITY_NAMES])
qdd = sp.Matrix([sp.Symbol(n, real=True) for n in ACCELERATION_NAMES])
x, y, phi = q
dx, dy, dphi = qd
ddx, ddy, ddphi = qdd

params: dict[str, sp.Symbol] = {
    name: sp.Symbol(name, real=True, positive=True)
    if name in _POSITIVE
    else sp.Symbol(name, real=True)
    for name in PARAM_NAMES
}

l0, l2, c1, c2 = (params[n] for n in ("l0", "l2", "c1", "c2"))
m1, m2, m3, J1, J2, J3 = (params[n] for n in ("m1", "m2", "m3", "J1", "J2", "J3"))
gravity = sp.Matrix([params["gx"], params["gy"], 0])
payload_force = sp.Matrix([params["fx"], params["fy"], 0])
payload_moment = sp.Matrix([0, 0, params["mz"]])


class wrap_angle(sp.Function):  # noqa: N801  (a function, named like sympy's)
    """An angle wrapped into [-pi, pi]: ``x - 2 pi round(x / 2 pi)``.

    Printed as ``x - 2 pi nearbyint(x / 2 pi)`` in C99 and with ``numpy.rint`` in NumPy (see
    printers, lowering); within an ulp or two of C99 ``remainder(x, 2 pi)``, and much cheaper.
    """

    nargs = 1

    def _eval_evalf(self, prec: int) -> sp.Expr:
        x = self.args[0].evalf(prec)
        two_pi = 2 * sp.pi.evalf(prec)
        return (x - two_pi * sp.floor(x / two_pi + sp.Rational(1, 2))).evalf(prec)


def base_pivot(leg: str) -> sp.Matrix:
    """World position of the fixed pivot ``A1`` of ``leg`` (m), a 3-vector with z = 0."""
    return sp.Matrix([params[f"x{leg}1"], params[f"y{leg}1"], 0])


def platform_joint(leg: str) -> sp.Matrix:
    """Position of the platform joint ``A3`` of ``leg`` in the platform frame ``G xG yG zG``."""
    return sp.Matrix([params[f"x{leg}3"], params[f"y{leg}3"], 0])


def alpha(leg: str) -> sp.Symbol:
    """Leg angle in the central configuration, alpha_i (rad)."""
    return params[f"alpha_{leg}"]


@dataclass(frozen=True)
class Assignment:
    """One named intermediate of the derivation: ``symbol = expr``, tagged with its paper step."""

    symbol: sp.Symbol
    expr: sp.Expr
    step: str


@dataclass
class Program:
    """An ordered list of assignments; each right-hand side uses inputs and earlier symbols only.

    The derivation writes the paper's algorithm as such a program, so that the notebooks can show
    each step and the emitter can eliminate common subexpressions across all of it.
    """

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
