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


#: The index of a generated tree (``rpr3gen generate`` writes it beside the variants): every
#: file's SHA-256 and the key of the render that made them (:func:`render_key`), so that
#: ``rpr3gen generate --check`` can tell an unchanged tree without rendering it again.
CHECKSUMS = "checksums.json"


def render_key(digest: str) -> str:
    """What a render's bytes depend on: the generator's sources (``digest``), the installed
    SymPy and Jinja2 (pinned by the ``derive`` extra) and Python's version. Two renders of the
    same key give the same bytes (regeneration is deterministic, whatever the hash seed)."""
    import sys

    import jinja2
    import sympy

    text = (
        f"{digest}\0sympy {sympy.__version__}\0jinja2 {jinja2.__version__}\0"
        f"python {sys.version_info[0]}.{sys.version_info[1]}"
    )
    return hashlib.sha256(text.encode()).hexdigest()


def checksums(files: dict[str, str], key: str) -> str:
    """The text of :data:`CHECKSUMS` for the rendered ``files`` (``{relative path: text}``)."""
    import json

    data = {
        "generated": "by rpr3gen generate: do not edit",
        "render_key": key,
        "files": {
            rel: hashlib.sha256(text.encode()).hexdigest() for rel, text in sorted(files.items())
        },
    }
    return json.dumps(data, indent=1) + "\n"


def quick_stale(out_dir: Path, key: str) -> list[str] | None:
    """The files of ``out_dir`` that differ from what its :data:`CHECKSUMS` records (edited by
    hand, or missing), when that index is of the render key ``key``; None when there is no
    index or it is of another key (another generator, SymPy, Jinja2 or Python: only a render
    tells then)."""
    import json

    try:
        data = json.loads((out_dir / CHECKSUMS).read_text(encoding="utf-8"))
        recorded = dict(data["files"])
        if data["render_key"] != key or not recorded:
            return None
    except (OSError, ValueError, KeyError, TypeError):
        return None
    stale = []
    for rel, digest in sorted(recorded.items()):
        path = out_dir / rel
        if not path.is_file() or hashlib.sha256(path.read_bytes()).hexdigest() != digest:
            stale.append(rel)
    return stale
