"""The runtime's backends behind one small interface: call a generated function by name.

An :class:`Evaluator` evaluates any function of a generated variant's manifest over a block of
samples (:meth:`~Evaluator.run`) into output arrays it allocates in its own layout
(:meth:`~Evaluator.allocate`; always seen as (n, size)). ``numpy`` runs the generated NumPy
module; ``jax`` its graph module through JAX (:class:`rpr3gen.jax_graph.JaxEvaluator`, the extra
``jax``); ``c`` the generated C, compiled and bound by :mod:`rpr3gen.cbackend`, on every core:
its batch functions are re-entrant and ctypes releases the GIL while they run, so contiguous
chunks of a block run on a pool of threads (:data:`threads`). Neither knows any function in
particular: both read the manifest.
"""

from __future__ import annotations

import itertools
import os
import threading
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Protocol

import numpy as np

from rpr3gen import composed, failures
from rpr3gen.buffers import OUTPUTS
from rpr3gen.errors import InputError
from rpr3gen.loader import numpy_module
from rpr3gen.manifest import FunctionInfo, Variant

__all__ = [
    "BACKENDS",
    "CEvaluator",
    "Evaluator",
    "NumpyEvaluator",
    "all_cores",
    "evaluator",
    "numpy_module",
    "thread_count",
]

BACKENDS: tuple[str, ...] = ("numpy", "c", "jax")


def all_cores() -> int:
    """The cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def thread_count(threads: int | None) -> int:
    """``threads``, checked, or every core for None."""
    if threads is None:
        return all_cores()
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise InputError(f"threads must be a positive integer, got {threads!r}")
    return threads


_POOL: tuple[ThreadPoolExecutor, int] | None = None  # the pool and its size
_POOL_LOCK = threading.Lock()


def _pool(workers: int) -> ThreadPoolExecutor:
    """A shared pool of at least ``workers`` threads (made once, grown on demand)."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None or _POOL[1] < workers:
            _POOL = (ThreadPoolExecutor(max_workers=workers, thread_name_prefix="rpr3gen"), workers)
        return _POOL[0]


class Evaluator(Protocol):
    """Evaluates the functions of one generated variant.

    ``applies_checks``: the backend applies the failure conditions itself (the generated C
    does, writing NaN rows; see :func:`rpr3gen.failures.return_codes`).
    """

    variant: Variant
    applies_checks: bool
    block: int  # samples per call of run() from rpr3gen.evaluate (bounds temporaries, progress)

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        """Uninitialised outputs for n samples, each seen as (n, size); a large one reuses the
        memory of outputs their callers dropped (:mod:`rpr3gen.buffers`)."""
        ...

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
        threads: int = 1,
    ) -> int | None:
        """Evaluate n samples: ``inputs`` (n, size) C-contiguous float64, ``outputs`` rows of
        arrays from :meth:`allocate`, on up to ``threads`` threads. Failed samples hold inf or
        NaN (see :mod:`rpr3gen.failures`). Returns how many failed, when the backend knows."""
        ...


class NumpyEvaluator:
    """The generated NumPy code; outputs are stored (size, n), so each output row is contiguous.

    One thread: ``threads`` is accepted and ignored. The generated functions' scratch rows
    (``work``) are one array per thread, kept between calls: fresh ones would cost mapping and
    zeroing new pages at every block. :meth:`run` returns 0 when no sample failed, as the
    generated function's sums of its output rows and one reduction of each other array tested
    tell (:func:`rpr3gen.failures.none_failed`), else None: unknown, the per-sample checks
    decide (``rpr3gen.failures.apply``).
    """

    applies_checks = False
    #: The generated code's temporaries of one block stay in cache, and its ~650 ufunc calls'
    #: fixed cost is spread over enough samples (benchmarks/ measures it).
    block = 12288

    def __init__(self, variant: Variant) -> None:
        self.variant = variant
        self.module = numpy_module(variant)
        self._scratch = threading.local()

    def _work(self, rows: int, n: int) -> np.ndarray | None:
        """This thread's scratch array, at least ``rows`` x ``n`` (grown on demand)."""
        if not rows:
            return None
        work = getattr(self._scratch, "work", None)
        if work is None or work.shape[0] < rows or work.shape[1] < n:
            shape = (rows, n) if work is None else (max(rows, work.shape[0]), max(n, work.shape[1]))
            work = self._scratch.work = np.empty(shape)
        return work

    def _sums(self, rows: int) -> np.ndarray:
        """This thread's array of output-row sums, at least ``rows`` long."""
        sums = getattr(self._scratch, "sums", None)
        if sums is None or sums.shape[0] < rows:
            sums = self._scratch.sums = np.empty(rows)
        return sums

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        return [OUTPUTS.empty(o.size * n).reshape(o.size, n).T for o in function.outputs]

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
        threads: int = 1,
    ) -> int | None:
        if function.numpy_function is None and composed.composable(self.variant, function):
            composed.run(self.variant, function, params, inputs, outputs, self._generated)
            return None
        if function.numpy_function is None:
            raise InputError(
                f"{function.name} has no NumPy version (its generated code is C only); "
                "use backend='c'"
            )
        call = getattr(self.module, function.numpy_function)
        rows = getattr(self.module, "WORK_ROWS", {}).get(function.numpy_function)
        if rows is None:  # generated before the work argument
            call(params, *inputs, *(o.T for o in outputs))
            return None
        work = self._work(rows, inputs[0].shape[0])
        count = getattr(self.module, "OUTPUT_ROWS", {}).get(function.numpy_function)
        if count is None:  # generated before the sums argument
            call(params, *inputs, *(o.T for o in outputs), work=work)
            return None
        sums = self._sums(count)
        call(params, *inputs, *(o.T for o in outputs), work=work, sums=sums)
        return 0 if failures.none_failed(function, inputs, outputs, sums[:count]) else None

    def _generated(
        self, name: str, params: np.ndarray, inputs: Sequence[np.ndarray]
    ) -> list[np.ndarray]:
        """The generated NumPy function ``name`` on ``inputs``: its public outputs, (n, size)
        each, failed samples NaN (for the compositions of :mod:`rpr3gen.composed`)."""
        function = self.variant.function(name)
        outputs = self.allocate(function, inputs[0].shape[0])
        if self.run(function, params, inputs, outputs) != 0:
            failures.apply(function, inputs, outputs)
        return [o for o, info in zip(outputs, function.outputs, strict=True) if not info.hidden]


class CEvaluator:
    """The generated C, through its batch functions; outputs are row-major (n, size).

    A block of at least 2 :data:`MIN_CHUNK` samples is split into contiguous chunks, one per
    thread; each sample's result does not depend on the split (the generated batch evaluates
    every sample alone), so every thread count gives the same bits. Hidden outputs (the values
    the checks test) stay inside the C: they are allocated, NaN.
    """

    applies_checks = True
    #: The batch keeps no temporaries between samples: blocks only pace the progress bar.
    block = 1 << 18
    #: Fewest samples a thread gets: below, starting it costs more than it saves.
    MIN_CHUNK = 4096

    def __init__(self, variant: Variant) -> None:
        from rpr3gen import cbackend

        self.variant = variant
        self.library = cbackend.library(variant)

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        outputs = [OUTPUTS.empty(n * o.size).reshape(n, o.size) for o in function.outputs]
        for out, o in zip(outputs, function.outputs, strict=True):
            if o.hidden:
                out.fill(np.nan)
        return outputs

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
        threads: int = 1,
    ) -> int:
        public = [o for o, info in zip(outputs, function.outputs, strict=True) if not info.hidden]
        for out in public:
            if not out.flags.c_contiguous:
                raise InputError("outputs of the c backend must be C-contiguous (n, size) arrays")
        batch = self.library.entries[function.name].batch
        arrays = [*inputs, *public]
        n = inputs[0].shape[0]
        chunks = max(1, min(threads, n // self.MIN_CHUNK))
        bounds = [n * k // chunks for k in range(chunks + 1)]

        def part(lo: int, hi: int) -> int:  # ctypes releases the GIL for the call
            return int(
                batch(
                    params.ctypes.data,
                    hi - lo,
                    *(a.ctypes.data + lo * a.strides[0] for a in arrays),
                )
            )

        if chunks == 1:
            return part(0, n)
        pool = _pool(chunks)
        return sum(
            f.result() for f in [pool.submit(part, lo, hi) for lo, hi in itertools.pairwise(bounds)]
        )


_EVALUATORS: dict[tuple[str, str], Evaluator] = {}


def evaluator(variant: Variant, backend: str) -> Evaluator:
    """The evaluator of ``variant`` for ``backend`` (``"numpy"``, ``"c"`` or ``"jax"``), made
    once."""
    key = (str(variant.folder), backend)
    found = _EVALUATORS.get(key)
    if found is not None and found.variant.source_hash == variant.source_hash:
        return found
    if backend == "numpy":
        made: Evaluator = NumpyEvaluator(variant)
    elif backend == "c":
        made = CEvaluator(variant)
    elif backend == "jax":
        from rpr3gen.jax_graph import JaxEvaluator  # imports JAX on first use (the extra "jax")

        made = JaxEvaluator(variant)
    else:
        raise InputError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")
    _EVALUATORS[key] = made
    return made
