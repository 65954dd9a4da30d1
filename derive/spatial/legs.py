"""Each leg type: its kinematics from the platform's motion and its joint loads.

A leg reaches the platform at one point (hexapods: the S centre) or two (Deltas: the lower S of
its two rods). The platform's force there is unknown; the leg's own balance under the virtual
motions of its passive joints (the U's two turns; a rod's turns about its upper S) fixes all of
it but its component along the leg or rod, ``t``: ``F = F0 + t w`` (:class:`Connector`). The six
``t`` of the robot follow from the platform's balance (:mod:`.virtual_work`); then every joint
load follows down the leg (:meth:`Leg.loads`), the last one giving the actuator effort.

Joint outputs (docs/spatial-robots.md): the wrench the earlier body exerts on the later one, the
moment about the joint's point.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import sympy as sp
from rpr3gen_derive.spatial.bodies import Wrench, body_wrench, u_joint
from rpr3gen_derive.spatial.platform import PlatformMotion, param
from rpr3gen_derive.spatial.structures import INERTIA_ENTRIES
from rpr3gen_derive.spatial.vectors import Namer, Vec, cross, dot, inertia, rotation, vec

ZERO = vec(0, 0, 0)


@dataclass(frozen=True)
class Connector:
    """Where a leg holds the platform: the point (world), its offset from the platform's
    origin, the free direction ``w`` (unit) and the force ``F0`` the leg's own balance gives."""

    point: Vec
    offset: Vec
    w: Vec
    F0: Vec


@dataclass(frozen=True)
class JointLoad:
    joint: int
    force: Vec
    moment: Vec


@dataclass
class Leg:
    """One leg's kinematic outputs (``(family, expr)``), connectors, actuator coordinate, its
    reach (1 at home, 0 at a serial singularity) and the loads from its connectors' forces."""

    coordinates: list[tuple[str, sp.Expr]]
    connectors: list[Connector]
    actuator: sp.Expr
    reach: sp.Expr
    loads: Callable[[list[Vec]], tuple[list[JointLoad], sp.Expr]]
    #: ``g`` with ``qa' = g . S'`` (``S`` the platform point the leg reaches, its offset from
    #: the platform's origin ``offset``): the leg's row of the actuator Jacobian.
    gradient: Vec = field(default_factory=lambda: vec(0, 0, 0))
    offset: Vec = field(default_factory=lambda: vec(0, 0, 0))


def _p(name: str, leg: str) -> sp.Symbol:
    return param(f"{name}_{leg}")


def _pv(name: str, leg: str) -> Vec:
    return vec(*(_p(f"{name}{a}", leg) for a in "xyz"))


def _tensor(k: int, leg: str) -> sp.Matrix:
    return inertia(tuple(_p(f"I{k}{e}", leg) for e in INERTIA_ENTRIES))


def gravity() -> Vec:
    return vec(param("gx"), param("gy"), param("gz"))


def _norm(n: Namer, name: str, v: Vec) -> sp.Expr:
    return n.s(name, sp.sqrt(dot(v, v)))


@dataclass(frozen=True)
class Elbow:
    """Joint 1 (R or P) carrying the elbow ``E``: its coordinate, rate and acceleration, the
    elbow's motion, the body's rotation (None for P) and the serial determinant ``D``."""

    q: sp.Expr
    dq: sp.Expr
    ddq: sp.Expr
    E: Vec
    aE: Vec
    d: Vec
    dd: Vec
    ddd: Vec
    R: sp.Matrix | None
    omega: Vec | None
    alpha: Vec | None
    reach: sp.Expr
    D: sp.Expr


def elbow(n: Namer, kind: str, leg: str, S: Vec, vS: Vec, aS: Vec) -> Elbow:
    """Joint 1 of RUS, PUS, RSS2, PSS2: the elbow ``E`` at distance ``L = |S_home - E_home|``
    from the platform point ``S``, in the working mode of ``sigma`` (the sign of
    ``D = (S - E) . dE/dq1`` at home)."""
    B, a, Eh, Sh = _pv("b", leg), _pv("a", leg), _pv("e", leg), _pv("p", leg)
    sigma = _p("sigma", leg)
    L2 = n.s("L2h", dot(Sh - Eh, Sh - Eh))
    if kind == "R":
        c0 = n.v("c0", B + dot(a, Eh - B) * a)
        r0 = n.v("r0", Eh - c0)
        r0p = n.v("r0p", cross(a, r0))
        Dh = n.s("Dh", dot(Sh - Eh, r0p))
        s = n.v("sc0", S - c0)
        K, M = n.s("K", 2 * dot(s, r0)), n.s("Mk", 2 * dot(s, r0p))
        N = n.s("Nk", dot(s, s) + dot(r0, r0) - L2)
        rho2 = n.s("rho2", K**2 + M**2)
        Q = n.s("Qk", sigma * sp.sqrt(rho2 - N**2))
        cq, sq = n.s("cq1", (K * N + M * Q) / rho2), n.s("sq1", (M * N - K * Q) / rho2)
        q = n.s("q1", sp.atan2(sq, cq))
        E = n.v("E", c0 + cq * r0 + sq * r0p)
        t1 = n.v("t1", cross(a, E - c0))  # dE/dq1
        d = n.v("d", S - E)
        D = n.s("D", dot(d, t1))
        dq = n.s("dq1", dot(d, vS) / D)
        vE = dq * t1
        dd = n.v("dd", vS - vE)
        ddq = n.s("ddq1", (dot(d, aS + dq**2 * (E - c0)) + dot(dd, dd)) / D)
        aE = n.v("aE", ddq * t1 - dq**2 * (E - c0))
        cosq, sinq = cq, sq
        R = n.m("R1", rotation(a, cosq, sinq))
        ddd = n.v("ddd", aS - aE)
        return Elbow(q, dq, ddq, E, aE, d, dd, ddd, R, dq * a, ddq * a, D / Dh, D)
    Dh = n.s("Dh", dot(Sh - Eh, a))
    dh = n.v("dh", S - Eh)
    ad = n.s("ad", dot(a, dh))
    q = n.s("q1", ad - sigma * sp.sqrt(ad**2 - dot(dh, dh) + L2))
    E = n.v("E", Eh + q * a)
    d = n.v("d", S - E)
    D = n.s("D", dot(d, a))
    dq = n.s("dq1", dot(d, vS) / D)
    dd = n.v("dd", vS - dq * a)
    ddq = n.s("ddq1", (dot(d, aS) + dot(dd, dd)) / D)
    aE = ddq * a
    ddd = n.v("ddd", aS - aE)
    return Elbow(q, dq, ddq, E, aE, d, dd, ddd, None, None, None, D / Dh, D)


def _joint1_body(n: Namer, leg: str, el: Elbow, kind: str) -> tuple[Vec, Wrench]:
    """Joint 1's point (R: ``base``; P: ``base + q1 axis``, sliding with the body) and the
    wrench of the body after it (the crank, carriage or arm)."""
    g, B, a = gravity(), _pv("b", leg), _pv("a", leg)
    P1 = B if kind == "R" else n.v("P1", B + el.q * a)
    if el.R is None:
        r1 = n.v("r1", _pv("c1", leg) + el.q * a - P1)
        return P1, body_wrench(n, "1", _p("m1", leg), P1 + r1, el.aE, g)
    r1 = n.v("r1", el.R * (_pv("c1", leg) - B))
    w1, al1 = el.omega, el.alpha
    assert w1 is not None
    assert al1 is not None
    a1 = cross(al1, r1) + cross(w1, cross(w1, r1))
    return P1, body_wrench(n, "1", _p("m1", leg), B + r1, a1, g, _tensor(1, leg), el.R, w1, al1)


def _moment(point: Vec, at: Vec, force: Vec) -> Vec:
    return cross(at - point, force)


def ups(n: Namer, leg: str, pm: PlatformMotion) -> Leg:
    """A UPS leg: U at ``base``, cylinder, P along the leg (actuated), piston, S at the
    platform. The U's balance about its centre along its two axes leaves the force along the
    leg free."""
    g = gravity()
    B, p = _pv("b", leg), _pv("p", leg)
    r, S, vS, aS = pm.point(n, "S", p)
    d = n.v("d", S - B)
    L = _norm(n, "L", d)
    Lh = _norm(n, "Lh", p - B)
    u = n.v("u", d / L)
    dL = n.s("dL", dot(u, vS))
    du = n.v("du", (vS - dL * u) / L)
    ddL = n.s("ddL", dot(du, vS) + dot(u, aS))
    ddu = n.v("ddu", (aS - ddL * u - 2 * dL * du) / L)
    U = u_joint(n, _pv("u1", leg), _pv("u2", leg), (p - B) / Lh, u, du, ddu)
    q2 = n.s("q2", L - Lh)
    R1 = n.m("R1", U.rotation)
    w, al = U.omega, U.alpha
    r1 = n.v("r1", R1 * (_pv("c1", leg) - B))
    a1 = cross(al, r1) + cross(w, cross(w, r1))
    W1 = body_wrench(n, "1", _p("m1", leg), B + r1, a1, g, _tensor(1, leg), R1, w, al)
    r2 = n.v("r2", R1 * (_pv("c2", leg) - B) + q2 * u)
    a2 = cross(al, r2) + cross(w, cross(w, r2)) + 2 * dL * cross(w, u) + ddL * u
    W2 = body_wrench(n, "2", _p("m2", leg), B + r2, a2, g, _tensor(2, leg), R1, w, al)
    Mb = n.v("Mb", W1.about(B) + W2.about(B))
    un = n.s("uN", L * dot(u, cross(U.e1, U.e2)))
    F0 = n.v("F0", (dot(U.e2, Mb) * U.e1 - dot(U.e1, Mb) * U.e2) / un)
    Q2 = B + q2 * u

    def loads(F: list[Vec]) -> tuple[list[JointLoad], sp.Expr]:
        (F3,) = F
        f2 = n.v("f2", F3 - W2.force)
        m2 = n.v("m2", _moment(Q2, S, F3) - W2.about(Q2))
        f1 = n.v("f1", f2 - W1.force)
        m1 = n.v("m1", m2 + _moment(B, Q2, f2) - W1.about(B))
        return [JointLoad(1, f1, m1), JointLoad(2, f2, m2), JointLoad(3, F3, ZERO)], dot(f2, u)

    coordinates = [("q1a", U.ua), ("q1b", U.ub), ("q2", q2), ("qd2", dL), ("qdd2", ddL)]
    coordinates += _s_joint(n, R1, pm)
    return Leg(coordinates, [Connector(S, r, u, F0)], q2, L / Lh, loads, u, r)


def _s_joint(n: Namer, earlier: sp.Matrix | None, pm: PlatformMotion) -> list[tuple[str, sp.Expr]]:
    """The S's rotation vector of ``earlier^T R`` (the platform's ``R``): ``theta / sin theta``
    times the axial vector of its skew part, ``theta = atan2(|v|, (trace - 1) / 2)``."""
    assert pm.R is not None
    rel = pm.R if earlier is None else earlier.T * pm.R
    v = vec(rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]) / 2
    v = n.v("sv", v)
    s = n.s("ss", sp.sqrt(dot(v, v)))
    c = n.s("scos", (rel[0, 0] + rel[1, 1] + rel[2, 2] - 1) / 2)
    # v = 0 exactly when theta = 0 (or pi, outside the range): any finite factor serves there
    k = n.s("sk", sp.atan2(s, c) / sp.Max(s, sp.Float("1e-300")))
    return [(f"q3{a}", v[i] * k) for i, a in enumerate("xyz")]


def rus_pus(n: Namer, leg: str, pm: PlatformMotion, kind: str) -> Leg:
    """An RUS or PUS leg: joint 1 (R or P, actuated) moves the crank or carriage holding the U
    at the elbow; the rod joins the U to the S at the platform."""
    g = gravity()
    p, a = _pv("p", leg), _pv("a", leg)
    r, S, vS, aS = pm.point(n, "S", p)
    el = elbow(n, kind, leg, S, vS, aS)
    Eh, Sh = _pv("e", leg), p
    L = _norm(n, "L", Sh - Eh)
    u = n.v("u", el.d / L)
    du, ddu = n.v("du", el.dd / L), n.v("ddu", el.ddd / L)
    U = u_joint(n, _pv("u1", leg), _pv("u2", leg), (Sh - Eh) / L, u, du, ddu, el.R, el.omega,
                el.alpha)  # fmt: skip
    P1, W1 = _joint1_body(n, leg, el, kind)
    R2 = n.m("R2", U.rotation if el.R is None else el.R * U.rotation)
    w2, al2 = U.omega, U.alpha
    r2 = n.v("r2", R2 * (_pv("c2", leg) - Eh))
    a2 = el.aE + cross(al2, r2) + cross(w2, cross(w2, r2))
    W2 = body_wrench(n, "2", _p("m2", leg), el.E + r2, a2, g, _tensor(2, leg), R2, w2, al2)
    Mb = n.v("Mb", W2.about(el.E))
    un = n.s("uN", L * dot(u, cross(U.e1, U.e2)))
    F0 = n.v("F0", (dot(U.e2, Mb) * U.e1 - dot(U.e1, Mb) * U.e2) / un)

    def loads(F: list[Vec]) -> tuple[list[JointLoad], sp.Expr]:
        (F3,) = F
        f2 = n.v("f2", F3 - W2.force)
        m2 = n.v("m2", _moment(el.E, S, F3) - W2.about(el.E))
        f1 = n.v("f1", f2 - W1.force)
        m1 = n.v("m1", m2 + _moment(P1, el.E, f2) - W1.about(P1))
        tau = dot(m1, a) if kind == "R" else dot(f1, a)
        return [JointLoad(1, f1, m1), JointLoad(2, f2, m2), JointLoad(3, F3, ZERO)], tau

    coordinates = [("q1", el.q), ("qd1", el.dq), ("qdd1", el.ddq), ("q2a", U.ua), ("q2b", U.ub)]
    coordinates += _s_joint(n, R2, pm)
    g_ = n.v("g", el.d / el.D)
    return Leg(coordinates, [Connector(S, r, u, F0)], el.q, el.reach, loads, g_, r)


def delta(n: Namer, leg: str, pm: PlatformMotion, kind: str) -> Leg:
    """A Delta leg (RSS2, PSS2): joint 1 (R or P, actuated) moves the arm or carriage; two
    parallel rods, S at both ends, join it to the platform. A rod's balance about its upper S
    leaves the force along the rod free."""
    g = gravity()
    p, a = _pv("p", leg), _pv("a", leg)
    bar = a if kind == "R" else _pv("bar", leg)
    half = _p("w", leg) / 2
    _, P, vP, aP = pm.point(n, "P", p)
    el = elbow(n, kind, leg, P, vP, aP)
    L = _norm(n, "L", p - _pv("e", leg))
    u = n.v("u", el.d / L)
    ddu = n.v("ddu", el.ddd / L)
    fr, mr, Ir = _p("fr", leg), _p("mr", leg), _p("Ir", leg)
    aC = (1 - fr) * el.aE + fr * aP
    Wr_force = n.v("Fr", mr * (g - aC))
    # about the upper S: the rod's weight and inertia at fr L u, and -Ir u x u''
    Mr = n.v("Mr", fr * L * cross(u, Wr_force) - Ir * cross(u, ddu))
    F0 = n.v("F0", cross(Mr, u) / L)
    uppers = [n.v(f"Uu{k}", el.E + s * half * bar) for k, s in ((1, 1), (2, -1))]
    lowers = [n.v(f"Pl{k}", P + s * half * bar) for k, s in ((1, 1), (2, -1))]
    offsets = [n.v(f"rP{k}", p + s * half * bar) for k, s in ((1, 1), (2, -1))]
    P1, W1 = _joint1_body(n, leg, el, kind)

    def loads(F: list[Vec]) -> tuple[list[JointLoad], sp.Expr]:
        ups_ = [n.v(f"fu{k}", Fk - Wr_force) for k, Fk in enumerate(F, start=1)]
        f1 = n.v("f1", ups_[0] + ups_[1] - W1.force)
        m1 = _moment(P1, uppers[0], ups_[0]) + _moment(P1, uppers[1], ups_[1])
        m1 = n.v("m1", m1 - W1.about(P1))
        tau = dot(m1, a) if kind == "R" else dot(f1, a)
        out = [JointLoad(1, f1, m1)]
        out += [JointLoad(2 + k, f, ZERO) for k, f in enumerate(ups_)]
        out += [JointLoad(4 + k, Fk, ZERO) for k, Fk in enumerate(F)]
        return out, tau

    connectors = [Connector(lowers[k], offsets[k], u, F0) for k in range(2)]
    coordinates = [("q1", el.q), ("qd1", el.dq), ("qdd1", el.ddq)]
    g_ = n.v("g", el.d / el.D)
    return Leg(coordinates, connectors, el.q, el.reach, loads, g_, p)


def leg(prog_namer: Namer, kinds: str, leg_: str, pm: PlatformMotion) -> Leg:
    """The leg ``leg_`` of type ``kinds``."""
    if kinds == "UPS":
        return ups(prog_namer, leg_, pm)
    if kinds in ("RUS", "PUS"):
        return rus_pus(prog_namer, leg_, pm, kinds[0])
    return delta(prog_namer, leg_, pm, kinds[0])


__all__ = ["Connector", "JointLoad", "Leg", "leg"]
