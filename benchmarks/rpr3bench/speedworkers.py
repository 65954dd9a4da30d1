"""Workers of the speed measurements added for issue 15, each run in a fresh interpreter
(:func:`rpr3bench.workers.run_worker`): NumPy per function, the NumPy profile per generated
statement and per block size, and the C backend's scaling with threads."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from rpr3bench.common import sample_inputs, variant


def _best(call: Callable[[], Any], repeats: int) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


def worker_numpy_functions(args: dict[str, Any]) -> dict[str, Any]:
    """``evaluate(backend="numpy")`` of each function at n samples: best ns per sample."""
    import rpr3gen

    model = rpr3gen.load_model()
    n, repeats = int(args["n"]), int(args["repeats"])
    result = {}
    for name in args["functions"]:
        inputs = sample_inputs(variant().function(name), n)
        rpr3gen.evaluate(model, name, [a[:100] for a in inputs])  # imports, warm-up
        seconds = _best(lambda name=name, inputs=inputs: rpr3gen.evaluate(model, name, inputs),
                        repeats)  # fmt: skip
        result[name] = seconds / n * 1e9
    return {"ns": result}


def worker_numpy_profile(args: dict[str, Any]) -> dict[str, Any]:
    """The generated NumPy function of ``function``, statement by statement, on one block; and
    the whole function over 2 10^5 samples in blocks of each size of ``blocks``."""
    import numpy as np

    import rpr3gen
    from rpr3bench import npprofile
    from rpr3gen.backends import BLOCK
    from rpr3gen.evaluators import numpy_module

    found = variant()
    info = found.function(args["function"])
    params = rpr3gen.load_model().vector(found.param_names)
    block = int(args.get("block", BLOCK))
    inputs = sample_inputs(info, block)

    def arguments() -> list[Any]:
        return [params, *inputs, *(np.empty((o.size, block)) for o in info.outputs)]

    prof = npprofile.profile(
        found.path("numpy"), info.numpy_function, arguments, block, int(args["calls"])
    )
    function = getattr(numpy_module(found), info.numpy_function)
    n = 2 * 10**5
    samples = sample_inputs(info, n)
    outputs = [np.empty((o.size, n)) for o in info.outputs]
    for out in outputs:
        out.fill(0.0)
    sweep = {}
    for size in args["blocks"]:

        def run(size: int = size) -> None:
            for lo in range(0, n, size):
                part = slice(lo, lo + size)
                function(params, *(a[part] for a in samples), *(o[:, part] for o in outputs))

        sweep[str(size)] = _best(run, int(args["repeats"])) / n * 1e9
    return {
        "block": block,
        "by_kind": {k: v * 1e9 for k, v in prof.by_kind.items()},
        "count": prof.count,
        "total": prof.total * 1e9,
        "dispatch": {k: v * 1e9 for k, v in prof.dispatch.items()},
        "top": [(s * 1e9, label) for s, label in prof.top],
        "sweep": sweep,
    }


def worker_c_threads(args: dict[str, Any]) -> dict[str, Any]:
    """The c backend of ``function`` with 1 to ``threads`` threads: ``evaluate()`` (allocates
    its outputs) at each size, and the evaluator alone into outputs allocated and touched
    beforehand, the whole batch (streamed) and a chunk per thread that stays in cache."""

    import rpr3gen
    from rpr3gen.evaluators import CEvaluator, evaluator

    model = rpr3gen.load_model()
    found = variant()
    info = found.function(args["function"])
    params = model.vector(found.param_names)
    counts = list(range(1, int(args["threads"]) + 1))
    repeats = int(args["repeats"])
    result: dict[str, Any] = {"threads": counts, "evaluate": {}, "streamed": {}, "cached": {}}
    ev = evaluator(found, "c")
    for n in args["sizes"]:
        inputs = sample_inputs(info, n)
        rpr3gen.evaluate(model, info.name, [a[:10] for a in inputs], backend="c")
        result["evaluate"][str(n)] = [
            _best(lambda k=k, inputs=inputs: rpr3gen.evaluate(
                model, info.name, inputs, backend="c", threads=k), repeats) / n * 1e9
            for k in counts
        ]  # fmt: skip
        outputs = ev.allocate(info, n)
        for out in outputs:
            out.fill(0.0)
        result["streamed"][str(n)] = [
            _best(lambda k=k, inputs=inputs, outputs=outputs: ev.run(
                info, params, inputs, outputs, k), repeats) / n * 1e9
            for k in counts
        ]  # fmt: skip
    chunk = 2 * CEvaluator.MIN_CHUNK  # per thread: its outputs stay in its cache
    rounds = 50
    inputs = [a[:chunk] for a in sample_inputs(info, chunk)]
    outputs = {k: [ev.allocate(info, chunk) for _ in range(k)] for k in counts}
    from rpr3gen.evaluators import _pool

    def cached(k: int) -> None:
        pool = _pool(k)
        jobs = [
            pool.submit(
                lambda out=out: [ev.run(info, params, inputs, out, 1) for _ in range(rounds)]
            )
            for out in outputs[k]
        ]
        for job in jobs:
            job.result()

    for k in counts:
        result["cached"][str(k)] = (
            _best(lambda k=k: cached(k), repeats) / (k * chunk * rounds) * 1e9
        )
    result["chunk"] = chunk
    result["rounds"] = rounds
    result["repeats"] = repeats
    return result


WORKERS: dict[str, Callable[[dict[str, Any]], dict[str, Any]]] = {
    "numpy_functions": worker_numpy_functions,
    "numpy_profile": worker_numpy_profile,
    "c_threads": worker_c_threads,
}
