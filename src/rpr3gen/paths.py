"""Output paths, checked before any work: the real reason a file or folder cannot be written.

Every output of the commands and of the Python API (``--out``, ``--plots``, ``sweep(out=)``,
``write_workspace(wmap, outdir)``) goes through :func:`check_output` first, so that a path that
cannot be written is refused in one line naming it, before hours of work, and not reported as
whatever the operating system says later ("File exists" for a folder below a regular file).
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path
from typing import NoReturn

from rpr3gen.errors import InputError
from rpr3gen.validation import PathArg

__all__ = ["check_output"]

_TEMPORARY_EXTRA = 14  # bytes that rpr3gen.atomic's temporary name adds to a file's name


def check_output(
    path: str | os.PathLike[str],
    what: str,
    *,
    folder: bool = False,
    argument: str | None = None,
) -> Path:
    """Refuse an output path that cannot be written, with the reason; folders missing on the
    way are fine (they are created later).

    Args:
        path: the file (``folder=False``) or the folder to write.
        what: what is written there, for the message (``"the CSV"``).
        folder: ``path`` is a folder to create or fill.
        argument: the argument (or option) that gave it.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        InputTypeError: ``path`` is not a path.
        InputError: ``path: cannot write <what>: <reason>``: it is a folder (a file was asked
            for), a file (a folder was asked for), not a regular file (a device, a pipe), below
            a regular file, or in a folder where no file can be created (permissions, a
            read-only or special file system), or the name is not valid there.
    """
    target = Path(PathArg()(argument or "path", path))

    def fail(reason: str) -> NoReturn:
        raise InputError(f"{target}: cannot write {what}: {reason}", argument=argument)

    try:
        mode = target.stat().st_mode if os.path.lexists(target) else None
        if mode is not None and not folder:
            if stat.S_ISDIR(mode):
                fail("it is a folder")
            if not stat.S_ISREG(mode):
                fail("it is not a regular file (a device, a pipe or a socket)")
        existing = _nearest_existing(target if folder else target.parent)
    except OSError as exc:  # a name too long, a loop of links, a folder that cannot be searched
        fail(exc.strerror or str(exc))
    if existing is None:
        fail("no folder of it exists")
    if not existing.is_dir():
        it = "it" if existing == target else str(existing)
        fail(f"{it} is a file, not a folder")
    reason = _cannot_create_in(existing)
    if reason:
        fail(f"cannot create a file in {existing}: {reason}")
    longest = _name_max(existing)
    for part in (target, *target.parents):
        if part == existing:
            break
        # The file itself is first written as ".NAME.XXXXXXXX.tmp" (rpr3gen.atomic).
        most = longest - (0 if folder or part != target else _TEMPORARY_EXTRA)
        if len(os.fsencode(part.name)) > most:
            fail(f"the name {part.name[:20]}... is longer than {most} bytes")
    return target


def _name_max(folder: Path) -> int:
    """The longest file name (bytes) the file system of ``folder`` takes (255 if unknown)."""
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        return 255


def _nearest_existing(path: Path) -> Path | None:
    """``path`` or its nearest ancestor that exists."""
    for part in (path, *path.parents):
        if os.path.lexists(part):
            return part
    return None


def _cannot_create_in(folder: Path) -> str:
    """Why no file can be created in ``folder`` ("" when one can): a file is made and removed,
    which asks the file system itself (permissions, read-only mounts, /proc)."""
    try:
        fd, name = tempfile.mkstemp(prefix=".rpr3gen-", suffix=".probe", dir=folder)
    except OSError as exc:
        return exc.strerror or str(exc)
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(name)
    return ""
