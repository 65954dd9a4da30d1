"""The report: Markdown tables and number formats, the machine block, the targets and verdicts.

Every figure of a report is measured in the same run; the machine block says where and when,
and warns when the generated code changed while the run was going on.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import importlib.metadata
import os
import platform
import subprocess
from collections import defaultdict
from collections.abc import Sequence
from typing import Any

from rpr3bench.common import CC, CODE_IDS, REPO, VARIANT, shown, variant

#: Goals of the project, scored in the report's first table.
TARGETS = {
    "c_batch_floor": 1.2,  # C batch ns/sample <= 1.2 x the scalar floor
    "c_single_floor": 2.0,  # C single call <= 2 x the scalar floor
    "numpy_vs_ne": 20.0,  # NumPy batch >= 20 x faster than the Newton-Euler solve
    "numpy_1e6_ns": 500.0,  # NumPy at 10^6 samples < 500 ns/sample
    "python_single_us": 1.0,  # SampleEvaluator call < 1 us
    "regeneration_s": 5.0,  # full regeneration < 5 s
    # Control model (issue 12; section "Control model"):
    "control_fd_ns": 300.0,  # C forward dynamics, one call < 300 ns
    "control_fd_exact": 1e-12,  # forward dynamics of the ID efforts vs q'': max rel. error
    "control_tick_ns": 1000.0,  # one control tick in C < 1 us
    "control_python_tick_us": 10.0,  # one control tick in Python < 10 us
}
#: The function the targets score.
SCORED = "inverse_dynamics"


# ---------------------------------------------------------------------------------------------
# Tables and numbers
# ---------------------------------------------------------------------------------------------


def table(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    cells = [[str(c) for c in header]] + [[str(c) for c in row] for row in rows]
    widths = [max(len(row[k]) for row in cells) for k in range(len(header))]
    lines = ["| " + " | ".join(c.ljust(w) for c, w in zip(cells[0], widths, strict=True)) + " |"]
    lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for row in cells[1:]:
        lines.append("| " + " | ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) + " |")
    return "\n".join(lines)


def ns(value: float | None) -> str:
    if value is None:
        return "n/a"
    return f"{value:,.0f}" if value >= 1000 else f"{value:.1f}"


def secs(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.3f}"


def mb(value: float | None) -> str:
    return "n/a" if value is None else f"{value / 1e6:,.0f}"


def ratio(value: float | None) -> str:
    if value is None:
        return "n/a"
    return f"{value:.2f}x" if value < 100 else f"{value:,.0f}x"


def median(values: Sequence[float]) -> float:
    ordered = sorted(values)
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else 0.5 * (ordered[mid - 1] + ordered[mid])


def size_label(n: int) -> str:
    exponent = len(str(n)) - 1
    return f"10^{exponent}" if n == 10**exponent else f"{n:,}"


# ---------------------------------------------------------------------------------------------
# The machine
# ---------------------------------------------------------------------------------------------


def _command_output(command: Sequence[str]) -> str:
    try:
        done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
    except OSError:
        return "n/a"
    return (done.stdout.strip().splitlines() or ["n/a"])[0]


def loadavg() -> str:
    with open("/proc/loadavg") as handle:
        return " ".join(handle.read().split()[:3]) + " (1, 5, 15 min)"


def machine() -> dict[str, str]:
    model = "unknown"
    with contextlib.suppress(OSError), open("/proc/cpuinfo") as handle:
        for line in handle:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    lscpu = _command_output(["sh", "-c", "lscpu | grep -i 'model name'"])
    if lscpu != "n/a" and ":" in lscpu:
        model_lscpu = lscpu.split(":", 1)[1].strip()
        if model_lscpu and model_lscpu != model:
            model = f"{model} (lscpu: {model_lscpu})"
    mem_total = "n/a"
    with contextlib.suppress(OSError), open("/proc/meminfo") as handle:
        for line in handle:
            if line.startswith("MemTotal:"):
                mem_total = f"{int(line.split()[1]) / 1024**2:.1f} GiB"
    found = variant()
    dirty = _command_output(
        ["sh", "-c", "git status --porcelain -- derive generated src | wc -l"]
    ).strip()

    def version(package: str) -> str:
        try:
            return importlib.metadata.version(package)
        except importlib.metadata.PackageNotFoundError:
            return "not installed"

    return {
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        "cpu": model,
        "cores": f"{os.cpu_count()} logical, {len(os.sched_getaffinity(0))} usable",
        "memory": mem_total,
        "os": f"{platform.system()} {platform.release()} ({platform.machine()})",
        "python": platform.python_version(),
        "numpy": version("numpy"),
        "sympy": version("sympy"),
        "jinja2": version("jinja2"),
        "compiler": _command_output([*CC, "--version"]),
        "libc": " ".join(platform.libc_ver()),
        "git": _command_output(["git", "rev-parse", "--short", "HEAD"])
        + f" ({dirty} uncommitted paths in derive/ generated/ src/)",
        "generated code": f"{shown(found.folder)}, functions: {', '.join(found.functions)}",
        "generated source hash": found.source_hash[:16],
        "load average (start)": loadavg(),
    }


# ---------------------------------------------------------------------------------------------
# Targets
# ---------------------------------------------------------------------------------------------


def verdict(measured: float | None, limit: float, at_most: bool = True) -> tuple[str, str]:
    """("pass"/"miss", margin text) for measured <= limit (or >= limit)."""
    if measured is None:
        return "n/a", "not measured"
    factor = measured / limit if at_most else limit / measured
    if factor <= 1.0:
        return "**pass**", f"{1 / factor:.2f}x headroom"
    return "**miss**", f"{factor:.2f}x over"


def targets(results: dict[str, Any]) -> str:
    """The targets table, from the results of every section that ran."""
    c = results.get("c", {})
    floor = c.get("floor_ns")
    rows = []

    def add(
        name: str,
        measured_text: str,
        measured: float | None,
        limit: float,
        limit_text: str,
        at_most: bool = True,
    ) -> None:
        status, margin = verdict(measured, limit, at_most)
        rows.append([name, measured_text, limit_text, status, margin])

    if floor:
        b = c["batch_ns"] / floor
        s = c["single_ns"] / floor
        add(
            "C batch vs scalar floor",
            f"{ns(c['batch_ns'])} / {ns(floor)} ns = {ratio(b)}",
            b,
            TARGETS["c_batch_floor"],
            "≤ 1.2x",
        )
        add(
            "C single call vs scalar floor",
            f"{ns(c['single_ns'])} / {ns(floor)} ns = {ratio(s)}",
            s,
            TARGETS["c_single_floor"],
            "≤ 2x",
        )
    for n, value in sorted(results.get("peers", {}).get("ne_ratio", {}).items()):
        add(
            f"NumPy vs Newton–Euler, {size_label(n)}",
            f"{ratio(value)} faster",
            value,
            TARGETS["numpy_vs_ne"],
            "≥ 20x faster",
            at_most=False,
        )
    if "numpy" in results:
        backend = results["numpy"].get(SCORED, {}).get("backend", {})
        n6 = backend.get(10**6, {}).get("best_ns")
        add(
            "NumPy at 10^6 samples",
            f"{ns(n6)} ns/sample",
            n6,
            TARGETS["numpy_1e6_ns"],
            "< 500 ns/sample",
        )
    if "python" in results:
        py = results["python"].get("functions", {}).get(SCORED, {}).get("c_call")
        add(
            "Python single call (`SampleEvaluator`)",
            f"{py * 1e6:.3f} µs" if py else "n/a",
            py * 1e6 if py else None,
            TARGETS["python_single_us"],
            "< 1 µs",
        )
    if "regen" in results:
        regen = results["regen"]
        add(
            "full regeneration, `rpr3gen generate --check`",
            f"{secs(regen.get('cli'))} s",
            regen.get("cli"),
            TARGETS["regeneration_s"],
            "< 5 s",
        )
        add(
            "full regeneration, `generate.render()` in process",
            f"{secs(regen.get('total'))} s",
            regen.get("total"),
            TARGETS["regeneration_s"],
            "< 5 s",
        )
    if "control" in results:
        control = results["control"]
        for actuation, value in control.get("fd_ns", {}).items():
            add(
                f"C forward dynamics, one call ({actuation})",
                f"{ns(value)} ns",
                value,
                TARGETS["control_fd_ns"],
                "< 300 ns",
            )
        err = control.get("fd_rel_err")
        add(
            "forward dynamics of the ID efforts vs q'' (max relative error)",
            f"{err:.1e}" if err is not None else "n/a",
            err,
            TARGETS["control_fd_exact"],
            "≤ 1e-12",
        )
        for actuation, value in control.get("tick_ns", {}).items():
            add(
                f"C control tick ({actuation})",
                f"{ns(value)} ns",
                value,
                TARGETS["control_tick_ns"],
                "< 1 µs",
            )
        ticks = (
            ("python_tick_us", "generated calls only (3x3 solves in C)"),
            ("python_tick_floats_us", "3x3 solves on Python floats"),
        )
        for key, how in ticks:
            for actuation, value in control.get(key, {}).items():
                add(
                    f"Python control tick, {how} ({actuation})",
                    f"{value:.2f} µs",
                    value,
                    TARGETS["control_python_tick_us"],
                    "< 10 µs",
                )
    return table(["target", "measured", "goal", "result", "margin"], rows) + "\n"


def speed_summary(results: dict[str, Any]) -> str:
    """Issue 15's figures in one table: C single and batch against the floor, the threaded
    batch, NumPy against Newton-Euler, and every generated function against its own floor."""
    c = results.get("c", {})
    rows = []
    floor = c.get("floor_ns")
    if floor:
        rows.append(
            [
                f"`{SCORED}`: C single call, C batch 10^6 (streamed) / of 1,000 (in cache)",
                f"{ns(floor)} ns",
                f"{ns(c['single_ns'])} ns = {ratio(c['single_ns'] / floor)}",
                f"{ns(c['batch_ns'])} ns = {ratio(c['batch_ns'] / floor)} / "
                f"{ns(c['batch_small_ns'])} ns = {ratio(c['batch_small_ns'] / floor)}",
                "",
            ]
        )
    threads = c.get("threads") or {}
    if threads.get("threads"):
        k = threads["threads"][-1]
        cached = threads["cached"]
        streamed = threads["streamed"].get(str(10**6))
        rows.append(
            [
                f"C batch on {k} threads: speed-up over one",
                "",
                "",
                f"in cache {ratio(cached['1'] / cached[str(k)])}"
                + (f"; 10^6 streamed {ratio(streamed[0] / streamed[-1])}" if streamed else ""),
                "",
            ]
        )
    for n, value in sorted(results.get("peers", {}).get("ne_ratio", {}).items()):
        rows.append(
            [f"NumPy vs Newton–Euler, {size_label(n)}", "", "", "", f"{ratio(value)} faster"]
        )
    for name, f in results.get("functions", {}).items():
        base = f["floor_ns"]
        rows.append(
            [
                f"`{name}`",
                f"{ns(base)} ns",
                f"{ns(f['single_ns'])} ns = {ratio(f['single_ns'] / base)}",
                f"{ns(f['batch_ns'])} ns = {ratio(f['batch_ns'] / base)}",
                f"{ns(f['numpy_ns'])} ns = {ratio(f['numpy_ns'] / base)}" if f.get("numpy_ns")
                else "n/a",
            ]
        )  # fmt: skip
    if not rows:
        return ""
    return (
        table(["issue 15", "floor", "C single", "C batch", "NumPy"], rows)
        + "\n\nFloors: the libm calls a sample must make (section 3 for the headline: one "
        "sin/cos, 3 sqrt, 3 atan2; section 7 per function: the calls of its kernel after CSE). "
        "Per function, the C batch runs over chunks of 1,000 samples (outputs in cache) and "
        "NumPy is `evaluate` at 10^5 samples. Goals: C single ≤ 2x, C batch ≤ 1.2x the floor, "
        "NumPy ≥ 20x Newton–Euler.\n"
    )


README_BEGIN = "<!-- performance: written by `python benchmarks/run.py --readme`; do not edit -->"
README_END = "<!-- end of performance -->"


def readme_block(command: str, info: dict[str, str], results: dict[str, Any]) -> str:
    """The README's performance tables: where and when they were measured, the targets table,
    and issue 15's summary."""
    where = (
        f"`{command}`, {info.get('date', 'n/a')} ({info.get('cpu', 'n/a')}, "
        f"{info.get('cores', 'n/a')}, {info.get('compiler', 'n/a')}, git "
        f"{info.get('git', 'n/a').split(' ')[0]}; {info.get('run', 'n/a')}; load average "
        f"{info.get('load average (start)', 'n/a').split(' (')[0]} at the start, "
        f"{info.get('load average (end)', 'n/a').split(' (')[0]} at the end):"
    )
    parts = [README_BEGIN, where, "", targets(results), speed_summary(results).rstrip()]
    if "control" in results:
        from rpr3bench.control import _summary

        parts += ["", "The control model in that run:", "", _summary(results["control"]).rstrip()]
    return "\n".join([*parts, README_END])


def update_readme(path: Any, block: str) -> bool:
    """Replace the text between the README's performance markers by ``block``; False when the
    README has no such markers."""
    text = path.read_text(encoding="utf-8")
    start, end = text.find(README_BEGIN), text.find(README_END)
    if start < 0 or end < start:
        return False
    path.write_text(text[:start] + block + text[end + len(README_END) :], encoding="utf-8")
    return True


# ---------------------------------------------------------------------------------------------
# The document
# ---------------------------------------------------------------------------------------------


def document(
    command: str,
    info: dict[str, str],
    results: dict[str, Any],
    sections: Sequence[tuple[str, str]],
) -> str:
    """The whole report: machine block, a warning if the code changed, targets, sections."""
    ids = sorted({cid for _, cid in CODE_IDS if cid})
    info = {**info, "generated code id": ids[0] if len(ids) == 1 else "**changed during the run**"}
    lines = ["# rpr3gen benchmarks", "", f"`{command}`", ""]
    if len(ids) > 1:
        seen: dict[str, list[str]] = defaultdict(list)
        for label, cid in CODE_IDS:
            if label not in seen[cid]:
                seen[cid].append(label)
        lines.append(
            f"**Warning: generated/{VARIANT} changed while this run was going on**; figures "
            "measured on different code are not comparable. Code id (SHA-256 of the variant's "
            "manifest.json and generated sources) seen by each measurement:\n"
        )
        lines += [f"- `{cid}`: {'; '.join(labels)}" for cid, labels in seen.items()]
        lines.append("")
    lines.append(table(["machine", ""], [[k, v] for k, v in info.items()]))
    lines += ["", "## Targets", "", targets(results)]
    summary = speed_summary(results)
    if summary:
        lines += ["### Speed (issue 15)", "", summary]
    for title, body in sections:
        lines += [f"## {title}", "", body]
    return "\n".join(lines).rstrip() + "\n"
