"""A moving body's inertia wrench, and the U joint's coordinates and rates.

A body's wrench ``(F, M)`` is what gravity and its inertia apply to it: ``F = m (g - a_C)``,
``M = -(I alpha + omega x I omega)`` about its centre of mass, with ``I = R I_home R^T`` (the
tensor turns with the body). The virtual work of a body under a virtual motion is that of its
wrench; the legs' equations (:mod:`.legs`) state it for each free direction of their joints.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.spatial.vectors import Namer, Vec, cross, dot, rotation, vec


@dataclass(frozen=True)
class Wrench:
    """A body's gravity and inertia wrench: ``force`` at its centre of mass ``com`` (world
    position), ``moment`` about it."""

    force: Vec
    moment: Vec
    com: Vec

    def about(self, point: Vec) -> Vec:
        """The wrench's moment about ``point``."""
        return self.moment + cross(self.com - point, self.force)


def body_wrench(
    n: Namer,
    name: str,
    mass: sp.Expr,
    com: Vec,
    acc: Vec,
    g: Vec,
    tensor: sp.Matrix | None = None,
    R: sp.Matrix | None = None,
    omega: Vec | None = None,
    alpha: Vec | None = None,
) -> Wrench:
    """The wrench of a body of ``mass`` whose centre of mass is at ``com`` with acceleration
    ``acc``; a turning body gives its home ``tensor``, rotation ``R`` (None: none since home),
    ``omega`` and ``alpha``."""
    force = n.v(f"F{name}", mass * (g - acc))
    if omega is None or tensor is None:
        return Wrench(force, vec(0, 0, 0), com)
    assert alpha is not None
    if R is None:
        Iw, Ia = tensor * omega, tensor * alpha
    else:
        Iw, Ia = R * (tensor * (R.T * omega)), R * (tensor * (R.T * alpha))
    Iw = n.v(f"H{name}", Iw)
    moment = n.v(f"M{name}", -(Ia + cross(omega, Iw)))
    return Wrench(force, moment, com)


@dataclass(frozen=True)
class UJoint:
    """A U joint's state: coordinates ``(ua, ub)``, rates, accelerations, its current axes
    ``e1`` (in the earlier body) and ``e2`` (in the later), the later body's rotation relative
    to the earlier in world axes ``R_rel_world`` and the relative angular velocity and
    acceleration parts."""

    ua: sp.Expr
    ub: sp.Expr
    e1: Vec
    e2: Vec
    rotation: sp.Matrix  # Rot(u1, a) Rot(u2, b), in the earlier body's axes (world's at home)
    omega: Vec  # relative angular velocity, world
    alpha: Vec  # relative angular acceleration (the part not from the earlier body's turning)


def u_joint(
    n: Namer,
    u1: Vec,
    u2: Vec,
    home: Vec,
    u: Vec,
    du: Vec,
    ddu: Vec,
    earlier: sp.Matrix | None = None,
    w1: Vec | None = None,
    al1: Vec | None = None,
) -> UJoint:
    """The U joint whose later body carries the unit direction ``home`` (at home) now at ``u``
    (world), with time derivatives ``du``, ``ddu``; ``earlier``: the earlier body's rotation
    (None: the base), ``w1``, ``al1`` its angular velocity and acceleration.

    In the frame ``(e1, e2, e3 = e1 x e2)`` of the home axes, ``home = (p1, 0, p3)`` (the later
    body's line is perpendicular to its own axis ``e2``) and the earlier body's view of ``u`` is
    ``(v1, v2, v3)``: ``Rot(e1, a) Rot(e2, b) home = v`` gives ``b = atan2(p3, p1) -
    atan2(w3, v1)`` with ``w3 = sign(p3) sqrt(v2^2 + v3^2)`` and ``a = atan2(-v2 w3, v3 w3)``.
    The rates follow from ``du = (da E1 + db E2) x u`` (``E1``, ``E2`` the current axes):
    ``db = du_rel . E1 / (u . N)``, ``da = -du_rel . E2 / (u . N)``, ``N = E1 x E2``.
    """
    e3 = cross(u1, u2)
    p1, p3 = n.s("up1", dot(u1, home)), n.s("up3", dot(e3, home))
    s3 = n.s("us3", p3 / sp.Abs(p3))
    if earlier is None:
        E1, E2h, E3 = u1, u2, e3
    else:
        E1, E2h, E3 = n.v("E1", earlier * u1), n.v("E2h", earlier * u2), n.v("E3", earlier * e3)
    v1, v2, v3 = n.s("v1", dot(E1, u)), n.s("v2", dot(E2h, u)), n.s("v3", dot(E3, u))
    w3abs = n.s("w3", sp.sqrt(v2**2 + v3**2))
    ca, sa = n.s("cua", v3 / w3abs), n.s("sua", -v2 / w3abs)  # cos a, sin a (s3^2 = 1)
    ca, sa = n.s("cuas", ca * s3), n.s("suas", sa * s3)
    w3 = n.s("w3s", s3 * w3abs)
    pn = n.s("upn", sp.sqrt(p1**2 + p3**2))
    cb = n.s("cub", (p1 * v1 + p3 * w3) / pn)
    sb = n.s("sub", (p3 * v1 - p1 * w3) / pn)
    ua = n.s("ua", sp.atan2(sa, ca))
    ub = n.s("ub", sp.atan2(sb, cb))
    rel = rotation(u1, ca, sa) * rotation(u2, cb, sb)  # earlier body's axes
    E2 = n.v("E2", (earlier * (rotation(u1, ca, sa) * u2)) if earlier is not None
             else rotation(u1, ca, sa) * u2)  # fmt: skip
    N = n.v("N", cross(E1, E2))
    un = n.s("un", dot(u, N))
    rel_du = du if w1 is None else n.v("dur", du - cross(w1, u))
    da = n.s("dua", -dot(rel_du, E2) / un)
    db = n.s("dub", dot(rel_du, E1) / un)
    omega_rel = da * E1 + db * E2
    w2 = omega_rel if w1 is None else w1 + omega_rel
    w2 = n.v("wu", w2)
    # d/dt of da E1 + db E2 without dda, ddb: E1' = w1 x E1, E2' = (w1 + da E1) x E2
    w1_ = w1 if w1 is not None else vec(0, 0, 0)
    al1_ = al1 if al1 is not None else vec(0, 0, 0)
    known = al1_ + da * cross(w1_, E1) + db * cross(w1_ + da * E1, E2)
    known = n.v("alk", known)
    rr = n.v("rr", ddu - cross(w2, du) - cross(known, u))
    dda = n.s("ddua", -dot(rr, E2) / un)
    ddb = n.s("ddub", dot(rr, E1) / un)
    alpha = n.v("alu", known + dda * E1 + ddb * E2)
    return UJoint(ua, ub, E1, E2, rel, w2, alpha)
