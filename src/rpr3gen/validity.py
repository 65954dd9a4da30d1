"""Which samples of a trajectory the robot cannot follow: singular poses and stroke limits.

The measure of closeness to a parallel singularity is the generated output ``conditioning``
(derive/virtual_work.py: the Hadamard ratio of the closure matrix whose solve gives every load,
with the platform's rotation scaled by its radius): 1 at best, 0 at a singular pose, where the
loads grow as 1/conditioning. ``rpr3gen simulate`` refuses a trajectory that comes closer than
:data:`DEFAULT_MIN_CONDITIONING` unless told to write such rows as NaN.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from rpr3gen.model import LEGS, Model

#: Default refusal threshold on ``conditioning``: loads there are ~1000x their well-conditioned
#: size. On the paper's robot and motions it stays above 0.6.
DEFAULT_MIN_CONDITIONING = 1e-3


@dataclass(frozen=True)
class Invalid:
    """The samples at fault and why the first one is."""

    mask: np.ndarray  # (n,) bool
    first: int  # index of the first sample at fault
    reason: str  # one line, without the time


def invalid_samples(
    model: Model, out: Mapping[str, np.ndarray], min_conditioning: float
) -> Invalid | None:
    """Samples that are singular, too close to a singularity, or outside a stroke limit."""
    conditioning = out["conditioning"]
    with np.errstate(invalid="ignore"):
        singular = ~(conditioning >= min_conditioning)
        outside = {
            leg: (out[f"lambda21_{leg}"] < lo) | (out[f"lambda21_{leg}"] > hi)
            for leg, (lo, hi) in zip(LEGS, model.stroke or (), strict=False)
        }
    mask = singular.copy()
    for leg_mask in outside.values():
        mask |= leg_mask
    if not mask.any():
        return None
    first = int(np.argmax(mask))
    if singular[first]:
        c = conditioning[first]
        what = "a singular pose" if not c >= 1e-9 else f"conditioning {c:.3g}"
        reason = f"{what}, under the threshold {min_conditioning:g} (too close to a singularity)"
    else:
        assert model.stroke is not None
        leg = next(leg for leg, leg_mask in outside.items() if leg_mask[first])
        lo, hi = model.stroke[LEGS.index(leg)]
        value = out[f"lambda21_{leg}"][first]
        reason = (
            f"piston displacement lambda21_{leg} = {value:.6g} m "
            f"outside its stroke [{lo:g}, {hi:g}]"
        )
    return Invalid(mask=mask, first=first, reason=reason)
