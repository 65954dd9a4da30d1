"""Ctrl-C during ``rpr3gen sweep`` on the local Dask cluster (issue 23): a real SIGINT to the
command's process group, as a terminal sends it, once the finished chunks are written and a
worker is busy (``hostile_sweep_tasks`` says both on stderr: no clock is involved).

Then: exit status 130, one line saying what is kept and how to go on, no traceback (the workers
ignore the terminal's Ctrl-C; the cluster shuts down quietly), the earlier output untouched, and
``--resume`` computes only the chunks that were not done, to the bytes of a straight run.
"""

from __future__ import annotations

import os
import selectors
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import hostile_sweep_tasks as tasks
import pytest

from rpr3gen.cli import main
from rpr3gen.design import sweeps
from rpr3gen.design.metrics import evaluate_chunk

TESTS = Path(__file__).resolve().parent
#: The most a line of the command may take to come (a hung cluster fails, it does not stall CI).
LINE_LIMIT = 120.0
FINISHED = [f"chunk-{i:06d}.parquet" for i in range(tasks.FINISHED)]


def _lines(proc: subprocess.Popen[str], log: list[str]) -> Any:
    """The command's stderr, line by line, each within :data:`LINE_LIMIT` seconds; every line
    read is also appended to ``log`` (a failure shows them all)."""
    assert proc.stderr is not None
    with selectors.DefaultSelector() as selector:
        selector.register(proc.stderr, selectors.EVENT_READ)
        while True:
            if not selector.select(timeout=LINE_LIMIT):
                os.kill(proc.pid, signal.SIGUSR1)  # its threads' stacks (hostile_sweep_tasks)
                while selector.select(timeout=5.0):
                    more = proc.stderr.readline()
                    if not more:
                        break
                    log.append(more)
                proc.kill()
                pytest.fail(
                    f"no line from the sweep for {LINE_LIMIT:g} s; it said:\n{''.join(log)}"
                )
            line = proc.stderr.readline()
            if not line:
                return
            log.append(line)
            yield line


@pytest.mark.skipif(not hasattr(os, "killpg"), reason="needs POSIX process groups")
def test_ctrl_c_keeps_every_finished_chunk_says_one_line_and_resume_finishes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    grid = tmp_path / "grid.toml"
    grid.write_text('"mass.m3" = [2.0, 3.0, 4.0, 5.0]\n')
    out = tmp_path / "sweep.parquet"
    out.write_bytes(b"earlier results\n")
    argv = ["sweep", "--grid", str(grid), "--chunk-size", "1", "--area-resolution", "0",
            "--samples", "11", "--trajectory", "rotation", "--out", str(out)]  # fmt: skip
    path = os.pathsep.join(p for p in (str(TESTS), os.environ.get("PYTHONPATH", "")) if p)
    command = [*argv, "--workers", "1"]
    code = f"import sys, hostile_sweep_tasks as h; sys.exit(h.run_command({command!r}))"
    with subprocess.Popen(
        [sys.executable, "-c", code],
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": path, **tasks.PRELOAD},
        start_new_session=True,  # its own process group, as a command in a terminal
    ) as proc:
        seen, written, blocked = [], set(), False
        log: list[str] = []
        for line in _lines(proc, log):
            seen.append(line)
            written |= {Path(line.split()[-1]).name} if line.startswith(tasks.WROTE) else set()
            blocked = blocked or line.startswith(tasks.BLOCKED)
            if blocked and set(FINISHED) <= written:
                break
        else:
            pytest.fail(f"the sweep ended before Ctrl-C: {''.join(seen)}")
        os.killpg(proc.pid, signal.SIGINT)  # a terminal's Ctrl-C: every process of the command
        after = list(_lines(proc, log))
        assert proc.wait() == 130
    # A chunk written as Ctrl-C came may be written again (kept as finished): the same bytes.
    rest = "".join(line for line in after if not line.startswith(tasks.WROTE))
    parts = sweeps.parts_folder(out)
    assert rest == (
        f"rpr3gen: interrupted; {len(FINISHED)} of 4 chunks done, kept in {parts}: rerun with "
        "--resume to compute only the others\n"
    ), rest
    everything = "".join(seen + after)
    for word in ("Traceback", "CancelledError", "KeyboardInterrupt", "Exception"):
        assert word not in everything, everything
    assert sorted(p.name for p in parts.glob("chunk-*.parquet")) == FINISHED
    assert out.read_bytes() == b"earlier results\n"

    evaluated: list[int] = []

    def counted(plan: Any, index: int) -> Any:
        evaluated.append(index)
        return evaluate_chunk(plan, index)

    monkeypatch.setattr(sweeps, "evaluate_chunk", counted)
    assert main([*argv, "--workers", "0", "--resume"]) == 0
    assert evaluated == [2, 3]
    straight = tmp_path / "straight.parquet"
    assert main([*argv[:-1], str(straight), "--workers", "0"]) == 0
    assert out.read_bytes() == straight.read_bytes()
    assert not parts.exists()
    assert capsys.readouterr().err == ""
