"""Virtual velocities (7)-(8) and joint loads (12)-(17) by the principle of virtual work.

Every joint of a leg allows, or when released would allow, three relative motions of its later
body: two translations and a rotation about the joint's point ``X_j``. A revolute joint's
translations are taken along the leg frame ``(e, perp(e))`` and its loads turned to the world
axes x0, y0 on output (``fx``, ``fy``); a prismatic joint's along its current axis ``w`` and
across it, ``perp(w)`` (loads ``f_axis``, ``f_normal``).
The load of each motion is the component of the chain wrench ``(F_j, M_j)`` of eqs. (10)-(11)
that does work on it.

Two motions per leg are free (their load is zero): those of its two passive joints, the
rotation of a revolute one and the slide of a prismatic one. The actuated joint's own motion is
loaded: its load is the actuator effort.

For a load, eq. (8) sets its own virtual velocity to 1 and every other loaded one, in every leg,
to 0; the closure (7) of the three chains at the platform then fixes the six free virtual
velocities and the platform's virtual twist. The principle of virtual work gives the load as the
virtual power of the required wrenches:

    load = (its own component of F_j or M_j) + u3^T {sum over free velocities of v * F or M},

the form of the paper's eqs. (12)-(17). Each motion is described by its *column*: what a unit
velocity of it does to joint 3's point (velocity, world) and to the platform (angular velocity),
the columns of the leg's serial Jacobian for the joints' own motions (:mod:`.kinematics`).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar.dynamics import LegWrenches
from rpr3gen_derive.planar.kinematics import LegKinematics
from rpr3gen_derive.planar.vectors import Vec, along, dot, norm2, perp

STEP_CLOSURE = "closure of the virtual motions, eq. (7)"
STEP_VIRTUAL = "characteristic virtual velocities, eqs. (7)-(8)"
STEP_LOADS = "joint loads by virtual work, eqs. (12)-(17)"

Column = tuple[sp.Expr, sp.Expr, sp.Expr]


@dataclass(frozen=True)
class Motion:
    """A relative motion of a joint: its name, column (X3 velocity, platform rate) and power."""

    name: str  # "{joint}a", "{joint}b" (translations) or "{joint}r" (rotation)
    column: Column
    power: sp.Expr


@dataclass(frozen=True)
class JointLoad:
    """The load a joint transmits: force components along its translation basis and moment.

    ``basis``: the two translation directions (world) the components ``force`` are along: the
    leg frame ``(e, perp(e))`` for a revolute joint, ``(w, perp(w))`` for a prismatic joint of
    axis ``w``. ``moment``: about the joint's point, z0.
    """

    force: tuple[sp.Expr, sp.Expr]
    moment: sp.Expr
    basis: tuple[Vec, Vec]

    @property
    def world(self) -> Vec:
        """The force in world components."""
        (ax, ay), (bx, by) = self.basis
        return (self.force[0] * ax + self.force[1] * bx, self.force[0] * ay + self.force[1] * by)


def _world_basis(kin: LegKinematics, joint: int) -> tuple[Vec, Vec]:
    a, b = translation_basis(kin, joint)
    return kin.pose.world(a), kin.pose.world(b)


ONE, NIL = sp.Integer(1), sp.Integer(0)
WORLD: tuple[Vec, Vec] = ((ONE, NIL), (NIL, ONE))


def translation_basis(kin: LegKinematics, joint: int) -> tuple[Vec, Vec]:
    """The two translation directions of joint ``joint``'s loads (leg frame): the leg frame's
    own for a revolute joint, ``(w, perp(w))`` for a prismatic joint of axis ``w``."""
    if kin.kinds[joint - 1] == "R":
        return WORLD
    w = kin.pose.axes[joint]
    return w, perp(w)


def leg_motions(kin: LegKinematics, wrenches: LegWrenches) -> list[Motion]:
    """The nine relative motions of a leg, joint by joint: two translations, one rotation (leg
    frame)."""
    motions = []
    for j in (1, 2, 3):
        wrench = wrenches.joints[j - 1]
        for tag, t in zip("ab", translation_basis(kin, j), strict=True):
            motions.append(Motion(f"{j}{tag}", (t[0], t[1], NIL), dot(t, wrench.force)))
        arm = perp(kin.arms[j - 1])
        motions.append(Motion(f"{j}r", (arm[0], arm[1], ONE), wrench.moment))
    return motions


def free_motions(kinds: str, actuated: int) -> tuple[str, str]:
    """The two free motions of a leg: each passive joint's own (rotation or slide)."""
    return tuple(  # type: ignore[return-value]
        f"{j}r" if kinds[j - 1] == "R" else f"{j}a" for j in (1, 2, 3) if j != actuated
    )


def actuator_motion(kinds: str, actuated: int) -> str:
    """The actuated joint's own motion, whose load is the actuator effort."""
    return f"{actuated}r" if kinds[actuated - 1] == "R" else f"{actuated}a"


def _cross3(a: Column, b: Column) -> Column:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot3(a: Column, b: Column) -> sp.Expr:
    return sp.expand(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])


def platform_twist_row(null: Column, s: Vec, frame: Vec) -> Column:
    """``null^T A``: the closure row of a leg, ``A`` mapping the platform twist at G
    ``(vGx, vGy, omega)`` (world) to joint 3's point's velocity in the leg frame ``(e,
    perp(e))`` and the rate: ``(R_e^T (vG + omega perp(s)), omega)``, ``s = X3 - G`` (world)."""
    world = along((null[0], null[1]), frame)
    turn = perp(s)
    return (world[0], world[1], world[0] * turn[0] + world[1] * turn[1] + null[2])


@dataclass(frozen=True)
class Loads:
    """Every joint load by virtual work: ``joints[(leg, j)]``, and the closure's conditioning."""

    joints: dict[tuple[str, int], JointLoad]
    conditioning: sp.Expr


def joint_loads(
    prog: Program,
    actuated: int,
    kinematics: dict[str, LegKinematics],
    wrenches: dict[str, LegWrenches],
    platform_radius2: sp.Expr,
    tag: str = "",
) -> Loads:
    """Every joint load of every leg by virtual work (eqs. 7-8 and 12-17).

    The closure (7) per leg: the platform twist seen at X3 equals the sum of the motions'
    columns times their virtual velocities. Eliminating the two free velocities of a leg (their
    columns c1, c2) leaves one condition ``n . A_i t = n . (loaded part)`` with ``n = c1 x c2``:
    the three rows form the matrix W of the platform's virtual twist t, solved by explicit
    cofactors. The free velocities then follow as ``f1 = (c2 x n) . r / (c2 x n) . c1`` and
    ``f2 = (c1 x n) . r / (c1 x n) . c2``, with r the twist not produced by loaded motions.

    The virtual motions for the loads of leg i all move the platform by ``b Winv[:, i]`` (``b``:
    the load's own column seen through leg i's closure row), and the free velocities are linear
    in that twist: so the bracket of eqs. (12)-(17) is ``b`` times one bracket ``Q_i`` per leg,
    evaluated once for the unit closure motion, plus the free velocities that the load's own
    joint forces in its own leg.

    ``platform_radius2``: the squared RMS radius of the platform joints, the length that makes
    rotation commensurable with translation in :func:`conditioning`. ``tag`` marks the names of
    what depends on the wrenches (the powers, brackets and loads), so that a second run of the
    algorithm on other wrenches (the regressor's) can share one program with the first.
    """
    legs = tuple(kinematics)
    motions = {leg: leg_motions(kinematics[leg], wrenches[leg]) for leg in legs}
    by_name = {leg: {m.name: m for m in motions[leg]} for leg in legs}
    free = {leg: free_motions(kinematics[leg].kinds, actuated) for leg in legs}

    null, rows = {}, []
    for leg in legs:
        units = kinematics[leg].pose.units
        c1, c2 = (by_name[leg][f].column for f in free[leg])
        n = tuple(
            prog.define(f"n{k + 1}_{leg}", reduce_units(_cross3(c1, c2)[k], units), STEP_CLOSURE)
            for k in range(3)
        )
        null[leg] = n
        row = platform_twist_row(n, kinematics[leg].s, kinematics[leg].pose.frame)
        rows.append(
            [prog.define(f"W_{leg}{k + 1}", sp.expand(row[k]), STEP_CLOSURE) for k in range(3)]
        )
    W = sp.Matrix(rows)
    det = prog.define("det_W", W.det(method="bareiss"), STEP_CLOSURE)
    inv_det = prog.define("inv_det_W", 1 / det, STEP_CLOSURE)
    adjugate = W.adjugate()
    cofactors = sp.Matrix(
        3, 3, lambda i, j: prog.define(f"adjW_{i + 1}{j + 1}", adjugate[i, j], STEP_CLOSURE)
    )
    power = {
        (leg, m.name): prog.define(f"P{m.name}{tag}_{leg}", m.power, STEP_CLOSURE)
        for leg in legs
        for m in motions[leg]
    }

    # Eq. (7) for the free velocities of a leg, given the rest r of its closure: with the free
    # columns c1, c2 and d1 = c2 x n, d2 = c1 x n, f1 = d1 . r / d1 . c1 and f2 = d2 . r / d2 . c2.
    # Each denominator is named once per leg (1 for the paper's legs, in their frame).
    solvers: dict[str, list[tuple[Column, sp.Expr]]] = {}
    for leg in legs:
        units = kinematics[leg].pose.units
        c1, c2 = (by_name[leg][f].column for f in free[leg])
        pairs = []
        for k, (across, along_) in enumerate(((c2, c1), (c1, c2))):
            d = tuple(reduce_units(e, units) for e in _cross3(across, null[leg]))
            den = reduce_units(_dot3(d, along_), units)
            scale_ = (
                1 / den
                if den.is_number
                else prog.define(f"inv_den{k + 1}_{leg}", 1 / den, STEP_CLOSURE)
            )
            pairs.append((d, scale_))
        solvers[leg] = pairs

    def free_velocities(leg: str, r: Column) -> tuple[sp.Expr, sp.Expr]:
        """Eq. (7) solved for the free velocities of ``leg``, given the rest r of its closure."""
        units = kinematics[leg].pose.units
        return tuple(  # type: ignore[return-value]
            reduce_units(_dot3(d, r), units) * k for d, k in solvers[leg]
        )

    def twist_at(leg: str, t: sp.Matrix) -> Column:
        """The platform twist t (world, at G) seen at X3 in the leg's frame."""
        kin = kinematics[leg]
        turn = perp(kin.s)
        v = kin.to_frame((t[0] + t[2] * turn[0], t[1] + t[2] * turn[1]))
        return (v[0], v[1], t[2])

    # The free velocities are linear in the twist t = Winv[:, i] of the loads of leg i, and so
    # is their virtual power: sum_other sum_f v_f P_f = h . t, h the platform-twist image of the
    # free joints' powers (the adjoint of eq. 7, one 3-vector for all nine brackets). Then
    # Q_i = Winv[:, i] . h = (adj(W)[:, i] . h) / det(W): the characteristic virtual velocities
    # of eq. (8) are never formed one by one.
    twist = sp.symbols("t1:4", real=True, cls=sp.Dummy)  # never a parameter's name
    parts: list[list[sp.Expr]] = [[], [], []]
    for other in legs:
        values = free_velocities(other, twist_at(other, sp.Matrix(twist)))
        power_of = sp.expand(
            sum(
                (v * power[(other, f)] for f, v in zip(free[other], values, strict=True)),
                sp.Integer(0),
            )
        )
        for k in range(3):
            part = reduce_units(power_of.coeff(twist[k]), kinematics[other].pose.units)
            parts[k].append(prog.define(f"h{k + 1}{tag}_{other}", part, STEP_VIRTUAL))
    h = [
        prog.define(f"h{k + 1}{tag}", sum(parts[k], sp.Integer(0)), STEP_VIRTUAL) for k in range(3)
    ]
    bracket: dict[str, sp.Expr] = {}
    for i, leg in enumerate(legs):
        column = sum((cofactors[k, i] * h[k] for k in range(3)), sp.Integer(0))
        bracket[leg] = prog.define(f"Q{tag}_{leg}", inv_det * column, STEP_VIRTUAL)

    loads: dict[tuple[str, int], JointLoad] = {}
    for leg in legs:
        kin = kinematics[leg]
        value: dict[str, sp.Expr] = {}
        for motion in motions[leg]:
            if motion.name in free[leg]:
                value[motion.name] = sp.Integer(0)
                continue
            # Eq. (8): this velocity = 1, every other loaded one = 0; eq. (7) closes the chains.
            b = reduce_units(_dot3(null[leg], motion.column), kin.pose.units)
            own = free_velocities(leg, tuple(-c for c in motion.column))
            total = power[(leg, motion.name)] + b * bracket[leg]
            for f, velocity in zip(free[leg], own, strict=True):
                total = total + velocity * power[(leg, f)]
            value[motion.name] = prog.define(f"load{motion.name}{tag}_{leg}", total, STEP_LOADS)
        for j in (1, 2, 3):
            loads[(leg, j)] = JointLoad(
                (value[f"{j}a"], value[f"{j}b"]), value[f"{j}r"], _world_basis(kin, j)
            )
    cond = prog.define("conditioning", conditioning(W, det, platform_radius2), STEP_CLOSURE)
    return Loads(loads, cond)


def reduce_units(expr: sp.Expr, units: tuple[Vec, ...]) -> sp.Expr:
    """``expr`` expanded, with ``a^2 = 1 - b^2`` for each unit pair ``(a, b)`` of ``units``."""
    expr = sp.expand(expr)
    for a, b in units:
        if expr.has(a):
            expr = sp.expand(expr.subs(a**2, 1 - b**2))
    return expr


def platform_radius2(points: list[Vec]) -> sp.Expr:
    """Mean squared distance of the platform joints from G (m^2), in the platform frame."""
    return sum(norm2(p) for p in points) / len(points)


def conditioning(W: sp.Matrix, det: sp.Expr, rho2: sp.Expr) -> sp.Expr:
    """Closeness to a parallel singularity, dimensionless, in [0, 1]: 0 at a singular pose.

    ``|det(W S)| / prod_i |row_i(W S)|`` with ``S = diag(1, 1, 1/rho)`` (``rho^2``: the mean
    squared radius of the platform joints), the Hadamard ratio of the closure matrix W whose
    solve gives every load. It is 1 when the three legs' constraint lines are mutually
    orthogonal in the scaled twist space and falls to 0 as they become dependent (the legs'
    constraint lines concurrent or parallel), where the loads grow without bound. One square
    root.
    """
    norms2 = [W[i, 0] ** 2 + W[i, 1] ** 2 + W[i, 2] ** 2 / rho2 for i in range(3)]
    return sp.sqrt(det**2 / (rho2 * norms2[0] * norms2[1] * norms2[2]))
