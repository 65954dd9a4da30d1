"""Which platform poses a design reaches: stroke limits, singularities and the grid around them.

A pose is **reachable** when the generated code evaluates it (every piston joint in front of its
base pivot: ``reach`` above ``MIN_REACH``), its ``conditioning`` is at least the threshold (as
``rpr3gen simulate --min-conditioning``, default 1e-3) and every piston displacement
``lambda21`` is within the leg's stroke.

**Assumption** (design studies only): a model without ``[limits] stroke`` gets the stroke
``lambda21`` in ``[-l0, l0 + l2]`` for every leg: from the piston joint on its base pivot (the
serial singularity that ``reach`` guards) to twice the central leg length ``l0 + l2``. Without a
bound the workspace has no edge; the paper gives none, and its two motions stay inside this one
(``lambda21`` from -0.076 to 0.22 m). Set ``[limits] stroke`` in the model file to study your
own.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from rpr3gen.design.stacked import PARAM_INDEX, evaluate_stacked, piston_displacements
from rpr3gen.model import LEGS, Model

__all__ = [
    "design_stroke",
    "jacobian_sign",
    "pose_extent",
    "reachable",
    "reachable_signed",
    "within",
]


def design_stroke(model: Model) -> tuple[tuple[float, float], ...]:
    """The stroke ``((lo, hi), ...)`` of legs A, B, C (m, bounds on ``lambda21``): the model's
    ``[limits] stroke``, else ``[-l0, l0 + l2]`` (the module's **Assumption**)."""
    if model.stroke is not None:
        return model.stroke
    l0, l2 = model.params["l0"], model.params["l2"]
    return ((-l0, l0 + l2),) * len(LEGS)


def pose_extent(params: np.ndarray, phi: float, hi: np.ndarray) -> np.ndarray:
    """A box ``(x0, x1, y0, y1)`` that holds every position of G reachable at the angle ``phi``.

    G lies within ``l0 + l2 + hi_i`` of ``A1_i - R(phi) p_i`` for every leg i (``p_i`` the platform
    joint in the platform frame), so the box is the intersection of the three discs' boxes. It
    is empty (``x0 >= x1`` or ``y0 >= y1``) when the discs share no box.

    Args:
        params: (P,) or (P, D) parameter vectors (:data:`PARAM_NAMES` order).
        phi: platform angle, rad.
        hi: (3,) or (D, 3) upper stroke bounds (m).

    Returns:
        (4,) or (4, D).
    """
    c, s = math.cos(phi), math.sin(phi)
    hi = np.asarray(hi, dtype=np.float64)
    reach = params[PARAM_INDEX["l0"]] + params[PARAM_INDEX["l2"]]
    boxes = []
    for k, leg in enumerate(LEGS):
        x3, y3 = params[PARAM_INDEX[f"x{leg}3"]], params[PARAM_INDEX[f"y{leg}3"]]
        cx = params[PARAM_INDEX[f"x{leg}1"]] - (c * x3 - s * y3)
        cy = params[PARAM_INDEX[f"y{leg}1"]] - (s * x3 + c * y3)
        radius = reach + hi[..., k]
        boxes.append((cx - radius, cx + radius, cy - radius, cy + radius))
    x0 = np.maximum.reduce([b[0] for b in boxes])
    x1 = np.minimum.reduce([b[1] for b in boxes])
    y0 = np.maximum.reduce([b[2] for b in boxes])
    y1 = np.minimum.reduce([b[3] for b in boxes])
    return np.array([x0, x1, y0, y1])


def reachable(
    model: Model,
    params: np.ndarray,
    q: np.ndarray,
    stroke: np.ndarray,
    min_conditioning: float,
) -> np.ndarray:
    """(n,) bool: the poses ``q`` (n, 3) that the designs reach (see the module).

    Args:
        model: picks the generated variant.
        params: (P,) or (P, n) parameter vectors.
        q: (n, 3) poses.
        stroke: (3, 2) or (n, 3, 2) bounds ``(lo, hi)`` of ``lambda21`` per leg (m).
        min_conditioning: the least ``conditioning`` accepted.
    """
    found = evaluate_stacked(model, "actuator_coordinates", params, [q])
    lambda21 = piston_displacements(params, q)
    return within(found.ok(), found["conditioning"], lambda21, stroke, min_conditioning)


def reachable_signed(
    model: Model,
    params: np.ndarray,
    q: np.ndarray,
    stroke: np.ndarray,
    min_conditioning: float,
) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`reachable`, with the sign of ``det J`` at each pose (NaN where not evaluated).

    The sign changes across a parallel singularity, so two reachable poses on a path whose
    signs differ have an unreachable pose between them, however close they are.
    """
    found = evaluate_stacked(model, "actuator_jacobian", params, [q])
    lambda21 = piston_displacements(params, q)
    ok = within(found.ok(), found["conditioning"], lambda21, stroke, min_conditioning)
    return ok, jacobian_sign(found.values)


def jacobian_sign(values: Mapping[str, np.ndarray]) -> np.ndarray:
    """The sign of ``det J`` from the components ``J11 .. J33`` of the actuator Jacobian."""
    J = [[values[f"J{i}{j}"] for j in (1, 2, 3)] for i in (1, 2, 3)]
    with np.errstate(invalid="ignore"):
        det = (
            J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1])
            - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0])
            + J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0])
        )
        return np.sign(det)


def within(
    ok: np.ndarray,
    conditioning: np.ndarray,
    lambda21: np.ndarray,
    stroke: np.ndarray,
    min_conditioning: float,
) -> np.ndarray:
    """(n,) bool: evaluated (``ok``), conditioning at least the threshold, strokes respected.

    ``lambda21`` is (n, 3); ``stroke`` (3, 2) or (n, 3, 2).
    """
    stroke = np.asarray(stroke, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        inside = (lambda21 >= stroke[..., 0]) & (lambda21 <= stroke[..., 1])
        return ok & (conditioning >= min_conditioning) & inside.all(axis=1)
