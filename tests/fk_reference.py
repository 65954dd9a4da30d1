"""Forward kinematics of the 3-RPR robot, numerically: every assembly mode, and the tracked one.

A prototype for the runtime and for C99, with NumPy (and ``math``) only. Every routine works on
one sample with a fixed number of scalars, fixed loop bounds and no allocation that C would need
(``numpy.roots`` in :func:`sextic_angles_by_roots` is the one exception, for the Python runtime
only; :func:`sextic_angles_by_sampling` is its C counterpart). The closed forms mirror the
symbolic ones of ``control.py`` (``assembly_modes_revolute``, ``sextic_coefficients``,
``pose_from_angle``), which the tests compare with these.

Conventions (conventions.md): pose ``q = (x, y, phi)``; actuator coordinates ``qa`` are
``phi10_A..C`` (rad, revolute actuation) or ``lambda21_A..C`` (m, prismatic), measured from the
central configuration; leg ``i`` has base pivot ``A1_i`` (world), platform joint ``p_i``
(platform frame), ``A3_i = G + R(phi) p_i``, leg angle ``theta_i = alpha_i + phi10_i`` and length
``|A1A3| = l0 + l2 + lambda21_i``. Distances between poses are measured in ``(x, y, rho*phi)``,
``rho`` the platform's RMS joint radius.

The tracked forward kinematics (:func:`tracked_forward_kinematics`) is damped Newton on the
closure ``qa(q) = qa_measured`` from a reference pose, with the actuator Jacobian ``J = d qa/dq``
and each step corrected to third order (Chebyshev) by the closure's second derivative along it;
when it does not converge, or lands in another aspect (``det J`` changed sign), it falls back to
every assembly mode and picks the one nearest the reference.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

LEGS: tuple[str, ...] = ("A", "B", "C")
ACTUATIONS: tuple[str, ...] = ("revolute", "prismatic")
MAX_MODES: dict[str, int] = {"revolute": 2, "prismatic": 6}
#: A leg shorter than this times the platform's RMS radius has no length (not a mode).
LENGTH_TOL = 1e-9
#: Revolute direct kinematics: all legs parallel (``|k|``) or ``|(A, B)| / (|k| rho)`` below this
#: is degenerate (no isolated mode); see ``direct_kinematics.assembly_modes_revolute``.
DEGENERACY_TOL = 1e-10
#: Sampled sextic: an extremum within this fraction of the polynomial's scale of zero is a root.
TOUCH_TOL = 1e-9
#: Back substitution: ``|D| <= PARALLEL_TOL |w_B| |w_C|`` counts as parallel equations.
PARALLEL_TOL = 1e-6

Vec2 = tuple[float, float]
Pose = tuple[float, float, float]


@dataclass(frozen=True)
class Geometry:
    """What forward kinematics needs of a model (SI units, rad)."""

    base: tuple[Vec2, Vec2, Vec2]  # A1_i, world frame
    platform: tuple[Vec2, Vec2, Vec2]  # p_i = A3_i - G, platform frame
    alpha: tuple[float, float, float]  # leg angles in the central configuration
    offset: float  # l0 + l2: leg length |A1A3| at lambda21 = 0
    rho: float  # RMS distance of the platform joints from G
    l0: float = math.nan  # |A1A2| at lambda21 = 0: the scale of reach

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Geometry:
        """From model parameters named as in interfaces.md (``xA1``, ``yA3``, ``alpha_A``...)."""

        def point(leg: str, k: int) -> Vec2:
            return (float(params[f"x{leg}{k}"]), float(params[f"y{leg}{k}"]))

        base = (point("A", 1), point("B", 1), point("C", 1))
        platform = (point("A", 3), point("B", 3), point("C", 3))
        alpha = (float(params["alpha_A"]), float(params["alpha_B"]), float(params["alpha_C"]))
        rho = math.sqrt(sum(px * px + py * py for px, py in platform) / 3.0)
        return cls(
            base,
            platform,
            alpha,
            float(params["l0"]) + float(params["l2"]),
            rho,
            float(params["l0"]),
        )


def wrap(angle: float) -> float:
    """``angle`` wrapped into ``(-pi, pi]``."""
    out = math.remainder(angle, 2 * math.pi)
    return math.pi if out == -math.pi else out


def unwrap_near(angle: float, reference: float) -> float:
    """``angle + 2 pi k`` nearest ``reference``."""
    return angle + 2 * math.pi * round((reference - angle) / (2 * math.pi))


def distance(geom: Geometry, a: Sequence[float], b: Sequence[float]) -> float:
    """Distance of two poses in ``(x, y, rho*phi)`` (m); ``phi`` is not wrapped."""
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (geom.rho * (a[2] - b[2])) ** 2)


def _legs(geom: Geometry, q: Sequence[float]) -> tuple[list[Vec2], list[Vec2]]:
    """Per leg ``d = A3 - A1`` and ``s = A3 - G`` (world), eq. (5)."""
    c, s = math.cos(q[2]), math.sin(q[2])
    d, r = [], []
    for (ax, ay), (px, py) in zip(geom.base, geom.platform, strict=True):
        sx, sy = c * px - s * py, s * px + c * py
        r.append((sx, sy))
        d.append((q[0] + sx - ax, q[1] + sy - ay))
    return d, r


def actuator_coordinates(geom: Geometry, actuation: str, q: Sequence[float]) -> list[float]:
    """``qa(q)``: inverse kinematics (eq. 5), ``phi10`` in ``(-pi, pi]`` or ``lambda21``."""
    d, _ = _legs(geom, q)
    if actuation == "revolute":
        return [wrap(math.atan2(dy, dx) - a) for (dx, dy), a in zip(d, geom.alpha, strict=True)]
    return [math.hypot(dx, dy) - geom.offset for dx, dy in d]


def _residual(geom: Geometry, actuation: str, qa: Sequence[float], q: Sequence[float]) -> list:
    """``qa(q) - qa`` (angles wrapped), the closure that Newton drives to zero."""
    qa_q = actuator_coordinates(geom, actuation, q)
    if actuation == "revolute":
        return [wrap(a - b) for a, b in zip(qa_q, qa, strict=True)]
    return [a - b for a, b in zip(qa_q, qa, strict=True)]


def actuator_jacobian(geom: Geometry, actuation: str, q: Sequence[float]) -> list[list[float]]:
    """``J = d qa / d q`` (rows per leg), eq. (6).

    Rows ``(n_x, n_y, e . s) / L`` (revolute) or ``(e_x, e_y, s_x e_y - s_y e_x)`` (prismatic).
    """
    d, r = _legs(geom, q)
    rows = []
    for (dx, dy), (sx, sy) in zip(d, r, strict=True):
        length = math.hypot(dx, dy)
        ex, ey = dx / length, dy / length
        if actuation == "revolute":
            rows.append([-ey / length, ex / length, (ex * sx + ey * sy) / length])
        else:
            rows.append([ex, ey, sx * ey - sy * ex])
    return rows


def actuator_curvature(
    geom: Geometry, actuation: str, q: Sequence[float], dq: Sequence[float]
) -> list[float]:
    """``H[dq, dq]``: the second derivative of ``qa(q + s dq)`` in ``s`` at 0, per leg.

    Along ``dq`` the leg vector ``d`` moves at ``v = (dx, dy) + dphi (-s_y, s_x)`` with
    acceleration ``a = -dphi^2 s``; then ``theta'' = (d x a) / L^2 - 2 (d . v)(d x v) / L^4``
    (revolute) or ``L'' = (v . v + d . a) / L - (d . v)^2 / L^3`` (prismatic).
    """
    d, r = _legs(geom, q)
    out = []
    for (dx, dy), (sx, sy) in zip(d, r, strict=True):
        vx, vy = dq[0] - dq[2] * sy, dq[1] + dq[2] * sx
        ax, ay = -(dq[2] ** 2) * sx, -(dq[2] ** 2) * sy
        l2 = dx * dx + dy * dy
        dv = dx * vx + dy * vy
        if actuation == "revolute":
            out.append((dx * ay - dy * ax) / l2 - 2.0 * dv * (dx * vy - dy * vx) / l2**2)
        else:
            length = math.sqrt(l2)
            out.append((vx * vx + vy * vy + dx * ax + dy * ay) / length - dv**2 / length**3)
    return out


def det3(m: Sequence[Sequence[float]]) -> float:
    return (
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    )


def solve3(m: Sequence[Sequence[float]], b: Sequence[float]) -> tuple[list[float], float]:
    """``m x = b`` by cofactors (Cramer's rule); returns ``(x, det m)``, x NaN when det is 0."""
    det = det3(m)
    if det == 0.0:
        return [math.nan] * 3, det
    x = []
    for k in range(3):
        mk = [[b[i] if j == k else m[i][j] for j in range(3)] for i in range(3)]
        x.append(det3(mk) / det)
    return x, det


@dataclass(frozen=True)
class NewtonResult:
    """Outcome of :func:`closure_newton`."""

    q: Pose
    converged: bool
    iterations: int  # Newton steps taken (Jacobian solves)
    det: float  # det J at the last linearization (its sign is the aspect)


def closure_newton(
    geom: Geometry,
    actuation: str,
    qa: Sequence[float],
    q0: Sequence[float],
    *,
    max_iter: int = 12,
    tol: float = 1e-12,
    max_step: float | None = None,
    max_halvings: int = 12,
) -> NewtonResult:
    """Damped Newton on ``qa(q) = qa``, from ``q0``.

    Each step solves ``J dq = -(qa(q) - qa)`` (3 x 3, cofactors), adds the Chebyshev correction
    ``e``, ``J e = -H[dq, dq] / 2`` (:func:`actuator_curvature`), when ``|e| <= |dq| / 2`` in the
    pose metric, limits ``|dq|`` in the pose metric to ``max_step`` (default: the platform's RMS
    radius ``rho``) and halves it until the largest residual drops by the Armijo factor
    ``1 - t/2`` (at most ``max_halvings`` times).
    Converged when the largest residual is at most ``tol`` (rad or m). Fails (``converged``
    False) on a singular ``J`` (``|det J|`` below 1e-14 of the product of its row norms), a
    failed line search, or ``max_iter`` steps.
    """
    limit = geom.rho if max_step is None else max_step
    q = (float(q0[0]), float(q0[1]), float(q0[2]))
    r = _residual(geom, actuation, qa, q)
    norm = max(abs(v) for v in r)
    det = math.nan
    for iteration in range(max_iter + 1):
        if not math.isfinite(norm):
            return NewtonResult(q, False, iteration, det)
        if norm <= tol:
            return NewtonResult(q, True, iteration, det)
        if iteration == max_iter:
            break
        J = actuator_jacobian(geom, actuation, q)
        dq, det = solve3(J, [-v for v in r])
        # |det J| against Hadamard's bound, the product of the row norms: scale-free.
        bound = math.prod(math.sqrt(sum(v * v for v in row)) for row in J)
        if not abs(det) > 1e-14 * bound:
            return NewtonResult(q, False, iteration, det)
        h = actuator_curvature(geom, actuation, q, dq)
        e, _ = solve3(J, [-0.5 * v for v in h])
        if math.hypot(e[0], e[1], geom.rho * e[2]) <= 0.5 * math.hypot(
            dq[0], dq[1], geom.rho * dq[2]
        ):
            dq = [a + b for a, b in zip(dq, e, strict=True)]
        size = math.sqrt(dq[0] ** 2 + dq[1] ** 2 + (geom.rho * dq[2]) ** 2)
        t = min(1.0, limit / size) if size > 0 else 1.0
        for _ in range(max_halvings):
            trial = (q[0] + t * dq[0], q[1] + t * dq[1], q[2] + t * dq[2])
            r_trial = _residual(geom, actuation, qa, trial)
            n_trial = max(abs(v) for v in r_trial)
            if n_trial < (1.0 - 0.5 * t) * norm or n_trial <= tol:
                break
            t *= 0.5
        else:
            return NewtonResult(q, False, iteration + 1, det)
        q, r, norm = trial, r_trial, n_trial
    return NewtonResult(q, False, max_iter, det)


# ----------------------------------------------------------------------------------------------
# Every assembly mode: revolute actuation, closed form.


def leg_lengths_along_axis(geom: Geometry, qa: Sequence[float], q: Sequence[float]) -> list:
    """``(A3 - A1) . e_i`` with ``e_i`` the leg axis given by the revolute actuators."""
    d, _ = _legs(geom, q)
    return [
        dx * math.cos(a + v) + dy * math.sin(a + v)
        for (dx, dy), a, v in zip(d, geom.alpha, qa, strict=True)
    ]


def revolute_modes(geom: Geometry, qa: Sequence[float]) -> list[Pose]:
    """Every assembly mode of revolute actuation (0, 1 or 2), closed form.

    ``A cos(phi) + B sin(phi) + C = 0`` (see ``direct_kinematics.assembly_modes_revolute``),
    then ``G`` from the normal equations of the three line conditions. A mode needs
    ``A^2 + B^2 >= C^2``,
    ``|(A, B)| > DEGENERACY_TOL |k| rho``, ``|k| > DEGENERACY_TOL`` and every leg length
    ``(A3 - A1) . e_i`` above ``LENGTH_TOL * rho`` (round-off of a zero length is not a mode).
    Sorted by phi, phi in ``(-pi, pi]``; two coincident modes (a singularity) are reported once.
    """
    c, s, u, v, w = [], [], [], [], []
    for (ax, ay), (px, py), alpha, value in zip(
        geom.base, geom.platform, geom.alpha, qa, strict=True
    ):
        ci, si = math.cos(alpha + value), math.sin(alpha + value)
        c.append(ci)
        s.append(si)
        u.append(-si * px + ci * py)  # n . p
        v.append(ci * px + si * py)  # e . p
        w.append(-si * ax + ci * ay)  # n . A1
    k = [s[(i + 2) % 3] * c[(i + 1) % 3] - s[(i + 1) % 3] * c[(i + 2) % 3] for i in range(3)]
    A = sum(k[i] * u[i] for i in range(3))
    B = sum(k[i] * v[i] for i in range(3))
    C = -sum(k[i] * w[i] for i in range(3))
    ab2 = A * A + B * B
    disc = ab2 - C * C
    ksq = k[0] ** 2 + k[1] ** 2 + k[2] ** 2
    tol2 = DEGENERACY_TOL**2
    if not (disc >= 0 and ab2 > tol2 * ksq * geom.rho**2 and ksq > tol2):
        return []
    root = math.sqrt(disc)
    s_ss = sum(si * si for si in s)
    s_cc = sum(ci * ci for ci in c)
    s_sc = sum(-si * ci for si, ci in zip(s, c, strict=True))
    modes: list[Pose] = []
    for sign in (1.0, -1.0) if root > 0 else (1.0,):
        cos_phi = (-A * C - sign * B * root) / ab2
        sin_phi = (-B * C + sign * A * root) / ab2
        r = [w[i] - u[i] * cos_phi - v[i] * sin_phi for i in range(3)]
        b1 = sum(-s[i] * r[i] for i in range(3))
        b2 = sum(c[i] * r[i] for i in range(3))
        x = (s_cc * b1 - s_sc * b2) / ksq
        y = (s_ss * b2 - s_sc * b1) / ksq
        pose = (x, y, wrap(math.atan2(sin_phi, cos_phi)))
        if min(leg_lengths_along_axis(geom, qa, pose)) > LENGTH_TOL * geom.rho:
            modes.append(pose)
    return sorted(modes, key=lambda m: m[2])


# ----------------------------------------------------------------------------------------------
# Every assembly mode: prismatic actuation, the sextic in t = tan(phi/2).


def _differences(geom: Geometry) -> tuple[list[Vec2], list[Vec2]]:
    """``P_i = p_i - p_A`` and ``Q_i = A1_i - A1_A`` for i = B, C."""
    (pax, pay), (aax, aay) = geom.platform[0], geom.base[0]
    P = [(px - pax, py - pay) for px, py in geom.platform[1:]]
    Q = [(ax - aax, ay - aay) for ax, ay in geom.base[1:]]
    return P, Q


def _harmonics(geom: Geometry, qa: Sequence[float]) -> dict[str, list[tuple[float, ...]]]:
    """``(f0, fc, fs)`` of ``rho_B, rho_C``, ``|w_B|^2, |w_C|^2``, ``w_B.w_C``, ``D``."""
    lengths = [geom.offset + v for v in qa]
    P, Q = _differences(geom)

    def dot(a: Vec2, b: Vec2) -> float:
        return a[0] * b[0] + a[1] * b[1]

    def cross(a: Vec2, b: Vec2) -> float:
        return a[0] * b[1] - a[1] * b[0]

    rho: list[tuple[float, ...]] = []
    wsq: list[tuple[float, ...]] = []
    for i in range(2):
        qp, pq = dot(Q[i], P[i]), cross(P[i], Q[i])
        norms = dot(P[i], P[i]) + dot(Q[i], Q[i])
        rho.append(((lengths[i + 1] ** 2 - lengths[0] ** 2 - norms) / 2, qp, pq))
        wsq.append((norms, -2 * qp, -2 * pq))
    (Pb, Pc), (Qb, Qc) = P, Q
    wbc = (
        dot(Pb, Pc) + dot(Qb, Qc),
        -(dot(Qb, Pc) + dot(Qc, Pb)),
        -(cross(Pc, Qb) + cross(Pb, Qc)),
    )
    det = (cross(Pb, Pc) + cross(Qb, Qc), cross(Pc, Qb) - cross(Pb, Qc), dot(Pb, Qc) - dot(Pc, Qb))
    return {"rho": rho, "wsq": wsq, "wbc": [wbc], "det": [det]}


def _half(f: tuple[float, ...]) -> list[float]:
    return [f[0] + f[1], 2 * f[2], f[0] - f[1]]


def _mul(a: Sequence[float], b: Sequence[float]) -> list[float]:
    out = [0.0] * (len(a) + len(b) - 1)
    for i, ai in enumerate(a):
        for j, bj in enumerate(b):
            out[i + j] += ai * bj
    return out


def sextic_coefficients(geom: Geometry, qa: Sequence[float]) -> list[float]:
    """``a0..a6`` (ascending) of the sextic in ``t = tan(phi/2)``, as
    ``direct_kinematics.sextic_coefficients`` (m^6)."""
    h = _harmonics(geom, qa)
    rb, rc = _half(h["rho"][0]), _half(h["rho"][1])
    wbb, wcc = _half(h["wsq"][0]), _half(h["wsq"][1])
    wbc, det = _half(h["wbc"][0]), _half(h["det"][0])
    left = [x - y for x, y in zip(_mul(rc, wbb), _mul(rb, wbc), strict=True)]
    right = [x - y for x, y in zip(_mul(rb, wcc), _mul(rc, wbc), strict=True)]
    main = [x + y for x, y in zip(_mul(rc, left), _mul(rb, right), strict=True)]
    det_term = _mul(_mul(det, det), [1.0, 0.0, 1.0])
    la2 = (geom.offset + qa[0]) ** 2
    return [main[j] - la2 * det_term[j] for j in range(7)]


def pose_candidates(geom: Geometry, qa: Sequence[float], phi: float) -> list[Pose]:
    """Poses with orientation ``phi`` that close legs B, C relative to leg A (back substitution).

    ``u = (rho_C w_B^perp - rho_B w_C^perp) / D`` (``direct_kinematics.pose_from_angle``). Where
    ``|D| <= 1e-9 |w_B| |w_C|`` the two linear equations for ``u`` are (nearly) parallel: then
    the line ``u . w = rho`` of the longer ``w`` is intersected with the circle ``|u| = L_A``
    (0, 1 or 2 candidates); when both ``w`` vanish (``<= 1e-12 rho``) there is no isolated pose.
    """
    c, s = math.cos(phi), math.sin(phi)
    P, Q = _differences(geom)
    h = _harmonics(geom, qa)
    w = [
        (c * p[0] - s * p[1] - q_[0], s * p[0] + c * p[1] - q_[1])
        for p, q_ in zip(P, Q, strict=True)
    ]
    rho = [f[0] + f[1] * c + f[2] * s for f in h["rho"]]
    det = w[0][0] * w[1][1] - w[0][1] * w[1][0]
    norm = [math.hypot(*wi) for wi in w]
    la = geom.offset + qa[0]
    us: list[Vec2] = []
    tiny = 1e-12 * geom.rho
    if min(norm) > tiny and abs(det) > PARALLEL_TOL * norm[0] * norm[1]:
        us.append(
            (
                (-rho[1] * w[0][1] + rho[0] * w[1][1]) / det,
                (rho[1] * w[0][0] - rho[0] * w[1][0]) / det,
            )
        )
    else:
        i = 0 if norm[0] >= norm[1] else 1
        if norm[i] <= tiny:
            return []
        ex, ey = w[i][0] / norm[i], w[i][1] / norm[i]
        along = rho[i] / norm[i]
        h2 = la * la - along * along
        if h2 < 0:
            return []
        across = math.sqrt(h2)
        us = [
            (along * ex - sign * across * ey, along * ey + sign * across * ex) for sign in (1, -1)
        ]
    (pax, pay), (aax, aay) = geom.platform[0], geom.base[0]
    return [(aax + ux - (c * pax - s * pay), aay + uy - (s * pax + c * pay), phi) for ux, uy in us]


def _horner(a: Sequence[float], x: float) -> float:
    value = 0.0
    for coeff in reversed(a):
        value = value * x + coeff
    return value


def _bisect(poly: Sequence[float], lo: float, hi: float) -> float:
    """A root of ``poly`` in ``[lo, hi]``, where its sign changes, by 60 bisections."""
    vlo = _horner(poly, lo)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        vm = _horner(poly, mid)
        if vm == 0.0:
            return mid
        if (vm < 0.0) == (vlo < 0.0):
            lo, vlo = mid, vm
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _cell_roots(poly: Sequence[float], slope: Sequence[float], x0: float, x1: float) -> list:
    """Roots of ``poly`` in the cell ``(x0, x1]``: one per sign change; and where the cell holds
    an extremum (a sign change of ``slope``), two if ``poly`` dips through zero there, or the
    extremum itself if it touches zero to round-off (a double root: two modes with one
    orientation, see :func:`pose_candidates`)."""
    v0, v1 = _horner(poly, x0), _horner(poly, x1)
    if v1 == 0.0:
        return [x1]
    if v0 * v1 < 0.0:
        return [_bisect(poly, x0, x1)]
    if v0 != 0.0 and _horner(slope, x0) * _horner(slope, x1) < 0.0:
        xm = _bisect(slope, x0, x1)
        vm = _horner(poly, xm)
        if vm * v0 < 0.0:
            return [_bisect(poly, x0, xm), _bisect(poly, xm, x1)]
        size = sum(abs(c) * abs(xm) ** k for k, c in enumerate(poly))
        if abs(vm) <= TOUCH_TOL * size:
            return [xm]
    return []


def sextic_angles_by_sampling(a: Sequence[float], samples: int = 256) -> list[float]:
    """Real roots of the sextic as angles ``phi`` in ``(-pi, pi]``, with no polynomial solver.

    The polynomial is sampled at ``samples + 1`` points of ``t`` in ``[-1, 1]`` (``|phi| <= pi/2``)
    and, as ``u^6 p(1/u)`` (coefficients reversed), of ``u = 1/t`` in ``[-1, 1]`` (the rest,
    ``phi = pi`` at ``u = 0``): no trigonometric call per sample and no trouble at ``t = inf``.
    Each sign change is refined by bisection; a cell without one but with an extremum (sign
    change of the derivative) is split at the extremum, so that two close roots are found too.
    Still missed: a double root that round-off keeps from touching zero (a tangency, i.e. a
    singular pose) and three or more roots in one cell (cells are at most ``4/samples`` rad
    wide). At most 6 roots, a fixed-size output for C.
    """
    roots: list[float] = []
    for poly, inverse in ((list(a), False), (list(a)[::-1], True)):
        slope = [k * poly[k] for k in range(1, len(poly))]
        cells = [-1.0] if _horner(poly, -1.0) == 0.0 else []
        for j in range(samples):
            x0, x1 = -1.0 + 2.0 * j / samples, -1.0 + 2.0 * (j + 1) / samples
            cells.extend(_cell_roots(poly, slope, x0, x1))
        # t = tan(phi/2) on the first pass; u = 1/t = cot(phi/2) on the second.
        roots.extend(wrap(2 * math.atan2(1.0, x)) if inverse else 2 * math.atan(x) for x in cells)
    unique: list[float] = []
    for phi in sorted(roots):
        if not unique or abs(phi - unique[-1]) > 1e-9:
            unique.append(phi)
    if len(unique) > 1 and abs(unique[0] + 2 * math.pi - unique[-1]) <= 1e-9:
        unique.pop(0)
    return unique[:6]


def sextic_angles_by_roots(a: Sequence[float], imag_tol: float = 1e-6) -> list[float]:
    """Real roots of the sextic as angles, by ``numpy.roots`` (Python runtime only).

    Roots with ``|Im t| <= imag_tol (1 + |t|)`` count as real (Newton decides later). When the
    leading coefficient vanishes relative to the others, ``phi = pi`` (``t = inf``) is added.
    """
    a = [float(v) for v in a]
    scale = max(abs(v) for v in a)
    if scale == 0.0 or not math.isfinite(scale):
        return []
    angles = []
    if abs(a[6]) <= 1e-12 * scale:
        angles.append(math.pi)
    for t in np.roots(a[::-1]):
        if abs(t.imag) <= imag_tol * (1 + abs(t)):
            angles.append(2 * math.atan(t.real))
    return sorted(angles)


def prismatic_modes(
    geom: Geometry,
    qa: Sequence[float],
    coefficients: Sequence[float] | None = None,
    method: str = "roots",
    samples: int = 256,
) -> list[Pose]:
    """Every assembly mode of prismatic actuation (at most 6), sorted by phi in ``(-pi, pi]``.

    Roots of the sextic (``method="roots"``: :func:`sextic_angles_by_roots`; ``"sampling"``:
    :func:`sextic_angles_by_sampling`), back substitution (:func:`pose_candidates`), then each
    candidate polished by :func:`closure_newton` on the original equations; candidates that do
    not converge are spurious (complex roots, a vanishing ``D``) and dropped, duplicates merged.
    No mode when a leg length ``l0 + l2 + qa_i`` is not above ``LENGTH_TOL * rho``.
    """
    if min(geom.offset + v for v in qa) <= LENGTH_TOL * geom.rho:
        return []
    if coefficients is None:
        coefficients = sextic_coefficients(geom, qa)
    if method == "roots":
        angles = sextic_angles_by_roots(coefficients)
    elif method == "sampling":
        angles = sextic_angles_by_sampling(coefficients, samples)
    else:
        raise ValueError(f"method must be 'roots' or 'sampling', got {method!r}")
    modes: list[Pose] = []
    for phi in angles:
        for candidate in pose_candidates(geom, qa, phi):
            result = closure_newton(geom, "prismatic", qa, candidate, max_iter=20)
            if result.converged:
                _add_mode(geom, modes, result.q)
    return sorted(modes, key=lambda m: m[2])


def _add_mode(geom: Geometry, modes: list[Pose], q: Pose) -> None:
    q = (q[0], q[1], wrap(q[2]))
    for m in modes:
        if distance(geom, m, (q[0], q[1], unwrap_near(q[2], m[2]))) <= 1e-9 * (1 + geom.rho):
            return
    modes.append(q)


#: A pose whose reach is below this is refused (the generated code's MIN_REACH).
MIN_REACH = 1e-9


def reach(geom: Geometry, q: Sequence[float]) -> float:
    """``min (l0 + lambda21) / l0`` over the legs: 1 central, <= 0 with a piston joint on or
    behind its base pivot (a pose the generated code refuses)."""
    d, _ = _legs(geom, q)
    l2 = geom.offset - geom.l0
    return min((math.hypot(*di) - l2) / geom.l0 for di in d)


def assembly_modes(geom: Geometry, actuation: str, qa: Sequence[float], **kw) -> list[Pose]:
    """Every assembly mode for ``qa`` (closed form or sextic): at most 2 or 6 poses, each one
    the generated code evaluates (reach above :data:`MIN_REACH`)."""
    modes = revolute_modes(geom, qa) if actuation == "revolute" else prismatic_modes(geom, qa, **kw)
    return [m for m in modes if reach(geom, m) > MIN_REACH]


# ----------------------------------------------------------------------------------------------
# Tracked forward kinematics.


@dataclass(frozen=True)
class Tracked:
    """Result of :func:`tracked_forward_kinematics`: ``q`` (NaN when no mode), how it was found
    (``"newton"``, ``"fallback"`` or ``"none"``), and the Newton steps taken."""

    q: Pose
    status: str
    iterations: int


def tracked_forward_kinematics(
    geom: Geometry,
    actuation: str,
    qa: Sequence[float],
    q_near: Sequence[float],
    *,
    max_iter: int = 8,
    tol: float = 1e-12,
    fallback: bool = True,
    samples: int = 256,
) -> Tracked:
    """The assembly mode for ``qa`` nearest ``q_near``: damped Newton, else every mode.

    1. :func:`closure_newton` from ``q_near`` (at most ``max_iter`` steps, largest residual
       ``<= tol``, step limited to ``rho`` in the pose metric, backtracking line search).
    2. Accepted when it converged, the pose is evaluable (reach above :data:`MIN_REACH`, as
       every mode of :func:`assembly_modes`), and ``det J`` at the solution
       has the sign it has at ``q_near`` (same aspect: Newton did not jump across a parallel
       singularity into another mode).
    3. Otherwise (fallback): every mode, by the closed form (revolute) or by sampling the sextic
       (prismatic, :func:`sextic_angles_by_sampling`, no polynomial solver), each with ``phi``
       unwrapped next to ``q_near[2]``; the nearest in ``(x, y, rho*phi)`` wins. No mode: NaN.

    ``phi`` of the result is unwrapped next to ``q_near[2]``.

    Which reference: the constant-velocity prediction ``2 q[k-1] - q[k-2]`` of the two previous
    solutions is better than ``q[k-1]``: fewer Newton steps, and it is the only one that follows
    the robot through a parallel singularity. There the two modes merge and part again, and the
    mode nearest the previous pose (and of its aspect) is the one that turns back, while the
    robot goes on into the other aspect, which the prediction is in.
    """
    near = (float(q_near[0]), float(q_near[1]), float(q_near[2]))
    result = closure_newton(geom, actuation, qa, near, max_iter=max_iter, tol=tol)
    if result.converged:
        det_near = det3(actuator_jacobian(geom, actuation, near))
        det_here = det3(actuator_jacobian(geom, actuation, result.q))
        # a mode is a pose the generated code evaluates, whichever path finds it (as in
        # assembly_modes): reach above MIN_REACH, so every leg is longer than l2 > 0
        evaluable = reach(geom, result.q) > MIN_REACH
        if evaluable and det_near * det_here > 0:
            return Tracked(result.q, "newton", result.iterations)
    if not fallback:
        return Tracked((math.nan, math.nan, math.nan), "none", result.iterations)
    modes = assembly_modes(
        geom,
        actuation,
        qa,
        **({} if actuation == "revolute" else {"method": "sampling", "samples": samples}),
    )
    best: Pose | None = None
    for m in modes:
        m = (m[0], m[1], unwrap_near(m[2], near[2]))
        if best is None or distance(geom, m, near) < distance(geom, best, near):
            best = m
    if best is None:
        return Tracked((math.nan, math.nan, math.nan), "none", result.iterations)
    return Tracked(best, "fallback", result.iterations)


# ----------------------------------------------------------------------------------------------
# Samples shared by the forward-kinematics tests.


def evaluable(geom: Geometry, poses: np.ndarray) -> np.ndarray:
    """The rows of ``poses`` the generated code evaluates (:func:`reach` above MIN_REACH)."""
    return np.array([p for p in poses if reach(geom, p) > MIN_REACH]).reshape(-1, 3)


def random_poses(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` poses near the central configuration: |x|, |y| <= 5 cm, |phi| <= 0.6 rad."""
    return np.stack(
        [rng.uniform(-0.05, 0.05, n), rng.uniform(-0.05, 0.05, n), rng.uniform(-0.6, 0.6, n)],
        axis=1,
    )


def robots(rng: np.random.Generator, n: int) -> list[dict]:
    """The paper's robot, then ``n - 1`` random ones (``newton_euler.random_robot``)."""
    import newton_euler as ne

    return [ne.paper_params()] + [ne.random_robot(rng)["params"] for _ in range(n - 1)]
