"""The size policy: every size a user gives is checked against the memory it will take.

A size (a number of samples, harmonics, grid points, designs, workers, threads...) is refused
before any work when what it makes the command or function allocate exceeds the **memory
limit**: ``RPR3GEN_MAX_MEMORY`` (bytes, or with a binary suffix: ``512M``, ``8G``, ``1T``) when
set, else half of this machine's memory (its physical memory, or its control group's limit
when lower). The error is one line naming the argument (the option, on the command line), the
memory the value would need, the limit, and the largest value that fits::

    resolution: 1000000000000 would need about 1.7 ZiB of memory for the workspace map, more
    than the limit of 11.7 GiB (half this machine's memory; RPR3GEN_MAX_MEMORY sets it); at
    most 2474

The costs below are measured upper bounds (peak resident memory over the interpreter's own,
rounded up), one constant per unit of work; :func:`check` finds the bound by bisection, so a
cost may combine several sizes (``excite``: harmonics and samples).
"""

from __future__ import annotations

import contextlib
import functools
import os
import re
from collections.abc import Callable
from pathlib import Path

from rpr3gen.errors import InputError, Rpr3genError

__all__ = [
    "DESIGN_ROW",
    "EVALUATED_VALUE",
    "EXCITE_SAMPLE",
    "IDENTIFY_SAMPLE",
    "MEMORY_VARIABLE",
    "PAPER_SAMPLE",
    "SIMULATED_SAMPLE",
    "STACKED_SAMPLE",
    "TASK",
    "THREAD",
    "WORKER",
    "WORKSPACE_POINT",
    "check",
    "memory_limit",
]

KIB, MIB, GIB = 1 << 10, 1 << 20, 1 << 30

MEMORY_VARIABLE = "RPR3GEN_MAX_MEMORY"
"""The environment variable that sets the memory limit (bytes, or ``512M``, ``8G``, ``1T``)."""

PAPER_SAMPLE = 256
"""A sample of a paper trajectory: t, q, qd, qdd and their temporaries (bytes)."""
SIMULATED_SAMPLE = 2 * KIB
"""A sample through ``rpr3gen simulate``: trajectory, every output, CSV and figures (~1.1 KiB)."""
EVALUATED_VALUE = 8
"""A value of a generated function's inputs or outputs, per sample (float64)."""
IDENTIFY_SAMPLE = 4 * KIB
"""A sample of ``identify``: regressor, weighted copies, QR and residuals."""
WORKSPACE_POINT = 2 * KIB
"""A point of a workspace map, its orientation march, Parquet row and figures (~1.2 KiB)."""
STACKED_SAMPLE = 2 * KIB
"""A design x sample of a sweep's stacked evaluation: parameter column, inputs, outputs."""
DESIGN_ROW = 512
"""A design's row of a sweep's result, held whole when the table is read back at the end."""
TASK = 16 * KIB
"""A chunk's task on Dask: its future, its key and the scheduler's state."""
WORKER = 256 * MIB
"""A worker process of the local Dask cluster, before its task (~146 MiB measured)."""
THREAD = 8 * MIB
"""A thread of the c backend: its stack."""
EXCITE_SAMPLE = 96 * KIB
"""A sample of an exciting motion: regressor and inverse dynamics in each of the 64 evaluations
that ``excite`` keeps for SLSQP."""


def memory_limit() -> int:
    """The memory (bytes) any one size may make rpr3gen allocate.

    Raises:
        InputError: ``RPR3GEN_MAX_MEMORY`` is set to something that is not a size.
    """
    text = os.environ.get(MEMORY_VARIABLE, "").strip()
    if text:
        return _parse_bytes(text)
    return max(_machine_memory() // 2, 256 * MIB)


def _why() -> str:
    if os.environ.get(MEMORY_VARIABLE, "").strip():
        return f"{MEMORY_VARIABLE}"
    return f"half this machine's memory; {MEMORY_VARIABLE} sets it"


_SIZE = re.compile(r"^(?P<number>\d+(\.\d+)?)\s*(?P<unit>[KMGT]?)(i?B)?$", re.IGNORECASE)


def _parse_bytes(text: str) -> int:
    found = _SIZE.match(text)
    if found is None:
        raise InputError(
            f"{MEMORY_VARIABLE}={text!r}: not a memory size; give bytes or e.g. 512M, 8G, 1T"
        )
    power = "KMGT".find(found["unit"].upper()) + 1 if found["unit"] else 0
    value = int(float(found["number"]) * 1024**power)
    if value < 1:
        raise InputError(f"{MEMORY_VARIABLE}={text!r}: must be at least one byte")
    return value


@functools.cache
def _machine_memory() -> int:
    """Physical memory, or the control group's limit when lower; 8 GiB when neither is known."""
    found = []
    with contextlib.suppress(AttributeError, ValueError, OSError):
        found.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(path).read_text(encoding="ascii").strip()
        except (OSError, UnicodeDecodeError):
            continue
        if text.isdigit() and int(text) < 1 << 60:  # "max", or v1's "no limit" (2^63 - page)
            found.append(int(text))
    positive = [n for n in found if n > 0]
    return min(positive) if positive else 8 * GIB


def human(size: float) -> str:
    """``size`` bytes in binary units: ``"11.7 GiB"``."""
    units = ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB", "ZiB", "YiB")
    if size >= 1024 ** len(units):  # an order of magnitude: such integers overflow floats
        return f"10^{len(str(int(size))) - 1} bytes"
    k = 0
    while size >= 1024 and k < len(units) - 1:
        size /= 1024
        k += 1
    return f"{size:.0f} {units[k]}" if k == 0 else f"{size:.3g} {units[k]}"


def check(
    label: str,
    value: int,
    cost: Callable[[int], float],
    what: str,
    *,
    least: int = 0,
    unit: str = "",
    argument: str | None = None,
    error: type[Rpr3genError] = InputError,
) -> None:
    """Refuse ``value`` when ``cost(value)`` bytes exceed :func:`memory_limit`.

    Args:
        label: what the message names first: the argument (``"resolution"``), or a grid
            file's key.
        value: the size given, already checked to be an integer >= ``least``.
        cost: the bytes allocated for a value, non-decreasing in it (other sizes fixed).
        what: what the memory is for, e.g. ``"the workspace map"``.
        least: the smallest value allowed (for the bound in the message).
        unit: what the value counts, after it (``"samples"``).
        argument: the argument's name, when ``label`` is one (the command line shows the option).
        error: the class raised.

    Raises:
        error: one line with the memory needed, the limit and the largest value that fits.
    """
    limit = memory_limit()
    need = cost(value)
    if need <= limit:
        return
    if cost(least) > limit:
        bound = "; the other sizes already take all of it"
    else:
        lo, hi = least, value  # cost(lo) fits, cost(hi) does not
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if cost(mid) <= limit else (lo, mid)
        bound = f"; at most {lo}"
    counted = f"{value} {unit}" if unit else f"{value}"
    raise error(
        f"{label}: {counted} would need about {human(need)} of memory for {what}, more than the "
        f"limit of {human(limit)} ({_why()}){bound}",
        argument=argument,
    )


def ceil_div(a: int, b: int) -> int:
    """``ceil(a / b)`` for positive integers, exactly."""
    return -(-a // b)


def sweep_cost(
    designs: int,
    chunk_size: int,
    samples: int,
    area_resolution: int,
    processes: int,
    block: int,
    *,
    points: int | None = None,
    sample_bytes: int = STACKED_SAMPLE,
) -> int:
    """Bytes of a sweep: the table of every design read back at the end, a task per chunk on
    Dask, and ``processes`` tasks at once, each evaluating at least ``block`` stacked samples of
    the trajectories and (``area_resolution`` > 0) ``4 block`` of the area grid.

    ``points``: the poses of each design's workspace grid, when not ``area_resolution`` squared
    (a spatial robot's volume: its resolution cubed); ``sample_bytes``: a design x sample of the
    stacked evaluation, when not a planar robot's (:data:`STACKED_SAMPLE`).
    """
    points = area_resolution * area_resolution if points is None else points
    per_task = max(block, samples) * sample_bytes + chunk_size * DESIGN_ROW
    if points:
        per_task += max(4 * block, points) * sample_bytes
    tasks = ceil_div(designs, chunk_size) * TASK
    return designs * DESIGN_ROW + tasks + processes * (WORKER + per_task)


def excite_cost(harmonics: int, samples: int) -> int:
    """Bytes of ``excite``: the kept evaluations per sample, and SLSQP's constraint Jacobian
    and work arrays (10 constraints per sample, ``3 + 6 harmonics`` unknowns; a few copies)."""
    unknowns = 3 + 6 * harmonics
    return samples * EXCITE_SAMPLE + 8 * 4 * (10 * samples + unknowns) * unknowns
