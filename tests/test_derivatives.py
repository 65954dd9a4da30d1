"""Trajectories of positions only: derivatives from a quintic spline; given ones are checked."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.atomic import write_csv_table
from rpr3gen.cli import main
from rpr3gen.derivatives import MIN_SAMPLES, mismatch
from rpr3gen.errors import InputError, InputTypeError, TrajectoryError, TrajectoryWarning
from rpr3gen.trajectory import (
    POSITION_COLUMNS,
    Trajectory,
    paper_trajectory,
    read_trajectory_csv,
    write_trajectory_csv,
)


def _positions_file(path: Path, traj: Trajectory) -> Path:
    write_csv_table(path, POSITION_COLUMNS, np.column_stack([traj.t, traj.q]))
    return path


def _relative(derived: np.ndarray, exact: np.ndarray) -> float:
    return float(np.abs(derived - exact).max() / np.abs(exact).max())


# Largest error of the derived velocities and accelerations, relative to the analytic peak, on
# the paper's motions sampled every 10 ms (301 samples) and every 100 ms (31 samples).
TOLERANCE = {301: (1e-9, 1e-7), 31: (1e-5, 1e-3)}


@pytest.mark.parametrize("samples", sorted(TOLERANCE))
@pytest.mark.parametrize("name", ["rotation", "rectilinear"])
def test_paper_trajectory_as_positions_only(name: str, samples: int, tmp_path: Path) -> None:
    exact = paper_trajectory(name, samples=samples)
    traj = read_trajectory_csv(_positions_file(tmp_path / "p.csv", exact))
    np.testing.assert_array_equal(traj.t, exact.t)
    np.testing.assert_array_equal(traj.q, exact.q)  # the spline passes through the file's
    velocity, acceleration = TOLERANCE[samples]
    assert _relative(traj.qd, exact.qd) < velocity
    assert _relative(traj.qdd, exact.qdd) < acceleration


def test_smoothing_measured_positions() -> None:
    exact = paper_trajectory("rectilinear")
    noise = 1e-6  # m and rad, RMS
    measured = exact.q + np.random.default_rng(7).normal(0.0, noise, exact.q.shape)
    followed = Trajectory.from_positions(exact.t, measured)  # through every noisy sample
    smoothed = Trajectory.from_positions(exact.t, measured, smoothing=noise)
    assert _relative(followed.qdd, exact.qdd) > 1.0  # the noise, amplified
    assert _relative(smoothed.qd, exact.qd) < 1e-3
    assert _relative(smoothed.qdd, exact.qdd) < 1e-2
    assert np.sqrt(np.mean((smoothed.q - measured) ** 2)) <= 1.001 * noise


def test_a_smoothing_too_small_for_the_noise_is_reported() -> None:
    exact = paper_trajectory("rectilinear")
    measured = exact.q + np.random.default_rng(0).normal(0.0, 1e-5, exact.q.shape)
    with pytest.warns(TrajectoryWarning, match=r"spline of (x|y|phi) could not meet smoothing"):
        Trajectory.from_positions(exact.t, measured, smoothing=1e-8, source="m.csv")


def test_cli_runs_a_positions_only_file(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    exact = paper_trajectory("rectilinear")
    motion = _positions_file(tmp_path / "planned.csv", exact)
    out = tmp_path / "out.csv"
    assert main(["simulate", "--trajectory", str(motion), "--out", str(out)]) == 0
    assert capsys.readouterr().err == ""
    table = np.genfromtxt(out, delimiter=",", names=True)
    want = rpr3gen.inverse_dynamics(rpr3gen.load_model(), exact.q, exact.qd, exact.qdd)
    for name in ("m10_A", "f10y_B", "f32z_C"):
        assert _relative(table[name], want[name]) < 1e-6, name
    smoothed = ["simulate", "--trajectory", str(motion), "--smoothing", "1e-6"]
    assert main(smoothed) == 0


def _wrong(traj: Trajectory, qd: np.ndarray, qdd: np.ndarray) -> Trajectory:
    return Trajectory(traj.t, traj.q, qd, qdd)


ROTATION = paper_trajectory("rotation")
RECTILINEAR = paper_trajectory("rectilinear")
WRONG = {
    "degrees": (
        _wrong(ROTATION, np.rad2deg(ROTATION.qd), ROTATION.qdd),
        "dphi with phi, ddphi with dphi",
    ),
    "no-accelerations": (_wrong(ROTATION, ROTATION.qd, 0 * ROTATION.qdd), "ddphi with dphi"),
    "at-rest": (_wrong(ROTATION, 0 * ROTATION.qd, 0 * ROTATION.qdd), "dphi with phi"),
    "sign": (_wrong(RECTILINEAR, -RECTILINEAR.qd, -RECTILINEAR.qdd), "dx with x, dy with y"),
    "swapped": (
        _wrong(RECTILINEAR, RECTILINEAR.qd[:, [1, 0, 2]], RECTILINEAR.qdd[:, [1, 0, 2]]),
        "dx with x, dy with y",
    ),
}


@pytest.mark.parametrize(("traj", "pairs"), WRONG.values(), ids=WRONG.keys())
def test_wrong_derivatives_give_a_warning(traj: Trajectory, pairs: str, tmp_path: Path) -> None:
    path = tmp_path / "wrong.csv"
    write_trajectory_csv(path, traj)
    with pytest.warns(TrajectoryWarning) as caught:
        back = read_trajectory_csv(path)
    (warning,) = caught
    message = str(warning.message)
    assert message.startswith(f"{path}: velocities or accelerations disagree with the positions")
    assert f"({pairs})" in message
    assert "\n" not in message
    np.testing.assert_array_equal(back.qd, traj.qd)  # used as given


@pytest.mark.parametrize("samples", [4, 6, 11, 301])
@pytest.mark.parametrize("name", ["rotation", "rectilinear"])
def test_right_derivatives_pass_the_check(name: str, samples: int) -> None:
    traj = paper_trajectory(name, samples=samples)
    assert mismatch(traj.t, traj.q, traj.qd, traj.qdd) is None


def test_cli_prints_the_warning_as_one_line(tmp_path: Path) -> None:
    path = tmp_path / "wrong.csv"
    write_trajectory_csv(path, WRONG["degrees"][0])
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "simulate", "--trajectory", str(path)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stderr.count("\n") == 1, result.stderr
    assert result.stderr.startswith(f"rpr3gen: warning: {path}: velocities or accelerations")
    assert "wrong: 301 samples" in result.stdout


def test_bad_positions_only_input(tmp_path: Path) -> None:
    exact = paper_trajectory("rotation", samples=MIN_SAMPLES - 1)
    short = _positions_file(tmp_path / "short.csv", exact)
    with pytest.raises(
        TrajectoryError, match=f"5 samples of positions only.*at least {MIN_SAMPLES}"
    ):
        read_trajectory_csv(short)
    full = tmp_path / "full.csv"
    write_trajectory_csv(full, paper_trajectory("rotation"))
    with pytest.raises(TrajectoryError, match="smoothing is for a file of positions only"):
        read_trajectory_csv(full, smoothing=0.0)
    good = _positions_file(tmp_path / "good.csv", paper_trajectory("rotation"))
    with pytest.raises(InputTypeError, match="smoothing"):
        read_trajectory_csv(good, smoothing="0.1")  # type: ignore[arg-type]
    for value in (-1e-3, float("nan"), float("inf")):
        with pytest.raises(InputError, match="smoothing"):
            read_trajectory_csv(good, smoothing=value)
    partial = tmp_path / "partial.csv"
    partial.write_text("t,x,y,phi,dx,dy,dphi\n0,0,0,0,0,0,0\n")
    with pytest.raises(TrajectoryError, match="missing column 'ddx'"):
        read_trajectory_csv(partial)
    with pytest.raises(TrajectoryError, match="strictly increasing"):
        Trajectory.from_positions(np.zeros(6), np.zeros((6, 3)))


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--smoothing", "1e-3"], "--smoothing: only for a trajectory CSV file"),
        (["--trajectory", "FULL", "--smoothing", "1e-3"], "smoothing is for a file of positions"),
        (["--trajectory", "SHORT"], "at least 6"),
        (["--trajectory", "FULL", "--smoothing", "-1"], "--smoothing: must be a number in [0"),
    ],
)
def test_cli_smoothing_errors(args: list[str], needle: str, tmp_path: Path) -> None:
    write_trajectory_csv(tmp_path / "full.csv", paper_trajectory("rotation"))
    _positions_file(tmp_path / "short.csv", paper_trajectory("rotation", samples=5))
    paths = {"FULL": str(tmp_path / "full.csv"), "SHORT": str(tmp_path / "short.csv")}
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "simulate", *[paths.get(a, a) for a in args]],
        capture_output=True, text=True, check=False, cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert needle in result.stderr
