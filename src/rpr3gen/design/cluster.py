"""Running a sweep's chunks: in this process, on a local Dask cluster, or on a scheduler.

Each chunk is one task; results come back to this process as they finish, in any order, and a
progress bar (tqdm, on stderr when it is a terminal) counts the designs done. Dask's own
``progress`` does not fit: in a terminal it blocks until every task is done and writes to
stdout, and this loop must write each chunk as it arrives.
"""

from __future__ import annotations

import logging
import os
import sys
import uuid
from collections.abc import Callable, Iterable
from typing import Any

from rpr3gen.design.metrics import SweepPlan
from rpr3gen.errors import Rpr3genError

__all__ = ["MALLOC_TRIM", "ClusterClient", "run_chunks", "task_result"]

Columns = dict[str, Any]

#: Dask's setting that makes its worker processes return freed memory to the system beyond 64 KiB
#: (``MALLOC_TRIM_THRESHOLD_``). With it, glibc maps and unmaps every large NumPy temporary of
#: the generated code, and the page faults halve a sweep's speed; the local cluster's workers
#: run without it (glibc's default: freed memory is reused). See README, "On a cluster".
MALLOC_TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"


def run_chunks(
    plan: SweepPlan,
    chunks: Iterable[int],
    task: Callable[[SweepPlan, int], tuple[int, Columns]],
    done: Callable[[int, Columns], None],
    scheduler: str | None,
    workers: int | None,
    progress: bool,
    initial: int = 0,
) -> None:
    """Run ``task(plan, index)`` for each of ``chunks`` (:func:`.metrics.evaluate_chunk`),
    calling ``done(index, columns)`` with each result as it arrives.

    In this process when ``workers == 0``; else on the Dask scheduler at ``scheduler``, or on a
    local cluster of ``workers`` processes (None: one per core) started and stopped here.
    """
    todo = list(chunks)
    with _ProgressBar(len(plan.grid), initial, progress) as bar:
        if workers == 0 and scheduler is None:
            for index in todo:
                done(*task(plan, index))
                bar.update(len(plan.chunk(index)))
            return
        if not todo:
            return
        with ClusterClient(scheduler, workers) as client:
            from distributed import as_completed

            shared = client.scatter(plan, broadcast=True, hash=False)
            run = uuid.uuid4().hex[:12]  # task names unique on a shared scheduler
            futures = [
                client.submit(task, shared, index, key=f"rpr3gen-sweep-{run}-{index}")
                for index in todo
            ]
            try:
                for future in as_completed(futures):
                    index, columns = task_result(future)
                    done(index, columns)
                    bar.update(len(plan.chunk(index)))
                    future.release()
            finally:
                client.cancel(futures)


def task_result(future: Any) -> tuple[int, Columns]:
    """A task's result; its failure (a lost worker, rpr3gen missing there...) as one line."""
    try:
        result: tuple[int, Columns] = future.result()
    except Rpr3genError:
        raise
    except Exception as exc:
        raise Rpr3genError(
            f"a sweep task failed on the Dask cluster: {type(exc).__name__}: {exc}"
        ) from exc
    return result


class ClusterClient:
    """A Dask client of the scheduler at ``address``, or of a local cluster made for the run."""

    def __init__(self, address: str | None, workers: int | None) -> None:
        self.address = address
        self.workers = workers
        self.cluster: Any = None
        self.client: Any = None

    def __enter__(self) -> Any:
        import dask
        from distributed import Client, LocalCluster

        if self.address is not None:
            try:
                self.client = Client(self.address, timeout="30s")
            except (OSError, TimeoutError, ValueError) as exc:
                raise Rpr3genError(f"scheduler {self.address}: cannot connect: {exc}") from None
            return self.client
        n = self.workers or len(os.sched_getaffinity(0))
        with dask.config.set({MALLOC_TRIM: None}):
            self.cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                # No dashboard, and its health routes on a free port, not on 8787: that one may
                # be another cluster's (Dask warns, then takes another).
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                silence_logs=logging.ERROR,
            )
        self.client = Client(self.cluster)
        return self.client

    def __exit__(self, *exc: object) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


class _ProgressBar:
    """A tqdm bar of designs on stderr, when asked for and stderr is a terminal."""

    def __init__(self, total: int, initial: int, wanted: bool) -> None:
        self.bar: Any = None
        if wanted and sys.stderr.isatty():
            from tqdm import tqdm

            try:  # a terminal that reports no size (serial consoles, some CI) gets 80 x 24
                size = os.get_terminal_size(sys.stderr.fileno())
            except OSError:
                size = os.terminal_size((0, 0))
            self.bar = tqdm(
                total=total,
                initial=initial,
                unit="design",
                file=sys.stderr,
                leave=False,
                ncols=size.columns or 80,
                nrows=size.lines or 24,
            )

    def __enter__(self) -> _ProgressBar:
        return self

    def update(self, n: int) -> None:
        if self.bar is not None:
            self.bar.update(n)

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.close()
