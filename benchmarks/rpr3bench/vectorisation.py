"""Whether the generated batch loops run in SIMD lanes: gcc's own report and the assembly.

The generated C is compiled as the runtime compiles it (``cbackend.CFLAGS`` and the first
``EXTRA_FLAGS``), once to assembly (``-S``) and once with ``-fopt-info-vec-optimized``. For each
``rpr3_*_batch`` function this counts, in its assembly, the double-precision arithmetic
instructions by width: packed on 512-bit (``zmm``), 256-bit (``ymm``) or 128-bit registers, and
scalar (``*sd``); fused multiply-adds (none may appear: single and batch must agree bit for
bit); and calls into libm. gcc's report says which of the batch's three loops (A, B, C: see
the generated source) it vectorised, and with which vector size.
"""

from __future__ import annotations

import re
import subprocess
import tempfile
from collections import Counter
from pathlib import Path
from typing import Any

from rpr3bench.common import CC, REPO, shown, variant

ARITHMETIC = re.compile(
    r"^\s+v?(?P<op>add|sub|mul|div|sqrt|min|max|and|andn|or|xor|blendm|cmp\w*|round|rndscale)"
    r"(?P<kind>pd|sd)\s+(?P<args>.*)$"
)
FMA = re.compile(r"^\s+vf(n?m(add|sub)\w*)(pd|sd)\s")
CALL = re.compile(r"^\s+(call|jmp)\s+(?P<target>[\w.@]+)")
LIBM = ("sin", "cos", "sincos", "atan2", "sqrt", "nearbyint", "rint", "fmin", "fmax", "pow")


def runtime_flags() -> list[str]:
    """The flags the runtime builds the generated C with (without ``-fPIC -shared``)."""
    from rpr3gen import cbackend

    flags = [f for f in cbackend.CFLAGS if f not in ("-fPIC", "-shared")]
    return flags + list(cbackend.EXTRA_FLAGS[0])


def _functions(assembly: str) -> dict[str, list[str]]:
    """Instruction lines of each ``rpr3_*_batch`` function of an assembly listing."""
    bodies: dict[str, list[str]] = {}
    current = None
    for line in assembly.splitlines():
        match = re.match(r"^(rpr3_\w+_batch):", line)
        if match:
            current = match.group(1)
            bodies[current] = []
        elif current and re.match(rf"^\s+\.size\s+{current},", line):
            current = None
        elif current:
            bodies[current].append(line)
    return bodies


def _count(lines: list[str]) -> dict[str, Any]:
    widths: Counter[str] = Counter()
    fma = 0
    libm: Counter[str] = Counter()
    for line in lines:
        match = ARITHMETIC.match(line)
        if match:
            args = match.group("args")
            if match.group("kind") == "sd":
                widths["scalar"] += 1
            elif "zmm" in args:
                widths["512"] += 1
            elif "ymm" in args:
                widths["256"] += 1
            else:
                widths["128"] += 1
        if FMA.match(line):
            fma += 1
        call = CALL.match(line)
        if call:
            target = call.group("target").split("@")[0]
            if target in LIBM:
                libm[target] += 1
    return {"widths": dict(widths), "fma": fma, "libm": dict(libm)}


def _loops(source: Path, report: str) -> dict[str, dict[str, str]]:
    """``{batch function: {"A": "64-byte vectors" | "scalar", ...}}`` from gcc's report."""
    lines = source.read_text().splitlines()
    passes: dict[int, tuple[str, str]] = {}
    current = None
    for number, line in enumerate(lines, 1):
        match = re.match(r"^size_t (rpr3_\w+_batch)\(", line)
        if match:
            current = match.group(1)
        tag = re.search(r"/\* ([ABC]): ", line)
        if current and tag and line.lstrip().startswith("for ("):
            passes[number] = (current, tag.group(1))
    loops: dict[str, dict[str, str]] = {}
    for function, tag in passes.values():
        loops.setdefault(function, {})[tag] = "scalar"
    for line in report.splitlines():
        match = re.search(r":(\d+):\d+: optimized: loop vectorized using (\d+) byte vectors", line)
        if match and int(match.group(1)) in passes:
            function, tag = passes[int(match.group(1))]
            size = f"{match.group(2)}-byte"
            if loops[function][tag] == "scalar" or size > loops[function][tag]:
                loops[function][tag] = size  # the main loop's, not its epilogue's
    return loops


def report() -> dict[str, Any] | str:
    """Per batch function: instruction counts and gcc's loop verdicts; or why it failed."""
    found = variant()
    source = found.path("c_source")
    flags = runtime_flags()
    with tempfile.TemporaryDirectory(prefix="rpr3bench-asm-") as tmp:
        asm, info = Path(tmp) / "rpr3.s", Path(tmp) / "vec.txt"
        command = [*CC, *flags, "-I", str(found.folder), "-S", str(source), "-o", str(asm),
                   f"-fopt-info-vec-optimized={info}"]  # fmt: skip
        done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
        if done.returncode != 0 or not asm.exists():
            return f"compiling to assembly failed: {done.stderr.strip()[:300]}"
        bodies = _functions(asm.read_text())
        loops = _loops(source, info.read_text() if info.exists() else "")
    shown_command = [*CC, *flags, "-S", shown(source)]
    return {
        "command": " ".join(shown_command),
        "functions": {
            name: {**_count(lines), "loops": loops.get(name, {})} for name, lines in bodies.items()
        },
    }
