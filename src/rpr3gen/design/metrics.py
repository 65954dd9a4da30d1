"""What a sweep measures of each design, for a chunk of designs at once.

For every design of the chunk, over all the sweep's trajectories: whether it is feasible (every
pose reachable, :mod:`rpr3gen.design.reach`) and, if not, why (the first trajectory and time at
fault), the peak and RMS actuator effort per leg, the peak joint loads, the least conditioning;
and the reachable area at ``phi = 0``.

The peak joint loads depend on the model's format: the paper's, the largest ``|load|`` of each
of its joint-load families (:data:`JOINT_FAMILIES`, ``peak_f10x`` ...); the general one, per
joint j of the legs, the largest force ``|(fxj, fyj)|`` and the largest moment ``|mj|`` over the
three legs (:data:`GENERAL_JOINT_COLUMNS`, ``peak_f1`` ... ``peak_m3``).

The designs are evaluated together: each generated call takes designs x samples, one parameter
column per sample (:mod:`rpr3gen.design.stacked`). Designs whose structure (the paper's
actuation, a general model's actuated joint) differs use different generated code, so a chunk is
evaluated per structure.

A spatial base model (a hexapod or a Delta) is measured by :mod:`rpr3gen.design.spatial_metrics`
(:func:`evaluate_chunk` hands its chunks over).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from rpr3gen import variants
from rpr3gen.backends import BLOCK
from rpr3gen.design.grid import Grid
from rpr3gen.design.grid import design_model as grid_model
from rpr3gen.design.maps import cell_centres
from rpr3gen.design.plan import SweepPlan
from rpr3gen.design.reach import (
    bounds,
    design_limits,
    design_model,
    leg_boxes_meet,
    pose_extent,
    reachable,
    within,
)
from rpr3gen.design.reductions import least, peak, trajectory_samples
from rpr3gen.design.spatial_metrics import evaluate_spatial_chunk
from rpr3gen.design.stacked import evaluate_stacked, param_rows
from rpr3gen.errors import ModelError
from rpr3gen.model import LEGS, Model
from rpr3gen.policy import invalid_samples

__all__ = [
    "GENERAL_JOINT_COLUMNS",
    "GENERAL_RESULT_COLUMNS",
    "JOINT_FAMILIES",
    "RESULT_COLUMNS",
    "SweepPlan",
    "evaluate_chunk",
    "result_columns",
]

JOINT_FAMILIES: tuple[str, ...] = ("f10x", "f10y", "f21y", "m21", "f32y", "f32z")
"""Joint-load families whose peak a sweep reports as ``peak_<family>`` (docs/conventions.md)."""

_INTERFACE_COLUMNS: tuple[str, ...] = (
    "feasible",
    "reason",
    *(f"peak_tau_{leg}" for leg in LEGS),
    *(f"rms_tau_{leg}" for leg in LEGS),
    "min_conditioning",
    "workspace_area",
)

RESULT_COLUMNS: tuple[str, ...] = (
    *_INTERFACE_COLUMNS,
    *(f"peak_{family}" for family in JOINT_FAMILIES),
)
"""The columns after the grid's keys, in order, for a base model of the paper's format: the
interface's, then ``peak_<family>``."""

GENERAL_JOINT_COLUMNS: tuple[str, ...] = (
    *(f"peak_f{j}" for j in (1, 2, 3)),
    *(f"peak_m{j}" for j in (1, 2, 3)),
)
"""A general model's peak joint loads: ``peak_fj``, the largest ``|(fxj, fyj)|`` (N), and
``peak_mj``, the largest ``|mj|`` (N m), of joint j over the three legs (0 for a passive
revolute joint's moment)."""

GENERAL_RESULT_COLUMNS: tuple[str, ...] = (*_INTERFACE_COLUMNS, *GENERAL_JOINT_COLUMNS)
"""The columns after the grid's keys, in order, for a base model of the general format."""

#: How a reason names a limit that is the design studies' default (not the model's).
_DEFAULT_LIMIT = "(the design studies' default travel; set [limits] in the model file)"

#: Samples per generated call when computing areas (designs x grid points).
_AREA_BLOCK = 4 * BLOCK


def result_columns(grid: Grid, general: bool = False) -> tuple[str, ...]:
    """Every column of a sweep's output, in order: the grid's keys, then
    :data:`RESULT_COLUMNS` (a base model of the general format: :data:`GENERAL_RESULT_COLUMNS`).
    """
    return (*grid.keys, *(GENERAL_RESULT_COLUMNS if general else RESULT_COLUMNS))


def evaluate_chunk(plan: SweepPlan, index: int) -> tuple[int, dict[str, Any]]:
    """Evaluate chunk ``index`` of ``plan``: ``(index, {column: values})``, one row per design.

    The columns are :func:`result_columns` (a spatial base model's:
    :func:`rpr3gen.design.spatial_metrics.spatial_result_columns`): float64 arrays,
    ``feasible`` bool, ``reason`` (and ``actuation`` when varied) object arrays of text. A
    design whose values make an invalid model is infeasible, its reason the model's error, its
    numbers NaN.
    """
    if plan.spatial:
        return evaluate_spatial_chunk(plan, index)
    designs = plan.chunk(index)
    n = len(designs)
    columns: dict[str, Any] = plan.grid.columns(designs.start, designs.stop)
    names = GENERAL_RESULT_COLUMNS if plan.general else RESULT_COLUMNS
    results: dict[str, Any] = {name: np.full(n, np.nan) for name in names}
    results["feasible"] = np.zeros(n, dtype=bool)
    results["reason"] = np.full(n, "", dtype=object)
    groups: dict[str, list[tuple[int, Model]]] = {}
    for k, design in enumerate(designs):
        try:
            model = grid_model(plan.grid, plan.base, design, plan.base_source)
        except ModelError as exc:
            results["reason"][k] = f"invalid model: {exc}"
            continue
        groups.setdefault(model.variant, []).append((k, model))
    for variant in sorted(groups):
        rows = np.array([k for k, _ in groups[variant]])
        models = [m for _, m in groups[variant]]
        _trajectory_metrics(plan, models, rows, results)
        if plan.area_resolution:
            results["workspace_area"][rows] = workspace_areas(
                models, plan.area_resolution, plan.min_conditioning
            )
    columns.update(results)
    return index, columns


def _trajectory_metrics(
    plan: SweepPlan, models: Sequence[Model], rows: np.ndarray, results: dict[str, Any]
) -> None:
    """Fill the trajectory columns of ``results`` at ``rows`` for ``models`` (one structure)."""
    q, qd, qdd, which, t, weight = trajectory_samples(plan)
    S = q.shape[0]
    params = param_rows(models)
    structure = models[0].structure
    limits = design_limits(models[0])  # the same coordinates for every design of a structure
    bound = np.array([bounds(design_limits(m)) for m in models]).reshape(len(models), -1, 2)
    effort = structure.effort
    per_call = max(1, BLOCK // S)
    for lo in range(0, len(models), per_call):
        hi = min(lo + per_call, len(models))
        k = hi - lo
        found = evaluate_stacked(
            models[0],
            "inverse_dynamics",
            np.repeat(params[:, lo:hi], S, axis=1),
            [np.tile(q, (k, 1)), np.tile(qd, (k, 1)), np.tile(qdd, (k, 1))],
        )
        ok = found.ok().reshape(k, S)
        get = _blanked(found.values, ok)

        conditioning = get("conditioning")
        values = np.stack(
            [get(f"{family}_{leg}") for leg, family, _, _ in limits] or [np.empty((k, S))], axis=2
        )[:, :, : len(limits)]
        valid = within(
            ok.ravel(),
            conditioning.ravel(),
            values.reshape(k * S, -1),
            np.repeat(bound[lo:hi], S, axis=0),
            plan.min_conditioning,
        ).reshape(k, S)
        at = rows[lo:hi]
        results["feasible"][at] = valid.all(axis=1)
        raw = found["conditioning"].reshape(k, S)
        results["min_conditioning"][at] = least(np.where(np.isfinite(raw), raw, np.inf))
        w = np.where(ok, weight, 0.0)
        total = w.sum(axis=1)
        for leg in LEGS:
            tau = get(f"{effort}_{leg}")
            results[f"peak_tau_{leg}"][at] = peak(tau)
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # inf: too large
                power = np.where(ok, tau, 0.0) ** 2
                results[f"rms_tau_{leg}"][at] = np.sqrt((power * w).sum(axis=1) / total)
        if structure.paper:
            for family in JOINT_FAMILIES:
                loads = np.concatenate([get(f"{family}_{leg}") for leg in LEGS], axis=1)
                results[f"peak_{family}"][at] = peak(loads)
        else:
            for j in (1, 2, 3):
                forces = np.concatenate(
                    [np.hypot(get(f"fx{j}_{leg}"), get(f"fy{j}_{leg}")) for leg in LEGS], axis=1
                )
                results[f"peak_f{j}"][at] = peak(forces)
                moments = np.concatenate([get(f"m{j}_{leg}") for leg in LEGS], axis=1)
                results[f"peak_m{j}"][at] = peak(moments)
        for j in map(int, np.flatnonzero(~valid.all(axis=1))):
            model = models[lo + j]
            bounded = {f"{f}_{leg}": values[j][:, i] for i, (leg, f, _, _) in enumerate(limits)}
            results["reason"][at[j]] = _reason(plan, model, which, t, q, conditioning[j], bounded)


def _blanked(values: dict[str, np.ndarray], ok: np.ndarray) -> Callable[[str], np.ndarray]:
    """``get(name)``: the output ``name`` as (designs, samples), NaN where not ``ok``."""

    def get(name: str) -> np.ndarray:
        return np.where(ok, values[name].reshape(ok.shape), np.nan)

    return get


def _reason(
    plan: SweepPlan,
    model: Model,
    which: np.ndarray,
    t: np.ndarray,
    q: np.ndarray,
    conditioning: np.ndarray,
    values: dict[str, np.ndarray],
) -> str:
    """``"<trajectory>: t = <time> s: <why>"`` for the first pose at fault of one design.

    ``values``: the bounded joint coordinates by output name, (S,) each. A limit that is the
    design studies' default, not the model's, is named so.
    """
    thresholds = variants.load(model.structure, model.generated).thresholds
    limited = design_model(model)
    for i, name in enumerate(plan.names):
        at = which == i
        out = {"conditioning": conditioning[at]}
        for key, column in values.items():
            out[key] = column[at]
        invalid = invalid_samples(limited, q[at], out, plan.min_conditioning, thresholds)
        if invalid is not None:
            reason = invalid.reason
            for key in limited.limits or {}:
                if key not in (model.limits or {}):
                    reason = reason.replace(f"(limits.{key})", _DEFAULT_LIMIT)
            return f"{name}: t = {t[at][invalid.first]:.6g} s: {reason}"
    return ""


def workspace_areas(
    models: Sequence[Model], resolution: int, min_conditioning: float
) -> np.ndarray:
    """The reachable area (m²) at ``phi = 0`` of each model (one structure), on a grid of
    ``resolution`` x ``resolution`` cells over the box of
    :func:`rpr3gen.design.reach.pose_box`, as :func:`rpr3gen.workspace` counts it."""
    params = param_rows(models)
    limits = np.array([bounds(design_limits(m)) for m in models]).reshape(len(models), -1, 2)
    if models[0].structure.paper:
        x0, x1, y0, y1 = pose_extent(params, 0.0, limits[:, :, 1])
    else:
        x0, x1, y0, y1 = np.array([leg_boxes_meet(m, 0.0) for m in models]).T
    areas = np.zeros(len(models))
    cells = resolution * resolution
    per_call = max(1, _AREA_BLOCK // cells)
    todo = np.flatnonzero((x0 < x1) & (y0 < y1))
    for lo in range(0, todo.size, per_call):
        d = todo[lo : lo + per_call]
        xs = np.stack([cell_centres(x0[i], x1[i], resolution) for i in d])
        ys = np.stack([cell_centres(y0[i], y1[i], resolution) for i in d])
        xx = np.broadcast_to(xs[:, np.newaxis, :], (d.size, resolution, resolution))
        yy = np.broadcast_to(ys[:, :, np.newaxis], (d.size, resolution, resolution))
        q = np.column_stack([xx.ravel(), yy.ravel(), np.zeros(d.size * cells)])
        ok = reachable(
            models[0],
            np.repeat(params[:, d], cells, axis=1),
            q,
            np.repeat(limits[d], cells, axis=0),
            min_conditioning,
        ).reshape(d.size, cells)
        cell = (x1[d] - x0[d]) / resolution * ((y1[d] - y0[d]) / resolution)
        areas[d] = np.count_nonzero(ok, axis=1) * cell
    return areas
