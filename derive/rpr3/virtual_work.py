"""Virtual velocities (7)–(8) and joint loads (12)–(17) by the principle of virtual work.

Each joint of a leg allows (or, when released, would allow) a relative motion; its load is the
wrench component that does work on it. Per leg, in order along the chain:

=========  ====================================================  =========
velocity   relative motion                                       load
=========  ====================================================  =========
v10x/y     translation of A1 along x0 / y0 (world)               f10x/y
omega10    rotation of the cylinder about z1 = z0 at A1          m10
v21y/z     translation of the piston along y2 = n / z2 = e       f21y/z
omega21    rotation of the piston about x2 = -z0 at A2           m21
v32y/z     translation of the platform along y2 = n / z2 = e     f32y/z
omega32    rotation of the platform about z3 = z0 at A3          (none)
=========  ====================================================  =========

Two of them per leg are free (their load is zero): omega32, and v21z when the motors are at A1
(``revolute``) or omega10 when the prismatic joint is actuated (``prismatic``).

For a load, eq. (8) sets its own virtual velocity to 1 and every other loaded one, in every leg,
to 0; the closure (7) of the three chains at the platform then fixes the six free virtual
velocities and the platform's virtual twist. The principle of virtual work gives the load as the
virtual power of the required wrenches F_k, M_k of eqs. (10)-(11):

    load = (its own component of F_k or M_k) + u3^T {sum over free velocities of v * F or M},

which is the form of the paper's eqs. (12)-(17).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.dynamics import LegWrenches
from rpr3gen_derive.rpr3.frames import skew, u1, u2, u3
from rpr3gen_derive.rpr3.kinematics import LegKinematics

STEP_CLOSURE = "closure of the virtual motions, eq. (7)"
STEP_VIRTUAL = "characteristic virtual velocities, eqs. (7)-(8)"
STEP_LOADS = "joint loads by virtual work, eqs. (12)-(17)"

JOINT_VELOCITIES: tuple[str, ...] = (
    "v10x", "v10y", "omega10", "v21y", "v21z", "omega21", "v32y", "v32z", "omega32",
)  # fmt: skip

#: The load each joint velocity does work against (omega32: none, the joint at A3 is free).
LOAD_OF: dict[str, str] = {
    "v10x": "f10x",
    "v10y": "f10y",
    "omega10": "m10",
    "v21y": "f21y",
    "v21z": "f21z",
    "omega21": "m21",
    "v32y": "f32y",
    "v32z": "f32z",
}

#: Free joint velocities (zero load) for each actuation scheme.
FREE: dict[str, tuple[str, str]] = {
    "revolute": ("v21z", "omega32"),
    "prismatic": ("omega10", "omega32"),
}


@dataclass(frozen=True)
class Joint:
    """A joint velocity's effect: A3's velocity (x1, y1) and the platform rotation, per unit."""

    column: sp.Matrix  # closure column in frame 1: (v_A3 . x1, v_A3 . y1, omega about z0)
    power: sp.Expr  # virtual power per unit velocity: the load's component of F_k or M_k


def leg_joints(kin: LegKinematics, wrenches: LegWrenches) -> dict[str, Joint]:
    """Closure columns of eq. (7) and power terms of eqs. (12)-(17) for one leg, in frame 1.

    A joint twist with rotation axis ``w`` (unit) through the point P and translation ``t`` moves
    the platform point A3 by ``t + w x (A3 - P)``. Axes and directions are the paper's: x0, y0
    at A1 (``a10 u_j``), z1 at A1, x2 at A2 and y2, z2 for the slides (``a21^T u_j``).
    """
    F1, F2, F3 = wrenches.F
    M1, M2, M3 = wrenches.M
    a10, a21, a32 = kin.a10, kin.a21, kin.a32
    a3 = kin.length * u1  # A3 - A1 in frame 1
    a2 = (syms.l0 + kin.lambda21) * u1  # A2 - A1 in frame 1

    def column(translation: sp.Matrix, axis: sp.Matrix | None = None, point=None) -> sp.Matrix:
        motion = translation
        rotation = sp.Integer(0)
        if axis is not None:
            motion = motion + skew(axis) * (a3 - point)
            rotation = axis[2]
        return sp.Matrix([motion[0], motion[1], rotation])

    zero = sp.zeros(3, 1)
    return {
        "v10x": Joint(column(a10 * u1), (u1.T * a10.T * F1)[0]),
        "v10y": Joint(column(a10 * u2), (u2.T * a10.T * F1)[0]),
        "omega10": Joint(column(zero, u3, zero), (u3.T * M1)[0]),
        "v21y": Joint(column(a21.T * u2), (u2.T * F2)[0]),
        "v21z": Joint(column(a21.T * u3), (u3.T * F2)[0]),
        "omega21": Joint(column(zero, a21.T * u1, a2), (u1.T * M2)[0]),
        "v32y": Joint(column(a21.T * u2), (u2.T * a32.T * F3)[0]),
        "v32z": Joint(column(a21.T * u3), (u3.T * a32.T * F3)[0]),
        "omega32": Joint(column(zero, u3, a3), (u3.T * M3)[0]),
    }


def platform_twist_matrix(kin: LegKinematics) -> sp.Matrix:
    """A_i: the platform twist (vGx, vGy, omega) mapped to A3's velocity in frame 1 and omega."""
    a10 = kin.a10[0:2, 0:2]
    turn = sp.Matrix([-kin.s[1], kin.s[0]])  # z0 x (A3 - G)
    top = a10.row_join(a10 * turn)
    return top.col_join(sp.Matrix([[0, 0, 1]]))


def _cross(a: sp.Matrix, b: sp.Matrix) -> sp.Matrix:
    return sp.Matrix(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _dot(a: sp.Matrix, b: sp.Matrix) -> sp.Expr:
    return sp.expand(sum(a[k] * b[k] for k in range(3)))


def joint_loads(
    prog: Program,
    actuation: str,
    kinematics: dict[str, LegKinematics],
    wrenches: dict[str, LegWrenches],
) -> dict[str, sp.Expr]:
    """Every joint load of every leg, ``{"m10_A": expr, ...}``, by virtual work.

    The closure (7) per leg: the platform twist seen at A3 equals the sum of the joint columns
    times their virtual velocities. Eliminating the two free velocities of a leg (their columns
    c1, c2) leaves one condition ``w . A_i t = w . (loaded part)``, with ``w = c1 x c2``: the
    three rows form the matrix W of the platform's virtual twist t, solved by explicit cofactors.
    The free velocities then follow as ``f1 = (c2 x w) . r / (c2 x w) . c1`` and
    ``f2 = (c1 x w) . r / (c1 x w) . c2``, with r the twist not produced by loaded joints.

    Also returns ``conditioning``, the closeness of W to singularity (:func:`conditioning`).
    """
    legs = tuple(kinematics)
    free = FREE[actuation]
    joints = {leg: leg_joints(kinematics[leg], wrenches[leg]) for leg in legs}
    twist = {leg: platform_twist_matrix(kinematics[leg]) for leg in legs}

    null = {}
    rows = []
    for leg in legs:
        c1, c2 = (joints[leg][f].column for f in free)
        w = _cross(c1, c2)
        null[leg] = w
        row = (w.T * twist[leg]).applyfunc(sp.expand)
        rows.append([prog.define(f"W_{leg}{k + 1}", row[k], STEP_CLOSURE) for k in range(3)])
    W = sp.Matrix(rows)
    det = prog.define("det_W", W.det(method="bareiss"), STEP_CLOSURE)
    inv_det = prog.define("inv_det_W", 1 / det, STEP_CLOSURE)
    adjugate = W.adjugate()
    inverse = sp.Matrix(
        3,
        3,
        lambda i, j: prog.define(f"Winv_{i + 1}{j + 1}", adjugate[i, j] * inv_det, STEP_CLOSURE),
    )

    power = {
        (leg, name): prog.define(f"P_{name}_{leg}", joint.power, STEP_CLOSURE)
        for leg in legs
        for name, joint in joints[leg].items()
    }

    def free_velocities(leg: str, r: sp.Matrix) -> tuple[sp.Expr, sp.Expr]:
        """Eq. (7) solved for the free velocities of ``leg``, given the rest r of its closure."""
        c1, c2 = (joints[leg][f].column for f in free)
        d1, d2 = _cross(c2, null[leg]), _cross(c1, null[leg])
        return (
            sp.cancel(_dot(d1, r) / _dot(d1, c1)),
            sp.cancel(_dot(d2, r) / _dot(d2, c2)),
        )

    # The virtual motions of eq. (8) for the loads of leg i all move the platform by
    # b * Winv[:, i] (b: the load's own joint column seen through leg i's closure row), and the
    # free velocities are linear in that twist. So the bracket of eqs. (12)-(17),
    # u3^T {v21^A F2^A + omega32^A M3^A + v21^B F2^B + v21^C F2^C}, is b times one bracket Q_i
    # per leg, evaluated once for the unit closure motion t = Winv[:, i], plus the free
    # velocities that the load's own joint forces in its own leg.
    bracket: dict[str, sp.Expr] = {}
    for i, leg in enumerate(legs):
        unit_twist = inverse[:, i]
        total = sp.Integer(0)
        for other in legs:
            values = free_velocities(other, twist[other] * unit_twist)
            for f, value in zip(free, values, strict=True):
                v = prog.define(f"{f}_v_{leg}__{other}", value, STEP_VIRTUAL)
                total = total + v * power[(other, f)]
        bracket[leg] = prog.define(f"Q_{leg}", total, STEP_VIRTUAL)

    loads: dict[str, sp.Expr] = {}
    for leg in legs:
        for name, joint in joints[leg].items():
            if name in free or name not in LOAD_OF:
                continue
            # Eq. (8): this velocity = 1, every other loaded one = 0; eq. (7) closes the chains.
            b = _dot(null[leg], joint.column)
            own = free_velocities(leg, -joint.column)
            total = power[(leg, name)] + b * bracket[leg]
            for f, value in zip(free, own, strict=True):
                total = total + value * power[(leg, f)]
            load_name = f"{LOAD_OF[name]}_{leg}"
            loads[load_name] = prog.define(load_name, total, STEP_LOADS)
    loads["conditioning"] = prog.define("conditioning", conditioning(W, det), STEP_CLOSURE)
    return loads


def platform_radius_squared() -> sp.Expr:
    """Mean squared distance of the platform joints from G (m^2): rho^2, the length that makes
    the platform's rotation commensurable with its translation."""
    squares = sum((syms.platform_joint(leg).T * syms.platform_joint(leg))[0] for leg in syms.LEGS)
    return squares / 3


def conditioning(W: sp.Matrix, det: sp.Expr) -> sp.Expr:
    """Closeness to a parallel singularity, dimensionless, in [0, 1]: 0 at a singular pose.

    ``|det(W S)| / prod_i |row_i(W S)|`` with ``S = diag(1, 1, 1/rho)`` (rho^2:
    :func:`platform_radius_squared`), the Hadamard ratio of the closure matrix W whose solve
    gives every load. It is 1 when the three legs' constraint lines are mutually orthogonal in
    the scaled twist space and falls to 0 as they become dependent (legs' constraint lines
    concurrent or parallel), where the loads grow without bound. Computed with one square root.
    """
    rho2 = platform_radius_squared()
    norms2 = [W[i, 0] ** 2 + W[i, 1] ** 2 + W[i, 2] ** 2 / rho2 for i in range(3)]
    return sp.sqrt(det**2 / (rho2 * norms2[0] * norms2[1] * norms2[2]))
