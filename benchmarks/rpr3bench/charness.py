"""The C timing harness ``benchmarks/bench.c``: build it against the generated C, run it, read it.

``bench.c`` times ``rpr3_inverse_dynamics`` and its batch form against a "floor" loop of the
transcendental functions one sample needs (see its header comment). This module writes its
inputs (``rpr3gen params`` and raw float64 samples), compiles it with the system compiler, runs
it, asks gcc whether the floor loop was vectorised and, when ``perf`` is installed, where the
batch time goes.
"""

from __future__ import annotations

import re
import subprocess
import tempfile
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rpr3bench.common import BENCH, CC, PY, REPO, log, shown, trajectory, variant

#: bench.c is built as the runtime builds the generated C (``cbackend.CFLAGS`` and the first
#: ``EXTRA_FLAGS``, without ``-fPIC -shared``): -O3, no errno, no traps, no FMA, -march=native.
C_FLAGS = (
    "-std=c99",
    "-O3",
    "-fno-math-errno",
    "-fno-trapping-math",
    "-march=native",
    "-mno-fma",
)
SOURCE = BENCH / "bench.c"


@dataclass
class CRun:
    """What one run of the harness gave."""

    command: list[str]  # the compile command, as run from the repository
    values: dict[str, Any]  # bench's "key value" lines
    probe: dict[str, float]  # bench's "probe name value" lines: every output of one sample
    symbols: str  # undefined symbols of the executable (libm calls)
    vectorised: str  # gcc's verdict on the floor loop
    calls: dict[str, int]  # libm calls in the generated C source
    inputs: dict[str, Any]  # the samples, by input name
    fast_values: dict[str, Any] = field(default_factory=dict)  # floor built with -ffast-math
    fast_vectorised: str = "n/a"
    profile: dict[str, float] = field(default_factory=dict)  # perf share per function
    profiled_ns: float | None = None  # batch ns/sample of the profiled run


def count_calls(source: str) -> dict[str, int]:
    """How often each libm function (or the generated kernel in its place) is called in the
    kernels and batches of a C source (the math kernels' own definitions left out)."""
    start = source.find("#define RPR3_BLOCK")
    return count_in(source[start:] if start > 0 else source)


def _command_output(command: Sequence[str]) -> str:
    try:
        done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
    except OSError:
        return "n/a"
    return (done.stdout.strip().splitlines() or ["n/a"])[0]


def _vector_report(build: Path, include: str, extra: Sequence[str]) -> str:
    """What gcc says about the loops between FLOOR BEGIN and FLOOR END of bench.c."""
    lines = SOURCE.read_text().splitlines()
    first = next(k for k, line in enumerate(lines, 1) if "FLOOR BEGIN" in line)
    last = next(k for k, line in enumerate(lines, 1) if "FLOOR END" in line)
    report = build / f"vec{len(extra)}.txt"
    command = [*CC, *C_FLAGS, *extra, "-I", include, "-c", str(SOURCE), "-o",
               str(build / "vec.o"), f"-fopt-info-vec-all={report}"]  # fmt: skip
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


def _parse(stdout: str) -> tuple[dict[str, Any], dict[str, float]]:
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
        batch_ns = _parse(done.stdout)[0].get("batch_ns")
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


def run(n: int, repeats: int) -> CRun | str:
    """Build and run bench.c on n samples; the results, or why it failed (Markdown)."""
    import numpy as np

    found = variant()
    include = shown(found.folder)
    source = shown(found.path("c_source"))
    calls = count_calls(found.path("c_source").read_text())
    with tempfile.TemporaryDirectory(prefix="rpr3bench-") as tmp:
        build = Path(tmp)
        params_file = build / "params.txt"
        done = subprocess.run(
            [PY, "-m", "rpr3gen.cli", "params"], capture_output=True, text=True, check=False
        )
        if done.returncode != 0:
            return f"`rpr3gen params` failed: {done.stderr.strip()}\n"
        params_file.write_text(done.stdout)
        inputs = trajectory(n)
        samples = build / "inputs.bin"
        np.concatenate([inputs[k].ravel() for k in ("q", "qd", "qdd")]).astype("=f8").tofile(
            samples
        )
        exe = build / "bench"
        command = [*CC, *C_FLAGS, "-I", include, shown(SOURCE), source, "-lm", "-o", str(exe)]
        log("c: " + " ".join(command))
        done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
        if done.returncode != 0:
            return f"Compiling bench.c failed:\n\n```\n{done.stderr}\n```\n"
        symbols = _command_output(["sh", "-c", f"nm -u {exe} | tr -s ' ' | tr '\\n' ' '"])
        log(f"c: {n:,} samples x {repeats}")
        args = [str(params_file), str(samples), str(n), str(repeats)]
        done = subprocess.run([str(exe), *args], capture_output=True, text=True, check=False)
        if done.returncode != 0:
            return f"bench failed: {done.stderr.strip()}\n"
        values, probe = _parse(done.stdout)
        result = CRun(
            command=[*command[:-2], "-o", "bench"],
            values=values,
            probe=probe,
            symbols=symbols,
            vectorised=_vector_report(build, include, []),
            calls=calls,
            inputs=inputs,
        )
        result.profile, result.profiled_ns = _profile(exe, [*args, "batch"])
        # Informational: the floor with -ffast-math, which lets gcc use libmvec if it can.
        fast = build / "bench_fast"
        done = subprocess.run(
            [*command[:-2], "-ffast-math", "-o", str(fast)],
            capture_output=True,
            text=True,
            check=False,
            cwd=REPO,
        )
        if done.returncode == 0:
            log("c: floor with -ffast-math")
            done = subprocess.run(
                [str(fast), *args, "floor"], capture_output=True, text=True, check=False
            )
            result.fast_values = _parse(done.stdout)[0] if done.returncode == 0 else {}
            fast_symbols = _command_output(["sh", "-c", f"nm -u {fast} | grep -c _ZGV || true"])
            result.fast_vectorised = (
                _vector_report(build, include, ["-ffast-math"])
                + f"; libmvec (`_ZGV*`) symbols used: {fast_symbols}"
            )
    return result


# ---------------------------------------------------------------------------------------------
# The control model: bench_control.c (both variants, two builds) and the MuJoCo peer from C
# ---------------------------------------------------------------------------------------------

CONTROL_SOURCE = BENCH / "bench_control.c"
MUJOCO_SOURCE = BENCH / "bench_mujoco.c"
#: Builds of bench_control.c: the runtime's flags (``cbackend.CFLAGS`` and its first
#: ``EXTRA_FLAGS``, without ``-fPIC -shared``), and plain -O2 as in examples/control_loop.
CONTROL_BUILDS: dict[str, tuple[str, ...]] = {"O3": C_FLAGS, "O2": ("-std=c99", "-O2")}
#: The paper's trajectories the control harness runs, one after the other, each sampled at 1 ms.
CONTROL_TRAJECTORIES = ("rotation", "rectilinear")
CONTROL_SAMPLES = 3001  # 3 s at 1 ms


#: libm functions counted in the kernels of the control functions.
LIBM = ("sin", "cos", "sqrt", "atan2", "atan", "pow", "exp", "log")


def count_in(body: str, prefix: str = "rpr3") -> dict[str, int]:
    """Calls of each :data:`LIBM` function in C text: libm's own (``sin(``) and the generated
    C's kernels that stand for them (``rpr3_sin(``, ``rpr3_sin_fast(``)."""
    found = {}
    for f in LIBM:
        count = len(re.findall(rf"(?:\b|\b{prefix}_){f}(?:_fast)?\(", body))
        if count:
            found[f] = count
    return found


def kernel_calls(actuation: str) -> dict[str, dict[str, int]]:
    """libm calls (:data:`LIBM`, or the generated kernels in their place) in the body of each
    ``rpr3_NAME_kernel`` of a variant's generated C, by NAME: after CSE, what one sample of
    that function must evaluate."""
    from rpr3gen import manifest

    source = manifest.load(actuation).path("c_source").read_text()
    kernels = re.finditer(r"^static int rpr3_(\w+)_kernel\(", source, re.M)
    calls = {}
    for match in kernels:
        end = source.find("\nint rpr3_", match.start())
        calls[match.group(1)] = count_in(source[match.start() : end if end > 0 else None])
    return calls


def control_inputs(build: Path) -> tuple[Path, Path, int, int]:
    """Write ``rpr3gen params`` and the trajectories (raw q, qd, qdd) for bench_control.c:
    (params file, samples file, samples, samples per trajectory)."""
    import numpy as np

    import rpr3gen

    done = subprocess.run(
        [PY, "-m", "rpr3gen.cli", "params"], capture_output=True, text=True, check=True
    )
    params_file = build / "params.txt"
    params_file.write_text(done.stdout)
    runs = [
        rpr3gen.paper_trajectory(name, samples=CONTROL_SAMPLES, duration=3.0)
        for name in CONTROL_TRAJECTORIES
    ]
    arrays = [np.concatenate([getattr(r, k) for r in runs]) for k in ("q", "qd", "qdd")]
    samples = build / "control.bin"
    np.concatenate([a.ravel() for a in arrays]).astype("=f8").tofile(samples)
    return params_file, samples, len(arrays[0]), CONTROL_SAMPLES


def _build_and_run(
    command: list[str], exe: Path, args: Sequence[str], what: str
) -> dict[str, Any] | str:
    log(f"{what}: " + " ".join(command))
    done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=REPO)
    if done.returncode != 0:
        return f"Compiling {what} failed:\n\n```\n{done.stderr}\n```\n"
    done = subprocess.run([str(exe), *args], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        return f"{what} failed: {done.stderr.strip()}\n"
    return _parse(done.stdout)[0]


def run_control(build: Path, actuation: str, flags: str, repeats: int) -> dict[str, Any] | str:
    """Build bench_control.c against one variant with ``CONTROL_BUILDS[flags]`` and run it on
    the trajectories of :func:`control_inputs` (written into ``build`` once)."""
    from rpr3gen import manifest

    params_file, samples = build / "params.txt", build / "control.bin"
    if not samples.exists():
        control_inputs(build)
    n = len(CONTROL_TRAJECTORIES) * CONTROL_SAMPLES
    found = manifest.load(actuation)
    exe = build / f"bench_control_{actuation}_{flags}"
    command = [
        *CC,
        *CONTROL_BUILDS[flags],
        "-I",
        shown(found.folder),
        shown(CONTROL_SOURCE),
        shown(found.path("c_source")),
        "-lm",
        "-o",
        str(exe),
    ]
    args = [str(params_file), str(samples), str(n), str(CONTROL_SAMPLES), str(repeats)]
    result = _build_and_run(command, exe, args, f"bench_control ({actuation}, {flags})")
    if isinstance(result, dict):
        result["command"] = " ".join([*command[:-2], "-o", "bench_control"])
    return result


def mujoco_library() -> tuple[Path, Path] | str:
    """(include folder, libmujoco) of the installed mujoco Python package, or why not."""
    import importlib.util

    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.origin:
        return "the mujoco package is not installed"
    folder = Path(spec.origin).parent
    libraries = sorted(folder.glob("libmujoco.so*"))
    include = folder / "include"
    if not libraries or not (include / "mujoco" / "mujoco.h").exists():
        return f"no C headers or libmujoco in {folder}"
    return include, libraries[-1]


def run_mujoco(
    build: Path, xml: Path, state: Path, calls: int, repeats: int
) -> dict[str, Any] | str:
    """Build bench_mujoco.c against the mujoco package's library and time mj_forward and
    mj_step from C on the model ``xml`` at the state ``state``."""
    found = mujoco_library()
    if isinstance(found, str):
        return found
    include, library = found
    exe = build / "bench_mujoco"
    command = [
        *CC,
        "-std=c11",
        "-O2",
        "-I",
        str(include),
        shown(MUJOCO_SOURCE),
        str(library),
        f"-Wl,-rpath,{library.parent}",
        "-o",
        str(exe),
    ]
    result = _build_and_run(
        command, exe, [str(xml), str(state), str(calls), str(repeats)], "bench_mujoco"
    )
    if isinstance(result, dict):
        result["command"] = " ".join(
            [
                *CC,
                "-std=c11",
                "-O2",
                "-I .../mujoco/include",
                shown(MUJOCO_SOURCE),
                f".../mujoco/{library.name}",
                "-o",
                "bench_mujoco",
            ]
        )
    return result
