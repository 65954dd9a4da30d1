"""Shared fixtures and session set-up: paths of the source tree, one cache of derived variants
and C builds per session, the long tests first.

The suite runs on every core (``-n auto --dist worksteal``, pytest-xdist, in
``pyproject.toml``). Its workers
share one cache of derived variants and C builds, a fresh folder per session unless
``RPR3GEN_CACHE_DIR`` is set (then that folder, and it is kept): each structure is derived and
each variant compiled once per session, by whichever worker needs it first, while the others
wait on the cache's lock. A fresh folder makes the suite's time the same on every run, and
leaves the user's own cache alone.
"""

from __future__ import annotations

import os
import shutil
import tempfile
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
