"""A sweep's arguments, checked before any work: their types and values
(:mod:`rpr3gen.validation`) and their sizes against the memory limit (:mod:`rpr3gen.sizes`)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

from rpr3gen import sizes
from rpr3gen.backends import BLOCK
from rpr3gen.errors import GridError, InputError, InputTypeError
from rpr3gen.trajectory import DURATIONS, Trajectory
from rpr3gen.validation import (
    COMMON,
    Check,
    Flag,
    Instance,
    Integer,
    Number,
    Optional,
    PathArg,
    describe,
)

__all__ = [
    "ARGUMENTS",
    "SPATIAL_STACKED_SAMPLE",
    "check_memory",
    "check_paper_samples",
    "check_values",
]


class _FileOrTables(Check):
    """A path, or a mapping (the parsed TOML), or None when ``optional``."""

    def __init__(self, what: str, *, optional: bool) -> None:
        self.what, self.optional = what, optional

    def __call__(self, name: str, value: Any) -> Any:
        if (value is None and self.optional) or isinstance(value, Mapping):
            return value
        if isinstance(value, str | os.PathLike):
            return PathArg()(name, value)
        raise InputTypeError(f"{name}: must be {self.what}, got {describe(value)}", argument=name)


class _Trajectories(Check):
    """A non-empty list of ``"rotation"``, ``"rectilinear"``, CSV files or Trajectory objects."""

    def __call__(self, name: str, value: Any) -> tuple[Any, ...]:
        what = "a list of trajectories ('rotation', 'rectilinear', CSV files, Trajectory objects)"
        one = str | bytes | bytearray | os.PathLike | Trajectory  # not a list, though iterable
        if isinstance(value, one) or not isinstance(value, Sequence):
            raise InputTypeError(f"{name}: must be {what}, got {describe(value)}", argument=name)
        if not value:
            raise InputError(f"{name}: give at least one trajectory", argument=name)
        for i, item in enumerate(value):
            if not isinstance(item, str | os.PathLike | Trajectory):
                raise InputTypeError(
                    f"{name}: item {i + 1} must be 'rotation', 'rectilinear', a CSV file or a "
                    f"Trajectory, got {describe(item)}",
                    argument=name,
                )
        return tuple(value)


ARGUMENTS: dict[str, Check] = {
    "model": _FileOrTables("a model file, its tables as a mapping, or None", optional=True),
    "grid": _FileOrTables("a grid file or a mapping {dotted model key: values}", optional=False),
    "trajectories": _Trajectories(),
    "out": Optional(PathArg()),
    "scheduler": Optional(Instance(str, "a scheduler address such as 'tcp://host:8786'")),
    "workers": Optional(Integer(0)),
    "resume": Flag(),
    "chunk_size": Integer(1),
    "area_resolution": Integer(0),
    "volume_resolution": Integer(
        0,
        cost=lambda n: n**3 * sizes.STACKED_SAMPLE,
        what="each design's workspace volume",
    ),
    "samples": Integer(2),
    "duration": Number(least=DURATIONS[0], most=DURATIONS[1], unit="s"),
}
"""The check of each argument of :func:`rpr3gen.sweep` (with :data:`rpr3gen.validation.COMMON`'s
``min_conditioning``, ``backend`` and ``progress``)."""

#: A design x sample (or pose of its volume) of a spatial sweep's stacked evaluation: its
#: parameter column (about 100 values for a Delta, 210 for a hexapod), its inputs, its outputs
#: and the generated code's temporaries (bytes). Measured (tracemalloc's peak of a chunk of 64
#: designs): 5.0 KiB a sample of the Delta's trajectory, 7.1 KiB of the 6-UPS's, and 1.6 and 2.6
#: KiB a pose of their volumes; rounded up.
SPATIAL_STACKED_SAMPLE = 8 * sizes.KIB


def check_values(
    grid: Any,
    chunk_size: Any,
    area_resolution: Any,
    samples: Any,
    duration: Any,
    min_conditioning: Any,
    volume_resolution: Any = 0,
    backend: Any = "numpy",
) -> None:
    """The values a plan is made of (for callers of ``make_plan`` that skipped ``sweep``'s
    checks), and ``area_resolution`` and ``volume_resolution`` 0 (none) or at least 2."""
    if grid is None:
        raise InputTypeError(
            "grid: give a grid file or a mapping {dotted model key: values}", argument="grid"
        )
    given = {"chunk_size": chunk_size, "area_resolution": area_resolution, "samples": samples,
             "duration": duration, "volume_resolution": volume_resolution}  # fmt: skip
    for name, value in given.items():
        ARGUMENTS[name](name, value)
    COMMON["min_conditioning"]("min_conditioning", min_conditioning)
    COMMON["backend"]("backend", backend)
    for name, what in (("area_resolution", "area"), ("volume_resolution", "volume")):
        if given[name] == 1:
            raise InputError(
                f"{name}: must be 0 (no {what}) or an integer >= 2, got 1", argument=name
            )


def _cost(
    designs: int,
    chunk: int,
    samples: int,
    area: int,
    processes: int,
    volume: int = 0,
    sample_bytes: int = sizes.STACKED_SAMPLE,
) -> int:
    """Bytes of a sweep (:func:`rpr3gen.sizes.sweep_cost`): a planar one's with its ``area``
    resolution, a spatial one's with its ``volume`` resolution and ``sample_bytes``."""
    points = volume**3 if volume else None
    return sizes.sweep_cost(designs, min(chunk, designs), samples, area, processes, BLOCK,
                            points=points, sample_bytes=sample_bytes)  # fmt: skip


def check_paper_samples(samples: int, papers: int) -> None:
    """``samples`` of each of the ``papers`` paper trajectories, before they are made."""
    sizes.check("samples", samples, lambda n: _cost(1, 1, papers * n, 0, 1),
                "the paper trajectories' evaluation", least=2, argument="samples")  # fmt: skip


def check_memory(
    grid: Any,
    samples: int,
    chunk: int,
    area: int,
    processes: int,
    workers: int | None,
    volume: int = 0,
    sample_bytes: int = sizes.STACKED_SAMPLE,
) -> None:
    """The sweep's sizes against the memory limit, each with those before it as given and those
    after it at their least: the area's (or a spatial sweep's volume's) resolution, the number
    of designs, the worker processes (``processes`` running tasks on this machine; ``workers``
    the argument that set them). A spatial sweep gives ``area`` 0, its ``volume`` resolution
    and its ``sample_bytes`` (:data:`SPATIAL_STACKED_SAMPLE`)."""

    def cost(designs: int, chunk: int, area: int, processes: int, volume: int) -> int:
        return _cost(designs, chunk, samples, area, processes, volume, sample_bytes)

    if volume:
        sizes.check("volume_resolution", volume, lambda v: cost(1, 1, 0, 1, v),
                    "each design's workspace volume", argument="volume_resolution")  # fmt: skip
    else:
        sizes.check("area_resolution", area, lambda a: cost(1, 1, a, 1, 0),
                    "each design's workspace area", argument="area_resolution")  # fmt: skip
    sizes.check(grid.source, len(grid), lambda d: cost(d, chunk, area, 1, volume),
                "the sweep's results and tasks", least=1, unit="designs",
                error=GridError)  # fmt: skip
    if processes > 1:
        designs = len(grid)
        sizes.check("workers" if workers else "workers (one per core)", processes,
                    lambda w: cost(designs, chunk, area, w, volume),
                    "the local cluster's processes and their tasks", least=1,
                    argument="workers")  # fmt: skip
