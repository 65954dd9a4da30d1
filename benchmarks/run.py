"""Every benchmark of rpr3gen in one command: ``python benchmarks/run.py [--quick] [--docs]``.

Runs, over the paper's variants in ``generated/`` (``harness/samples.py``): the C per-function
harness (``harness/cbench.py``: floor, single call, batch), the control-loop examples
(``harness/examples.py``: their own tick latencies), NumPy against the Newton-Euler solver timed
in turn (``harness/paired.py``, a fresh process), the parts of the NumPy inverse dynamics'
time (``harness/numpy_parts.py``, another) and the Python benchmarks on pyperf
(``harness/pybench.py``, one pyperf run per group, fresh worker processes); and for every one of
the 18 structures, on its own model: its generation time (``harness/generation.py``: cold and
cached, fresh interpreters), the same C per-function harness and NumPy per function (pyperf);
and for every spatial robot of the gallery (the hexapods and Deltas of ``models/``), on its own
model and trajectory: the same C harness on its inverse dynamics, forward dynamics and tracked
forward kinematics, and MuJoCo's ``mj_forward`` on the same robot (``harness/mujoco.py``, in C).
Variants that ``generated/`` lacks are derived into the run's own cache folder (a temporary
``RPR3GEN_CACHE_DIR``), never the user's. Writes ``benchmarks/results.json`` (every figure, the
machine and its load average at the start and the end), then ``report.py`` turns it into
``benchmarks/results.md`` and, with ``--docs``, the Performance tables of ``docs/performance.md``.

``--quick`` (fewer repeats) and ``--structures rrr_1,prr_1`` (those structures alone, without
the paper's figures: about a minute a structure with ``--quick``) write ``results-quick.json``
and ``results-quick.md`` instead, so that they never replace the committed full results.
``--structures spatial`` (the spatial robots alone, about 5 minutes) writes
``spatial-results.json`` and ``.md``, and with ``--docs`` the spatial block of the page.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import pyperf

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report
from harness import cbench, examples, generation, mujoco, samples

#: Time the optimised C libraries, not the quick ones a first use runs on (rpr3gen.cbackend).
os.environ.setdefault("RPR3GEN_C_BUILD", "optimised")

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent
#: pyperf's options per group, full run / quick run (None: skipped).
PYPERF: dict[str, tuple[list[str], list[str] | None]] = {
    "functions": (["--processes", "2", "--values", "3"], ["--processes", "1", "--values", "1"]),
    # 18 structures x 14 functions: one process each, no calibration (a call takes milliseconds)
    "structures": (
        ["--processes", "1", "--values", "3", "--loops", "1"],
        ["--processes", "1", "--values", "1", "--loops", "1"],
    ),
    "calls": (["--processes", "3", "--values", "5"], ["--processes", "1", "--values", "3"]),
    "peers": (["--processes", "2", "--values", "3"], ["--processes", "1", "--values", "2"]),
    "regen": (
        ["--processes", "1", "--values", "3", "--loops", "1"],
        ["--processes", "1", "--values", "1", "--loops", "1"],
    ),
}


START = time.monotonic()


def log(message: str) -> None:
    print(f"[bench {time.monotonic() - START:5.0f} s] {message}", file=sys.stderr, flush=True)


def machine() -> dict[str, Any]:
    """CPU, cores, memory, versions and commit: what a figure depends on."""
    info = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    cpu = cpu_fields(info).get("model name", platform.processor())
    cc = subprocess.run([*cbench.CC, "--version"], capture_output=True, text=True, check=False)
    git = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO,
                         capture_output=True, text=True, check=False)  # fmt: skip
    dirty = subprocess.run(["git", "status", "--porcelain", "--", "derive", "generated", "src"],
                           cwd=REPO, capture_output=True, text=True, check=False)  # fmt: skip
    return {
        "cpu": cpu,
        "cpu_id": cpu_id(info),
        "cores": os.cpu_count(),
        "usable_cores": len(os.sched_getaffinity(0)),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pyperf": pyperf.__version__,
        "cc": cc.stdout.splitlines()[0] if cc.stdout else "?",
        "commit": git.stdout.strip() + (" (modified)" if dirty.stdout.strip() else ""),
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
    }


def cpu_fields(cpuinfo: str) -> dict[str, str]:
    """The first processor's ``key: value`` lines of ``/proc/cpuinfo``."""
    fields: dict[str, str] = {}
    for line in cpuinfo.splitlines():
        if not line.strip():
            break
        key, _, value = line.partition(":")
        fields[key.strip()] = value.strip()
    return fields


def cpu_id(cpuinfo: str) -> str:
    """What tells one CPU from another of the same ``model name`` (the benchmark machine has been
    a Zen 3, a first-generation Zen and a Zen 4, all "AMD EPYC"): family, model, clock and the
    widest vector instructions, e.g. ``"family 25 model 17, 2596 MHz, AVX-512"``; "" off Linux."""
    fields = cpu_fields(cpuinfo)
    if "cpu family" not in fields:
        return ""
    flags = set(fields.get("flags", "").split())
    vector = next((name for flag, name in (("avx512f", "AVX-512"), ("avx2", "AVX2"),
                                          ("avx", "AVX"), ("sse2", "SSE2")) if flag in flags),
                  "no SIMD")  # fmt: skip
    mhz = fields.get("cpu MHz", "")
    clock = f", {float(mhz):.0f} MHz" if mhz else ""
    return f"family {fields['cpu family']} model {fields.get('model', '?')}{clock}, {vector}"


def run_pyperf(
    group: str, quick: bool, structures: Sequence[str] = ()
) -> dict[str, dict[str, float]]:
    """One pyperf run of a group of ``harness/pybench.py``: median, min (s) and counts. Its
    workers use the run's cache of variants; ``structures``: those of the group ``structures``."""
    options = PYPERF[group][1 if quick else 0]
    if options is None or (group == "structures" and not structures):
        return {}
    with tempfile.TemporaryDirectory(prefix="rpr3bench-pyperf-") as tmp:
        out = Path(tmp) / f"{group}.json"
        subprocess.run(
            [sys.executable, str(BENCH / "harness" / "pybench.py"), group, "--quiet",
             "--warmups", "1", *options, "--inherit-environ", "RPR3GEN_CACHE_DIR",
             *(["--structures", ",".join(structures)] if structures else []), "-o", str(out)],
            check=True,
        )  # fmt: skip
        suite = pyperf.BenchmarkSuite.load(str(out))
    return {
        b.get_name(): {"median": b.median(), "min": min(b.get_values()),
                       "values": b.get_nvalue(), "loops": b.get_loops()}
        for b in suite.get_benchmarks()
    }  # fmt: skip


def run_harness(script: str, quick: bool) -> dict[str, Any]:
    """The JSON that ``harness/SCRIPT.py [--quick] -o FILE`` writes, run in a fresh process:
    ``paired`` (NumPy and the Newton-Euler solver timed in turn) or ``numpy_parts`` (where the
    NumPy inverse dynamics' time goes)."""
    with tempfile.TemporaryDirectory(prefix=f"rpr3bench-{script}-") as tmp:
        out = Path(tmp) / f"{script}.json"
        subprocess.run(
            [sys.executable, str(BENCH / "harness" / f"{script}.py"),
             *(["--quick"] if quick else []), "-o", str(out)],
            check=True,
        )  # fmt: skip
        return dict(json.loads(out.read_text()))


def dump(value: Any, indent: str = "") -> str:
    """JSON with one measurement a line: a dict of numbers and strings stays on one line."""
    if not isinstance(value, dict) or not any(isinstance(v, dict) for v in value.values()):
        return json.dumps(value, sort_keys=True)
    inner = indent + " "
    items = [f"{inner}{json.dumps(k)}: {dump(v, inner)}" for k, v in sorted(value.items())]
    return "{\n" + ",\n".join(items) + "\n" + indent + "}"


def results_path(quick: bool, spatial: bool = False) -> Path:
    """Where a run's results go: ``results.json``; ``spatial-results.json`` for a full run of
    the spatial robots alone; or ``results-quick.json`` (ignored by git) for a quick or other
    partial run, so that it never replaces the committed full results."""
    if quick:
        return BENCH / "results-quick.json"
    return BENCH / ("spatial-results.json" if spatial else "results.json")


def everything() -> tuple[str, ...]:
    """Every structure a full run measures: the planar ones, then the spatial robots."""
    return samples.structures() + samples.spatial()


def chosen(text: str) -> tuple[str, ...]:
    """The structures of ``--structures``: ``all``, ``spatial`` or variant names (planar or
    spatial), comma-separated."""
    known = everything()
    if text == "all":
        return known
    if text == "spatial":
        return samples.spatial()
    names = tuple(dict.fromkeys(name.strip() for name in text.split(",")))
    unknown = [name for name in names if name not in known]
    if unknown:
        raise argparse.ArgumentTypeError(
            f"not a structure: {', '.join(unknown)} (they are: all, spatial, {', '.join(known)})"
        )
    return names


def measure(results: dict[str, Any], selected: Sequence[str], quick: bool) -> None:
    """Every figure into ``results``: the paper's when every structure is measured, then the
    planar structures', then the spatial robots'. The variants come from the cache folder
    ``$RPR3GEN_CACHE_DIR``."""
    paper = samples.paper_variants() if tuple(selected) == everything() else ()
    structures = [v for v in selected if v in samples.structures()]
    spatial = [v for v in selected if v in samples.spatial()]
    results.update(paper=list(paper), structures=structures, spatial=spatial, c={},
                   generation={}, mujoco={})  # fmt: skip
    n, repeats = (20_000, 3) if quick else (100_000, 9)
    for variant in paper:
        for motion in samples.motions(variant):
            log(f"C functions: {variant}, {motion} motion")
            results["c"][f"{variant}/{motion}"] = cbench.run(variant, motion, n, repeats)
    cache = Path(os.environ["RPR3GEN_CACHE_DIR"])
    for variant in structures:
        log(f"{variant}: generation (cold, cached), model and motion")
        results["generation"][variant] = generation.run(variant, keep=cache)
        results["generation"][variant].update(
            model=samples.model_source(variant), scale=samples.scale(variant)
        )
        log(f"{variant}: C functions")
        results["c"][f"{variant}/generic"] = cbench.run(variant, "generic", n, repeats)
    for variant in spatial:
        log(f"{variant}: C functions (its model's trajectory)")
        # the forward dynamics takes microseconds: fewer samples, as many rounds
        results["c"][f"{variant}/trajectory"] = cbench.run(variant, "trajectory", n // 5, repeats)
        results["c"][f"{variant}/trajectory"]["model"] = samples.model_source(variant)
        log(f"{variant}: mj_forward, in C")
        results["mujoco"][variant] = mujoco.run(variant, repeats)
    if paper:
        log("control-loop examples")
        results["examples"] = examples.run(2 if quick else examples.RUNS)
        log("NumPy against Newton-Euler, in turn")
        results["paired"] = run_harness("paired", quick)
        log("NumPy inverse dynamics, where the time goes")
        results["numpy_parts"] = run_harness("numpy_parts", quick)
    results["python"] = {}
    for group in PYPERF if paper else ("structures",) if structures else ():
        log(f"pyperf: {group}")
        results["python"].update(run_pyperf(group, quick, structures))


def main() -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats; results-quick.*")
    parser.add_argument(
        "--docs", "--readme", dest="docs", action="store_true",
        help="also the tables of docs/performance.md (--readme: the former name)",
    )  # fmt: skip
    parser.add_argument(
        "--structures", type=chosen, default="all", metavar="LIST",
        help="the structures measured: all (the default: a full run), spatial (the spatial "
             "robots alone) or variant names, comma-separated (rrr_1,prr_1: those alone, "
             "without the paper's figures)",
    )  # fmt: skip
    args = parser.parse_args()
    partial = args.structures != everything()
    spatial = args.structures == samples.spatial()
    if args.docs and partial and not spatial:
        parser.error("--docs needs a run of every structure, or of the spatial robots alone")
    start = time.monotonic()
    results: dict[str, Any] = {"machine": machine(), "quick": args.quick,
                               "load_start": os.getloadavg()}  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="rpr3bench-cache-") as cache:
        os.environ["RPR3GEN_CACHE_DIR"] = cache  # the run's variants and C libraries
        measure(results, args.structures, args.quick)
    results["load_end"] = os.getloadavg()
    results["seconds"] = round(time.monotonic() - start)
    out = results_path(args.quick or (partial and not spatial), spatial)
    out.write_text(dump(results) + "\n")
    log(f"wrote {out.relative_to(REPO)}")
    report.main([str(out), *(["--docs"] if args.docs else [])])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
