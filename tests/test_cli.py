"""The `rpr3gen` command end to end: simulate, paper, and its errors."""

from __future__ import annotations

import csv
import importlib.metadata
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.trajectory import Trajectory, write_trajectory_csv

HEADER = ["t", "x", "y", "phi", *rpr3gen.OUTPUT_NAMES]


def _read(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize("name", ["rotation", "rectilinear"])
def test_simulate_paper_trajectory_writes_csv_and_figures(name: str, tmp_path: Path) -> None:
    out, figs = tmp_path / "r.csv", tmp_path / "figs"
    assert main(["simulate", "--trajectory", name, "--out", str(out), "--plots", str(figs)]) == 0
    header, table = _read(out)
    assert header == HEADER
    assert table.shape == (301, len(HEADER))
    traj = rpr3gen.paper_trajectory(name)
    expected = rpr3gen.inverse_dynamics(rpr3gen.load_model(), traj.q, traj.qd, traj.qdd)
    np.testing.assert_array_equal(table[:, 0], traj.t)
    for k, column in enumerate(rpr3gen.OUTPUT_NAMES, start=4):
        np.testing.assert_array_equal(table[:, k], expected[column], err_msg=column)
    pngs = sorted(p.name for p in figs.glob("*.png"))
    for family in ("f10x", "f10y", "f21y", "m21", "f32y", "f32z", "m10"):
        assert f"{name}_{family}.png" in pngs


def test_simulate_model_file_and_trajectory_file(tmp_path: Path, repo_root: Path) -> None:
    model = tmp_path / "slide.toml"
    text = (repo_root / "models" / "paper.toml").read_text()
    model.write_text(text.replace('actuation = "revolute"', 'actuation = "prismatic"'))
    t = np.linspace(0.0, 1.0, 50)
    w = 2 * np.pi
    q = np.stack([0.02 * np.sin(w * t), 0.01 * np.cos(w * t), 0.1 * np.sin(w * t)], axis=1)
    qd = np.stack([0.02 * w * np.cos(w * t), -0.01 * w * np.sin(w * t), 0.1 * w * np.cos(w * t)], 1)
    qdd = -(w**2) * q
    motion = tmp_path / "motion.csv"
    write_trajectory_csv(motion, Trajectory(t, q, qd, qdd))
    out, figs = tmp_path / "out.csv", tmp_path / "figs"
    argv = ["simulate", "--model", str(model), "--trajectory", str(motion), "--out", str(out)]
    assert main([*argv, "--plots", str(figs)]) == 0
    header, table = _read(out)
    assert header == HEADER
    assert table.shape == (50, len(HEADER))
    assert np.all(table[:, HEADER.index("m10_A")] == 0.0)  # passive base joint
    assert np.any(table[:, HEADER.index("f21z_A")] != 0.0)  # the actuated slide
    assert (figs / "motion_f21z.png").is_file()


def test_paper_command_runs_both_examples(tmp_path: Path) -> None:
    assert main(["paper", "--out", str(tmp_path)]) == 0
    for name in ("rotation", "rectilinear"):
        header, _ = _read(tmp_path / f"{name}.csv")
        assert header == HEADER
        assert (tmp_path / "figures" / f"{name}_f32z.png").is_file()


def _cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", *args], capture_output=True, text=True, cwd=cwd
    )


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["simulate", "--model", "missing.toml"], "missing.toml"),
        (["simulate", "--trajectory", "nowhere.csv"], "nowhere.csv"),
        (["simulate", "--trajectory", "spiral"], "spiral"),
        (["simulate", "--samples", "1"], "samples"),
    ],
)
def test_errors_are_one_line_without_traceback(
    args: list[str], expected: str, tmp_path: Path
) -> None:
    result = _cli(*args, cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert expected in result.stderr
    assert "Traceback" not in result.stderr


def test_bad_trajectory_leaves_existing_output_untouched(tmp_path: Path) -> None:
    out = tmp_path / "keep.csv"
    out.write_text("precious\n")
    bad = tmp_path / "bad.csv"
    bad.write_text(
        "t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi\n0,0,0,0,0,0,0,0,0,0\n1,0,0,nan,0,0,0,0,0,0\n"
    )
    result = _cli("simulate", "--trajectory", str(bad), "--out", str(out), cwd=tmp_path)
    assert result.returncode == 2
    assert "phi" in result.stderr
    assert out.read_text() == "precious\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv", "keep.csv"]


def test_singular_pose_is_refused_with_its_time(tmp_path: Path) -> None:
    # The last sample puts the platform joint B3 on the base pivot B1: leg B has zero length.
    model = rpr3gen.load_model()
    p = model.params
    x = p["xB1"] - p["xB3"]
    y = p["yB1"] - p["yB3"]
    t = np.array([0.0, 0.5, 1.0])
    q = np.array([[0.0, 0.0, 0.0], [x / 4, y / 4, 0.0], [x, y, 0.0]])  # (x, y) t^2
    qd = np.outer(2 * t, [x, y, 0.0])
    qdd = np.tile([2 * x, 2 * y, 0.0], (3, 1))
    motion = tmp_path / "through.csv"
    write_trajectory_csv(motion, Trajectory(t, q, qd, qdd))
    out = tmp_path / "o.csv"
    result = _cli("simulate", "--trajectory", str(motion), "--out", str(out), cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith("rpr3gen: error: t = 1 s"), result.stderr
    assert "leg B" in result.stderr
    assert not out.exists()


@pytest.mark.parametrize("command", ["simulate", "params", "paper"])
def test_a_reader_that_went_away_ends_the_command_quietly(command: str, tmp_path: Path) -> None:
    # As `rpr3gen simulate | head -0`: the pipe's reader is gone before the first line.
    read_end, write_end = os.pipe()
    os.close(read_end)
    args = [command, "--out", str(tmp_path / "paper")] if command == "paper" else [command]
    try:
        result = subprocess.run(
            [sys.executable, "-m", "rpr3gen.cli", *args],
            stdout=write_end, stderr=subprocess.PIPE, text=True, check=False, cwd=tmp_path,
        )  # fmt: skip
    finally:
        os.close(write_end)
    assert result.stderr == ""
    assert result.returncode == 0
    if command == "paper":  # the files were complete before the summary was printed
        assert (tmp_path / "paper" / "rectilinear.csv").is_file()


# -- options are checked, not ignored ----------------------------------------------------------


@pytest.mark.parametrize("value", ["2", "1", "-0.1", "nan", "x"])
def test_min_conditioning_is_range_checked_before_any_work(value: str, tmp_path: Path) -> None:
    result = _cli("simulate", "--min-conditioning", value, "--out", "o.csv", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert "--min-conditioning" in result.stderr
    assert "t = " not in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_min_conditioning_zero_is_allowed(tmp_path: Path) -> None:
    assert main(["simulate", "--min-conditioning", "0", "--out", str(tmp_path / "o.csv")]) == 0


@pytest.mark.parametrize("option", [["--samples", "11"], ["--duration", "2"]])
def test_paper_trajectory_options_with_a_csv_file_are_an_error(
    option: list[str], tmp_path: Path
) -> None:
    motion = tmp_path / "motion.csv"
    write_trajectory_csv(motion, rpr3gen.paper_trajectory("rectilinear", samples=11))
    result = _cli("simulate", "--trajectory", str(motion), *option, cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert option[0] in result.stderr
    assert "motion.csv" in result.stderr


def test_samples_and_duration_apply_to_a_paper_trajectory(capsys: pytest.CaptureFixture) -> None:
    assert main(["simulate", "--samples", "11", "--duration", "2"]) == 0
    assert "rotation: 11 samples over 2 s" in capsys.readouterr().out


def test_a_mistyped_trajectory_name_gets_a_suggestion(tmp_path: Path) -> None:
    result = _cli("simulate", "--trajectory", "rotaton", cwd=tmp_path)
    assert result.returncode == 2
    assert "did you mean 'rotation'?" in result.stderr


def test_help_gives_every_default_and_the_units(capsys: pytest.CaptureFixture) -> None:
    for command in ("simulate", "paper", "params", "generate"):
        with pytest.raises(SystemExit) as info:
            main([command, "--help"])
        assert info.value.code == 0
        text = " ".join(capsys.readouterr().out.split())
        options = re.split(r" (?=--[a-z])", text.split("options: ", 1)[1])[1:]
        assert len(options) > 1, text
        for option in options[1:]:  # after --help, each option's help ends with its default
            assert "(default: " in option, (command, option)
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "duration of a paper trajectory, s (default: 3)" in text
    assert "(dimensionless, 0 = singular, 1 = best)" in text
    assert "(default: 0.001)" in text


def test_bare_command_prints_the_usage(tmp_path: Path) -> None:
    result = _cli(cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith("usage: rpr3gen")
    for command in ("simulate", "paper", "params", "generate"):
        assert command in result.stderr


def test_version(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out == f"rpr3gen {rpr3gen.__version__}\n"
    assert rpr3gen.__version__ == importlib.metadata.version("rpr3gen")


# -- errors name the user's files --------------------------------------------------------------


def test_output_paths_in_the_way_are_refused_before_any_work(tmp_path: Path) -> None:
    (tmp_path / "afile").write_text("")
    (tmp_path / "adir").mkdir()
    cases = [
        (["--out", "adir"], "adir: cannot write the CSV: it is a folder"),
        (["--plots", "afile"], "afile: cannot write the figures: it is a file, not a folder"),
        (["--out", "afile/x.csv"], "afile/x.csv: cannot write the CSV: afile is a file"),
        (["--out", "new.csv", "--plots", "afile/sub"], "afile/sub: cannot write the figures"),
    ]
    for args, message in cases:
        result = _cli("simulate", *args, cwd=tmp_path)
        assert result.returncode == 2
        assert result.stderr.startswith(f"rpr3gen: error: {message}"), result.stderr
        assert result.stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir", "afile"]
    assert list((tmp_path / "adir").iterdir()) == []


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
def test_an_unwritable_out_names_the_users_file(tmp_path: Path) -> None:
    result = _cli("simulate", "--out", "/proc/x.csv", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith("rpr3gen: error: /proc/x.csv: cannot write the CSV: ")
    assert ".tmp" not in result.stderr


# -- what --allow-invalid dropped is reported --------------------------------------------------


@pytest.mark.parametrize(
    ("name", "threshold", "spans"),
    [
        ("rectilinear", "0.8", ((182, 300),)),  # conditioning falls all along this motion
        ("rotation", "0.98", ((0, 90), (240, 300))),  # ... and rises, then falls, along this one
    ],
)
def test_allow_invalid_reports_how_many_rows_were_refused_and_when(
    name: str,
    threshold: str,
    spans: tuple[tuple[int, int], ...],
    tmp_path: Path,
    capsys: pytest.CaptureFixture,
) -> None:
    out_csv = tmp_path / "o.csv"
    argv = [
        "simulate",
        "--trajectory",
        name,
        "--min-conditioning",
        threshold,
        "--out",
        str(out_csv),
    ]
    assert main([*argv, "--allow-invalid"]) == 0
    captured = capsys.readouterr()
    traj = rpr3gen.paper_trajectory(name)
    conditioning = rpr3gen.inverse_dynamics(rpr3gen.load_model(), traj.q, traj.qd, traj.qdd)[
        "conditioning"
    ]
    refused = conditioning < float(threshold)
    expected = np.zeros(len(traj), dtype=bool)
    for first, last in spans:
        expected[first : last + 1] = True
    np.testing.assert_array_equal(refused, expected)  # the spans above are the right ones
    when = ", ".join(f"{traj.t[a]:.6g} to {traj.t[b]:.6g} s" for a, b in spans)
    count = int(expected.sum())
    line = f"{count} of 301 samples refused and written as NaN, t = {when} (first: conditioning"
    assert captured.err.count("\n") == 1, captured.err
    assert captured.err.startswith(f"rpr3gen: warning: {name}: {line}")
    assert line in captured.out
    assert f"the peaks are of the {301 - count} others" in captured.out
    _, table = _read(out_csv)
    np.testing.assert_array_equal(np.isnan(table[:, HEADER.index("m10_A")]), expected)
    # Without the flag: refused at the first of them, nothing written.
    out_csv.unlink()
    assert main(argv) == 2
    assert f"t = {traj.t[spans[0][0]]:.6g} s (sample {spans[0][0] + 1} of 301)" in (
        capsys.readouterr().err
    )
    assert not out_csv.exists()
