"""A sweep whose first chunks finish and whose others block: Ctrl-C tested without a clock.

``tests/test_hostile_interrupt.py`` runs ``rpr3gen sweep`` in a subprocess through
:func:`run_command`. On the workers (which import this module by name, from ``PYTHONPATH``),
:func:`chunk_or_block` evaluates the chunks below :data:`FINISHED` and blocks in the others,
after saying so on stderr, until the worker closes (this module is also the workers' preload:
:func:`dask_teardown`); in the command's process each part file written is said on stderr
too. The test reads those lines, so it knows, without waiting on a clock, that the finished
chunks are written and a worker is busy when it sends Ctrl-C.
"""

from __future__ import annotations

import sys
import threading
from typing import Any

FINISHED = 2
"""Chunks that finish; every later one blocks."""

BLOCKED = "hostile-test: blocking in chunk"
WROTE = "hostile-test: wrote"
PRELOAD = {"DASK_DISTRIBUTED__WORKER__PRELOAD": '["hostile_sweep_tasks"]'}
"""The environment that makes the workers preload this module (for :func:`dask_teardown`)."""

_CLOSING = threading.Event()


def dask_teardown(worker: Any) -> None:
    """Dask calls this as the worker closes, before it waits for its running task."""
    _CLOSING.set()


def chunk_or_block(plan: Any, index: int) -> Any:
    """The real chunk below :data:`FINISHED`; else say so on stderr and block until the worker
    closes (then an empty result, which nobody reads: the sweep was interrupted)."""
    from rpr3gen.design.metrics import evaluate_chunk

    if index < FINISHED:
        return evaluate_chunk(plan, index)
    print(f"{BLOCKED} {index}", file=sys.stderr, flush=True)
    _CLOSING.wait()
    return index, {}


def run_command(argv: list[str]) -> int:
    """``rpr3gen`` with the sweep's tasks replaced and each part file reported."""
    import faulthandler
    import signal

    from rpr3gen.cli import main
    from rpr3gen.design import parquet, sweeps

    faulthandler.register(signal.SIGUSR1, all_threads=True)  # the test's view of a hang
    # A command started from a terminal has SIGINT's default action; one started by a
    # non-interactive shell in the background (``pytest ... &``) inherits it ignored, and Python
    # then leaves it ignored. The test sends a terminal's Ctrl-C: make it one that can be heard.
    signal.signal(signal.SIGINT, signal.default_int_handler)

    write_table = parquet.write_table

    def reporting(path: Any, table: Any) -> None:
        write_table(path, table)
        print(f"{WROTE} {path}", file=sys.stderr, flush=True)

    parquet.write_table = reporting
    sweeps.evaluate_chunk = chunk_or_block
    return main(argv)
