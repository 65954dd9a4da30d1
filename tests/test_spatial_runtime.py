"""Spatial robots through the runtime and the commands: the gallery's models and trajectories,
``simulate`` (CSV and figures), ``fk`` (assembly modes), the tracked forward kinematics on both
backends, ``generate --leg``, and the commands that do not serve spatial robots yet (one line).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen import control
from rpr3gen.backends import output_names
from rpr3gen.cli import main
from rpr3gen.errors import TrajectoryError

ROOT = Path(__file__).resolve().parent.parent
GALLERY = ("tsai-ups", "rus-hexapod", "pus-hexapod", "delta", "linear-delta")
COMMITTED = ("tsai-ups", "delta")


@pytest.fixture(autouse=True)
def _quick(quick_c_builds: None) -> None:
    """The C backend at -O0 (a spatial variant takes about a minute at -O3; same values)."""


def _model(name: str) -> rpr3gen.Model:
    return rpr3gen.load_model(ROOT / "models" / f"{name}.toml")


def _trajectory(name: str) -> rpr3gen.Trajectory:
    model = _model(name)
    return rpr3gen.read_trajectory_csv(ROOT / "models" / f"{name}.csv", pose=model.structure.pose)


@pytest.mark.parametrize("name", GALLERY)
def test_gallery_trajectory_stays_in_the_workspace(name: str) -> None:
    model = _model(name)
    traj = _trajectory(name)
    out = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    assert np.isfinite(out["conditioning"]).all()
    assert out["conditioning"].min() > 0.05
    # rest to rest: the efforts at both ends are the static ones at home
    for leg in model.structure.legs:
        tau = out[f"tau_{leg}"]
        assert tau[0] == pytest.approx(tau[-1], rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("name", COMMITTED)
def test_simulate_writes_every_joint_load_of_every_leg(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "out.csv"
    figures = tmp_path / "figs"
    code = main(["simulate", "--model", str(ROOT / "models" / f"{name}.toml"), "--trajectory",
                 str(ROOT / "models" / f"{name}.csv"), "--out", str(out), "--plots",
                 str(figures)])  # fmt: skip
    assert code == 0
    model = _model(name)
    with open(out, newline="") as f:
        header = next(csv.reader(f))
    assert header[: 1 + model.structure.dof] == ["t", *model.structure.pose]
    names = output_names(model)
    assert header[1 + model.structure.dof :] == list(names)
    joints = 5 if model.structure.leg.endswith("SS2") else 3
    for leg in model.structure.legs:
        for j in range(1, joints + 1):
            for kind in ("fx", "fy", "fz", "mx", "my", "mz"):
                assert f"{kind}{j}_{leg}" in header
    assert (figures / f"{name}_tau.png").is_file()
    summary = capsys.readouterr().out
    assert all(f"leg {leg}" in summary for leg in model.structure.legs)


def test_a_paper_trajectory_is_refused_for_a_spatial_robot(
    capsys: pytest.CaptureFixture,
) -> None:
    code = main(["simulate", "--model", str(ROOT / "models" / "delta.toml")])
    assert code != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "trajectory CSV" in err


def test_a_planar_trajectory_file_names_the_missing_column(tmp_path: Path) -> None:
    path = tmp_path / "t.csv"
    path.write_text("t,x,y,phi\n0,0,0,0\n")
    with pytest.raises(TrajectoryError, match="missing column 'z'"):
        rpr3gen.read_trajectory_csv(path, pose=("x", "y", "z"))


def test_fk_prints_the_delta_modes(capsys: pytest.CaptureFixture) -> None:
    model = _model("delta")
    q = np.array([0.05, -0.03, -0.04])
    qa = control.actuator_coordinates(model, q)[0]
    code = main(["fk", "--model", str(ROOT / "models" / "delta.toml"),
                 *(repr(float(v)) for v in qa)])  # fmt: skip
    assert code == 0
    text = capsys.readouterr().out.splitlines()
    lines = [line for line in text if not line.startswith("#")]
    poses = np.array([[float(v) for v in line.split()[:3]] for line in lines])
    assert len(poses) >= 1
    assert np.min(np.abs(poses - q).max(axis=1)) < 1e-9
    # the other sphere intersection, as a comment: every rod at its length, legs elsewhere
    others = [line[2:].split() for line in text[1:] if line.startswith("# ") and "(" not in line]
    assert len(poses) + len(others) == 2
    for other in others:
        o = np.array([float(v) for v in other])
        back = control.actuator_coordinates(model, o)[0]
        assert not (np.isfinite(back).all() and np.abs(back - qa).max() < 1e-9)


def test_delta_modes_are_both_sphere_intersections_in_the_working_mode() -> None:
    """Every mode gives the actuator coordinates back; the candidates not returned do not."""
    from rpr3gen.spatial_modes import delta_candidates

    model = _model("delta")
    q = np.array([0.02, 0.04, -0.06])
    qa = control.actuator_coordinates(model, q)[0]
    candidates = delta_candidates(model, qa)
    assert len(candidates) == 2
    modes = control.assembly_modes(model, qa)
    for c in candidates:
        back = control.actuator_coordinates(model, c)[0]
        is_mode = np.isfinite(back).all() and np.abs(back - qa).max() < 1e-9
        assert is_mode == any(np.abs(c - m).max() < 1e-9 for m in modes)


def test_fk_takes_one_reading_per_leg(capsys: pytest.CaptureFixture) -> None:
    code = main(["fk", "--model", str(ROOT / "models" / "tsai-ups.toml"), "0", "0", "0"])
    assert code != 0
    assert "takes 6 actuator coordinates" in capsys.readouterr().err


@pytest.mark.parametrize("name", GALLERY)
@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_tracked_forward_kinematics_round_trip(name: str, backend: str) -> None:
    model = _model(name)
    traj = _trajectory(name)
    q = traj.q[::20]
    qa = control.actuator_coordinates(model, q, backend)
    near = np.vstack([q[:1], q[:-1]])  # the previous sample: the controller's reference
    found = control.forward_kinematics(model, qa, near, backend)
    assert np.allclose(found, q, rtol=0, atol=1e-9)


def test_hexapod_search_includes_the_tracked_pose() -> None:
    model = _model("tsai-ups")
    q = np.array([0.05, 0.02, 0.03, 0.05, -0.04, 0.1])
    qa = control.actuator_coordinates(model, q)[0]
    modes = control.assembly_modes(model, qa)
    assert np.min(np.abs(modes - q).max(axis=1)) < 1e-9
    back = control.actuator_coordinates(model, modes)
    assert np.allclose(back, qa, atol=1e-9)


def test_generate_one_spatial_variant(tmp_path: Path) -> None:
    assert main(["generate", "--leg", "RSS2", "--actuated", "1", "--out", str(tmp_path)]) == 0
    manifest = (tmp_path / "rss2_1" / "manifest.json").read_text()
    assert '"DOF": "3"' in manifest
    committed = (ROOT / "generated" / "rss2_1" / "rpr3.c").read_text()
    assert (tmp_path / "rss2_1" / "rpr3.c").read_text() == committed


def test_generate_refuses_a_wrong_actuated_joint(capsys: pytest.CaptureFixture) -> None:
    assert main(["generate", "--leg", "UPS", "--actuated", "1", "--out", "x"]) != 0
    assert "joint 2" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["tsai-ups", "delta"])
def test_animate_draws_a_spatial_robot_in_3d(name: str, tmp_path: Path) -> None:
    from PIL import Image

    out = tmp_path / f"{name}.gif"
    args = ["animate", "--model", str(ROOT / "models" / f"{name}.toml"), "--trajectory",
            str(ROOT / "models" / f"{name}.csv"), "--out", str(out), "--fps", "4", "--size",
            "240x240", "--loads"]  # fmt: skip
    assert main(args) == 0
    with Image.open(out) as movie:
        assert movie.size == (240, 240)
        frames = []
        for k in range(movie.n_frames):
            movie.seek(k)
            frames.append(np.asarray(movie.convert("L")))
    traj = _trajectory(name)
    assert len(frames) == int((traj.t[-1] - traj.t[0]) * 4) + 1
    assert any(np.any(f != frames[0]) for f in frames[1:])  # the robot moves


def test_params_prints_the_spatial_parameter_vector(capsys: pytest.CaptureFixture) -> None:
    assert main(["params", "--model", str(ROOT / "models" / "delta.toml")]) == 0
    lines = capsys.readouterr().out.splitlines()
    model = _model("delta")
    assert [line.split()[0] for line in lines] == list(model.param_names)
    assert [float(line.split()[1]) for line in lines] == list(model.vector())
