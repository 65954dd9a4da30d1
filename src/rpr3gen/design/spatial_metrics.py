"""What a sweep measures of each spatial design (a hexapod or a Delta), for a chunk at once.

For every design of the chunk, over all the sweep's trajectories: whether it is feasible (the
generated inverse dynamics evaluates every pose: every leg reaches it in its working mode, clear
of a serial and a parallel singularity; its ``conditioning`` is at least the sweep's
``min_conditioning``; every joint coordinate the model's ``[limits]`` bound is within them)
and, if not, why (the first trajectory and time at fault, as ``rpr3gen
simulate`` says it); the peak and RMS effort of each leg's actuator, the peak force and moment
of each joint over the legs, the least conditioning; and the reachable volume at the home
orientation, :func:`rpr3gen.design.spatial_workspace`'s.

With the NumPy backend the designs are evaluated together, designs x samples in each generated
call (one parameter column per sample, :mod:`rpr3gen.design.stacked`); with the C backend one
batch call per design. Both give the same numbers to rounding.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from rpr3gen import variants
from rpr3gen.backends import BLOCK, evaluate
from rpr3gen.design.grid import design_model
from rpr3gen.design.plan import SweepPlan
from rpr3gen.design.reductions import least, peak, rms, trajectory_samples
from rpr3gen.design.spatial_workspace import cell_volume, reachable_poses, workspace_box
from rpr3gen.design.stacked import evaluate_stacked
from rpr3gen.errors import ModelError
from rpr3gen.model import Model
from rpr3gen.policy import invalid_samples, joint_limits
from rpr3gen.structure import SPATIAL_LEG_TYPES, Structure

__all__ = [
    "base_structure",
    "evaluate_spatial_chunk",
    "spatial_joint_columns",
    "spatial_result_columns",
    "workspace_volumes",
]

#: Each spatial leg type's joints, base to platform (docs/spatial-robots.md, "Outputs"): a
#: Delta's joint 1 is its R or P, joints 2 and 3 the upper S of its rods, 4 and 5 the lower.
_JOINTS = {"UPS": "UPS", "RUS": "RUS", "PUS": "PUS", "RSS2": "RSSSS", "PSS2": "PSSSS"}

#: Poses per generated call when computing volumes (designs x grid points).
_VOLUME_BLOCK = 4 * BLOCK


def spatial_joint_columns(structure: Structure) -> tuple[str, ...]:
    """A spatial structure's peak joint loads: ``peak_fj``, the largest force
    ``|(fxj, fyj, fzj)|`` (N) of joint j over the legs, for every joint; then ``peak_mj``, the
    largest moment ``|(mxj, myj, mzj)|`` (N m), for every joint but the S joints (which
    transmit none)."""
    joints = _JOINTS[structure.leg]
    return (
        *(f"peak_f{j}" for j in range(1, len(joints) + 1)),
        *(f"peak_m{j}" for j, kind in enumerate(joints, 1) if kind != "S"),
    )


def spatial_result_columns(structure: Structure) -> tuple[str, ...]:
    """The columns after the grid's keys, in order, for a spatial base model: ``feasible``,
    ``reason``, ``peak_tau_L`` and ``rms_tau_L`` for every leg L (A to F, or A to C),
    ``min_conditioning``, ``workspace_volume``, then :func:`spatial_joint_columns`."""
    legs = structure.legs
    return (
        "feasible",
        "reason",
        *(f"peak_tau_{leg}" for leg in legs),
        *(f"rms_tau_{leg}" for leg in legs),
        "min_conditioning",
        "workspace_volume",
        *spatial_joint_columns(structure),
    )


def base_structure(base: dict[str, Any]) -> Structure:
    """The structure of a spatial base model's data (valid): its leg type, on its motor joint."""
    return Structure(base["leg"], SPATIAL_LEG_TYPES[base["leg"]][1])


def evaluate_spatial_chunk(plan: SweepPlan, index: int) -> tuple[int, dict[str, Any]]:
    """Evaluate chunk ``index`` of a spatial ``plan``: ``(index, {column: values})``, one row
    per design, the grid's keys then :func:`spatial_result_columns`. A design whose values make
    an invalid model is infeasible, its reason the model's error, its numbers NaN."""
    structure = base_structure(plan.base)
    designs = plan.chunk(index)
    n = len(designs)
    columns: dict[str, Any] = plan.grid.columns(designs.start, designs.stop)
    results: dict[str, Any] = {c: np.full(n, np.nan) for c in spatial_result_columns(structure)}
    results["feasible"] = np.zeros(n, dtype=bool)
    results["reason"] = np.full(n, "", dtype=object)
    rows, models = [], []
    for k, design in enumerate(designs):
        try:
            models.append(design_model(plan.grid, plan.base, design, plan.base_source))
        except ModelError as exc:
            results["reason"][k] = f"invalid model: {exc}"
            continue
        rows.append(k)
    if models:
        at = np.array(rows)
        _trajectory_metrics(plan, models, at, results)
        if plan.volume_resolution:
            results["workspace_volume"][at] = workspace_volumes(
                models, plan.volume_resolution, plan.min_conditioning, plan.backend
            )
    columns.update(results)
    return index, columns


def _evaluate(
    models: Sequence[Model], function: str, inputs: Sequence[np.ndarray], backend: str
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """``function`` of each design at its own samples: ``inputs`` (k x S, width), design by
    design, S samples each. Returns every output component (hidden ones too, with NumPy) as
    (k, S), as computed (anything where refused), and (k, S) bool: the sample evaluated."""
    k = len(models)
    S = inputs[0].shape[0] // k
    variant = variants.load(models[0].structure, models[0].generated)
    if backend == "numpy":
        params = np.stack([m.vector(variant.param_names) for m in models], axis=1)
        found = evaluate_stacked(models[0], function, np.repeat(params, S, axis=1), inputs)
        values = {name: v.reshape(k, S) for name, v in found.values.items()}
        return values, found.ok().reshape(k, S)
    names = [arg.names for arg in variant.function(function).outputs if not arg.hidden]
    values = {name: np.empty((k, S)) for group in names for name in group}
    ok = np.empty((k, S), dtype=bool)
    for d, model in enumerate(models):
        part = [a[d * S : (d + 1) * S] for a in inputs]
        outputs, codes = evaluate(model, function, part, backend, threads=1)
        ok[d] = codes == 0
        for group, out in zip(names, outputs, strict=True):
            for j, name in enumerate(group):
                values[name][d] = out[:, j]
    return values, ok


def _trajectory_metrics(
    plan: SweepPlan, models: Sequence[Model], rows: np.ndarray, results: dict[str, Any]
) -> None:
    """Fill the trajectory columns of ``results`` at ``rows`` for ``models``."""
    q, qd, qdd, which, t, weight = trajectory_samples(plan)
    S = q.shape[0]
    structure = models[0].structure
    legs = structure.legs
    joints = _JOINTS[structure.leg]
    per_call = max(1, BLOCK // S)
    for lo in range(0, len(models), per_call):
        group = models[lo : lo + per_call]
        k = len(group)
        tiled = [np.tile(a, (k, 1)) for a in (q, qd, qdd)]
        values, ok = _evaluate(group, "inverse_dynamics", tiled, plan.backend)

        def get(name: str, ok: np.ndarray = ok, values: dict = values) -> np.ndarray:
            return np.where(ok, values[name], np.nan)

        at = rows[lo : lo + k]
        conditioning = get("conditioning")
        with np.errstate(invalid="ignore"):
            valid = ok & (conditioning >= plan.min_conditioning)
        limits = [joint_limits(model) for model in group]
        blanked = {f"{f}_{leg}": get(f"{f}_{leg}") for each in limits for leg, f, _, _ in each}
        bounded = [
            {f"{f}_{leg}": ((low, high), blanked[f"{f}_{leg}"][d]) for leg, f, low, high in each}
            for d, each in enumerate(limits)
        ]
        for d, coordinates in enumerate(bounded):
            for (low, high), coordinate in coordinates.values():
                with np.errstate(invalid="ignore"):
                    valid[d] &= (coordinate >= low) & (coordinate <= high)
        feasible = valid.all(axis=1)
        results["feasible"][at] = feasible
        results["min_conditioning"][at] = _least_conditioning(group, q, ok, conditioning, plan)
        for leg in legs:
            tau = get(f"tau_{leg}")
            results[f"peak_tau_{leg}"][at] = peak(tau)
            results[f"rms_tau_{leg}"][at] = rms(tau, ok, weight)
        for j, kind in enumerate(joints, 1):
            for load in ("f",) if kind == "S" else ("f", "m"):
                sizes = [
                    np.sqrt(sum(get(f"{load}{axis}{j}_{leg}") ** 2 for axis in "xyz"))
                    for leg in legs
                ]
                results[f"peak_{load}{j}"][at] = peak(np.concatenate(sizes, axis=1))
        for d in map(int, np.flatnonzero(~feasible)):
            out = {"conditioning": conditioning[d]}
            out.update({name: coordinate for name, (_, coordinate) in bounded[d].items()})
            results["reason"][at[d]] = _reason(plan, group[d], which, t, q, out)


def _least_conditioning(
    models: Sequence[Model],
    q: np.ndarray,
    ok: np.ndarray,
    conditioning: np.ndarray,
    plan: SweepPlan,
) -> np.ndarray:
    """Per design, the least conditioning over the samples where every leg reaches the pose:
    the inverse dynamics' where it evaluated the sample, else ``pose_diagnostics``' (a pose
    that the generated code refused at a parallel singularity has its conditioning there)."""
    found = np.where(ok, conditioning, np.inf)
    for d in map(int, np.flatnonzero(~ok.all(axis=1))):
        refused = ~ok[d]
        (diagnostics,), _ = evaluate(
            models[d], "pose_diagnostics", (q[refused],), plan.backend, threads=1
        )
        _, at_refused = reachable_poses(diagnostics, 0.0)
        found[d, refused] = np.where(np.isfinite(at_refused), at_refused, np.inf)
    return least(found)


def _reason(
    plan: SweepPlan,
    model: Model,
    which: np.ndarray,
    t: np.ndarray,
    q: np.ndarray,
    values: dict[str, np.ndarray],
) -> str:
    """``"<trajectory>: t = <time> s: <why>"`` for the first pose at fault of one design
    (``values``: its samples' conditioning and bounded joint coordinates by output name, NaN
    where the generated code refused the pose), as ``rpr3gen simulate`` says it."""
    thresholds = variants.load(model.structure, model.generated).thresholds
    for i, name in enumerate(plan.names):
        at = which == i
        out = {key: column[at] for key, column in values.items()}
        invalid = invalid_samples(model, q[at], out, plan.min_conditioning, thresholds)
        if invalid is not None:
            return f"{name}: t = {t[at][invalid.first]:.6g} s: {invalid.reason}"
    return ""


def workspace_volumes(
    models: Sequence[Model], resolution: int, min_conditioning: float, backend: str = "numpy"
) -> np.ndarray:
    """The reachable volume (m^3) of each spatial model (one structure) at its home
    orientation, as :func:`rpr3gen.design.spatial_workspace` counts it with ``resolution``
    points along x, along y and along z (its ``heights``)."""
    volumes = np.zeros(len(models))
    points = resolution**3
    per_call = max(1, _VOLUME_BLOCK // points)
    home = (0.0, 0.0, 0.0)
    for lo in range(0, len(models), per_call):
        group = models[lo : lo + per_call]
        boxes = [workspace_box(m, resolution, resolution, home) for m in group]
        q = np.concatenate([box[3] for box in boxes])
        values, _ = _evaluate(group, "pose_diagnostics", [q], backend)
        variant = variants.load(group[0].structure, group[0].generated)
        (names,) = (arg.names for arg in variant.function("pose_diagnostics").outputs)
        for d, (x, y, z, _) in enumerate(boxes):
            diagnostics = np.column_stack([values[name][d] for name in names])
            reachable, _ = reachable_poses(diagnostics, min_conditioning)
            volumes[lo + d] = float(np.count_nonzero(reachable) * cell_volume(x, y, z))
    return volumes
