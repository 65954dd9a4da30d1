"""The platform's motion from its pose coordinates, and the wrench its motion demands.

Hexapods: ``q = (x, y, z, a, b, c)``, ``R = Rz(c) Ry(b) Rx(a)``; the angular velocity is
``omega = da R ex + db Rz(c) ey + dc ez`` (the rates of the angles are not the angular
velocity). Deltas: ``q = (x, y, z)``, ``R = I``.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.spatial.structures import SpatialStructure
from rpr3gen_derive.spatial.vectors import Namer, Vec, cross, inertia, vec


def pose_symbols(structure: SpatialStructure) -> tuple[tuple[sp.Symbol, ...], ...]:
    """``(q, qd, qdd)``: the pose, its rates and accelerations, as symbols."""
    return tuple(
        tuple(sp.Symbol(f"{prefix}{n}", real=True) for n in structure.pose)
        for prefix in ("", "d", "dd")
    )


def param(name: str) -> sp.Symbol:
    return sp.Symbol(name, real=True)


@dataclass(frozen=True)
class PlatformMotion:
    """The platform's origin ``o`` and its derivatives, its rotation ``R`` (None: identity) and
    angular velocity and acceleration (None: zero)."""

    o: Vec
    vo: Vec
    ao: Vec
    R: sp.Matrix | None
    omega: Vec | None
    alpha: Vec | None
    #: ``omega = sum_j rates[j] axes[j]`` over the angles' rates (hexapods)
    axes: tuple[Vec, ...] = ()

    def point(self, n: Namer, name: str, p: Vec) -> tuple[Vec, Vec, Vec, Vec]:
        """A platform point at ``p`` at home: its offset from ``o``, position, velocity and
        acceleration (world)."""
        if self.R is None:
            r = p
            return r, n.v(name, self.o + r), self.vo, self.ao
        r = n.v(f"r{name}", self.R * p)
        w, al = self.omega, self.alpha
        assert w is not None
        assert al is not None
        v = n.v(f"v{name}", self.vo + cross(w, r))
        wr = cross(w, r)
        a = n.v(f"a{name}", self.ao + cross(al, r) + cross(w, wr))
        return r, n.v(name, self.o + r), v, a


def motion(prog: Program, structure: SpatialStructure) -> PlatformMotion:
    """The platform's motion (eq. 3's pose, its rates and accelerations)."""
    q, qd, qdd = pose_symbols(structure)
    n = Namer(prog, "", "platform motion")
    o, vo, ao = vec(*q[:3]), vec(*qd[:3]), vec(*qdd[:3])
    if structure.dof == 3:
        return PlatformMotion(o, vo, ao, None, None, None)
    a, b, c = q[3:]
    da, db, dc = qd[3:]
    dda, ddb, ddc = qdd[3:]
    sa, ca = n.s("sa", sp.sin(a)), n.s("ca", sp.cos(a))
    sb, cb = n.s("sb", sp.sin(b)), n.s("cb", sp.cos(b))
    sc, cc = n.s("sc", sp.sin(c)), n.s("cc", sp.cos(c))
    rz = sp.Matrix([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    ry = sp.Matrix([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rx = sp.Matrix([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    R = n.m("R", rz * ry * rx)
    col = vec(cc * cb, sc * cb, -sb)  # R ex
    dcol = vec(-sc * dc * cb - cc * sb * db, cc * dc * cb - sc * sb * db, -cb * db)
    ey = vec(-sc, cc, 0)  # Rz(c) ey
    dey = vec(-cc * dc, -sc * dc, 0)
    omega = n.v("w", da * col + db * ey + dc * vec(0, 0, 1))
    alpha = n.v("al", dda * col + ddb * ey + ddc * vec(0, 0, 1) + da * dcol + db * dey)
    return PlatformMotion(o, vo, ao, R, omega, alpha, (col, ey, vec(0, 0, 1)))


def demand(prog: Program, motion: PlatformMotion) -> tuple[Vec, Vec]:
    """``(F, M)``: the force and the moment about the platform's origin that the legs must
    exert on the platform for its motion, against gravity and the payload (Newton–Euler of
    the platform, the balance the virtual work of a platform displacement states)."""
    n = Namer(prog, "", "platform demand")
    m = param("m3")
    g = vec(param("gx"), param("gy"), param("gz"))
    f_ext = vec(param("fx"), param("fy"), param("fz"))
    m_ext = vec(param("mx"), param("my"), param("mz"))
    c = vec(param("c3x"), param("c3y"), param("c3z"))
    I3 = inertia(tuple(param(f"I3{e}") for e in ("xx", "yy", "zz", "xy", "xz", "yz")))
    rG, _, _, aG = motion.point(n, "G", c)
    inertial = n.v("FG", m * (aG - g))
    F = n.v("Fd", inertial - f_ext)
    M = cross(rG, inertial) - m_ext
    if motion.R is not None:
        R, w, al = motion.R, motion.omega, motion.alpha
        assert w is not None
        assert al is not None
        Iw = R * (I3 * (R.T * w))
        Ia = R * (I3 * (R.T * al))
        M = M + Ia + cross(w, n.v("IwG", Iw))
    return F, n.v("Md", M)
