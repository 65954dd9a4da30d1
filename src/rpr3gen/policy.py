"""The failure policy, in one place: which samples fail, with which return code, and which a
command refuses.

Two levels:

1. **What the generated functions refuse** (a return code other than 0): the failure conditions
   of each function, with their thresholds and codes, come from the manifest
   (:mod:`rpr3gen.manifest`; e.g. ``conditioning`` under ``MIN_CONDITIONING`` = 1e-9 is
   ``SINGULAR``). The generated C applies them itself; :func:`return_codes` applies the same
   conditions to any backend's results, so the NumPy and C paths agree on every code, and
   :func:`apply` blanks the failed samples (NaN).
2. **What ``rpr3gen simulate`` refuses** on top: poses closer to a singularity than
   ``--min-conditioning`` (:data:`DEFAULT_MIN_CONDITIONING`) and piston displacements outside a
   model's stroke limits (:func:`invalid_samples`).

The measure of closeness to a parallel singularity is the generated output ``conditioning``
(``derive/rpr3/virtual_work.py``: the Hadamard ratio of the closure matrix whose solve gives every
load, with the platform's rotation scaled by its radius): 1 at best, 0 at a singular pose, where
the loads grow as 1/conditioning.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from rpr3gen.manifest import FunctionInfo
from rpr3gen.model import LEGS, Model

#: Default refusal threshold of ``rpr3gen simulate`` on ``conditioning``: loads there are
#: ~1000x their well-conditioned size. On the paper's robot and motions it stays above 0.6.
DEFAULT_MIN_CONDITIONING = 1e-3


def finite_rows(array: np.ndarray) -> np.ndarray:
    """(n,) bool: every value of the row is finite, for an (n, k) array of either layout.

    One pass over the values in memory order answers the usual case, all finite; only then is
    each row looked at (``isfinite(...).all(axis=1)`` over rows of 3 would cost ten times more).
    """
    if np.isfinite(array).all():
        return np.ones(array.shape[0], dtype=bool)
    return np.isfinite(array.T).all(axis=0)


def return_codes(
    function: FunctionInfo,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
    applied: bool = False,
) -> np.ndarray:
    """Per sample, the code the generated C returns for it: 0, or the first failed check's.

    Args:
        function: the function, from the manifest.
        inputs: its inputs, each (n, size).
        outputs: all its outputs as computed, hidden ones included, each (n, size).
        applied: the backend applied the checks itself and wrote a failed sample as a row of
            NaN (the generated C batch): then a failed sample's code is the input check's when
            an input is not finite, else the one code all the other checks share.

    Returns:
        (n,) int array.
    """
    n = inputs[0].shape[0]
    codes = np.zeros(n, dtype=np.intc)
    pending = np.ones(n, dtype=bool)
    if applied:
        public = [o for o, info in zip(outputs, function.outputs, strict=True) if not info.hidden]
        failed = np.zeros(n, dtype=bool)
        for out in public:
            failed |= np.isnan(out).all(axis=1)
        for check in function.checks:
            if check.kind == "inputs_not_finite":
                bad = ~np.all([finite_rows(a) for a in inputs], axis=0)
                codes[bad] = check.code
                pending &= ~bad
        later = [c.code for c in function.checks if c.kind != "inputs_not_finite"]
        if later:
            codes[failed & pending] = later[0]
        return codes
    with np.errstate(invalid="ignore"):
        for check in function.checks:
            if check.kind == "inputs_not_finite":
                failed = ~np.all([finite_rows(a) for a in inputs], axis=0)
            elif check.kind == "custom":  # C only, applied there
                continue
            elif check.kind == "below":
                assert check.output is not None
                assert check.component is not None
                value = outputs[check.output][:, check.component]
                failed = ~(value >= check.threshold)
            else:
                public = [o for o, i in zip(outputs, function.outputs, strict=True) if not i.hidden]
                failed = ~np.all([finite_rows(a) for a in public], axis=0)
            hit = failed & pending
            codes[hit] = check.code
            pending &= ~hit
    return codes


def apply(
    function: FunctionInfo,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
    applied: bool = False,
) -> np.ndarray:
    """Blank (NaN) every output row of a failed sample, in place; return the codes.

    ``applied``: as in :func:`return_codes`.
    """
    codes = return_codes(function, inputs, outputs, applied)
    failed = codes != 0
    if failed.any():
        for out in outputs:
            out[failed] = np.nan
    return codes


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
        from rpr3gen.backends import evaluate

        (diagnostics,), _ = evaluate(model, "pose_diagnostics", (q,))
        *reaches, conditioning = diagnostics[0]
        for leg, r in zip(LEGS, reaches, strict=True):
            if not np.isfinite(r):
                return f"leg {leg} cannot reach this pose in its working mode"
        k = int(np.argmin(reaches))
        if not reaches[k] >= thresholds["MIN_REACH"]:
            return (
                f"leg {LEGS[k]} is at a serial singularity (reach {reaches[k]:.3g}: its joints' "
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
