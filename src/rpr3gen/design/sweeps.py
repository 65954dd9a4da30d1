"""Parameter sweeps: every design of a grid over the given trajectories, on Dask, as Parquet.

The designs are cut into chunks of ``chunk_size`` in the grid's order; each chunk is one task
(:func:`rpr3gen.design.metrics.evaluate_chunk`). Tasks run on a Dask cluster (a local one on
this machine's cores by default, or the scheduler at ``scheduler``) or, with ``workers=0``, in
this process (:mod:`rpr3gen.design.cluster`). The client writes each finished chunk as
``OUT.parts/chunk-NNNNNN.parquet`` (atomically) as it arrives, so an interrupted sweep resumes
(``resume=True``) from the chunks done; at the end the chunks are joined, in order, into ``OUT``
(atomically) and the parts folder is removed. The chunks, and so the output's bytes, do not
depend on the number of workers.

A spatial base model (a hexapod or a Delta, docs/spatial-robots.md) is swept the same way over
its own trajectory files (the paper's two motions are planar), with the keys of its file
(:mod:`rpr3gen.design.spatial_grid`), the columns of
:func:`rpr3gen.design.spatial_metrics.spatial_result_columns` (the workspace volume in place of
the area) and either backend.
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
from rpr3gen.design.spatial_metrics import base_structure
from rpr3gen.design.sweep_checks import (
    ARGUMENTS,
    SPATIAL_STACKED_SAMPLE,
    check_memory,
    check_paper_samples,
    check_values,
)
from rpr3gen.errors import (
    InputError,
    Rpr3genError,
    SetupError,
    TrajectoryError,
    did_you_mean,
)
from rpr3gen.evaluators import all_cores
from rpr3gen.model import ACTUATIONS, model_from_dict, read_model_data
from rpr3gen.paths import check_output
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.structure import Structure
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
    "DEFAULT_VOLUME_RESOLUTION",
    "SweepInterrupted",
    "parts_folder",
    "sweep",
]

DEFAULT_CHUNK_SIZE = 64
"""Designs per chunk (one Dask task, one part file)."""

DEFAULT_AREA_RESOLUTION = 48
"""Grid points per axis of each design's workspace area at ``phi = 0``."""

DEFAULT_VOLUME_RESOLUTION = 12
"""Grid points per axis (x, y and z) of each spatial design's workspace volume at its home
orientation: 1,728 poses, about 1.6 ms a design in NumPy (0.3 ms in C) on the gallery Delta,
about what its trajectory costs; coarse (the gallery's volumes within -7 to +27 % of their value
at 48 points, docs/design-studies.md), but the same for every design."""

DEFAULT_TRAJECTORIES: tuple[str, ...] = tuple(PAPER_TRAJECTORIES)
"""The paper's two motions (planar: a spatial model's sweep needs its own trajectory files)."""

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
    volume_resolution: int = DEFAULT_VOLUME_RESOLUTION,
    backend: str = "numpy",
) -> Any:
    """Evaluate every design of ``grid`` over ``trajectories``; one row per design.

    Args:
        model: the base model, of either format (any leg type) or a spatial robot's (a hexapod
            or a Delta): a model file, its data as a mapping, or None for the paper's.
        grid: the grid file (TOML), or its content as a mapping ``{dotted key: values}``
            (:mod:`rpr3gen.design.grid`).
        trajectories: ``"rotation"``, ``"rectilinear"``, trajectory CSV files or
            :class:`~rpr3gen.Trajectory` objects (named ``"trajectory N"`` in the reasons); a
            spatial model's: CSV files of its pose (docs/spatial-robots.md) or Trajectory
            objects of its pose's width (the paper's two motions are planar).
        out: write the result as Parquet there (and its chunks to ``out + ".parts"`` on the
            way); None writes nothing.
        scheduler: the address of a Dask scheduler (``"tcp://host:port"``) to run on; None
            starts a local cluster.
        workers: processes of the local cluster (None: this machine's cores); 0 runs in this
            process without Dask.
        resume: continue the sweep whose chunks are in ``out + ".parts"``.
        chunk_size: designs per task.
        min_conditioning: the least conditioning of a feasible pose, in [0, 1).
        area_resolution: grid points per axis of a planar robot's workspace area (0: no
            area); a spatial model's sweep refuses any other value than the default.
        samples: samples of each paper trajectory.
        duration: duration of each paper trajectory, s.
        progress: show a progress bar on stderr when it is a terminal.
        volume_resolution: a spatial robot's: grid points per axis (x, y and z) of its
            workspace volume at the home orientation (0: no volume); a planar model's sweep
            refuses any other value than the default.
        backend: ``"numpy"`` (designs x samples in each generated call) or ``"c"`` (one
            batch call per design; compiled on first use in each worker): a spatial model's
            sweep; a planar model's evaluates in NumPy only.

    Returns:
        A :class:`pyarrow.Table`: the grid's keys, then
        :data:`rpr3gen.design.metrics.RESULT_COLUMNS` (a base model of the general format:
        :data:`rpr3gen.design.metrics.GENERAL_RESULT_COLUMNS`; a spatial one:
        :func:`rpr3gen.design.spatial_metrics.spatial_result_columns`), rows in the grid's
        order.

    Raises:
        ModelError, GridError, TrajectoryError, InputError: bad input, before any work.
        SetupError: an interrupted sweep's chunks are in the way (without ``resume``), or
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
                     workers=workers, volume_resolution=volume_resolution,
                     backend=backend)  # fmt: skip
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
        hint = f"{exc}; the chunks done are in {folder}: rerun with --resume"
        raise type(exc)(hint, argument=exc.argument) from exc  # the same class, with the hint
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
    volume_resolution: int = DEFAULT_VOLUME_RESOLUTION,
    backend: str = "numpy",
) -> SweepPlan:
    """Check every input and build the :class:`SweepPlan` (no work yet).

    ``processes``: how many tasks run at once on this machine (local workers, or 1 in this
    process, 0 on a remote cluster), for the memory check
    (:func:`rpr3gen.design.sweep_checks.check_memory`); ``workers``:
    the argument that set them, to name in its message (None: one per core).
    """
    check_values(grid, chunk_size, area_resolution, samples, duration, min_conditioning,
                 volume_resolution, backend)  # fmt: skip
    assert grid is not None  # checked
    if isinstance(model, Mapping):
        source, base = "<model>", dict(model)
    else:
        source, base = read_model_data(model)
    structure = model_from_dict(base, source=source).structure  # valid
    _check_family(structure, area_resolution, volume_resolution, backend)
    if structure.spatial:
        _no_paper_trajectory(trajectories, structure)
    checked = read_grid(grid, base)
    papers = sum(isinstance(t, str) and t in PAPER_TRAJECTORIES for t in trajectories)
    check_paper_samples(samples, papers)
    names, trajs = _trajectories(trajectories, samples, duration, structure)
    total = sum(len(t) for t in trajs)
    if structure.spatial:
        check_memory(checked, total, chunk_size, 0, processes, workers, volume_resolution,
                     SPATIAL_STACKED_SAMPLE)  # fmt: skip
    else:
        check_memory(checked, total, chunk_size, area_resolution, processes, workers)
    return SweepPlan(
        base=base,
        base_source=source,
        grid=checked,
        names=names,
        trajectories=trajs,
        min_conditioning=float(min_conditioning),
        area_resolution=0 if structure.spatial else int(area_resolution),
        chunk_size=int(chunk_size),
        volume_resolution=int(volume_resolution) if structure.spatial else 0,
        backend=backend if structure.spatial else "numpy",
    )


def _check_family(
    structure: Structure, area_resolution: int, volume_resolution: int, backend: str
) -> None:
    """Refuse an option of the other family's sweep: a planar robot's workspace area or a
    spatial robot's volume; the c backend for a planar robot (evaluated in NumPy only)."""
    if structure.spatial and area_resolution != DEFAULT_AREA_RESOLUTION:
        raise InputError(
            "area_resolution: for a planar robot's workspace area; a spatial robot's sweep "
            "measures its workspace volume (volume_resolution, --volume-resolution)",
            argument="area_resolution",
        )
    if not structure.spatial and volume_resolution != DEFAULT_VOLUME_RESOLUTION:
        raise InputError(
            "volume_resolution: for a spatial robot's workspace volume; a planar robot's sweep "
            "measures its workspace area (area_resolution, --area-resolution)",
            argument="volume_resolution",
        )
    if not structure.spatial and backend != "numpy":
        raise InputError(
            f"backend: {backend!r} is for a spatial robot's sweep; a planar robot's evaluates "
            "its designs together in NumPy (rpr3gen.design.stacked)",
            argument="backend",
        )


def _no_paper_trajectory(
    given: Sequence[str | os.PathLike[str] | Trajectory], structure: Structure
) -> None:
    """A spatial robot takes none of the paper's two (planar) motions, the default."""
    for item in given:
        if isinstance(item, str) and item in PAPER_TRAJECTORIES:
            raise TrajectoryError(
                f"trajectories: {item!r} is one of the paper's planar motions (the default); "
                f"the {structure.title} (pose {', '.join(structure.pose)}) needs its own: give "
                "a trajectory CSV file, --trajectory FILE.csv",
                argument="trajectories",
            )


def _trajectories(
    given: Sequence[str | os.PathLike[str] | Trajectory],
    samples: int,
    duration: float,
    structure: Structure,
) -> tuple[tuple[str, ...], tuple[Trajectory, ...]]:
    """The trajectories' names and samples: the paper's made, the files read with the
    structure's pose, each of the structure's width."""
    from rpr3gen.trajectory import read_trajectory_csv

    if isinstance(given, str | os.PathLike | Trajectory) or not given:
        raise InputError("trajectories: give a non-empty list of trajectories")
    names, trajs = [], []
    for i, item in enumerate(given):
        if isinstance(item, Trajectory):
            width = item.q.shape[1]
            if width != structure.dof:
                raise InputError(
                    f"trajectories: item {i + 1} has poses of {width} coordinates; the "
                    f"{structure.title}'s are {', '.join(structure.pose)}",
                    argument="trajectories",
                )
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
            trajs.append(read_trajectory_csv(path, pose=structure.pose))
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
        "volume_resolution": plan.volume_resolution,
        "backend": plan.backend,
        "chunk_size": plan.chunk_size,
        "rpr3gen": __version__,
        "generated": _generated(plan),
    }
    text = json.dumps(described, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _generated(plan: SweepPlan) -> dict[str, str]:
    """The source hash of each generated variant the sweep may use (deriving the general
    format's on first use)."""
    if plan.spatial:
        structure = base_structure(plan.base)
        return {structure.variant: variants.load(structure).source_hash}
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
            raise SetupError(
                f"{folder}: holds the chunks of an interrupted sweep; pass --resume "
                "(resume=True) to continue it, or remove the folder"
            )
        try:
            found = json.loads((folder / _PLAN_FILE).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            found = None
        if found != stamp:
            raise SetupError(
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
