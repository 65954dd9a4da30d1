"""Singular poses, stroke limits, and refusing bad input without losing existing output."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import newton_euler as ne
import numpy as np
import pytest

import rpr3gen
from rpr3gen.atomic import write_csv_table
from rpr3gen.cli import main
from rpr3gen.model import Model, model_from_dict
from rpr3gen.trajectory import POSITION_COLUMNS

LEG_ANGLES = np.deg2rad([30.0, 150.0, 270.0])


def _conditioning_reference(params, actuation: str, q) -> np.ndarray:
    """Hadamard ratio of the rows (u, (A3 - G) x u / rho), u = n or e, from ne.kinematics."""
    kin = ne.kinematics(params, q, np.zeros_like(q))
    rho = math.sqrt(sum(params[f"x{g}3"] ** 2 + params[f"y{g}3"] ** 2 for g in "ABC") / 3)
    rows = []
    for leg in "ABC":
        u = kin[leg]["n" if actuation == "revolute" else "e"]
        s = kin[leg]["A3"] - kin["platform"]["G"]
        moment = (s[:, 0] * u[:, 1] - s[:, 1] * u[:, 0]) / rho
        rows.append(np.column_stack([u, moment]))
    W = np.stack(rows, axis=1)
    return np.abs(np.linalg.det(W)) / np.prod(np.linalg.norm(W, axis=2), axis=1)


@pytest.mark.parametrize("seed", range(8))
def test_conditioning_matches_an_independent_formula(seed: int) -> None:
    robot, q, qd, qdd = ne.random_case(seed, np.linspace(0.0, 2.0, 41))
    for actuation in ("revolute", "prismatic"):
        model = Model("r", actuation, robot["params"], "<test>")
        out = rpr3gen.inverse_dynamics(model, q, qd, qdd)
        want = _conditioning_reference(robot["params"], actuation, q)
        np.testing.assert_allclose(out["conditioning"], want, rtol=1e-9, atol=1e-12)
        assert np.all((out["conditioning"] > 0) & (out["conditioning"] <= 1 + 1e-12))


def _singular_robot(actuation: str) -> dict:
    """At q = 0 the three constraint lines meet at G: legs radial (prismatic actuation) or
    tangential (revolute actuation) to the platform."""
    r, length = 0.2, 0.4
    base, platform, alpha = [], [], []
    for a in LEG_ANGLES:
        p = np.array([math.cos(a), math.sin(a)]) * r
        radial = p / r
        direction = radial if actuation == "prismatic" else np.array([-radial[1], radial[0]])
        base.append((p - length * direction).tolist())
        platform.append(p.tolist())
        alpha.append(math.degrees(math.atan2(direction[1], direction[0])))
    return {
        "name": "singular",
        "actuation": actuation,
        "geometry": {"l0": 0.2, "l1": 0.2, "l2": 0.2, "alpha_deg": alpha, "base": base,
                     "platform": platform},
        "mass": {"m1": 1.0, "m2": 1.0, "m3": 2.0, "J3": 0.05},
    }  # fmt: skip


@pytest.mark.parametrize("actuation", ["revolute", "prismatic"])
def test_singular_pose_gives_nan_with_both_backends(actuation: str) -> None:
    model = model_from_dict(_singular_robot(actuation))
    q = np.array([[0.0, 0.0, 0.0], [0.02, 0.0, 0.05]])
    z = np.zeros_like(q)
    for backend in ("numpy", "c"):
        out = rpr3gen.inverse_dynamics(model, q, z, z, backend=backend)
        assert all(np.isnan(v[0]) for v in out.values()), backend
        assert all(np.isfinite(v[1]) for v in out.values()), backend
    assert _conditioning_reference(model.params, actuation, q[:1])[0] < 1e-12


def _write(path: Path, t, q) -> Path:
    """A trajectory file of positions only (velocities and accelerations derived on reading)."""
    write_csv_table(path, POSITION_COLUMNS, np.column_stack([t, q]))
    return path


@pytest.mark.parametrize("actuation", ["revolute", "prismatic"])
def test_trajectory_through_a_singularity_is_refused_with_its_time(
    actuation: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    model = tmp_path / "m.toml"
    robot = _singular_robot(actuation)
    model.write_text(_toml(robot))
    t = np.linspace(0.0, 1.0, 11)
    # A pure translation keeps this robot singular; turning the platform clears it.
    q = np.column_stack([np.zeros_like(t), np.zeros_like(t), 0.6 * (1 - t)])  # reaches q = 0
    motion = _write(tmp_path / "through.csv", t, q)
    out = tmp_path / "out.csv"
    out.write_text("earlier results\n")
    argv = ["simulate", "--model", str(model), "--trajectory", str(motion), "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    first_bad = rpr3gen.inverse_dynamics(rpr3gen.load_model(model), q, 0 * q, 0 * q)
    k = int(np.argmax(~(np.nan_to_num(first_bad["conditioning"]) >= 1e-3)))
    assert f"t = {t[k]:.6g} s" in err
    assert "singular" in err
    assert out.read_text() == "earlier results\n"
    # With the explicit flag, the rows are written as NaN and the rest as usual.
    assert main([*argv, "--allow-invalid"]) == 0
    table = np.genfromtxt(out, delimiter=",", names=True)
    assert np.isnan(table["m21_A"][-1])
    assert np.isfinite(table["m21_A"][0])


def test_trajectory_that_stays_clear_runs(tmp_path: Path) -> None:
    assert main(["simulate", "--trajectory", "rectilinear", "--out", str(tmp_path / "o.csv")]) == 0


def _toml(d: dict) -> str:
    lines = [f'name = "{d["name"]}"', f'actuation = "{d["actuation"]}"']
    for table in ("geometry", "mass", "limits"):
        if table in d:
            lines.append(f"[{table}]")
            lines += [
                f"{k} = {v!r}".replace("(", "[").replace(")", "]") for k, v in d[table].items()
            ]
    return "\n".join(lines) + "\n"


def test_stroke_limits_refuse_with_leg_and_time(
    tmp_path: Path, repo_root: Path, capsys: pytest.CaptureFixture
) -> None:
    model = tmp_path / "limited.toml"
    text = (repo_root / "models" / "paper.toml").read_text()
    model.write_text(text + "\n[limits]\nstroke = [[-0.02, 0.02], [-0.02, 0.02], [-0.02, 0.02]]\n")
    argv = ["simulate", "--model", str(model), "--trajectory", "rectilinear"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "outside its stroke [-0.02, 0.02]" in err
    assert "lambda21_" in err
    assert "t = " in err
    # On both examples the paper's lambda21 stays within [-0.08, 0.22] m.
    wide = tmp_path / "wide.toml"
    wide.write_text(text + "\n[limits]\nstroke = [[-0.1, 0.25], [-0.1, 0.25], [-0.1, 0.25]]\n")
    for name in ("rotation", "rectilinear"):
        assert main(["simulate", "--model", str(wide), "--trajectory", name]) == 0


@pytest.mark.parametrize(
    ("csv_text", "expected"),
    [
        ("t,x,y,phi,dx,dy,dphi,ddx,ddy\n0,0,0,0,0,0,0,0,0\n", "ddphi"),
        ("t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi\n0,0,0,0,0,0,0,0,0,0\n1,0,0,x,0,0,0,0,0,0\n", "phi"),
        ("t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi\n0,0,0,0,0,0,0,0,0,0\n0,0,0,0,0,0,0,0,0,0\n", "t"),
        ("t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi\n0,0,inf,0,0,0,0,0,0,0\n", "y"),
        ("", "empty"),
    ],
)
def test_bad_trajectory_files(csv_text: str, expected: str, tmp_path: Path) -> None:
    motion = tmp_path / "bad.csv"
    motion.write_text(csv_text)
    out = tmp_path / "out.csv"
    out.write_bytes(b"keep me")
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "simulate", "--trajectory", str(motion),
         "--out", str(out), "--plots", str(tmp_path / "figs")],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert "bad.csv" in result.stderr
    assert expected in result.stderr
    assert out.read_bytes() == b"keep me"
    assert not (tmp_path / "figs").exists()


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (("l0 = 0.1", "l0 = -0.1"), "geometry.l0"),
        (("beta_deg = 30.0", "bata_deg = 30.0"), "did you mean 'beta_deg'"),
        (('actuation = "revolute"', 'actuation = "rotary"'), "actuation"),
        (("m3 = 5.0", "m3 = nan"), "mass.m3"),
        (("[mass]", "[mass\n"), "line"),
        (("r = 0.3", "r = 0.3\nbase = [[0, 0], [1, 0], [0, 1]]"), "geometry"),
    ],
)
def test_bad_model_files(edit, expected: str, tmp_path: Path, repo_root: Path) -> None:
    model = tmp_path / "bad.toml"
    model.write_text((repo_root / "models" / "paper.toml").read_text().replace(*edit, 1))
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "simulate", "--model", str(model)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert expected in result.stderr
    assert "Traceback" not in result.stderr


def test_usage_errors_are_one_line() -> None:
    for argv in (["simulate", "--samples", "many"], ["frobnicate"]):
        result = subprocess.run(
            [sys.executable, "-m", "rpr3gen.cli", *argv], capture_output=True, text=True
        )
        assert result.returncode == 2
        assert result.stderr.count("\n") == 1, result.stderr


def test_debug_shows_the_traceback() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "--debug", "simulate", "--model", "missing.toml"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode != 0
    assert "Traceback" in result.stderr
