"""All-or-nothing file output: a file is either fully written or left as it was.

Outputs are written to a temporary file next to the target, flushed to disk and then moved over
the target with :func:`os.replace`, which is atomic on POSIX and Windows. If anything fails in
between, including a ``KeyboardInterrupt``, the temporary file is removed and an existing target
is untouched, so a failed run never leaves a partial output file behind.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from typing import IO, Any

import numpy as np

from rpr3gen.errors import InputError, Rpr3genError

__all__ = ["atomic_path", "atomic_write", "write_csv_table", "write_results_csv"]

_WRITE_MODES = frozenset({"w", "wt", "wb", "tw", "bw"})


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], mode: str = "w", **kw: Any) -> Iterator[IO[Any]]:
    """Open a temporary file for writing that replaces ``path`` when the block succeeds.

    The temporary file lives in the target's folder (so the final rename cannot cross file
    systems) and is fsynced before the rename. An existing target keeps its permission bits;
    a new one gets the usual ``0o666 & ~umask``.

    Args:
        path: The file to create or replace. Its folder must exist.
        mode: ``"w"`` (text) or ``"wb"`` (binary).
        **kw: Passed to :func:`open` (e.g. ``newline``); text mode defaults to UTF-8.

    Yields:
        The open temporary file.

    Raises:
        InputError: For a mode other than a plain write mode.
        OSError: If the temporary file cannot be created, written or renamed; its
            ``filename`` is ``path`` as given, never the temporary file's name.
    """
    if mode not in _WRITE_MODES:
        raise InputError(f"atomic_write: mode must be 'w' or 'wb', got {mode!r}")
    if "b" not in mode:
        kw.setdefault("encoding", "utf-8")
    target = os.path.abspath(os.fspath(path))
    folder, name = os.path.split(target)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise _about(exc, path) from exc
    try:
        f = os.fdopen(fd, mode, **kw)
    except BaseException:
        with contextlib.suppress(OSError):
            os.close(fd)  # open() may already have closed it
        os.unlink(tmp)
        raise
    with _replacing(tmp, target, path), f:
        yield f
        f.flush()
        os.fsync(f.fileno())


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[str]:
    """A temporary file's path that replaces ``path`` when the block succeeds.

    For writers that want a file name rather than an open file (a movie encoder run as a
    subprocess, an image library that picks the format from the suffix): the temporary file
    lives in the target's folder and keeps the target's suffix. On success it gets the
    permission bits :func:`atomic_write` gives and is renamed over ``path``; on any failure,
    including a ``KeyboardInterrupt``, it is removed and an existing target is untouched.

    Raises:
        OSError: If the temporary file cannot be created or renamed; its ``filename`` is
            ``path`` as given.
    """
    target = os.path.abspath(os.fspath(path))
    folder, name = os.path.split(target)
    suffix = os.path.splitext(name)[1]
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=f".tmp{suffix}", dir=folder)
        os.close(fd)
    except OSError as exc:
        raise _about(exc, path) from exc
    with _replacing(tmp, target, path):
        yield tmp


@contextlib.contextmanager
def _replacing(tmp: str, target: str, path: str | os.PathLike[str]) -> Iterator[None]:
    """Rename ``tmp`` over ``target`` (with :func:`atomic_write`'s permission bits, then the
    folder synced) when the block succeeds; on any failure remove it, an ``OSError`` about
    ``tmp`` reported about ``path``."""
    try:
        yield
        os.chmod(tmp, _mode_for(target))
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        # The package's own OSErrors (a SetupError: no compiler...) are not about the file.
        own = isinstance(exc, Rpr3genError)
        if not own and isinstance(exc, OSError) and exc.filename in (None, tmp):
            raise _about(exc, path) from exc
        raise
    _fsync_folder(os.path.dirname(target))


def _about(exc: OSError, path: str | os.PathLike[str]) -> OSError:
    """The same error about the file the caller named, not its temporary file (or no file).

    The errno is kept, so the class is too (``PermissionError``, ``IsADirectoryError`` ...).
    """
    return OSError(exc.errno, f"cannot write: {exc.strerror or exc}", os.fspath(path))


def write_results_csv(
    path: str | os.PathLike[str],
    t: np.ndarray,
    q: np.ndarray,
    outputs: Mapping[str, np.ndarray],
    names: Sequence[str],
    pose: Sequence[str] = ("x", "y", "phi"),
) -> None:
    """Write simulation results as CSV, atomically.

    Columns are ``t``, the ``pose`` (``x,y,phi``) and then ``names`` in the given order; every
    value is written with
    ``%.17g``, which reads back bit-for-bit (``nan`` marks a failed sample).

    Args:
        path: Output file.
        t: Sample times, s, shape ``(n,)``.
        q: Platform pose ``(x, y, phi)``, shape ``(n, 3)``.
        outputs: Output arrays by name, each of shape ``(n,)`` (or a scalar, broadcast).
        names: Which outputs to write, in column order.

    Raises:
        InputError: If a shape is wrong, or a name is missing from ``outputs`` or repeated.
        OSError: If the file cannot be written.
    """
    t = np.asarray(t, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    if t.ndim != 1:
        raise InputError(f"t must have shape (n,), got {t.shape}")
    n = t.size
    if q.shape != (n, len(pose)):
        raise InputError(f"q must have shape ({n}, {len(pose)}), got {q.shape}")
    if len(set(names)) != len(names):
        raise InputError("names must not repeat")
    columns = [t, *(q[:, k] for k in range(len(pose)))]
    for name in names:
        if name not in outputs:
            raise InputError(f"no output named {name!r}")
        value = np.asarray(outputs[name], dtype=np.float64)
        if value.shape not in ((n,), ()):
            raise InputError(f"output {name!r} must have shape ({n},), got {value.shape}")
        columns.append(np.broadcast_to(value, (n,)))
    write_csv_table(path, ["t", *pose, *names], np.column_stack(columns))


def write_csv_table(path: str | os.PathLike[str], header: Sequence[str], table: np.ndarray) -> None:
    """Write a header line and a 2-D float table as CSV, atomically, each value as ``%.17g``.

    Args:
        path: Output file.
        header: Column names, ``len(header) == table.shape[1]``.
        table: Values, shape ``(n, len(header))``.

    Raises:
        InputError: If the table's shape does not match the header.
        OSError: If the file cannot be written.
    """
    table = np.asarray(table, dtype=np.float64)
    if table.ndim != 2 or table.shape[1] != len(header):
        raise InputError(f"table must have shape (n, {len(header)}), got {table.shape}")
    with atomic_write(path, "w", newline="") as f:
        f.write(",".join(header) + "\n")
        for row in table:
            f.write(",".join(f"{x:.17g}" for x in row) + "\n")


def _mode_for(target: str) -> int:
    """Permission bits for the new file: those of the file it replaces, else from the umask."""
    try:
        return os.stat(target).st_mode & 0o7777
    except OSError:
        return 0o666 & ~_umask()


def _umask() -> int:
    # Reading the umask means setting it; /proc avoids that (and its race) where available.
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_folder(folder: str) -> None:
    """Make the rename durable; best effort (not possible on every platform)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
