"""The bridges' timings (one run, on demand): the inverse dynamics of the committed 3-RRR
(``rrr_1``) and 6-UPS (``ups_2``) on CasADi and JAX beside the NumPy and C backends, for one
sample and for a batch.

    python benchmarks/bridges.py            # prints a Markdown table, writes bridges-results.md

One sample: the generated C and NumPy through ``rpr3gen.SampleEvaluator`` (no allocation for
the C), the CasADi ``Function`` called from Python on NumPy arrays (its SX virtual machine), the
C that CasADi generates from it built as a shared library and called through
``casadi.external``, and the JAX function jitted (``rpr3gen.jax.COMPILER_OPTIONS``) called
on NumPy arrays. A batch of 10,000 samples: ``rpr3gen.evaluate`` on the NumPy and C backends
(one thread) and on ``backend="jax"`` (``jit(vmap)``, with the runtime's failure checks), the
CasADi function mapped over the samples (``Function.map``, serial), and the bare
``jit(vmap(g))`` of JAX. The median of 7 rounds; the compile times of the first calls are
reported too. A figure is of this machine, in one run: compare rows with each other.
"""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import rpr3gen
import rpr3gen.casadi as rc
import rpr3gen.jax as rj

#: Time the optimised C libraries, not the quick ones a first use runs on (rpr3gen.cbackend).
os.environ.setdefault("RPR3GEN_C_BUILD", "optimised")

ROOT = Path(__file__).resolve().parent.parent
MODELS = {"rrr_1": ROOT / "models" / "rrr.toml", "ups_2": ROOT / "models" / "tsai-ups.toml"}
BATCH = 10_000
ROUNDS = 7


def cpu() -> str:
    """The processor's model name and family, from /proc/cpuinfo."""
    fields: dict[str, str] = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            fields.setdefault(key.strip(), value.strip())
    except OSError:
        return platform.processor() or "unknown"
    return f"{fields.get('model name', '?')} (family {fields.get('cpu family', '?')})"


def timed(call: Callable[[], object], repeat: int) -> float:
    """Seconds per call: the median of :data:`ROUNDS` rounds of ``repeat`` calls."""
    rounds = []
    for _ in range(ROUNDS):
        start = time.perf_counter()
        for _ in range(repeat):
            call()
        rounds.append((time.perf_counter() - start) / repeat)
    return statistics.median(rounds)


def first(call: Callable[[], object]) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def motion(model: rpr3gen.Model, n: int) -> list[np.ndarray]:
    rng = np.random.default_rng(0)
    k = model.structure.dof
    scale = np.array([0.01] * k)
    return [np.ascontiguousarray(rng.normal(0.0, 1.0, (n, k)) * scale) for _ in range(3)]


def casadi_c(f: object, folder: Path) -> object:
    """CasADi's generated C of ``f`` as a shared library, loaded by ``casadi.external``."""
    import casadi

    source = f.generate("bridge_id.c")  # type: ignore[attr-defined]
    Path(source).rename(folder / source)
    library = folder / "bridge_id.so"
    subprocess.run(
        ["gcc", "-O3", "-fPIC", "-shared", str(folder / source), "-o", str(library)], check=True
    )
    return casadi.external(f.name(), str(library))  # type: ignore[attr-defined]


def bench(variant: str) -> list[tuple[str, str, float, float | None]]:
    """``(kind, backend, seconds per sample, first-call seconds)`` rows of one variant."""
    import jax

    model = rpr3gen.load_model(MODELS[variant])
    one = [a[0] for a in motion(model, 1)]
    many = motion(model, BATCH)
    rows: list[tuple[str, str, float, float | None]] = []
    for backend in ("c", "numpy"):
        s = rpr3gen.SampleEvaluator(model, backend)
        s.q[:], s.qd[:], s.qdd[:] = one
        rows.append(("one sample", backend, timed(s, 2000), None))
    params = rc.parameters(model)
    made = first(lambda: rc.function(model, "inverse_dynamics"))
    f = rc.function(model, "inverse_dynamics")
    rows.append(("one sample", "CasADi SX", timed(lambda: f(params, *one), 2000), made))
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        ext = casadi_c(f, Path(tmp))
        built = time.perf_counter() - start
        rows.append(("one sample", "CasADi generated C", timed(lambda: ext(params, *one), 2000),
                     built))  # fmt: skip
    g = jax.jit(rj.function(model, "inverse_dynamics"), compiler_options=rj.COMPILER_OPTIONS)
    compiled = first(lambda: np.asarray(g(params, *one)))
    rows.append(("one sample", "JAX jit", timed(lambda: np.asarray(g(params, *one)), 500),
                 compiled))  # fmt: skip
    for backend in ("c", "numpy", "jax"):
        warm = first(lambda b=backend: rpr3gen.evaluate(model, "inverse_dynamics", many, b))
        t = timed(lambda b=backend: rpr3gen.evaluate(model, "inverse_dynamics", many, b,
                                                     threads=1), 1)  # fmt: skip
        rows.append((f"batch of {BATCH:,}", backend, t / BATCH, warm if backend == "jax" else None))
    mapped = f.map(BATCH)
    columns = [a.T for a in many]
    t = timed(lambda: mapped(params, *columns), 1)
    rows.append((f"batch of {BATCH:,}", "CasADi SX map", t / BATCH, None))
    gv = jax.jit(jax.vmap(rj.function(model, "inverse_dynamics"), in_axes=(None, 0, 0, 0)),
                 compiler_options=rj.COMPILER_OPTIONS)  # fmt: skip
    compiled = first(lambda: np.asarray(gv(params, *many)))
    t = timed(lambda: np.asarray(gv(params, *many)), 1)
    rows.append((f"batch of {BATCH:,}", "JAX jit(vmap)", t / BATCH, compiled))
    return rows


def main() -> None:
    lines = [
        "# Bridges: the inverse dynamics on CasADi and JAX beside NumPy and C",
        "",
        "`python benchmarks/bridges.py`, one run (docs/bridges.md). CPU: " + cpu() + ".",
        "",
        "| variant | call | backend | µs per sample | first call (build or compile), s |",
        "|---|---|---|---:|---:|",
    ]
    for variant in MODELS:
        for kind, backend, seconds, once in bench(variant):
            once_text = "" if once is None else f"{once:.2f}"
            lines.append(f"| {variant} | {kind} | {backend} | {seconds * 1e6:.3g} | {once_text} |")
    text = "\n".join(lines) + "\n"
    print(text)
    (ROOT / "benchmarks" / "bridges-results.md").write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
