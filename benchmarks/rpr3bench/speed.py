"""The tables of issue 15 inside sections 2 and 3: the NumPy profile per generated statement and
per block size, the assembly of the C batches, and the C backend's scaling with threads."""

from __future__ import annotations

from typing import Any

from rpr3bench import vectorisation
from rpr3bench.common import log
from rpr3bench.report import SCORED, ns, ratio, size_label, table
from rpr3bench.workers import run_worker

#: Block sizes of the NumPy sweep (the runtime's is rpr3gen.backends.BLOCK).
BLOCKS = (2048, 4096, 8192, 12288, 16384, 32768, 65536)


def numpy_profile(quick: bool) -> tuple[str, dict[str, Any]]:
    """Where the NumPy time of the scored function goes, and the block size sweep."""
    log(f"numpy: profile of {SCORED} per generated statement, block sizes")
    r = run_worker(
        "numpy_profile",
        function=SCORED,
        calls=10 if quick else 30,
        blocks=list(BLOCKS),
        repeats=3 if quick else 5,
    )
    if "error" in r:
        return f"\nProfile failed: {r['error']}\n", {}
    block = r["block"]
    rows = []
    for kind, spent in r["by_kind"].items():
        count = r["count"][kind]
        fixed = r["dispatch"].get(kind)
        rows.append(
            [
                f"`{kind}`",
                str(count),
                ns(spent),
                f"{100 * spent / r['total']:.0f}%",
                f"{fixed:.0f} ns = {count * fixed / block:.1f} ns/sample" if fixed else "",
            ]
        )
    calls = sum(c for k, c in r["count"].items() if k.startswith("numpy."))
    fixed_total = sum(r["count"][k] * v for k, v in r["dispatch"].items()) / block
    text = [
        f"\nWhere the time of the generated `{SCORED}` goes, statement by statement (one block of "
        f"{block:,} samples, {r['total']:.1f} ns/sample in all; `rpr3bench/npprofile.py` times a "
        "copy of the generated function with a clock reading after every statement; the "
        "module itself is untouched):\n",
        table(["statement", "count", "ns/sample", "share", "fixed cost per call"], rows),
        "",
        f"{calls} ufunc calls a block; their fixed cost (the same call on one-element arrays: "
        f"interpreter and NumPy dispatch) adds up to {fixed_total:.1f} ns/sample, the rest is "
        "the passes over the block's arrays. `_sincos` is the generated pair of sin and cos "
        "(one reduction, two polynomials, in ufunc passes). Costliest single statements, "
        "ns/sample: "
        + "; ".join(f"`{label[:60]}` {spent:.1f}" for spent, label in r["top"][:4])
        + ".",
        "",
        "The whole generated function over 2 x 10^5 samples in blocks of each size (outputs "
        "preallocated), ns/sample: "
        + ", ".join(
            f"{size_label(int(size))}: {ns(value)}"
            + (" (**runtime**)" if int(size) == block else "")
            for size, value in r["sweep"].items()
        )
        + ". Small blocks pay the fixed cost of every call more often; large ones fall out of "
        "the cache.",
    ]
    return "\n".join(text) + "\n", r


def c_assembly() -> tuple[str, dict[str, Any]]:
    """Section 3's evidence that the batch loops vectorise: gcc's report and the assembly."""
    log("c: assembly of the generated batches")
    r = vectorisation.report()
    if isinstance(r, str):
        return f"\n{r}\n", {}
    rows = []
    for name, f in r["functions"].items():
        widths = f["widths"]
        loops = f["loops"]
        packed = widths.get("512", 0) + widths.get("256", 0) + widths.get("128", 0)
        rows.append(
            [
                f"`{name}`",
                ", ".join(f"{k}: {v}" for k, v in sorted(loops.items())) or "(loops the kernel)",
                str(widths.get("512", 0)),
                str(widths.get("256", 0)),
                str(widths.get("128", 0)),
                str(widths.get("scalar", 0)),
                f"{100 * packed / max(1, packed + widths.get('scalar', 0)):.0f}%",
                str(f["fma"]),
                ", ".join(f"{k} {v}" for k, v in f["libm"].items()) or "none",
            ]
        )
    text = (
        "\nDo the batch loops run in SIMD lanes? `"
        + r["command"]
        + "` (the runtime's flags) with `-fopt-info-vec-optimized`, per batch function: gcc's "
        "verdict on its three loops (A: inputs; B: everything else, the math kernels inlined; "
        "C: checks and row-major stores), and its double-precision arithmetic instructions "
        "(add, sub, mul, div, sqrt, min, max, compares, blends, bit operations) by register "
        "width:\n\n"
        + table(
            [
                "batch function",
                "loops vectorised (gcc)",
                "zmm (512)",
                "ymm (256)",
                "xmm (128)",
                "scalar",
                "packed share",
                "FMA",
                "libm calls",
            ],
            rows,
        )
        + "\n\nThe ymm count is mostly the vectorised loops' epilogues (the last samples of a "
        "block); the scalar count is pass C and the single-sample kernel inlined into it for "
        "the samples a batch evaluates again (a failed check, or a sin/cos argument past the "
        "fast path's 2^20). No FMA (the single call must give the same bits) and no libm call "
        "anywhere in the batches.\n"
    )
    return text, r


def c_threads(quick: bool, cores: int) -> tuple[str, dict[str, Any]]:
    """The c backend's batch on 1..cores threads."""
    log(f"c: threads 1..{cores}")
    r = run_worker(
        "c_threads",
        function=SCORED,
        threads=cores,
        sizes=[10**5, 10**6],
        repeats=3 if quick else 7,
    )
    if "error" in r:
        return f"\nThreads: failed: {r['error']}\n", {}
    counts = r["threads"]
    rows = []

    def add(label: str, values: list[float]) -> None:
        rows.append([label, *(f"{ns(v)} ({ratio(values[0] / v)})" for v in values)])

    add(
        f"batch of {r['chunk']:,} per thread, outputs in cache",
        [r["cached"][str(k)] for k in counts],
    )
    for n in sorted(r["streamed"], key=int):
        add(f"batch of {size_label(int(n))}, outputs preallocated (streamed)", r["streamed"][n])
    for n in sorted(r["evaluate"], key=int):
        add(f"`evaluate(backend=\"c\")`, {size_label(int(n))} (allocates outputs)",
            r["evaluate"][n])  # fmt: skip
    k = counts[-1]
    cached = r["cached"]["1"] / r["cached"][str(k)]
    streamed = {n: v[0] / v[-1] for n, v in r["streamed"].items()}
    slow = [size_label(int(n)) for n, x in streamed.items() if x < 0.8 * min(cached, k)]
    text = (
        f"\nThe c backend on every core (`{SCORED}`, `threads=1..{k}`: contiguous "
        "chunks of the batch on a thread pool, ctypes releasing the GIL), ns per sample of the "
        "whole run (speed-up over one thread):\n\n"
        + table(["run", *(f"{c} thread{'s' if c > 1 else ''}" for c in counts)], rows)
        + f"\n\nBest of {r['repeats']} repeats, each configuration in turn. The in-cache row is "
        f"the compute alone: each thread runs the batch on its own chunk, {r['rounds']} times "
        f"({ratio(cached)} on {k} cores). The batches over 10^5 and 10^6 samples also write "
        "424 bytes of outputs a sample to memory, and `evaluate` pays the kernel for the fresh "
        "pages of the outputs it allocates"
        + (f"; at {', '.join(slow)} the memory, not the cores, sets the pace" if slow else "")
        + ". Other processes on the machine take cores too: see the load average above.\n"
    )
    return text, r
