"""Peer check: SchapplM's published 6-UPS dynamics (robsynth-parroblib) against rpr3gen's ups_2.

SchapplM's model (``tests/schappl_p6ups.py``, Maple-generated, transliterated; its conventions
are in that module's docstring) describes six identical UPS legs (``P6RRPRRR14V3``: a U of two
revolute joints at the base, the actuated prismatic joint, an S at the platform), each leg's
base frame turned anywhere (``G8``: three XYZ Euler angles per leg), with inertial parameters in
the links' frames, the same for every leg. Every such robot is an rpr3gen 6-UPS: here the
gallery's ``tsai-ups`` and random robots of six congruent legs (random base and platform
points, U axes in any direction, masses, centres of mass off the leg axis and full inertia
tensors in the links' frames, gravity in any direction); the gallery's U axes, printed to 12
digits, are made exactly perpendicular (a change below 1e-12) and its inertia tensors, printed
to 1e-8 kg m^2, exactly congruent (below 3e-8 kg m^2). The mapping from an rpr3gen model:

- leg frames: ``R_leg`` with z along the U's first axis ``u1`` and y along ``-u2`` (``u2`` its
  second axis at home), so that SchapplM's joint 1 is 0 at home and its frame 2's z is ``u2``:
  ``legFrame`` are the XYZ Euler angles of ``R_leg``. rpr3gen's U angles are then
  ``(qJ[0] - 0, qJ[1] - qJ[1]_home)``, its P coordinate ``qJ[2] - |S - U|_home``; SchapplM's
  ``qJ`` are computed here from the pose (the leg's direction in its frame); the branch of
  ``qJ[1]`` is the one with ``qJ[0] = 0`` at home, which the U assumption of
  docs/spatial-robots.md (the leg perpendicular to ``u2`` and not along ``u1``) makes exist;
- ``koppelP``: the platform points at home (the platform frame is the world frame at home);
- bodies: SchapplM's link 1 (the U's cross) has no rpr3gen counterpart and is given no mass;
  link 2 is the cylinder (frame 2 at the U centre), link 3 the piston (frame 3 at the S centre at
  home), each with its centre of mass and inertia in its frame: ``R2^T (com - U)``,
  ``R3^T (com - S)``, ``R^T I R`` from the model's world values at home; the platform's are the
  model's (platform frame = world frame at home); ``g`` the model's gravity; no payload;
- pose: rpr3gen's ``R = Rz(c) Ry(b) Rx(a)`` is SchapplM's ``Rx(phi_x) Ry(phi_y) Rz(phi_z)``; with
  ``omega = H_r (a, b, c)' = H_s phi'`` (the angular velocity, base axes), SchapplM's rates are
  ``phi' = H_s^-1 omega`` and ``phi'' = H_s^-1 (H_r (a, b, c)'' + H_r' (a, b, c)' - H_s' phi')``.

SchapplM's ``xDP`` and ``xDDP`` are the derivatives of its angles, as documented, but its
``Jinv`` and ``tauX`` are not in those coordinates (measured; the ``Jinv`` header calls it the
analytic Jacobian): ``Jinv`` is ``d qa / d (x, y, z, omega)``, the rates of the prismatic joints
per the platform's velocity and angular velocity, and ``tauX`` is the wrench conjugate to it
(force, and moment about the platform frame's origin, base axes). So, with ``W =
blockdiag(I, H_r^-1)``: ``Jinv = J W`` (``J`` rpr3gen's ``actuator_jacobian``) and ``tauX =
W^T (M q'' + c)`` (``task_space_dynamics``: ``J^T tau = M q'' + c``, so ``tauX = Jinv^T tau``);
and the actuator forces ``Jinv^-T tauX``, SchapplM's alone, are rpr3gen's ``tau_A..F``.

Measured (four robots, six states each, poses within 5 cm and 0.25 rad of home, rates within
1 m/s and 1 rad/s, accelerations within 3 m/s^2 and 3 rad/s^2): ``Jinv`` within 5e-16, ``tauX``
8e-16 and the forces 1.7e-15 of their largest values (forces up to 132 N), the joint
coordinates within 1.3e-15; the tolerance is 1e-12 of the largest value (1e-12 absolute for the
joint coordinates). Read as the header says (``d qa / d xP``), ``Jinv`` would differ from
rpr3gen's by 5e-2. Changes that the check must see, each in SchapplM's inputs alone (the
largest relative difference in the forces over six states of ``random0``;
:func:`test_a_changed_schappl_input_is_seen` asserts each above 1e-6): the angular velocity and
acceleration given for ``xDP``, ``xDDP`` instead of the angles' rates 1e-2; gravity reversed
3.2; a 1 kg U cross (link 1, centre of mass 3 cm off the U centre) 3.5e-2; the piston's centre
of mass moved 2 cm 3e-3; the cylinder's inertia 10 % larger 3.6e-3; one leg frame's first
angle 0.01 rad off (its joint coordinates kept) 3.9e-3.

Not compared: a massive U cross (SchapplM's link 1; rpr3gen's UPS has no such body), the other
branch of SchapplM's joint 2 (``qJ[0] = pi`` at home, ``sin qJ[1] < 0``: the same robot with
other link frames), the folder's other generated functions (the ``G1A0`` dynamics and the
``G1``-``G6`` ``Jinv``, whose leg frames ``G8``'s three angles include; the separate gravity,
inertia and Coriolis parts, the ``vp2`` and regressor forms), and every rpr3gen joint load but
the actuator forces (SchapplM's functions give none). SchapplM's model has no payload.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.model import model_from_dict

try:
    from . import schappl_p6ups as schappl
    from . import spatial_reference as sr
except ImportError:
    import schappl_p6ups as schappl
    import spatial_reference as sr

LEGS = "ABCDEF"
ROOT = Path(__file__).resolve().parent.parent
TOL = 1e-12
EX, EY, EZ = np.eye(3)
PKIN = np.zeros(1)  # SchapplM's dummy kinematic parameter


def _rx(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rz(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _xyz(phi: np.ndarray) -> np.ndarray:
    """SchapplM's orientation ``Rx(phi_x) Ry(phi_y) Rz(phi_z)``."""
    return _rx(phi[0]) @ _ry(phi[1]) @ _rz(phi[2])


def _xyz_angles(R: np.ndarray) -> np.ndarray:
    """The XYZ Euler angles of ``R`` (``|phi_y| < pi/2``)."""
    return np.array(
        [
            math.atan2(-R[1, 2], R[2, 2]),
            math.atan2(R[0, 2], math.hypot(R[1, 2], R[2, 2])),
            math.atan2(-R[0, 1], R[0, 0]),
        ]
    )


def _zyx(a: np.ndarray) -> np.ndarray:
    """rpr3gen's orientation ``Rz(c) Ry(b) Rx(a)``."""
    return _rz(a[2]) @ _ry(a[1]) @ _rx(a[0])


def _h_r(a: np.ndarray, ad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rpr3gen's ``H_r`` (``omega = H_r (a, b, c)'``) and its time derivative."""
    cols = (_rz(a[2]) @ _ry(a[1]) @ EX, _rz(a[2]) @ EY, EZ)
    w1 = ad[2] * EZ + ad[1] * cols[1]  # the angular velocity of Rz(c) Ry(b)
    dcols = (np.cross(w1, cols[0]), np.cross(ad[2] * EZ, cols[1]), np.zeros(3))
    return np.stack(cols, axis=1), np.stack(dcols, axis=1)


def _h_s(p: np.ndarray, pd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """SchapplM's ``H_s`` (``omega = H_s phi'``) and its time derivative."""
    cols = (EX, _rx(p[0]) @ EY, _rx(p[0]) @ _ry(p[1]) @ EZ)
    w1 = pd[0] * EX + pd[1] * cols[1]  # the angular velocity of Rx(phi_x) Ry(phi_y)
    dcols = (np.zeros(3), np.cross(pd[0] * EX, cols[1]), np.cross(w1, cols[2]))
    return np.stack(cols, axis=1), np.stack(dcols, axis=1)


def _leg_frame(u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """``R_leg``: z along ``u1``, y along ``-u2``."""
    z = u1 / np.linalg.norm(u1)
    y = -u2 / np.linalg.norm(u2)
    return np.stack([np.cross(y, z), y, z], axis=1)


def _leg_joints(v: np.ndarray, sign: float) -> np.ndarray:
    """SchapplM's ``qJ`` of a leg whose S centre is at ``v`` in its leg frame: ``v = q3 Rz(q1)
    (sin q2, 0, -cos q2)``; ``sign`` that of ``sin q2``."""
    h = math.hypot(v[0], v[1])
    return np.array(
        [
            math.atan2(sign * v[1], sign * v[0]),
            math.atan2(sign * h, -v[2]),
            float(np.linalg.norm(v)),
        ]
    )


def _link_frames(R_leg: np.ndarray, qj: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations of SchapplM's frames 2 (cylinder) and 3 (piston)."""
    R2 = R_leg @ _rz(qj[0]) @ _rx(math.pi / 2) @ _rz(qj[1])
    return R2, R2 @ _rx(math.pi / 2)


def _leg(d: dict) -> dict:
    """A model leg's frames at home and its bodies' numbers in SchapplM's links' frames."""
    B, P = np.asarray(d["base"], dtype=float), np.asarray(d["platform"], dtype=float)
    u1, u2 = (np.asarray(u, dtype=float) for u in d["u_axes"])
    R_leg = _leg_frame(u1, u2)
    v = R_leg.T @ (P - B)
    sign = math.copysign(1.0, v[0])
    qj = _leg_joints(v, sign)
    assert abs(qj[0]) < 1e-12  # joint 1 is 0 at home, frame 2's z is u2
    R2, R3 = _link_frames(R_leg, qj)
    com = np.asarray(d["com"], dtype=float)
    inertia = [sr.inertia_matrix(row) for row in d["inertia"]]
    return {
        "R_leg": R_leg, "sign": sign, "home": qj, "R2": R2, "R3": R3, "B": B, "P": P,
        "local": [
            R2.T @ (com[0] - B),
            R3.T @ (com[1] - P),
            np.array(sr.inertia_list(R2.T @ inertia[0] @ R2)),
            np.array(sr.inertia_list(R3.T @ inertia[1] @ R3)),
        ],
    }  # fmt: skip


def _schappl_parameters(data: dict) -> dict[str, np.ndarray]:
    """SchapplM's parameters of an rpr3gen 6-UPS model of congruent legs (asserted)."""
    legs = [_leg(data["legs"][leg]) for leg in LEGS]
    for lg in legs[1:]:  # congruent legs: the same numbers in the links' frames
        for a, b in zip(lg["local"], legs[0]["local"], strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    local = legs[0]["local"]
    plat = data["platform"]
    return {
        "R_leg": np.array([lg["R_leg"] for lg in legs]),
        "sign": np.array([lg["sign"] for lg in legs]),
        "home": np.array([lg["home"] for lg in legs]),
        "legFrame": np.array([_xyz_angles(lg["R_leg"]) for lg in legs]),
        "koppelP": np.array([lg["P"] for lg in legs]),
        "base": np.array([lg["B"] for lg in legs]),
        "m": np.array([0.0, *data["legs"]["A"]["mass"], plat["mass"]], dtype=float),
        "rSges": np.array([np.zeros(3), local[0], local[1], plat["com"]], dtype=float),
        "Icges": np.array([np.zeros(6), local[2], local[3], plat["inertia"]], dtype=float),
        "g": np.array(data.get("environment", {}).get("gravity", (0.0, 0.0, -9.81)), dtype=float),
    }


def _with_leg_a_s_numbers(data: dict) -> float:
    """Give every leg leg A's centres of mass and inertias in the links' frames (in place); the
    largest change of a model number."""
    local = _leg(data["legs"]["A"])["local"]
    change = 0.0
    for leg in LEGS:
        d, lg = data["legs"][leg], _leg(data["legs"][leg])
        R2, R3 = lg["R2"], lg["R3"]
        com = [lg["B"] + R2 @ local[0], lg["P"] + R3 @ local[1]]
        inertia = [
            sr.inertia_list(R @ sr.inertia_matrix(v) @ R.T)
            for R, v in ((R2, local[2]), (R3, local[3]))
        ]
        change = max(
            change,
            float(np.max(np.abs(np.asarray(d["com"]) - np.array(com)))),
            float(np.max(np.abs(np.asarray(d["inertia"]) - np.array(inertia)))),
        )
        d["com"], d["inertia"] = [c.tolist() for c in com], inertia
    return change


def _physical_inertia(rng: np.random.Generator, mass: float, size: float) -> np.ndarray:
    """A random inertia tensor of a body (moments of a random ellipsoid-like mass spread)."""
    s = rng.uniform(0.1, 1.0, 3) * mass * size**2
    Q = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return Q @ np.diag([s[1] + s[2], s[0] + s[2], s[0] + s[1]]) @ Q.T


def _congruent_robot(rng: np.random.Generator) -> dict:
    """Six copies of one random UPS leg of SchapplM's kind (masses, centres of mass and inertias
    in the links' frames), between random base and platform points, U axes in any direction;
    random platform, gravity in any direction, no payload."""
    m2, m3 = rng.uniform(0.5, 2.0), rng.uniform(0.2, 1.0)
    rS2 = np.array([*rng.uniform(-0.03, 0.03, 2), 0.0]) + rng.uniform(0.1, 0.3) * np.array(
        [0.0, -1.0, 0.0]
    )  # frame 2's -y is along the leg
    rS3 = rng.uniform(-0.03, 0.03, 3) + rng.uniform(0.1, 0.3) * EZ  # frame 3's z: S -> U
    I2, I3 = _physical_inertia(rng, m2, 0.15), _physical_inertia(rng, m3, 0.1)
    rb, rp, h = rng.uniform(0.45, 0.6), rng.uniform(0.25, 0.35), rng.uniform(0.6, 0.9)
    legs = {}
    for i, leg in enumerate(LEGS):
        k, odd = divmod(i, 2)
        s = 1.0 if odd else -1.0
        tb = math.radians(120 * k + s * 15 + rng.uniform(-4, 4))
        tp = math.radians(120 * k + s * 45 + rng.uniform(-4, 4))
        B = np.array([rb * math.cos(tb), rb * math.sin(tb), -h]) + rng.uniform(-0.01, 0.01, 3)
        P = np.array([rp * math.cos(tp), rp * math.sin(tp), 0.0]) + rng.uniform(-0.01, 0.01, 3)
        e0 = (P - B) / np.linalg.norm(P - B)
        n = np.cross(e0, rng.normal(size=3))
        u2 = n / np.linalg.norm(n)  # any direction across the leg
        beta = rng.uniform(-0.7, 0.7)  # u1 at least 50 deg from the leg
        u1 = math.cos(beta) * np.cross(u2, e0) + math.sin(beta) * e0
        R_leg = _leg_frame(u1, u2)
        qj = _leg_joints(R_leg.T @ (P - B), math.copysign(1.0, (R_leg.T @ (P - B))[0]))
        R2, R3 = _link_frames(R_leg, qj)
        legs[leg] = {
            "base": B.tolist(),
            "u_axes": [u1.tolist(), u2.tolist()],
            "platform": P.tolist(),
            "mass": [float(m2), float(m3)],
            "com": [(B + R2 @ rS2).tolist(), (P + R3 @ rS3).tolist()],
            "inertia": [sr.inertia_list(R2 @ I2 @ R2.T), sr.inertia_list(R3 @ I3 @ R3.T)],
        }
    mp = float(rng.uniform(1.0, 4.0))
    g = rng.normal(size=3)
    return {
        "name": "congruent-6ups",
        "leg": "UPS",
        "actuated": 2,
        "legs": legs,
        "platform": {
            "mass": mp,
            "com": rng.uniform(-0.04, 0.04, 3).tolist(),
            "inertia": sr.inertia_list(_physical_inertia(rng, mp, 0.2)),
        },
        "environment": {"gravity": (9.81 * g / np.linalg.norm(g)).tolist()},
    }


def _gallery() -> dict:
    with (ROOT / "models" / "tsai-ups.toml").open("rb") as handle:
        data = tomllib.load(handle)
    data.pop("symmetric")
    data["legs"] = sr.expand_symmetric("UPS", data["legs"])
    # Its U axes are printed to 12 digits (u1 . u2 and u2 . leg are 3e-13 and 2e-13) and its
    # tensors to 1e-8 kg m^2 (the legs congruent to 3e-8): both made exact here.
    for d in data["legs"].values():
        e0 = np.subtract(d["platform"], d["base"])
        u1, u2 = (np.asarray(u, dtype=float) for u in d["u_axes"])
        u2 = np.cross(e0, np.cross(u2, e0))
        u2 /= np.linalg.norm(u2)
        u1 = u1 - (u1 @ u2) * u2
        u1 /= np.linalg.norm(u1)
        assert np.max(np.abs(np.array([u1, u2]) - d["u_axes"])) < 1e-12
        d["u_axes"] = [u1.tolist(), u2.tolist()]
    assert _with_leg_a_s_numbers(data) < 3e-8
    return data


def _states(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q = np.concatenate([rng.uniform(-0.05, 0.05, (n, 3)), rng.uniform(-0.25, 0.25, (n, 3))], 1)
    return q, rng.uniform(-1.0, 1.0, (n, 6)), rng.uniform(-3.0, 3.0, (n, 6))


def _schappl_state(p: dict, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict:
    """SchapplM's inputs at one rpr3gen state, and ``W = blockdiag(I, H_r^-1)``."""
    a, ad, add = q[3:], qd[3:], qdd[3:]
    R = _zyx(a)
    phi = _xyz_angles(R)
    assert np.max(np.abs(_xyz(phi) - R)) < 1e-14
    Hr, dHr = _h_r(a, ad)
    omega = Hr @ ad
    Hs, _ = _h_s(phi, np.zeros(3))
    phid = np.linalg.solve(Hs, omega)
    _, dHs = _h_s(phi, phid)
    domega = Hr @ add + dHr @ ad
    phidd = np.linalg.solve(Hs, domega - dHs @ phid)
    qJ = np.empty((3, 6))
    for i in range(6):
        S = q[:3] + R @ p["koppelP"][i]
        qJ[:, i] = _leg_joints(p["R_leg"][i].T @ (S - p["base"][i]), p["sign"][i])
    W = np.eye(6)
    W[3:, 3:] = np.linalg.inv(Hr)
    return {
        "xP": np.r_[q[:3], phi],
        "xDP": np.r_[qd[:3], phid],
        "xDDP": np.r_[qdd[:3], phidd],
        "omega": (np.r_[qd[:3], omega], np.r_[qdd[:3], domega]),
        "qJ": qJ,
        "W": W,
    }


def _schappl(p: dict, s: dict, xDP=None, xDDP=None) -> tuple[np.ndarray, np.ndarray]:
    """SchapplM's ``Jinv`` and ``tauX`` at a state."""
    Jinv = schappl.jacobian_inverse(s["xP"], s["qJ"], PKIN, p["koppelP"], p["legFrame"])
    tauX = schappl.invdyn_platform(
        s["xP"], s["xDP"] if xDP is None else xDP, s["xDDP"] if xDDP is None else xDDP, s["qJ"],
        p["g"], p["legFrame"], p["koppelP"], PKIN, p["m"], p["rSges"], p["Icges"],
    )  # fmt: skip
    return Jinv, tauX


CASES = {"gallery": _gallery} | {
    f"random{k}": (lambda k=k: _congruent_robot(np.random.default_rng(600 + k))) for k in range(3)
}


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("name", list(CASES))
def test_schappl_p6ups_gives_rpr3gen_s_jacobian_dynamics_and_forces(name: str) -> None:
    data = CASES[name]()
    model = model_from_dict(data, source=name)
    assert model.variant == "ups_2"
    p = _schappl_parameters(data)
    q, qd, qdd = _states(np.random.default_rng(sum(map(ord, name))), 6)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    J = rpr3gen.actuator_jacobian(model, q)
    M, c = rpr3gen.task_space_dynamics(model, q, qd)
    tau = np.stack([out[f"tau_{leg}"] for leg in LEGS], axis=1)
    for k in range(len(q)):
        s = _schappl_state(p, q[k], qd[k], qdd[k])
        # The joint coordinates: rpr3gen's U angles and P coordinate from SchapplM's qJ.
        for i, leg in enumerate(LEGS):
            ours = [out[f"q1a_{leg}"][k], out[f"q1b_{leg}"][k], out[f"q2_{leg}"][k]]
            np.testing.assert_allclose(s["qJ"][:, i] - p["home"][i], ours, rtol=0, atol=1e-12)
        Jinv, tauX = _schappl(p, s)
        assert _rel(Jinv, J[k] @ s["W"]) < TOL
        assert _rel(tauX, s["W"].T @ (M[k] @ qdd[k] + c[k])) < TOL
        assert _rel(np.linalg.solve(Jinv.T, tauX), tau[k]) < TOL


def _changed(change: str, p: dict, s: dict) -> tuple[np.ndarray, np.ndarray]:
    p = {key: value.copy() for key, value in p.items()}
    xDP = xDDP = None
    if change == "omega":
        xDP, xDDP = s["omega"]
    elif change == "gravity":
        p["g"] = -p["g"]
    elif change == "u_cross":
        p["m"][0], p["rSges"][0] = 1.0, [0.03, 0.0, 0.0]
    elif change == "piston_com":
        p["rSges"][2] += [0.0, 0.02, 0.0]
    elif change == "cylinder_inertia":
        p["Icges"][1] *= 1.1
    elif change == "leg_frame":
        p["legFrame"][0, 0] += 0.01
    return _schappl(p, s, xDP, xDDP)


CHANGES = ("omega", "gravity", "u_cross", "piston_com", "cylinder_inertia", "leg_frame")


@pytest.mark.parametrize("change", CHANGES)
def test_a_changed_schappl_input_is_seen(change: str) -> None:
    data = CASES["random0"]()
    model = model_from_dict(data, source="random0")
    p = _schappl_parameters(data)
    q, qd, qdd = _states(np.random.default_rng(1), 6)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    tau = np.stack([out[f"tau_{leg}"] for leg in LEGS], axis=1)
    worst = 0.0
    for k in range(len(q)):
        Jinv, tauX = _changed(change, p, _schappl_state(p, q[k], qd[k], qdd[k]))
        worst = max(worst, _rel(np.linalg.solve(Jinv.T, tauX), tau[k]))
    assert worst > 1e-6
