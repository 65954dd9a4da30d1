"""Long runs show a progress bar on a terminal, and nothing when stderr is not one."""

from __future__ import annotations

import os
import pty
import subprocess
import sys

ARGS = [sys.executable, "-m", "rpr3gen.cli", "simulate", "--samples", "1500000"]


def test_no_progress_bar_when_stderr_is_not_a_terminal() -> None:
    result = subprocess.run(ARGS, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert "1500000 samples" in result.stdout


def test_progress_bar_on_a_terminal() -> None:
    primary, secondary = pty.openpty()
    proc = subprocess.Popen(ARGS, stdout=subprocess.DEVNULL, stderr=secondary)
    os.close(secondary)
    seen = b""
    while True:
        try:
            chunk = os.read(primary, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        seen += chunk
    os.close(primary)
    assert proc.wait() == 0
    assert b"sample" in seen
    assert b"%" in seen
