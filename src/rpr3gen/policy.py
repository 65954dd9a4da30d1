"""The failure policy, in one place: which samples fail, with which return code, and which a
command refuses.

Two levels:

1. **What the generated functions refuse** (a return code other than 0): the failure conditions
   of each function come from the manifest and are applied to any backend's results by
   :mod:`rpr3gen.failures` (below the backends, which use it).
2. **What ``rpr3gen simulate`` refuses** on top, here: poses closer to a singularity than
   ``--min-conditioning`` (:data:`DEFAULT_MIN_CONDITIONING`) and joint coordinates outside a
   model's limits (:func:`invalid_samples`).

The measure of closeness to a parallel singularity is the generated output ``conditioning``
(``derive/planar/virtual_work.py``: the Hadamard ratio of the closure matrix whose solve gives
every load, with the platform's rotation scaled by its radius): 1 at best, 0 at a singular pose,
where the loads grow as 1/conditioning.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from rpr3gen.backends import evaluate
from rpr3gen.model import LEGS, Model

#: Default refusal threshold of ``rpr3gen simulate`` on ``conditioning``: loads there are
#: ~1000x their well-conditioned size. On the paper's robot and motions it stays above 0.6.
DEFAULT_MIN_CONDITIONING = 1e-3


@dataclass(frozen=True)
class Invalid:
    """The samples at fault and why the first one is."""

    mask: np.ndarray  # (n,) bool
    first: int  # index of the first sample at fault
    reason: str  # one line, without the time


def leg_extensions(model: Model, q: np.ndarray) -> np.ndarray:
    """``|A1A2| = l0 + lambda21`` of each leg (m), (n, 3), straight from the geometry (eq. 5).

    For messages about poses the generated code refused (whose outputs are NaN).
    """
    p = model.params
    c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
    columns = []
    for leg in LEGS:
        x3 = q[:, 0] + c * p[f"x{leg}3"] - s * p[f"y{leg}3"] - p[f"x{leg}1"]
        y3 = q[:, 1] + s * p[f"x{leg}3"] + c * p[f"y{leg}3"] - p[f"y{leg}1"]
        columns.append(np.hypot(x3, y3) - p["l2"])
    return np.stack(columns, axis=1)


def joint_limits(model: Model) -> list[tuple[str, str, float, float]]:
    """The model's joint limits as ``(leg, output family, lo, hi)``: the paper's piston strokes
    (``lambda21``) or the general format's ``[limits]`` (``q2`` ...)."""
    if model.stroke:
        return [
            (leg, "lambda21", lo, hi) for leg, (lo, hi) in zip(LEGS, model.stroke, strict=False)
        ]
    return [
        (key.split(".")[0], key.split(".")[1], lo, hi)
        for key, (lo, hi) in (model.limits or {}).items()
    ]


def _singular_reason(
    model: Model,
    q: np.ndarray,
    conditioning: float,
    min_conditioning: float,
    thresholds: Mapping[str, float],
) -> str:
    """Why the pose ``q`` (3,) is refused: which leg, or how close to a parallel singularity."""
    floor = thresholds["MIN_CONDITIONING"]
    if model.structure.paper:
        extension = leg_extensions(model, q[np.newaxis])[0]
        k = int(np.argmin(extension))
        if not extension[k] >= thresholds["MIN_REACH"] * model.params["l0"]:
            return (
                f"leg {LEGS[k]}: its piston joint {LEGS[k]}2 is on or behind its base pivot "
                f"{LEGS[k]}1 (l0 + lambda21_{LEGS[k]} = {extension[k]:.6g} m), where the leg "
                "folds onto the serial singularity |A1A3| = 0"
            )
    else:
        (diagnostics,), _ = evaluate(model, "pose_diagnostics", (q,))
        *reaches, conditioning = diagnostics[0]
        legs = model.structure.legs
        for leg, r in zip(legs, reaches, strict=True):
            if not np.isfinite(r):
                return f"leg {leg} cannot reach this pose in its working mode"
        k = int(np.argmin(reaches))
        if not reaches[k] >= thresholds["MIN_REACH"]:
            return (
                f"leg {legs[k]} is at a serial singularity (reach {reaches[k]:.3g}: its joints' "
                "motions dependent)"
            )
    what = "a singular pose" if not conditioning >= floor else f"conditioning {conditioning:.3g}"
    return f"{what}, under the threshold {min_conditioning:g} (too close to a singularity)"


def invalid_samples(
    model: Model,
    q: np.ndarray,
    out: Mapping[str, np.ndarray],
    min_conditioning: float,
    thresholds: Mapping[str, float],
) -> Invalid | None:
    """Samples that are singular, too close to a singularity, or outside a joint limit.

    Args:
        model: the robot (its joint limits).
        q: (n, 3) the poses.
        out: the inverse dynamics' outputs (NaN where the generated code refused the sample).
        min_conditioning: refuse ``conditioning`` below this.
        thresholds: the generated code's own floors (``MIN_CONDITIONING``, ``MIN_REACH`` of the
            manifest), to say why it refused a sample.
    """
    conditioning = out["conditioning"]
    limits = joint_limits(model)
    with np.errstate(invalid="ignore"):
        singular = ~(conditioning >= min_conditioning)
        outside = [
            (out[f"{family}_{leg}"] < lo) | (out[f"{family}_{leg}"] > hi)
            for leg, family, lo, hi in limits
        ]
    mask = singular.copy()
    for limit_mask in outside:
        mask |= limit_mask
    if not mask.any():
        return None
    first = int(np.argmax(mask))
    if singular[first]:
        reason = _singular_reason(
            model, q[first], float(conditioning[first]), min_conditioning, thresholds
        )
    else:
        k = next(k for k, limit_mask in enumerate(outside) if limit_mask[first])
        leg, family, lo, hi = limits[k]
        value = out[f"{family}_{leg}"][first]
        if family == "lambda21":
            reason = (
                f"piston displacement lambda21_{leg} = {value:.6g} m "
                f"outside its stroke [{lo:g}, {hi:g}]"
            )
        else:
            unit = "rad" if model.structure.leg[int(family[1]) - 1] == "R" else "m"
            reason = (
                f"joint coordinate {family}_{leg} = {value:.6g} {unit} "
                f"outside its limits [{lo:g}, {hi:g}] (limits.{leg}.{family})"
            )
    return Invalid(mask=mask, first=first, reason=reason)
