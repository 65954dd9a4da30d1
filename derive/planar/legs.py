"""The leg types: what is specific to each, in one table (:data:`LEG_TYPES`).

A leg is a serial chain base - joint 1 - body 1 - joint 2 - body 2 - joint 3 - platform of
revolute (R) and prismatic (P) joints. Everything else the derivation does (rates,
accelerations, wrenches, virtual work, the control model, the direct kinematics of the locked
legs) is written once for any chain; a leg type only adds its **inverse kinematics**: given the
platform, where joint 3's point ``X3`` is and the platform angle ``phi``, the joint
coordinates in the leg's working mode, the current joint points, axes and body references.

Working mode (docs/interfaces.md): the solution where the serial determinant
``D = det d(x3, y3, phi) / d(q1, q2, q3)`` has the sign ``sigma`` it has at home. Two R joints
put ``X3`` on a circle and one P joint on a line, so four types have two solutions (picked by
``sigma``) and the three with two P joints one. The formulas, with ``r`` from joint 1's point to
``X3`` and ``a c + b perp(c)`` a body vector of coordinates ``(a, b)`` (``geometry``):

======  ===========================================================  ========================
type    inverse kinematics                                           ``D``
======  ===========================================================  ========================
RRR     two links of lengths ``|h1|``, ``|h2|`` from joint 1 to X3    ``cross(c1, c2)``
RPR     ``|r|^2 = (A + q2)^2 + B^2`` along the slide                  ``-(A + q2)``
RRP     ``|y - q3 w3|^2 = |h1|^2``, ``w3 = R(phi) u3``                 ``c1 . w3``
PRR     ``|y - q1 u1|^2 = |h2|^2``                                    ``c2 . u1``
PPR     ``y = q1 u1 + q2 u2``                                         ``cross(u1, u2)``
PRP     ``y = q1 u1 + q3 w3``                                         ``-cross(u1, w3)``
RPP     ``y = q2 w2 + q3 w3``, ``w = R(phi) u``                       ``cross(u2, u3)``
======  ===========================================================  ========================

Revolute coordinates found by ``atan2`` are in ``(-pi, pi]``; the last revolute joint of the
chain takes the rest of ``phi`` (``phi`` minus the others), unwrapped, so that the revolute
coordinates of a leg always add up to ``phi``.

Adding a leg type: a function here and a row of :data:`LEG_TYPES` (and its entry in the
interface's list of types).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.functions import wrap_angle
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar.geometry import LegGeometry, Reference
from rpr3gen_derive.planar.vectors import (
    Vec,
    add,
    along,
    cross,
    dot,
    norm2,
    perp,
    rotate,
    scale,
    sub,
)

STEP_POSE = "inverse kinematics of the legs, eq. (5)"


@dataclass(frozen=True)
class Platform:
    """The platform's pose as the legs see it: ``phi``, its cosine and sine (program symbols)."""

    phi: sp.Expr
    cos_phi: sp.Expr
    sin_phi: sp.Expr

    def turn(self, v: Vec) -> Vec:
        """``R(phi) v``."""
        return rotate(self.cos_phi, self.sin_phi, v)


@dataclass(frozen=True)
class LegPose:
    """A leg's configuration from its inverse kinematics (program symbols).

    The leg is described in its own orthonormal *leg frame* ``(e, perp(e))``: ``frame`` is the
    unit vector ``e`` in the world frame (a prismatic axis, or x0 for a leg of revolute joints),
    and every other vector is given by its coordinates in that frame, which the inverse
    kinematics knows exactly (a prismatic axis is ``(1, 0)``), as the paper writes eq. (6) in
    the leg's frame 1. ``arms``: ``X3 - X1`` and ``X3 - X2`` (joint 3's point from joints 1 and
    2); ``axes``: each P joint's current unit axis; ``references``: the current values of bodies
    1 and 2's reference vectors (same length as at home); ``D``: the serial determinant (its
    sign is ``sigma``); ``units``: pairs of program symbols known to be unit vectors' coordinates
    (``a^2 + b^2 = 1``), which simplifies the virtual work's algebra.
    """

    q: tuple[sp.Expr, sp.Expr, sp.Expr]
    frame: Vec
    arms: tuple[Vec, Vec]
    axes: dict[int, Vec]
    references: tuple[Vec, Vec]
    D: sp.Expr
    units: tuple[Vec, ...] = ()

    def world(self, v: Vec) -> Vec:
        """A vector given in the leg frame, in the world frame."""
        return along(v, self.frame)


class _Leg:
    """Names the intermediates of one leg's inverse kinematics in the program."""

    def __init__(self, prog: Program, g: LegGeometry, names: tuple[str, str, str]) -> None:
        self.prog, self.g, self.names = prog, g, names

    def define(self, name: str, expr: sp.Expr) -> sp.Expr:
        return self.prog.define(f"{name}_{self.g.leg}", expr, STEP_POSE)

    def vector(self, name: str, v: Vec) -> Vec:
        return (self.define(f"{name}x", v[0]), self.define(f"{name}y", v[1]))

    def coordinate(self, joint: int, expr: sp.Expr) -> sp.Expr:
        return self.define(self.names[joint - 1], expr)

    def angle(self, reference: Reference, current: Vec) -> sp.Expr:
        """The rotation from ``reference.home`` to ``current`` (any positive multiple of the
        reference's current value), in ``(-pi, pi]`` (``[-pi, pi]`` from a given angle, the
        difference named before it is wrapped, so that it is computed once)."""
        if reference.angle is not None:
            turn = self.define("turn", sp.atan2(current[1], current[0]) - reference.angle)
            return wrap_angle(turn)
        h = reference.home
        return sp.atan2(cross(h, current), dot(h, current))


def in_frame(e: Vec, v: Vec) -> Vec:
    """Coordinates of the world vector ``v`` in the frame ``(e, perp(e))``, ``e`` a unit vector."""
    return (dot(e, v), cross(e, v))


X0: Vec = (sp.Integer(1), sp.Integer(0))


def _slide_to_circle(
    leg: _Leg, w: Vec, y: Vec, radius2: sp.Expr
) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """The slide ``q`` along the unit ``w`` with ``|y - q w|^2 = radius2``, in the working mode:
    ``(t, k, D)``, ``(t, k)`` the coordinates of ``y`` in the frame ``(w, perp(w))``,
    ``D = sigma sqrt(radius2 - k^2)`` and ``q = t - D`` (RRP and PRR)."""
    t, k = (leg.define("t", dot(w, y)), leg.define("k", cross(w, y)))
    D = leg.define("D", leg.g.sigma * sp.sqrt(radius2 - k**2))
    return t, k, D


def _two_links(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """RRR: joint 2's point is where the circles about joint 1 and about X3 meet (the leg frame
    is the world's)."""
    g = leg.g
    h1, h2 = g.references
    r = leg.vector("r", sub(x3, g.points[0]))
    r2 = leg.define("r2", norm2(r))
    k = leg.define("k", (r2 + h1.length2 - h2.length2) / 2)
    D = leg.define("D", g.sigma * sp.sqrt(h1.length2 * r2 - k**2))
    inv_r2 = leg.define("inv_r2", 1 / r2)
    c1 = leg.vector("c1", scale(inv_r2, sub(scale(k, r), scale(D, perp(r)))))
    c2 = leg.vector("c2", sub(r, c1))
    q1 = leg.coordinate(1, leg.angle(h1, c1))
    # q2: body 2's rotation relative to body 1, from the two bodies' rotations from home.
    cos1, sin1 = dot(h1.home, c1), cross(h1.home, c1)
    cos2, sin2 = dot(h2.home, c2), cross(h2.home, c2)
    q2 = leg.coordinate(2, sp.atan2(sin2 * cos1 - cos2 * sin1, cos2 * cos1 + sin2 * sin1))
    q3 = leg.coordinate(3, platform.phi - q1 - q2)
    return LegPose((q1, q2, q3), X0, (r, c2), {}, (c1, c2), D)


def _rpr(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """RPR: X3 on the slide's line, turned about joint 1: ``|r|^2 = (A + q2)^2 + B^2``.

    ``(A, B)``: coordinates of ``X3 - X1`` along the slide and across it at ``q2 = 0``; the leg
    frame is the slide's axis ``w = (s r - B perp(r)) / |r|^2``, ``s = A + q2``, in which
    ``X3 - X1 = (s, B)``.
    """
    g = leg.g
    (a12, b12), (a23, b23) = g.links
    along_slide, across = a12 + a23, b12 + b23
    r = leg.vector("r", sub(x3, g.points[0]))
    if across == 0:  # the slide's line through joint 1 (the paper's robot): w = r / |r|
        length = leg.define("L", sp.sqrt(norm2(r)))
        s = leg.define("s", -g.sigma * length)
        inv_length = leg.define("inv_L", 1 / length)
        w = leg.vector("w", scale(-g.sigma * inv_length, r))
        direction = scale(-g.sigma, r)
    else:
        r2 = leg.define("r2", norm2(r))
        s = leg.define("s", -g.sigma * sp.sqrt(r2 - across**2))
        direction = sub(scale(s, r), scale(across, perp(r)))
        w = leg.vector("w", scale(1 / r2, direction))
    q2 = leg.coordinate(2, s - along_slide)
    q1 = leg.coordinate(1, leg.angle(g.references[0], direction))
    q3 = leg.coordinate(3, platform.phi - q1)
    return LegPose((q1, q2, q3), w, ((s, across), (a23, b23)), {2: X0}, (X0, X0), -s)


def _rrp(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """RRP: the slide turns with the platform (the leg frame); joint 2's point is on it and
    ``|h1|`` from joint 1: ``|y - q3 w3|^2 = |h1|^2``."""
    g = leg.g
    h1 = g.references[0]
    a23, b23 = g.links[1]
    w3 = leg.vector("w3", platform.turn(g.axis(3)))
    y = sub(sub(x3, g.points[0]), along((a23, b23), w3))
    t, k, D = _slide_to_circle(leg, w3, y, h1.length2)
    q3 = leg.coordinate(3, t - D)
    c1 = (D, k)  # X2 - X1 = y - q3 w3 in the frame
    q1 = leg.coordinate(1, leg.angle(h1, along(c1, w3)))
    q2 = leg.coordinate(2, platform.phi - q1)
    arms = ((t + a23, k + b23), (a23 + q3, b23))
    return LegPose((q1, q2, q3), w3, arms, {3: X0}, (c1, X0), D)


def _prr(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """PRR: body 1 slides along u1 (the leg frame); X3 is ``|h2|`` from joint 2's point:
    ``|y - q1 u1|^2 = |h2|^2``."""
    g = leg.g
    h2 = g.references[1]
    u1 = g.axis(1)
    y = sub(x3, g.points[1])
    t, k, D = _slide_to_circle(leg, u1, y, h2.length2)
    q1 = leg.coordinate(1, t - D)
    c2 = (D, k)  # X3 - X2 = y - q1 u1 in the frame
    q2 = leg.coordinate(2, leg.angle(h2, along(c2, u1)))
    q3 = leg.coordinate(3, platform.phi - q2)
    link = leg.vector("l21f", in_frame(u1, sub(g.points[1], g.points[0])))
    return LegPose((q1, q2, q3), u1, (add(c2, link), c2), {1: X0}, (X0, c2), D)


def _ppr(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """PPR: two slides place X3: ``X3 - X3(0) = q1 u1 + q2 u2`` (the leg frame is u1)."""
    g = leg.g
    u1 = g.axis(1)
    u2 = leg.vector("u2f", in_frame(u1, g.axis(2)))
    y = in_frame(u1, sub(x3, g.points[2]))
    D = u2[1]
    inv_d = leg.define("inv_det", 1 / D)
    q2 = leg.coordinate(2, y[1] * inv_d)
    q1 = leg.coordinate(1, y[0] - q2 * u2[0])
    q3 = leg.coordinate(3, platform.phi)
    arm2 = leg.vector("l32f", in_frame(u1, sub(g.points[2], g.points[1])))
    arm1 = add(leg.vector("l31f", in_frame(u1, sub(g.points[2], g.points[0]))), scale(q2, u2))
    return LegPose((q1, q2, q3), u1, (arm1, arm2), {1: X0, 2: u2}, (u2, u2), D, (u2,))


def _prp(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """PRP: a fixed slide (the leg frame) and one turning with the platform:
    ``y = q1 u1 + q3 w3``."""
    g = leg.g
    u1 = g.axis(1)
    a23, b23 = g.links[1]
    w3 = leg.vector("w3", in_frame(u1, platform.turn(g.axis(3))))
    y = in_frame(u1, sub(x3, g.points[1]))
    y = sub(y, along((a23, b23), w3))
    inv_det = leg.define("inv_det", 1 / w3[1])
    q3 = leg.coordinate(3, y[1] * inv_det)
    q1 = leg.coordinate(1, y[0] - q3 * w3[0])
    q2 = leg.coordinate(2, platform.phi)
    arm2 = along((a23 + q3, b23), w3)
    arm1 = add(arm2, leg.vector("l21f", in_frame(u1, sub(g.points[1], g.points[0]))))
    return LegPose((q1, q2, q3), u1, (arm1, arm2), {1: X0, 3: w3}, (X0, w3), -w3[1], (w3,))


def _rpp(leg: _Leg, platform: Platform, x3: Vec) -> LegPose:
    """RPP: both slides turn with the platform; the leg frame is the first, w2:
    ``y = q2 w2 + q3 w3``."""
    g = leg.g
    link1, link2 = g.links  # body 1's along u2, body 2's along u3
    w2 = leg.vector("w2", platform.turn(g.axis(2)))
    u3 = leg.vector("u3f", in_frame(g.axis(2), g.axis(3)))  # w3 in the frame: a constant
    arm1 = in_frame(w2, sub(x3, g.points[0]))
    y = sub(sub(arm1, link1), along(link2, u3))
    inv_d = leg.define("inv_det", 1 / u3[1])
    q3 = leg.coordinate(3, y[1] * inv_d)
    q2 = leg.coordinate(2, y[0] - q3 * u3[0])
    q1 = leg.coordinate(1, platform.phi)
    arm2 = along((link2[0] + q3, link2[1]), u3)
    return LegPose((q1, q2, q3), w2, (arm1, arm2), {2: X0, 3: u3}, (X0, u3), u3[1], (u3,))


InverseKinematics = Callable[[_Leg, Platform, Vec], LegPose]


@dataclass(frozen=True)
class LegType:
    """A leg type: its joints and its inverse kinematics (see the module's table)."""

    name: str
    inverse_kinematics: InverseKinematics

    @property
    def joints(self) -> str:
        return self.name


#: Every leg type rpr3gen derives (PPP cannot turn the platform).
LEG_TYPES: dict[str, LegType] = {
    t.name: t
    for t in (
        LegType("RRR", _two_links),
        LegType("RPR", _rpr),
        LegType("RRP", _rrp),
        LegType("PRR", _prr),
        LegType("PPR", _ppr),
        LegType("PRP", _prp),
        LegType("RPP", _rpp),
    )
}


def inverse_kinematics(
    prog: Program, g: LegGeometry, platform: Platform, x3: Vec, names: tuple[str, str, str]
) -> LegPose:
    """The leg's configuration in its working mode for joint 3's point ``x3`` (eq. 5)."""
    return LEG_TYPES[g.kinds].inverse_kinematics(_Leg(prog, g, names), platform, x3)
