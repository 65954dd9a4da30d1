"""Where the NumPy inverse dynamics' time goes: ``python harness/numpy_parts.py [--quick] -o F``.

Per paper variant, on :data:`N` samples of the generic motion, ns per sample (each the best of
its rounds, the five measures alternating within a round):

- ``evaluate``: ``rpr3gen.evaluate(model, "inverse_dynamics", ..., backend="numpy")``, as a user
  calls it again and again, each result dropped before the next call: the input checks, the
  outputs' allocation (the memory of the result dropped, reused: :mod:`rpr3gen.buffers`), the
  generated kernel block by block, the failure checks;
- ``fresh``: the same with the pool of output memory off, as a first call or one whose caller
  keeps the earlier results: the outputs' pages are new, and the kernel maps and zeroes each at
  its first write;
- ``checked``: the NumPy evaluator block by block, as ``evaluate`` runs it, into outputs
  allocated once (their pages mapped): the generated kernel, the failure checks' short cut
  (``rpr3gen.failures.none_failed`` on the output rows' sums that the kernel takes) and, when
  it cannot answer, the per-sample checks (``rpr3gen.failures.apply``);
- ``kernel``: the generated function alone (its row sums included), the same way;
- ``floor``: the eager floor: the very ufunc calls one block of the kernel makes, recorded with
  their operands' kinds (a row of the block, or a scalar) and replayed on a few rows that stay
  in cache, with nothing between the calls but the replay loop. What the kernel spends above
  it is its working set (rows streamed from the outer caches) and its Python statements.

``calls`` is the number of calls one block makes: the ``_sincos`` and ``_atan2`` helpers' and
the sums of the output rows included, the per-block constants and the helpers' rare fallbacks
not (``tests/test_benchmark_numpy.py`` counts them from the module's text).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import rpr3gen
from harness import samples
from rpr3gen import backends, buffers, failures, variants

N = 10**5
#: Rounds, full run / quick run.
ROUNDS = (9, 3)
#: Rows the replay's operands rotate over, and as many for its outputs: few enough to stay in
#: L2 at the block size.
HOT_ROWS = 2


class _Recorder:
    """Stands for a ufunc in the generated module: calls it, and logs the call's form."""

    def __init__(self, ufunc: np.ufunc, log: list[tuple[Callable[..., Any], tuple, dict]], n: int):
        self.ufunc, self.log, self.n = ufunc, log, n

    def _form(self, call: Callable[..., Any], args: tuple, kwargs: dict) -> None:
        self.log.append((call, tuple(kind(a, self.n) for a in args), kwargs))

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        self._form(self.ufunc, args, kwargs)
        return self.ufunc(*args, **kwargs)

    def reduce(self, *args: Any, **kwargs: Any) -> Any:
        self._form(self.ufunc.reduce, args, kwargs)
        return self.ufunc.reduce(*args, **kwargs)


def kind(a: Any, n: int) -> tuple[str, Any, tuple[int, ...]]:
    """An operand's kind: ``("row", dtype, lead)`` for an array of the block's ``n`` samples
    (``lead``: its shape before them, ``(3,)`` for the legs' (3, n) blocks), else
    ``("scalar", a, ())`` (a 0-d constant, the legs' (3, 1) parameter column, ``sums``)."""
    if isinstance(a, np.ndarray) and a.ndim and a.shape[-1] == n:
        return ("row", a.dtype, a.shape[:-1])
    return ("scalar", a, ())


class _Numpy:
    """Stands for ``numpy`` in the generated module: logs ``copyto``, passes the rest."""

    def __init__(self, log: list[tuple[Callable[..., Any], tuple, dict]], n: int):
        self.log, self.n = log, n

    def __getattr__(self, name: str) -> Any:
        return getattr(np, name)

    def copyto(self, dst: np.ndarray, src: Any) -> None:
        self.log.append((np.copyto, (kind(dst, self.n), kind(src, self.n)), {}))
        np.copyto(dst, src)


def record(
    module: Any, run: Callable[[], object], n: int
) -> list[tuple[Callable[..., Any], tuple, dict]]:
    """The calls ``run()`` makes through ``module``'s ufuncs and ``numpy.copyto``, in order, on
    a block of ``n`` samples."""
    log: list[tuple[Callable[..., Any], tuple, dict]] = []
    saved = dict(vars(module))
    try:
        for name, value in saved.items():
            if isinstance(value, np.ufunc):
                setattr(module, name, _Recorder(value, log, n))
        module.numpy = _Numpy(log, n)
        run()
    finally:
        for name, value in saved.items():
            setattr(module, name, value)
    return log


def replay(log: list[tuple[Callable[..., Any], tuple, dict]], block: int) -> Callable[[], None]:
    """The logged calls, their operands taken in turn from :data:`HOT_ROWS` rows of ``block``
    values that no call writes (random, in [0.5, 1.5): no call meets a NaN, an infinity or a
    subnormal, which would change its cost) and their outputs written in turn to as many
    other rows."""
    rng = np.random.default_rng(0)
    rows: dict[tuple[bool, Any, tuple[int, ...]], list[np.ndarray]] = {}
    bound = []
    turn = 0
    for call, kinds, kwargs in log:
        inputs = getattr(call, "nin", 2 if call is np.copyto else len(kinds))
        outputs_first = call is np.copyto
        args = []
        for k, (form, what, lead) in enumerate(kinds):
            if form == "scalar":
                args.append(what)
                continue
            written = (k == 0) if outputs_first else (k >= inputs)
            shape = (*lead, block)
            pool = rows.setdefault((written, what, lead), [(0.5 + rng.random(shape)).astype(what)
                                                           for _ in range(HOT_ROWS)])  # fmt: skip
            args.append(pool[turn % HOT_ROWS])
            turn += 1
        bound.append((call, tuple(args), kwargs))

    def run() -> None:
        for call, args, kwargs in bound:
            call(*args, **kwargs)

    return run


def seconds(call: Callable[[], object]) -> float:
    """Seconds of one call."""
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def parts(variant: str, rounds: int) -> dict[str, float]:
    """The five measures of this module for one variant, ns per sample."""
    model = samples.model(variant)
    a = samples.motion(variant, "generic", N)
    inputs = [a["q"], a["qd"], a["qdd"]]
    found, info = variants.load_function(model.structure, model.generated, "inverse_dynamics")
    ev = backends.evaluator(found, "numpy")
    params = model.vector(found.param_names)
    blocks = list(backends._blocks(N, False, ev.block))

    function = getattr(ev.module, info.numpy_function)
    longest = max(b.stop - b.start for b in blocks)
    work = np.empty((ev.module.WORK_ROWS[info.numpy_function], longest))
    sums = np.empty(ev.module.OUTPUT_ROWS[info.numpy_function])

    def kernel(outputs: list[np.ndarray], checks: bool) -> None:
        for b in blocks:
            ins, outs = [x[b] for x in inputs], [o[b] for o in outputs]
            if not checks:
                function(params, *ins, *(o.T for o in outs), work=work, sums=sums)
            elif ev.run(info, params, ins, outs) != 0:
                failures.apply(info, ins, outs)

    first = blocks[0]
    one_block = ev.allocate(info, first.stop)
    log = record(
        ev.module,
        lambda: ev.run(info, params, [x[first] for x in inputs], one_block),
        first.stop - first.start,
    )
    floor = replay(log, first.stop - first.start)
    kept = ev.allocate(info, N)

    def evaluate() -> object:
        return rpr3gen.evaluate(model, "inverse_dynamics", inputs, backend="numpy")

    def fresh() -> object:
        keep, buffers.OUTPUTS.keep = buffers.OUTPUTS.keep, 0
        try:
            return evaluate()
        finally:
            buffers.OUTPUTS.keep = keep

    measures: dict[str, Callable[[], object]] = {
        "fresh": fresh,
        "evaluate": evaluate,
        "checked": lambda: kernel(kept, True),
        "kernel": lambda: kernel(kept, False),
        "floor": lambda: [floor() for _ in blocks],
    }
    times: dict[str, list[float]] = {name: [] for name in measures}
    for call in measures.values():  # warm: the first call maps pages and fills caches
        call()
    for _ in range(rounds):
        for name, call in measures.items():
            times[name].append(seconds(call))
    per_sample = {name: min(t) / N * 1e9 for name, t in times.items()}
    return {**per_sample, "calls": len(log), "block": first.stop - first.start}


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help="fewer rounds")
    parser.add_argument("-o", "--output", type=Path, required=True, help="the JSON written")
    args = parser.parse_args()
    np.seterr(all="ignore")
    rounds = ROUNDS[1 if args.quick else 0]
    found = {v: parts(v, rounds) for v in samples.paper_variants()}
    args.output.write_text(json.dumps(found) + "\n")


if __name__ == "__main__":
    main()
