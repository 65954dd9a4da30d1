"""Leg kinematics for any leg type: pose (5), connectivity and velocities (6), accelerations (9).

The leg type's inverse kinematics (:mod:`.legs`) gives the joint coordinates and the leg in its
own frame ``(e, perp(e))``; the rest is the same for every chain, written in that frame (as the
paper writes eq. 6 in the leg's frame 1). The platform's motion is the input: the velocity of
joint 3's point ``X3`` and the platform's angular velocity are the *connectivity conditions*
(6), ``S q' = (v_X3, phi')`` with the leg's serial Jacobian ``S``, whose column of joint j is
``(perp(X3 - Xj), 1)`` for a revolute joint and ``(w_j, 0)`` for a prismatic one (axis
``w_j``); ``det S = D``. Differentiated, ``S q'' = (a_X3, phi'') - S' q'`` (9), where ``S' q'``
is the acceleration of ``X3`` that the joint rates alone produce, from the recursion of the
chain's point accelerations (paper ref. [9]) with ``q'' = 0``. The same recursion with the joint
accelerations gives each body's motion, which the dynamics uses.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.geometry import LegGeometry, Robot
from rpr3gen_derive.planar.legs import (
    STEP_POSE,
    LegPose,
    Platform,
    in_frame,
    inverse_kinematics,
)
from rpr3gen_derive.planar.vectors import ZERO, Vec, add, along, norm2, perp, scale, sub

STEP_VELOCITY = "connectivity conditions and joint rates, eq. (6)"
STEP_ACCELERATION = "joint accelerations, eq. (9)"

Column = tuple[sp.Expr, sp.Expr, sp.Expr]


@dataclass(frozen=True)
class LegKinematics:
    """A leg's kinematic state, as program symbols; vectors in the leg frame (``pose.frame``).

    ``s``: ``X3 - G`` (world frame); ``omega``, ``eps``: angular velocity and acceleration of
    bodies 1 and 2; ``accel``: the accelerations of the joint points X1 (a point of body 1) and
    X2 (of body 2).
    """

    leg: str
    geometry: LegGeometry
    pose: LegPose
    s: Vec
    qd: tuple[sp.Expr, sp.Expr, sp.Expr]
    qdd: tuple[sp.Expr, sp.Expr, sp.Expr]
    omega: tuple[sp.Expr, sp.Expr]
    eps: tuple[sp.Expr, sp.Expr]
    accel: tuple[Vec, Vec]

    @property
    def q(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        return self.pose.q

    @property
    def kinds(self) -> str:
        return self.geometry.kinds

    @property
    def arms(self) -> tuple[Vec, Vec, Vec]:
        """``X3 - X1``, ``X3 - X2``, ``X3 - X3``, leg frame."""
        return (*self.pose.arms, ZERO)

    def column(self, joint: int) -> Column:
        """Column ``joint`` (1-3) of the serial Jacobian S (leg frame)."""
        return serial_column(self.kinds, self.pose, joint)

    def body_vector(self, body: int, coords: Vec) -> Vec:
        """The current value (leg frame) of a vector of body ``body`` given by coordinates."""
        return along(coords, self.pose.references[body - 1])

    def to_frame(self, v: Vec) -> Vec:
        """A world vector in the leg frame."""
        return in_frame(self.pose.frame, v)


def serial_column(kinds: str, pose: LegPose, joint: int) -> Column:
    """Column ``joint`` (1-3) of a leg's serial Jacobian S in the leg frame: what a unit rate of
    the joint does to joint 3's point (velocity) and to the platform (angular velocity)."""
    if kinds[joint - 1] == "R":
        arm = perp((*pose.arms, ZERO)[joint - 1])
        return (arm[0], arm[1], sp.Integer(1))
    w = pose.axes[joint]
    return (w[0], w[1], sp.Integer(0))


def platform_rotation(prog: Program) -> Platform:
    """cos(phi) and sin(phi) of the platform rotation R = rot(z, phi), once for all legs."""
    return Platform(
        syms.phi,
        prog.define("cos_phi", sp.cos(syms.phi), STEP_POSE),
        prog.define("sin_phi", sp.sin(syms.phi), STEP_POSE),
    )


def _serial_solve(
    prog: Program,
    columns: list[Column],
    det: sp.Expr,
    inv_det: sp.Expr,
    rhs: Column,
    names: list[str],
    step: str,
) -> tuple[sp.Expr, ...]:
    """``S x = rhs`` by cofactors, ``x = adj(S) rhs / det S`` (no symbolic inverse)."""
    S = sp.Matrix(3, 3, lambda i, j: columns[j][i])
    adjugate = S.adjugate()
    return tuple(
        prog.define(
            name,
            _over(sp.expand(sum(adjugate[i, k] * rhs[k] for k in range(3))), det, inv_det),
            step,
        )
        for i, name in enumerate(names)
    )


def _over(expr: sp.Expr, det: sp.Expr, inv_det: sp.Expr) -> sp.Expr:
    """``expr / det``, ``expr`` expanded: when ``det`` is a number times one symbol (the 3-RPR's
    ``D = -L``), the terms it divides are divided exactly (``-L dphi / -L`` is ``dphi``, and
    ``L v / -L`` is ``-v``: no product ``L (1/L)``, which is 1 only to round-off), and only the
    others are multiplied by ``inv_det``. Otherwise ``expr inv_det``."""
    _, symbol = det.as_coeff_Mul()
    if not symbol.is_Symbol:
        return expr * inv_det
    exact: list[sp.Expr] = []
    rest: list[sp.Expr] = []
    for term in sp.Add.make_args(expr):
        _, power = term.as_independent(symbol, as_Add=False)
        divides = power == symbol or (
            power.is_Pow and power.base == symbol and power.exp.is_integer and power.exp.is_positive
        )
        (exact if divides else rest).append(term)
    return sp.Add(*(t / det for t in exact)) + sp.Add(*rest) * inv_det


def _point_accelerations(
    kinds: str,
    pose: LegPose,
    qd: tuple[sp.Expr, ...],
    qdd: tuple[sp.Expr, ...],
    omega: tuple[sp.Expr, sp.Expr],
    eps: tuple[sp.Expr, sp.Expr],
) -> tuple[Vec, Vec, Vec]:
    """Accelerations of X1, X2, X3, each a point of body 1, 2 and the platform, down the chain.

    ``a_{k+1} = a_k + eps_k perp(d) - omega_k^2 d`` with ``d = X_{k+1} - X_k`` (the point of body
    k where joint k+1 is), plus, for a prismatic joint k+1 of axis w, the Coriolis and sliding
    terms ``2 omega_k qd_{k+1} perp(w) + qdd_{k+1} w``.
    """
    arm1, arm2 = pose.arms
    steps = (sub(arm1, arm2), arm2)  # X2 - X1, X3 - X2
    accel = [scale(qdd[0], pose.axes[1]) if kinds[0] == "P" else ZERO]
    for k in (0, 1):
        d = steps[k]
        a = add(accel[k], scale(eps[k], perp(d)), scale(-(omega[k] ** 2), d))
        if kinds[k + 1] == "P":
            w = pose.axes[k + 2]
            a = add(a, scale(2 * omega[k] * qd[k + 1], perp(w)), scale(qdd[k + 1], w))
        accel.append(a)
    return accel[0], accel[1], accel[2]


def _rotations(kinds: str, rates: tuple[sp.Expr, ...]) -> tuple[sp.Expr, sp.Expr]:
    """Angular velocities (or accelerations) of bodies 1 and 2 from the joint rates."""
    one = rates[0] if kinds[0] == "R" else sp.Integer(0)
    two = one + (rates[1] if kinds[1] == "R" else 0)
    return one, two


def leg_kinematics(prog: Program, robot: Robot, leg: str, platform: Platform) -> LegKinematics:
    """Pose, rates and accelerations of ``leg`` from the platform motion (eqs. 5, 6, 9)."""
    g = robot.legs[leg]
    names = robot.names
    turned = platform.turn(g.platform_point)
    s = (
        prog.define(f"s_{leg}_x", turned[0], STEP_POSE),
        prog.define(f"s_{leg}_y", turned[1], STEP_POSE),
    )
    pose = inverse_kinematics(prog, g, platform, add((syms.x, syms.y), s), names.q)
    e = pose.frame

    def frame_vector(name: str, v: Vec, step: str) -> Vec:
        local = in_frame(e, v)
        return (
            prog.define(f"{name}_{leg}_x1", local[0], step),
            prog.define(f"{name}_{leg}_y1", local[1], step),
        )

    columns = [serial_column(g.kinds, pose, j) for j in (1, 2, 3)]
    inv_det = prog.define(f"inv_D_{leg}", 1 / pose.D, STEP_VELOCITY)

    step = STEP_VELOCITY
    v3 = frame_vector("v3", add((syms.dx, syms.dy), scale(syms.dphi, perp(s))), step)
    qd = _serial_solve(
        prog,
        columns,
        pose.D,
        inv_det,
        (v3[0], v3[1], syms.dphi),
        [f"{n}_{leg}" for n in names.qd],
        step,
    )
    omega = _rotations(g.kinds, qd)

    step = STEP_ACCELERATION
    a3 = in_frame(
        e, add((syms.ddx, syms.ddy), scale(syms.ddphi, perp(s)), scale(-(syms.dphi**2), s))
    )
    zero = (sp.Integer(0),) * 3
    bias = _point_accelerations(g.kinds, pose, qd, zero, omega, (0, 0))[2]
    rhs = sub(a3, bias)
    rhs = (prog.define(f"a3_{leg}_x1", rhs[0], step), prog.define(f"a3_{leg}_y1", rhs[1], step))
    qdd = _serial_solve(
        prog, columns, pose.D, inv_det, (*rhs, syms.ddphi), [f"{n}_{leg}" for n in names.qdd], step
    )
    eps = _rotations(g.kinds, qdd)
    a1, a2, _ = _point_accelerations(g.kinds, pose, qd, qdd, omega, eps)
    accel = tuple(
        (
            prog.define(f"acc{k + 1}_{leg}_x1", a[0], step),
            prog.define(f"acc{k + 1}_{leg}_y1", a[1], step),
        )
        for k, a in enumerate((a1, a2))
    )
    return LegKinematics(leg, g, pose, s, qd, qdd, omega, eps, accel)  # type: ignore[arg-type]


def body_offsets(kin: LegKinematics) -> tuple[Vec, Vec]:
    """Current offsets (leg frame) of bodies 1 and 2's centres of mass from their first joint
    points."""
    return kin.body_vector(1, kin.geometry.com[0]), kin.body_vector(2, kin.geometry.com[1])


def offset_length2(kin: LegKinematics, body: int) -> sp.Expr:
    """``|COM - X_body|^2`` of body ``body`` (1 or 2): a function of the parameters only."""
    return norm2(kin.geometry.com[body - 1]) * kin.geometry.references[body - 1].length2
