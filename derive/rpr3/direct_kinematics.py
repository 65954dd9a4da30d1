"""The direct kinematics of the 3-RPR robot: every assembly mode of the actuator coordinates.

- :func:`assembly_modes_revolute`: revolute actuation, closed form, at most 2 modes (the line
  conditions reduce to ``A cos(phi) + B sin(phi) + C = 0``);
- :func:`sextic_coefficients` and :func:`pose_from_angle`: prismatic actuation, the classical
  sextic in ``tan(phi/2)`` (Gosselin & Sefrioui; Merlet), at most 6 modes, and the back
  substitution of a root.

Each appends named assignments to a :class:`~rpr3gen_derive.codegen.program.Program`, from the
inputs :data:`~rpr3gen_derive.rpr3.control.qa`; see docs/control-model.md.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.control import Builder, qa
from rpr3gen_derive.rpr3.symbols import LEGS
from rpr3gen_derive.rpr3.virtual_work import platform_radius_squared

STEP_FK_REVOLUTE = "direct kinematics, revolute actuation (closed form)"
STEP_FK_PRISMATIC = "direct kinematics, prismatic actuation (sextic in tan(phi/2))"

#: Most assembly modes for given actuator coordinates (interfaces.md, RPR3_MAX_MODES).
MAX_MODES: dict[str, int] = {"revolute": 2, "prismatic": 6}

#: A leg shorter than this times the platform's RMS radius has no length (not an assembly mode).
LENGTH_TOL = 1e-9
#: Revolute direct kinematics: legs within this angle (rad) of all parallel (``|k|``), or
#: ``|(A, B)|`` below this times ``|k| rho``, are degenerate (round-off is ~1e-16 of either).
DEGENERACY_TOL = 1e-10


def _xy(v: sp.Matrix) -> tuple[sp.Expr, sp.Expr]:
    return v[0], v[1]


def _cross(a: tuple[sp.Expr, sp.Expr], b: tuple[sp.Expr, sp.Expr]) -> sp.Expr:
    return a[0] * b[1] - a[1] * b[0]


def _dot(a: tuple[sp.Expr, sp.Expr], b: tuple[sp.Expr, sp.Expr]) -> sp.Expr:
    return a[0] * b[0] + a[1] * b[1]


class Mode(NamedTuple):
    """One assembly mode ``(x, y, phi, margin)``: the pose, and ``margin >= 0`` where it exists.

    ``margin`` is the smallest of the quantities whose signs decide existence (the discriminant,
    the degeneracy tests and the leg lengths, each minus its tolerance), so that the generated
    code returns a number where SymPy would say True or False.
    """

    x: sp.Expr
    y: sp.Expr
    phi: sp.Expr
    margin: sp.Expr


def assembly_modes_revolute(prog: Program) -> list[Mode]:
    """The two assembly modes of revolute actuation, in closed form, from the inputs :data:`qa`.

    With the leg angles ``theta_i = alpha_i + qa_i`` known (eq. 5), each platform joint lies on
    the line through ``A1_i`` along ``e_i``: ``n_i . (G + R(phi) p_i - A1_i) = 0``, i.e.
    ``n_i . G + u_i cos(phi) + v_i sin(phi) = w_i`` with ``u_i = n_i . p_i``, ``v_i = e_i . p_i``,
    ``w_i = n_i . A1_i``. The vector ``k = (sin(th_C - th_B), sin(th_A - th_C), sin(th_B - th_A))``
    annihilates the ``G`` columns (``sum_i k_i n_i = 0``), which leaves
    ``A cos(phi) + B sin(phi) + C = 0`` with ``A = k . u``, ``B = k . v``, ``C = -k . w``:
    ``(cos, sin)(phi) = (-A C -/+ B r, -B C +/- A r) / (A^2 + B^2)``, ``r = sqrt(A^2 + B^2 - C^2)``.
    ``G`` then solves the three (consistent) line equations in the least-squares sense,
    ``N^T N G = N^T (w - u cos - v sin)`` with ``det(N^T N) = |k|^2``.

    A mode is valid when it is real (``A^2 + B^2 >= C^2``) and every leg length
    ``(A3 - A1) . e_i`` exceeds ``LENGTH_TOL`` times the platform's RMS radius ``rho``: the
    round-off of a zero length is not a mode (the paper's robot, whose base and platform triangles
    are congruent, has every leg of zero length at ``G = 0, phi = -pi/3`` whatever ``qa``).

    Degenerate inputs have no isolated mode, and both modes are reported invalid: all legs
    parallel (``|k| <= DEGENERACY_TOL``: G is not fixed), or ``A = B = 0``
    (``|(A, B)| <= DEGENERACY_TOL |k| rho``), where the actuators do not fix the orientation:
    either no pose at all (``C != 0``) or a continuum of them (``C = 0``, a self-motion). The
    round-off of a zero ``k``, ``A`` or ``B`` is about 1e-16 of these scales.

    ``phi`` is in ``[-pi, pi]`` (``atan2``); the two modes coincide where ``A^2 + B^2 = C^2``
    (a parallel singularity). Units: m, m, rad.
    """
    step = STEP_FK_REVOLUTE
    bld = Builder(prog)
    e, n, u, v, w = {}, {}, {}, {}, {}
    for i, leg in enumerate(LEGS):
        angle = syms.alpha(leg) + qa[i]
        c = bld.define(f"fk_cos_theta_{leg}", sp.cos(angle), step)
        s = bld.define(f"fk_sin_theta_{leg}", sp.sin(angle), step)
        e[leg], n[leg] = (c, s), (-s, c)
        p = _xy(syms.platform_joint(leg))
        u[leg] = bld.define(f"fk_u_{leg}", _dot(n[leg], p), step)
        v[leg] = bld.define(f"fk_v_{leg}", _dot(e[leg], p), step)
        w[leg] = bld.define(f"fk_w_{leg}", _dot(n[leg], _xy(syms.base_pivot(leg))), step)
    k = {
        leg: bld.define(f"fk_k_{leg}", _cross(e[LEGS[(i + 1) % 3]], e[LEGS[(i + 2) % 3]]), step)
        for i, leg in enumerate(LEGS)
    }
    A = bld.define("fk_A", sum(k[leg] * u[leg] for leg in LEGS), step)
    B = bld.define("fk_B", sum(k[leg] * v[leg] for leg in LEGS), step)
    C = bld.define("fk_C", -sum(k[leg] * w[leg] for leg in LEGS), step)
    ab2 = bld.define("fk_AB2", A**2 + B**2, step)
    disc = bld.define("fk_disc", ab2 - C**2, step)
    root = bld.define("fk_root", sp.sqrt(sp.Max(disc, 0)), step)
    inv_ab2 = bld.define("fk_inv_AB2", 1 / ab2, step)
    # Normal equations of the three line conditions for G: N has rows n_i^T.
    s_ss = sum(n[leg][0] ** 2 for leg in LEGS)
    s_cc = sum(n[leg][1] ** 2 for leg in LEGS)
    s_sc = sum(n[leg][0] * n[leg][1] for leg in LEGS)
    ksq = bld.define("fk_ksq", sum(k[leg] ** 2 for leg in LEGS), step)
    inv_ksq = bld.define("fk_inv_ksq", 1 / ksq, step)
    min_length = platform_rms_radius()
    modes = []
    for m, sign in ((1, 1), (2, -1)):
        cos_phi = bld.define(f"fk{m}_cos_phi", (-A * C - sign * B * root) * inv_ab2, step)
        sin_phi = bld.define(f"fk{m}_sin_phi", (-B * C + sign * A * root) * inv_ab2, step)
        phi = bld.define(f"fk{m}_phi", sp.atan2(sin_phi, cos_phi), step)
        r = {leg: w[leg] - u[leg] * cos_phi - v[leg] * sin_phi for leg in LEGS}
        b1 = bld.define(f"fk{m}_b1", sum(n[leg][0] * r[leg] for leg in LEGS), step)
        b2 = bld.define(f"fk{m}_b2", sum(n[leg][1] * r[leg] for leg in LEGS), step)
        x = bld.define(f"fk{m}_x", (s_cc * b1 - s_sc * b2) * inv_ksq, step)
        y = bld.define(f"fk{m}_y", (s_ss * b2 - s_sc * b1) * inv_ksq, step)
        lengths = []
        for leg in LEGS:
            p = syms.platform_joint(leg)
            a1 = syms.base_pivot(leg)
            d = (
                x + cos_phi * p[0] - sin_phi * p[1] - a1[0],
                y + sin_phi * p[0] + cos_phi * p[1] - a1[1],
            )
            lengths.append(bld.define(f"fk{m}_length_{leg}", _dot(e[leg], d), step))
        margin = bld.define(
            f"fk{m}_margin",
            sp.Min(
                disc,
                ab2 - DEGENERACY_TOL**2 * ksq * platform_radius_squared(),
                ksq - DEGENERACY_TOL**2,
                *(length - LENGTH_TOL * min_length for length in lengths),
            ),
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
class _PrismaticClosure:
    """The leg-A-relative quantities of the prismatic direct kinematics (see sextic docs)."""

    length_a_sq: sp.Expr  # L_A^2
    rho: dict[str, _Harmonic]  # rho_i, i = B, C: u . w_i = rho_i
    w: dict[str, tuple[_Harmonic, _Harmonic]]  # w_i = R P_i - Q_i, x and y components
    wsq: dict[str, _Harmonic]  # |w_i|^2
    wbc: _Harmonic  # w_B . w_C
    det: _Harmonic  # D = w_B x w_C


def _prismatic_closure(bld: Builder) -> _PrismaticClosure:
    step = STEP_FK_PRISMATIC
    ref, others = LEGS[0], LEGS[1:]
    length = {
        leg: bld.define(f"fkp_L_{leg}", syms.l0 + syms.l2 + qa[i], step)
        for i, leg in enumerate(LEGS)
    }
    pa, aa = _xy(syms.platform_joint(ref)), _xy(syms.base_pivot(ref))
    P, Q = {}, {}
    for leg in others:
        p, a = _xy(syms.platform_joint(leg)), _xy(syms.base_pivot(leg))
        P[leg] = (p[0] - pa[0], p[1] - pa[1])
        Q[leg] = (a[0] - aa[0], a[1] - aa[1])
    rho, w, wsq = {}, {}, {}

    def harmonic(name: str, f0: sp.Expr, fc: sp.Expr, fs: sp.Expr) -> _Harmonic:
        parts = zip("0cs", (f0, fc, fs), strict=True)
        return _Harmonic(*(bld.define(f"{name}_{k}", f, step) for k, f in parts))

    la2 = bld.define("fkp_LA2", length[ref] ** 2, step)
    for leg in others:
        qp = bld.define(f"fkp_QP_{leg}", _dot(Q[leg], P[leg]), step)  # Q . P
        pq = bld.define(f"fkp_PxQ_{leg}", _cross(P[leg], Q[leg]), step)  # P x Q
        norms = bld.define(f"fkp_PPQQ_{leg}", _dot(P[leg], P[leg]) + _dot(Q[leg], Q[leg]), step)
        # u . w_i = rho_i, from |u + w_i|^2 = L_i^2 and |u|^2 = L_A^2; Q . R P = c QP + s PxQ.
        rho[leg] = harmonic(f"fkp_rho_{leg}", (length[leg] ** 2 - la2 - norms) / 2, qp, pq)
        wsq[leg] = _Harmonic(norms, -2 * qp, -2 * pq)
        # R P - Q = cos (P) + sin (-P_y, P_x) - Q
        w[leg] = (
            _Harmonic(-Q[leg][0], P[leg][0], -P[leg][1]),
            _Harmonic(-Q[leg][1], P[leg][1], P[leg][0]),
        )
    b, c = others
    wbc = harmonic(
        "fkp_wBC",
        _dot(P[b], P[c]) + _dot(Q[b], Q[c]),
        -(_dot(Q[b], P[c]) + _dot(Q[c], P[b])),
        -(_cross(P[c], Q[b]) + _cross(P[b], Q[c])),
    )
    det = harmonic(
        "fkp_D",
        _cross(P[b], P[c]) + _cross(Q[b], Q[c]),
        _cross(P[c], Q[b]) - _cross(P[b], Q[c]),
        _dot(P[b], Q[c]) - _dot(P[c], Q[b]),
    )
    return _PrismaticClosure(la2, rho, w, wsq, wbc, det)


def sextic_coefficients(prog: Program) -> list[sp.Expr]:
    """Coefficients ``a0..a6`` (ascending) of the direct-kinematics sextic in ``t = tan(phi/2)``.

    Prismatic actuation, leg lengths ``L_i = l0 + l2 + qa_i`` (eq. 5). With ``u = A3 - A1`` of
    leg A, ``P_i = p_i - p_A`` (platform frame) and ``Q_i = A1_i - A1_A`` (world), the equations
    ``|u|^2 = L_A^2`` and ``|u + w_i|^2 = L_i^2`` with ``w_i = R(phi) P_i - Q_i`` (i = B, C) give,
    by subtraction, two equations linear in ``u``: ``u . w_i = rho_i``,
    ``rho_i = (L_i^2 - L_A^2 - |P_i|^2 - |Q_i|^2) / 2 + Q_i . R P_i``. Then
    ``D u = rho_C w_B^perp - rho_B w_C^perp`` with ``D = w_B x w_C``, and ``|u|^2 = L_A^2``
    becomes ``F(phi) = rho_C^2 |w_B|^2 + rho_B^2 |w_C|^2 - 2 rho_B rho_C w_B . w_C - L_A^2 D^2
    = 0``. Each of ``rho_i``, ``|w_i|^2``, ``w_B . w_C``, ``D`` is ``f0 + fc cos + fs sin`` (the
    rotation appears once), so ``F`` has trigonometric degree 3 and ``(1 + t^2)^3 F`` is a
    polynomial of degree 6 in ``t`` (Gosselin & Sefrioui; Merlet): at most six modes.

    ``a6 = F(pi)``: when ``phi = pi`` is a root the degree drops (the root is at ``t = inf``);
    the numeric drivers of ``fk_tracking`` look for it there. A root with ``D = 0`` needs the
    treatment described in :func:`pose_from_angle`. Units: m^6.
    """
    step = STEP_FK_PRISMATIC
    bld = Builder(prog)
    k = _prismatic_closure(bld)
    b, c = LEGS[1:]
    rb = _poly_define(bld, "fkp_trho_B", k.rho[b].half_angle(), step)
    rc = _poly_define(bld, "fkp_trho_C", k.rho[c].half_angle(), step)
    wbb = k.wsq[b].half_angle()
    wcc = k.wsq[c].half_angle()
    wbc = k.wbc.half_angle()
    det = _poly_define(bld, "fkp_tD", k.det.half_angle(), step)
    # rho_C^2 |w_B|^2 + rho_B^2 |w_C|^2 - 2 rho_B rho_C w_B.w_C
    #   = rho_C (rho_C |w_B|^2 - rho_B w_B.w_C) + rho_B (rho_B |w_C|^2 - rho_C w_B.w_C)
    left = [x - y for x, y in zip(_poly_mul(rc, wbb), _poly_mul(rb, wbc), strict=True)]
    right = [x - y for x, y in zip(_poly_mul(rb, wcc), _poly_mul(rc, wbc), strict=True)]
    left = _poly_define(bld, "fkp_left", left, step)
    right = _poly_define(bld, "fkp_right", right, step)
    main = [x + y for x, y in zip(_poly_mul(rc, left), _poly_mul(rb, right), strict=True)]
    det2 = _poly_define(bld, "fkp_tD2", _poly_mul(det, det), step)
    one_plus_t2 = [sp.Integer(1), sp.Integer(0), sp.Integer(1)]
    det_term = _poly_mul(det2, one_plus_t2)
    return [bld.define(f"fkp_a{j}", main[j] - k.length_a_sq * det_term[j], step) for j in range(7)]


def pose_from_angle(prog: Program, cos_phi: sp.Expr, sin_phi: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """``(x, y)`` of G for a root ``phi`` of the sextic (prismatic actuation), back substitution.

    ``u = (rho_C w_B^perp - rho_B w_C^perp) / D`` (see :func:`sextic_coefficients`), then
    ``G = A1_A + u - R(phi) p_A``. Singular where ``D = w_B x w_C = 0``: the two linear
    equations for ``u`` are then parallel, or void. That happens at a root where two modes share
    one orientation (``F`` then has a double root there), or at a spurious root where both
    ``w_i`` vanish (base and platform triangles congruent at this angle: the paper's robot at
    ``phi = -pi/3``, a root of ``F`` for any lengths). This function does not guard it; the
    numeric driver (``fk_tracking.pose_candidates``) tests
    ``|D| <= PARALLEL_TOL |w_B| |w_C|`` and then intersects the line ``u . w_i = rho_i`` of the
    longer ``w_i`` with the circle ``|u| = L_A`` (two candidates, each polished by Newton on the
    original equations), or drops the root when both ``w_i`` vanish (no isolated mode). Units: m.
    """
    step = STEP_FK_PRISMATIC
    bld = Builder(prog)
    k = _prismatic_closure(bld)
    b, c = LEGS[1:]
    cs = (cos_phi, sin_phi)
    rho_b = bld.define("fkp_rho_B", k.rho[b].at(*cs), step)
    rho_c = bld.define("fkp_rho_C", k.rho[c].at(*cs), step)
    wb = [bld.define(f"fkp_wB_{a}", h.at(*cs), step) for a, h in zip("xy", k.w[b], strict=True)]
    wc = [bld.define(f"fkp_wC_{a}", h.at(*cs), step) for a, h in zip("xy", k.w[c], strict=True)]
    inv_det = bld.define("fkp_inv_D", 1 / _cross((wb[0], wb[1]), (wc[0], wc[1])), step)
    ux = (-rho_c * wb[1] + rho_b * wc[1]) * inv_det
    uy = (rho_c * wb[0] - rho_b * wc[0]) * inv_det
    p, a1 = syms.platform_joint(LEGS[0]), syms.base_pivot(LEGS[0])
    x = bld.define("fkp_x", a1[0] + ux - (cos_phi * p[0] - sin_phi * p[1]), step)
    y = bld.define("fkp_y", a1[1] + uy - (sin_phi * p[0] + cos_phi * p[1]), step)
    return x, y


def platform_rms_radius() -> sp.Expr:
    """``rho = sqrt(mean |p_i|^2)`` (m): the length that turns ``phi`` into a distance."""
    return sp.sqrt(platform_radius_squared())
