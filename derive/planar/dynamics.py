"""Required wrenches of the bodies and the recursive relations (10)-(11), for any leg type.

Each moving body k of a leg is described about its first joint point ``X_k`` (world frame): the
wrench ``(F_k0, M_k0)`` that must act on it, at ``X_k``, for it to move as the kinematics says
(inertia, minus its weight). The chain wrench of joint k, ``(F_k, M_k)``, is that of body k plus
everything after it in the chain, moved to ``X_k`` (eqs. 10-11):

    F_3 = F_30,  F_2 = F_20 + F_3,  F_1 = F_10 + F_2,
    M_3 = M_30,  M_2 = M_20 + M_3 + (X3 - X2) x F_3,  M_1 = M_10 + M_2 + (X2 - X1) x F_2.

The platform is carried by leg A's chain only (the robot is cut open at the other legs' third
joints); legs B and C see it through the closure of the virtual motions (:mod:`.virtual_work`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.geometry import Robot
from rpr3gen_derive.planar.kinematics import LegKinematics, body_offsets, offset_length2
from rpr3gen_derive.planar.vectors import ZERO, Vec, add, cross, perp, rotate, scale, sub

STEP_INERTIA = "inertia forces and moments of each body"
STEP_RECURSION = "recursive relations (10)-(11)"


@dataclass(frozen=True)
class Inertia:
    """A body's inertia about a point: mass, first moment ``m (COM - point)`` (current, world)
    and moment of inertia about the point, axis z. Every wrench is linear in these."""

    mass: sp.Expr
    first_moment: Vec
    about_point: sp.Expr


@dataclass(frozen=True)
class Wrench:
    """A force (world) and its moment about a stated point (z component)."""

    force: Vec
    moment: sp.Expr


@dataclass(frozen=True)
class LegWrenches:
    """The chain wrenches ``(F_k, M_k)`` of eqs. (10)-(11), k = 1, 2, 3, each about ``X_k``."""

    joints: tuple[Wrench, Wrench, Wrench]


ZERO_WRENCH = Wrench(ZERO, sp.Integer(0))


def required_wrench(
    body: Inertia, accel: Vec, omega: sp.Expr, eps: sp.Expr, gravity: Vec
) -> Wrench:
    """The wrench, about the body's reference point P, that moves the body as given.

    With ``a`` the acceleration of P (a point of the body), ``omega`` and ``eps`` the body's
    angular velocity and acceleration, ``mc = m (COM - P)`` and ``J_P`` its inertia about P:
    ``F = m (a - g) + eps perp(mc) - omega^2 mc`` and ``M_P = J_P eps + mc x (a - g)``
    (Newton and Euler, the weight moved to the left side). Linear in ``(m, mc, J_P)``.
    """
    a_g = sub(accel, gravity)
    mc = body.first_moment
    force = add(scale(body.mass, a_g), scale(eps, perp(mc)), scale(-(omega**2), mc))
    return Wrench(force, body.about_point * eps + cross(mc, a_g))


def leg_inertias(kin: LegKinematics) -> tuple[Inertia, Inertia]:
    """Bodies 1 and 2 of a leg about their first joint points, from the model's numbers."""
    g = kin.geometry
    out = []
    for body, offset in zip((1, 2), body_offsets(kin), strict=True):
        m = g.mass[body - 1]
        out.append(
            Inertia(m, scale(m, offset), g.inertia[body - 1] + m * offset_length2(kin, body))
        )
    return out[0], out[1]


def platform_inertia(robot: Robot, cos_phi: sp.Expr, sin_phi: sp.Expr) -> Inertia:
    """The platform about G: ``m3``, ``m3 R(phi) c3``, ``J3 + m3 |c3|^2``."""
    p = robot.platform
    offset = rotate(cos_phi, sin_phi, p.com)
    return Inertia(
        p.mass, scale(p.mass, offset), p.inertia + p.mass * (p.com[0] ** 2 + p.com[1] ** 2)
    )


def platform_wrench(robot: Robot, body: Inertia, payload: bool = True) -> Wrench:
    """The wrench the platform requires, about G: its inertia and weight (:func:`required_wrench`,
    the motion being the input q, q', q''), less the payload wrench acting on it at G."""
    own = required_wrench(body, (syms.ddx, syms.ddy), syms.dphi, syms.ddphi, robot.gravity)
    if not payload:
        return own
    return Wrench(sub(own.force, robot.payload_force), own.moment - robot.payload_moment)


def moved(wrench: Wrench, arm: Vec) -> Wrench:
    """The same wrench about a point ``arm`` behind: ``M + arm x F`` (``arm`` = old - new)."""
    return Wrench(wrench.force, wrench.moment + cross(arm, wrench.force))


InertiaBuilder = Callable[[LegKinematics], tuple[Inertia, Inertia]]


def leg_wrenches(
    prog: Program,
    kin: LegKinematics,
    platform: Wrench | None,
    robot: Robot,
    inertias: InertiaBuilder = leg_inertias,
    tag: str = "",
    define: Callable[[str, sp.Expr, str], sp.Expr] | None = None,
) -> LegWrenches:
    """``(F_k, M_k)`` of eqs. (10)-(11) for one leg, in its frame, named ``W1_A_x`` and so on.

    ``platform``: the platform's required wrench about G (world) when this leg carries it, else
    None.
    ``inertias``: the bodies' inertial data (the model's numbers, or symbols for the regressor).
    ``define``: how to name an assignment (default ``prog.define``; a builder's reuses one that
    exists with the same right-hand side).
    """
    leg = kin.leg
    define = define or prog.define

    def named(name: str, w: Wrench, step: str) -> Wrench:
        return Wrench(
            (
                define(f"{name}{tag}_{leg}_x", w.force[0], step),
                define(f"{name}{tag}_{leg}_y", w.force[1], step),
            ),
            define(f"{name}{tag}_{leg}_z", w.moment, step),
        )

    body1, body2 = inertias(kin)
    gravity = kin.to_frame(robot.gravity)
    g = (
        define(f"g{tag}_{leg}_x1", gravity[0], STEP_INERTIA),
        define(f"g{tag}_{leg}_y1", gravity[1], STEP_INERTIA),
    )
    own1 = required_wrench(body1, kin.accel[0], kin.omega[0], kin.eps[0], g)
    own2 = required_wrench(body2, kin.accel[1], kin.omega[1], kin.eps[1], g)
    own1, own2 = named("W10", own1, STEP_INERTIA), named("W20", own2, STEP_INERTIA)
    w3 = ZERO_WRENCH
    if platform is not None:  # about G, moved to X3 (the arm G - X3 is -s), in the leg frame
        at_x3 = moved(platform, scale(-1, kin.s))
        w3 = named("W3", Wrench(kin.to_frame(at_x3.force), at_x3.moment), STEP_INERTIA)
    arm1, arm2, _ = kin.arms
    w2 = Wrench(add(own2.force, w3.force), own2.moment + moved(w3, arm2).moment)
    w2 = named("W2", w2, STEP_RECURSION)
    w1 = Wrench(add(own1.force, w2.force), own1.moment + moved(w2, sub(arm1, arm2)).moment)
    w1 = named("W1", w1, STEP_RECURSION)
    return LegWrenches((w1, w2, w3))
