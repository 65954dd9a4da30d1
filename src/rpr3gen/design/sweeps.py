"""Parameter sweeps: every design of a grid over the given trajectories, on Dask, as Parquet.

The designs are cut into chunks of ``chunk_size`` in the grid's order; each chunk is one task
(:func:`rpr3gen.design.metrics.evaluate_chunk`). Tasks run on a Dask cluster (a local one on
this machine's cores by default, or the scheduler at ``scheduler``) or, with ``workers=0``, in
this process (:mod:`rpr3gen.design.cluster`). The client writes each finished chunk as
``OUT.parts/chunk-NNNNNN.parquet`` (atomically) as it arrives, so an interrupted sweep resumes
(``resume=True``) from the chunks done; at the end the chunks are joined, in order, into ``OUT``
(atomically) and the parts folder is removed. The chunks, and so the output's bytes, do not
depend on the number of workers.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rpr3gen import manifest, variants
from rpr3gen.design.cluster import run_chunks
from rpr3gen.design.grid import read_grid
from rpr3gen.design.metrics import SweepPlan, evaluate_chunk
from rpr3gen.design.sweep_checks import (
    ARGUMENTS,
    check_memory,
    check_paper_samples,
    check_values,
)
from rpr3gen.errors import (
    InputError,
    Rpr3genError,
    TrajectoryError,
    did_you_mean,
)
from rpr3gen.evaluators import all_cores
from rpr3gen.model import ACTUATIONS, model_from_dict, read_model_data
from rpr3gen.paths import check_output
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.structure import Structure, planar_only
from rpr3gen.trajectory import (
    DEFAULT_DURATION,
    DEFAULT_SAMPLES,
    PAPER_TRAJECTORIES,
    Trajectory,
    paper_trajectory,
)
from rpr3gen.validation import checked
from rpr3gen.version import __version__

__all__ = [
    "DEFAULT_AREA_RESOLUTION",
    "DEFAULT_CHUNK_SIZE",
    "DEFAULT_TRAJECTORIES",
    "SweepInterrupted",
    "parts_folder",
    "sweep",
]

DEFAULT_CHUNK_SIZE = 64
"""Designs per chunk (one Dask task, one part file)."""

DEFAULT_AREA_RESOLUTION = 48
"""Grid points per axis of each design's workspace area at ``phi = 0``."""

DEFAULT_TRAJECTORIES: tuple[str, ...] = tuple(PAPER_TRAJECTORIES)
"""The paper's two motions."""

_PLAN_FILE = "sweep.json"
_FORMAT = 1

Columns = dict[str, Any]


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep that writes a file: how many chunks are done and kept, and where.

    Attributes:
        kept: chunks done, in ``folder``.
        chunks: chunks of the sweep.
        folder: the parts folder, which ``resume=True`` continues from.
    """

    def __init__(self, kept: int, chunks: int, folder: Path) -> None:
        super().__init__(
            f"{kept} of {chunks} chunks done, kept in {folder}: resume=True computes only the "
            "others"
        )
        self.kept, self.chunks, self.folder = kept, chunks, folder


def parts_folder(out: str | os.PathLike[str]) -> Path:
    """Where a sweep writing ``out`` keeps its finished chunks: ``out`` + ``.parts``."""
    return Path(f"{os.fspath(out)}.parts")


@checked(ARGUMENTS)
def sweep(
    model: str | os.PathLike[str] | Mapping[str, Any] | None = None,
    grid: str | os.PathLike[str] | Mapping[str, Any] | None = None,
    trajectories: Sequence[str | os.PathLike[str] | Trajectory] = DEFAULT_TRAJECTORIES,
    *,
    out: str | os.PathLike[str] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
    area_resolution: int = DEFAULT_AREA_RESOLUTION,
    samples: int = DEFAULT_SAMPLES,
    duration: float = DEFAULT_DURATION,
    progress: bool = False,
) -> Any:
    """Evaluate every design of ``grid`` over ``trajectories``; one row per design.

    Args:
        model: the base model, of either format (any leg type): a model file, its data as a
            mapping, or None for the paper's.
        grid: the grid file (TOML), or its content as a mapping ``{dotted key: values}``
            (:mod:`rpr3gen.design.grid`).
        trajectories: ``"rotation"``, ``"rectilinear"``, trajectory CSV files or
            :class:`~rpr3gen.Trajectory` objects (named ``"trajectory N"`` in the reasons).
        out: write the result as Parquet there (and its chunks to ``out + ".parts"`` on the
            way); None writes nothing.
        scheduler: the address of a Dask scheduler (``"tcp://host:port"``) to run on; None
            starts a local cluster.
        workers: processes of the local cluster (None: this machine's cores); 0 runs in this
            process without Dask.
        resume: continue the sweep whose chunks are in ``out + ".parts"``.
        chunk_size: designs per task.
        min_conditioning: the least conditioning of a feasible pose, in [0, 1).
        area_resolution: grid points per axis of the workspace area (0: no area).
        samples: samples of each paper trajectory.
        duration: duration of each paper trajectory, s.
        progress: show a progress bar on stderr when it is a terminal.

    Returns:
        A :class:`pyarrow.Table`: the grid's keys, then
        :data:`rpr3gen.design.metrics.RESULT_COLUMNS` (a base model of the general format:
        :data:`rpr3gen.design.metrics.GENERAL_RESULT_COLUMNS`), rows in the grid's order.

    Raises:
        ModelError, GridError, TrajectoryError, InputError: bad input, before any work.
        Rpr3genError: an interrupted sweep's chunks are in the way (without ``resume``), or
            they belong to another sweep.
    """
    if out is None and resume:
        raise InputError("resume: needs out, the file whose chunks are resumed", argument="resume")
    if out is not None:
        target = check_output(out, "the sweep", argument="out")
        check_output(parts_folder(target), "the sweep's parts", folder=True, argument="out")
    local = scheduler is None and workers != 0
    processes = (workers or all_cores()) if local else 1 if scheduler is None else 0
    plan = make_plan(model, grid, trajectories, chunk_size=chunk_size,
                     min_conditioning=min_conditioning, area_resolution=area_resolution,
                     samples=samples, duration=duration, processes=processes,
                     workers=workers)  # fmt: skip
    if out is None:
        parts: dict[int, Columns] = {}
        run_chunks(plan, range(plan.chunks), evaluate_chunk, parts.__setitem__, scheduler, workers,
                   progress)  # fmt: skip
        return _joined(_table(parts[i]) for i in range(plan.chunks))
    from rpr3gen.design import parquet

    folder = _open_parts(plan, parts_folder(target), resume)

    def keep(index: int, columns: Columns) -> None:
        parquet.write_table(folder / _part_name(index), _table(columns))

    done = _done_chunks(plan, folder)
    todo = [i for i in range(plan.chunks) if i not in done]
    initial = sum(len(plan.chunk(i)) for i in done)
    try:
        run_chunks(plan, todo, evaluate_chunk, keep, scheduler, workers, progress, initial=initial)
    except Rpr3genError as exc:
        raise Rpr3genError(f"{exc}; the chunks done are in {folder}: rerun with --resume") from exc
    except KeyboardInterrupt as exc:
        raise SweepInterrupted(len(_done_chunks(plan, folder)), plan.chunks, folder) from exc
    target.parent.mkdir(parents=True, exist_ok=True)
    parquet.write_tables(target, (folder / _part_name(i) for i in range(plan.chunks)))
    shutil.rmtree(folder)
    return parquet.read_table(target)


def make_plan(
    model: str | os.PathLike[str] | Mapping[str, Any] | None,
    grid: str | os.PathLike[str] | Mapping[str, Any] | None,
    trajectories: Sequence[str | os.PathLike[str] | Trajectory],
    *,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
    area_resolution: int = DEFAULT_AREA_RESOLUTION,
    samples: int = DEFAULT_SAMPLES,
    duration: float = DEFAULT_DURATION,
    processes: int = 1,
    workers: int | None = None,
) -> SweepPlan:
    """Check every input and build the :class:`SweepPlan` (no work yet).

    ``processes``: how many tasks run at once on this machine (local workers, or 1 in this
    process, 0 on a remote cluster), for the memory check
    (:func:`rpr3gen.design.sweep_checks.check_memory`); ``workers``:
    the argument that set them, to name in its message (None: one per core).
    """
    check_values(grid, chunk_size, area_resolution, samples, duration, min_conditioning)
    assert grid is not None  # checked
    if isinstance(model, Mapping):
        source, base = "<model>", dict(model)
    else:
        source, base = read_model_data(model)
    planar_only(model_from_dict(base, source=source).structure, "sweep")  # valid, planar
    checked = read_grid(grid, base)
    papers = sum(isinstance(t, str) and t in PAPER_TRAJECTORIES for t in trajectories)
    check_paper_samples(samples, papers)
    names, trajs = _trajectories(trajectories, samples, duration)
    check_memory(checked, sum(len(t) for t in trajs), chunk_size, area_resolution, processes,
                 workers)  # fmt: skip
    return SweepPlan(
        base=base,
        base_source=source,
        grid=checked,
        names=names,
        trajectories=trajs,
        min_conditioning=float(min_conditioning),
        area_resolution=int(area_resolution),
        chunk_size=int(chunk_size),
    )


def _trajectories(
    given: Sequence[str | os.PathLike[str] | Trajectory], samples: int, duration: float
) -> tuple[tuple[str, ...], tuple[Trajectory, ...]]:
    from rpr3gen.trajectory import read_trajectory_csv

    if isinstance(given, str | os.PathLike | Trajectory) or not given:
        raise InputError("trajectories: give a non-empty list of trajectories")
    names, trajs = [], []
    for i, item in enumerate(given):
        if isinstance(item, Trajectory):
            names.append(f"trajectory {i + 1}")
            trajs.append(item)
        elif isinstance(item, str) and item in PAPER_TRAJECTORIES:
            names.append(item)
            trajs.append(paper_trajectory(item, samples=samples, duration=duration))
        else:
            path = Path(item)
            if path.suffix.lower() != ".csv" and not path.exists():
                hint = did_you_mean(str(item), PAPER_TRAJECTORIES)
                raise TrajectoryError(
                    f"trajectories: {os.fspath(item)!r} is neither "
                    f"{', '.join(PAPER_TRAJECTORIES)} nor a CSV file{hint}",
                    argument="trajectories",
                )
            names.append(path.stem)
            trajs.append(read_trajectory_csv(path))
    return tuple(names), tuple(trajs)


def identity(plan: SweepPlan) -> str:
    """A hash of everything that decides a sweep's results (SHA-256, hex): the base model, the
    grid, the trajectories, the options, the chunking, the runtime's version and the generated
    code's."""
    digest = hashlib.sha256()
    for traj in plan.trajectories:
        for array in (traj.t, traj.q, traj.qd, traj.qdd):
            digest.update(np.ascontiguousarray(array).tobytes())
    described = {
        "format": _FORMAT,
        "base": plan.base,
        "grid": plan.grid.as_dict(),
        "trajectories": list(plan.names),
        "samples": digest.hexdigest(),
        "min_conditioning": plan.min_conditioning,
        "area_resolution": plan.area_resolution,
        "chunk_size": plan.chunk_size,
        "rpr3gen": __version__,
        "generated": _generated(plan),
    }
    text = json.dumps(described, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _generated(plan: SweepPlan) -> dict[str, str]:
    """The source hash of each generated variant the sweep may use (deriving the general
    format's on first use)."""
    if not plan.general:
        return {a: manifest.load(a).source_hash for a in ACTUATIONS}
    base = model_from_dict(plan.base, source=plan.base_source).structure
    joints = {base.actuated}
    if "actuated" in plan.grid.keys:
        joints.update(plan.grid.values[plan.grid.keys.index("actuated")])
    found = {}
    for joint in sorted(joints):
        structure = Structure(base.leg, joint)
        found[structure.variant] = variants.load(structure).source_hash
    return found


def _open_parts(plan: SweepPlan, folder: Path, resume: bool) -> Path:
    """The parts folder, made or checked: it must be this sweep's to resume it."""
    stamp = {"identity": identity(plan), "designs": len(plan.grid), "chunks": plan.chunks}
    if folder.exists():
        if not resume:
            raise Rpr3genError(
                f"{folder}: holds the chunks of an interrupted sweep; pass --resume "
                "(resume=True) to continue it, or remove the folder"
            )
        try:
            found = json.loads((folder / _PLAN_FILE).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            found = None
        if found != stamp:
            raise Rpr3genError(
                f"{folder}: holds the chunks of another sweep (other model, grid, "
                "trajectories, options or version); remove it to start this one"
            )
        return folder
    folder.mkdir(parents=True)
    from rpr3gen.atomic import atomic_write

    with atomic_write(folder / _PLAN_FILE) as f:
        json.dump(stamp, f, sort_keys=True)
    return folder


def _part_name(index: int) -> str:
    return f"chunk-{index:06d}.parquet"


def _done_chunks(plan: SweepPlan, folder: Path) -> set[int]:
    """The chunks whose part file is there, whole (its rows all there)."""
    import pyarrow.parquet as pq

    done = set()
    for index in range(plan.chunks):
        path = folder / _part_name(index)
        if path.is_file():
            try:
                rows = pq.read_metadata(path).num_rows
            except (OSError, ValueError):
                continue
            if rows == len(plan.chunk(index)):
                done.add(index)
    return done


def _table(columns: Columns) -> Any:
    from rpr3gen.design.parquet import to_table

    return to_table(columns)


def _joined(tables: Iterable[Any]) -> Any:
    import pyarrow as pa

    return pa.concat_tables(list(tables)).combine_chunks()
