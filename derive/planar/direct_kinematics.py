"""The direct kinematics of any structure: every assembly mode of the actuator coordinates.

With its motor locked at ``qa``, a leg keeps two passive joints and holds the platform by one
equation (:func:`locked_legs`). Which one depends only on the passive joints' types, in chain
order, so it is the same for the three legs of a structure:

=========  =====================================================================  ============
passive    the platform ...                                                        modes
=========  =====================================================================  ============
R, R       a platform point ``a`` on a circle about a world point ``b``            at most 6
P, R       a platform point ``a`` on a world line (normal ``n``, through ``b``)   at most 2
R, P       a world point ``b`` on a platform line (normal ``m``, through ``a``)   at most 2
P, P       only its angle is held: every motor sees the platform angle alone      (singular)
=========  =====================================================================  ============

The data come from the leg's chain as rigid motions of the plane: the platform's pose is
``g = T1(q1) T2(q2) T3(q3) g0`` (``T_j`` the joint's motion, ``g0`` the platform's pose when
every coordinate is zero: the identity at home, in the general format). With joint a locked,
``L g R = T_i(q_i) T_j(q_j)`` for fixed ``L``, ``R`` and the two free joints i, j (joint 3 moved
by the locked joint 2 when a = 2), and each free pair leaves one invariant.

Three circles give the classical sextic in ``t = tan(phi/2)`` (Gosselin & Sefrioui; Merlet),
:func:`sextic_coefficients`, whose real roots :func:`pose_from_angle` turns into poses; three
lines give ``A cos(phi) + B sin(phi) + C = 0``, solved in closed form by :func:`line_modes`
(platform lines: the same in the platform's view of the world, ``phi -> -phi``). A candidate is
an assembly mode when every leg is in its working mode there: the runtime and the generated C
check that the inverse kinematics gives back ``qa``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.calculus import Builder
from rpr3gen_derive.planar.geometry import LEGS, LegGeometry, Robot
from rpr3gen_derive.planar.structures import Structure
from rpr3gen_derive.planar.vectors import Vec, add, cross, dot, norm2, perp, rotate, scale, sub

STEP_LOCKED = "the legs with their motors locked: the platform's constraints"
STEP_LINES = "direct kinematics, platform on three lines (closed form)"
STEP_CIRCLES = "direct kinematics, platform on three circles (sextic in tan(phi/2))"

#: Revolute direct kinematics: legs within this angle (rad) of all parallel (``|k|``), or
#: ``|(A, B)|`` below this times ``|k| rho``, are degenerate (round-off is ~1e-16 of either).
DEGENERACY_TOL = 1e-10
#: A circle of radius below this times the platform's RMS radius holds nothing (no mode).
LENGTH_TOL = 1e-9

#: The most assembly modes of each kind of locked leg (interfaces.md, RPR3_MAX_MODES).
MAX_MODES: dict[str, int] = {"circle": 6, "line": 2, "platform_line": 2}


@dataclass(frozen=True)
class Rigid:
    """A rigid motion of the plane, ``x -> R(c, s) x + t``."""

    c: sp.Expr
    s: sp.Expr
    t: Vec

    def __call__(self, p: Vec) -> Vec:
        return add(rotate(self.c, self.s, p), self.t)

    def turn(self, v: Vec) -> Vec:
        """Its rotation alone, applied to a direction."""
        return rotate(self.c, self.s, v)

    def inverse(self) -> Rigid:
        back = rotate(self.c, -self.s, self.t)
        return Rigid(self.c, -self.s, (-back[0], -back[1]))

    def __mul__(self, other: Rigid) -> Rigid:
        return Rigid(
            self.c * other.c - self.s * other.s,
            self.s * other.c + self.c * other.s,
            add(self.turn(other.t), self.t),
        )


IDENTITY = Rigid(sp.Integer(1), sp.Integer(0), (sp.Integer(0), sp.Integer(0)))


class Joint(NamedTuple):
    """A free joint of a locked leg: ``"R"`` with its centre, or ``"P"`` with its axis."""

    kind: str
    point: Vec  # centre (R) or axis (P), at zero coordinates (moved by the locked joint 2)


def joint_motion(g: LegGeometry, joint: int, cos_q: sp.Expr, sin_q: sp.Expr, q: sp.Expr) -> Rigid:
    """``T_j(q)``: rotation by q about the joint's point (R), translation by ``q u_j`` (P)."""
    if g.kinds[joint - 1] == "R":
        p = g.points[joint - 1]
        return Rigid(cos_q, sin_q, sub(p, rotate(cos_q, sin_q, p)))
    return Rigid(sp.Integer(1), sp.Integer(0), scale(q, g.axis(joint)))


@dataclass(frozen=True)
class Locked:
    """One locked leg's hold on the platform (see the module's table).

    ``kind``: ``"circle"`` (``|G + R a - b|^2 = r2``), ``"line"`` (``n . (G + R a) = n . b``),
    ``"platform_line"`` (``n . (R^T (b - G) - a) = 0``, ``n`` in the platform frame).
    """

    kind: str
    a: Vec
    b: Vec
    n: Vec = (sp.S.Zero, sp.S.Zero)
    r2: sp.Expr = sp.S.Zero


def locked_kind(kinds: str, actuated: int) -> str:
    """The kind of hold of a leg type locked at joint ``actuated`` (the module's table)."""
    free = "".join(kinds[j - 1] for j in (1, 2, 3) if j != actuated)
    return {"RR": "circle", "PR": "line", "RP": "platform_line", "PP": "angle"}[free]


LEG_LETTERS = "".join(LEGS)


def _simple(expr: sp.Expr) -> sp.Expr:
    """Small constraint data, simplified (the paper's parameters give cos^2 + sin^2 and sums
    of angles that SymPy only sees through trigsimp).

    trigsimp is slow (it was most of a variant's derivation), and the three legs' data are one
    expression in their own symbols. So one leg's expression is simplified as leg A's: each
    symbol named with leg B's (or C's) letter, and no other leg letter, is renamed to leg A's,
    the result memoised and renamed back. Where the renaming would not be one to one (an
    expression of several legs), the expression is simplified as it is.
    """
    to_a: dict[sp.Symbol, sp.Symbol] = {}
    for s in expr.free_symbols:
        letters = [ch for ch in s.name if ch in LEG_LETTERS] if type(s) is sp.Symbol else []
        if len(letters) == 1 and letters[0] != LEG_LETTERS[0]:
            to_a[s] = sp.Symbol(s.name.replace(letters[0], LEG_LETTERS[0]), **s.assumptions0)
    renamed = set(to_a.values())
    if not to_a or len(renamed) < len(to_a) or renamed & expr.free_symbols:
        return _simplified(expr)
    back = {a: s for s, a in to_a.items()}
    return _simplified(expr.xreplace(to_a)).xreplace(back)


@lru_cache(maxsize=1024)
def _simplified(expr: sp.Expr) -> sp.Expr:
    """:func:`_simple`'s work, memoised."""
    return sp.trigsimp(sp.expand(expr))


def locked_leg(
    g: LegGeometry, actuated: int, qa: sp.Expr, cos_qa: sp.Expr, sin_qa: sp.Expr
) -> Locked:
    """Leg ``g``'s hold on the platform with joint ``actuated`` locked at ``qa``."""
    offset = sub(g.points[2], g.platform_point)  # g0: the pose at zero joint coordinates
    g0_inverse = Rigid(sp.Integer(1), sp.Integer(0), scale(-1, offset))
    locked = joint_motion(g, actuated, cos_qa, sin_qa, qa)

    def free(joint: int, moved: Rigid = IDENTITY) -> Joint:
        if g.kinds[joint - 1] == "R":
            return Joint("R", moved(g.points[joint - 1]))
        return Joint("P", moved.turn(g.axis(joint)))

    if actuated == 1:
        left, right = locked.inverse(), g0_inverse
        i, j = free(2), free(3)
    elif actuated == 2:
        left, right = IDENTITY, g0_inverse * locked.inverse()
        i, j = free(1), free(3, locked)
    else:
        left, right = IDENTITY, g0_inverse * locked.inverse()
        i, j = free(1), free(2)
    back = left.inverse()
    kind = locked_kind(g.kinds, actuated)

    def vec(v: Vec) -> Vec:
        return (_simple(v[0]), _simple(v[1]))

    if kind == "circle":  # |N(cj) - ci| = |cj - ci|
        return Locked(
            kind, vec(right(j.point)), vec(back(i.point)), r2=_simple(norm2(sub(j.point, i.point)))
        )
    if kind == "line":  # N(cj) - cj along u_i
        return Locked(
            kind, vec(right(j.point)), vec(back(j.point)), n=vec(perp(back.turn(i.point)))
        )
    if kind == "platform_line":  # N^-1(ci) - ci along u_j
        return Locked(
            kind, vec(right(i.point)), vec(back(i.point)), n=vec(perp(right.turn(j.point)))
        )
    raise ValueError(f"{g.kinds} locked at joint {actuated} holds only the platform's angle")


def locked_legs(robot: Robot, structure: Structure) -> dict[str, Locked]:
    """Every leg's hold on the platform, as expressions of the inputs ``qa`` (simplified, so
    that the paper's ``cos(alpha) cos(qa) - ...`` become ``cos(alpha + qa)``)."""
    out = {}
    for i, leg in enumerate(LEGS):
        q = syms.qa[i]
        turns = structure.actuated_kind == "R"
        cos_q, sin_q = (sp.cos(q), sp.sin(q)) if turns else (sp.Integer(1), sp.Integer(0))
        out[leg] = locked_leg(robot.legs[leg], structure.actuated, q, cos_q, sin_q)
    return out


def platform_rms_radius(robot: Robot) -> sp.Expr:
    """``rho = sqrt(mean |p_i|^2)`` (m): the length that turns ``phi`` into a distance."""
    return sp.sqrt(sum(norm2(robot.legs[leg].platform_point) for leg in LEGS) / 3)


class Mode(NamedTuple):
    """One assembly mode ``(x, y, phi, margin)``: the pose, and ``margin >= 0`` where it exists
    (the smallest of the quantities whose signs decide existence: the discriminant and the
    degeneracy tests, each minus its tolerance)."""

    x: sp.Expr
    y: sp.Expr
    phi: sp.Expr
    margin: sp.Expr


def line_modes(prog: Program, robot: Robot, holds: dict[str, Locked]) -> list[Mode]:
    """The two candidate modes of three line holds, in closed form.

    World lines: ``n_i . (G + R(phi) a_i) = n_i . b_i``, i.e. ``n_i . G + u_i cos(phi) +
    v_i sin(phi) = w_i`` with ``u_i = n_i . a_i``, ``v_i = n_i . perp(a_i)``, ``w_i = n_i . b_i``.
    The vector ``k = (n_B x n_C, n_C x n_A, n_A x n_B)`` annihilates the ``G`` columns, which
    leaves ``A cos(phi) + B sin(phi) + C = 0`` with ``A = k . u``, ``B = k . v``, ``C = -k . w``:
    ``(cos, sin)(phi) = (-A C -/+ B r, -B C +/- A r) / (A^2 + B^2)``, ``r = sqrt(A^2 + B^2 -
    C^2)``. ``G`` then solves the three (consistent) line equations in the least-squares sense,
    ``N^T N G = N^T (w - u cos - v sin)``, ``det(N^T N) = |k|^2``.

    Platform lines (``n_i . (R^T (b_i - G) - a_i) = 0``) are the same with the roles of the
    platform and the world exchanged: with ``H = -R^T G`` (the world origin seen from the
    platform) and ``psi = -phi``, ``n_i . H + n_i . R(psi) b_i = n_i . a_i``; then ``phi = -psi``
    and ``G = -R(phi) H``.

    Degenerate inputs (all lines parallel, ``|k| <= DEGENERACY_TOL``; or ``A = B = 0``, where the
    actuators do not fix the orientation) give no mode: both margins negative.
    """
    step = STEP_LINES
    bld = Builder(prog)
    platform_lines = next(iter(holds.values())).kind == "platform_line"
    n, u, v, w = {}, {}, {}, {}
    for leg, hold in holds.items():
        point, target = (hold.b, hold.a) if platform_lines else (hold.a, hold.b)
        n[leg] = hold.n
        u[leg] = bld.define(f"fk_u_{leg}", _simple(dot(hold.n, point)), step)
        v[leg] = bld.define(f"fk_v_{leg}", _simple(dot(hold.n, perp(point))), step)
        w[leg] = bld.define(f"fk_w_{leg}", _simple(dot(hold.n, target)), step)
    k = {
        leg: bld.define(f"fk_k_{leg}", cross(n[LEGS[(i + 1) % 3]], n[LEGS[(i + 2) % 3]]), step)
        for i, leg in enumerate(LEGS)
    }
    A = bld.define("fk_A", sum(k[leg] * u[leg] for leg in LEGS), step)
    B = bld.define("fk_B", sum(k[leg] * v[leg] for leg in LEGS), step)
    C = bld.define("fk_C", -sum(k[leg] * w[leg] for leg in LEGS), step)
    ab2 = bld.define("fk_AB2", A**2 + B**2, step)
    disc = bld.define("fk_disc", ab2 - C**2, step)
    root = bld.define("fk_root", sp.sqrt(sp.Max(disc, 0)), step)
    inv_ab2 = bld.define("fk_inv_AB2", 1 / ab2, step)
    s_xx = sum(n[leg][0] ** 2 for leg in LEGS)
    s_yy = sum(n[leg][1] ** 2 for leg in LEGS)
    s_xy = sum(n[leg][0] * n[leg][1] for leg in LEGS)
    ksq = bld.define("fk_ksq", sum(k[leg] ** 2 for leg in LEGS), step)
    inv_ksq = bld.define("fk_inv_ksq", 1 / ksq, step)
    rho2 = bld.define("fk_rho2", platform_rms_radius(robot) ** 2, step)
    modes = []
    for m, sign in ((1, 1), (2, -1)):
        cos_a = bld.define(f"fk{m}_cos", (-A * C - sign * B * root) * inv_ab2, step)
        sin_a = bld.define(f"fk{m}_sin", (-B * C + sign * A * root) * inv_ab2, step)
        r = {leg: w[leg] - u[leg] * cos_a - v[leg] * sin_a for leg in LEGS}
        b1 = bld.define(f"fk{m}_b1", sum(n[leg][0] * r[leg] for leg in LEGS), step)
        b2 = bld.define(f"fk{m}_b2", sum(n[leg][1] * r[leg] for leg in LEGS), step)
        px = bld.define(f"fk{m}_px", (s_yy * b1 - s_xy * b2) * inv_ksq, step)
        py = bld.define(f"fk{m}_py", (s_xx * b2 - s_xy * b1) * inv_ksq, step)
        if platform_lines:  # phi = -psi, G = -R(phi) H
            cos_phi, sin_phi = cos_a, -sin_a
            g = rotate(cos_phi, sin_phi, (px, py))
            x = bld.define(f"fk{m}_x", -g[0], step)
            y = bld.define(f"fk{m}_y", -g[1], step)
        else:
            cos_phi, sin_phi, x, y = cos_a, sin_a, px, py
        phi = bld.define(f"fk{m}_phi", sp.atan2(sin_phi, cos_phi), step)
        margin = bld.define(
            f"fk{m}_margin",
            sp.Min(disc, ab2 - DEGENERACY_TOL**2 * ksq * rho2, ksq - DEGENERACY_TOL**2),
            step,
        )
        modes.append(Mode(x, y, phi, margin))
    return modes


@dataclass(frozen=True)
class _Harmonic:
    """``f0 + fc cos(phi) + fs sin(phi)``: a trigonometric polynomial of degree one."""

    f0: sp.Expr
    fc: sp.Expr
    fs: sp.Expr

    def half_angle(self) -> list[sp.Expr]:
        """``(1 + t^2) f`` in ``t = tan(phi/2)``, ascending: ``f0 + fc, 2 fs, f0 - fc``."""
        return [self.f0 + self.fc, 2 * self.fs, self.f0 - self.fc]

    def at(self, cos_phi: sp.Expr, sin_phi: sp.Expr) -> sp.Expr:
        return self.f0 + self.fc * cos_phi + self.fs * sin_phi


def _poly_mul(a: Sequence[sp.Expr], b: Sequence[sp.Expr]) -> list[sp.Expr]:
    out = [sp.Integer(0)] * (len(a) + len(b) - 1)
    for i, ai in enumerate(a):
        for j, bj in enumerate(b):
            out[i + j] += ai * bj
    return out


def _poly_define(bld: Builder, name: str, poly: Sequence[sp.Expr], step: str) -> list[sp.Expr]:
    return [bld.define(f"{name}_{k}", coeff, step) for k, coeff in enumerate(poly)]


@dataclass(frozen=True)
class _Circles:
    """The leg-A-relative quantities of the three circles (see :func:`sextic_coefficients`)."""

    r2_a: sp.Expr  # r_A^2
    rho: dict[str, _Harmonic]  # rho_i, i = B, C: u . w_i = rho_i
    w: dict[str, tuple[_Harmonic, _Harmonic]]  # w_i = R P_i - Q_i, x and y components
    wsq: dict[str, _Harmonic]  # |w_i|^2
    wbc: _Harmonic  # w_B . w_C
    det: _Harmonic  # D = w_B x w_C


def _circles(bld: Builder, holds: dict[str, Locked]) -> _Circles:
    step = STEP_CIRCLES
    ref, others = LEGS[0], LEGS[1:]
    pa, ba = holds[ref].a, holds[ref].b
    P, Q = {}, {}
    for leg in others:
        P[leg] = sub(holds[leg].a, pa)
        Q[leg] = sub(holds[leg].b, ba)
    rho, w, wsq = {}, {}, {}

    def harmonic(name: str, f0: sp.Expr, fc: sp.Expr, fs: sp.Expr) -> _Harmonic:
        parts = zip("0cs", (f0, fc, fs), strict=True)
        return _Harmonic(*(bld.define(f"{name}_{k}", f, step) for k, f in parts))

    r2_a = holds[ref].r2
    for leg in others:
        qp = bld.define(f"fkc_QP_{leg}", dot(Q[leg], P[leg]), step)  # Q . P
        pq = bld.define(f"fkc_PxQ_{leg}", cross(P[leg], Q[leg]), step)  # P x Q
        norms = bld.define(f"fkc_PPQQ_{leg}", norm2(P[leg]) + norm2(Q[leg]), step)
        # u . w_i = rho_i, from |u + w_i|^2 = r_i^2 and |u|^2 = r_A^2; Q . R P = c QP + s PxQ.
        rho[leg] = harmonic(f"fkc_rho_{leg}", (holds[leg].r2 - r2_a - norms) / 2, qp, pq)
        wsq[leg] = _Harmonic(norms, -2 * qp, -2 * pq)
        # R P - Q = cos (P) + sin (-P_y, P_x) - Q
        w[leg] = (
            _Harmonic(-Q[leg][0], P[leg][0], -P[leg][1]),
            _Harmonic(-Q[leg][1], P[leg][1], P[leg][0]),
        )
    b, c = others
    wbc = harmonic(
        "fkc_wBC",
        dot(P[b], P[c]) + dot(Q[b], Q[c]),
        -(dot(Q[b], P[c]) + dot(Q[c], P[b])),
        -(cross(P[c], Q[b]) + cross(P[b], Q[c])),
    )
    det = harmonic(
        "fkc_D",
        cross(P[b], P[c]) + cross(Q[b], Q[c]),
        cross(P[c], Q[b]) - cross(P[b], Q[c]),
        dot(P[b], Q[c]) - dot(P[c], Q[b]),
    )
    return _Circles(r2_a, rho, w, wsq, wbc, det)


def sextic_coefficients(prog: Program, holds: dict[str, Locked]) -> list[sp.Expr]:
    """Coefficients ``a0..a6`` (ascending) of the direct-kinematics sextic in ``t = tan(phi/2)``.

    Three circle holds ``|G + R a_i - b_i|^2 = r_i^2``. With ``u = G + R a_A - b_A``,
    ``P_i = a_i - a_A`` (platform frame) and ``Q_i = b_i - b_A`` (world), the equations
    ``|u|^2 = r_A^2`` and ``|u + w_i|^2 = r_i^2`` with ``w_i = R(phi) P_i - Q_i`` (i = B, C)
    give, by subtraction, two equations linear in ``u``: ``u . w_i = rho_i``,
    ``rho_i = (r_i^2 - r_A^2 - |P_i|^2 - |Q_i|^2) / 2 + Q_i . R P_i``. Then
    ``D u = rho_C w_B^perp - rho_B w_C^perp`` with ``D = w_B x w_C``, and ``|u|^2 = r_A^2``
    becomes ``F(phi) = rho_C^2 |w_B|^2 + rho_B^2 |w_C|^2 - 2 rho_B rho_C w_B . w_C - r_A^2 D^2
    = 0``. Each of ``rho_i``, ``|w_i|^2``, ``w_B . w_C``, ``D`` is ``f0 + fc cos + fs sin`` (the
    rotation appears once), so ``F`` has trigonometric degree 3 and ``(1 + t^2)^3 F`` is a
    polynomial of degree 6 in ``t``: at most six modes.

    ``a6 = F(pi)``: when ``phi = pi`` is a root the degree drops (the root is at ``t = inf``).
    A root with ``D = 0`` needs the treatment described in :func:`pose_from_angle`. Units: m^6.
    """
    step = STEP_CIRCLES
    bld = Builder(prog)
    k = _circles(bld, holds)
    b, c = LEGS[1:]
    rb = _poly_define(bld, "fkc_trho_B", k.rho[b].half_angle(), step)
    rc = _poly_define(bld, "fkc_trho_C", k.rho[c].half_angle(), step)
    wbb = k.wsq[b].half_angle()
    wcc = k.wsq[c].half_angle()
    wbc = k.wbc.half_angle()
    det = _poly_define(bld, "fkc_tD", k.det.half_angle(), step)
    # rho_C^2 |w_B|^2 + rho_B^2 |w_C|^2 - 2 rho_B rho_C w_B.w_C
    #   = rho_C (rho_C |w_B|^2 - rho_B w_B.w_C) + rho_B (rho_B |w_C|^2 - rho_C w_B.w_C)
    left = [x - y for x, y in zip(_poly_mul(rc, wbb), _poly_mul(rb, wbc), strict=True)]
    right = [x - y for x, y in zip(_poly_mul(rb, wcc), _poly_mul(rc, wbc), strict=True)]
    left = _poly_define(bld, "fkc_left", left, step)
    right = _poly_define(bld, "fkc_right", right, step)
    main = [x + y for x, y in zip(_poly_mul(rc, left), _poly_mul(rb, right), strict=True)]
    det2 = _poly_define(bld, "fkc_tD2", _poly_mul(det, det), step)
    one_plus_t2 = [sp.Integer(1), sp.Integer(0), sp.Integer(1)]
    det_term = _poly_mul(det2, one_plus_t2)
    return [bld.define(f"fkc_a{j}", main[j] - k.r2_a * det_term[j], step) for j in range(7)]


def pose_from_angle(
    prog: Program, holds: dict[str, Locked], cos_phi: sp.Expr, sin_phi: sp.Expr
) -> tuple[sp.Expr, sp.Expr]:
    """``(x, y)`` of G for a root ``phi`` of the sextic (three circle holds), back substitution.

    ``u = (rho_C w_B^perp - rho_B w_C^perp) / D`` (see :func:`sextic_coefficients`), then
    ``G = b_A + u - R(phi) a_A``. Singular where ``D = w_B x w_C = 0``: the two linear
    equations for ``u`` are then parallel, or void. That happens at a root where two modes share
    one orientation (``F`` then has a double root there), or at a spurious root where both
    ``w_i`` vanish (base and platform triangles congruent at this angle: the paper's robot at
    ``phi = -pi/3``, a root of ``F`` for any lengths). This function does not guard it; the
    generated C tests ``|D| <= PARALLEL_TOL |w_B| |w_C|`` and then intersects the line
    ``u . w_i = rho_i`` of the longer ``w_i`` with the circle ``|u| = r_A``. Units: m.
    """
    step = STEP_CIRCLES
    bld = Builder(prog)
    k = _circles(bld, holds)
    b, c = LEGS[1:]
    cs = (cos_phi, sin_phi)
    rho_b = bld.define("fkc_rho_B", k.rho[b].at(*cs), step)
    rho_c = bld.define("fkc_rho_C", k.rho[c].at(*cs), step)
    wb = [bld.define(f"fkc_wB_{a}", h.at(*cs), step) for a, h in zip("xy", k.w[b], strict=True)]
    wc = [bld.define(f"fkc_wC_{a}", h.at(*cs), step) for a, h in zip("xy", k.w[c], strict=True)]
    inv_det = bld.define("fkc_inv_D", 1 / cross((wb[0], wb[1]), (wc[0], wc[1])), step)
    ux = (-rho_c * wb[1] + rho_b * wc[1]) * inv_det
    uy = (rho_c * wb[0] - rho_b * wc[0]) * inv_det
    a, base = holds[LEGS[0]].a, holds[LEGS[0]].b
    turned = rotate(cos_phi, sin_phi, a)
    x = bld.define("fkc_x", base[0] + ux - turned[0], step)
    y = bld.define("fkc_y", base[1] + uy - turned[1], step)
    return x, y
