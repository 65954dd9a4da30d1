"""The C per-function benchmark: writes ``functions.h`` from a manifest, builds, runs, parses.

``benchmarks/c/functions.c`` (with the shared ``benchmarks/c/timing.h``) times, per generated
function, its floor, its single call and its batch; the code that differs per function (the
arguments of its calls and its floor's libm calls) is written here from the manifest, so a new
function or variant adds rows, not code.

The floor of a function is the libm calls that its generated kernel makes after common
subexpression elimination and nothing else: its ``sin``, ``cos``, ``sqrt``, ``atan2`` (the
kernels' ``rpr3_sin`` etc. count as the libm call they replace, ``rpr3_sincos`` as a sin and a
cos), on arguments formed from the sample's first input: a sin and a cos of one argument (gcc
merges them into ``sincos``), the sqrt of a sum of squares, the atan2 of two components.

The chain floor of a function (:mod:`harness.chain`) is its kernel's longest chain of dependent
operations, each weighted by its latency as ``benchmarks/c/latency.c`` measures it right after
the functions, in the same build: what one call takes when it waits for nothing but itself.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from rpr3gen_derive.codegen.backends.c.lanes import LOOP

from harness import chain, samples
from rpr3gen import cbackend
from rpr3gen.manifest import FunctionInfo

C_DIR = Path(__file__).resolve().parent.parent / "c"
CC = shlex.split(os.environ.get("CC", "cc"))
#: The runtime's flags (``rpr3gen.cbackend``), without those of a shared library.
FLAGS = [f for f in cbackend.CFLAGS if f not in ("-fPIC", "-shared")] + list(
    cbackend.EXTRA_FLAGS[0]
)
LIBM = ("sin", "cos", "sqrt", "atan2")


def kernel_calls(source: str, prefix: str) -> dict[str, dict[str, int]]:
    """libm calls (or the generated kernels standing for them) in each ``PREFIX_NAME_kernel``,
    per sample: a call inside a loop over the legs (``derive/codegen/backends/c/lanes.py``)
    counts once per leg."""
    calls = {}
    for name, body in chain.kernel_bodies(source, prefix).items():
        found = dict.fromkeys(LIBM, 0)
        legs, close = 1, None  # inside a lane loop: its calls run once per leg
        for line in body.splitlines():
            opened = LOOP.fullmatch(line.strip())
            if opened:  # the loop's comment names its legs
                legs = len(opened["legs"].split(", "))
                close = line[: len(line) - len(line.lstrip())] + "}"
            elif line == close:
                legs, close = 1, None
            for f in LIBM:
                found[f] += legs * len(re.findall(rf"(?:\b|\b{prefix}_){f}(?:_fast)?\(", line))
            pairs = len(re.findall(rf"\b{prefix}_sincos(?:_fast)?\(", line))  # a sin and a cos
            found["sin"] += legs * pairs
            found["cos"] += legs * pairs
        calls[name] = {f: k for f, k in found.items() if k}
    return calls


def floor_body(calls: dict[str, int], size: int) -> list[str]:
    """C statements adding one sample's floor calls to ``acc`` (inputs ``u[0..size)``)."""
    lines = []
    for k in range(max(calls.get("sin", 0), calls.get("cos", 0))):
        arg = f"u[{(2 + k) % size}] + {0.1 * k!r}"
        lines += [f"acc += {f}({arg});" for f in ("sin", "cos") if k < calls.get(f, 0)]
    pairs = [(f"u[{k % size}]", f"u[{(k + 1) % size}]") for k in range(8)]
    for k in range(calls.get("sqrt", 0)):
        a, b = pairs[k % 8]
        lines.append(f"acc += sqrt({a} * {a} + {b} * {b} + {0.25 + 0.01 * k!r});")
    for k in range(calls.get("atan2", 0)):
        a, b = pairs[k % 8]
        lines.append(f"acc += atan2({a} + {0.3 + 0.01 * k!r}, {b} - {0.2 + 0.01 * k!r});")
    return lines or ["acc += u[0];"]


def entry(f: FunctionInfo, calls: dict[str, int]) -> str:
    """The floor, single and batch loops of one function, for ``functions.h``."""
    ins, outs = f.inputs, f.public_outputs
    single = ", ".join(
        [
            *(f"in[{j}] + {a.size} * i" for j, a in enumerate(ins)),
            *(f"out[{j}] + {o.size} * i * step" for j, o in enumerate(outs)),
        ]
    )
    batch = ", ".join(
        [
            *(f"in[{j}] + {a.size} * k" for j, a in enumerate(ins)),
            *(f"out[{j}]" for j in range(len(outs))),
        ]
    )
    body = "\n        ".join(floor_body(calls, ins[0].size))
    n = f.name
    return f"""
static double floor_{n}(const double *const *in, size_t n)
{{
    double acc = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {{
        const double *u = in[0] + {ins[0].size} * i;
        {body}
    }}
    return acc;
}}

static size_t single_{n}(const double *p, const double *const *in, size_t n, double *const *out,
                         size_t step)
{{
    size_t i, failed = 0;
    for (i = 0; i < n; ++i) {{
        failed += {f.c_symbol}(p, {single}) != 0;
    }}
    return failed;
}}

static size_t batch_{n}(const double *p, const double *const *in, size_t n, double *const *out)
{{
    size_t k, failed = 0;
    for (k = 0; k + CHUNK <= n; k += CHUNK) {{
        failed += {f.c_batch_symbol}(p, CHUNK, {batch});
    }}
    return failed;
}}
"""


def header(variant: str) -> tuple[str, list[str]]:
    """``functions.h`` of a variant and the names of the functions it measures."""
    found = samples.code(variant)
    calls = kernel_calls(found.path("c_source").read_text(), found.prefix)
    names = [n for n, f in found.functions.items() if samples.measurable(found, f)]
    rows = []
    for n in names:
        f = found.function(n)
        sizes = [", ".join(str(a.size) for a in args) for args in (f.inputs, f.public_outputs)]
        rows.append(f'    {{"{n}", {len(f.inputs)}, {len(f.public_outputs)}, {{{sizes[0]}}}, '
                    f"{{{sizes[1]}}}, floor_{n}, single_{n}, batch_{n}}},")  # fmt: skip
    text = "".join(entry(found.function(n), calls.get(n, {})) for n in names)
    text += "\nstatic const struct function FUNCTIONS[] = {\n" + "\n".join(rows) + "\n};\n"
    return text, names


def parse(stdout: str) -> dict[str, dict[str, Any]]:
    """The JSON lines of a C benchmark, by name."""
    lines = (json.loads(line) for line in stdout.splitlines() if line.startswith("{"))
    return {line.pop("name"): line for line in lines}


def chains(
    source: str, prefix: str, latency: dict[str, float], names: list[str]
) -> dict[str, dict[str, float]]:
    """The chain floor (:mod:`harness.chain`) of each function of ``names`` whose kernel is
    straight-line code, ns, as result lines ``NAME/chain``."""
    found = {}
    bodies = chain.kernel_bodies(source, prefix)
    for name in names:
        length = chain.critical_path(bodies[name], latency, prefix)
        if length is not None:
            found[f"{name}/chain"] = {"min": length}
    return found


def run(variant: str, motion: str, n: int, repeats: int) -> dict[str, Any]:
    """Time every measurable function of ``variant`` on ``n`` samples of ``motion``, and the
    latencies of its chains' operations (``c/latency.c``) right after, in the same build."""
    found = samples.code(variant)
    arrays = samples.motion(variant, motion, n)
    source = found.path("c_source")
    with tempfile.TemporaryDirectory(prefix="rpr3bench-") as tmp:
        build = Path(tmp)
        text, names = header(variant)
        (build / "functions.h").write_text(text)
        for name in names:
            f = found.function(name)
            for j, array in enumerate(samples.inputs(variant, f, arrays)):
                array.astype("=f8").tofile(build / f"{name}-{j}.bin")
        model = samples.model(variant)
        params = build / "params.txt"
        params.write_text("".join(f"{k} {v!r}\n" for k, v in model.params.items()))
        exe, probe = build / "functions", build / "latency"
        include = ["-I", str(build), "-I", str(C_DIR), "-I", str(found.folder)]
        subprocess.run(
            [*CC, *FLAGS, *include, str(C_DIR / "functions.c"), str(source), "-lm", "-o", str(exe)],
            check=True,
        )  # fmt: skip
        subprocess.run([*CC, *FLAGS, *include, str(C_DIR / "latency.c"), "-lm", "-o", str(probe)],
                       check=True)  # fmt: skip
        done = subprocess.run(
            [str(exe), str(params), str(build), str(n), str(repeats)],
            capture_output=True, text=True, check=True,
        )  # fmt: skip
        timed = subprocess.run([str(probe), "2000000", str(repeats)], capture_output=True,
                               text=True, check=True)  # fmt: skip
    results = parse(done.stdout)
    latency = {name.split("/", 1)[1]: x["min"] for name, x in parse(timed.stdout).items()}
    results.update(chains(source.read_text(), found.prefix, latency, names))
    return {"flags": " ".join(FLAGS), "samples": n, "results": results, "latency": latency}
