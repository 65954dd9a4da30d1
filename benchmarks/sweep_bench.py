"""Throughput and memory of `rpr3gen sweep`, in one run (not a test).

    python benchmarks/sweep_bench.py                  # writes benchmarks/sweep-results.md
    python benchmarks/sweep_bench.py --designs 2500 --large 10000   # a quicker look

Measures, on a grid of two parameters (``geometry.l0`` x ``mass.m3``, the paper's robot, both
paper trajectories of 301 samples, the workspace area on 48 x 48 points):

- designs per second in this process without Dask (``workers=0``), on a local Dask cluster of
  one worker and of every core, and through a ``dask scheduler`` with two ``dask worker``
  processes on localhost (started and stopped here);
- the same work as a plain Python loop calling ``rpr3gen.inverse_dynamics`` per design and
  trajectory (trajectory metrics only, so it is compared with a sweep without the area);
- the peak resident memory (ru_maxrss) of the client and of each worker, for every run, and for
  a larger sweep (``--large`` designs, local cluster).

Each run is a fresh interpreter, so its memory peak is its own. Other processes on the machine
slow every figure; the report gives the load average before and after.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

#: Time the optimised C libraries, not the quick ones a first use runs on (rpr3gen.cbackend).
os.environ.setdefault("RPR3GEN_C_BUILD", "optimised")

HERE = Path(__file__).resolve().parent
AREA = 48


def _grid(designs: int) -> dict[str, Any]:
    side = max(1, round(designs**0.5))
    return {
        "geometry.l0": {"start": 0.08, "stop": 0.12, "num": side},
        "mass.m3": {"start": 2.0, "stop": 8.0, "num": max(1, designs // side)},
    }


def _rss_kib() -> int:
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)


def _worker_rss(scheduler: str | None = None, client: Any = None) -> list[int]:
    return sorted(client.run(_rss_kib).values()) if client is not None else []


def run_sweep(mode: str, designs: int, area: int, scheduler: str | None) -> dict[str, Any]:
    """One sweep in this (fresh) interpreter; its time and memory peaks."""
    import rpr3gen
    from rpr3gen.design import cluster

    grid = _grid(designs)
    workers = {"inprocess": 0, "local1": 1, "local": None, "scheduler": None}[mode]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "sweep.parquet"
        peaks: list[int] = []
        startup: list[float] = []
        enter, leave = cluster.ClusterClient.__enter__, cluster.ClusterClient.__exit__

        def timed_enter(self: Any) -> Any:  # importing distributed, starting the cluster
            begin = time.perf_counter()
            client = enter(self)
            startup.append(time.perf_counter() - begin)
            return client

        def exit_with_peaks(self: Any, *exc: object) -> None:  # read the workers' peaks first
            if self.client is not None:
                peaks.extend(_worker_rss(client=self.client))
            leave(self, *exc)

        cluster.ClusterClient.__enter__ = timed_enter  # type: ignore[method-assign]
        cluster.ClusterClient.__exit__ = exit_with_peaks  # type: ignore[method-assign]
        start = time.perf_counter()
        table = rpr3gen.sweep(None, grid, out=out, scheduler=scheduler, workers=workers,
                              area_resolution=area)  # fmt: skip
        seconds = time.perf_counter() - start
        size = out.stat().st_size
    return {
        "mode": mode,
        "designs": table.num_rows,
        "area": area,
        "seconds": seconds,
        "startup": sum(startup),
        "client_rss_kib": _rss_kib(),
        "worker_rss_kib": peaks,
        "parquet_bytes": size,
    }


def run_loop(designs: int) -> dict[str, Any]:
    """The plain loop: one model and one inverse_dynamics call per design and trajectory."""
    import numpy as np

    import rpr3gen
    from rpr3gen.design.grid import read_grid
    from rpr3gen.model import model_from_dict, read_model_data

    source, base = read_model_data()
    grid = read_grid(_grid(designs), base)
    trajs = [rpr3gen.paper_trajectory(name) for name in ("rotation", "rectilinear")]
    start = time.perf_counter()
    rows = []
    for i in range(len(grid)):
        model = model_from_dict(grid.apply(base, grid.design(i)), source=source)
        outs = [rpr3gen.inverse_dynamics(model, tr.q, tr.qd, tr.qdd) for tr in trajs]
        row = {}
        for leg in "ABC":
            tau = np.concatenate([o[f"m10_{leg}"] for o in outs])
            row[leg] = (np.abs(tau).max(), np.sqrt(np.mean(tau**2)))
        row["c"] = min(o["conditioning"].min() for o in outs)
        rows.append(row)
    return {"mode": "loop", "designs": len(rows), "seconds": time.perf_counter() - start,
            "client_rss_kib": _rss_kib()}  # fmt: skip


def _fresh(args: list[str]) -> dict[str, Any]:
    result = subprocess.run(
        [sys.executable, __file__, "--worker", *args], capture_output=True, text=True, check=False
    )
    if result.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed:\n{result.stderr}")
    return json.loads(result.stdout.strip().splitlines()[-1])


def _best(repeat: int, args: list[str]) -> dict[str, Any]:
    """The fastest of ``repeat`` fresh runs (other jobs on the machine only slow a run)."""
    return min((_fresh(args) for _ in range(repeat)), key=lambda run: run["seconds"])


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class _Cluster:
    """A dask scheduler and two dask workers on localhost, one thread each."""

    def __enter__(self) -> str:
        from distributed import Client

        self.tmp = tempfile.TemporaryDirectory()
        port = _free_port()
        self.address = f"tcp://127.0.0.1:{port}"
        dask = [sys.executable, "-m", "dask"]
        self.procs = [
            subprocess.Popen(
                [
                    *dask,
                    "scheduler",
                    "--host",
                    "127.0.0.1",
                    "--port",
                    str(port),
                    "--no-dashboard",
                    "--dashboard-address",
                    "127.0.0.1:0",
                ],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        ]
        # As docs/design-studies.md's "On a cluster" says: workers that keep their freed memory
        # (Dask's nanny would make them return it beyond 64 KiB, and every NumPy temporary
        # page-faults).
        env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": str(1 << 28),
               "MALLOC_MMAP_THRESHOLD_": str(1 << 25)}  # fmt: skip
        for k in range(2):
            self.procs.append(subprocess.Popen(
                [*dask, "worker", self.address, "--nworkers", "1", "--nthreads", "1",
                 "--no-dashboard", "--name", f"bench-{k}", "--local-directory", self.tmp.name],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env))  # fmt: skip
        with Client(self.address, timeout="120s") as client:
            client.wait_for_workers(2, timeout=120)
        return self.address

    def __exit__(self, *exc: object) -> None:
        for proc in reversed(self.procs):
            proc.terminate()
        for proc in reversed(self.procs):
            proc.wait(timeout=60)
        self.tmp.cleanup()


def _mib(kib: int | list[int]) -> str:
    if isinstance(kib, list):
        return ", ".join(f"{k / 1024:.0f}" for k in kib) if kib else "-"
    return f"{kib / 1024:.0f}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=10_000)
    parser.add_argument("--large", type=int, default=100_000)
    parser.add_argument("--loop-designs", type=int, default=1_000)
    parser.add_argument("--repeat", type=int, default=2, help="best of N runs (not --large)")
    parser.add_argument("--out", default=str(HERE / "sweep-results.md"))
    parser.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        mode, designs, area, *rest = args.worker
        result = run_loop(int(designs)) if mode == "loop" else run_sweep(
            mode, int(designs), int(area), rest[0] if rest else None)  # fmt: skip
        print(json.dumps(result))
        return 0

    load_before = os.getloadavg()
    started = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    n = args.designs
    runs = []
    for mode, area in (("inprocess", AREA), ("inprocess", 0), ("local1", AREA), ("local", AREA)):
        print(f"{mode}, area {area}: {n} designs ...", file=sys.stderr)
        runs.append(_best(args.repeat, [mode, str(n), str(area)]))
    with _Cluster() as address:
        print(f"scheduler {address}: {n} designs ...", file=sys.stderr)
        runs.append(_best(args.repeat, ["scheduler", str(n), str(AREA), address]))
    print(f"plain loop: {args.loop_designs} designs ...", file=sys.stderr)
    loop = _best(args.repeat, ["loop", str(args.loop_designs), "0"])
    print(f"local, large: {args.large} designs ...", file=sys.stderr)
    large = _fresh(["local", str(args.large), str(AREA)])
    load_after = os.getloadavg()

    commit = subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True, check=False).stdout.strip()  # fmt: skip
    cores = len(os.sched_getaffinity(0))
    loop_rate = loop["designs"] / loop["seconds"]
    names = {
        "inprocess": "this process, no Dask (`--workers 0`)",
        "local1": "local Dask cluster, 1 worker (`--workers 1`)",
        "local": f"local Dask cluster, {cores} workers (the default)",
        "scheduler": "`--scheduler`: dask scheduler + 2 dask workers on localhost",
    }
    machine = platform.processor() or platform.machine()
    header = ["run", "designs", "area", "time (start)", "designs/s", "after start",
              "vs plain loop", "client RSS (MiB)", "workers' RSS (MiB)"]  # fmt: skip
    lines = [
        "# Sweep throughput and memory",
        "",
        f"`python benchmarks/sweep_bench.py` at {commit}, {started}; {machine}, {cores} usable "
        f"cores, Python {platform.python_version()}. Load average {load_before[0]:.2f} before, "
        f"{load_after[0]:.2f} after (the sweeps' own workers raise it; a load above 1 before "
        "means other jobs shared the cores, and the figures are then lower bounds).",
        "",
        "Grid: `geometry.l0` x `mass.m3` of the paper robot, both paper trajectories (301 samples "
        f"each), workspace area on {AREA} x {AREA} points, chunks of 64 designs. Each run is a "
        f"fresh interpreter, the best of {args.repeat} (the large one: one run); the time "
        "includes starting and stopping the local cluster (not the external one), and writing "
        "the Parquet file; (start) is the part spent importing Dask "
        "and connecting to or starting the cluster, and *after start* the rate without it. RSS: "
        "peak resident memory (ru_maxrss).",
        "",
        "| " + " | ".join(header) + " |",
        "|---|---:|---|---:|---:|---:|---:|---:|---|",
    ]
    for run in [*runs, large]:
        rate = run["designs"] / run["seconds"]
        area = f"{run['area']}²" if run["area"] else "none"
        steady = run["designs"] / (run["seconds"] - run["startup"])
        lines.append(
            f"| {names[run['mode']]} | {run['designs']:,} | {area} | {run['seconds']:.1f} s "
            f"({run['startup']:.1f} s) | {rate:,.0f} | {steady:,.0f} | {rate / loop_rate:.1f}x | "
            f"{_mib(run['client_rss_kib'])} | {_mib(run['worker_rss_kib'])} |"
        )
    lines += [
        "| plain loop over `rpr3gen.inverse_dynamics`, one design at a time | "
        f"{loop['designs']:,} | none | {loop['seconds']:.1f} s | {loop_rate:,.0f} | - | 1x | "
        f"{_mib(loop['client_rss_kib'])} | - |",
        "",
        "The plain loop does the trajectory part only (a model per design, one "
        "`inverse_dynamics` call per trajectory, peaks, RMS, least conditioning): compare it with "
        "the in-process sweep without the area, the same work. The other sweeps also compute "
        f"each design's workspace area ({AREA}² poses per design, about four times the "
        "trajectories' samples).",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
