"""Serial (leg) singularities: a piston joint on or behind its base pivot is refused everywhere.

The measure is the output ``reach = min_i (l0 + lambda21_i) / l0`` (derive/rpr3/kinematics.py):
1 in the central configuration, not positive once a piston joint A2 reaches its base pivot A1.
Refusing those poses keeps every leg at least l2 long, clear of |A1A3| = 0, where the leg's
direction is undefined and the loads grow without bound.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import newton_euler as ne
import numpy as np
import pytest

import rpr3gen
from rpr3gen.trajectory import Trajectory, write_trajectory_csv

ACTUATIONS = ("revolute", "prismatic")


def _model(actuation: str) -> rpr3gen.Model:
    return dataclasses.replace(rpr3gen.load_model(), actuation=actuation)


def _pose_with_extension(model: rpr3gen.Model, leg: str, extension: float) -> np.ndarray:
    """A pose (phi = 0) on the line from the centre towards leg's base pivot, where
    l0 + lambda21 of that leg equals ``extension`` (m)."""
    p = model.params
    a1 = np.array([p[f"x{leg}1"], p[f"y{leg}1"]])
    a3 = np.array([p[f"x{leg}3"], p[f"y{leg}3"]])  # platform frame = world at phi = 0
    direction = (a1 - a3) / np.linalg.norm(a1 - a3)
    length = extension + p["l2"]  # |A1A3| wanted
    g = a1 - a3 - length * direction
    return np.array([g[0], g[1], 0.0])


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_reach_agrees_with_the_reference_kinematics(actuation: str) -> None:
    model = _model(actuation)
    _, q, qd, qdd = ne.paper_motion("rectilinear", 31, 3.0)
    out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
    kin = ne.kinematics(model.params, q, qd, qdd)
    l0 = model.params["l0"]
    lambdas = np.stack([kin[leg]["lambda21"] for leg in ne.LEGS], axis=1)
    expected = np.min((l0 + lambdas) / l0, axis=1)
    np.testing.assert_allclose(out["reach"], expected, rtol=1e-13)


@pytest.mark.parametrize("actuation", ACTUATIONS)
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_piston_behind_its_pivot_is_refused(actuation: str, backend: str) -> None:
    model = _model(actuation)
    ok = _pose_with_extension(model, "B", 0.01)  # A2 1 cm in front of B1
    behind = _pose_with_extension(model, "B", -0.01)  # 1 cm behind: the leg is still 0.19 m
    onto = _pose_with_extension(model, "B", -model.params["l2"])  # |B1B3| = 0 (the pose)
    q = np.stack([ok, behind, onto])
    z = np.zeros_like(q)
    (out,), codes = rpr3gen.evaluate(model, "inverse_dynamics", (q, z, z), backend=backend)
    assert codes.tolist() == [0, 2, 2]
    assert np.isfinite(out[0]).all()
    assert np.isnan(out[1:]).all()
    ev = rpr3gen.SampleEvaluator(model, backend=backend)
    for pose, code in zip(q, [0, 2, 2], strict=True):
        ev.q[:] = pose
        before = ev.out.copy()
        assert ev() == code
        if code:
            assert np.array_equal(ev.out, before, equal_nan=True)


def test_the_paper_robot_with_a_leg_on_its_pivot_is_refused_by_the_cli(tmp_path: Path) -> None:
    # The pose: (0, -0.3, 0) puts A3 = (0.2598, 0.15) - (0, 0.3) on A1 = (0.2598, -0.15).
    t = np.array([0.0, 1.0])
    q = np.array([[0.0, 0.0, 0.0], [0.0, -0.3, 0.0]])
    z = np.zeros_like(q)
    motion = tmp_path / "m.csv"
    write_trajectory_csv(motion, Trajectory(t, q, z, z))
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "simulate", "--trajectory", str(motion)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 2
    assert "t = 1 s" in result.stderr
    assert "leg A" in result.stderr
    assert "behind its base pivot" in result.stderr
