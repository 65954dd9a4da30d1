"""Spatial robots' joint limits (``[limits]`` in the model file): read, enforced by ``simulate``
and kept by ``excite``, judged by the joint coordinates of the independent reference
(``tests/spatial_reference.py``)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.cli import main

try:
    from . import spatial_reference as sr
except ImportError:
    import spatial_reference as sr

ROOT = Path(__file__).resolve().parents[1]


def _data(name: str) -> dict:
    return tomllib.loads((ROOT / "models" / f"{name}.toml").read_text())


def test_limits_are_read_for_every_leg_or_one() -> None:
    data = _data("tsai-ups")
    data["limits"] = {"q2": [-0.05, 0.05], "B.q2": [-0.02, 0.03], "A.q1a": [-0.5, 0.5]}
    model = rpr3gen.model_from_dict(data, source="limited")
    assert model.limits is not None
    assert model.limits["B.q2"] == (-0.02, 0.03)
    assert model.limits["C.q2"] == (-0.05, 0.05)
    assert model.limits["A.q1a"] == (-0.5, 0.5)
    assert "B.q1a" not in model.limits


def _first_outside(data: dict, q: np.ndarray, family: str, lo: float, hi: float) -> tuple:
    """The first sample and leg where the reference's joint coordinate leaves ``[lo, hi]``."""
    coords = sr.inverse_kinematics(data, q)
    for i in range(len(q)):
        for leg in sr.leg_names(data["leg"]):
            value = coords[f"{family}_{leg}"][i]
            if not lo <= value <= hi:
                return i, leg
    raise AssertionError("the trajectory stays within the limits")


def test_simulate_names_the_first_sample_outside_a_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    data = _data("tsai-ups")
    traj = rpr3gen.read_trajectory_csv(
        ROOT / "models" / "tsai-ups.csv", pose=("x", "y", "z", "a", "b", "c")
    )
    coords = sr.inverse_kinematics(data, traj.q)
    stroke = max(np.abs(coords[f"q2_{leg}"]).max() for leg in sr.leg_names("UPS"))
    bound = float(0.6 * stroke)
    limited = copy.deepcopy(data)
    limited["limits"] = {"q2": [-bound, bound]}
    model_file = tmp_path / "limited.toml"
    text = (ROOT / "models" / "tsai-ups.toml").read_text()
    model_file.write_text(text + f"\n[limits]\nq2 = [{-bound!r}, {bound!r}]\n")
    out = tmp_path / "out"
    code = main(["simulate", "--model", str(model_file), "--trajectory",
                 str(ROOT / "models" / "tsai-ups.csv"), "--out", str(out)])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code != 0
    assert len(err.splitlines()) == 1
    i, leg = _first_outside(limited, traj.q, "q2", -bound, bound)
    assert f"sample {i + 1} of" in err
    assert f"q2_{leg}" in err
    assert f"limits.{leg}.q2" in err
    assert not out.exists()


def test_excite_keeps_a_delta_within_its_arm_limits() -> None:
    data = _data("delta")
    data["limits"] = {"q1": [-0.15, 0.15]}
    model = rpr3gen.model_from_dict(data, source="limited delta")
    found = rpr3gen.excite(model, harmonics=2, samples=41, max_iterations=8)
    coords = sr.inverse_kinematics(data, found.trajectory.q)
    for leg in "ABC":
        assert np.abs(coords[f"q1_{leg}"]).max() <= 0.15 + 1e-9
        lo, hi = found.ranges[f"q1_{leg}"]
        assert -0.15 <= lo <= hi <= 0.15
