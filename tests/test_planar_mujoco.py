"""Peer check (extra ``peers``): MuJoCo against the generated forward dynamics.

A 3-RRR (the gallery's ``models/rrr.toml``, base motors) and a 3-PRR (a random one with its
motors on the base slides) are built in MuJoCo from the model (``tests/mujoco_planar.py``: open
chains, each loop closed at joint 3 by a ``connect`` equality, one motor per leg), started at
the same state and driven by the same constant efforts (those that hold the start pose, plus
a few percent of their peak with random signs) for 0.3 s. MuJoCo integrates with RK4 at 1 ms
(stiff closures, Newton solver); the generated ``forward_dynamics`` (NumPy, through the public
API) is integrated by RK4 at 10 ms. The two platforms stay together: measured at most 8.9e-9 m
and 2.9e-8 rad apart (3-RRR) and 1.9e-8 m, 4.7e-8 rad (3-PRR), while the platforms travel 7 and
18 mm, 0.026 rad (3-RRR) and 4 and 32 mm, 0.023 rad (3-PRR); MuJoCo's loops stay closed within
8e-9 m. With the generated dynamics at 5 ms the gaps drop to 5.4e-9 m and 7.4e-9 rad (both):
what remains is the integrations' discretisation and MuJoCo's soft closures. At a state of the
motion, MuJoCo's open-tree inverse dynamics with the loops as rigid constraints gives the
generated efforts and joint-3 forces to 4e-16 of the largest.
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
    from . import mujoco_planar as mp
    from . import planar_models as pm
    from . import planar_reference as pr
except ImportError:
    import mujoco_planar as mp
    import planar_models as pm
    import planar_reference as pr

mujoco = pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parent.parent
LEGS = pr.LEGS


def _gallery_rrr() -> dict:
    with (ROOT / "models" / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    data.pop("symmetric")
    data["legs"] = pr.expand_symmetric(data["legs"]["A"])
    return data


@functools.cache
def _case(name: str):
    """Model dict, runtime model, start pose and rate, efforts."""
    if name == "RRR":
        data = _gallery_rrr()
        q0 = np.array([0.01, -0.015, 0.08])
    else:
        data = pm.random_model(np.random.default_rng(77), "PRR", 1)
        q0 = np.array([-0.01, 0.005, -0.05])
    model = model_from_dict(data)
    robot = pr.parse_model(data)
    assert pm.motion_ok(robot, q0[None])
    qd0 = np.array([0.05, -0.04, 0.3])
    zero = np.zeros(3)
    tau = rpr3gen.actuator_efforts(model, q0, zero, zero)[0]
    rng = np.random.default_rng(5)
    tau = tau + 0.06 * np.max(np.abs(tau)) * rng.choice([-1.0, 1.0], 3) * rng.uniform(0.5, 1, 3)
    return data, model, robot, q0, qd0, tau


@pytest.mark.parametrize("name", ["RRR", "PRR"])
def test_mujoco_rigid_inverse_dynamics_gives_the_generated_loads(name: str) -> None:
    _, model, robot, q0, qd0, _ = _case(name)
    qdd0 = np.array([0.3, -0.2, 1.5])
    mj_model, mj_data = mp.compile_model(robot)
    tau, force = mp.rigid_inverse_dynamics(robot, mj_model, mj_data, q0, qd0, qdd0)
    out = rpr3gen.inverse_dynamics(model, q0, qd0, qdd0)
    f3 = np.array([[out[f"fx3_{L}"][0], out[f"fy3_{L}"][0]] for L in LEGS])
    ours = np.array([out[f"tau_{L}"][0] for L in LEGS])
    scale = max(np.max(np.abs(f3)), np.max(np.abs(ours)))
    assert np.max(np.abs(tau - ours)) < 1e-12 * scale
    assert np.max(np.abs(force - f3)) < 1e-12 * scale


def _drive(name: str, duration: float = 0.3, step: float = 10e-3):
    """Both integrations; the largest distances between the platforms' G (m) and angles (rad)
    at the steps, MuJoCo's largest loop-closure error (m), and the generated run's poses."""
    _, model, robot, q0, qd0, tau = _case(name)
    mj_model, mj_data = mp.compile_model(robot)
    mp.set_state(robot, mj_model, mj_data, q0, qd0)
    mj_data.ctrl[:] = tau
    per_step = round(step / mj_model.opt.timestep)

    def rate(state: np.ndarray) -> np.ndarray:
        qdd = rpr3gen.forward_dynamics(model, state[:3], state[3:], tau)[0]
        return np.concatenate([state[3:], qdd])

    state = np.concatenate([q0, qd0])
    poses = [state[:3]]
    position = angle = closure = 0.0
    for _ in range(round(duration / step)):
        k1 = rate(state)
        k2 = rate(state + step / 2 * k1)
        k3 = rate(state + step / 2 * k2)
        k4 = rate(state + step * k3)
        state = state + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        for _ in range(per_step):
            mujoco.mj_step(mj_model, mj_data)
        pose = mp.platform_state(mj_model, mj_data)[0]
        position = max(position, math.hypot(*(pose[:2] - state[:2])))
        angle = max(angle, abs(pose[2] - state[2]))
        closure = max(closure, mp.closure_error(mj_model, mj_data))
        poses.append(state[:3])
    return position, angle, closure, np.array(poses)


@pytest.mark.parametrize("name", ["RRR", "PRR"])
def test_mujoco_moves_like_the_generated_forward_dynamics(name: str) -> None:
    position, angle, closure, poses = _drive(name)
    assert np.all(np.isfinite(poses))
    assert pm.motion_ok(_case(name)[2], poses)  # away from singularities all the way
    travel = np.max(np.abs(poses - poses[0]), axis=0)
    assert travel[:2].max() > 0.01  # a real motion, far beyond the bounds below
    assert travel[2] > 0.02
    assert position < 5e-8
    assert angle < 2e-7
    assert closure < 5e-8
