"""Smoke tests of examples/control_loop: the C program and the Python loop, short runs."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

from rpr3gen.cli import main


def _check_report(text: str) -> None:
    rms = float(re.search(r"rms ([\d.]+) mm", text).group(1))
    assert rms < 2.0, text  # a 1 mm start offset is being corrected, not amplified
    assert re.search(r"p50 [\d.]+ \w?s, p99 [\d.]+ \w?s, max [\d.]+ \w?s", text), text


def test_c_control_loop(repo_root: Path, tmp_path: Path, capsys) -> None:
    example = repo_root / "examples" / "control_loop"
    work = tmp_path / "control_loop"
    shutil.copytree(example, work, ignore=shutil.ignore_patterns("control_loop", "*.params"))
    gen = repo_root / "generated" / "revolute"
    flags = "CFLAGS=-std=c99 -O2 -Wall -Wextra -pedantic -Werror"
    subprocess.run(["make", "-s", f"GEN={gen}", flags], cwd=work, check=True, capture_output=True)
    assert main(["params"]) == 0
    (work / "paper.params").write_text(capsys.readouterr().out)
    result = subprocess.run(
        ["./control_loop", "paper.params", "rectilinear", "0.4"],
        cwd=work, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "400 steps" in result.stdout
    _check_report(result.stdout)


def test_python_control_loop(repo_root: Path) -> None:
    script = repo_root / "examples" / "control_loop" / "control_loop.py"
    result = subprocess.run(
        [sys.executable, str(script), "--seconds", "0.4", "--trajectory", "rotation"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "400 steps" in result.stdout
    _check_report(result.stdout)
