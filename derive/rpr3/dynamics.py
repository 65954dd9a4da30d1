"""Inertia wrenches and the recursive relations (10)–(11) of one leg.

Each body k of a leg is described in its own frame k, about its joint point A_k: the cylinder
(1) about A1 in frame 1, the piston (2) about A2 in frame 2, the platform (3) about A3 in frame
3. The platform is carried by leg A's chain only (the robot is cut open at A3, B3, C3); legs B
and C see it only through the closure of the virtual motions (``virtual_work``).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.frames import skew, u1, u2, u3
from rpr3gen_derive.rpr3.kinematics import LegKinematics

STEP_INERTIA = "inertia forces and moments of each body"
STEP_RECURSION = "recursive relations (10)-(11)"

ZERO = sp.zeros(3, 1)


@dataclass(frozen=True)
class BodyMotion:
    """Absolute motion of a body, in its own frame k, at its joint point A_k."""

    omega: sp.Matrix  # angular velocity omega_k0
    eps: sp.Matrix  # angular acceleration eps_k0
    gamma: sp.Matrix  # acceleration of A_k, gamma_k0


@dataclass(frozen=True)
class LegWrenches:
    """F_k, M_k of eqs. (10)-(11) for k = 1, 2, 3, each in frame k (M about A_k)."""

    F: tuple[sp.Matrix, sp.Matrix, sp.Matrix]
    M: tuple[sp.Matrix, sp.Matrix, sp.Matrix]


def body_motions(kin: LegKinematics) -> tuple[BodyMotion, BodyMotion, BodyMotion]:
    """Recursive kinematics of the cylinder, the piston and the platform (paper ref. [9]).

    ``omega_k0 = a_k,k-1 omega_k-1,0 + omega_k,k-1 u3``, and
    ``gamma_k0 = a_k,k-1 [gamma_k-1,0 + (~omega ~omega + ~eps)_k-1,0 r_k,k-1]
    + 2 v_k,k-1 ~omega_k0 u3 + gamma_k,k-1 u3``. For the platform, whose motion is given,
    gamma_30 is the acceleration of A3 found in eq. (9), turned into frame 3.
    """
    cyl = BodyMotion(omega=kin.omega10 * u3, eps=kin.eps10 * u3, gamma=ZERO)
    r21 = (syms.l0 + kin.lambda21) * u1  # A1 -> A2 in frame 1
    omega20 = kin.a21 * cyl.omega
    piston = BodyMotion(
        omega=omega20,
        eps=kin.a21 * cyl.eps,
        gamma=kin.a21 * (skew(cyl.omega) ** 2 + skew(cyl.eps)) * r21
        + 2 * kin.v21 * skew(omega20) * u3
        + kin.gamma21 * u3,
    )
    # The platform's motion is the input: its point A3 accelerates as eq. (9) found, which
    # equals the chain recursion a32 [gamma_20 + (~w ~w + ~eps)_20 r32]. Frame 3 is parallel to
    # the platform frame, so a30 = a32 a21 a10 is rot(z, phi), applied directly.
    platform = BodyMotion(
        omega=kin.a32 * piston.omega + kin.omega32 * u3,
        eps=kin.a32 * piston.eps + kin.eps32 * u3,
        gamma=kin.a30 * kin.accel_a3_world,
    )
    return cyl, piston, platform


def required_wrench(
    motion: BodyMotion,
    mass: sp.Expr,
    com: sp.Matrix,
    inertia_about_joint: sp.Matrix,
    gravity: sp.Matrix,
    external_force: sp.Matrix = ZERO,
    external_moment: sp.Matrix = ZERO,
) -> tuple[sp.Matrix, sp.Matrix]:
    """``F_k0 = -f_in - f*`` and ``M_k0 = -m_in - m*`` of a body, about its joint point.

    ``f_in = -m [gamma + (~omega ~omega + ~eps) r_C]``,
    ``m_in = -[m ~r_C gamma + J eps + ~omega J omega]`` (J about the joint point), and the known
    wrench (weight and external load, applied at the centre of mass) ``f* = m g + f_ext``,
    ``m* = ~r_C f* + m_ext``. All vectors in the body frame.
    """
    w, eps = skew(motion.omega), skew(motion.eps)
    f_inertia = -mass * (motion.gamma + (w * w + eps) * com)
    m_inertia = -(
        mass * skew(com) * motion.gamma
        + inertia_about_joint * motion.eps
        + w * inertia_about_joint * motion.omega
    )
    f_known = mass * gravity + external_force
    m_known = skew(com) * f_known + external_moment
    return -f_inertia - f_known, -m_inertia - m_known


def leg_wrenches(prog: Program, kin: LegKinematics, carries_platform: bool) -> LegWrenches:
    """F_k, M_k of eqs. (10)-(11) for one leg, named in the program as ``F1_A_x`` and so on.

    ``F_3 = F_30``, ``F_2 = F_20 + a32^T F_3``, ``F_1 = F_10 + a21^T F_2``;
    ``M_3 = M_30``, ``M_2 = M_20 + a32^T M_3 + ~r32 a32^T F_3``,
    ``M_1 = M_10 + a21^T M_2 + ~r21 a21^T F_2``.
    """
    leg = kin.leg
    cyl, piston, platform = body_motions(kin)
    g1 = kin.a10 * syms.gravity
    g2 = kin.a21 * g1
    g3 = kin.a30 * syms.gravity  # = a32 g2, with a30 = a32 a21 a10 = rot(z, phi)
    # Inertia tensors about the joint point; only the component on the rotation axis acts in
    # planar motion (z1 for the cylinder, x2 = -z0 for the piston, z3 for the platform).
    # Centres of mass off the leg axis by c1_perp, c2_perp along n (y1 = y2 = n).
    c1, c1p = syms.c1, syms.params["c1_perp"]
    c2, c2p = syms.c2, syms.params["c2_perp"]
    F10, M10 = required_wrench(
        cyl, syms.m1, c1 * u1 + c1p * u2, sp.diag(0, 0, syms.J1 + syms.m1 * (c1**2 + c1p**2)), g1
    )
    F20, M20 = required_wrench(
        piston,
        syms.m2,
        c2 * u3 + c2p * u2,
        sp.diag(syms.J2 + syms.m2 * (c2**2 + c2p**2), 0, 0),
        g2,
    )
    step = STEP_INERTIA
    F10 = prog.define_vector(f"F10_{leg}", F10, step)
    M10 = prog.define_vector(f"M10_{leg}", M10, step)
    F20 = prog.define_vector(f"F20_{leg}", F20, step)
    M20 = prog.define_vector(f"M20_{leg}", M20, step)
    if carries_platform:
        rho2 = (kin.rho.T * kin.rho)[0]
        F30, M30 = required_wrench(
            platform,
            syms.m3,
            kin.rho,
            sp.diag(0, 0, syms.J3 + syms.m3 * rho2),
            g3,
            external_force=kin.a30 * syms.payload_force,
            external_moment=syms.payload_moment,  # about z3 = z0
        )
        F3 = prog.define_vector(f"F3_{leg}", F30, step)
        M3 = prog.define_vector(f"M3_{leg}", M30, step)
    else:
        F3, M3 = ZERO, ZERO
    step = STEP_RECURSION
    r21 = (syms.l0 + kin.lambda21) * u1
    r32 = syms.l2 * u3
    F2 = prog.define_vector(f"F2_{leg}", F20 + kin.a32.T * F3, step)
    M2 = prog.define_vector(f"M2_{leg}", M20 + kin.a32.T * M3 + skew(r32) * kin.a32.T * F3, step)
    F1 = prog.define_vector(f"F1_{leg}", F10 + kin.a21.T * F2, step)
    M1 = prog.define_vector(f"M1_{leg}", M10 + kin.a21.T * M2 + skew(r21) * kin.a21.T * F2, step)
    return LegWrenches(F=(F1, F2, F3), M=(M1, M2, M3))
