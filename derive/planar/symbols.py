"""Symbols of the inputs of the generated functions: the platform's motion, actuator values.

Every symbol is created once, here, with its assumptions. The model parameters belong to a
parametrisation (:mod:`.general`, :mod:`.paper`).
"""

from __future__ import annotations

import sympy as sp

LEGS: tuple[str, ...] = ("A", "B", "C")

#: Platform pose, velocity and acceleration (paper: x0G, y0G, phi and their derivatives).
POSE_NAMES: tuple[str, ...] = ("x", "y", "phi")
VELOCITY_NAMES: tuple[str, ...] = ("dx", "dy", "dphi")
ACCELERATION_NAMES: tuple[str, ...] = ("ddx", "ddy", "ddphi")

q = sp.Matrix([sp.Symbol(n, real=True) for n in POSE_NAMES])
qd = sp.Matrix([sp.Symbol(n, real=True) for n in VELOCITY_NAMES])
qdd = sp.Matrix([sp.Symbol(n, real=True) for n in ACCELERATION_NAMES])
x, y, phi = q
dx, dy, dphi = qd
ddx, ddy, ddphi = qdd

#: Actuator coordinates (rad or m), their rates, and actuator efforts (N m or N): inputs of the
#: control model's functions.
qa = sp.Matrix([sp.Symbol(f"qa_{leg}", real=True) for leg in LEGS])
qa_dot = sp.Matrix([sp.Symbol(f"qa_dot_{leg}", real=True) for leg in LEGS])
tau = sp.Matrix([sp.Symbol(f"tau_{leg}", real=True) for leg in LEGS])

#: Names of every input symbol: no assignment may take one.
INPUT_NAMES: frozenset[str] = frozenset(s.name for s in (*q, *qd, *qdd, *qa, *qa_dot, *tau))
