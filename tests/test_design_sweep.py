"""Sweeps: each row against a plain loop over the public API, on a real Dask cluster as in this
process, byte-identical whatever the workers, and resumed without losing anything.

The cluster is real: a ``dask scheduler`` and two ``dask worker`` processes on localhost, on
free ports, started and stopped by the ``scheduler`` fixture (``tests/conftest.py``, shared with
``tests/test_spatial_sweep.py``); it waits for them by asking the scheduler
(``Client.wait_for_workers``), never by sleeping.
"""

from __future__ import annotations

import os
import pty
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.design import cluster, sweeps
from rpr3gen.design.grid import read_grid
from rpr3gen.design.metrics import RESULT_COLUMNS, evaluate_chunk
from rpr3gen.design.stacked import evaluate_stacked, param_rows
from rpr3gen.model import model_from_dict, read_model_data

_, PAPER = read_model_data()
SAMPLES = 31  # per paper trajectory: enough to exercise everything, quick
GRID_TOML = '"geometry.l0" = [0.09, 0.1, 0.11]\n"mass.m3" = { start = 3.0, stop = 7.0, num = 3 }\n'
GRID = {"geometry.l0": [0.09, 0.1, 0.11], "mass.m3": {"start": 3.0, "stop": 7.0, "num": 3}}
OPTIONS: dict[str, Any] = {"samples": SAMPLES, "chunk_size": 2, "area_resolution": 16}


def _weights(t: np.ndarray) -> np.ndarray:
    dt = np.diff(t)
    return np.concatenate([[dt[0]], dt[1:] + dt[:-1], [dt[-1]]]) / 2


def _plain_loop(base: dict[str, Any], grid: dict[str, Any], effort: str = "m10") -> list[dict]:
    """What a sweep reports, one design at a time through ``rpr3gen.inverse_dynamics``."""
    checked = read_grid(grid, base)
    trajs = [rpr3gen.paper_trajectory(n, samples=SAMPLES) for n in ("rotation", "rectilinear")]
    rows = []
    for i in range(len(checked)):
        model = model_from_dict(checked.apply(base, checked.design(i)))
        outs = [rpr3gen.inverse_dynamics(model, tr.q, tr.qd, tr.qdd) for tr in trajs]
        w = np.concatenate([_weights(tr.t) for tr in trajs])
        row: dict[str, Any] = dict(zip(checked.keys, checked.design(i), strict=True))
        for leg in "ABC":
            tau = np.concatenate([o[f"{effort}_{leg}"] for o in outs])
            row[f"peak_tau_{leg}"] = np.abs(tau).max()
            row[f"rms_tau_{leg}"] = np.sqrt((w * tau**2).sum() / w.sum())
        row["min_conditioning"] = min(o["conditioning"].min() for o in outs)
        for family in ("f10x", "f10y", "f21y", "m21", "f32y", "f32z"):
            row[f"peak_{family}"] = max(
                np.abs(o[f"{family}_{leg}"]).max() for o in outs for leg in "ABC"
            )
        row["workspace_area"] = rpr3gen.workspace(model, 0.0, 16).area
        rows.append(row)
    return rows


def _compare(table: Any, expected: list[dict]) -> None:
    got = table.to_pylist()
    assert len(got) == len(expected)
    for row, want in zip(got, expected, strict=True):
        for key, value in want.items():
            if isinstance(value, str):
                assert row[key] == value, key
            else:
                assert row[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key


def test_stacked_designs_are_each_design_alone() -> None:
    checked = read_grid(GRID, PAPER)
    models = [model_from_dict(checked.apply(PAPER, checked.design(i))) for i in range(len(checked))]
    traj = rpr3gen.paper_trajectory("rectilinear", samples=SAMPLES)
    n = len(traj)
    params = np.repeat(param_rows(models), n, axis=1)
    tiled = [np.tile(a, (len(models), 1)) for a in (traj.q, traj.qd, traj.qdd)]
    found = evaluate_stacked(models[0], "inverse_dynamics", params, tiled)
    assert found.ok().all()
    for k, model in enumerate(models):
        alone = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
        for name in rpr3gen.OUTPUT_NAMES:
            np.testing.assert_allclose(
                found[name][k * n : (k + 1) * n], alone[name], rtol=1e-13, atol=1e-12, err_msg=name
            )


def test_rows_are_the_plain_loops_in_grid_order() -> None:
    table = rpr3gen.sweep(None, GRID, workers=0, **OPTIONS)
    assert table.column_names == ["geometry.l0", "mass.m3", *RESULT_COLUMNS]
    assert table.column("feasible").to_pylist() == [True] * 9
    assert table.column("reason").to_pylist() == [""] * 9
    _compare(table, _plain_loop(PAPER, GRID))


def test_prismatic_designs_report_the_slide_forces() -> None:
    grid = {"actuation": ["revolute", "prismatic"]}
    table = rpr3gen.sweep(None, grid, workers=0, **OPTIONS)
    assert table.column("actuation").to_pylist() == ["revolute", "prismatic"]
    expected = _plain_loop(PAPER, grid)[:1] + _plain_loop(PAPER, grid, effort="f21z")[1:]
    _compare(table, expected)


def test_infeasible_designs_say_where_and_why() -> None:
    base = {**PAPER, "limits": {"stroke": [[-0.1, 0.25]] * 3}}
    grid = {"limits.stroke[0][1]": [0.1, 0.25], "mass.m3": [5.0]}
    table = rpr3gen.sweep(base, grid, workers=0, **OPTIONS)
    assert table.column("feasible").to_pylist() == [False, True]
    reason = table.column("reason").to_pylist()[0]
    traj = rpr3gen.paper_trajectory("rotation", samples=SAMPLES)
    out = rpr3gen.inverse_dynamics(rpr3gen.load_model(), traj.q, traj.qd, traj.qdd)
    first = int(np.argmax(out["lambda21_A"] > 0.1))
    assert reason.startswith(f"rotation: t = {traj.t[first]:.6g} s: ")
    assert "lambda21_A" in reason
    assert "outside its stroke [-0.1, 0.1]" in reason
    assert table.column("reason").to_pylist()[1] == ""
    assert np.isfinite(table.column("peak_tau_A").to_numpy()).all()  # peaks are still reported


def test_an_invalid_combination_is_an_infeasible_row() -> None:
    """Each value is a valid model alone; together, pivot B1 lands on A1."""
    explicit = dict(PAPER)
    geometry = {k: v for k, v in PAPER["geometry"].items() if k not in ("r", "beta_deg")}
    geometry["base"] = [[0.2598, -0.15], [0.0, 0.3], [-0.2598, -0.15]]
    geometry["platform"] = [[0.2598, 0.15], [-0.2598, 0.15], [0.0, -0.3]]
    explicit["geometry"] = geometry
    explicit["mass"] = {**PAPER["mass"], "J3": 0.1125}
    grid = {"geometry.base[1][0]": [0.0, 0.2598], "geometry.base[1][1]": [0.3, -0.15]}
    table = rpr3gen.sweep(explicit, grid, workers=0, **OPTIONS)
    rows = table.to_pylist()
    assert rows[0]["feasible"]  # the base itself
    assert not any(r["reason"].startswith("invalid model") for r in rows[:3])
    assert not rows[3]["feasible"]
    assert rows[3]["reason"].startswith("invalid model: ")
    assert "base pivots A1 and B1 coincide" in rows[3]["reason"]
    assert all(np.isnan(rows[3][c]) for c in RESULT_COLUMNS[2:])


# -- the cluster ---------------------------------------------------------------------------------


@pytest.mark.slow
def test_the_scheduler_run_is_the_in_process_run(
    scheduler: str, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID_TOML)
    common = ["sweep", "--grid", str(grid), "--samples", str(SAMPLES), "--chunk-size", "2",
              "--area-resolution", "16"]  # fmt: skip
    here, there = tmp_path / "here.parquet", tmp_path / "there.parquet"
    assert main([*common, "--workers", "0", "--out", str(here)]) == 0
    assert main([*common, "--scheduler", scheduler, "--out", str(there)]) == 0
    captured = capfd.readouterr()
    assert captured.err == ""  # no bar off a terminal, no log lines of Dask's
    assert captured.out.splitlines() == [
        f"9 designs, 9 feasible; wrote {here}",
        f"9 designs, 9 feasible; wrote {there}",
    ]
    rows_here, rows_there = pq.read_table(here).to_pylist(), pq.read_table(there).to_pylist()
    assert len(rows_here) == 9
    for a, b in zip(rows_here, rows_there, strict=True):
        assert a == b
    assert here.read_bytes() == there.read_bytes()
    assert not Path(f"{there}.parts").exists()


@pytest.mark.slow
def test_same_bytes_whatever_the_number_of_workers(tmp_path: Path) -> None:
    files = {}
    for workers in (0, 1, 2):
        files[workers] = tmp_path / f"w{workers}.parquet"
        rpr3gen.sweep(None, GRID, out=files[workers], workers=workers, **OPTIONS)
    content = {w: f.read_bytes() for w, f in files.items()}
    assert content[0] == content[1] == content[2]
    assert pq.read_table(files[0]).num_rows == 9


# -- resuming ------------------------------------------------------------------------------------


def test_an_interrupted_sweep_resumes_and_loses_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    straight = tmp_path / "straight.parquet"
    rpr3gen.sweep(None, GRID, out=straight, workers=0, **OPTIONS)  # 5 chunks of 2, 2, 2, 2, 1

    out = tmp_path / "resumed.parquet"
    parts = sweeps.parts_folder(out)
    evaluated: list[int] = []

    def interrupted(plan: Any, index: int) -> Any:
        if index == 3:
            raise KeyboardInterrupt
        evaluated.append(index)
        return evaluate_chunk(plan, index)

    monkeypatch.setattr(sweeps, "evaluate_chunk", interrupted)
    with pytest.raises(KeyboardInterrupt):
        rpr3gen.sweep(None, GRID, out=out, workers=0, **OPTIONS)
    assert not out.exists()
    assert sorted(p.name for p in parts.glob("chunk-*.parquet")) == [
        "chunk-000000.parquet", "chunk-000001.parquet", "chunk-000002.parquet",
    ]  # fmt: skip
    # As a crash would leave it: one finished chunk lost, one being written (a temporary file).
    (parts / "chunk-000001.parquet").unlink()
    (parts / ".chunk-000003.parquet.x1y2.tmp").write_bytes(b"PAR1 half a file")

    evaluated.clear()

    def counted(plan: Any, index: int) -> Any:
        evaluated.append(index)
        return evaluate_chunk(plan, index)

    monkeypatch.setattr(sweeps, "evaluate_chunk", counted)
    rpr3gen.sweep(None, GRID, out=out, workers=0, resume=True, **OPTIONS)
    assert evaluated == [1, 3, 4]
    assert out.read_bytes() == straight.read_bytes()
    assert not parts.exists()


def test_chunks_in_the_way_need_resume(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID_TOML)
    out = tmp_path / "s.parquet"
    parts = sweeps.parts_folder(out)
    parts.mkdir()
    (parts / "chunk-000000.parquet").write_bytes(b"earlier work")
    argv = ["sweep", "--grid", str(grid), "--out", str(out), "--workers", "0"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"rpr3gen: error: {parts}: holds the chunks of an interrupted sweep")
    assert "--resume" in err
    assert (parts / "chunk-000000.parquet").read_bytes() == b"earlier work"
    assert not out.exists()
    # Resuming them is refused too: they are not this sweep's (no stamp, or another grid).
    assert main([*argv, "--resume"]) == 2
    assert "holds the chunks of another sweep" in capsys.readouterr().err
    assert (parts / "chunk-000000.parquet").read_bytes() == b"earlier work"


def test_a_failure_keeps_its_class_and_says_where_the_chunks_are(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A scheduler lost mid-sweep (an OSError of the environment) stays a SetupError, with how
    to resume added; a bad value stays an InputError naming its argument."""
    out = tmp_path / "s.parquet"
    for error in (
        rpr3gen.SetupError("scheduler tcp://x:8786: cannot connect: refused"),
        rpr3gen.InputError("samples: too many", argument="samples"),
    ):

        def fail(*args: Any, error: Exception = error, **kwargs: Any) -> None:
            raise error

        monkeypatch.setattr(sweeps, "run_chunks", fail)
        with pytest.raises(type(error)) as info:
            rpr3gen.sweep(None, GRID, out=out, workers=0, resume=True, **OPTIONS)
        assert str(info.value).startswith(f"{error}; the chunks done are in ")
        assert str(info.value).endswith(": rerun with --resume")
        assert info.value.argument == error.argument


def test_resuming_another_grid_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "s.parquet"

    def stop(plan: Any, index: int) -> Any:
        raise KeyboardInterrupt

    monkeypatch.setattr(sweeps, "evaluate_chunk", stop)
    with pytest.raises(KeyboardInterrupt):
        rpr3gen.sweep(None, GRID, out=out, workers=0, **OPTIONS)
    monkeypatch.undo()
    other = {**GRID, "mass.m3": [3.0, 4.0]}
    with pytest.raises(rpr3gen.SetupError, match="holds the chunks of another sweep"):
        rpr3gen.sweep(None, other, out=out, workers=0, resume=True, **OPTIONS)
    table = rpr3gen.sweep(None, GRID, out=out, workers=0, resume=True, **OPTIONS)
    assert table.num_rows == 9


# -- the command ---------------------------------------------------------------------------------


def test_the_command_summary_and_a_progress_bar_on_a_terminal(tmp_path: Path) -> None:
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID_TOML)
    out = tmp_path / "s.parquet"
    argv = ["sweep", "--grid", str(grid), "--out", str(out), "--workers", "0",
            "--samples", str(SAMPLES), "--chunk-size", "2", "--area-resolution", "16"]  # fmt: skip
    code = (  # tqdm's clock advances one second at each reading: every update is drawn
        "import itertools, sys, tqdm.std\n"
        "ticks = itertools.count()\n"
        "tqdm.std.time = lambda: float(next(ticks))\n"
        f"from rpr3gen.cli import main\nsys.exit(main({argv!r}))\n"
    )
    primary, secondary = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=secondary, text=True
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
    stdout, _ = proc.communicate()
    assert proc.returncode == 0
    assert stdout == f"9 designs, 9 feasible; wrote {out}\n"
    assert b"9/9" in seen
    assert b"design" in seen
    assert pq.read_table(out).num_rows == 9


def test_the_bytes_depend_on_the_rows_alone(tmp_path: Path) -> None:
    """Chunks of another size (so other part files) give the same file."""
    files = [tmp_path / "a.parquet", tmp_path / "b.parquet"]
    for path, chunk_size in zip(files, (2, 5), strict=True):
        rpr3gen.sweep(None, GRID, out=path, workers=0, **{**OPTIONS, "chunk_size": chunk_size})
    assert files[0].read_bytes() == files[1].read_bytes()


def test_a_failed_task_is_one_line() -> None:
    class Lost:
        def result(self) -> Any:
            raise RuntimeError("worker tcp://10.0.0.7:4321 died")

    with pytest.raises(rpr3gen.SetupError) as caught:
        cluster.task_result(Lost())
    assert str(caught.value) == (
        "a sweep task failed on the Dask cluster: RuntimeError: worker tcp://10.0.0.7:4321 died"
    )
