"""A wheel built from the repository runs `rpr3gen simulate` in a fresh venv, no source tree."""

from __future__ import annotations

import subprocess
import sys
import venv
from pathlib import Path

import pytest


@pytest.mark.slow
def test_wheel_runs_simulate_in_a_fresh_venv(repo_root: Path, tmp_path: Path) -> None:
    wheels = tmp_path / "wheels"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "-q",
            "-w",
            str(wheels),
            str(repo_root),
        ],
        check=True,
        capture_output=True,
    )
    (wheel,) = wheels.glob("rpr3gen-*.whl")
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    python = env_dir / "bin" / "python"
    subprocess.run(
        [str(python), "-m", "pip", "install", "-q", str(wheel)], check=True, capture_output=True
    )
    work = tmp_path / "elsewhere"
    work.mkdir()
    result = subprocess.run(
        [str(env_dir / "bin" / "rpr3gen"), "simulate", "--trajectory", "rectilinear",
         "--out", "r.csv", "--plots", "figs"],
        cwd=work, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert (work / "r.csv").read_text().startswith("t,x,y,phi,phi10_A")
    assert (work / "figs" / "rectilinear_m10.png").is_file()
    where = subprocess.run(
        [str(python), "-c", "import rpr3gen_generated, rpr3gen; print(rpr3gen_generated.__file__)"],
        cwd=work, capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    assert str(repo_root) not in where
