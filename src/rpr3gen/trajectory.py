"""Platform trajectories: the paper's two motions (eq. 3) and trajectory CSV files.

A trajectory samples the platform pose ``q = (x, y, phi)`` (position of G in the world frame, m,
and the platform's rotation from the central configuration, rad) with its first and second time
derivatives. The CSV layout is fixed by ``docs/interfaces.md``: a header naming the columns
``t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi`` (any order, extra columns ignored), then one row per
sample with time strictly increasing. A file may also give the positions alone, ``t,x,y,phi``:
the velocities and accelerations are then those of a quintic smoothing spline through them, and
a file that gives them is checked against its positions (:mod:`rpr3gen.derivatives`).
"""

from __future__ import annotations

import csv
import difflib
import math
import os
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import TextIO

import numpy as np

from rpr3gen import sizes
from rpr3gen.atomic import write_csv_table
from rpr3gen.derivatives import MAX_SMOOTHING, check_smoothing, differentiate, mismatch
from rpr3gen.errors import TrajectoryError, TrajectoryWarning, did_you_mean
from rpr3gen.validation import Instance, Integer, Number, Optional, PathArg, checked, numbers

__all__ = [
    "CSV_COLUMNS",
    "DEFAULT_DURATION",
    "DEFAULT_SAMPLES",
    "DURATIONS",
    "PAPER_TRAJECTORIES",
    "PLANAR_POSE",
    "POSITION_COLUMNS",
    "Trajectory",
    "csv_columns",
    "paper_trajectory",
    "read_trajectory_csv",
    "write_trajectory_csv",
]

CSV_COLUMNS: tuple[str, ...] = ("t", "x", "y", "phi", "dx", "dy", "dphi", "ddx", "ddy", "ddphi")

PLANAR_POSE: tuple[str, ...] = ("x", "y", "phi")
"""The pose of a planar robot; a spatial robot's is its structure's ``pose`` (``x, y, z, a, b,
c`` for a hexapod, ``x, y, z`` for a Delta; docs/spatial-robots.md)."""


def csv_columns(pose: Sequence[str] = PLANAR_POSE) -> tuple[str, ...]:
    """The columns of a trajectory file of the pose ``pose``: ``t``, the pose, its ``d``- and
    ``dd``-prefixed rates and accelerations."""
    return ("t", *pose, *(f"d{n}" for n in pose), *(f"dd{n}" for n in pose))


"""Columns of a trajectory CSV file, in the order :func:`write_trajectory_csv` writes them."""

POSITION_COLUMNS: tuple[str, ...] = CSV_COLUMNS[:4]
"""Columns of a file of positions only, whose derivatives :func:`read_trajectory_csv` derives."""

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

DURATIONS: tuple[float, float] = (1e-6, 1e9)
"""The durations a paper trajectory may have, s: from a microsecond (accelerations ~1e11 m/s²)
to 30 years; beyond, its loads and their squares leave float64's range."""


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Sampled platform motion; the arrays are float64 copies and read-only.

    Attributes:
        t: Sample times, s, shape ``(n,)``.
        q: Pose ``(x, y, phi)`` per sample (m, m, rad), shape ``(n, 3)``; a spatial robot's
            pose (docs/spatial-robots.md): ``(n, 6)`` for a hexapod, ``(n, 3)`` for a Delta.
        qd: Velocity ``(dx, dy, dphi)`` (m/s, m/s, rad/s), shape ``(n, 3)`` (or the pose's).
        qdd: Acceleration ``(ddx, ddy, ddphi)`` (m/s², m/s², rad/s²), shape ``(n, 3)`` (or the
            pose's).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def __post_init__(self) -> None:
        t = np.array(numbers("t", self.t, TrajectoryError))  # InputTypeError: not numbers
        if t.ndim != 1 or t.size == 0:
            raise TrajectoryError(f"trajectory: t must have shape (n,) with n >= 1, got {t.shape}")
        try:  # the pose's width (3, or a hexapod's 6); a malformed q is reported below
            shape = np.shape(self.q)
        except ValueError:
            shape = ()
        width = 6 if len(shape) == 2 and shape[1] == 6 else 3
        for name in ("t", "q", "qd", "qdd"):
            value = (
                t if name == "t" else np.array(numbers(name, getattr(self, name), TrajectoryError))
            )
            if name != "t" and value.shape != (t.size, width):
                raise TrajectoryError(
                    f"trajectory: {name} must have shape ({t.size}, {width}), a row per time of "
                    f"t, got {value.shape}"
                )
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        with np.errstate(invalid="ignore"):  # inf - inf: that t is refused as not finite
            bad = ~np.isfinite(t) | np.r_[False, ~(np.diff(t) > 0)]
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise TrajectoryError(
                f"trajectory: t must be finite and strictly increasing, got t[{k}] = {t[k]:g}"
                + (f" after {t[k - 1]:g}" if k else "")
            )

    def __len__(self) -> int:
        """Number of samples."""
        return int(self.t.size)

    @classmethod
    def from_positions(
        cls,
        t: np.ndarray,
        q: np.ndarray,
        smoothing: float = 0.0,
        *,
        source: str = "positions",
        pose: Sequence[str] = PLANAR_POSE,
    ) -> Trajectory:
        """The motion through the poses ``q``, with the derivatives of a quintic spline.

        Velocities and accelerations are the first and second derivatives of a quintic
        smoothing spline per coordinate (:func:`rpr3gen.derivatives.differentiate`).

        Args:
            t: Sample times, s, finite and strictly increasing, shape ``(n,)``, ``n >= 6``.
            q: Poses ``(x, y, phi)`` (m, m, rad), finite, shape ``(n, 3)``.
            smoothing: RMS deviation allowed between the spline and ``q`` (m for x and y, rad
                for phi). 0 (the default) passes through every pose, which then stay as given;
                for measured poses give their noise level.
            source: Where the poses come from, for messages.

        Raises:
            TrajectoryError: For a bad shape, a value not finite, time not strictly increasing
                or fewer than 6 samples.
            InputTypeError, InputError: For a ``smoothing`` that is not a number >= 0.
        """
        Instance(str, "a name for messages")("source", source)
        given = cls(t=t, q=q, qd=q, qdd=q)  # shapes checked, float64 copies
        if not (np.isfinite(given.t).all() and np.isfinite(given.q).all()):
            raise TrajectoryError(f"{source}: t and q must be finite")
        if np.any(np.diff(given.t) <= 0):
            raise TrajectoryError(f"{source}: time must be strictly increasing")
        q_fit, qd, qdd = differentiate(
            given.t, given.q, smoothing, source=source, names=tuple(pose)
        )
        return cls(t=given.t, q=q_fit, qd=qd, qdd=qdd)


@checked(
    name=Instance(str, "'rotation' or 'rectilinear'"),
    samples=Integer(2, cost=lambda n: n * sizes.PAPER_SAMPLE, what="the trajectory",
                    error=TrajectoryError),
    duration=Number(least=DURATIONS[0], most=DURATIONS[1], unit="s", error=TrajectoryError),
)  # fmt: skip
def paper_trajectory(
    name: str, samples: int = DEFAULT_SAMPLES, duration: float = DEFAULT_DURATION
) -> Trajectory:
    """Sample one of the paper's motions, eq. (3).

    ``x/x* = y/y* = phi/phi* = 1 - cos(pi t / duration)`` for ``t`` in ``[0, duration]``: the
    platform starts at rest in the central configuration. Derivatives are analytic.

    Args:
        name: ``"rotation"`` or ``"rectilinear"`` (keys of :data:`PAPER_TRAJECTORIES`).
        samples: Number of samples, at least 2, equally spaced including both ends.
        duration: Length of the motion, s, in :data:`DURATIONS` (the paper: 3 s).

    Raises:
        TrajectoryError: For an unknown name, ``samples < 2`` or a ``duration`` not finite and
            positive.
        InputTypeError: If ``samples`` is not an integer or ``duration`` not a number.
    """
    if name not in PAPER_TRAJECTORIES:
        hint = did_you_mean(str(name), PAPER_TRAJECTORIES)
        choices = " or ".join(PAPER_TRAJECTORIES)
        raise TrajectoryError(
            f"name: unknown trajectory {name!r}: choose {choices}{hint}", argument="name"
        )

    amplitude = np.array(PAPER_TRAJECTORIES[name], dtype=np.float64)
    t = np.linspace(0.0, float(duration), int(samples))
    w = math.pi / float(duration)
    with np.errstate(over="ignore", invalid="ignore"):
        s = 1.0 - np.cos(w * t)
        sd = w * np.sin(w * t)
        sdd = w * w * np.cos(w * t)
        q, qd, qdd = (np.outer(x, amplitude) for x in (s, sd, sdd))
    if not (np.isfinite(qd).all() and np.isfinite(qdd).all() and (np.diff(t) > 0).all()):
        raise TrajectoryError(
            f"duration: {duration!r} s is too short for {samples} samples: the times or the "
            "accelerations are beyond float64",
            argument="duration",
        )
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)


@checked(
    path=PathArg(),
    smoothing=Optional(Number(least=0.0, most=MAX_SMOOTHING)),
    pose=Instance(tuple, "the pose's column names, a tuple of str"),
)
def read_trajectory_csv(
    path: str | os.PathLike[str],
    *,
    smoothing: float | None = None,
    pose: Sequence[str] = PLANAR_POSE,
) -> Trajectory:
    """Read a trajectory CSV file (layout in the module docstring).

    Blank lines are skipped. Errors name the file, the line number in the file (the first
    line is line 1), the 1-based data row (blank lines not counted) and the column.

    A file with the columns ``t,x,y,phi`` and none of the derivatives gives the positions only:
    velocities and accelerations are derived as in :meth:`Trajectory.from_positions`. A file
    that gives them is checked against its positions (:func:`rpr3gen.derivatives.mismatch`)
    and used as given.

    Args:
        path: The CSV file.
        smoothing: For a file of positions only: the RMS deviation allowed between the fitted
            spline and the positions (m for x and y, rad for phi); None or 0 passes through
            every sample. An error with a file that gives the derivatives.
        pose: The pose's column names: ``("x", "y", "phi")`` (planar robots, the default), or a
            spatial model's ``model.structure.pose`` (``x, y, z, a, b, c`` or ``x, y, z``).

    Raises:
        TrajectoryError: If the file cannot be read, a column is missing, a value is not a
            finite number, a row is short or long, there are no data rows, time is not
            strictly increasing, a file of positions only has fewer than 6 rows, or
            ``smoothing`` is given for a file with derivatives.
        InputTypeError, InputError: For a ``smoothing`` that is not a number >= 0.

    Warns:
        TrajectoryWarning: If the file's velocities or accelerations disagree with its
            positions (a ``UserWarning``; the command prints it as one line).
    """
    traj, _ = read_trajectory_columns(path, (), smoothing=smoothing, pose=tuple(pose))
    return traj


def read_trajectory_columns(
    path: str | os.PathLike[str],
    extra: Sequence[str],
    *,
    smoothing: float | None = None,
    pose: Sequence[str] = PLANAR_POSE,
) -> tuple[Trajectory, np.ndarray]:
    """:func:`read_trajectory_csv` of a file that also has the columns ``extra`` (required,
    checked as the trajectory's are): the trajectory and those columns, (n, len(extra)).

    Used for identification data: a trajectory plus the measured actuator efforts.
    """
    source = os.fspath(path)
    if smoothing is not None:
        smoothing = check_smoothing(smoothing)
    try:
        with open(source, encoding="utf-8-sig", newline="") as f:
            table = _parse(f, source, tuple(extra), tuple(pose))
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
    data, columns = table[:, : table.shape[1] - len(extra)], table[:, table.shape[1] - len(extra) :]
    k = len(pose)
    t, q = data[:, 0], data[:, 1 : 1 + k]
    if data.shape[1] == 1 + k:
        return Trajectory.from_positions(t, q, smoothing or 0.0, source=source, pose=pose), columns
    if smoothing is not None:
        raise TrajectoryError(
            f"{source}: smoothing is for a file of positions only (t,{','.join(pose)}); this one "
            "gives "
            "the velocities and accelerations"
        )
    traj = Trajectory(t=t, q=q, qd=data[:, 1 + k : 1 + 2 * k], qdd=data[:, 1 + 2 * k : 1 + 3 * k])
    problem = mismatch(traj.t, traj.q, traj.qd, traj.qdd, tuple(pose))
    if problem:
        warnings.warn(f"{source}: {problem}", TrajectoryWarning, stacklevel=3)
    return traj, columns


def _parse(
    f: TextIO, source: str, extra: tuple[str, ...] = (), pose: tuple[str, ...] = PLANAR_POSE
) -> np.ndarray:
    """The table of a trajectory file: columns :data:`CSV_COLUMNS` or :data:`POSITION_COLUMNS`,
    then the required columns ``extra``."""
    every = csv_columns(pose)
    positions = every[: 1 + len(pose)]
    reader = csv.reader(f)
    header: list[str] | None = None
    for row in reader:
        if any(cell.strip() for cell in row):
            header = [cell.strip() for cell in row]
            break
    if header is None:
        raise TrajectoryError(f"{source}: empty file (expected a header {','.join(every)})")
    header_line = reader.line_num

    index: dict[str, int] = {}
    for i, name in enumerate(header):
        if (name in every or name in extra) and name in index:
            raise TrajectoryError(
                f"{source}: line {header_line} (header): column {name!r} appears twice"
            )
        index.setdefault(name, i)
    # Positions alone, or everything: a file with some of the derivatives lacks the others.
    given = any(name in index for name in every[len(positions) :])
    columns = (*(every if given else positions), *extra)
    for name in columns:
        if name not in index:
            others = [h for h in header if h not in columns]
            match = difflib.get_close_matches(name, others, n=1)
            hint = f" (found {match[0]!r})" if match else ""
            raise TrajectoryError(
                f"{source}: line {header_line} (header): missing column {name!r}{hint}"
            )
    wanted = [index[name] for name in columns]

    values: list[list[float]] = []
    for row in reader:
        if not any(cell.strip() for cell in row):
            continue
        where = f"{source}: line {reader.line_num} (data row {len(values) + 1})"
        if len(row) != len(header):
            raise TrajectoryError(f"{where}: has {len(row)} fields, the header has {len(header)}")
        numbers = row_numbers(row, zip(columns, wanted, strict=True), where)
        if values and numbers[0] <= values[-1][0]:
            raise TrajectoryError(
                f"{where}, column 't': time {numbers[0]!r} is not greater than the previous "
                f"row's {values[-1][0]!r} (time must be strictly increasing)"
            )
        values.append(numbers)
    if not values:
        raise TrajectoryError(f"{source}: no data rows after the header")

    return np.array(values, dtype=np.float64)


def row_numbers(row: Sequence[str], columns: Iterable[tuple[str, int]], where: str) -> list[float]:
    """The finite numbers of a CSV ``row`` at ``columns`` (``(name, index)``), or a
    :class:`TrajectoryError` naming ``where`` and the column."""
    out = []
    for name, col in columns:
        cell = row[col].strip()
        try:
            x = float(cell)
        except ValueError:
            raise TrajectoryError(f"{where}, column {name!r}: not a number: {cell!r}") from None
        if not math.isfinite(x):
            raise TrajectoryError(f"{where}, column {name!r}: not finite: {cell!r}")
        out.append(x)
    return out


def write_trajectory_csv(
    path: str | os.PathLike[str], traj: Trajectory, pose: Sequence[str] = PLANAR_POSE
) -> None:
    """Write ``traj`` as a trajectory CSV file that :func:`read_trajectory_csv` reads back exactly.

    Columns are :data:`CSV_COLUMNS`; values are written with ``%.17g`` so they round-trip
    bit-for-bit. The file is replaced atomically: on error any existing file is left unchanged.

    Raises:
        OSError: If the file cannot be written.
    """
    columns = csv_columns(pose)
    write_csv_table(path, columns, np.column_stack([traj.t, traj.q, traj.qd, traj.qdd]))
