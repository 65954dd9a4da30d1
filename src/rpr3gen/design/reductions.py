"""What a sweep reduces over samples: the trajectories' samples one after the other with their
time weights, and per design the peak, the least value and the time RMS."""

from __future__ import annotations

import numpy as np

from rpr3gen.design.plan import SweepPlan

__all__ = ["least", "peak", "rms", "trajectory_samples"]


def trajectory_samples(plan: SweepPlan) -> tuple[np.ndarray, ...]:
    """Every trajectory's samples one after the other: q, qd, qdd (S, dof), the trajectory of
    each sample (S,), its time (S,) and its time weight (S,), the trapezoid rule's."""
    weights = []
    for traj in plan.trajectories:
        if len(traj) == 1:
            weights.append(np.ones(1))
            continue
        dt = np.diff(traj.t)
        weights.append(np.concatenate([[dt[0]], dt[1:] + dt[:-1], [dt[-1]]]) / 2)
    which = np.concatenate([np.full(len(tr), i) for i, tr in enumerate(plan.trajectories)])
    return (
        np.concatenate([tr.q for tr in plan.trajectories]),
        np.concatenate([tr.qd for tr in plan.trajectories]),
        np.concatenate([tr.qdd for tr in plan.trajectories]),
        which,
        np.concatenate([tr.t for tr in plan.trajectories]),
        np.concatenate(weights),
    )


def peak(values: np.ndarray) -> np.ndarray:
    """Per row, the largest ``|value|`` of the finite ones; NaN when none is."""
    found = np.where(np.isfinite(values), np.abs(values), -np.inf).max(axis=1)
    return np.where(np.isfinite(found), found, np.nan)


def least(values: np.ndarray) -> np.ndarray:
    """Per row, the least value (give ``inf`` for a sample to leave out); NaN when none is
    finite."""
    found = values.min(axis=1)
    return np.where(np.isfinite(found), found, np.nan)


def rms(values: np.ndarray, ok: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Per row, the time RMS of ``values`` over the samples ``ok`` (trapezoid ``weight`` (S,)
    of each sample); NaN when no sample is ``ok``; inf when the squares overflow."""
    w = np.where(ok, weight, 0.0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # inf: too large
        power = np.where(ok, values, 0.0) ** 2
        return np.sqrt((power * w).sum(axis=1) / w.sum(axis=1))
