"""Shared fixtures and session set-up: paths of the source tree, one cache of derived variants
and C builds per session, the long tests first, a real Dask cluster for the sweeps.

The suite runs on every core (``-n auto --dist worksteal``, pytest-xdist, in
``pyproject.toml``). Its workers
share one cache of derived variants and C builds, a fresh folder per session unless
``RPR3GEN_CACHE_DIR`` is set (then that folder, and it is kept): each structure is derived and
each variant compiled once per session, by whichever worker needs it first, while the others
wait on the cache's lock. A fresh folder makes the suite's time the same on every run, and
leaves the user's own cache alone.

The C libraries are quick builds (``RPR3GEN_C_BUILD=quick``, -O1: the same values bit for bit
as the optimised ones, ``tests/test_c_build_modes.py``), with no optimised build left running in
the background, unless ``RPR3GEN_C_BUILD`` is set; the tests of what the optimised flags do
ask for them (:func:`optimised_c_builds`).
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
_CACHE_KEY = pytest.StashKey[str]()


def pytest_configure(config: pytest.Config) -> None:
    # xdist's workers start after this runs in the controller, and inherit its environment.
    if "RPR3GEN_CACHE_DIR" not in os.environ:
        folder = tempfile.mkdtemp(prefix="rpr3gen-test-cache-")
        os.environ["RPR3GEN_CACHE_DIR"] = folder
        config.stash[_CACHE_KEY] = folder
    os.environ.setdefault("RPR3GEN_C_BUILD", "quick")


def pytest_unconfigure(config: pytest.Config) -> None:
    folder = config.stash.get(_CACHE_KEY, None)
    if folder is not None:
        os.environ.pop("RPR3GEN_CACHE_DIR", None)
        shutil.rmtree(folder, ignore_errors=True)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The tests marked ``slow`` first (stable: otherwise in collection order), so that on
    several workers none of the long ones is left to end the run on one worker."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT


@pytest.fixture
def quick_c_builds(monkeypatch: pytest.MonkeyPatch) -> None:
    """The c backend builds at -O0 in this test (half a second instead of seven): for tests of
    the build cache or of a temporary generated folder, which need a library, not a fast one.
    The flags are part of the cache key, so no other test meets these libraries."""
    from rpr3gen import cbackend

    flags = tuple("-O0" if f == "-O3" else f for f in cbackend.CFLAGS)
    assert flags != cbackend.CFLAGS
    monkeypatch.setattr(cbackend, "CFLAGS", flags)


@pytest.fixture
def optimised_c_builds(monkeypatch: pytest.MonkeyPatch) -> None:
    """The c backend builds with the runtime's optimised flags in this test, and waits for them
    (``RPR3GEN_C_BUILD=optimised``): for the tests of what those flags do (gcc's vectorisers).
    The libraries and evaluators this process loaded before (quick builds) are set aside."""
    from rpr3gen import cbackend, evaluators

    monkeypatch.setenv("RPR3GEN_C_BUILD", "optimised")
    monkeypatch.setattr(cbackend, "_LIBRARIES", {})
    monkeypatch.setattr(evaluators, "_EVALUATORS", {})


# -- a Dask cluster ------------------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="session")
def stopping() -> Iterator[list[subprocess.Popen[bytes]]]:
    """Processes told to stop, waited for at the end of the session: a ``dask worker`` takes
    seconds to exit after its nanny has closed it, time the other tests can use meanwhile."""
    procs: list[subprocess.Popen[bytes]] = []
    yield procs
    for proc in procs:
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.fixture(scope="session")
def scheduler(
    tmp_path_factory: pytest.TempPathFactory, stopping: list[subprocess.Popen[bytes]]
) -> Iterator[str]:
    """A ``dask scheduler`` and two ``dask worker`` processes on localhost, for the session's
    sweep tests (``tests/test_design_sweep.py``, ``tests/test_spatial_sweep.py``); their
    address. The test waits for them by asking the scheduler, never by sleeping."""
    from distributed import Client

    logs = tmp_path_factory.mktemp("dask")
    address = f"tcp://127.0.0.1:{_free_port()}"
    dask = [sys.executable, "-m", "dask"]
    commands = [
        [*dask, "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
         "--no-dashboard", "--dashboard-address", "127.0.0.1:0"],
        *([*dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
           "--name", f"worker-{k}", "--local-directory", str(logs)] for k in range(2)),
    ]  # fmt: skip
    procs = []
    try:
        for k, command in enumerate(commands):
            with (logs / f"process-{k}.log").open("wb") as log:
                procs.append(subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT))
        with Client(address, timeout="120s") as client:
            client.wait_for_workers(2, timeout=120)
            assert len(client.scheduler_info()["workers"]) == 2
        yield address
    finally:
        for proc in reversed(procs):
            proc.terminate()
        stopping.extend(reversed(procs))
