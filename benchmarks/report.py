"""Tables from a benchmark run: ``python benchmarks/report.py results.json [--docs]``.

Reads what ``run.py`` wrote and writes the Markdown beside it (``results.json`` ->
``results.md``); with ``--docs`` also the Performance block of ``docs/performance.md``, between
its ``<!-- performance`` markers. Every figure comes from the one file; nothing is measured here.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
#: The page whose Performance block ``--docs`` writes.
PAGE = REPO / "docs" / "performance.md"
BEGIN = "<!-- performance: written by `python benchmarks/run.py --docs`; do not edit -->"
END = "<!-- end of performance -->"
SPATIAL_BEGIN = (
    "<!-- spatial performance: written by `python benchmarks/run.py --structures spatial --docs` "
    "or a full run's `--docs`; do not edit -->"
)
SPATIAL_END = "<!-- end of spatial performance -->"
#: The spatial robots' measured functions, in the tables' order.
SPATIAL_FUNCTIONS = ("inverse_dynamics", "forward_dynamics", "forward_kinematics")
#: Issue 49's goals for the spatial robots: (what, variants, function, goal in ns).
SPATIAL_GOALS = (
    ("6-UPS inverse dynamics, every joint load, one call", ("ups_2",), "inverse_dynamics", 1000),
    ("Delta inverse dynamics, every joint load, one call", ("rss2_1", "pss2_1"),
     "inverse_dynamics", 300),
    ("hexapod tracked forward kinematics, one call", ("ups_2", "rus_1", "pus_1"),
     "forward_kinematics", 2000),
)  # fmt: skip
#: ``mj_forward`` against our forward dynamics' call, at least (issue 49).
PEER_GOAL = 10.0
#: The spatial robots' names in the tables, by variant (a variant not here: its name).
ROBOTS = {"ups_2": "6-UPS", "rus_1": "6-RUS", "pus_1": "6-PUS", "rss2_1": "Delta (3-RSS2)",
          "pss2_1": "linear Delta (3-PSS2)"}  # fmt: skip
#: The tick's generated calls in the Python example (control_loop.py's Controller).
TICK_CALLS = ("forward_kinematics", "platform_velocity", "actuator_efforts")
#: The functions of the structures' compact table (the forward kinematics has no NumPy version
#: and no C row: its modes are ``assembly_modes``).
KEY_FUNCTIONS = ("inverse_dynamics", "forward_dynamics", "assembly_modes", "actuator_jacobian")


def table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows]) + "\n"


def ns(value: float) -> str:
    return f"{value:.0f} ns" if value >= 100 else f"{value:.1f} ns"


def verdict(value: float, goal: float, below: bool) -> str:
    ok = value <= goal if below else value >= goal
    return "**pass**" if ok else "**miss**"


def header(r: dict[str, Any]) -> str:
    m = r["machine"]
    load = (
        " ".join(f"{x:.2f}" for x in r["load_start"]),
        " ".join(f"{x:.2f}" for x in r["load_end"]),
    )
    kind = "quick" if r["quick"] else "full"
    cpu = m["cpu"] + (f" ({m['cpu_id']})" if m.get("cpu_id") else "")  # runs before 2026-11-28
    return (f"`python benchmarks/run.py`, {m['date']}, git {m['commit']} "
            f"({kind}, {r['seconds']} s): "
            f"{cpu}, {m['cores']} logical cores ({m['usable_cores']} usable), {m['cc']}, "
            f"Python {m['python']}, NumPy {m['numpy']}, pyperf {m['pyperf']}; load average "
            f"{load[0]} at the start, {load[1]} at the end.\n")  # fmt: skip


def c_figures(r: dict[str, Any], key: str) -> dict[str, dict[str, float]]:
    """``{function: {"floor", "single", "batch", "chain": ns, "agree": 0|1, "failed": n}}``: the
    best of the repeats (the least disturbed by other processes: the machine is shared);
    ``chain``: the chain floor (runs before 2026-11-27 and the iterative forward kinematics have
    none); ``failed``: the samples on which a single call failed."""
    found: dict[str, dict[str, float]] = {}
    for name, value in r["c"][key]["results"].items():
        function, what = name.split("/")
        if what == "agree":
            found.setdefault(function, {}).update(agree=value["agree"],
                                                  failed=value["failed_single"])  # fmt: skip
        else:
            found.setdefault(function, {})[what] = value["min"]
    return found


def paper(r: dict[str, Any]) -> list[str]:
    """The paper's variants of the run (a run before the structures: every variant in it)."""
    return list(r["paper"]) if "paper" in r else sorted({key.split("/")[0] for key in r["c"]})


def agreed(x: dict[str, float]) -> str:
    """The ``single = batch`` cell: the bit check, and the failed samples if any."""
    cell = "yes" if x["agree"] == 1 else "**no**"
    return cell + (f", **{x['failed']:.0f} failed**" if x.get("failed") else "")


def py(r: dict[str, Any], name: str) -> float | None:
    found = r["python"].get(name)
    return None if found is None else float(found["min"])


def ne_ratios(r: dict[str, Any], variant: str) -> list[tuple[str, int, float, float, float]]:
    """(motion, n, NumPy ns/sample, Newton-Euler ns/sample, median ratio) of the variant, from
    the rounds of ``harness/paired.py``: each side's best round, and the median over the rounds
    of Newton-Euler / NumPy within a round."""
    rows = []
    for name, sides in r.get("paired", {}).items():
        _, v, motion, size = name.split("/")
        if v == variant:
            n = int(size)
            ours, ne = sides["numpy"], sides["newton_euler"]
            within = statistics.median(b / a for a, b in zip(ours, ne, strict=True))
            rows.append((motion, n, min(ours) / n * 1e9, min(ne) / n * 1e9, within))
    return sorted(rows)


def targets(r: dict[str, Any]) -> str:
    rows = []
    for v in paper(r):
        c = c_figures(r, f"{v}/generic")
        for f, goal in (("inverse_dynamics", 2.0), ("forward_dynamics", 2.0)):
            x = c[f]["single"] / c[f]["floor"]
            rows.append([f"C single / floor, `{f}` ({v})",
                         f"{ns(c[f]['single'])} / {ns(c[f]['floor'])} = {x:.2f}x{chained(c[f])}",
                         f"≤ {goal}x", verdict(x, goal, True)])  # fmt: skip
        x = c["inverse_dynamics"]["batch"] / c["inverse_dynamics"]["floor"]
        rows.append([f"C batch / floor, `inverse_dynamics` ({v})", f"{x:.2f}x", "≤ 1.2x",
                     verdict(x, 1.2, True)])  # fmt: skip
        fd = c["forward_dynamics"]["single"]
        rows.append([f"C forward dynamics, one call ({v})", ns(fd), "< 300 ns",
                     verdict(fd, 300, True)])  # fmt: skip
        for motion in ("generic", "rotation"):
            ratios = [(ne / ours, n) for m, n, ours, ne, _ in ne_ratios(r, v) if m == motion]
            if ratios:
                worst = min(ratios)[0]
                text = ", ".join(f"{x:.1f}x at 10^{len(str(k)) - 1}" for x, k in ratios)
                rows.append([f"NumPy vs Newton–Euler, {motion} motion ({v})", text, "≥ 20x",
                             verdict(worst, 20, False)])  # fmt: skip
        ticks = {k.split("/")[1]: t for k, t in r["examples"]["c"].items() if k.startswith(v)}
        if ticks:
            worst = max(t["whole tick"]["p50"] for t in ticks.values())
            text = ", ".join(f"{ns(t['whole tick']['p50'])} {k}" + runs_note(t)
                             for k, t in sorted(ticks.items()))  # fmt: skip
            rows.append([f"C control tick p50, the example ({v})", text, "< 500 ns",
                         verdict(worst, 500, True)])  # fmt: skip
        calls = [py(r, f"calls/{v}/{f}") for f in TICK_CALLS]
        if all(calls):
            total = sum(c for c in calls if c) * 1e6
            rows.append([f"Python: a tick's generated calls, `SampleEvaluator` ({v})",
                         f"{total:.2f} µs", "< 5 µs", verdict(total, 5, True)])  # fmt: skip
        single = py(r, f"calls/{v}/inverse_dynamics")
        if single:
            rows.append([f"Python single call, `inverse_dynamics` ({v})", f"{single * 1e6:.3f} µs",
                         "< 1 µs", verdict(single * 1e6, 1, True)])  # fmt: skip
        big = [ours for m, n, ours, _, _ in ne_ratios(r, v) if (m, n) == ("generic", 10**6)]
        if big:
            rows.append([f"NumPy at 10^6, generic motion ({v})", f"{big[0]:.0f} ns/sample",
                         "< 500 ns", verdict(big[0], 500, True)])  # fmt: skip
    regen = py(r, "regen/generate_check")
    if regen:
        rows.append(["full regeneration, `rpr3gen generate --check`", f"{regen:.2f} s", "< 5 s",
                     verdict(regen, 5, True)])  # fmt: skip
    return table(["target", "measured", "goal", "result"], rows)


def over_chain(x: dict[str, float]) -> str:
    """``68 ns = 1.45x``: the chain floor and the single call's ratio to it, if measured."""
    return f"{ns(x['chain'])} = {x['single'] / x['chain']:.2f}x" if "chain" in x else ""


def chained(x: dict[str, float]) -> str:
    """`` (chain floor 68 ns = 1.45x)`` after a target's figure, if measured."""
    return f" (chain floor {over_chain(x)})" if "chain" in x else ""


def functions(r: dict[str, Any], v: str) -> str:
    rows = []
    c = c_figures(r, f"{v}/generic")
    for f, x in c.items():
        numpy = py(r, f"functions/{v}/{f}")
        cells = [f"`{f}`", ns(x["floor"])]
        cells.append(over_chain(x))
        cells += [f"{ns(x[k])} = {x[k] / x['floor']:.2f}x" for k in ("single", "batch")]
        cells.append(f"{ns(numpy * 1e4)} = {numpy * 1e4 / x['floor']:.2f}x" if numpy else "")
        cells.append(agreed(x))
        rows.append(cells)
    if f"{v}/rotation" in r["c"]:
        rot = c_figures(r, f"{v}/rotation")["inverse_dynamics"]
        rows.append(["`inverse_dynamics`, rotation motion", ns(rot["floor"]),
                     over_chain(rot),
                     *(f"{ns(rot[k])} = {rot[k] / rot['floor']:.2f}x" for k in ("single", "batch")),
                     "", agreed(rot)])  # fmt: skip
    flags = r["c"][f"{v}/generic"]["flags"]
    head = ["function", "floor", "chain floor", "C single", "C batch", "NumPy", "single = batch"]
    return f"**{v}** (`cc {flags}`; ns per sample, best of the repeats):\n\n" + table(head, rows)


def ratio(x: float) -> str:
    """A ratio to its floor: two figures (``0.96``, ``2.3``, ``12``, ``150``)."""
    return f"{x:.2f}" if x < 1 else f"{x:.1f}" if x < 10 else f"{x:.0f}"


def title(variant: str) -> str:
    """``3-PRR/2``: a structure's leg type and actuated joint, from its variant's name."""
    leg, _, joint = variant.partition("_")
    return f"3-{leg.upper()}/{joint}"


def structures(r: dict[str, Any]) -> str:
    """The compact table: per structure its generation times and, for :data:`KEY_FUNCTIONS`,
    C single, C batch and NumPy against the function's floor."""
    rows = []
    for v in r.get("structures", []):
        g, c = r["generation"][v], c_figures(r, f"{v}/generic")
        cached = sum(g["cached"][k] for k in ("derive", "numpy", "c"))
        cold = f"{g['cold']['derive']:.1f} + {g['cold']['c']:.1f} s"
        cells = [f"{title(v)} `{v}`", f"{g['model']}; x{g['scale']:.2g}", cold,
                 f"{cached * 1e3:.0f} ms"]  # fmt: skip
        for f in KEY_FUNCTIONS:
            x, numpy = c[f], py(r, f"functions/{v}/{f}")
            ratios = [ratio(x[k] / x["floor"]) for k in ("single", "batch")]
            cells.append(" / ".join([*ratios, ratio(numpy * 1e4 / x["floor"]) if numpy else "-"]))
        cells.append(agreed({"agree": min(x["agree"] for x in c.values()),
                             "failed": sum(x["failed"] for x in c.values())}))  # fmt: skip
        rows.append(cells)
    head = ["structure", "model; motion's scale", "generation: derive + C build", "cached",
            *(f"`{f}`" for f in KEY_FUNCTIONS), "single = batch"]  # fmt: skip
    return (
        "Generation: the variant's first use in a fresh interpreter with an empty cache "
        "(SymPy derivation and emission, then the C library's build) and in a second fresh "
        "interpreter (finding the variant, importing its NumPy module, loading its C "
        "library). Per function: C single / floor, C batch / floor, NumPy (10^5 samples) / "
        "floor, on the structure's generic motion.\n\n" + table(head, rows)
    )


def generation(r: dict[str, Any]) -> str:
    """Every step of every structure's first uses, cold and cached (seconds)."""
    steps = ("import", "derive", "numpy", "c", "wall")
    rows = []
    for v in r.get("structures", []):
        g = r["generation"][v]
        rows.append([f"`{v}`", *(f"{g[kind][k]:.3f}" for kind in ("cold", "cached")
                                 for k in steps)])  # fmt: skip
    label = {"wall": "process"}
    head = [f"{kind}: {label.get(k, k)}" for kind in ("cold", "cached") for k in steps]
    return table(["variant", *head], rows)


def numpy_vs_ne(r: dict[str, Any]) -> str:
    rows = [[v, m, f"10^{len(str(n)) - 1}", str(len(r["paired"][f"paired/{v}/{m}/{n}"]["numpy"])),
             f"{ours:.0f} ns", f"{ne:.0f} ns", f"{ne / ours:.1f}x", f"{within:.1f}x"]
            for v in paper(r) for m, n, ours, ne, within in ne_ratios(r, v)]  # fmt: skip
    head = ["variant", "motion", "samples", "rounds", "NumPy, best round", "Newton–Euler, best",
            "ratio of the bests", "median of the rounds' ratios"]  # fmt: skip
    return table(head, rows)


def numpy_parts(r: dict[str, Any]) -> str:
    """Where the NumPy inverse dynamics' time goes (``harness/numpy_parts.py``), ns per sample."""
    rows = []
    for v, x in sorted(r.get("numpy_parts", {}).items()):
        steps = [("floor", x["floor"]), ("kernel", x["kernel"] - x["floor"]),
                 ("checked", x["checked"] - x["kernel"]),
                 ("evaluate", x["evaluate"] - x["checked"])]  # fmt: skip
        fresh = f"{x['fresh']:.0f} = {x['fresh'] / x['floor']:.2f}x" if "fresh" in x else ""
        rows.append([v, f"{x['calls']:.0f}", f"{x['floor']:.0f}",
                     *(f"{d:+.0f} = {x[k]:.0f}" for k, d in steps[1:]),
                     f"{x['evaluate'] / x['floor']:.2f}x", fresh])  # fmt: skip
    head = ["variant", "ufunc calls a block", "eager floor", "kernel", "+ failure checks",
            "+ the rest: `evaluate`", "`evaluate` / floor",
            "`evaluate`, new output pages / floor"]  # fmt: skip
    return table(head, rows)


def runs_note(tick: dict[str, Any]) -> str:
    """`` (best of 5 runs, median 601 ns)`` for a tick measured in several runs, else ``""``."""
    runs = tick.get("runs", [])
    if len(runs) < 2:
        return ""
    return f" (best of {len(runs)} runs, median {ns(statistics.median(runs))})"


def control_loop(r: dict[str, Any]) -> str:
    rows = []
    for key in sorted(r["examples"]["c"]):
        c, p = r["examples"]["c"][key], r["examples"]["python"].get(key, {})
        cells = [*key.split("/")]
        cells += [f"{c[k]['p50']:.0f}" for k in ("forward kinematics", "rest of the tick")]
        cells.append(f"{c['whole tick']['p50']:.0f} / {c['whole tick']['p99']:.0f}")
        cells.append(", ".join(f"{x:.0f}" for x in c.get("runs", [])))
        if p:
            cells.append(f"{p['whole tick']['p50'] / 1e3:.2f} / {p['whole tick']['p99'] / 1e3:.2f}")
        rows.append(cells)
    head = ["variant", "trajectory", "C: FK p50 (ns)", "C: rest p50", "C: tick p50 / p99",
            "C: tick p50, every run", "Python: tick p50 / p99 (µs)"]  # fmt: skip
    # The generated folder as the Makefile names it, not the measuring checkout's absolute path.
    build = re.sub(r"/\S*?/generated/", "$(GENERATED)/", r["examples"]["build"])
    return f"Build: `{build}`\n\n" + table(head, rows)


def calls(r: dict[str, Any]) -> str:
    rows = []
    for name in sorted(r["python"]):
        parts = name.split("/")
        if parts[0] == "calls" and len(parts) == 3:
            call, nan = py(r, name), py(r, name + "/nan")
            assert call is not None
            floor = f"{nan * 1e6:.3f}" if nan else ""
            rows.append([parts[1], f"`{parts[2]}`", f"{call * 1e6:.3f}", floor,
                         f"{(call - (nan or 0)) * 1e6:.3f}"])  # fmt: skip
    arrays = [f"`rpr3gen.{name.split('/')[2]}` ({name.split('/')[1]}) "
              f"{py(r, name) * 1e6:.0f} µs"  # type: ignore[operator]
              for name in sorted(r["python"]) if name.startswith("array/")]  # fmt: skip
    text = table(["variant", "function", "call (µs)", "NaN input: the ctypes floor", "the C"], rows)
    if arrays:
        text += (
            '\nThe array API on one sample, `backend="c"` (its checks, the parameter '
            "vector and the named outputs around the same C): " + ", ".join(arrays) + ".\n"
        )
    return text


FLOOR = (
    "*Floor*: the libm calls the function's generated kernel makes (sin, cos, sqrt, atan2), in a "
    "loop, nothing else (the ratios of the C and NumPy columns are to it). *Chain floor*: the "
    "kernel's longest chain of dependent operations, each at its latency measured in the same "
    "run (`benchmarks/c/latency.c`), and the single call's ratio to it: what one call takes "
    "when it waits for nothing but itself (back-to-back calls can overlap and go below it). "
    "*C single*: the function once per sample, back to back; *C batch*: over "
    "chunks of 1,000 samples, outputs in cache; *NumPy*: `evaluate` at 10^5 samples (allocation "
    "and checks included), ns per sample.\n"
)


def paper_parts(r: dict[str, Any]) -> list[str]:
    """The paper's robot's sections (a run of some structures alone has none)."""
    peers = [f"`mj_forward` ({name.split('/')[1]}) {py(r, name) * 1e6:.2f} µs"  # type: ignore[operator]
             for name in sorted(r["python"]) if name.startswith("peers/")]  # fmt: skip
    return [
        "\n## Targets\n", targets(r),
        "\n## Every function against its floor (generic motion)\n", FLOOR,
        *(functions(r, v) + "\n" for v in paper(r)),
        "## NumPy against Newton–Euler\n",
        "`evaluate(model, \"inverse_dynamics\", ...)` against `tests/newton_euler.py` on the same "
        "samples (in chunks of 10^5), ns per sample, timed in turn in one process "
        "(`harness/paired.py`): each round times both sides back to back, so that a slow spell "
        "of this shared machine falls on both. The ratio of the two best rounds is the target's "
        "figure; the median of the rounds' own ratios shows how far a spell moves it.\n\n",
        numpy_vs_ne(r),
        "\nWhere the NumPy inverse dynamics' time goes, ns per sample at 10^5 samples of the "
        "generic motion, each the best of its rounds (`harness/numpy_parts.py`). *Eager floor*: "
        "the very ufunc calls of one block of the generated kernel, replayed on rows that stay "
        "in cache, nothing between them (the sums of the output rows included); *kernel*: the "
        "generated function block by block into outputs allocated once (above the floor: its "
        "working set streamed from the outer caches, its Python statements); *failure checks*: "
        "the evaluator's short cut on those sums and the other tested arrays "
        "(`rpr3gen.failures.none_failed`), and the per-sample checks of a block it cannot "
        "clear; *the rest*: `evaluate` itself, called again and again with each result dropped "
        "before the next call, so that its outputs reuse that result's memory "
        "(`rpr3gen.buffers`); *new output pages*: the same with that reuse off, as a first call "
        "or one whose caller keeps its earlier results: the kernel maps and zeroes the new "
        "arrays' pages at their first writes.\n\n",
        numpy_parts(r),
        "\n## The control-loop examples' latencies\n",
        "Each program's own report, 3 s at 1 kHz (`examples/control_loop`). The C program "
        "runs several times and the run with the lowest tick p50 is shown (its FK, rest and "
        "p99 are that run's), with every run's tick p50 after it (`harness/examples.py`: the "
        "same binary's p50 moves by up to half between runs on this shared machine); the "
        "Python program runs once. The ticks alternate: an even one is split at the end of its "
        "forward kinematics (FK and rest), an odd one is timed whole, with no clock reading "
        "inside it (one costs ~30 ns, `clock_gettime` on this machine).\n\n",
        control_loop(r),
        "\n## Python calls (`SampleEvaluator`, the C through ctypes)\n", calls(r),
        "\n## Peers\n",
        ", ".join(peers) + (" from Python.\n" if peers else "MuJoCo not installed.\n"),
    ]  # fmt: skip


def structure_parts(r: dict[str, Any]) -> list[str]:
    """The structures' sections: the compact table, generation's steps, every function."""
    return [
        "\n## Every structure\n", structures(r),
        "\n### Generation, step by step (s)\n",
        "`import rpr3gen`; finding the variant (cold: deriving and writing it); importing its "
        "NumPy module; its C library (cold: compiling it); the whole process, interpreter "
        "included. Cold derives even `rrr_1`, which the package carries.\n\n",
        generation(r),
        "\n### Every function against its floor, per structure (generic motion)\n", FLOOR,
        *("\n" + functions(r, v) for v in r["structures"]),
    ]  # fmt: skip


def robot(r: dict[str, Any], v: str) -> str:
    """``6-UPS `ups_2` (models/tsai-ups.toml)``: a spatial robot's row head."""
    model = r["c"][f"{v}/trajectory"].get("model", "")
    return f"{ROBOTS.get(v, v)} `{v}`" + (f" ({model})" if model else "")


def mj_forward(r: dict[str, Any], v: str) -> float | None:
    """MuJoCo's ``mj_forward`` on the spatial robot ``v``, ns a call (the best of the rounds)."""
    found = r.get("mujoco", {}).get(v)
    return None if found is None else float(found["results"]["mj_forward/single"]["min"])


def spatial_targets(r: dict[str, Any]) -> str:
    """Issue 49's goals, per spatial robot of the run."""
    rows = []
    for what, variants, f, goal in SPATIAL_GOALS:
        for v in (v for v in variants if v in r.get("spatial", [])):
            x = c_figures(r, f"{v}/trajectory")[f]["single"]
            rows.append([f"{what} ({ROBOTS.get(v, v)})", ns(x), f"< {ns(goal)}",
                         verdict(x, goal, True)])  # fmt: skip
    for v in r.get("spatial", []):
        mj, c = mj_forward(r, v), c_figures(r, f"{v}/trajectory")
        if mj is None:
            continue
        fd, inv = c["forward_dynamics"]["single"], c["inverse_dynamics"]["single"]
        rows.append([f"`mj_forward` / forward dynamics, one call ({ROBOTS.get(v, v)})",
                     f"{ns(mj)} / {ns(fd)} = {mj / fd:.1f}x (inverse dynamics "
                     f"{mj / inv:.0f}x)", f"≥ {PEER_GOAL:.0f}x",
                     verdict(mj / fd, PEER_GOAL, False)])  # fmt: skip
    return table(["target", "measured", "goal", "result"], rows)


def spatial(r: dict[str, Any]) -> str:
    """Per spatial robot and function: C single and batch, both floors and ``mj_forward``."""
    rows = []
    for v in r.get("spatial", []):
        c, mj = c_figures(r, f"{v}/trajectory"), mj_forward(r, v)
        chains = r["c"][f"{v}/trajectory"]["results"]
        for k, f in enumerate(SPATIAL_FUNCTIONS):
            if f not in c:
                continue
            x = c[f]
            through = chains.get(f"{f}/chain", {}).get("kernel")
            chain = ns(x["chain"]) + (f" (`{through}`)" if through else "") if "chain" in x else ""
            rows.append([
                robot(r, v) if k == 0 else "", f"`{f}`", ns(x["single"]), ns(x["batch"]),
                f"{ns(x['floor'])}: {ratio(x['single'] / x['floor'])} / "
                f"{ratio(x['batch'] / x['floor'])}",
                f"{chain}: {ratio(x['single'] / x['chain'])}" if chain else "",
                f"{ns(mj)}: {ratio(mj / x['single'])}" if mj else "", agreed(x),
            ])  # fmt: skip
    head = ["robot", "function", "C single", "C batch", "libm floor: single / batch",
            "chain floor: single", "`mj_forward`: / single", "single = batch"]  # fmt: skip
    flags = next((r["c"][f"{v}/trajectory"]["flags"] for v in r.get("spatial", [])), "")
    version = next((x["version"] for x in r.get("mujoco", {}).values()), "?")
    return (
        f"`cc {flags}`; MuJoCo {version}. ns per call, best of the rounds; a ratio is the "
        "column's floor (or `mj_forward`) against the call. *libm floor*: the `sin`, `cos`, "
        "`sqrt`, `atan2` calls the kernel makes, the kernels it calls included (the forward "
        "dynamics' one `efforts_matrix`; the tracked forward kinematics' one Newton step: "
        "two evaluations of `qa` and `J`); *chain floor*: the kernel's longest chain of "
        "dependent operations, or where the kernel is not straight-line code, the longest of "
        "the kernels it calls (named): a looser bound; *`mj_forward`*: MuJoCo's forward pass on "
        "the exported robot at the same states, in C, how many times the call's time.\n\n"
        + table(head, rows)
    )


def spatial_parts(r: dict[str, Any]) -> list[str]:
    """The spatial robots' sections: the goals and the table."""
    return ["\n## Spatial robots\n", spatial_targets(r), "\n", spatial(r)]


def document(r: dict[str, Any]) -> str:
    parts = ["# Benchmark results\n", header(r)]
    parts += paper_parts(r) if paper(r) else []
    parts += structure_parts(r) if r.get("structures") else []
    parts += spatial_parts(r) if r.get("spatial") else []
    return "".join(parts)


def docs_block(r: dict[str, Any]) -> str:
    every = ["**Every structure**:\n", structures(r)] if r.get("structures") else []
    return "\n".join([BEGIN, header(r), targets(r), functions(r, "revolute"), control_loop(r),
                      *every, END])  # fmt: skip


def spatial_block(r: dict[str, Any]) -> str:
    return "\n".join([SPATIAL_BEGIN, header(r), spatial_targets(r), spatial(r), SPATIAL_END])


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("results", help="the JSON file run.py wrote")
    parser.add_argument(
        "--docs", "--readme", dest="docs", action="store_true",
        help="also the tables of docs/performance.md (--readme: the former name)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    path = Path(args.results)
    r = json.loads(path.read_text())
    path.with_suffix(".md").write_text(document(r))
    if args.docs:
        text = PAGE.read_text()
        if paper(r):
            pattern = re.compile(re.escape(BEGIN) + ".*?" + re.escape(END), re.S)
            text = pattern.sub(lambda _: docs_block(r), text, count=1)
        if r.get("spatial"):
            pattern = re.compile(re.escape(SPATIAL_BEGIN) + ".*?" + re.escape(SPATIAL_END), re.S)
            text = pattern.sub(lambda _: spatial_block(r), text, count=1)
        PAGE.write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
