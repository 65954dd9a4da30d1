"""Frames and transformation matrices of a leg, paper eqs. (1)–(2).

A matrix ``a_kj`` transforms coordinates from frame j to frame k (``v_k = a_kj v_j``); its rows
are the axes of frame k written in frame j.
"""

from __future__ import annotations

import sympy as sp

#: ``rot(y, pi/2)``: frame 2 from frame 1, so that x2 = -z1, y2 = y1, z2 = x1 (the slide axis).
theta = sp.Matrix([[0, 0, -1], [0, 1, 0], [1, 0, 0]])

#: Unit vectors u1, u2, u3 and their skew-symmetric matrices ũ1, ũ3.
u1 = sp.Matrix([1, 0, 0])
u2 = sp.Matrix([0, 1, 0])
u3 = sp.Matrix([0, 0, 1])


def skew(v: sp.Matrix) -> sp.Matrix:
    """Skew-symmetric matrix ``ṽ`` such that ``ṽ w = v × w``."""
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def rot_z(cos_angle: sp.Expr, sin_angle: sp.Expr) -> sp.Matrix:
    """``rot(z, angle)`` of eq. (2), given the cosine and sine of the angle."""
    return sp.Matrix([[cos_angle, sin_angle, 0], [-sin_angle, cos_angle, 0], [0, 0, 1]])


def leg_matrices(
    cos_theta: sp.Expr, sin_theta: sp.Expr, cos_turn: sp.Expr, sin_turn: sp.Expr
) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """The matrices a10, a21, a32 of eq. (1) for one leg.

    ``a10 = rot(z, phi10) rot(z, alpha) = rot(z, theta)`` with ``theta = alpha + phi10`` the world
    angle of the leg; ``a21 = theta``; ``a32 = rot(z, phi32) rot(z, -alpha) theta^T``, a rotation
    by ``phi - theta`` (``cos_turn``, ``sin_turn``) after ``theta^T``.

    The paper writes ``a32 = rot(z, phi32) a_beta theta^T``. Here the constant turn ``a_beta`` is
    ``rot(z, -alpha)``, which makes frame 3 parallel to the platform frame G xG yG: the platform
    joint vector is then a constant in it for any platform, including ones given by explicit
    joint points (which have no beta), and no trigonometry of alpha is needed. Frame 3 only
    carries intermediates; every output is written in frames 0, 1 or 2, so nothing a user sees
    depends on this choice.
    """
    a10 = rot_z(cos_theta, sin_theta)
    a21 = theta
    a32 = rot_z(cos_turn, sin_turn) * theta.T
    return a10, a21, a32
