"""The waypoints of a path to retime: an array of poses or a path CSV file, checked, each row with
a name for messages.

A path CSV file has a header naming the pose's columns (``x,y,phi`` for a planar robot, the
spatial pose's ``x,y,z[,a,b,c]``) in any order, then one waypoint per row. Other columns (a
trajectory file's ``t`` and derivatives) are ignored, so a trajectory file is also a path file:
its poses, in order. Blank lines are skipped.
"""

from __future__ import annotations

import csv
import difflib
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TextIO

import numpy as np

from rpr3gen.errors import InputError, TrajectoryError
from rpr3gen.trajectory import row_numbers
from rpr3gen.validation import Check, PathArg, numbers

__all__ = ["PathInput", "Waypoints", "read_path_csv"]


class PathInput(Check):
    """``retime``'s ``path``: a file name (str or os.PathLike) or an array of numbers, (m, k)."""

    def __call__(self, name: str, value: Any) -> str | np.ndarray:
        if isinstance(value, str | os.PathLike):
            return PathArg()(name, value)
        array = numbers(name, value)
        if array.ndim != 2:
            raise InputError(
                f"{name}: must be waypoints of shape (m, 3) or (m, 6), one pose a row, or a "
                f"path CSV file, got an array of shape {array.shape}",
                argument=name,
            )
        return np.ascontiguousarray(array)


@dataclass(frozen=True)
class Waypoints:
    """The poses of a path (m, k), and where each came from.

    Attributes:
        q: the waypoints, one pose a row, finite, no two consecutive ones equal.
        source: ``"path"`` (an array) or the file's name.
        lines: the file's line of each waypoint (empty for an array).
    """

    q: np.ndarray
    source: str = "path"
    lines: tuple[int, ...] = ()

    def row(self, i: int, inline: bool = False) -> str:
        """Where waypoint ``i`` (0-based) is: ``path: row 4`` or ``P.csv: line 5 (waypoint 4)``
        to start a message, ``path row 4`` or ``P.csv line 5 (waypoint 4)`` within one."""
        sep = " " if inline else ": "
        if self.lines:
            return f"{self.source}{sep}line {self.lines[i]} (waypoint {i + 1})"
        return f"{self.source}{sep}row {i + 1}"

    def between(self, i: int, inline: bool = False) -> str:
        """Where the path between waypoints ``i`` and ``i + 1`` is (as :meth:`row`)."""
        sep = " " if inline else ": "
        if self.lines:
            return (
                f"{self.source}{sep}between lines {self.lines[i]} and {self.lines[i + 1]} "
                f"(waypoints {i + 1} and {i + 2})"
            )
        return f"{self.source}{sep}between rows {i + 1} and {i + 2}"

    @classmethod
    def of(cls, path: str | np.ndarray, pose: Sequence[str], title: str) -> Waypoints:
        """The checked waypoints of ``retime``'s ``path`` for a robot of pose ``pose``.

        Raises:
            InputError: an array of another width, with a value not finite, fewer than 2 rows
                or two consecutive rows equal.
            TrajectoryError: the same of a file, or a file that cannot be read.
        """
        if isinstance(path, str):
            q, lines = read_path_csv(path, pose)
            waypoints = cls(q, path, lines)
        else:
            k = len(pose)
            if path.shape[1] != k:
                raise InputError(
                    f"path: the {title} takes waypoints of shape (m, {k}), one pose "
                    f"({', '.join(pose)}) a row, got {path.shape}",
                    argument="path",
                )
            waypoints = cls(path)
        waypoints._check()
        return waypoints

    def _error(self, message: str) -> InputError | TrajectoryError:
        if self.lines:
            return TrajectoryError(message)
        return InputError(message, argument="path")

    def _check(self) -> None:
        q = self.q
        bad = ~np.isfinite(q).all(axis=1)
        if bad.any():
            raise self._error(f"{self.row(int(np.argmax(bad)))}: a value is not finite")
        if len(q) < 2:
            raise self._error(
                f"{self.source}: a path needs at least 2 waypoints (its start and its end), "
                f"got {len(q)}"
            )
        same = (np.diff(q, axis=0) == 0).all(axis=1)
        if same.any():
            i = int(np.argmax(same))
            raise self._error(
                f"{self.row(i + 1)}: the same pose as the waypoint before it; give each "
                "waypoint once"
            )


def read_path_csv(path: str, pose: Sequence[str]) -> tuple[np.ndarray, tuple[int, ...]]:
    """The waypoints (m, k) of a path CSV file (module docstring) and the line of each.

    Raises:
        TrajectoryError: naming the file (and the line and column) when it cannot be read, a
            column of the pose is missing or repeated, a value is not a finite number or a row
            has another number of fields than the header.
    """
    try:
        with open(path, encoding="utf-8-sig", newline="") as f:
            return _parse(f, path, tuple(pose))
    except FileNotFoundError:
        raise TrajectoryError(f"{path}: path file not found") from None
    except IsADirectoryError:
        raise TrajectoryError(f"{path}: is a directory, not a path file") from None
    except UnicodeDecodeError as exc:
        raise TrajectoryError(f"{path}: not UTF-8 text (bad byte at offset {exc.start})") from None
    except csv.Error as exc:
        raise TrajectoryError(f"{path}: malformed CSV: {exc}") from None
    except OSError as exc:
        raise TrajectoryError(f"{path}: cannot read: {exc.strerror or exc}") from None


def _parse(f: TextIO, source: str, pose: tuple[str, ...]) -> tuple[np.ndarray, tuple[int, ...]]:
    reader = csv.reader(f)
    header: list[str] | None = None
    for row in reader:
        if any(cell.strip() for cell in row):
            header = [cell.strip() for cell in row]
            break
    if header is None:
        raise TrajectoryError(f"{source}: empty file (expected a header {','.join(pose)})")
    where = f"{source}: line {reader.line_num} (header)"
    columns = []
    for name in pose:
        if header.count(name) > 1:
            raise TrajectoryError(f"{where}: column {name!r} appears twice")
        if name not in header:
            match = difflib.get_close_matches(name, [h for h in header if h not in pose], n=1)
            hint = f" (found {match[0]!r})" if match else ""
            raise TrajectoryError(
                f"{where}: missing column {name!r}{hint}; a path file has the pose's columns "
                f"{','.join(pose)}"
            )
        columns.append(header.index(name))
    values: list[list[float]] = []
    lines: list[int] = []
    for row in reader:
        if not any(cell.strip() for cell in row):
            continue
        where = f"{source}: line {reader.line_num} (waypoint {len(values) + 1})"
        if len(row) != len(header):
            raise TrajectoryError(f"{where}: has {len(row)} fields, the header has {len(header)}")
        values.append(row_numbers(row, zip(pose, columns, strict=True), where))
        lines.append(reader.line_num)
    return np.array(values, dtype=np.float64).reshape(-1, len(pose)), tuple(lines)
