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
import math
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
    counts once per leg, one inside a loop of a constant count (``for (j = 0; j < 6; ++j) {``)
    as often as the loop turns, but once in a loop that can stop early (a ``break``: the tracked
    forward kinematics' Newton steps and their halvings, so that its floor is one Newton step);
    a call of another kernel (a spatial forward dynamics' inverse dynamics) counts as that
    kernel's calls."""
    bodies = chain.kernel_bodies(source, prefix)
    own: dict[str, dict[str, int]] = {}
    called: dict[str, dict[str, int]] = {}
    for name, body in bodies.items():
        found = dict.fromkeys(LIBM, 0)
        kernels: dict[str, int] = {}
        for line, times in turns(body.split("{", 1)[1]):  # after the signature
            for f in LIBM:
                found[f] += times * len(re.findall(rf"(?:\b|\b{prefix}_){f}(?:_fast)?\(", line))
            pairs = len(re.findall(rf"\b{prefix}_sincos(?:_fast)?\(", line))  # a sin and a cos
            found["sin"] += times * pairs
            found["cos"] += times * pairs
            for callee in chain.calls(line, prefix):
                kernels[callee] = kernels.get(callee, 0) + times
        own[name], called[name] = found, kernels

    def total(name: str, seen: tuple[str, ...]) -> dict[str, int]:
        found = dict(own[name])
        for callee, times in called[name].items():
            if callee in bodies and callee not in seen:
                for f, k in total(callee, (*seen, callee)).items():
                    found[f] += times * k
        return found

    return {name: {f: k for f, k in total(name, (name,)).items() if k} for name in bodies}


#: A loop of a constant count, as the hand-written kernels write it.
FOR = re.compile(r"for \((\w+) = 0; \1 (<=?) (\d+); \+\+\1\) \{")


def turns(body: str) -> list[tuple[str, int]]:
    """Each line of a kernel's body and how often it runs a call: the product of its enclosing
    loops' turns (a lane loop's legs; a constant loop's count, or 1 if it can ``break``)."""
    lines = body.splitlines()
    result = []
    open_: list[tuple[str, int]] = []  # (the closing line, turns) of each enclosing loop
    for k, line in enumerate(lines):
        times = math.prod(n for _, n in open_)
        result.append((line, times))
        text = line.strip()
        close = line[: len(line) - len(line.lstrip())] + "}"
        lane, loop = LOOP.fullmatch(text), FOR.match(text)
        if lane:  # the loop's comment names its legs
            open_.append((close, len(lane["legs"].split(", "))))
        elif loop:
            end = lines.index(close, k + 1) if close in lines[k + 1 :] else len(lines)
            stops = any(x.strip() == "break;" for x in lines[k + 1 : end])
            open_.append((close, 1 if stops else int(loop[3]) + (loop[2] == "<=")))
        elif open_ and line == open_[-1][0]:
            open_.pop()
    return result


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
    """``functions.h`` of a variant and the names of the functions it measures
    (:func:`harness.samples.measured`)."""
    found = samples.code(variant)
    calls = kernel_calls(found.path("c_source").read_text(), found.prefix)
    names = samples.measured(variant)
    rows = []
    for n in names:
        f = found.function(n)
        sizes = [", ".join(str(a.size) for a in args) for args in (f.inputs, f.public_outputs)]
        rows.append(f'    {{"{n}", {len(f.inputs)}, {len(f.public_outputs)}, {{{sizes[0]}}}, '
                    f"{{{sizes[1]}}}, floor_{n}, single_{n}, batch_{n}}},")  # fmt: skip
    text = "".join(entry(found.function(n), calls.get(n, {})) for n in names)
    text += "\nstatic const struct function FUNCTIONS[] = {\n" + "\n".join(rows) + "\n};\n"
    return text, names


def latency_kernels(source: Path) -> set[str]:
    """The math kernels (``sin``, ``cos``, ``atan2``, ``fmin``, ``rint``) that a generated C
    source defines as ``PREFIX_NAME``: ``latency.c`` times these (a Delta's has no sine)."""
    text = source.read_text()
    return {k for k in chain.KERNELS if re.search(rf"\b\w+_{k}\(double \w+", text)}


def parse(stdout: str) -> dict[str, dict[str, Any]]:
    """The JSON lines of a C benchmark, by name."""
    lines = (json.loads(line) for line in stdout.splitlines() if line.startswith("{"))
    return {line.pop("name"): line for line in lines}


def chains(
    source: str, prefix: str, latency: dict[str, float], names: list[str]
) -> dict[str, dict[str, float]]:
    """The chain floor (:mod:`harness.chain`) of each function of ``names``, ns, as result lines
    ``NAME/chain``: its kernel's where it is straight-line code; else, where it calls kernels
    that are (a spatial forward dynamics, a tracked forward kinematics), the longest of theirs,
    named by ``"kernel"``: a looser lower bound, since the call waits for that kernel's
    result and then does more."""
    found: dict[str, dict[str, Any]] = {}
    bodies = chain.kernel_bodies(source, prefix)
    for name in names:
        length = chain.critical_path(bodies[name], latency, prefix)
        if length is not None:
            found[f"{name}/chain"] = {"min": length}
            continue
        inner = {c: chain.critical_path(bodies[c], latency, prefix)
                 for c in sorted(chain.called(bodies[name], prefix)) if c in bodies}  # fmt: skip
        known = {c: x for c, x in inner.items() if x is not None}
        if known:
            longest = max(known, key=lambda c: known[c])
            found[f"{name}/chain"] = {"min": known[longest], "kernel": longest}
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
        have = [f"-DLATENCY_{k.upper()}" for k in chain.KERNELS if k in latency_kernels(source)]
        subprocess.run([*CC, *FLAGS, *include, *have, str(C_DIR / "latency.c"), "-lm", "-o",
                        str(probe)], check=True)  # fmt: skip
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
