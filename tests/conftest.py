"""Shared fixtures: paths of the source tree, the cache of generated variants."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def variant_cache() -> Iterator[Path]:
    """The cache of generated variants and compiled C that the session's tests share.

    ``$RPR3GEN_CACHE_DIR`` when it is set (by the environment, or by the session's set-up before
    pytest-xdist starts its workers); else a folder of this user's in the temporary directory,
    set as ``$RPR3GEN_CACHE_DIR`` for the rest of the session. Every worker and every session
    then derives a variant once: its entries are keyed by content hashes of the generator and
    of the C, so nothing stale is ever reused, and the variants' lock makes concurrent first
    uses safe.
    """
    if folder := os.environ.get("RPR3GEN_CACHE_DIR"):
        yield Path(folder)
        return
    path = Path(tempfile.gettempdir()) / f"rpr3gen-test-cache-{os.getuid()}"
    path.mkdir(mode=0o700, exist_ok=True)
    if path.is_symlink() or path.stat().st_uid != os.getuid():  # not ours: a private one
        path = Path(tempfile.mkdtemp(prefix="rpr3gen-test-cache-"))
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RPR3GEN_CACHE_DIR", str(path))
        yield path
