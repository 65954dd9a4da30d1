"""Every generated function against its own transcendental floor: C single call, C batch, NumPy.

Generic over the manifest: a function is measured when the benchmarks can give it samples
(:func:`rpr3bench.common.derived_functions`: trajectory samples, or the outputs of another
measured function of the same name, e.g. ``tau`` of ``actuator_efforts`` for
``forward_dynamics``), and has a straight-line kernel (a NumPy version).

The floor of a function is a C loop that makes, per sample, the libm calls that function must
make and nothing else: the ``sin``, ``cos``, ``sqrt`` and ``atan2`` of its generated kernel
after common subexpression elimination (``charness.kernel_calls``; the kernels' own ``rpr3_sin``
etc. count as the libm call they replace), on arguments formed from the sample's inputs. The
harness (C) is written here from the manifest, so a new function adds a row and no code.
"""

from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path
from typing import Any

from rpr3bench import charness
from rpr3bench.common import CC, CODE_IDS, PY, REPO, code_id, derived_functions, log, variant
from rpr3bench.common import sample_inputs as inputs_of
from rpr3bench.report import ns, ratio, table
from rpr3bench.workers import run_worker

#: Samples per input file; the batch runs over chunks of SMALL_BATCH with outputs in cache.
SAMPLES = 100_000
SMALL_BATCH = 1000


def _floor_body(calls: dict[str, int], size: int) -> list[str]:
    """C statements adding the floor's libm calls of one sample (inputs ``u[0..size)``) to
    ``acc``: the sin and cos of one argument each time (the kernels share their reduction; gcc
    merges the libm pair into ``sincos``), sqrt of a sum of squares, atan2 of two components."""
    lines = []
    for k in range(max(calls.get("sin", 0), calls.get("cos", 0))):
        arg = f"u[{(2 + k) % size}] + {0.1 * k!r}"
        if k < calls.get("sin", 0):
            lines.append(f"acc += sin({arg});")
        if k < calls.get("cos", 0):
            lines.append(f"acc += cos({arg});")
    for k in range(calls.get("sqrt", 0)):
        a, b = u_pair(k, size)
        lines.append(f"acc += sqrt({a} * {a} + {b} * {b} + {0.25 + 0.01 * k!r});")
    for k in range(calls.get("atan2", 0)):
        a, b = u_pair(k, size)
        lines.append(f"acc += atan2({a} + {0.3 + 0.01 * k!r}, {b} - {0.2 + 0.01 * k!r});")
    return lines


def u_pair(k: int, size: int) -> tuple[str, str]:
    return f"u[{k % size}]", f"u[{(k + 1) % size}]"


def harness(info: Any, calls: dict[str, int]) -> str:
    """C source timing one function: its floor, single calls and in-cache batches.

    Usage: ``h PARAMS N REPEATS INPUT...`` (raw float64, n x size each); prints ``key value``
    lines, ns per sample of the best repeat, the repeats of the three loops interleaved.
    """
    name = info.c_symbol
    ins = [(a.name, a.size) for a in info.inputs]
    outs = [(o.name, o.size) for o in info.public_outputs]
    floor = "\n            ".join(_floor_body(calls, ins[0][1])) or "acc += u[0];"
    single_args = ", ".join([*(f"{a} + {s} * i" for a, s in ins), *(f"out_{o}" for o, _ in outs)])
    batch_args = ", ".join([*(f"{a} + {s} * k" for a, s in ins), *(f"bout_{o}" for o, _ in outs)])
    first_out = outs[0][0]
    lines = [
        "#define _POSIX_C_SOURCE 199309L",
        "#include <math.h>",
        "#include <stdio.h>",
        "#include <stdlib.h>",
        "#include <string.h>",
        "#include <time.h>",
        '#include "rpr3.h"',
        "",
        "static double now_s(void)",
        "{",
        "    struct timespec ts;",
        "    clock_gettime(CLOCK_MONOTONIC, &ts);",
        "    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;",
        "}",
        "",
        "static double *read_doubles(const char *path, size_t count)",
        "{",
        "    double *data = malloc(count * sizeof(double));",
        '    FILE *f = fopen(path, "rb");',
        "    if (data == NULL || f == NULL || fread(data, sizeof(double), count, f) != count) {",
        '        fprintf(stderr, "cannot read %zu doubles from %s\\n", count, path);',
        "        exit(2);",
        "    }",
        "    fclose(f);",
        "    return data;",
        "}",
        "",
        "int main(int argc, char **argv)",
        "{",
        "    double params[RPR3_NUM_PARAMS];",
        "    char pname[64];",
        "    double value, t0, acc = 0.0, check_single = 0.0, check_batch = 0.0;",
        "    double best_floor = 1e300, best_single = 1e300, best_batch = 1e300;",
        "    size_t n, i, k, failed_single = 0, failed_batch = 0;",
        "    int r, repeats, p;",
        "    FILE *f;",
        *(f"    double *{a};" for a, _ in ins),
        *(f"    double out_{o}[{s}], bout_{o}[{SMALL_BATCH} * {s}];" for o, s in outs),
        f"    if (argc != {4 + len(ins)}) {{",
        '        fprintf(stderr, "usage: %s PARAMS N REPEATS INPUTS...\\n", argv[0]);',
        "        return 2;",
        "    }",
        '    f = fopen(argv[1], "r");',
        "    if (f == NULL) {",
        "        return 2;",
        "    }",
        '    while (fscanf(f, "%63s %lf", pname, &value) == 2) {',
        "        for (p = 0; p < RPR3_NUM_PARAMS; ++p) {",
        "            if (strcmp(rpr3_param_names[p], pname) == 0) {",
        "                params[p] = value;",
        "            }",
        "        }",
        "    }",
        "    fclose(f);",
        "    n = (size_t)strtoull(argv[2], NULL, 10);",
        "    repeats = atoi(argv[3]);",
        *(f"    {a} = read_doubles(argv[{4 + j}], n * {s});" for j, (a, s) in enumerate(ins)),
        "    for (r = 0; r < repeats; ++r) {",
        "        t0 = now_s();",
        "        acc = 0.0;",
        "        for (i = 0; i < n; ++i) {",
        f"            const double *u = {ins[0][0]} + {ins[0][1]} * i;",
        f"            {floor}",
        "        }",
        "        if (now_s() - t0 < best_floor) {",
        "            best_floor = now_s() - t0;",
        "        }",
        "        t0 = now_s();",
        "        check_single = 0.0;",
        "        failed_single = 0;",
        "        for (i = 0; i < n; ++i) {",
        f"            failed_single += {name}(params, {single_args}) != RPR3_OK;",
        f"            check_single += out_{first_out}[0];",
        "        }",
        "        if (now_s() - t0 < best_single) {",
        "            best_single = now_s() - t0;",
        "        }",
        "        t0 = now_s();",
        "        check_batch = 0.0;",
        "        failed_batch = 0;",
        f"        for (k = 0; k + {SMALL_BATCH} <= n; k += {SMALL_BATCH}) {{",
        f"            failed_batch += {info.c_batch_symbol}(params, {SMALL_BATCH}, {batch_args});",
        f"            for (i = 0; i < {SMALL_BATCH}; ++i) {{",
        f"                check_batch += bout_{first_out}[i * {outs[0][1]}];",
        "            }",
        "        }",
        "        if (now_s() - t0 < best_batch) {",
        "            best_batch = now_s() - t0;",
        "        }",
        "    }",
        '    printf("floor_ns %.3f\\n", 1e9 * best_floor / (double)n);',
        '    printf("single_ns %.3f\\n", 1e9 * best_single / (double)n);',
        f'    printf("batch_ns %.3f\\n", 1e9 * best_batch / (double)(n / {SMALL_BATCH} * '
        f"{SMALL_BATCH}));",
        '    printf("floor_checksum %.17g\\n", acc);',
        '    printf("single_failed %zu\\n", failed_single);',
        '    printf("batch_failed %zu\\n", failed_batch);',
        '    printf("agree %d\\n", check_single == check_batch);',
        "    return 0;",
        "}",
    ]
    return "\n".join(lines) + "\n"


def run_c(names: list[str], repeats: int) -> dict[str, dict[str, Any] | str]:
    """Build and run the harness of each function; ``{name: values or why it failed}``."""
    import numpy as np

    from rpr3gen import cbackend

    found = variant()
    calls = charness.kernel_calls(found.variant)
    flags = [f for f in cbackend.CFLAGS if f not in ("-fPIC", "-shared")]
    flags += list(cbackend.EXTRA_FLAGS[0])
    results: dict[str, dict[str, Any] | str] = {}
    with tempfile.TemporaryDirectory(prefix="rpr3bench-functions-") as tmp:
        build = Path(tmp)
        params = build / "params.txt"
        done = subprocess.run(
            [PY, "-m", "rpr3gen.cli", "params"], capture_output=True, text=True, check=True
        )
        params.write_text(done.stdout)
        for name in names:
            info = found.function(name)
            files = []
            for arg, array in zip(info.inputs, inputs_of(info, SAMPLES), strict=True):
                path = build / f"{name}-{arg.name}.bin"
                np.ascontiguousarray(array, dtype="=f8").tofile(path)
                files.append(str(path))
            source = build / f"{name}.c"
            source.write_text(harness(info, calls.get(name, {})))
            exe = build / name
            command = [*CC, *flags, "-I", str(found.folder), str(source),
                       str(found.path("c_source")), "-lm", "-o", str(exe)]  # fmt: skip
            log(f"functions: C harness of {name}")
            built = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
            if built.returncode != 0:
                results[name] = f"build failed: {built.stderr.strip()[:200]}"
                continue
            ran = subprocess.run(
                [str(exe), str(params), str(SAMPLES), str(repeats), *files],
                capture_output=True,
                text=True,
                check=False,
            )
            if ran.returncode != 0:
                results[name] = f"failed: {ran.stderr.strip()[:200]}"
                continue
            values = charness._parse(ran.stdout)[0]
            values["calls"] = calls.get(name, {})
            values["flags"] = " ".join(flags)
            results[name] = values
    return results


def _calls_text(calls: dict[str, int]) -> str:
    return ", ".join(f"{n} {f}" if n > 1 else f for f, n in calls.items()) or "none"


def section_functions(quick: bool) -> tuple[str, dict[str, Any]]:
    """Section 7: every measured function, C single / batch / NumPy against its floor."""
    measured, skipped = derived_functions()
    found = variant()
    straight = [n for n in measured if found.function(n).numpy_function]
    skipped += [n for n in measured if n not in straight]
    CODE_IDS.append(("functions harness", code_id()))
    c = run_c(straight, 3 if quick else 7)
    log(f"functions: NumPy evaluate of {', '.join(straight)}")
    numpy_ns = run_worker("numpy_functions", functions=straight, n=10**5, repeats=3 if quick else 5)
    rows = []
    result: dict[str, Any] = {}
    for name in straight:
        values = c.get(name)
        np_ns = numpy_ns.get("ns", {}).get(name) if "error" not in numpy_ns else None
        if not isinstance(values, dict):
            rows.append([f"`{name}`", str(values), *[""] * 7])
            continue
        floor = values["floor_ns"]
        result[name] = {**values, "numpy_ns": np_ns}
        rows.append(
            [
                f"`{name}`",
                _calls_text(values["calls"]),
                ns(floor),
                f"{ns(values['single_ns'])} ({ratio(values['single_ns'] / floor)})",
                f"{ns(values['batch_ns'])} ({ratio(values['batch_ns'] / floor)})",
                f"{ns(np_ns)} ({ratio(np_ns / floor)})" if np_ns else "n/a",
                "yes" if values.get("agree") == 1 else "**no**",
                f"{values['single_failed']:.0f} / {values['batch_failed']:.0f}",
            ]
        )
    text = table(
        [
            "function",
            "floor: libm calls per sample",
            "floor ns",
            "C single ns (vs floor)",
            "C batch ns (vs floor)",
            "NumPy ns (vs floor)",
            "single = batch",
            "failed single / batch",
        ],
        rows,
    )
    flags = next((v["flags"] for v in c.values() if isinstance(v, dict)), "")
    text += (
        f"\n\n{SAMPLES:,} samples of the paper's rotation (derived inputs: the outputs of the "
        "function of the same name, e.g. `tau` of `actuator_efforts`), one C harness per "
        f"function written from the manifest, `cc {flags}` (the runtime's flags); ns per "
        f"sample, best of {3 if quick else 7} interleaved repeats. *Floor*: a loop of the libm "
        "calls the function's generated kernel makes after CSE (its `rpr3_sin`, `rpr3_cos`, "
        "`rpr3_atan2` counted as the libm call they replace; a sin and a cos of one argument "
        "are one `sincos`), on arguments formed from the sample's inputs, and nothing else. "
        f"*C batch*: the batch function over chunks of {SMALL_BATCH:,} samples whose outputs "
        'stay in cache. *NumPy*: `evaluate(model, function, inputs, backend="numpy")` at '
        "10^5 samples (allocation and failure checks included), in a fresh interpreter. "
        "*single = batch*: the same checksum of an output over every sample.\n"
    )
    if skipped:
        text += (
            "\nNot in this table: "
            + ", ".join(f"`{name}`" for name in skipped)
            + " (no samples for an input, or iterative: no straight-line kernel; the control "
            "section times the forward kinematics).\n"
        )
    CODE_IDS.append(("functions end", code_id()))
    return text, result


__all__ = ["REPO", "section_functions"]
