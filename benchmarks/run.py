"""Benchmarks of rpr3gen: regeneration, the NumPy and C backends, the Python call path, and peers.

Run from anywhere with the project's interpreter (rpr3gen installed with the ``dev`` extra)::

    python benchmarks/run.py                # full run, a few minutes; writes benchmarks/results.md
    python benchmarks/run.py --quick        # fewer repeats, no 10^7-sample NumPy run; writes
                                            # benchmarks/results-quick.md, not results.md
    python benchmarks/run.py --out FILE.md  # write the Markdown elsewhere

It prints the report (Markdown) on stdout, progress on stderr, and writes the same Markdown to
``--out``. Every figure is measured in this run, next to what it is compared with; each timing is
the best of several repeats unless a table says otherwise. See ``benchmarks/README.md`` for what
each number means.

Measurements that must not disturb each other (regeneration with cold caches, each NumPy size,
the peers) run in fresh subprocesses of this same file (``--worker NAME``); the C timings come from
``benchmarks/bench.c``, compiled here with the system compiler.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as dt
import importlib.metadata
import json
import os
import platform
import re
import resource
import shlex
import subprocess
import sys
import tempfile
import time
import timeit
from collections import defaultdict
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
PY = sys.executable
CC = shlex.split(os.environ.get("CC", "cc"))
C_FLAGS = ("-std=c99", "-O3", "-march=native")
VARIANT = "revolute"  # the paper's robot; the C harness builds against generated/revolute
TRAJECTORY = "rotation"  # the paper's platform rotation, eq. (3), figs 3-8

TARGETS = {
    "c_batch_floor": 1.2,  # C batch ns/sample <= 1.2 x the scalar floor
    "c_single_floor": 2.0,  # C single call <= 2 x the scalar floor
    "numpy_vs_ne": 20.0,  # NumPy batch >= 20 x faster than the Newton-Euler solve
    "numpy_1e6_ns": 500.0,  # NumPy at 10^6 samples < 500 ns/sample
    "python_single_us": 1.0,  # SampleEvaluator call < 1 us
    "regeneration_s": 5.0,  # full regeneration < 5 s
}


#: (what was measured, identity of generated/{VARIANT} at that time), filled as the run goes.
CODE_IDS: list[tuple[str, str]] = []


def code_id() -> str:
    """Short SHA-256 of the generated files of the measured variant, as they are on disk now.

    Others may regenerate while a run is going on; a report whose sections saw different code
    says so at the top.
    """
    import hashlib

    digest = hashlib.sha256()
    for name in ("rpr3_numpy.py", "rpr3.c", "rpr3.h"):
        path = REPO / "generated" / VARIANT / name
        digest.update(path.read_bytes() if path.is_file() else b"missing")
    return digest.hexdigest()[:12]


def log(message: str) -> None:
    print(f"[bench] {message}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# Workers: run in a fresh interpreter, print one JSON object on the last line of stdout.
# ---------------------------------------------------------------------------------------------


def _inputs(n: int) -> tuple[Any, Any, Any]:
    """q, qd, qdd (n, 3) of the paper's rotation trajectory, C-contiguous float64."""
    import numpy as np

    import rpr3gen

    traj = rpr3gen.paper_trajectory(TRAJECTORY, samples=n, duration=3.0)
    return tuple(np.ascontiguousarray(a, dtype=np.float64) for a in (traj.q, traj.qd, traj.qdd))


def _rss_bytes() -> int:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def _peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: kilobytes


def _mem_available() -> int:
    with open("/proc/meminfo") as handle:
        for line in handle:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    return 0


def _generated_numpy() -> tuple[Callable[..., None], Any, tuple[str, ...]]:
    """The generated NumPy function, the paper's parameter vector in its order, its outputs."""
    import rpr3gen
    from rpr3gen.backends import numpy_module

    model = rpr3gen.load_model()
    module = numpy_module(model.actuation)
    return module.rpr3_inverse_dynamics, model.vector(module.PARAM_NAMES), module.OUTPUT_NAMES


def worker_regen(_: dict[str, Any]) -> dict[str, Any]:
    """One cold regeneration (``render.render()``, both actuations), split into phases.

    The phases are timed by wrapping the functions ``render`` calls (``build_spec``,
    ``straight_line``, ``numpy_code``, ``c_code``, ``render_variant``) in this process only; the
    template time of a variant is what ``render_variant`` spends outside the other phases.
    """
    t0 = time.perf_counter()
    from rpr3gen_derive import render, specs

    imports = time.perf_counter() - t0
    specs.build_spec.cache_clear()
    times: dict[str, dict[str, float]] = defaultdict(lambda: defaultdict(float))
    ops: dict[str, dict[str, int]] = {}
    state = {"actuation": "shared"}
    missing = []

    def wrap(name: str, phase: str, sets_actuation: bool = False, on_result=None) -> None:
        original = getattr(render, name, None)
        if original is None:
            missing.append(name)
            return

        def wrapper(*args: Any, **kwargs: Any) -> Any:
            if sets_actuation:
                state["actuation"] = args[0] if args else kwargs["actuation"]
            start = time.perf_counter()
            try:
                result = original(*args, **kwargs)
            finally:
                times[state["actuation"]][phase] += time.perf_counter() - start
                if phase == "variant":
                    state["actuation"] = "shared"
            if on_result is not None:
                on_result(result)
            return result

        setattr(render, name, wrapper)

    def record_ops(code: Any) -> None:
        ops[state["actuation"]] = {
            "before": int(code.ops_before),
            "after": int(code.ops_after),
            "assignments": len(code.assignments),
        }

    wrap("render_variant", "variant", sets_actuation=True)
    wrap("build_spec", "derive")
    wrap("straight_line", "cse", on_result=record_ops)
    wrap("numpy_code", "print")
    wrap("c_code", "print")
    start = time.perf_counter()
    files = render.render()
    total = time.perf_counter() - start
    out_dir = render.default_out_dir()
    stale = render.stale_files(out_dir, files) if out_dir is not None else None
    return {
        "imports": imports,
        "total": total,
        "times": {act: dict(phases) for act, phases in times.items()},
        "ops": ops,
        "files": len(files),
        "stale": stale,
        "unwrapped": missing,
    }


def _numpy_backend() -> Callable[[Any, Any, Any], Any]:
    """``rpr3gen.inverse_dynamics(model, q, qd, qdd, backend="numpy")`` for the paper's robot."""
    import rpr3gen

    model = rpr3gen.load_model()
    return lambda q, qd, qdd: rpr3gen.inverse_dynamics(model, q, qd, qdd, backend="numpy")


def worker_numpy(args: dict[str, Any]) -> dict[str, Any]:
    """NumPy at one size: best time, peak RSS and tracemalloc peak of one call.

    ``mode`` "backend": the public ``inverse_dynamics(..., backend="numpy")`` (it allocates the
    output and evaluates in blocks of ``rpr3gen.backends.BLOCK`` samples); "direct": the
    generated function in one call over all samples (``chunk``: in calls of that many) into a
    preallocated output.
    """
    import tracemalloc

    import numpy as np

    n, repeats, chunk = int(args["n"]), int(args["repeats"]), args.get("chunk")
    limit = int(args["mem_limit"])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))  # fail with MemoryError, not the OOM
    func, params, names = _generated_numpy()
    backend = _numpy_backend()
    warm = _inputs(1000)
    func(params, *warm, np.empty((len(names), 1000)))  # import and warm up the code paths
    backend(*warm)
    q, qd, qdd = _inputs(n)
    direct = args["mode"] == "direct"
    out = np.empty((len(names), n)) if direct else np.empty((0, n))
    out.fill(0.0)  # touch the output pages before timing
    rss_before = _rss_bytes()
    step = int(chunk) if chunk else n

    def call(stop: int = n) -> None:
        if not direct:
            backend(q[:stop], qd[:stop], qdd[:stop])
            return
        for a in range(0, stop, step):
            b = min(stop, a + step)
            func(params, q[a:b], qd[a:b], qdd[a:b], out[:, a:b])

    times = []
    usage = resource.getrusage(resource.RUSAGE_SELF)
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    after = resource.getrusage(resource.RUSAGE_SELF)
    peak_rss = _peak_rss_bytes()
    tracemalloc.start()
    call(step)
    _, traced_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {
        "n": n,
        "mode": args["mode"],
        "chunk": step if chunk else None,
        "times": times,
        "rss_before": rss_before,
        "peak_rss": peak_rss,
        "traced_peak": traced_peak,
        "traced_samples": step,
        "minor_faults": after.ru_minflt - usage.ru_minflt,
        "user": after.ru_utime - usage.ru_utime,
        "system": after.ru_stime - usage.ru_stime,
        "outputs": len(names),
        "finite": bool(np.isfinite(out).all()),
    }


def _import_newton_euler() -> Any:
    import importlib.util

    path = REPO / "tests" / "newton_euler.py"
    spec = importlib.util.spec_from_file_location("rpr3_bench_newton_euler", path)
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(module)
    return module


def worker_newton_euler(args: dict[str, Any]) -> dict[str, Any]:
    """The reference Newton-Euler batched solve against the NumPy backend, interleaved."""
    import numpy as np

    import rpr3gen

    ne = _import_newton_euler()
    ne_params = ne.paper_params()
    model = rpr3gen.load_model()
    param_diff = max(abs(ne_params[k] - model.params[k]) for k in ne_params)
    func, params, names = _generated_numpy()
    backend = _numpy_backend()
    results = []
    for n in args["sizes"]:
        q, qd, qdd = _inputs(n)
        out = np.empty((len(names), n))
        t_ne, t_np, t_direct = [], [], []
        ref, got = {}, {}
        for _ in range(int(args["repeats"])):
            start = time.perf_counter()
            ref = ne.solve(ne_params, VARIANT, q, qd, qdd)
            t_ne.append(time.perf_counter() - start)
            start = time.perf_counter()
            got = backend(q, qd, qdd)
            t_np.append(time.perf_counter() - start)
            start = time.perf_counter()
            func(params, q, qd, qdd, out)
            t_direct.append(time.perf_counter() - start)
        worst, compared = 0.0, 0
        for name in got:
            if name not in ref:
                continue
            compared += 1
            scale = max(1.0, float(np.max(np.abs(ref[name]))))
            worst = max(worst, float(np.max(np.abs(got[name] - ref[name]))) / scale)
        results.append(
            {
                "n": n,
                "ne": t_ne,
                "numpy": t_np,
                "direct": t_direct,
                "max_rel_diff": worst,
                "compared": compared,
            }
        )
    return {"sizes": results, "param_diff": param_diff}


def worker_lambdify(args: dict[str, Any]) -> dict[str, Any]:
    """``sympy.lambdify`` (numpy, no CSE) of the fully expanded outputs, against the backend."""
    import numpy as np
    import sympy as sp
    from rpr3gen_derive import specs
    from rpr3gen_derive import symbols as syms

    start = time.perf_counter()
    program, outputs = specs.derive(VARIANT)
    t_derive = time.perf_counter() - start
    start = time.perf_counter()
    expanded = [program.expand(expr) for expr in outputs.values()]
    t_expand = time.perf_counter() - start
    arguments = [syms.params[name] for name in syms.PARAM_NAMES]
    arguments += [*syms.q, *syms.qd, *syms.qdd]
    # The derivation may use functions of its own (``wrap_angle``); the project's NumPy printer
    # (SymPy's, plus those) prints them. Everything else is plain lambdify.
    try:
        from rpr3gen_derive.printers import NumpyPrinter

        printer: Any = NumpyPrinter()
    except ImportError:
        printer = None
    start = time.perf_counter()
    func = sp.lambdify(arguments, expanded, modules="numpy", cse=False, printer=printer)
    t_lambdify = time.perf_counter() - start
    start = time.perf_counter()
    expanded_ops = sum(int(sp.count_ops(e)) for e in expanded)
    t_count = time.perf_counter() - start

    n = int(args["n"])
    q, qd, qdd = _inputs(n)
    _, params, _ = _generated_numpy()
    backend = _numpy_backend()
    values = [float(v) for v in params] + [q[:, 0], q[:, 1], q[:, 2]]
    values += [qd[:, 0], qd[:, 1], qd[:, 2], qdd[:, 0], qdd[:, 1], qdd[:, 2]]
    start = time.perf_counter()
    result = func(*values)
    t_first = time.perf_counter() - start
    t_lam, t_gen = [], []
    got = {}
    for _ in range(int(args["repeats"])):
        start = time.perf_counter()
        func(*values)
        t_lam.append(time.perf_counter() - start)
        start = time.perf_counter()
        got = backend(q, qd, qdd)
        t_gen.append(time.perf_counter() - start)
    worst, compared = 0.0, 0
    for name, value in zip(outputs, result, strict=True):
        if name not in got:
            continue
        compared += 1
        row = got[name]
        lam_row = np.broadcast_to(np.asarray(value, dtype=float), (n,))
        scale = max(1.0, float(np.max(np.abs(row))))
        worst = max(worst, float(np.max(np.abs(lam_row - row))) / scale)
    return {
        "n": n,
        "printer": type(printer).__module__ + "." + type(printer).__name__ if printer else None,
        "outputs": len(expanded),
        "compared": compared,
        "derive": t_derive,
        "expand": t_expand,
        "lambdify": t_lambdify,
        "count_ops": t_count,
        "expanded_ops": expanded_ops,
        "first_call": t_first,
        "lambdified": t_lam,
        "generated": t_gen,
        "max_rel_diff": worst,
        "peak_rss": _peak_rss_bytes(),
    }


def worker_python_single(args: dict[str, Any]) -> dict[str, Any]:
    """``SampleEvaluator`` calls: the C backend, its ctypes floor, and the NumPy backend."""
    import numpy as np

    import rpr3gen
    from rpr3gen import cbackend

    model = rpr3gen.load_model()
    q, qd, qdd = _inputs(301)
    mid = 150
    evaluator = rpr3gen.SampleEvaluator(model, backend="c")
    evaluator.q[:], evaluator.qd[:], evaluator.qdd[:] = q[mid], qd[mid], qdd[mid]
    status = evaluator()
    # The same entry point with a NaN input returns RPR3_NOT_FINITE after three isfinite checks:
    # what is left of its time is the cost of getting into C and back (ctypes, interpreter).
    rejected = rpr3gen.SampleEvaluator(model, backend="c")
    rejected.q[:] = np.nan
    rejected_status = rejected()
    slow = rpr3gen.SampleEvaluator(model, backend="numpy")
    slow.q[:], slow.qd[:], slow.qdd[:] = q[mid], qd[mid], qdd[mid]
    number, repeats = int(args["number"]), int(args["repeats"])

    def best(func: Callable[[], Any], count: int) -> float:
        return min(timeit.repeat(func, number=count, repeat=repeats)) / count

    def empty() -> None:
        pass

    results = {
        "c_call": best(evaluator, number),
        "c_rejected": best(rejected, number),
        "c_evaluate": best(lambda: evaluator.evaluate(q[mid], qd[mid], qdd[mid]), number // 4),
        "python_call": best(empty, number),
        "numpy_call": best(slow, max(10, int(args["numpy_number"]))),
    }
    slow()
    return {
        **results,
        "status": status,
        "rejected_status": rejected_status,
        "agree": bool(np.allclose(evaluator.out, slow.out, rtol=1e-9, atol=1e-9)),
        # The flags the runtime tries first (it drops extras the compiler refuses).
        "cflags": [*cbackend.CFLAGS, *cbackend.EXTRA_FLAGS[0]],
        "number": number,
        "repeats": repeats,
    }


WORKERS: dict[str, Callable[[dict[str, Any]], dict[str, Any]]] = {
    "regen": worker_regen,
    "numpy": worker_numpy,
    "newton_euler": worker_newton_euler,
    "lambdify": worker_lambdify,
    "python_single": worker_python_single,
}


def run_worker(
    name: str, timeout: float = 900.0, env: dict[str, str] | None = None, **args: Any
) -> dict[str, Any]:
    """Run one worker in a fresh interpreter; return its JSON result (or an "error")."""
    command = [PY, str(Path(__file__).resolve()), "--worker", name, "--args", json.dumps(args)]
    try:
        done = subprocess.run(
            command,
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
            cwd=REPO,
            env={**os.environ, **(env or {})},
        )
    except subprocess.TimeoutExpired:
        return {"error": f"timed out after {timeout:.0f} s"}
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines:
        tail = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        return {"error": f"exit status {done.returncode}: {tail}"}
    result = json.loads(lines[-1])
    label = f"{name} " + ", ".join(f"{k}={v}" for k, v in args.items() if k != "mem_limit")
    if env:
        label += " (" + " ".join(f"{k}={v}" for k, v in env.items()) + ")"
    if name != "regen":  # regeneration renders from derive/ and does not run generated/
        CODE_IDS.extend((label.strip(), cid) for cid in result.get("code_ids", []))
    return result


# ---------------------------------------------------------------------------------------------
# Formatting
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
# Sections
# ---------------------------------------------------------------------------------------------


def _command_output(command: Sequence[str]) -> str:
    try:
        done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
    except OSError:
        return "n/a"
    return (done.stdout.strip().splitlines() or ["n/a"])[0]


def _loadavg() -> str:
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
    header = (REPO / "generated" / VARIANT / "rpr3.h").read_text()
    source_hash = re.search(r'RPR3_SOURCE_HASH "([0-9a-f]+)"', header)
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
        "generated source hash": source_hash.group(1)[:16] if source_hash else "n/a",
        "load average (start)": _loadavg(),
    }


def section_regen(quick: bool) -> tuple[str, dict[str, Any]]:
    repeats = 1 if quick else 3
    runs = []
    for k in range(repeats):
        log(f"regeneration: cold run {k + 1}/{repeats}")
        runs.append(run_worker("regen"))
    good = [r for r in runs if "error" not in r]
    cli_times, cli_status, cli_error = [], None, ""
    for _ in range(repeats):
        start = time.perf_counter()
        done = subprocess.run(
            [PY, "-m", "rpr3gen.cli", "generate", "--check"],
            capture_output=True,
            text=True,
            check=False,
            cwd=REPO,
        )
        cli_times.append(time.perf_counter() - start)
        cli_status = done.returncode
        if done.returncode != 0 and "stale" not in done.stderr:  # failed before rendering all
            cli_error = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
    result: dict[str, Any] = {
        "cli": None if cli_error else min(cli_times),
        "cli_status": cli_status,
    }
    if not good:
        return f"Regeneration failed: {runs[0]['error']}\n", result
    best = min(good, key=lambda r: r["total"])
    result["total"] = best["total"]
    result["ops"] = best["ops"]
    rows = []
    sums: dict[str, float] = defaultdict(float)
    for actuation in ("revolute", "prismatic"):
        phases = best["times"].get(actuation, {})
        derive, cse = phases.get("derive", 0.0), phases.get("cse", 0.0)
        printing, variant = phases.get("print", 0.0), phases.get("variant", 0.0)
        templates = variant - derive - cse - printing
        for key, value in (("derive", derive), ("cse", cse), ("print", printing)):
            sums[key] += value
        sums["render"] += templates
        o = best["ops"].get(actuation, {})
        rows.append(
            [
                actuation,
                secs(derive),
                secs(cse),
                secs(printing),
                secs(templates),
                secs(variant),
                o.get("before", "n/a"),
                o.get("after", "n/a"),
                ratio(o["before"] / o["after"]) if o else "n/a",
                o.get("assignments", "n/a"),
            ]
        )
    variants = sum(best["times"].get(a, {}).get("variant", 0.0) for a in ("revolute", "prismatic"))
    shared_time = best["total"] - variants
    rows.append(
        [
            "shared (source hash, package `__init__`)",
            "",
            "",
            "",
            secs(shared_time),
            secs(shared_time),
            "",
            "",
            "",
            "",
        ]
    )
    sums["render"] += shared_time
    rows.append(
        [
            "**both: `render.render()`**",
            secs(sums["derive"]),
            secs(sums["cse"]),
            secs(sums["print"]),
            secs(sums["render"]),
            f"**{secs(best['total'])}**",
            "",
            "",
            "",
            "",
        ]
    )
    share = ", ".join(
        f"{k} {100 * sums[k] / best['total']:.0f}%" for k in ("derive", "cse", "print", "render")
    )
    text = [
        table(
            [
                "actuation",
                "derive s",
                "CSE s",
                "print s",
                "render s",
                "total s",
                "ops before CSE",
                "ops after CSE",
                "before/after",
                "assignments",
            ],
            rows,
        ),
        "",
        f"Best of {len(good)} cold run(s), each in a fresh interpreter (all runs, s: "
        + ", ".join(secs(r["total"]) for r in good)
        + f"). Shares of the total: {share}. Importing sympy, jinja2 and `rpr3gen_derive` "
        f"took a further {secs(best['imports'])} s (not in the total). "
        "`derive` = `build_spec` (the symbolic derivation into a `Program`), `CSE` = "
        "`cse.straight_line`, `print` = every `numpy_code` and `c_code` call, `render` = the rest "
        "of `render_variant` (Jinja2 templates, context) and, in the shared row, the source hash "
        "and package `__init__`. Op counts are `sympy.count_ops` over the live program before "
        "and after `sympy.cse`.",
        "",
        f"End to end, `rpr3gen generate --check` (interpreter start, imports, both variants, "
        f"compare with generated/) took **{secs(min(cli_times))} s** (best of {repeats}; exit "
        f"status {cli_status}"
        + (", i.e. generated/ was stale against derive/ at that moment" if cli_status else "")
        + ")."
        + (f" **It failed**: {cli_error}" if cli_error else ""),
    ]
    if best.get("unwrapped"):
        text.append(
            f"\nNot split (functions not found in `render`): {', '.join(best['unwrapped'])}."
        )
    if best.get("stale"):
        text.append(
            f"\nNote: generated/ differed from a fresh render in {', '.join(best['stale'])} "
            "(derive/ was being edited during this run)."
        )
    return "\n".join(text) + "\n", result


def _numpy_row(label: str, n: int, r: dict[str, Any]) -> list[str]:
    if "error" in r:
        return [label, "error", r["error"], *[""] * 7]
    if r["chunk"]:
        label += f" ({n // r['chunk']} calls of {size_label(r['chunk'])})"
    r["best_ns"] = min(r["times"]) / n * 1e9
    return [
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


def section_numpy(quick: bool, ops_after: int | None) -> tuple[str, dict[str, Any]]:
    plan = {10**3: 30, 10**4: 10, 10**5: 5, 10**6: 3}
    if quick:
        plan = {10**3: 10, 10**4: 5, 10**5: 3, 10**6: 2}
    results: dict[str, dict[int, dict[str, Any]]] = {"backend": {}, "direct": {}}
    notes = []
    limit = int(_mem_available() * 0.85)
    for n, repeats in plan.items():
        for mode in ("backend", "direct"):
            log(f"numpy {mode}: {size_label(n)} samples x {repeats}")
            results[mode][n] = run_worker("numpy", mode=mode, n=n, repeats=repeats, mem_limit=limit)
    big = 10**7
    if quick:
        notes.append("10^7 samples: skipped (--quick).")
    else:
        log("numpy backend: 10^7 samples x 1")
        results["backend"][big] = run_worker(
            "numpy", mode="backend", n=big, repeats=1, mem_limit=limit
        )
        r6 = results["direct"].get(10**6, {})
        needed = None
        if "error" not in r6 and r6:
            per_sample = r6["traced_peak"] / r6["traced_samples"] + (9 + r6["outputs"]) * 8
            needed = per_sample * big
        available = _mem_available()
        if needed is not None and needed < 0.75 * available:
            log("numpy direct: 10^7 samples x 1")
            results["direct"][big] = run_worker(
                "numpy", mode="direct", n=big, repeats=1, mem_limit=limit
            )
        else:
            notes.append(
                f"The generated function over 10^7 samples in one call would need about "
                f"{mb(needed)} MB (its allocation at 10^6, plus inputs and outputs) with "
                f"{mb(available)} MB available, so its 10^7 row makes 10 calls of 10^6 samples "
                "into one preallocated output."
            )
            log("numpy direct: 10^7 samples in calls of 10^6 x 1")
            results["direct"][big] = run_worker(
                "numpy", mode="direct", n=big, repeats=1, chunk=10**6, mem_limit=limit
            )
    # Diagnostic: glibc malloc told to keep freed memory, so that what one call allocates reuses
    # the pages freed by the previous call instead of being mapped (and zeroed) afresh.
    keep = {"MALLOC_MMAP_THRESHOLD_": str(2**32), "MALLOC_TRIM_THRESHOLD_": str(2**36)}
    kept: dict[tuple[str, int], dict[str, Any]] = {}
    for mode in ("backend", "direct"):
        for n in (10**5, 10**6):
            log(f"numpy {mode}: {size_label(n)} samples, malloc keeping freed memory")
            kept[mode, n] = run_worker(
                "numpy", mode=mode, n=n, repeats=3, mem_limit=limit, env=keep
            )
    what = {
        "backend": '`inverse_dynamics(backend="numpy")`',
        "direct": "generated function, one call",
    }
    rows = [
        _numpy_row(f"{what[mode]}, {size_label(n)}", n, r)
        for mode in ("backend", "direct")
        for n, r in results[mode].items()
    ]
    rows += [
        _numpy_row(f"{what[mode]}, {size_label(n)}, malloc keeps freed memory", n, r)
        for (mode, n), r in kept.items()
    ]
    text = table(
        [
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
    try:
        from rpr3gen.backends import BLOCK

        block = f"{BLOCK:,}"
    except ImportError:
        block = "(unknown)"
    text += (
        f"\n\nSamples of the paper's {TRAJECTORY} trajectory; each row in a fresh interpreter. "
        '`inverse_dynamics(model, q, qd, qdd, backend="numpy")` is the NumPy backend as users '
        f"call it: it allocates the (outputs, n) result and calls the generated code on blocks "
        f"of {block} samples; it is what the targets score. *Generated function, one call*: "
        "`rpr3_inverse_dynamics(params, q, qd, qdd, out)` over all n samples at once, `out` "
        "preallocated. *Peak RSS*: the whole process (interpreter, inputs, outputs, "
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
    best6 = results["direct"].get(10**6, {}).get("best_ns")
    if best6 and ops_after:
        notes.append(
            f"At 10^6 samples the generated function's {ns(best6)} ns/sample over the "
            f"{ops_after} operations left after CSE (revolute) is {best6 / ops_after:.2f} ns per "
            "operation per sample, each a NumPy pass over an array of n doubles."
        )
    if notes:
        text += "\n" + "\n".join(notes) + "\n"
    return text, results


def _count_calls(source: str) -> dict[str, int]:
    names = ("sin", "cos", "sqrt", "atan2", "pow", "exp", "log", "fabs", "isfinite")
    return {
        name: len(re.findall(rf"\b{name}\(", source))
        for name in names
        if re.search(rf"\b{name}\(", source)
    }


def _vector_report(build: Path, bench: Path, extra: Sequence[str]) -> str:
    """What gcc says about the loops between FLOOR BEGIN and FLOOR END of bench.c."""
    lines = bench.read_text().splitlines()
    first = next(k for k, line in enumerate(lines, 1) if "FLOOR BEGIN" in line)
    last = next(k for k, line in enumerate(lines, 1) if "FLOOR END" in line)
    report = build / f"vec{len(extra)}.txt"
    command = [
        *CC,
        *C_FLAGS,
        *extra,
        "-I",
        f"generated/{VARIANT}",
        "-c",
        str(bench),
        "-o",
        str(build / "vec.o"),
        f"-fopt-info-vec-all={report}",
    ]
    done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
    if done.returncode != 0 or not report.exists():
        return "no vectorisation report (the compiler does not support -fopt-info)"
    vectorized, reasons = False, set()
    for line in report.read_text().splitlines():
        match = re.match(r".*bench\.c:(\d+):\d+: (\w+): (.*)", line)
        if not match or not first <= int(match.group(1)) <= last:
            continue
        message = match.group(3)
        if "loop vectorized" in message:
            vectorized = True
        elif message.startswith("not vectorized"):
            reasons.add(": ".join(message.split(": ")[:2]).rstrip("."))
        elif "clobbers memory" in message:
            reasons.add("libm call clobbers memory (errno)")
    if vectorized:
        return "loop vectorised by gcc"
    return "loop **not** vectorised by gcc (" + "; ".join(sorted(reasons)) + ")"


def _parse_bench(stdout: str) -> tuple[dict[str, Any], dict[str, float]]:
    """bench's "key value" lines (numbers where they parse) and its "probe name value" lines."""
    values: dict[str, Any] = {}
    probe: dict[str, float] = {}
    for line in stdout.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0] == "probe":
            probe[parts[1]] = float(parts[2])
        elif len(parts) == 2:
            try:
                values[parts[0]] = float(parts[1])
            except ValueError:
                values[parts[0]] = parts[1]
    return values, probe


def _profile(exe: Path, args: Sequence[str]) -> tuple[dict[str, float], float | None]:
    """Share of perf samples per function, in the generated code and libm only, and the
    batch ns/sample of that profiled run (({}, None) without perf)."""
    data = exe.parent / "perf.data"
    try:
        done = subprocess.run(
            ["perf", "record", "-q", "-o", str(data), "--", str(exe), *args],
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0:
            return {}, None
        batch_ns = _parse_bench(done.stdout)[0].get("batch_ns")
        done = subprocess.run(
            ["perf", "report", "-i", str(data), "--stdio", "--sort", "dso,symbol"],
            capture_output=True,
            text=True,
            check=False,
        )
    except OSError:
        return {}, None
    shares: dict[str, float] = defaultdict(float)
    for line in done.stdout.splitlines():
        match = re.match(r"\s*([\d.]+)%\s+(\S+)\s+\[\.\]\s+(\S+)", line)
        if not match:
            continue
        share, dso, symbol = float(match.group(1)), match.group(2), match.group(3)
        if dso == exe.name and symbol.startswith("rpr3_"):
            shares["generated code (arithmetic, sqrt, checks)"] += share
        elif dso.startswith("libm"):
            name = re.sub(r"^(__ieee754_|__)|_fma$|@.*$", "", symbol)
            shares[f"libm {name or 'call stubs (plt)'}"] += share
    return dict(shares), batch_ns


def section_c(quick: bool) -> tuple[str, dict[str, Any]]:
    import numpy as np

    n = 10**6
    repeats = 3 if quick else 7
    bench = HERE / "bench.c"
    variant = REPO / "generated" / VARIANT
    calls = _count_calls((variant / "rpr3.c").read_text())
    CODE_IDS.append(("c harness build", code_id()))
    with tempfile.TemporaryDirectory(prefix="rpr3bench-") as tmp:
        build = Path(tmp)
        params_file = build / "params.txt"
        done = subprocess.run(
            [PY, "-m", "rpr3gen.cli", "params"], capture_output=True, text=True, check=False
        )
        if done.returncode != 0:
            return f"`rpr3gen params` failed: {done.stderr.strip()}\n", {}
        params_file.write_text(done.stdout)
        q, qd, qdd = _inputs(n)
        inputs = build / "inputs.bin"
        np.concatenate([q.ravel(), qd.ravel(), qdd.ravel()]).astype("=f8").tofile(inputs)
        exe = build / "bench"
        command = [
            *CC,
            *C_FLAGS,
            "-I",
            f"generated/{VARIANT}",
            "benchmarks/bench.c",
            f"generated/{VARIANT}/rpr3.c",
            "-lm",
            "-o",
            str(exe),
        ]
        log("c: " + " ".join(command))
        done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
        if done.returncode != 0:
            return f"Compiling bench.c failed:\n\n```\n{done.stderr}\n```\n", {}
        symbols = _command_output(["sh", "-c", f"nm -u {exe} | tr -s ' ' | tr '\\n' ' '"])
        log(f"c: {size_label(n)} samples x {repeats}")
        done = subprocess.run(
            [str(exe), str(params_file), str(inputs), str(n), str(repeats)],
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0:
            return f"bench failed: {done.stderr.strip()}\n", {}
        values, probe = _parse_bench(done.stdout)
        vec_scalar = _vector_report(build, bench, [])
        profile, profiled_ns = _profile(
            exe, [str(params_file), str(inputs), str(n), str(repeats), "batch"]
        )
        # Informational: the floor with -ffast-math, which lets gcc use libmvec if it can.
        fast = build / "bench_fast"
        done = subprocess.run(
            [*command[:-2], "-ffast-math", "-o", str(fast)],
            capture_output=True,
            text=True,
            check=False,
            cwd=REPO,
        )
        fast_values: dict[str, Any] = {}
        vec_fast = "n/a"
        if done.returncode == 0:
            log("c: floor with -ffast-math")
            done = subprocess.run(
                [str(fast), str(params_file), str(inputs), str(n), str(repeats), "floor"],
                capture_output=True,
                text=True,
                check=False,
            )
            fast_values = _parse_bench(done.stdout)[0] if done.returncode == 0 else {}
            vec_fast = _vector_report(build, bench, ["-ffast-math"])
            fast_symbols = _command_output(["sh", "-c", f"nm -u {fast} | grep -c _ZGV || true"])
            vec_fast += f"; libmvec (`_ZGV*`) symbols used: {fast_symbols}"
    # Check against the generated NumPy on the probe sample.
    func, params, names = _generated_numpy()
    out = np.empty((len(names), 1))
    k = int(values.get("probe_index", n // 2))
    func(params, q[k : k + 1], qd[k : k + 1], qdd[k : k + 1], out)
    worst = max(
        (
            abs(probe[name] - out[j, 0]) / max(1.0, abs(out[j, 0]))
            for j, name in enumerate(names)
            if name in probe
        ),
        default=float("nan"),
    )
    outputs = int(values.get("outputs", len(names)))
    floor = values["floor_ns"]
    rows = [
        ["scalar floor: sin+cos(phi), 3 sqrt, 3 atan2", ns(floor), "1.00x", vec_scalar],
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
    if fast_values:
        rows.append(
            [
                "scalar floor, built with -ffast-math",
                ns(fast_values["floor_ns"]),
                ratio(fast_values["floor_ns"] / floor),
                vec_fast,
            ]
        )
    agree = values.get("single_checksum") == values.get("batch_checksum")
    calls_text = ", ".join(f"{count} {name}" for name, count in calls.items())
    text = table(["loop", "ns/sample", "vs scalar floor", "note"], rows)
    text += (
        f"\n\n`{' '.join(command)}` (bench.c, best of {repeats}, {size_label(n)} samples of the "
        f"paper's {TRAJECTORY} trajectory, loops interleaved). Failed samples: single "
        f"{values.get('single_failed', 0):.0f}, batch {values.get('batch_failed', 0):.0f}; single "
        f"and batch checksums {'agree bit for bit' if agree else '**differ**'}; the probe sample "
        f"agrees with the generated NumPy to {worst:.1e} (relative). The generated C calls, per "
        f"sample: {calls_text}. gcc merges each sin/cos pair into one `sincos` call"
        + (" (it does here)" if "sincos" in symbols else "")
        + ".\n"
    )
    if profile and profiled_ns:
        inside = sum(profile.values())
        prow = [
            [name, f"{100 * share / inside:.0f}%", ns(profiled_ns * share / inside)]
            for name, share in sorted(profile.items(), key=lambda item: -item[1])
            if share / inside >= 0.005
        ]
        text += (
            "\nWhere the C batch time goes (`perf record` of `bench ... batch`, samples in the "
            "generated code and in libm only, so setup and page faults are left out; ns/sample "
            f"apportions that run's own batch time, {ns(profiled_ns)} ns/sample; `sqrt` is an "
            "inline instruction and is counted in the generated code):\n\n"
            + table(["function", "share", "ns/sample"], prow)
            + "\n"
        )
    else:
        text += "\n(`perf` not available: no breakdown of the C time by function.)\n"
    CODE_IDS.append(("c harness end", code_id()))
    result = dict(values, fast_floor_ns=fast_values.get("floor_ns"), calls=calls, profile=profile)
    return text, result


def section_python(quick: bool, c_single_ns: float | None) -> tuple[str, dict[str, Any]]:
    number = 20_000 if quick else 200_000
    log(f"python: SampleEvaluator x {number}")
    r = run_worker(
        "python_single", number=number, repeats=3 if quick else 5, numpy_number=50 if quick else 300
    )
    if "error" in r:
        return f"Python single call failed: {r['error']}\n", {}
    us = 1e6
    rows = [
        ["`ev()`, c backend", f"{r['c_call'] * us:.3f}", "the target: one sample, no allocation"],
        [
            "`ev()` with a NaN input, c backend",
            f"{r['c_rejected'] * us:.3f}",
            "same ctypes call, C returns after 3 isfinite checks: the cost of crossing into C",
        ],
        [
            "difference",
            f"{(r['c_call'] - r['c_rejected']) * us:.3f}",
            "the C work of one sample inside the Python call",
        ],
        [
            "`ev.evaluate(q, qd, qdd)`, c backend",
            f"{r['c_evaluate'] * us:.3f}",
            "copies the sample in, checks the status",
        ],
        ["empty Python function call", f"{r['python_call'] * us:.3f}", "interpreter floor"],
        ["`ev()`, numpy backend", f"{r['numpy_call'] * us:,.1f}", "generated NumPy on (1,) arrays"],
    ]
    if c_single_ns is not None:
        rows.insert(
            3,
            [
                "C single call in bench.c (section 3)",
                f"{c_single_ns / 1e3:.3f}",
                "-O3 -march=native; the library of SampleEvaluator is built "
                f"`{' '.join(r['cflags'])}`",
            ],
        )
    text = table(["call", "µs/call", "what it is"], rows)
    text += (
        f"\n\nBest of {r['repeats']} x {r['number']:,} calls (`timeit`), one sample of the "
        f"paper's {TRAJECTORY} trajectory; status {r['status']} (NaN call: "
        f"{r['rejected_status']}); c and numpy results agree: {r['agree']}.\n"
    )
    return text, r


def section_peers(quick: bool, numpy_results: dict[str, Any]) -> tuple[str, dict]:
    log("peers: sympy.lambdify of the expanded outputs (about a minute)")
    lam = run_worker("lambdify", n=10**3, repeats=3 if quick else 5, timeout=1800)
    log("peers: Newton-Euler solve")
    ne = run_worker("newton_euler", sizes=[10**4, 10**5], repeats=1 if quick else 3)
    text = []
    result: dict[str, Any] = {"lambdify": lam, "newton_euler": ne}
    if "error" in lam:
        text.append(f"lambdify failed: {lam['error']}\n")
    else:
        n = lam["n"]
        lam_ns = min(lam["lambdified"]) / n * 1e9
        gen_ns = min(lam["generated"]) / n * 1e9
        setup = lam["expand"] + lam["lambdify"]
        rows = [
            [
                f"`sympy.lambdify`, expanded, cse=False, {size_label(n)}",
                ns(lam_ns),
                ratio(lam_ns / gen_ns),
                f"setup {setup:.1f} s: `Program.expand` {lam['expand']:.1f} "
                f"s + `lambdify` {lam['lambdify']:.1f} s; first call {lam['first_call']:.2f} s",
            ],
            [
                f"NumPy backend (`inverse_dynamics`), {size_label(n)}, same process",
                ns(gen_ns),
                "1.00x",
                f"lambdify agrees to {lam['max_rel_diff']:.1e} (relative)",
            ],
        ]
        text.append(table(["implementation", "ns/sample", "vs NumPy backend", "note"], rows))
        result["lambdify_ns"] = lam_ns
        result["lambdify_setup"] = setup
        text.append(
            f"\nThe {lam['outputs']} outputs expanded down to inputs and parameters hold "
            f"{lam['expanded_ops']:,} operations (`sympy.count_ops`), each evaluated as its own "
            f"NumPy operation on the sample arrays (peak RSS of that process "
            f"{mb(lam['peak_rss'])} MB); {lam['compared']} outputs compared. "
            + (
                f"Printer: `{lam['printer']}` (SymPy's NumPy printer, plus the derivation's own "
                "functions such as `wrap_angle`)."
                if lam.get("printer")
                else "Printer: SymPy's default."
            )
            + "\n"
        )
    if "error" in ne:
        text.append(f"Newton-Euler failed: {ne['error']}\n")
    else:
        rows = []
        result["ne_ratio"] = {}
        for entry in ne["sizes"]:
            n = entry["n"]
            ne_ns = min(entry["ne"]) / n * 1e9
            np_ns = min(entry["numpy"]) / n * 1e9
            direct_ns = min(entry["direct"]) / n * 1e9
            section2 = numpy_results.get("backend", {}).get(n, {}).get("best_ns")
            result["ne_ratio"][n] = ne_ns / np_ns
            rows.append(
                [
                    size_label(n),
                    ns(ne_ns),
                    ns(np_ns),
                    ratio(ne_ns / np_ns),
                    ns(direct_ns),
                    ns(section2),
                    f"{entry['max_rel_diff']:.1e}",
                ]
            )
        text.append(
            table(
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
        )
        text.append(
            "\n`tests/newton_euler.py` `solve(paper_params(), 'revolute', q, qd, qdd)` "
            "(kinematics, an (n, 21, 21) system, one batched `numpy.linalg.solve`) interleaved "
            'with the NumPy backend `inverse_dynamics(model, q, qd, qdd, backend="numpy")` '
            "and the generated function in one call, on the same samples in one process (best of "
            f"{len(ne['sizes'][0]['ne'])}); the difference column compares the "
            f"{ne['sizes'][0]['compared']} outputs both give (backend against Newton–Euler, "
            "relative to max(1, |value|)).\n"
        )
    return "\n".join(text), result


def verdict(measured: float | None, limit: float, at_most: bool = True) -> tuple[str, str]:
    """("pass"/"miss", margin text) for measured <= limit (or >= limit)."""
    if measured is None:
        return "n/a", "not measured"
    factor = measured / limit if at_most else limit / measured
    if factor <= 1.0:
        return "**pass**", f"{1 / factor:.2f}x headroom"
    return "**miss**", f"{factor:.2f}x over"


def section_targets(results: dict[str, Any]) -> str:
    c = results.get("c", {})
    floor = c.get("floor_ns")
    rows = []

    def add(name: str, measured_text: str, measured, limit, limit_text, at_most=True) -> None:
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
    n6 = results.get("numpy", {}).get("backend", {}).get(10**6, {}).get("best_ns")
    add(
        "NumPy at 10^6 samples",
        f"{ns(n6)} ns/sample",
        n6,
        TARGETS["numpy_1e6_ns"],
        "< 500 ns/sample",
    )
    py = results.get("python", {}).get("c_call")
    add(
        "Python single call (`SampleEvaluator`)",
        f"{py * 1e6:.3f} µs" if py else "n/a",
        py * 1e6 if py else None,
        TARGETS["python_single_us"],
        "< 1 µs",
    )
    regen = results.get("regen", {})
    add(
        "full regeneration, `rpr3gen generate --check`",
        f"{secs(regen.get('cli'))} s",
        regen.get("cli"),
        TARGETS["regeneration_s"],
        "< 5 s",
    )
    add(
        "full regeneration, `render.render()` in process",
        f"{secs(regen.get('total'))} s",
        regen.get("total"),
        TARGETS["regeneration_s"],
        "< 5 s",
    )
    return table(["target", "measured", "goal", "result", "margin"], rows) + "\n"


def report_path(out: str | None, quick: bool) -> Path:
    """Where the report goes: ``out`` if given, else results.md, or results-quick.md for --quick."""
    if out:
        return Path(out)
    return HERE / ("results-quick.md" if quick else "results.md")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, no 10^7 NumPy run")
    parser.add_argument(
        "--out",
        help="Markdown report file (default: benchmarks/results.md, or results-quick.md with "
        "--quick, so a quick run never replaces the committed full results)",
    )
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--args", default="{}", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        before = code_id()
        result = WORKERS[args.worker](json.loads(args.args))
        result["code_ids"] = [before, code_id()]
        print(json.dumps(result))
        return 0

    started = time.perf_counter()
    info = machine()
    results: dict[str, Any] = {}
    sections = []
    text, results["regen"] = section_regen(args.quick)
    sections.append(("1. Regeneration", text))
    ops_after = results["regen"].get("ops", {}).get(VARIANT, {}).get("after")
    text, results["numpy"] = section_numpy(args.quick, ops_after)
    sections.append(("2. NumPy backend", text))
    text, results["c"] = section_c(args.quick)
    sections.append(("3. C backend against the transcendental floor", text))
    text, results["python"] = section_python(args.quick, results["c"].get("single_ns"))
    sections.append(("4. Python single-sample call into C", text))
    text, results["peers"] = section_peers(args.quick, results["numpy"])
    sections.append(("5. Peers", text))
    info["load average (end)"] = _loadavg()
    info["run"] = f"{'--quick' if args.quick else 'full'}, {time.perf_counter() - started:.0f} s"

    ids = sorted({cid for _, cid in CODE_IDS if cid})
    info["generated code id"] = ids[0] if len(ids) == 1 else "**changed during the run**"
    lines = ["# rpr3gen benchmarks", ""]
    lines.append(f"`python benchmarks/run.py{' --quick' if args.quick else ''}`")
    lines.append("")
    if len(ids) > 1:
        seen = defaultdict(list)
        for label, cid in CODE_IDS:
            if label not in seen[cid]:
                seen[cid].append(label)
        lines.append(
            f"**Warning: generated/{VARIANT} changed while this run was going on**; figures "
            "measured on different code are not comparable. Code id (SHA-256 of rpr3_numpy.py, "
            "rpr3.c, rpr3.h) seen by each measurement:\n"
        )
        lines += [f"- `{cid}`: {'; '.join(labels)}" for cid, labels in seen.items()]
        lines.append("")
    lines.append(table(["machine", ""], [[k, v] for k, v in info.items()]))
    lines += ["", "## Targets", "", section_targets(results)]
    for title, body in sections:
        lines += [f"## {title}", "", body]
    report = "\n".join(lines).rstrip() + "\n"
    print(report)
    out = report_path(args.out, args.quick)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(report)
    log(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
