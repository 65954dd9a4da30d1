"""Long runs show a progress bar on a terminal, and nothing when stderr is not one.

No outcome here depends on how fast the machine is: the bar shows only once tqdm's clock says
its delay has passed, so the run on a terminal reads a fake clock that advances one second at
each reading (the bar then appears at the first update, whatever the speed), and the runs are
a few blocks long, not long enough to race a real clock.
"""

from __future__ import annotations

import os
import pty
import subprocess
import sys

from rpr3gen.backends import BLOCK

SAMPLES = 3 * BLOCK + 1  # the bar is for runs of more than one block
ARGS = ["simulate", "--samples", str(SAMPLES)]
FAKE_CLOCK = (
    "import itertools, sys, tqdm.std\n"
    "ticks = itertools.count()\n"
    "tqdm.std.time = lambda: float(next(ticks))  # every reading is one second later\n"
    "from rpr3gen.cli import main\n"
    f"sys.exit(main({ARGS!r}))\n"
)


def test_no_progress_bar_when_stderr_is_not_a_terminal() -> None:
    result = subprocess.run(
        [sys.executable, "-c", FAKE_CLOCK], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert f"{SAMPLES} samples" in result.stdout


def test_progress_bar_on_a_terminal() -> None:
    primary, secondary = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-c", FAKE_CLOCK], stdout=subprocess.DEVNULL, stderr=secondary
    )
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
