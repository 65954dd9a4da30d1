"""Symbols of the 3-RPR derivation: inputs and model parameters.

Every symbol is created once, here, with its assumptions. Names follow the paper where it has
one (``phi10``, ``lambda21``, ``omega32``); the leg letter is a suffix (``phi10_A``).
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.functions import wrap_angle

LEGS: tuple[str, ...] = ("A", "B", "C")

#: Platform pose, velocity and acceleration (paper: x0G, y0G, phi and their derivatives).
POSE_NAMES: tuple[str, ...] = ("x", "y", "phi")
VELOCITY_NAMES: tuple[str, ...] = ("dx", "dy", "dphi")
ACCELERATION_NAMES: tuple[str, ...] = ("ddx", "ddy", "ddphi")

#: Model parameters, in the order of the generated parameter vector (docs/interfaces.md).
PARAM_NAMES: tuple[str, ...] = (
    "xA1", "yA1", "xB1", "yB1", "xC1", "yC1",
    "xA3", "yA3", "xB3", "yB3", "xC3", "yC3",
    "alpha_A", "alpha_B", "alpha_C",
    "l0", "l2", "c1", "c2", "m1", "m2", "m3", "J1", "J2", "J3",
    "gx", "gy", "fx", "fy", "mz",
    "c1_perp", "c2_perp",
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


def base_pivot(leg: str) -> sp.Matrix:
    """World position of the fixed pivot ``A1`` of ``leg`` (m), a 3-vector with z = 0."""
    return sp.Matrix([params[f"x{leg}1"], params[f"y{leg}1"], 0])


def platform_joint(leg: str) -> sp.Matrix:
    """Position of the platform joint ``A3`` of ``leg`` in the platform frame ``G xG yG zG``."""
    return sp.Matrix([params[f"x{leg}3"], params[f"y{leg}3"], 0])


def alpha(leg: str) -> sp.Symbol:
    """Leg angle in the central configuration, alpha_i (rad)."""
    return params[f"alpha_{leg}"]


__all__ = ["LEGS", "PARAM_NAMES", "alpha", "base_pivot", "platform_joint", "wrap_angle"]
