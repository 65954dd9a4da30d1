"""Peer check: SchapplM's published P3RRR1 dynamics (robsynth-parroblib) against rpr3gen's rrr_1.

SchapplM's model (``tests/schappl_p3rrr1.py``, Maple-generated, transliterated) describes three
identical RRR legs, each placed anywhere and turned by its own angle; its inverse dynamics is in
platform coordinates (``tauX``, the forces and moment at the platform frame's origin that give
the platform's acceleration) and its inverse Jacobian is that of base motors. rpr3gen's general
format takes any legs, so every robot of SchapplM's kind is one of its models: here the
gallery's symmetric 3-RRR and random robots of three congruent legs (random link lengths,
centres of mass off the links, elbows either way, base and platform points and gravity
anywhere). Their conventions map onto the general format as follows: leg i's base frame turned
by the home angle of its link 1, so ``qJ[0, i] = q1`` (rpr3gen's motor coordinate) and
``qJ[1, i] = q2 + (link 2's home angle - link 1's)``; ``koppelP`` the platform joints at home;
centres of mass in the links' frames (x from a joint to the next).

Compared: SchapplM's ``Jinv`` with rpr3gen's ``actuator_jacobian``; its ``tauX`` with
``M qdd + c`` of ``task_space_dynamics``; and the actuator torques ``Jinv^-T tauX``, SchapplM's
alone, with rpr3gen's ``inverse_dynamics`` ``tau_A..C``. Measured: J within 9e-16, ``tauX``
3.3e-16 and the torques 1.2e-15 of their largest values (torques up to 13 N m); gravity reversed,
a centre of mass moved 2 cm or an inertia 10 % off in SchapplM's parameters shows as 2, 5e-2
and 2e-4. The model has no payload: rpr3gen's is zero here.
"""

from __future__ import annotations

import functools
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.model import model_from_dict

try:
    from . import planar_models as pm
    from . import planar_reference as pr
    from . import schappl_p3rrr1 as schappl
except ImportError:
    import planar_models as pm
    import planar_reference as pr
    import schappl_p3rrr1 as schappl

LEGS = pr.LEGS
ROOT = Path(__file__).resolve().parent.parent


def _angle(v: np.ndarray) -> float:
    return math.atan2(v[1], v[0])


def _rot(th: float) -> np.ndarray:
    return np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])


def _congruent_robot(rng: np.random.Generator) -> dict:
    """Three copies of one random RRR leg (lengths, masses, centres of mass in the links'
    frames, inertias), each from a random base point to a random platform point, elbow either
    way; random platform, gravity in any direction, no payload."""
    a1, a2 = rng.uniform(0.2, 0.35, 2)
    mass = rng.uniform(0.5, 2.0, 2)
    inertia = rng.uniform(0.002, 0.01, 2)
    local = [np.array([rng.uniform(0.3, 0.7) * a, rng.uniform(-0.03, 0.03)]) for a in (a1, a2)]
    legs = {}
    for k, leg in enumerate(LEGS):
        base_angle = math.radians(-90 + 120 * k + rng.uniform(-20, 20))
        p1 = rng.uniform(0.45, 0.55) * np.array([math.cos(base_angle), math.sin(base_angle)])
        platform_angle = base_angle + rng.uniform(-0.4, 0.4)
        p3 = rng.uniform(0.12, 0.2) * np.array([math.cos(platform_angle), math.sin(platform_angle)])
        d = np.linalg.norm(p3 - p1)
        assert abs(a1 - a2) < d < a1 + a2
        # The elbow: |p2 - p1| = a1, |p3 - p2| = a2, on either side of p1 -> p3.
        along = (a1**2 - a2**2 + d**2) / (2 * d)
        u = (p3 - p1) / d
        side = rng.choice([-1.0, 1.0])
        p2 = p1 + along * u + side * math.sqrt(a1**2 - along**2) * np.array([-u[1], u[0]])
        frames = (_angle(p2 - p1), _angle(p3 - p2))
        legs[leg] = {
            "joints": [p1.tolist(), p2.tolist(), p3.tolist()],
            "mass": mass.tolist(),
            "com": [
                (p1 + _rot(frames[0]) @ local[0]).tolist(),
                (p2 + _rot(frames[1]) @ local[1]).tolist(),
            ],
            "inertia": inertia.tolist(),
        }
    g = 9.81 * np.array([math.cos(a := rng.uniform(-math.pi, math.pi)), math.sin(a)])
    return {
        "name": "congruent-3rrr",
        "leg": "RRR",
        "actuated": 1,
        "legs": legs,
        "platform": {
            "mass": float(rng.uniform(1, 4)),
            "com": rng.uniform(-0.03, 0.03, 2).tolist(),
            "inertia": float(rng.uniform(0.01, 0.05)),
        },
        "environment": {"gravity": g.tolist()},
    }


def _gallery() -> dict:
    with (ROOT / "models" / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    data.pop("symmetric")
    data["legs"] = pr.expand_symmetric(data["legs"]["A"])
    return data


def _schappl_parameters(data: dict) -> dict[str, np.ndarray]:
    """SchapplM's parameters of a general model of three congruent RRR legs."""
    frames, lengths, local = [], [], []
    for leg in LEGS:
        P = np.asarray(data["legs"][leg]["joints"], dtype=float)
        th = (_angle(P[1] - P[0]), _angle(P[2] - P[1]))
        frames.append(th)
        lengths.append((np.linalg.norm(P[1] - P[0]), np.linalg.norm(P[2] - P[1])))
        coms = np.asarray(data["legs"][leg]["com"], dtype=float)
        local.append([_rot(-th[k]) @ (coms[k] - P[k]) for k in range(2)])
    # Congruent legs: the same lengths and centres of mass in the links' frames.
    np.testing.assert_allclose(lengths, [lengths[0]] * 3, rtol=1e-9)
    np.testing.assert_allclose(np.array(local), np.array([local[0]] * 3), atol=1e-9)
    legA = data["legs"]["A"]
    plat = data["platform"]
    rS = [[*local[0][0], 0.0], [*local[0][1], 0.0], [*plat["com"], 0.0]]
    return {
        "frames": np.array(frames),
        "legFrame": np.array([[0.0, 0.0, th[0]] for th in frames]),
        "koppelP": np.array([[*data["legs"][leg]["joints"][2], 0.0] for leg in LEGS]),
        "pkin": np.array([*lengths[0], 0.0, 0.0, 0.0]),
        "m": np.array([*legA["mass"], plat["mass"]]),
        "rSges": np.array(rS),
        "Icges": np.array(
            [[0, 0, J, 0, 0, 0] for J in (*legA["inertia"], plat["inertia"])], dtype=float
        ),
        "g": np.array([*data.get("environment", {}).get("gravity", (0.0, -9.81)), 0.0]),
    }


CASES = {"gallery": _gallery, **{f"random{k}": functools.partial(
    lambda k: _congruent_robot(np.random.default_rng(500 + k)), k) for k in range(3)}}  # fmt: skip


@pytest.mark.parametrize("name", list(CASES))
def test_schappl_p3rrr1_gives_rpr3gen_s_jacobian_dynamics_and_torques(name: str) -> None:
    data = CASES[name]()
    model = model_from_dict(data, source=name)
    assert model.variant == "rrr_1"
    robot = pr.parse_model(data)
    rng = np.random.default_rng(sum(map(ord, name)))
    q, qd, qdd = pm.random_motion(rng, robot, np.linspace(0.0, 1.0, 6))
    p = _schappl_parameters(data)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    J = rpr3gen.actuator_jacobian(model, q)
    M, c = rpr3gen.task_space_dynamics(model, q, qd)
    tau = np.stack([out[f"tau_{leg}"] for leg in LEGS], axis=1)
    for k in range(len(q)):
        qJ = np.array(
            [
                [out[f"q1_{leg}"][k] for leg in LEGS],
                [
                    out[f"q2_{leg}"][k] + p["frames"][i][1] - p["frames"][i][0]
                    for i, leg in enumerate(LEGS)
                ],
            ]
        )
        Jinv = schappl.jacobian_inverse(q[k], qJ, p["pkin"], p["koppelP"], p["legFrame"])
        assert np.max(np.abs(Jinv - J[k])) < 1e-12 * np.max(np.abs(J[k]))
        tauX = schappl.invdyn_platform(
            q[k], qd[k], qdd[k], qJ, p["g"], p["legFrame"], p["koppelP"], p["pkin"], p["m"],
            p["rSges"], p["Icges"],
        )  # fmt: skip
        ours = M[k] @ qdd[k] + c[k]
        assert np.max(np.abs(tauX - ours)) < 1e-12 * np.max(np.abs(ours))
        torques = np.linalg.solve(Jinv.T, tauX)
        assert np.max(np.abs(torques - tau[k])) < 1e-12 * np.max(np.abs(tau[k]))
