"""Running a sweep's chunks: in this process, on a local Dask cluster, or on a scheduler.

Each chunk is one task; results come back to this process as they finish, in any order, and a
progress bar (tqdm, on stderr when it is a terminal) counts the designs done. Dask's own
``progress`` does not fit: in a terminal it blocks until every task is done and writes to
stdout, and this loop must write each chunk as it arrives.

**Ctrl-C** (the one interrupt path): a terminal sends SIGINT to every process of the command,
the local cluster's workers too, which would die mid-task with tracebacks. So the workers start
with SIGINT blocked (:func:`_workers_deaf_to_ctrl_c`); only this process sees it. It then keeps
every chunk that has finished (:func:`_keep_finished`), cancels the rest and shuts the cluster
down with Dask's loggers silenced and further Ctrl-C ignored until it is down
(:meth:`ClusterClient.close_quietly`), and raises ``KeyboardInterrupt``.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
import threading
import uuid
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from rpr3gen.design.metrics import SweepPlan
from rpr3gen.errors import Rpr3genError, SetupError

__all__ = ["MALLOC_TRIM", "ClusterClient", "run_chunks", "task_result"]

Columns = dict[str, Any]

#: Dask's setting that makes its worker processes return freed memory to the system beyond 64 KiB
#: (``MALLOC_TRIM_THRESHOLD_``). With it, glibc maps and unmaps every large NumPy temporary of
#: the generated code, and the page faults halve a sweep's speed; the local cluster's workers
#: run without it (glibc's default: freed memory is reused). See docs/design-studies.md, "On a
#: cluster".
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
            kept: set[int] = set()
            try:
                for future in as_completed(futures):
                    index, columns = task_result(future)
                    done(index, columns)
                    kept.add(index)
                    bar.update(len(plan.chunk(index)))
                    future.release()
            except KeyboardInterrupt:
                _keep_finished(futures, todo, kept, done)
                raise
            finally:
                with contextlib.suppress(Exception):
                    client.cancel(futures)


def _keep_finished(
    futures: list[Any], todo: list[int], kept: set[int], done: Callable[[int, Columns], None]
) -> None:
    """On Ctrl-C: hand every chunk whose task had finished, and was not yet kept, to ``done``
    (its result is on the cluster already), so that a resumed sweep finds all of them."""
    for index, future in zip(todo, futures, strict=True):
        if index not in kept and future.status == "finished":
            with contextlib.suppress(Exception):
                done(*future.result(timeout=5))


def task_result(future: Any) -> tuple[int, Columns]:
    """A task's result; its failure (a lost worker, rpr3gen missing there...) as one line."""
    try:
        result: tuple[int, Columns] = future.result()
    except Rpr3genError:
        raise
    except Exception as exc:
        raise SetupError(
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
                raise SetupError(f"scheduler {self.address}: cannot connect: {exc}") from None
            return self.client
        n = self.workers or len(os.sched_getaffinity(0))
        try:
            with dask.config.set({MALLOC_TRIM: None}), _workers_deaf_to_ctrl_c():
                self.cluster = LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    # No dashboard, and its health routes on a free port, not on 8787: that one
                    # may be another cluster's (Dask warns, then takes another).
                    scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                    silence_logs=logging.ERROR,
                )
                self.client = Client(self.cluster)
        except BaseException:  # Ctrl-C while starting, delivered once the workers are up
            self.close_quietly()
            raise
        return self.client

    def __exit__(self, kind: type[BaseException] | None, *exc: object) -> None:
        if kind is not None and issubclass(kind, KeyboardInterrupt):
            self.close_quietly()
            return
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def close_quietly(self) -> None:
        """Shut the client and the local cluster down after a Ctrl-C: Dask's loggers (tasks
        cancelled, connections closed) silenced, a second Ctrl-C ignored until it is done."""
        with _silenced("distributed", "tornado", "asyncio"), _ctrl_c_ignored():
            for closing in (self.client, self.cluster):
                if closing is not None:
                    with contextlib.suppress(Exception):
                        closing.close(timeout=10)


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextlib.contextmanager
def _workers_deaf_to_ctrl_c() -> Iterator[None]:
    """Start processes deaf to SIGINT (a terminal's Ctrl-C reaches every process of the
    command) without losing one meant for this process, nor raising it halfway through.

    SIGINT is blocked in this thread, so in the threads Dask starts meanwhile (its event loop,
    which spawns the workers), so in the workers: a process keeps its parent thread's mask, and
    Python does not unblock it (multiprocessing's resource tracker would, so it is started
    first). A Ctrl-C meanwhile, delivered to a thread that does not block
    it (BLAS's) or pending until the block ends, is only recorded, and raised as
    ``KeyboardInterrupt`` once the block ends, when the cluster is up and can be shut down.
    """
    if not _main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    # Started now, multiprocessing's resource tracker cannot unblock SIGINT later: starting it
    # blocks and then unblocks SIGINT in the thread that spawns, whatever it was before.
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda number, frame: caught.append(number))
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # a pending one raises here
    if caught:
        raise KeyboardInterrupt


@contextlib.contextmanager
def _ctrl_c_ignored() -> Iterator[None]:
    if not _main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextlib.contextmanager
def _silenced(*names: str) -> Iterator[None]:
    loggers = [logging.getLogger(name) for name in names]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)


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
