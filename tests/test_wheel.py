"""A wheel built from the repository runs `rpr3gen simulate` in a fresh venv, no source tree."""

from __future__ import annotations

import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

#: Not part of a build: environments, caches, build products.
_NOT_SOURCES = shutil.ignore_patterns(
    ".git", ".venv", "build", "dist", "*.egg-info", "__pycache__", ".*_cache", ".hypothesis"
)


@pytest.mark.slow
def test_wheel_runs_simulate_in_a_fresh_venv(repo_root: Path, tmp_path: Path) -> None:
    # Built from a copy of the sources: the build writes no build/ into the checkout, and no
    # stale build/lib of an earlier build can slip into the wheel.
    sources = tmp_path / "sources"
    shutil.copytree(repo_root, sources, ignore=_NOT_SOURCES, symlinks=True)
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(sources)],
        check=True,
        capture_output=True,
    )
    (wheel,) = wheels.glob("rpr3gen-*.whl")
    # A venv without pip of its own: this environment's pip installs into it (--python), the
    # wheel and the dependencies it declares, with nothing precompiled (what a user's pip would
    # do, less the seconds spent on bytecode).
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-compile",
         str(wheel)],
        check=True, capture_output=True,
    )  # fmt: skip
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
    assert where.startswith(str(env_dir))
