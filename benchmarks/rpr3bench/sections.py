"""The sections of the report: what each runs, and its table and notes.

Each ``section_*`` returns ``(Markdown text, results)``; the results feed later sections and the
targets (:func:`rpr3bench.report.targets`). Sections that are per function iterate over the
functions of the measured variant's manifest that the benchmarks can give samples
(:func:`rpr3bench.common.functions`), so a new generated function adds rows.
"""

from __future__ import annotations

import subprocess
import time
from collections import defaultdict
from typing import Any

from rpr3bench import charness, speed
from rpr3bench.common import (
    CODE_IDS,
    PY,
    REPO,
    TRAJECTORY,
    VARIANT,
    code_id,
    functions,
    log,
    mem_available,
)
from rpr3bench.report import SCORED, mb, median, ns, ratio, secs, size_label, table
from rpr3bench.workers import SHARED, NumpyCalls, run_worker
from rpr3gen.evaluators import all_cores

STAGES = ("derive", "cse", "print", "render")


def _skipped_note(skipped: list[str]) -> str:
    if not skipped:
        return ""
    return (
        f"\nNot measured here, for want of sample inputs (the benchmarks give q, qd, qdd): "
        f"{', '.join(f'`{name}`' for name in skipped)}.\n"
    )


# ---------------------------------------------------------------------------------------------
# 1. Regeneration
# ---------------------------------------------------------------------------------------------


def _cli_check(repeats: int) -> tuple[list[float], int | None, str]:
    """``rpr3gen generate --check`` end to end: times, last exit status, error (not stale)."""
    times, status, error = [], None, ""
    for _ in range(repeats):
        start = time.perf_counter()
        done = subprocess.run(
            [PY, "-m", "rpr3gen.cli", "generate", "--check"],
            capture_output=True,
            text=True,
            check=False,
            cwd=REPO,
        )
        times.append(time.perf_counter() - start)
        status = done.returncode
        if done.returncode != 0 and "stale" not in done.stderr:  # failed before rendering all
            error = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
    return times, status, error


def section_regen(quick: bool) -> tuple[str, dict[str, Any]]:
    repeats = 1 if quick else 3
    runs = []
    for k in range(repeats):
        log(f"regeneration: cold run {k + 1}/{repeats}")
        runs.append(run_worker("regen"))
    good = [r for r in runs if "error" not in r]
    cli_times, cli_status, cli_error = _cli_check(repeats)
    result: dict[str, Any] = {"cli": None if cli_error else min(cli_times)}
    if not good:
        return f"Regeneration failed: {runs[0]['error']}\n", result
    best = min(good, key=lambda r: r["total"])
    result["total"] = best["total"]
    result["ops"] = best["ops"]
    times: dict[str, dict[str, float]] = best["times"]
    variants = [v for v in times if v != SHARED]
    sums: dict[str, float] = defaultdict(float)
    rows = []
    for name in [*variants, SHARED]:
        stages = times.get(name, {})
        total = stages.get("total", 0.0)
        if name == SHARED:  # everything of render() outside the variants
            total = best["total"] - sum(times[v].get("total", 0.0) for v in variants)
        other = total - sum(stages.get(s, 0.0) for s in STAGES)
        for stage in STAGES:
            sums[stage] += stages.get(stage, 0.0)
        sums["other"] += other
        label = "shared (source hash, package `__init__`)" if name == SHARED else name
        cells = [secs(stages[s]) if s in stages else "" for s in STAGES]
        rows.append([label, *cells, secs(other), secs(total)])
    rows.append(
        [
            "**all: `generate.render()`**",
            *(secs(sums[s]) for s in STAGES),
            secs(sums["other"]),
            f"**{secs(best['total'])}**",
        ]
    )
    share = ", ".join(
        f"{label} {100 * sums[key] / best['total']:.0f}%"
        for key, label in zip(
            (*STAGES, "other"), ("derive", "CSE", "print", "render", "other"), strict=True
        )
    )
    op_rows = [
        [
            actuation,
            f"`{function}`",
            o["before"],
            o["after"],
            ratio(o["before"] / o["after"]) if o["after"] else "n/a",
            o["assignments"],
        ]
        for actuation, by_function in best["ops"].items()
        for function, o in by_function.items()
    ]
    text = [
        table(["variant", "derive s", "CSE s", "print s", "render s", "other s", "total s"], rows),
        "",
        f"Best of {len(good)} cold run(s), each in a fresh interpreter with the registry's cache "
        "cleared (all runs, s: "
        + ", ".join(secs(r["total"]) for r in good)
        + f"). Shares of the total: {share}. Importing sympy, jinja2 and `rpr3gen_derive` "
        f"took a further {secs(best['imports'])} s (not in the total). The stages are the "
        "engine's own (`generate.render(stage=...)`): `derive` = building the function specs "
        "(the symbolic derivation into a `Program`), `CSE` = `compile_function` (common "
        "subexpression elimination), `print` = printing and lowering the code of every backend, "
        "`render` = Jinja2 templates and the manifest; `other` = the rest of the variant's work "
        "(in the shared row: the source hash).",
        "",
        table(
            [
                "variant",
                "function",
                "ops before CSE",
                "ops after CSE",
                "before/after",
                "assignments",
            ],
            op_rows,
        ),
        "",
        "Op counts are `sympy.count_ops` over the function's live program and outputs before and "
        "after `sympy.cse`, as the generated files' headers report them.",
        "",
        f"End to end, `rpr3gen generate --check` (interpreter start, imports, every variant, "
        f"compare with generated/) took **{secs(min(cli_times))} s** (best of {repeats}; exit "
        f"status {cli_status}"
        + (", i.e. generated/ was stale against derive/ at that moment" if cli_status else "")
        + ")."
        + (f" **It failed**: {cli_error}" if cli_error else ""),
    ]
    if best.get("stale"):
        text.append(
            f"\nNote: generated/ differed from a fresh render in {', '.join(best['stale'])} "
            "(derive/ was being edited during this run)."
        )
    return "\n".join(text) + "\n", result


# ---------------------------------------------------------------------------------------------
# 2. NumPy backend
# ---------------------------------------------------------------------------------------------


def _numpy_row(function: str, label: str, n: int, r: dict[str, Any]) -> list[str]:
    if "error" in r:
        return [f"`{function}`", label, "error", r["error"], *[""] * 7]
    if r["chunk"]:
        label += f" ({n // r['chunk']} calls of {size_label(r['chunk'])})"
    r["best_ns"] = min(r["times"]) / n * 1e9
    return [
        f"`{function}`",
        label,
        ns(r["best_ns"]),
        ns(median(r["times"]) / n * 1e9),
        str(len(r["times"])),
        mb(r["peak_rss"]),
        mb(r["peak_rss"] - r["rss_before"]),
        mb(r["traced_peak"]),
        f"{r['traced_peak'] / r['traced_samples']:,.0f}",
        f"{r['minor_faults'] / (n * len(r['times'])):.2f}",
        f"{100 * r['system'] / max(1e-9, r['user'] + r['system']):.0f}%",
    ]


def _numpy_function(
    function: str, quick: bool, limit: int, notes: list[str]
) -> dict[str, dict[Any, dict[str, Any]]]:
    """Every NumPy measurement of one function: {"backend"|"direct"|"kept": {size: result}}."""
    plan = {10**3: 30, 10**4: 10, 10**5: 5, 10**6: 3}
    if quick:
        plan = {10**3: 10, 10**4: 5, 10**5: 3, 10**6: 2}
    results: dict[str, dict[Any, dict[str, Any]]] = {"backend": {}, "direct": {}, "kept": {}}

    def measure(mode: str, n: int, repeats: int, **extra: Any) -> dict[str, Any]:
        return run_worker(
            "numpy", function=function, mode=mode, n=n, repeats=repeats, mem_limit=limit, **extra
        )

    for n, repeats in plan.items():
        for mode in ("backend", "direct"):
            log(f"numpy {function} {mode}: {size_label(n)} samples x {repeats}")
            results[mode][n] = measure(mode, n, repeats)
    big = 10**7
    if not quick:
        log(f"numpy {function} backend: 10^7 samples x 1")
        results["backend"][big] = measure("backend", big, 1)
        r6 = results["direct"].get(10**6, {})
        needed = None
        if r6 and "error" not in r6:
            per_sample = r6["traced_peak"] / r6["traced_samples"]
            needed = (per_sample + (r6["inputs"] + r6["outputs"]) * 8) * big
        available = mem_available()
        if needed is not None and needed < 0.75 * available:
            log(f"numpy {function} direct: 10^7 samples x 1")
            results["direct"][big] = measure("direct", big, 1)
        else:
            notes.append(
                f"`{function}` over 10^7 samples in one call would need about {mb(needed)} MB "
                f"(its allocation at 10^6, plus inputs and outputs) with {mb(available)} MB "
                "available, so its 10^7 row makes 10 calls of 10^6 samples into one "
                "preallocated output."
            )
            log(f"numpy {function} direct: 10^7 samples in calls of 10^6 x 1")
            results["direct"][big] = measure("direct", big, 1, chunk=10**6)
    # Diagnostic: glibc malloc told to keep freed memory, so that what one call allocates reuses
    # the pages freed by the previous call instead of being mapped (and zeroed) afresh.
    keep = {"MALLOC_MMAP_THRESHOLD_": str(2**32), "MALLOC_TRIM_THRESHOLD_": str(2**36)}
    for mode in ("backend", "direct"):
        for n in (10**5, 10**6):
            log(f"numpy {function} {mode}: {size_label(n)} samples, malloc keeping freed memory")
            results["kept"][mode, n] = run_worker(
                "numpy",
                function=function,
                mode=mode,
                n=n,
                repeats=3,
                mem_limit=limit,
                env=keep,
            )
    return results


def section_numpy(quick: bool, ops: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    from rpr3gen.backends import BLOCK

    measured, skipped = functions()
    limit = int(mem_available() * 0.85)
    notes: list[str] = []
    if quick:
        notes.append("10^7 samples: skipped (--quick).")
    results = {name: _numpy_function(name, quick, limit, notes) for name in measured}
    what = {"backend": '`evaluate(backend="numpy")`', "direct": "generated function, one call"}
    rows = []
    for name, by_mode in results.items():
        rows += [
            _numpy_row(name, f"{what[mode]}, {size_label(n)}", n, r)
            for mode in ("backend", "direct")
            for n, r in by_mode[mode].items()
        ]
        rows += [
            _numpy_row(name, f"{what[mode]}, {size_label(n)}, malloc keeps freed memory", n, r)
            for (mode, n), r in by_mode["kept"].items()
        ]
    text = table(
        [
            "function",
            "call, samples",
            "best ns/sample",
            "median ns/sample",
            "repeats",
            "peak RSS MB",
            "RSS growth in calls MB",
            "allocated by one call MB",
            "allocated B/sample",
            "page faults/sample",
            "kernel CPU",
        ],
        rows,
    )
    text += (
        f"\n\nSamples of the paper's {TRAJECTORY} trajectory; each row in a fresh interpreter. "
        '`rpr3gen.evaluate(model, function, inputs, backend="numpy")` is the NumPy backend as '
        "users call it (`inverse_dynamics(...)` is that call for the inverse dynamics): it "
        f"allocates the outputs and calls the generated code on blocks of {BLOCK:,} samples; it "
        "is what the targets score. *Generated function, one call*: the generated module's "
        "function (`rpr3_inverse_dynamics(params, q, qd, qdd, out)`) over all n samples at once, "
        "outputs preallocated. *Peak RSS*: the whole process (interpreter, inputs, outputs, "
        "temporaries). *RSS growth*: peak minus the RSS just before the timed calls. *Allocated "
        "by one call*: `tracemalloc` peak of one further call (NumPy reports its buffers to "
        "tracemalloc): the generated function's temporaries, plus the result for the backend. "
        "*Page faults/sample* and *kernel CPU* (system share of the process CPU time) over the "
        "timed calls: the cost of the kernel mapping and zeroing fresh pages.\n\n"
        "Rows marked *malloc keeps freed memory* are a diagnostic and are not scored: the same "
        "worker with `MALLOC_MMAP_THRESHOLD_=2^32 MALLOC_TRIM_THRESHOLD_=2^36` in its "
        "environment, so that glibc reuses the pages freed by one call instead of returning them "
        "to the kernel (the first call still pays; best-of-3 excludes it).\n"
    )
    for name, by_mode in results.items():
        best6 = by_mode["direct"].get(10**6, {}).get("best_ns")
        after = ops.get(VARIANT, {}).get(name, {}).get("after")
        if best6 and after:
            notes.append(
                f"At 10^6 samples the generated `{name}`'s {ns(best6)} ns/sample over the "
                f"{after} operations left after CSE ({VARIANT}) is {best6 / after:.2f} ns per "
                "operation per sample, each a NumPy pass over an array of n doubles."
            )
    if notes:
        text += "\n" + "\n".join(notes) + "\n"
    profile_text, results["profile"] = speed.numpy_profile(quick)
    return text + _skipped_note(skipped) + profile_text, results


# ---------------------------------------------------------------------------------------------
# 3. C backend against the transcendental floor
# ---------------------------------------------------------------------------------------------


def _probe_difference(run: charness.CRun, n: int) -> float:
    """Largest relative difference of bench's probe sample from the generated NumPy's."""
    calls = NumpyCalls(SCORED)
    k = int(run.values.get("probe_index", n // 2))
    outputs = calls.allocate(1)
    calls.direct([run.inputs[a.name][k : k + 1] for a in calls.info.inputs], outputs)
    values = calls.named([out.T for out in outputs])
    return max(
        (
            abs(run.probe[name] - float(value[0])) / max(1.0, abs(float(value[0])))
            for name, value in values.items()
            if name in run.probe
        ),
        default=float("nan"),
    )


def section_c(quick: bool) -> tuple[str, dict[str, Any]]:
    n = 10**6
    repeats = 3 if quick else 7
    CODE_IDS.append(("c harness build", code_id()))
    run = charness.run(n, repeats)
    if isinstance(run, str):
        return run, {}
    worst = _probe_difference(run, n)
    values, calls = run.values, run.calls
    outputs = int(values["outputs"])
    floor = values["floor_ns"]
    rows = [
        ["scalar floor: sin+cos(phi), 3 sqrt, 3 atan2", ns(floor), "1.00x", run.vectorised],
        [
            "floor + sin, cos of the 3 alphas",
            ns(values["floor_gen_ns"]),
            ratio(values["floor_gen_ns"] / floor),
            f"what parameter trigonometry per sample costs; the generated C has "
            f"{calls.get('sin', 0)} sin, {calls.get('cos', 0)} cos",
        ],
        [
            "C single call `rpr3_inverse_dynamics`",
            ns(values["single_ns"]),
            ratio(values["single_ns"] / floor),
            f"out: one buffer of {outputs} doubles (cache resident)",
        ],
        [
            f"C batch `rpr3_inverse_dynamics_batch`, {size_label(n)}",
            ns(values["batch_ns"]),
            ratio(values["batch_ns"] / floor),
            f"out: {size_label(n)} x {outputs} doubles ({n * outputs * 8 / 1e6:,.0f} MB) streamed",
        ],
        [
            "C batch of 1000, repeated",
            ns(values["batch_small_ns"]),
            ratio(values["batch_small_ns"] / floor),
            f"out stays in cache ({1000 * outputs * 8 / 1e3:,.0f} kB)",
        ],
    ]
    if run.fast_values:
        rows.append(
            [
                "scalar floor, built with -ffast-math",
                ns(run.fast_values["floor_ns"]),
                ratio(run.fast_values["floor_ns"] / floor),
                run.fast_vectorised,
            ]
        )
    agree = values.get("single_checksum") == values.get("batch_checksum")
    kernel = charness.kernel_calls(VARIANT).get(SCORED, {})
    calls_text = ", ".join(f"{count} {name}" for name, count in kernel.items())
    text = table(["loop", "ns/sample", "vs scalar floor", "note"], rows)
    text += (
        f"\n\n`{' '.join(run.command)}` (bench.c, best of {repeats}, {size_label(n)} samples of "
        f"the paper's {TRAJECTORY} trajectory, loops interleaved; the runtime's flags). Failed "
        f"samples: single {values.get('single_failed', 0):.0f}, batch "
        f"{values.get('batch_failed', 0):.0f}; single and batch checksums "
        f"{'agree bit for bit' if agree else '**differ**'}; the probe sample agrees with the "
        f"generated NumPy to {worst:.1e} (relative). One sample of `{SCORED}` evaluates "
        f"{calls_text} (after CSE), with the generated C's own kernels (no libm: "
        "`derive/codegen/mathkernels.py`); the floors call libm's, and gcc merges each sin/cos "
        "pair of them into one `sincos` call"
        + (" (it does here)" if "sincos" in run.symbols else "")
        + ".\n"
    )
    if run.profile and run.profiled_ns:
        inside = sum(run.profile.values())
        prow = [
            [name, f"{100 * share / inside:.0f}%", ns(run.profiled_ns * share / inside)]
            for name, share in sorted(run.profile.items(), key=lambda item: -item[1])
            if share / inside >= 0.005
        ]
        text += (
            "\nWhere the C batch time goes (`perf record` of `bench ... batch`, samples in the "
            "generated code and in libm only, so setup and page faults are left out; ns/sample "
            f"apportions that run's own batch time, {ns(run.profiled_ns)} ns/sample; `sqrt` is "
            "an inline instruction and is counted in the generated code):\n\n"
            + table(["function", "share", "ns/sample"], prow)
            + "\n"
        )
    else:
        text += "\n(`perf` not available: no breakdown of the C time by function.)\n"
    asm_text, asm = speed.c_assembly()
    threads_text, threads = speed.c_threads(quick, all_cores())
    CODE_IDS.append(("c harness end", code_id()))
    result = dict(values, fast_floor_ns=run.fast_values.get("floor_ns"), asm=asm, threads=threads)
    return text + asm_text + threads_text, result


# ---------------------------------------------------------------------------------------------
# 4. Python single-sample call into C
# ---------------------------------------------------------------------------------------------


def section_python(quick: bool, c_single_ns: float | None) -> tuple[str, dict[str, Any]]:
    measured, skipped = functions()
    number = 20_000 if quick else 200_000
    log(f"python: SampleEvaluator x {number} for {', '.join(measured)}")
    r = run_worker(
        "python_single",
        functions=measured,
        number=number,
        repeats=3 if quick else 5,
        numpy_number=50 if quick else 300,
    )
    if "error" in r:
        return f"Python single call failed: {r['error']}\n", {}
    us = 1e6
    rows = [
        [
            f"`{name}`",
            f"{f['c_call'] * us:.3f}",
            f"{f['c_rejected'] * us:.3f}",
            f"{(f['c_call'] - f['c_rejected']) * us:.3f}",
            f"{f['c_evaluate'] * us:.3f}",
            f"{f['numpy_call'] * us:,.1f}",
            f"{f['status']}, {f['rejected_status']}",
            "yes" if f["agree"] else "**no**",
        ]
        for name, f in r["functions"].items()
    ]
    text = table(
        [
            "function",
            "`ev()` c µs",
            "`ev()` NaN input, c µs",
            "difference µs",
            "`ev.evaluate(...)` c µs",
            "`ev()` numpy µs",
            "status (NaN call)",
            "c and numpy agree",
        ],
        rows,
    )
    c_single = (
        f" The C single call of bench.c (section 3, `rpr3_inverse_dynamics`) takes "
        f"{c_single_ns / 1e3:.3f} µs; it is built with `-O3 -march=native`, the library of "
        f"`SampleEvaluator` with `{' '.join(r['cflags'])}`."
        if c_single_ns is not None
        else ""
    )
    text += (
        f"\n\nBest of {r['repeats']} x {r['number']:,} calls (`timeit`) of "
        "`SampleEvaluator(model, backend, function=...)` on one sample of the paper's "
        f"{TRAJECTORY} trajectory. `ev()`, c backend: the target, one sample, no allocation. "
        "*NaN input*: the same ctypes call with a NaN in the first input; C returns after its "
        "isfinite checks (status in the column), so this is the cost of crossing into C. "
        "*Difference*: the C work of one sample inside the Python call. `ev.evaluate(...)` copies "
        "the sample in and checks the status. `ev()`, numpy backend: the generated NumPy on "
        f"(1,) arrays. An empty Python function call takes {r['python_call'] * us:.3f} µs "
        f"(interpreter floor).{c_single}\n"
    )
    return text + _skipped_note(skipped), r


# ---------------------------------------------------------------------------------------------
# 5. Peers
# ---------------------------------------------------------------------------------------------


def _lambdify(quick: bool, measured: list[str]) -> tuple[str, dict[str, Any]]:
    rows, notes, results = [], [], {}
    for name in measured:
        log(f"peers: sympy.lambdify of the expanded outputs of {name}")
        lam = run_worker(
            "lambdify", function=name, n=10**3, repeats=3 if quick else 5, timeout=1800
        )
        results[name] = lam
        if "error" in lam:
            rows.append([f"`{name}`", "error", lam["error"], "", "", "", ""])
            continue
        n = lam["n"]
        lam["lambdify_ns"] = min(lam["lambdified"]) / n * 1e9
        gen_ns = min(lam["generated"]) / n * 1e9
        rows.append(
            [
                f"`{name}`",
                ns(lam["lambdify_ns"]),
                ns(gen_ns),
                ratio(lam["lambdify_ns"] / gen_ns),
                f"{lam['expand'] + lam['lambdify']:.1f} s (`Program.expand` {lam['expand']:.1f} "
                f"s + `lambdify` {lam['lambdify']:.1f} s); first call {lam['first_call']:.2f} s",
                f"{lam['outputs']} outputs, {lam['expanded_ops']:,} ops; peak RSS "
                f"{mb(lam['peak_rss'])} MB",
                f"{lam['max_rel_diff']:.1e} ({lam['compared']} outputs)",
            ]
        )
    text = table(
        [
            "function",
            f"`lambdify` ns/sample, {size_label(10**3)}",
            "NumPy backend ns/sample, same process",
            "lambdify slower by",
            "setup",
            "expanded",
            "max rel. difference",
        ],
        rows,
    )
    printer = next((r["printer"] for r in results.values() if "printer" in r), "n/a")
    notes.append(
        '`sympy.lambdify(..., modules="numpy", cse=False)` of every output expanded down to '
        "inputs and parameters (`Program.expand`), each operation (`sympy.count_ops`) evaluated "
        "as its own NumPy operation on the sample arrays, against the NumPy backend "
        '`evaluate(model, function, inputs, backend="numpy")` on the same samples. Printer: '
        f"`{printer}` (SymPy's NumPy printer, plus the derivation's own functions such as "
        "`wrap_angle`). The difference is relative to max(1, |generated value|)."
    )
    return text + "\n\n" + "\n".join(notes) + "\n", results


def _newton_euler(quick: bool, numpy_results: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    log("peers: Newton-Euler solve")
    ne = run_worker("newton_euler", sizes=[10**4, 10**5], repeats=1 if quick else 3)
    result: dict[str, Any] = {"newton_euler": ne, "ne_ratio": {}}
    if "error" in ne:
        return f"Newton-Euler failed: {ne['error']}\n", result
    backend = numpy_results.get(SCORED, {}).get("backend", {})
    rows = []
    for entry in ne["sizes"]:
        n = entry["n"]
        ne_ns = min(entry["ne"]) / n * 1e9
        np_ns = min(entry["numpy"]) / n * 1e9
        result["ne_ratio"][n] = ne_ns / np_ns
        rows.append(
            [
                size_label(n),
                ns(ne_ns),
                ns(np_ns),
                ratio(ne_ns / np_ns),
                ns(min(entry["direct"]) / n * 1e9),
                ns(backend.get(n, {}).get("best_ns")),
                f"{entry['max_rel_diff']:.1e}",
            ]
        )
    text = table(
        [
            "samples",
            "Newton–Euler ns/sample",
            "NumPy backend ns/sample",
            "NumPy speed-up",
            "generated function, one call",
            "backend in section 2",
            "max rel. difference",
        ],
        rows,
    )
    text += (
        "\n\n`tests/newton_euler.py` `solve(paper_params(), 'revolute', q, qd, qdd)` "
        "(kinematics, an (n, 21, 21) system, one batched `numpy.linalg.solve`) interleaved "
        'with the NumPy backend `evaluate(model, "inverse_dynamics", (q, qd, qdd), '
        'backend="numpy")` and the generated function in one call, on the same samples in one '
        f"process (best of {len(ne['sizes'][0]['ne'])}; each timed right after an untimed run "
        "of itself, so that each is measured warm and none just after the other's cache "
        "footprint); the difference column compares the "
        f"{ne['sizes'][0]['compared']} outputs both give (backend against Newton–Euler, "
        "relative to max(1, |value|)). The parameters of `newton_euler.paper_params()` and of "
        f"`load_model()` differ by at most {ne['param_diff']:.1e}.\n"
    )
    return text, result


def section_peers(quick: bool, numpy_results: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    measured, skipped = functions()
    lam_text, lam = _lambdify(quick, measured)
    text = ["### `sympy.lambdify`", "", lam_text + _skipped_note(skipped)]
    result: dict[str, Any] = {"lambdify": lam}
    if SCORED in measured:
        ne_text, ne = _newton_euler(quick, numpy_results)
        text += ["### Newton–Euler (inverse dynamics)", "", ne_text]
        result.update(ne)
    return "\n".join(text), result


#: Sections by key (``run.py --only KEY``), in order: title and what runs them.
SECTIONS: dict[str, str] = {
    "regen": "1. Regeneration",
    "numpy": "2. NumPy backend",
    "c": "3. C backend against the transcendental floor",
    "python": "4. Python single-sample call into C",
    "peers": "5. Peers",
    "control": "6. Control model",
    "functions": "7. Every generated function against its floor",
}


def run_all(
    quick: bool, only: list[str] | None = None
) -> tuple[list[tuple[str, str]], dict[str, Any]]:
    """Every section in order (or those of ``only``): ``[(title, Markdown)]`` and the results
    by section. A section whose input section did not run gets none (its figures say n/a)."""
    from rpr3bench.control import section_control
    from rpr3bench.functions import section_functions

    runs = {
        "regen": lambda r: section_regen(quick),
        "numpy": lambda r: section_numpy(quick, r.get("regen", {}).get("ops", {})),
        "c": lambda r: section_c(quick),
        "python": lambda r: section_python(quick, r.get("c", {}).get("single_ns")),
        "peers": lambda r: section_peers(quick, r.get("numpy", {})),
        "control": lambda r: section_control(quick),
        "functions": lambda r: section_functions(quick),
    }
    results: dict[str, Any] = {}
    sections = []
    for key, title in SECTIONS.items():
        if only and key not in only:
            continue
        text, results[key] = runs[key](results)
        sections.append((title, text))
    return sections, results
