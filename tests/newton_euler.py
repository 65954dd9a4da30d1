"""Independent Newton-Euler reference for the inverse dynamics of the 3-RPR planar robot.

Written only from ``docs/conventions.md`` (the physics contract), with NumPy alone: it
imports nothing from ``rpr3gen``, ``derive/`` or ``generated/``, so the tests that compare the
production code against it check the symbolic virtual-work derivation against plain mechanics.

Model (per leg L in A, B, C; world frame x0 horizontal, y0 up, z0 out of the plane):

- body 1, cylinder: turns about the base pivot ``A1``; COM at ``A1 + c1 e + c1_perp n``
  (``n`` = ``e`` turned by +90 deg); mass m1, inertia J1 about the COM.
- body 2, piston: slides along the leg axis ``e``; ``A2 = A1 + (l0 + lambda21) e``; COM at
  ``A2 + c2 e + c2_perp n``; turns with the cylinder; mass m2, inertia J2 about the COM.
- body 3, platform (shared): COM at G; joint ``A3 = G + R(phi) p``, ``|A2 A3| = l2``; mass m3,
  inertia J3 about G.

Unknown loads, each exerted by body k-1 on body k (body k-1 receives the opposite):

- at A1, base on cylinder: force ``f10`` (world x0, y0) and, when the revolute joint is actuated,
  the motor torque ``m10`` about +z0;
- at A2, cylinder on piston: force ``f21y n + f21z e`` (``f21z`` is unknown only when the prismatic
  joint is actuated) and a couple whose component along ``x2 = -z0`` is ``m21`` (so its component
  about +z0 is ``-m21``), moments taken about A2;
- at A3, piston on platform: force ``f32y n + f32z e``, no moment.

Seven bodies, three equations each, 21 unknowns; one dense 21 x 21 solve per sample.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

PARAM_NAMES: tuple[str, ...] = (
    "xA1",
    "yA1",
    "xB1",
    "yB1",
    "xC1",
    "yC1",
    "xA3",
    "yA3",
    "xB3",
    "yB3",
    "xC3",
    "yC3",
    "alpha_A",
    "alpha_B",
    "alpha_C",
    "l0",
    "l2",
    "c1",
    "c2",
    "m1",
    "m2",
    "m3",
    "J1",
    "J2",
    "J3",
    "gx",
    "gy",
    "fx",
    "fy",
    "mz",
    "c1_perp",
    "c2_perp",
)
FAMILIES = (
    "phi10",
    "lambda21",
    "phi32",
    "omega10",
    "v21",
    "omega32",
    "eps10",
    "gamma21",
    "eps32",
    "m10",
    "f10x",
    "f10y",
    "f21y",
    "f21z",
    "m21",
    "f32y",
    "f32z",
)
LEGS = ("A", "B", "C")
ACTUATIONS = ("revolute", "prismatic")

# Column of each unknown inside a leg's block of 7; "act" is m10 or f21z by actuation.
_F10X, _F10Y, _ACT, _F21Y, _M21, _F32Y, _F32Z = range(7)


def paper_params() -> dict[str, float]:
    """The default (paper) robot of conventions.md, computed from its table.

    Returns:
        Parameter name -> value (SI units, radians), keys exactly ``PARAM_NAMES``.
    """
    r = 0.3
    beta = math.pi / 6
    alphas = (math.pi / 2, -5 * math.pi / 6, -math.pi / 6)
    l0, l1, l2 = 0.1, 0.2, 0.2
    m1, m2, m3 = 3.0, 1.5, 5.0
    edge = r * math.sqrt(3.0)
    p: dict[str, float] = {}
    for leg, alpha in zip(LEGS, alphas, strict=True):
        px = r * math.sin(alpha + beta)
        py = -r * math.cos(alpha + beta)
        p[f"x{leg}3"] = px
        p[f"y{leg}3"] = py
        p[f"x{leg}1"] = px - (l0 + l2) * math.cos(alpha)
        p[f"y{leg}1"] = py - (l0 + l2) * math.sin(alpha)
        p[f"alpha_{leg}"] = alpha
    p.update(
        l0=l0,
        l2=l2,
        c1=l1 / 2,
        c2=l2 / 2,
        m1=m1,
        m2=m2,
        m3=m3,
        J1=m1 * l1**2 / 12,
        J2=m2 * l2**2 / 12,
        J3=m3 * edge**2 / 12,
        gx=0.0,
        gy=-9.81,
        fx=0.0,
        fy=0.0,
        mz=0.0,
        c1_perp=0.0,
        c2_perp=0.0,
    )
    return {name: float(p[name]) for name in PARAM_NAMES}


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z component of a x b for in-plane vectors stored in the last axis."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _perp(a: np.ndarray) -> np.ndarray:
    """a turned by +90 deg about z0 (z0 x a)."""
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


def _wrap(angle: np.ndarray) -> np.ndarray:
    """Wrap into (-pi, pi]."""
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def _as_motion(q, qd, qdd=None):
    q = np.atleast_2d(np.asarray(q, dtype=float))
    qd = np.atleast_2d(np.asarray(qd, dtype=float))
    if q.shape[-1] != 3 or qd.shape != q.shape:
        raise ValueError("q and qd must have shape (n, 3)")
    if qdd is None:
        return q, qd, None
    qdd = np.atleast_2d(np.asarray(qdd, dtype=float))
    if qdd.shape != q.shape:
        raise ValueError("qdd must have shape (n, 3)")
    return q, qd, qdd


def kinematics(params: Mapping[str, float], q, qd, qdd=None) -> dict:
    """Positions, velocities and accelerations of every body, from geometry alone.

    Args:
        params: model parameters (``PARAM_NAMES``).
        q, qd, qdd: arrays (n, 3) of (x, y, phi) of G and the platform angle, and derivatives;
            ``qdd`` may be None (then no accelerations are returned).

    Returns:
        ``{"platform": {...}, "A": {...}, "B": {...}, "C": {...}}``; vectors are (n, 2) world
        components, scalars (n,). Leg keys: A1, A2, A3, e, n, C1, C2 (COMs), length, theta (world
        leg angle), phi10, lambda21, phi32, omega10, v21, omega32, v1, v2 (COM velocities) and,
        with qdd, eps10, gamma21, eps32, a1, a2 (COM accelerations). Platform keys: G, phi, v, w,
        and with qdd a, eps.
    """
    q, qd, qdd = _as_motion(q, qd, qdd)
    G, phi = q[:, :2], q[:, 2]
    vG, w = qd[:, :2], qd[:, 2]
    c, s = np.cos(phi), np.sin(phi)
    out: dict = {"platform": {"G": G, "phi": phi, "v": vG, "w": w}}
    if qdd is not None:
        out["platform"].update(a=qdd[:, :2], eps=qdd[:, 2])
    l0, l2, c1, c2 = (params[k] for k in ("l0", "l2", "c1", "c2"))
    c1p, c2p = params["c1_perp"], params["c2_perp"]
    for leg in LEGS:
        A1 = np.array([params[f"x{leg}1"], params[f"y{leg}1"]])
        px, py = params[f"x{leg}3"], params[f"y{leg}3"]
        rho = np.stack([c * px - s * py, s * px + c * py], axis=-1)  # R(phi) p, G -> A3
        A3 = G + rho
        d = A3 - A1
        length = np.hypot(d[:, 0], d[:, 1])
        e = d / length[:, None]
        n = _perp(e)
        theta = np.arctan2(d[:, 1], d[:, 0])
        vA3 = vG + w[:, None] * _perp(rho)
        Ld = np.einsum("ij,ij->i", e, vA3)
        thd = np.einsum("ij,ij->i", n, vA3) / length
        sp = length - l2 + c2  # A1 -> C2 along e: l0 + lambda21 + c2
        r1 = c1 * e + c1p * n  # A1 -> C1, fixed in the cylinder
        r2 = sp[:, None] * e + c2p * n  # A1 -> C2
        lam = length - l0 - l2
        k = {
            "A1": np.broadcast_to(A1, d.shape),
            "A3": A3,
            "A2": A1 + (length - l2)[:, None] * e,
            "e": e,
            "n": n,
            "C1": A1 + r1,
            "C2": A1 + r2,
            "length": length,
            "theta": theta,
            "phi10": _wrap(theta - params[f"alpha_{leg}"]),
            "lambda21": lam,
            "omega10": thd,
            "v21": Ld,
            "omega32": w - thd,
            "v1": thd[:, None] * _perp(r1),
            "v2": Ld[:, None] * e + thd[:, None] * _perp(r2),
        }
        k["phi32"] = phi - k["phi10"]
        if qdd is not None:
            aA3 = qdd[:, :2] + qdd[:, 2][:, None] * _perp(rho) - (w**2)[:, None] * rho
            Ldd = np.einsum("ij,ij->i", e, aA3) + length * thd**2
            thdd = (np.einsum("ij,ij->i", n, aA3) - 2 * Ld * thd) / length
            k.update(
                eps10=thdd,
                gamma21=Ldd,
                eps32=qdd[:, 2] - thdd,
                a1=thdd[:, None] * _perp(r1) - (thd**2)[:, None] * r1,
                a2=Ldd[:, None] * e
                + (2 * Ld * thd)[:, None] * n
                + thdd[:, None] * _perp(r2)
                - (thd**2)[:, None] * r2,
            )
        out[leg] = k
    return out


def solve(params: Mapping[str, float], actuation: str, q, qd, qdd) -> dict[str, np.ndarray]:
    """Inverse dynamics by Newton-Euler on the seven bodies.

    Args:
        params: model parameters (``PARAM_NAMES``), SI units, radians.
        actuation: ``"revolute"`` (motor torque m10 at A1) or ``"prismatic"`` (force f21z at A2).
        q, qd, qdd: arrays (n, 3) of (x, y, phi), their first and second time derivatives.

    Returns:
        Every ``f"{family}_{leg}"`` of conventions.md -> array (n,).
    """
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, not {actuation!r}")
    kin = kinematics(params, q, qd, qdd)
    nsamp = kin["platform"]["G"].shape[0]
    g = np.array([params["gx"], params["gy"]])
    m1, m2, m3 = params["m1"], params["m2"], params["m3"]
    J1, J2, J3 = params["J1"], params["J2"], params["J3"]
    A = np.zeros((nsamp, 21, 21))
    b = np.zeros((nsamp, 21))
    pl = kin["platform"]
    G = pl["G"]
    for i, leg in enumerate(LEGS):
        k = kin[leg]
        e, n = k["e"], k["n"]
        r0, c0 = 6 * i, 7 * i  # first row (cylinder Fx) and first column of this leg
        cyl, pis, plat = r0, r0 + 3, 18
        col = {
            name: c0 + j
            for j, name in enumerate(("f10x", "f10y", "act", "f21y", "m21", "f32y", "f32z"))
        }
        # Force directions (world components) and moment arms of each unknown.
        # Cylinder: + f10 at A1, - f21 at A2, + m10 (revolute), + m21 about +z0 (reaction of the
        # piston's -m21); moments about its COM C1.
        rA1 = k["A1"] - k["C1"]
        rA2c = k["A2"] - k["C1"]
        A[:, cyl, col["f10x"]] = 1.0
        A[:, cyl + 1, col["f10y"]] = 1.0
        A[:, cyl + 2, col["f10x"]] = -rA1[:, 1]
        A[:, cyl + 2, col["f10y"]] = rA1[:, 0]
        A[:, cyl : cyl + 2, col["f21y"]] = -n
        A[:, cyl + 2, col["f21y"]] = -_cross(rA2c, n)
        A[:, cyl + 2, col["m21"]] = 1.0
        # Piston: + f21 at A2, - m21 about +z0, - f32 at A3; moments about its COM C2.
        rA2p = k["A2"] - k["C2"]
        rA3p = k["A3"] - k["C2"]
        A[:, pis : pis + 2, col["f21y"]] = n
        A[:, pis + 2, col["f21y"]] = _cross(rA2p, n)
        A[:, pis + 2, col["m21"]] = -1.0
        A[:, pis : pis + 2, col["f32y"]] = -n
        A[:, pis : pis + 2, col["f32z"]] = -e
        A[:, pis + 2, col["f32y"]] = -_cross(rA3p, n)
        A[:, pis + 2, col["f32z"]] = -_cross(rA3p, e)
        # Platform: + f32 at A3; moments about G.
        rA3g = k["A3"] - G
        A[:, plat : plat + 2, col["f32y"]] = n
        A[:, plat : plat + 2, col["f32z"]] = e
        A[:, plat + 2, col["f32y"]] = _cross(rA3g, n)
        A[:, plat + 2, col["f32z"]] = _cross(rA3g, e)
        # The actuated unknown.
        if actuation == "revolute":
            A[:, cyl + 2, col["act"]] = 1.0  # m10 about +z0 on the cylinder
        else:
            A[:, cyl : cyl + 2, col["act"]] = -e  # - f21z e on the cylinder at A2
            A[:, cyl + 2, col["act"]] = -_cross(rA2c, e)
            A[:, pis : pis + 2, col["act"]] = e  # + f21z e on the piston at A2
            A[:, pis + 2, col["act"]] = _cross(rA2p, e)
        # Right-hand sides: m a - m g and J eps.
        b[:, cyl : cyl + 2] = m1 * (k["a1"] - g)
        b[:, cyl + 2] = J1 * k["eps10"]
        b[:, pis : pis + 2] = m2 * (k["a2"] - g)
        b[:, pis + 2] = J2 * k["eps10"]
    b[:, 18:20] = m3 * (pl["a"] - g) - np.array([params["fx"], params["fy"]])
    b[:, 20] = J3 * pl["eps"] - params["mz"]
    x = np.linalg.solve(A, b[..., None])[..., 0]

    out: dict[str, np.ndarray] = {}
    zero = np.zeros(nsamp)
    for i, leg in enumerate(LEGS):
        k = kin[leg]
        xs = x[:, 7 * i : 7 * i + 7]
        act = xs[:, _ACT]
        vals = {
            "phi10": k["phi10"],
            "lambda21": k["lambda21"],
            "phi32": k["phi32"],
            "omega10": k["omega10"],
            "v21": k["v21"],
            "omega32": k["omega32"],
            "eps10": k["eps10"],
            "gamma21": k["gamma21"],
            "eps32": k["eps32"],
            "m10": act if actuation == "revolute" else zero.copy(),
            "f10x": xs[:, _F10X],
            "f10y": xs[:, _F10Y],
            "f21y": xs[:, _F21Y],
            "f21z": act if actuation == "prismatic" else zero.copy(),
            "m21": xs[:, _M21],
            "f32y": xs[:, _F32Y],
            "f32z": xs[:, _F32Z],
        }
        for fam in FAMILIES:
            out[f"{fam}_{leg}"] = np.array(vals[fam], dtype=float)
    return out


def energy(params: Mapping[str, float], q, qd) -> np.ndarray:
    """Kinetic plus potential energy of the seven bodies, (n,) J.

    Potential energy is ``-m g . r_COM`` for each body (zero at the world origin).
    """
    kin = kinematics(params, q, qd)
    g = np.array([params["gx"], params["gy"]])
    pl = kin["platform"]
    m1, m2, m3 = params["m1"], params["m2"], params["m3"]
    E = 0.5 * m3 * np.sum(pl["v"] ** 2, axis=1) + 0.5 * params["J3"] * pl["w"] ** 2
    E = E - m3 * pl["G"] @ g
    for leg in LEGS:
        k = kin[leg]
        w = k["omega10"]
        E = E + 0.5 * m1 * np.sum(k["v1"] ** 2, axis=1) + 0.5 * params["J1"] * w**2
        E = E + 0.5 * m2 * np.sum(k["v2"] ** 2, axis=1) + 0.5 * params["J2"] * w**2
        E = E - m1 * k["C1"] @ g - m2 * k["C2"] @ g
    return E


def energy_rate(params: Mapping[str, float], q, qd, qdd) -> np.ndarray:
    """dE/dt, analytically: sum over bodies of ``m a.v + J eps omega - m g.v``, (n,) W."""
    kin = kinematics(params, q, qd, qdd)
    g = np.array([params["gx"], params["gy"]])
    pl = kin["platform"]
    m1, m2, m3 = params["m1"], params["m2"], params["m3"]

    def dot(a, b):
        return np.einsum("ij,ij->i", a, b)

    P = m3 * dot(pl["a"] - g, pl["v"]) + params["J3"] * pl["eps"] * pl["w"]
    for leg in LEGS:
        k = kin[leg]
        P = P + m1 * dot(k["a1"] - g, k["v1"]) + m2 * dot(k["a2"] - g, k["v2"])
        P = P + (params["J1"] + params["J2"]) * k["eps10"] * k["omega10"]
    return P


def input_power(params: Mapping[str, float], out: Mapping[str, np.ndarray], qd) -> np.ndarray:
    """Power of the actuators and of the payload wrench: must equal ``energy_rate``, (n,) W."""
    qd = np.atleast_2d(np.asarray(qd, dtype=float))
    P = params["fx"] * qd[:, 0] + params["fy"] * qd[:, 1] + params["mz"] * qd[:, 2]
    for leg in LEGS:
        P = P + out[f"m10_{leg}"] * out[f"omega10_{leg}"] + out[f"f21z_{leg}"] * out[f"v21_{leg}"]
    return P


# ----------------------------------------------------------------------------------------------
# Helpers shared by the tests: motions and random robots.


def paper_motion(kind: str, samples: int = 301, duration: float = 3.0):
    """The paper's trajectories (eq. 3): ``x/x* = y/y* = phi/phi* = 1 - cos(pi t / duration)``.

    Returns:
        t (n,), q, qd, qdd (n, 3).
    """
    amp = {"rotation": (0.0, 0.0, math.pi / 6), "rectilinear": (0.05, -0.05, 0.0)}[kind]
    t = np.linspace(0.0, duration, samples)
    return (t, *cosine_motion(t, amp, duration))


def cosine_motion(t, amp, duration: float = 3.0):
    """q, qd, qdd of ``amp * (1 - cos(pi t / duration))`` for each of (x, y, phi)."""
    t = np.asarray(t, dtype=float)
    amp = np.asarray(amp, dtype=float)
    w = math.pi / duration
    q = amp * (1 - np.cos(w * t))[:, None]
    qd = amp * (w * np.sin(w * t))[:, None]
    qdd = amp * (w**2 * np.cos(w * t))[:, None]
    return q, qd, qdd


def sinusoid_motion(rng: np.random.Generator, t, amp=(0.03, 0.03, 0.25), terms: int = 3):
    """Random smooth motion: a sum of ``terms`` sinusoids per coordinate, analytic derivatives.

    Args:
        rng: random generator.
        t: times (n,).
        amp: rough amplitude of (x, y, phi) in m, m, rad.
        terms: sinusoids per coordinate.

    Returns:
        q, qd, qdd (n, 3).
    """
    t = np.asarray(t, dtype=float)
    q = np.zeros((t.size, 3))
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    for j in range(3):
        q[:, j] += amp[j] * rng.uniform(-0.5, 0.5)
        for _ in range(terms):
            a = amp[j] * rng.uniform(-1, 1) / terms
            w = rng.uniform(0.5, 6.0)
            ph = rng.uniform(0, 2 * math.pi)
            q[:, j] += a * np.sin(w * t + ph)
            qd[:, j] += a * w * np.cos(w * t + ph)
            qdd[:, j] -= a * w**2 * np.sin(w * t + ph)
    return q, qd, qdd


def random_robot(rng: np.random.Generator) -> dict:
    """A random robot shaped roughly like the paper's, with tilted gravity and a payload.

    Returns:
        A dict with ``params`` (``PARAM_NAMES``), and the model-file quantities ``l1``, ``base``
        (3 x 2), ``platform`` (3 x 2), ``alpha_deg`` (3,) the leg directions at the central pose.
    """
    base_ang = np.deg2rad([-30.0, 90.0, 210.0]) + rng.uniform(-0.3, 0.3, 3)
    base = (0.3 * rng.uniform(0.8, 1.2, 3))[:, None] * np.stack(
        [np.cos(base_ang), np.sin(base_ang)], axis=1
    )
    plat_ang = np.deg2rad([30.0, 150.0, 270.0]) + rng.uniform(-0.3, 0.3, 3)
    platform = rng.uniform(0.15, 0.3, 3)[:, None] * np.stack(
        [np.cos(plat_ang), np.sin(plat_ang)], axis=1
    )
    d = platform - base
    alpha = np.arctan2(d[:, 1], d[:, 0])
    alpha_deg = np.rad2deg(alpha)
    length = np.hypot(d[:, 0], d[:, 1])
    l0 = float(rng.uniform(0.2, 0.4) * length.min())
    l2 = float(rng.uniform(0.3, 0.6) * length.min())
    l1 = float(rng.uniform(0.1, 0.3))
    m1, m2, m3 = (float(v) for v in rng.uniform([1.0, 0.5, 2.0], [5.0, 3.0, 10.0]))
    gnorm = 9.81
    gang = -math.pi / 2 + rng.uniform(-0.6, 0.6)
    p: dict[str, float] = {}
    for i, leg in enumerate(LEGS):
        p[f"x{leg}1"], p[f"y{leg}1"] = float(base[i, 0]), float(base[i, 1])
        p[f"x{leg}3"], p[f"y{leg}3"] = float(platform[i, 0]), float(platform[i, 1])
        # What the loader will compute from alpha_deg.
        p[f"alpha_{leg}"] = math.radians(float(alpha_deg[i]))
    p.update(
        l0=l0,
        l2=l2,
        c1=float(rng.uniform(0.3, 0.7) * l1),
        c2=float(rng.uniform(0.3, 0.7) * l2),
        m1=m1,
        m2=m2,
        m3=m3,
        J1=float(m1 * l1**2 / 12 * rng.uniform(0.5, 1.5)),
        J2=float(m2 * l2**2 / 12 * rng.uniform(0.5, 1.5)),
        J3=float(m3 * 0.09 / 4 * rng.uniform(0.5, 1.5)),
        gx=gnorm * math.cos(gang),
        gy=gnorm * math.sin(gang),
        fx=float(rng.uniform(-20, 20)),
        fy=float(rng.uniform(-20, 20)),
        mz=float(rng.uniform(-3, 3)),
    )
    # Centres of mass off the leg axis, in [-0.2, 0.2] l, taken from the draws of c1, c2 rather
    # than drawn: a further draw would change every later robot of a seeded sequence.
    p.update(c1_perp=p["c1"] - 0.5 * l1, c2_perp=p["c2"] - 0.5 * l2)
    return {
        "params": {k: float(p[k]) for k in PARAM_NAMES},
        "l1": l1,
        "base": base,
        "platform": platform,
        "alpha_deg": alpha_deg,
    }


def well_conditioned(params: Mapping[str, float], q, min_length=0.05, max_cond=1e6) -> bool:
    """True when every leg is longer than ``min_length`` and both 3 x 3 platform force matrices
    have cond <= ``max_cond`` at every sample.

    The matrices map three leg forces at the platform joints to the wrench on the platform at G:
    forces along the legs ``e`` (the singularity of the prismatic-actuated robot) and normal to
    them ``n`` (that of the revolute-actuated robot, whose passive slider carries no axial force
    in a massless leg).
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    kin = kinematics(params, q, np.zeros_like(q))
    for direction in ("e", "n"):
        cols = []
        for leg in LEGS:
            k = kin[leg]
            if np.any(k["length"] < min_length):
                return False
            rho = k["A3"] - kin["platform"]["G"]
            u = k[direction]
            cols.append(np.concatenate([u, _cross(rho, u)[:, None]], axis=1))
        W = np.stack(cols, axis=2)  # (n, 3, 3)
        if not np.all(np.linalg.cond(W) <= max_cond):
            return False
    return True


def rotation(angle: float) -> np.ndarray:
    """2 x 2 rotation matrix about +z0."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def rotate_motion(angle: float, q, qd, qdd):
    """The motion turned by ``angle`` about the world origin: G -> R G, phi unchanged."""
    R = rotation(angle)
    out = []
    for a in (q, qd, qdd):
        a = np.array(a, dtype=float)
        a[:, :2] = a[:, :2] @ R.T
        out.append(a)
    return tuple(out)


def rotate_vectors(angle: float, params: Mapping[str, float]) -> dict[str, float]:
    """Gravity and payload force turned by ``angle`` (the geometry is left alone)."""
    R = rotation(angle)
    p = dict(params)
    p["gx"], p["gy"] = (float(v) for v in R @ [params["gx"], params["gy"]])
    p["fx"], p["fy"] = (float(v) for v in R @ [params["fx"], params["fy"]])
    return p


def body_residuals(
    params: Mapping[str, float], out: Mapping[str, np.ndarray], q, qdd
) -> dict[str, np.ndarray]:
    """Newton-Euler residuals of the seven bodies, built from a set of outputs alone.

    The leg geometry, velocities and accelerations are rebuilt from the outputs' own kinematic
    values (phi10, lambda21, omega10, v21, eps10, gamma21) and the platform's from ``q`` and
    ``qdd``; the loads are the outputs' (m10, f10, f21y, f21z, m21, f32y, f32z), with no moment at
    A3 and no other load. Residual = sum of loads + m g - m a (forces) and sum of moments about
    the COM - J eps (z0), so every entry is 0 for outputs that satisfy the mechanics.

    Returns:
        ``"cylinder_L"``, ``"piston_L"`` (L in A, B, C) and ``"platform"`` -> (n, 3) arrays
        (x0 force, y0 force, z0 moment), and ``"closure_L"`` -> (n, 2): the platform joint given
        by the leg chain ``A1 + (l0 + lambda21 + l2) e`` minus ``G + R(phi) p``.
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    qdd = np.atleast_2d(np.asarray(qdd, dtype=float))
    g = np.array([params["gx"], params["gy"]])
    m1, m2, m3 = params["m1"], params["m2"], params["m3"]
    J1, J2, J3 = params["J1"], params["J2"], params["J3"]
    l0, l2, c1, c2 = (params[k] for k in ("l0", "l2", "c1", "c2"))
    c1p, c2p = params["c1_perp"], params["c2_perp"]
    G, phi = q[:, :2], q[:, 2]
    res: dict[str, np.ndarray] = {}
    plat_f = m3 * g + np.array([params["fx"], params["fy"]]) - m3 * qdd[:, :2]
    plat_m = params["mz"] - J3 * qdd[:, 2]
    for leg in LEGS:

        def o(fam, leg=leg):
            return np.asarray(out[f"{fam}_{leg}"], dtype=float)

        theta = params[f"alpha_{leg}"] + o("phi10")
        e = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
        n = _perp(e)
        A1 = np.array([params[f"x{leg}1"], params[f"y{leg}1"]])
        s2 = l0 + o("lambda21")  # |A1 A2|
        A2 = A1 + s2[:, None] * e
        A3 = A2 + l2 * e
        r1 = c1 * e + c1p * n  # A1 -> C1
        r2 = (s2 + c2)[:, None] * e + c2p * n  # A1 -> C2
        C1 = A1 + r1
        C2 = A1 + r2
        p = np.array([params[f"x{leg}3"], params[f"y{leg}3"]])
        rho = np.stack(
            [np.cos(phi) * p[0] - np.sin(phi) * p[1], np.sin(phi) * p[0] + np.cos(phi) * p[1]],
            axis=-1,
        )
        res[f"closure_{leg}"] = A3 - (G + rho)
        w, eps = o("omega10"), o("eps10")
        sd, sdd = o("v21"), o("gamma21")
        a1 = eps[:, None] * _perp(r1) - (w**2)[:, None] * r1
        a2 = (
            sdd[:, None] * e
            + (2 * sd * w)[:, None] * n
            + eps[:, None] * _perp(r2)
            - (w**2)[:, None] * r2
        )
        f10 = np.stack([o("f10x"), o("f10y")], axis=-1)
        f21 = o("f21y")[:, None] * n + o("f21z")[:, None] * e
        m21z = -o("m21")  # moment of the cylinder on the piston about +z0
        f32 = o("f32y")[:, None] * n + o("f32z")[:, None] * e
        cyl_f = f10 - f21 + m1 * g - m1 * a1
        cyl_m = o("m10") + _cross(A1 - C1, f10) - _cross(A2 - C1, f21) - m21z - J1 * eps
        pis_f = f21 - f32 + m2 * g - m2 * a2
        pis_m = _cross(A2 - C2, f21) + m21z - _cross(A3 - C2, f32) - J2 * eps
        res[f"cylinder_{leg}"] = np.concatenate([cyl_f, cyl_m[:, None]], axis=1)
        res[f"piston_{leg}"] = np.concatenate([pis_f, pis_m[:, None]], axis=1)
        plat_f = plat_f + f32
        plat_m = plat_m + _cross(A3 - G, f32)
    res["platform"] = np.concatenate([plat_f, plat_m[:, None]], axis=1)
    return res


def random_case(seed: int, t, attempts: int = 100):
    """A random robot (``random_robot``) and random motion (``sinusoid_motion``) from a fixed
    seed, redrawn until every leg is longer than 0.05 m and the platform force matrix has
    cond <= 1e6 at every sample.

    Returns:
        (robot dict of ``random_robot``, q, qd, qdd).
    """
    rng = np.random.default_rng(seed)
    for _ in range(attempts):
        robot = random_robot(rng)
        q, qd, qdd = sinusoid_motion(rng, t)
        if well_conditioned(robot["params"], q):
            return robot, q, qd, qdd
    raise RuntimeError(f"no well-conditioned random robot for seed {seed}")
