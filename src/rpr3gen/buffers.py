"""Output memory reused: the pages of a large result, once its caller has dropped it.

``numpy.empty`` of a large array maps fresh pages, and the operating system zeroes each page at
its first write: for the inverse dynamics' 424 bytes of outputs a sample, 35-47 ns a sample on
the benchmark machine, a tenth of the NumPy evaluation and a third of the C batch's
(docs/performance-log.md). A caller that evaluates again after dropping its last result (a loop
over trajectories, identification's iterations, a sweep's chunks) can have the same pages back,
already mapped.

:data:`OUTPUTS` keeps the last few large buffers the evaluators handed out, and hands one out
again only when nothing but the pool refers to it. Every NumPy array that views a buffer,
however derived (a transpose, a slice, a reshape), refers to it through its ``base``, and so
does anything that wraps such an array (a pandas or Arrow column made without a copy): memory a
caller can still reach is never handed out twice. What the pool keeps is bounded
(:data:`MOST_BYTES`, and an eighth of :func:`rpr3gen.sizes.memory_limit`); :func:`release` gives
the free buffers back to the system.
"""

from __future__ import annotations

import sys
import threading

import numpy as np

from rpr3gen.errors import Rpr3genError
from rpr3gen.sizes import memory_limit

__all__ = ["LEAST_BYTES", "MOST_BYTES", "OUTPUTS", "BufferPool", "release"]

LEAST_BYTES = 1 << 20
"""Smaller buffers are not kept: the C allocator reuses their memory already."""
MOST_BYTES = 1 << 30
"""The most the pool keeps, all its buffers together (also at most an eighth of the memory
limit, ``RPR3GEN_MAX_MEMORY``)."""


class BufferPool:
    """Float64 buffers of the sizes last asked for, reused once their callers drop them.

    ``keep``: the most buffers kept (0: none, every :meth:`empty` is ``numpy.empty``);
    ``least``, ``most``: bytes, the smallest buffer kept and the most kept in all. Thread-safe.
    """

    def __init__(self, keep: int = 4, least: int = LEAST_BYTES, most: int = MOST_BYTES) -> None:
        self.keep, self.least, self.most = keep, least, most
        self._buffers: list[np.ndarray] = []  # least recently handed out first
        self._lock = threading.Lock()

    def empty(self, count: int) -> np.ndarray:
        """An array of ``count`` float64 values, its contents undefined: a kept buffer of that
        size that nothing else refers to, else a new one (kept when there is room)."""
        nbytes = 8 * count
        most = self._most()
        if self.keep <= 0 or not self.least <= nbytes <= most:
            return np.empty(count)
        with self._lock:
            free = [k for k in range(len(self._buffers)) if self._free(k)]
            for k in free:
                if self._buffers[k].size == count:
                    buffer = self._buffers.pop(k)
                    self._buffers.append(buffer)
                    return buffer
            buffer = np.empty(count)

            def room() -> bool:
                return len(self._buffers) < self.keep and self.kept_bytes() + nbytes <= most

            for dropped, k in enumerate(free):  # the least recently handed out first
                if room():
                    break
                del self._buffers[k - dropped]
            if room():
                self._buffers.append(buffer)
            return buffer

    def kept_bytes(self) -> int:
        """The bytes of every buffer kept, free or held."""
        return sum(b.nbytes for b in self._buffers)

    def release(self) -> None:
        """Drop the kept buffers that no caller holds: their memory goes back to the system."""
        with self._lock:
            held = [not self._free(k) for k in range(len(self._buffers))]
            self._buffers = [b for b, h in zip(self._buffers, held, strict=True) if h]

    def _free(self, k: int) -> bool:
        # The list's reference and getrefcount's own argument: nothing else refers to it.
        return sys.getrefcount(self._buffers[k]) <= 2

    def _most(self) -> int:
        try:
            return min(self.most, memory_limit() // 8)
        except Rpr3genError:  # a malformed RPR3GEN_MAX_MEMORY: the size checks report it
            return 0


OUTPUTS = BufferPool()
"""The pool of the evaluators' outputs (``rpr3gen.evaluate`` and what calls it)."""


def release() -> None:
    """Give back the memory of the outputs kept for reuse that no caller holds any more."""
    OUTPUTS.release()
