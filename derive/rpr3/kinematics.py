"""Inverse kinematics of one leg: pose (5), connectivity and velocities (6), accelerations (9).

Vectors are 3-vectors with z = 0 for the plane. ``s`` is the platform joint relative to G,
``A3 - G``, in the world frame; the leg vector is ``A3 - A1 = L e`` with ``L = l0 + l2 + lambda21``.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.frames import leg_matrices, rot_z, skew, u3

STEP_POSE = "inverse kinematics, eq. (5)"
STEP_VELOCITY = "connectivity conditions and velocities, eq. (6)"
STEP_ACCELERATION = "accelerations, eq. (9)"


@dataclass(frozen=True)
class LegKinematics:
    """Kinematic state of one leg, as symbols of the program (world frame unless noted)."""

    leg: str
    s: sp.Matrix  # A3 - G (m)
    length: sp.Expr  # |A1 A3| = l0 + l2 + lambda21 (m)
    cos_theta: sp.Expr  # cos(alpha + phi10): x1 = e = (cos_theta, sin_theta)
    sin_theta: sp.Expr
    phi10: sp.Expr
    lambda21: sp.Expr
    phi32: sp.Expr
    a10: sp.Matrix
    a21: sp.Matrix
    a32: sp.Matrix
    rho: sp.Matrix  # G - A3 in frame 3 (constant), the paper's r_3^GA
    accel_a3: sp.Matrix  # acceleration of the platform point A3, in frame 1
    accel_a3_world: sp.Matrix  # the same in the world frame
    a30: sp.Matrix  # frame 3 from frame 0: rot(z, phi), frame 3 being parallel to the platform
    connectivity: sp.Matrix  # K of eq. (6) written in frame 1: K (omega10, v21, omega32) = rhs
    omega10: sp.Expr
    v21: sp.Expr
    omega32: sp.Expr
    eps10: sp.Expr
    gamma21: sp.Expr
    eps32: sp.Expr

    @property
    def e(self) -> sp.Matrix:
        """Unit leg axis x1 = z2 (world)."""
        return sp.Matrix([self.cos_theta, self.sin_theta, 0])

    @property
    def n(self) -> sp.Matrix:
        """In-plane normal y1 = y2, the leg axis turned by +90 degrees (world)."""
        return sp.Matrix([-self.sin_theta, self.cos_theta, 0])


def platform_rotation(prog: Program) -> tuple[sp.Expr, sp.Expr]:
    """cos(phi) and sin(phi) of the platform rotation R = rot(z, phi)."""
    return (
        prog.define("cos_phi", sp.cos(syms.phi), STEP_POSE),
        prog.define("sin_phi", sp.sin(syms.phi), STEP_POSE),
    )


def leg_connectivity_matrix(length: sp.Expr) -> sp.Matrix:
    """Eq. (6) pre-multiplied by a10: the connectivity conditions in the leg frame 1.

    Rows: the x1 and y1 components of the velocity of the platform point A3, and the platform's
    angular velocity; columns: omega10, v21, omega32. Rotating the leg by omega10 moves A3 by
    ``L omega10`` along y1; the slide v21 moves it along x1; omega32 only turns the platform.
    """
    return sp.Matrix([[0, 1, 0], [length, 0, 0], [1, 0, 1]])


def solve_connectivity(matrix: sp.Matrix, rhs: sp.Matrix) -> list[sp.Expr]:
    """Solve ``matrix @ unknowns = rhs`` for a small matrix by explicit cofactors (no inv())."""
    det = matrix.det(method="bareiss")
    adjugate = matrix.adjugate()
    return [sp.expand(sum(adjugate[i, j] * rhs[j] for j in range(3)) / det) for i in range(3)]


def leg_kinematics(prog: Program, leg: str, cos_phi: sp.Expr, sin_phi: sp.Expr) -> LegKinematics:
    """Pose, velocities and accelerations of ``leg`` from the platform motion.

    Eq. (5): ``(l0 + l2 + lambda21)(cos, sin)(phi10 + alpha) = G + R p - A1``.
    Eq. (6): the connectivity conditions in frame 1 give omega10, v21 and omega32.
    Eq. (9): their time derivative, with the same matrix, gives eps10, gamma21, eps32.
    """
    step = STEP_POSE
    p = syms.platform_joint(leg)
    s = prog.define_vector(f"s_{leg}", rot_z(cos_phi, -sin_phi) * p, step)
    leg_vector = sp.Matrix([syms.x, syms.y, 0]) + s - syms.base_pivot(leg)
    lx = prog.define(f"lx_{leg}", leg_vector[0], step)
    ly = prog.define(f"ly_{leg}", leg_vector[1], step)
    length = prog.define(f"L_{leg}", sp.sqrt(lx**2 + ly**2), step)
    cos_theta = prog.define(f"cos_theta_{leg}", lx / length, step)
    sin_theta = prog.define(f"sin_theta_{leg}", ly / length, step)
    # phi10 is the leg angle measured from alpha, wrapped to [-pi, pi].
    turn = prog.define(f"theta_minus_alpha_{leg}", sp.atan2(ly, lx) - syms.alpha(leg), step)
    phi10 = prog.define(f"phi10_{leg}", syms.wrap_angle(turn), step)
    lambda21 = prog.define(f"lambda21_{leg}", length - syms.l0 - syms.l2, step)
    phi32 = prog.define(f"phi32_{leg}", syms.phi - phi10, step)  # eq. (4): phi10 + phi32 = phi
    # Frame 3 is parallel to the platform frame (see frames.leg_matrices): it is turned from
    # frame 2 by phi - theta, whose cosine and sine need no further trigonometry.
    cos_turn = prog.define(f"cos_turn32_{leg}", cos_phi * cos_theta + sin_phi * sin_theta, step)
    sin_turn = prog.define(f"sin_turn32_{leg}", sin_phi * cos_theta - cos_phi * sin_theta, step)
    a10, a21, a32 = leg_matrices(cos_theta, sin_theta, cos_turn, sin_turn)
    rho = -p  # G - A3 in frame 3, a constant: the paper's r_3^GA

    connectivity = leg_connectivity_matrix(length)

    step = STEP_VELOCITY
    v_a3 = syms.qd[0:2, :].col_join(sp.Matrix([0])) + syms.dphi * skew(u3) * s
    v_a3_1 = a10 * v_a3
    rhs = sp.Matrix(
        [
            prog.define(f"vA3_x1_{leg}", v_a3_1[0], step),
            prog.define(f"vA3_y1_{leg}", v_a3_1[1], step),
            syms.dphi,
        ]
    )
    omega10, v21, omega32 = (
        prog.define(f"{name}_{leg}", value, step)
        for name, value in zip(
            ("omega10", "v21", "omega32"), solve_connectivity(connectivity, rhs), strict=True
        )
    )

    step = STEP_ACCELERATION
    a_a3 = (
        syms.qdd[0:2, :].col_join(sp.Matrix([0]))
        + syms.ddphi * skew(u3) * s
        + syms.dphi**2 * skew(u3) * skew(u3) * s
    )
    a_a3_1 = a10 * a_a3
    # Derivative of (6): the same matrix; the velocity products move to the right-hand side.
    accel_a3 = sp.Matrix(
        [
            prog.define(f"aA3_x1_{leg}", a_a3_1[0], step),
            prog.define(f"aA3_y1_{leg}", a_a3_1[1], step),
            0,
        ]
    )
    rhs = sp.Matrix(
        [
            accel_a3[0] + length * omega10**2,
            accel_a3[1] - 2 * v21 * omega10,
            syms.ddphi,
        ]
    )
    eps10, gamma21, eps32 = (
        prog.define(f"{name}_{leg}", value, step)
        for name, value in zip(
            ("eps10", "gamma21", "eps32"), solve_connectivity(connectivity, rhs), strict=True
        )
    )
    return LegKinematics(
        leg=leg,
        s=s,
        length=length,
        cos_theta=cos_theta,
        sin_theta=sin_theta,
        phi10=phi10,
        lambda21=lambda21,
        phi32=phi32,
        a10=a10,
        a21=a21,
        a32=a32,
        rho=rho,
        accel_a3=accel_a3,
        accel_a3_world=a_a3,
        a30=rot_z(cos_phi, sin_phi),
        connectivity=connectivity,
        omega10=omega10,
        v21=v21,
        omega32=omega32,
        eps10=eps10,
        gamma21=gamma21,
        eps32=eps32,
    )


def reach(prog: Program, kinematics: dict[str, LegKinematics]) -> sp.Expr:
    """The serial-singularity measure: ``min_i (l0 + lambda21_i) / l0 = min_i |A1A2_i| / l0``.

    1 in the central configuration; it reaches 0 when a piston joint A2 comes onto its base pivot
    A1, and is negative with the piston behind it. Poses where it is not positive are refused:
    a real cylinder cannot put its piston behind the pivot, and refusing them keeps every leg at
    least ``l2`` long, away from the serial singularity ``|A1A3| = 0`` where the leg's direction
    (eq. 5) is undefined and every load grows as 1 / |A1A3|.
    """
    ratios = [(syms.l0 + kin.lambda21) / syms.l0 for kin in kinematics.values()]
    return prog.define("reach", sp.Min(*ratios), STEP_POSE)
