"""Platform trajectories: the paper's two motions (eq. 3) and trajectory CSV files.

A trajectory samples the platform pose ``q = (x, y, phi)`` (position of G in the world frame, m,
and the platform's rotation from the central configuration, rad) with its first and second time
derivatives. The CSV layout is fixed by ``interfaces.md``: a header naming the columns
``t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi`` (any order, extra columns ignored), then one row per
sample with time strictly increasing.
"""

from __future__ import annotations

import csv
import difflib
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TextIO

import numpy as np

from rpr3gen.atomic import write_csv_table
from rpr3gen.errors import InputTypeError, TrajectoryError, did_you_mean

__all__ = [
    "CSV_COLUMNS",
    "PAPER_TRAJECTORIES",
    "Trajectory",
    "paper_trajectory",
    "read_trajectory_csv",
    "write_trajectory_csv",
]

CSV_COLUMNS: tuple[str, ...] = ("t", "x", "y", "phi", "dx", "dy", "dphi", "ddx", "ddy", "ddphi")
"""Columns of a trajectory CSV file, in the order :func:`write_trajectory_csv` writes them."""

PAPER_TRAJECTORIES: Mapping[str, tuple[float, float, float]] = MappingProxyType(
    {
        "rotation": (0.0, 0.0, math.pi / 6),  # figures 3-8
        "rectilinear": (0.05, -0.05, 0.0),  # figures 9-14
    }
)
"""Amplitudes ``(x*, y*, phi*)`` (m, m, rad) of the paper's motions, eq. (3)."""

DEFAULT_SAMPLES = 301
"""Samples of a paper trajectory unless told otherwise (one every 10 ms over the 3 s)."""

DEFAULT_DURATION = 3.0
"""Duration of the paper's motions, s (Δt of eq. 3)."""


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Sampled platform motion; the arrays are float64 copies and read-only.

    Attributes:
        t: Sample times, s, shape ``(n,)``.
        q: Pose ``(x, y, phi)`` per sample (m, m, rad), shape ``(n, 3)``.
        qd: Velocity ``(dx, dy, dphi)`` (m/s, m/s, rad/s), shape ``(n, 3)``.
        qdd: Acceleration ``(ddx, ddy, ddphi)`` (m/s², m/s², rad/s²), shape ``(n, 3)``.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=np.float64)
        if t.ndim != 1 or t.size == 0:
            raise TrajectoryError(f"trajectory: t must have shape (n,) with n >= 1, got {t.shape}")
        for name in ("t", "q", "qd", "qdd"):
            value = t if name == "t" else np.array(getattr(self, name), dtype=np.float64)
            if name != "t" and value.shape != (t.size, 3):
                raise TrajectoryError(
                    f"trajectory: {name} must have shape ({t.size}, 3), got {value.shape}"
                )
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    def __len__(self) -> int:
        """Number of samples."""
        return int(self.t.size)


def paper_trajectory(
    name: str, samples: int = DEFAULT_SAMPLES, duration: float = DEFAULT_DURATION
) -> Trajectory:
    """Sample one of the paper's motions, eq. (3).

    ``x/x* = y/y* = phi/phi* = 1 - cos(pi t / duration)`` for ``t`` in ``[0, duration]``: the
    platform starts at rest in the central configuration. Derivatives are analytic.

    Args:
        name: ``"rotation"`` or ``"rectilinear"`` (keys of :data:`PAPER_TRAJECTORIES`).
        samples: Number of samples, at least 2, equally spaced including both ends.
        duration: Length of the motion, s, finite and positive (the paper: 3 s).

    Raises:
        TrajectoryError: For an unknown name, ``samples < 2`` or a ``duration`` not finite and
            positive.
        InputTypeError: If ``samples`` is not an integer or ``duration`` not a number.
    """
    if name not in PAPER_TRAJECTORIES:
        hint = did_you_mean(str(name), PAPER_TRAJECTORIES)
        choices = " or ".join(PAPER_TRAJECTORIES)
        raise TrajectoryError(f"unknown trajectory {name!r}: choose {choices}{hint}")
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer):
        raise InputTypeError(f"samples: must be an integer >= 2, got {samples!r}")
    if samples < 2:
        raise TrajectoryError(f"samples: must be an integer >= 2, got {samples!r}")
    if isinstance(duration, bool) or not isinstance(
        duration, int | float | np.integer | np.floating
    ):
        raise InputTypeError(f"duration: must be a finite number of seconds > 0, got {duration!r}")
    if not math.isfinite(duration) or duration <= 0:
        raise TrajectoryError(f"duration: must be a finite number of seconds > 0, got {duration!r}")

    amplitude = np.array(PAPER_TRAJECTORIES[name], dtype=np.float64)
    t = np.linspace(0.0, float(duration), int(samples))
    w = math.pi / float(duration)
    s = 1.0 - np.cos(w * t)
    sd = w * np.sin(w * t)
    sdd = w * w * np.cos(w * t)
    return Trajectory(
        t=t,
        q=np.outer(s, amplitude),
        qd=np.outer(sd, amplitude),
        qdd=np.outer(sdd, amplitude),
    )


def read_trajectory_csv(path: str | os.PathLike[str]) -> Trajectory:
    """Read a trajectory CSV file (layout in the module docstring).

    Blank lines are skipped. Errors name the file, the line number in the file (the first
    line is line 1), the 1-based data row (blank lines not counted) and the column.

    Raises:
        TrajectoryError: If the file cannot be read, a column is missing, a value is not a
            finite number, a row is short or long, there are no data rows, or time is not
            strictly increasing.
    """
    source = os.fspath(path)
    try:
        with open(source, encoding="utf-8-sig", newline="") as f:
            return _parse(f, source)
    except FileNotFoundError:
        raise TrajectoryError(f"{source}: trajectory file not found") from None
    except IsADirectoryError:
        raise TrajectoryError(f"{source}: is a directory, not a trajectory file") from None
    except UnicodeDecodeError as exc:
        msg = f"{source}: not UTF-8 text (bad byte at offset {exc.start})"
        raise TrajectoryError(msg) from None
    except csv.Error as exc:
        raise TrajectoryError(f"{source}: malformed CSV: {exc}") from None
    except OSError as exc:
        raise TrajectoryError(f"{source}: cannot read: {exc.strerror or exc}") from None


def _parse(f: TextIO, source: str) -> Trajectory:
    reader = csv.reader(f)
    header: list[str] | None = None
    for row in reader:
        if any(cell.strip() for cell in row):
            header = [cell.strip() for cell in row]
            break
    if header is None:
        raise TrajectoryError(f"{source}: empty file (expected a header {','.join(CSV_COLUMNS)})")
    header_line = reader.line_num

    index: dict[str, int] = {}
    for i, name in enumerate(header):
        if name in CSV_COLUMNS and name in index:
            raise TrajectoryError(
                f"{source}: line {header_line} (header): column {name!r} appears twice"
            )
        index.setdefault(name, i)
    for name in CSV_COLUMNS:
        if name not in index:
            others = [h for h in header if h not in CSV_COLUMNS]
            match = difflib.get_close_matches(name, others, n=1)
            hint = f" (found {match[0]!r})" if match else ""
            raise TrajectoryError(
                f"{source}: line {header_line} (header): missing column {name!r}{hint}"
            )
    wanted = [index[name] for name in CSV_COLUMNS]

    values: list[list[float]] = []
    for row in reader:
        if not any(cell.strip() for cell in row):
            continue
        where = f"{source}: line {reader.line_num} (data row {len(values) + 1})"
        if len(row) != len(header):
            raise TrajectoryError(f"{where}: has {len(row)} fields, the header has {len(header)}")
        numbers = []
        for name, col in zip(CSV_COLUMNS, wanted, strict=True):
            cell = row[col].strip()
            try:
                x = float(cell)
            except ValueError:
                raise TrajectoryError(f"{where}, column {name!r}: not a number: {cell!r}") from None
            if not math.isfinite(x):
                raise TrajectoryError(f"{where}, column {name!r}: not finite: {cell!r}")
            numbers.append(x)
        if values and numbers[0] <= values[-1][0]:
            raise TrajectoryError(
                f"{where}, column 't': time {numbers[0]!r} is not greater than the previous "
                f"row's {values[-1][0]!r} (time must be strictly increasing)"
            )
        values.append(numbers)
    if not values:
        raise TrajectoryError(f"{source}: no data rows after the header")

    data = np.array(values, dtype=np.float64)
    return Trajectory(t=data[:, 0], q=data[:, 1:4], qd=data[:, 4:7], qdd=data[:, 7:10])


def write_trajectory_csv(path: str | os.PathLike[str], traj: Trajectory) -> None:
    """Write ``traj`` as a trajectory CSV file that :func:`read_trajectory_csv` reads back exactly.

    Columns are :data:`CSV_COLUMNS`; values are written with ``%.17g`` so they round-trip
    bit-for-bit. The file is replaced atomically: on error any existing file is left unchanged.

    Raises:
        OSError: If the file cannot be written.
    """
    write_csv_table(path, CSV_COLUMNS, np.column_stack([traj.t, traj.q, traj.qd, traj.qdd]))
