"""Invariances of the generated code on general models, through the public API (NumPy).

- Turning the whole scene (every point, axis and centre of mass, gravity and the payload force)
  about the world origin turns the motion, the joint forces (world components) and the
  platform accelerations, and leaves every joint coordinate, moment, effort, ``conditioning``
  and ``reach`` as they were; assembly modes turn with it.
- The gallery's symmetric 3-RRR (``models/rrr.toml``: leg A placed three times, by 120
  degrees): a motion turned by 120 degrees, with gravity and the payload turned, gives leg A's
  loads to leg B, B's to C and C's to A.
- At rest, the base's loads on the legs balance the weight of every body and the payload
  (forces, and moments about the origin); without gravity the efforts are the payload's
  (``payload_efforts``).

Measured: joint forces within 2.6e-15 of the largest (rotation and symmetry alike), forward
dynamics 2.3e-13, assembly modes 1.8e-14 m; balance at rest 3.7e-16 of the weight.
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
    from . import planar_checks as chk
    from . import planar_models as pm
    from . import planar_reference as pr
except ImportError:
    import planar_checks as chk
    import planar_models as pm
    import planar_reference as pr


ROOT = Path(__file__).resolve().parent.parent
LEGS = chk.LEGS
#: Structures of the committed variant and of variants other tests generate anyway.
STRUCTURES = [("RRR", 1), ("PRR", 1), ("RPR", 3), ("PPR", 2)]
IDS = [f"{leg}{a}" for leg, a in STRUCTURES]


def _turn(degrees: float) -> np.ndarray:
    th = math.radians(degrees)
    return np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])


def _turn_motion(R: np.ndarray, *arrays: np.ndarray) -> list[np.ndarray]:
    """Poses, velocities or accelerations of the turned scene: (x, y) turned, phi kept."""
    return [np.column_stack([a[:, :2] @ R.T, a[:, 2]]) for a in arrays]


@functools.cache
def _case(leg: str, actuated: int):
    rng = np.random.default_rng(700 + 10 * pr.LEG_TYPES.index(leg) + actuated)
    data = pm.random_model(rng, leg, actuated)
    q, qd, qdd = pm.random_motion(rng, pr.parse_model(data), np.linspace(0, 1, 7))
    return data, q, qd, qdd


def _close(a, b, scale: float, what: str, tol: float = 1e-12) -> None:
    err = float(np.max(np.abs(np.asarray(a) - b))) / scale
    assert err < tol, f"{what}: {err:.2e}"


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_turning_the_scene_turns_the_loads(leg: str, actuated: int) -> None:
    data, q, qd, qdd = _case(leg, actuated)
    degrees = 37.0
    R = _turn(degrees)
    model = model_from_dict(data)
    turned = model_from_dict(chk.rotated(data, degrees))
    q2, qd2, qdd2 = _turn_motion(R, q, qd, qdd)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    out2 = rpr3gen.inverse_dynamics(turned, q2, qd2, qdd2)
    forces = max(
        float(np.max(np.abs(out[f"f{a}{j}_{L}"]))) for a in "xy" for j in "123" for L in LEGS
    )
    for name, value in out.items():
        family = name.split("_")[0]
        if family[0] == "f":
            continue
        d = out2[name] - value
        if family in ("q1", "q2", "q3") and leg[int(family[1]) - 1] == "R":
            d = chk.wrap(d)
        scale = max(float(np.max(np.abs(value))), 1e-300)
        if family[0] == "m" or family == "tau":
            scale = max(scale, 1e-3 * forces)  # moments of passive joints are round-off
        assert float(np.max(np.abs(d))) / scale < 1e-12, name
    for j in "123":
        for L in LEGS:
            f = np.column_stack([out[f"fx{j}_{L}"], out[f"fy{j}_{L}"]])
            f2 = np.column_stack([out2[f"fx{j}_{L}"], out2[f"fy{j}_{L}"]])
            _close(f2, f @ R.T, forces, f"f{j}_{L}")
    tau = np.stack([out[f"tau_{L}"] for L in LEGS], axis=1)
    (qdd_back,) = _turn_motion(R, rpr3gen.forward_dynamics(model, q, qd, tau))
    _close(
        rpr3gen.forward_dynamics(turned, q2, qd2, tau), qdd_back, np.max(np.abs(qdd)), "fd", 1e-11
    )
    qa = rpr3gen.actuator_coordinates(model, q[2])[0]
    modes = rpr3gen.assembly_modes(model, qa)
    modes2 = rpr3gen.assembly_modes(turned, qa)
    assert len(modes2) == len(modes)
    (expected,) = _turn_motion(R, modes)
    order = np.argsort(expected[:, 2])
    _close(modes2[np.argsort(modes2[:, 2])], expected[order], 1.0, "modes", 1e-10)


def _gallery(degrees: float) -> dict:
    """``models/rrr.toml`` (symmetric sugar kept) with a payload; gravity and the payload force
    turned by ``degrees``."""
    with (ROOT / "models" / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    R = _turn(degrees)
    gravity = np.asarray(data["environment"]["gravity"], dtype=float)
    data["environment"] = {"gravity": (R @ gravity).tolist()}
    data["payload"] = {"force": (R @ np.array([12.0, -7.0])).tolist(), "moment": 1.5}
    return data


def test_the_symmetric_rrr_passes_each_leg_s_loads_to_the_next() -> None:
    data = _gallery(0.0)
    assert data["symmetric"] is True
    assert set(data["legs"]) == {"A"}
    model = model_from_dict(data, source="rrr.toml")
    turned = model_from_dict(_gallery(120.0), source="rrr.toml turned")
    assert model.variant == "rrr_1"
    explicit = {k: v for k, v in data.items() if k != "symmetric"}
    explicit["legs"] = pr.expand_symmetric(data["legs"]["A"])
    rng = np.random.default_rng(31)
    q, qd, qdd = pm.random_motion(rng, pr.parse_model(explicit), np.linspace(0, 1, 7))
    R = _turn(120.0)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    out2 = rpr3gen.inverse_dynamics(turned, *_turn_motion(R, q, qd, qdd))
    nxt = dict(zip(LEGS, LEGS[1:] + LEGS[:1], strict=True))
    forces = max(float(np.max(np.abs(v))) for k, v in out.items() if k[0] == "f")
    for name, value in out.items():
        family, _, L = name.partition("_")
        if not L:  # conditioning, reach
            _close(out2[name], value, 1.0, name)
            continue
        if family[0] == "f":
            continue
        d = out2[f"{family}_{nxt[L]}"] - value
        if family in ("q1", "q2", "q3"):
            d = chk.wrap(d)
        scale = float(np.max(np.abs(value)))
        if family[0] == "m" or family == "tau":
            scale = max(scale, 1e-3 * forces)  # moments of passive joints are round-off
        assert float(np.max(np.abs(d))) / scale < 1e-12, name
    for j in "123":
        for L in LEGS:
            f = np.column_stack([out[f"fx{j}_{L}"], out[f"fy{j}_{L}"]])
            f2 = np.column_stack([out2[f"fx{j}_{nxt[L]}"], out2[f"fy{j}_{nxt[L]}"]])
            _close(f2, f @ R.T, forces, f"f{j}_{L}")


@pytest.mark.parametrize(("leg", "actuated"), STRUCTURES, ids=IDS)
def test_at_rest_the_loads_balance_gravity_and_the_payload(leg: str, actuated: int) -> None:
    data, q, _, _ = _case(leg, actuated)
    model = model_from_dict(data)
    zero = np.zeros_like(q)
    out = rpr3gen.inverse_dynamics(model, q, zero, zero)
    force, moment = chk.rest_residual(data, out, q)
    assert force < 1e-12
    assert moment < 1e-12
    weightless = model_from_dict({**data, "environment": {"gravity": [0.0, 0.0]}})
    tau = rpr3gen.actuator_efforts(weightless, q, zero, zero)
    held = rpr3gen.payload_efforts(model, q)
    _close(tau, held, float(np.max(np.abs(held))), "payload efforts")
