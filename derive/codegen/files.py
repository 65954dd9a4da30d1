"""Writing and checking generated files, and the hash of the sources they are derived from."""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path


def source_hash(roots: Iterable[Path]) -> str:
    """SHA-256 of every ``*.py`` and ``*.jinja`` file under ``roots``, by relative path and content.

    Line endings are normalised, so a checkout with CRLF endings hashes the same.
    """
    digest = hashlib.sha256()
    for root in roots:
        files = sorted(p for p in root.rglob("*") if p.suffix in (".py", ".jinja") and p.is_file())
        for path in files:
            digest.update(path.relative_to(root).as_posix().encode())
            digest.update(b"\0")
            digest.update(path.read_bytes().replace(b"\r\n", b"\n"))
            digest.update(b"\0")
    return digest.hexdigest()


def stale_files(out_dir: Path, files: dict[str, str]) -> list[str]:
    """Relative paths whose content on disk differs from ``files`` (or that are missing)."""
    stale = []
    for rel, text in files.items():
        path = out_dir / rel
        if not path.is_file() or path.read_bytes() != text.encode():
            stale.append(rel)
    return stale


def write_files(out_dir: Path, files: dict[str, str]) -> list[str]:
    """Write ``files`` under ``out_dir``; return the paths that changed.

    Every file is first written to a temporary file beside its target; only when all are written
    are they renamed into place, so an error leaves the previous sources as they were.
    """
    changed = stale_files(out_dir, files)
    staged: list[tuple[str, Path]] = []
    try:
        for rel in changed:
            target = out_dir / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, name = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as handle:
                handle.write(files[rel])
            staged.append((rel, Path(name)))
        for rel, temporary in staged:
            os.replace(temporary, out_dir / rel)
    except BaseException:
        for _, temporary in staged:
            temporary.unlink(missing_ok=True)
        raise
    return changed
