"""The control-loop examples as benchmarks: their own tick latencies (issue 20's figure).

``examples/control_loop`` is built by its Makefile (its flags, against ``generated/``) into a
temporary folder, and both programs, C and Python, run each of the paper's variants (the
examples drive the paper's robot) on both paper trajectories for 3 s; each prints the latency
(p50, p99, max) of its forward kinematics, of the rest of the tick and of the whole tick, which
are parsed here.

The C program runs :data:`RUNS` times per variant and trajectory, and the run with the lowest
tick p50 is kept, with every run's p50 beside it (``"runs"``): on this shared machine the same
binary's tick p50 moved between 461 and 691 ns in runs seconds apart (2026-11-27), so one run
measures the neighbours as much as the code; the best of several is what the rest of the
benchmark takes too (the best of the repeats). The runs go round the four cases in turn
(:func:`rounds`), as ``c/functions.c`` goes round the functions: a case's runs spread over the
minute the examples take, where back to back they could all fall in one slow spell (one full
run of 2026-11-27 had all five of one case at 732-761 ns and all five of another at 351).
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from harness import samples
from rpr3gen import manifest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "control_loop"
TRAJECTORIES = ("rectilinear", "rotation")
#: Runs of the C program per variant and trajectory (a quick run: two).
RUNS = 5
LATENCY = re.compile(r"latency (.+): p50 ([\d.]+) (ns|us), p99 ([\d.]+) \3, max ([\d.]+) \3")


def parse(text: str) -> dict[str, dict[str, float]]:
    """``{"whole tick": {"p50": ns, "p99": ns, "max": ns}, ...}`` from a program's report."""
    found = {}
    for label, p50, unit, p99, worst in LATENCY.findall(text):
        scale = 1e3 if unit == "us" else 1.0
        found[label] = {"p50": float(p50) * scale, "p99": float(p99) * scale,
                        "max": float(worst) * scale}  # fmt: skip
    return found


def best_run(reports: list[dict[str, dict[str, float]]]) -> dict[str, Any]:
    """The report of the run with the lowest tick p50, with ``"runs"``: every run's tick p50 in
    the order they ran."""
    best = min(reports, key=lambda found: found["whole tick"]["p50"])
    return {**best, "runs": [found["whole tick"]["p50"] for found in reports]}


def rounds(cases: list[tuple[str, str]], runs: int) -> list[tuple[str, str]]:
    """The order the C program runs ``cases``: each once, ``runs`` times over."""
    return [case for _ in range(runs) for case in cases]


def run(runs: int = RUNS) -> dict[str, Any]:
    """Latencies by language, variant and trajectory, with the C build's flags; the C program
    run ``runs`` times (:func:`best_run`)."""
    results: dict[str, Any] = {"c": {}, "python": {}}
    with tempfile.TemporaryDirectory(prefix="rpr3bench-loop-") as tmp:
        work = Path(tmp)
        for name in ("Makefile", "control_loop.c"):
            shutil.copy(EXAMPLE / name, work / name)
        generated = Path(manifest.default_folder())
        made = subprocess.run(["make", "-s", f"GENERATED={generated}", "-n"], cwd=work,
                              capture_output=True, text=True, check=True)  # fmt: skip
        results["build"] = made.stdout.splitlines()[0] if made.stdout else ""
        subprocess.run(["make", "-s", f"GENERATED={generated}"], cwd=work, check=True)
        params = subprocess.run([sys.executable, "-m", "rpr3gen.cli", "params"],
                                capture_output=True, text=True, check=True)  # fmt: skip
        (work / "paper.params").write_text(params.stdout)
        cases = [(v, t) for v in samples.paper_variants() for t in TRAJECTORIES]
        reports: dict[tuple[str, str], list[dict[str, dict[str, float]]]] = {c: [] for c in cases}
        built = [(v, t) for v, t in cases if (work / f"control_loop_{v}").exists()]
        for variant, trajectory in rounds(built, runs):
            done = subprocess.run([str(work / f"control_loop_{variant}"), trajectory], cwd=work,
                                  capture_output=True, text=True, check=True)  # fmt: skip
            reports[variant, trajectory].append(parse(done.stdout))
        for variant, trajectory in cases:
            key = f"{variant}/{trajectory}"
            if reports[variant, trajectory]:
                results["c"][key] = best_run(reports[variant, trajectory])
            done = subprocess.run(
                [sys.executable, str(EXAMPLE / "control_loop.py"), "--actuation", variant,
                 trajectory], cwd=work, capture_output=True, text=True, check=True,
            )  # fmt: skip
            results["python"][key] = parse(done.stdout)
    return results
