"""The output memory pool (rpr3gen.buffers): a buffer is handed out again only when nothing
else refers to it, what it keeps is bounded, and ``evaluate`` gives the same bits whether its
outputs' memory is new or reused."""

from __future__ import annotations

import threading

import newton_euler as ne
import numpy as np
import pytest

import rpr3gen
from rpr3gen import buffers, evaluators
from rpr3gen.buffers import BufferPool

N = 1000  # values of a test buffer: 8,000 bytes
SMALL = 1024  # bytes: the least a test pool keeps


def address(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


def test_a_dropped_buffer_is_handed_out_again() -> None:
    pool = BufferPool(keep=2, least=SMALL)
    first = pool.empty(N)
    where = address(first)
    del first
    again = pool.empty(N)
    assert address(again) == where
    assert pool.empty(N).size == N  # another one while `again` is held: a new buffer
    assert address(pool.empty(N + 1)) != where  # another size: a new buffer


VIEWS = {
    "the buffer": lambda a: a,
    "a transposed reshape": lambda a: a.reshape(10, N // 10).T,
    "a column of it": lambda a: a.reshape(10, N // 10).T[:, 3],
    "a memoryview": memoryview,
    "an array over a memoryview": lambda a: np.frombuffer(memoryview(a)),
    "a dict of rows": lambda a: dict(enumerate(a.reshape(10, N // 10))),
}


@pytest.mark.parametrize("view", VIEWS.values(), ids=list(VIEWS))
def test_memory_still_reachable_is_never_handed_out_twice(view) -> None:
    pool = BufferPool(keep=4, least=SMALL)
    buffer = pool.empty(N)
    buffer[:] = 7.0
    held = view(buffer)
    where = address(buffer)
    del buffer
    for _ in range(4):
        other = pool.empty(N)
        assert address(other) != where
        other[:] = -1.0
    if isinstance(held, dict):
        values = np.concatenate(list(held.values()))
    else:
        values = np.frombuffer(held) if isinstance(held, memoryview) else held
    assert np.all(values == 7.0)
    del held, values
    assert address(pool.empty(N)) == where  # and once dropped, it is


def test_it_keeps_at_most_keep_buffers_and_most_bytes() -> None:
    pool = BufferPool(keep=2, least=SMALL)
    held = [pool.empty(N) for _ in range(5)]
    assert pool.kept_bytes() == 2 * 8 * N
    del held
    capped = BufferPool(keep=8, least=SMALL, most=3 * 8 * N)
    held = [capped.empty(N) for _ in range(5)]
    assert capped.kept_bytes() == 3 * 8 * N
    first = address(held[0])
    del held
    kept = capped.empty(2 * N)  # room made by dropping free buffers, the least recent first
    assert capped.kept_bytes() == 3 * 8 * N
    del kept
    assert address(capped.empty(N)) != first  # the first was dropped, the third kept


def test_small_buffers_large_ones_and_keep_zero_are_not_kept() -> None:
    pool = BufferPool(keep=2, least=SMALL, most=8 * 8 * N)
    for count in (SMALL // 8 - 1, 8 * N + 1):
        pool.empty(count)
        assert pool.kept_bytes() == 0
    off = BufferPool(keep=0, least=SMALL)
    off.empty(N)
    assert off.kept_bytes() == 0


def test_release_drops_only_the_free_buffers() -> None:
    pool = BufferPool(keep=4, least=SMALL)
    held = pool.empty(N)
    pool.empty(2 * N)
    assert pool.kept_bytes() == 3 * 8 * N
    pool.release()
    assert pool.kept_bytes() == 8 * N
    held[:] = 1.0
    assert address(pool.empty(N)) != address(held)


def test_threads_never_share_a_buffer() -> None:
    pool = BufferPool(keep=2, least=SMALL)
    wrong = []

    def work(mark: float) -> None:
        for _ in range(300):
            buffer = pool.empty(N)
            buffer[:] = mark
            if not np.all(buffer == mark):
                wrong.append(mark)

    threads = [threading.Thread(target=work, args=(float(k),)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not wrong


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_evaluate_gives_the_same_bits_in_reused_memory_and_never_overwrites_a_held_result(
    backend: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    model = rpr3gen.load_model()
    t = np.linspace(0.0, 3.0, 4000)  # 53 outputs x 8 bytes x 4,000: 1.7 MB, kept
    first = ne.sinusoid_motion(np.random.default_rng(1), t)
    second = ne.sinusoid_motion(np.random.default_rng(2), t)
    monkeypatch.setattr(buffers, "OUTPUTS", BufferPool(keep=4))
    monkeypatch.setattr(evaluators, "OUTPUTS", buffers.OUTPUTS)

    def run(motion):
        (out,), codes = rpr3gen.evaluate(model, "inverse_dynamics", motion, backend=backend)
        return out, codes

    held, held_codes = run(first)
    copy = held.copy()
    other, _ = run(second)
    assert not np.shares_memory(held, other)
    assert np.array_equal(held, copy, equal_nan=True)
    where = address(np.asarray(held.base))
    del held, other
    again, codes = run(first)
    assert address(np.asarray(again.base)) == where  # the dropped result's memory, reused
    assert np.array_equal(again, copy, equal_nan=True)
    assert np.array_equal(codes, held_codes)
    buffers.OUTPUTS.keep = 0
    fresh, fresh_codes = run(first)
    assert np.array_equal(fresh, again, equal_nan=True)
    assert np.array_equal(fresh_codes, codes)
