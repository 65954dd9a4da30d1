"""Which platform poses a design reaches: joint limits, singularities and the grid around them.

A pose is **reachable** when the generated code evaluates it (every leg reaches the pose in its
working mode and clear of a serial singularity: ``reach`` at least the generated floor
``MIN_REACH``), its ``conditioning`` is at least the threshold (as ``rpr3gen simulate
--min-conditioning``, default 1e-3) and every bounded joint coordinate is within its limits
(:func:`design_limits`).

The paper's format: the pistons in front of their base pivots, and the piston displacements
``lambda21`` within the strokes. **Assumption** (design studies only): a model without
``[limits] stroke`` gets the stroke ``lambda21`` in ``[-l0, l0 + l2]`` for every leg: from the
piston joint on its base pivot (the serial singularity that ``reach`` guards) to twice the
central leg length ``l0 + l2``. Without a bound the workspace has no edge; the paper gives none,
and its two motions stay inside this one (``lambda21`` from -0.076 to 0.22 m). Set ``[limits]
stroke`` in the model file to study your own.

The general format: the model's ``[limits]`` bound the joint coordinates they name.
**Assumption** (design studies only): every prismatic joint coordinate that ``[limits]`` leaves
unbounded stays within plus or minus its leg's length at home, ``L = |P2 - P1| + |P3 - P2|``
(the distance from joint 1's point to joint 3's through joint 2's; where the three points
coincide, the platform's RMS joint radius). A prismatic joint alone has no edge, and a workspace
needs one; a revolute joint needs none (the links' lengths bound the legs' reach, and the serial
singularities where a leg folds or stretches are the edge). Set ``[limits]`` in the model file
(``"q2" = [lo, hi]`` for every leg, ``"A.q2"`` for one) to study your robot's travel. The
paper's robot in the general format gets ``q2`` in ``[-(l0 + l2), l0 + l2]`` this way, not the
paper format's ``[-l0, l0 + l2]``: give ``q2 = [-l0, l0 + l2]`` to compare the two.

**The grid's box** holds every position of G reachable at the angle ``phi``: a leg's platform
joint lies within the sum of its links' lengths plus the travel of its prismatic joints 2 and 3
of its base joint's point, which is fixed (revolute joint 1) or slides along its rail within its
limits (prismatic joint 1). The paper's format: within ``l0 + l2 + hi`` of the pivot (``hi``
the stroke's upper bound).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np

from rpr3gen.design.stacked import (
    PARAM_INDEX,
    Evaluated,
    evaluate_stacked,
    piston_displacements,
)
from rpr3gen.model import LEGS, Model

__all__ = [
    "Limit",
    "bounds",
    "coordinates",
    "design_limits",
    "design_model",
    "design_stroke",
    "jacobian_sign",
    "leg_boxes_meet",
    "leg_length",
    "pose_box",
    "pose_extent",
    "reachable",
    "reachable_signed",
    "within",
]

Limit = tuple[str, str, float, float]
"""A bounded joint coordinate: ``(leg, output family, lo, hi)``, e.g. ``("A", "q2", -0.3,
0.3)`` or the paper's ``("A", "lambda21", -0.1, 0.3)`` (m or rad)."""


def design_stroke(model: Model) -> tuple[tuple[float, float], ...]:
    """The paper's format: the stroke ``((lo, hi), ...)`` of legs A, B, C (m, bounds on
    ``lambda21``): the model's ``[limits] stroke``, else ``[-l0, l0 + l2]`` (the module's
    **Assumption**)."""
    if model.stroke is not None:
        return model.stroke
    l0, l2 = model.params["l0"], model.params["l2"]
    return ((-l0, l0 + l2),) * len(LEGS)


def leg_length(model: Model, leg: str) -> float:
    """A general model's leg ``leg`` at home: ``|P2 - P1| + |P3 - P2|`` (m), or the platform's
    RMS joint radius where the three joint points coincide."""
    p = model.params
    points = [(p[f"x{j}_{leg}"], p[f"y{j}_{leg}"]) for j in (1, 2, 3)]
    length = math.dist(points[0], points[1]) + math.dist(points[1], points[2])
    if length > 1e-9:
        return length
    return math.sqrt(sum(p[f"x3_{k}"] ** 2 + p[f"y3_{k}"] ** 2 for k in LEGS) / len(LEGS))


def design_limits(model: Model) -> tuple[Limit, ...]:
    """Every bounded joint coordinate of a design study, legs A, B, C then joints 1, 2, 3.

    The paper's format: ``lambda21`` of each leg within :func:`design_stroke`. The general
    format: the model's ``[limits]``, and every prismatic coordinate they leave unbounded
    within plus or minus :func:`leg_length` (the module's **Assumption**).
    """
    if model.structure.paper:
        stroke = design_stroke(model)
        return tuple((leg, "lambda21", lo, hi) for leg, (lo, hi) in zip(LEGS, stroke, strict=True))
    given = model.limits or {}
    found: list[Limit] = []
    for leg in LEGS:
        for j in (1, 2, 3):
            family = model.structure.coordinate(j)
            if f"{leg}.{family}" in given:
                lo, hi = given[f"{leg}.{family}"]
                found.append((leg, family, lo, hi))
            elif model.structure.leg[j - 1] == "P":
                length = leg_length(model, leg)
                found.append((leg, family, -length, length))
    return tuple(found)


def design_model(model: Model) -> Model:
    """``model`` with the limits of :func:`design_limits` as its own (the paper's ``stroke``,
    the general ``limits``): the model whose refusals (:func:`rpr3gen.policy.invalid_samples`)
    a design study's are."""
    if model.structure.paper:
        return dataclasses.replace(model, stroke=design_stroke(model))
    limits = {f"{leg}.{family}": (lo, hi) for leg, family, lo, hi in design_limits(model)}
    return dataclasses.replace(model, limits=limits or None)


def bounds(limits: Sequence[Limit]) -> np.ndarray:
    """(k, 2): the ``(lo, hi)`` of each limit."""
    return np.array([(lo, hi) for _, _, lo, hi in limits], dtype=np.float64).reshape(-1, 2)


def pose_extent(params: np.ndarray, phi: float, hi: np.ndarray) -> np.ndarray:
    """The paper's format: a box ``(x0, x1, y0, y1)`` that holds every position of G reachable
    at the angle ``phi``.

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


def _leg_boxes(model: Model, phi: float) -> list[tuple[float, float, float, float]]:
    """The box of G's positions that each leg of a design reaches at ``phi`` alone."""
    p = model.params
    c, s = math.cos(phi), math.sin(phi)
    rails = {(leg, family): (lo, hi) for leg, family, lo, hi in design_limits(model)}
    travel = {key: max(abs(lo), abs(hi)) for key, (lo, hi) in rails.items()}
    kinds = model.structure.leg
    boxes = []
    for leg in LEGS:
        points = [(p[f"x{j}_{leg}"], p[f"y{j}_{leg}"]) for j in (1, 2, 3)]
        radius = math.dist(points[0], points[1]) + math.dist(points[1], points[2])
        radius += sum(
            travel[(leg, model.structure.coordinate(j))] for j in (2, 3) if kinds[j - 1] == "P"
        )
        x1, y1 = points[0]
        xs, ys = [x1], [y1]
        if kinds[0] == "P":  # joint 1's point slides along its rail
            lo, hi = rails[(leg, model.structure.coordinate(1))]
            ux, uy = p[f"ux1_{leg}"], p[f"uy1_{leg}"]
            xs, ys = [x1 + lo * ux, x1 + hi * ux], [y1 + lo * uy, y1 + hi * uy]
        x3, y3 = points[2]
        gx, gy = c * x3 - s * y3, s * x3 + c * y3  # G to joint 3's point at phi
        boxes.append(
            (min(xs) - radius - gx, max(xs) + radius - gx, min(ys) - radius - gy,
             max(ys) + radius - gy)
        )  # fmt: skip
    return boxes


def pose_box(model: Model, phi: float) -> tuple[float, float, float, float]:
    """The box ``(x0, x1, y0, y1)`` of the workspace map of ``model`` at ``phi``: the one that
    holds every position of G reachable at that angle (the module's rule for the general
    format, :func:`pose_extent` for the paper's) or, when the legs' boxes share none, the box of
    them all together (nothing is reachable, the map shows where the legs could be)."""
    if model.structure.paper:
        params = model.vector()
        hi = np.array(design_stroke(model))[:, 1]
        x0, x1, y0, y1 = pose_extent(params, phi, hi)
        if not (x0 < x1 and y0 < y1):
            unbounded = [np.where(np.arange(3) == k, hi[k], np.inf) for k in range(3)]
            boxes = [pose_extent(params, phi, h) for h in unbounded]
            return _union(boxes)
        return float(x0), float(x1), float(y0), float(y1)
    x0, x1, y0, y1 = leg_boxes_meet(model, phi)
    if not (x0 < x1 and y0 < y1):
        return _union([np.array(b) for b in _leg_boxes(model, phi)])
    return x0, x1, y0, y1


def leg_boxes_meet(model: Model, phi: float) -> tuple[float, float, float, float]:
    """A general model: the box ``(x0, x1, y0, y1)`` that holds every position of G reachable
    at ``phi`` (the module's rule), empty (``x0 >= x1`` or ``y0 >= y1``) when the legs' boxes
    share none."""
    boxes = _leg_boxes(model, phi)
    return (
        max(b[0] for b in boxes),
        min(b[1] for b in boxes),
        max(b[2] for b in boxes),
        min(b[3] for b in boxes),
    )


def _union(boxes: Sequence[np.ndarray]) -> tuple[float, float, float, float]:
    return (
        float(min(b[0] for b in boxes)),
        float(max(b[1] for b in boxes)),
        float(min(b[2] for b in boxes)),
        float(max(b[3] for b in boxes)),
    )


def coordinates(
    model: Model,
    params: np.ndarray,
    q: np.ndarray,
    limits: Sequence[Limit],
    found: Evaluated | None = None,
    rows: np.ndarray | None = None,
) -> np.ndarray:
    """(n, k): the bounded joint coordinates (``limits``' order) at the poses ``q`` (n, 3).

    The paper's format: ``lambda21`` from the geometry (eq. 5). The general format: the joint
    coordinates of the generated code (``found``, when it already holds them: the inverse
    dynamics at rest; else the actuator coordinates when only the motors' joints are bounded,
    or the inverse dynamics at rest); only at ``rows`` when given (NaN elsewhere).

    Args:
        model: picks the generated variant.
        params: (P,) or (P, n) parameter vectors.
        q: (n, 3) poses.
        limits: the bounded coordinates (:func:`design_limits`); for the paper's format, the
            three legs' ``lambda21``.
        found: the inverse dynamics at ``q``, if evaluated.
        rows: evaluate these poses only.
    """
    n = q.shape[0]
    if not limits:
        return np.empty((n, 0))
    if model.structure.paper:
        return piston_displacements(params, q)
    names = [f"{family}_{leg}" for leg, family, _, _ in limits]
    if found is None:
        at = np.arange(n) if rows is None else rows
        out = np.full((n, len(names)), np.nan)
        if not at.size:
            return out
        p = params[:, at] if params.ndim == 2 else params
        found = _evaluate_coordinates(model, limits, p, q[at])
        out[at] = np.stack([found[name] for name in names], axis=1)
        return out
    return np.stack([found[name] for name in names], axis=1)


def _evaluate_coordinates(
    model: Model, limits: Sequence[Limit], params: np.ndarray, q: np.ndarray
) -> Evaluated:
    """A general model's generated function that gives the bounded coordinates at ``q``, with
    ``conditioning`` and the return codes: ``actuator_coordinates`` when only the motors'
    joints are bounded (or none), else the inverse dynamics at rest (every joint's)."""
    if all(family == model.structure.actuator for _, family, _, _ in limits):
        return evaluate_stacked(model, "actuator_coordinates", params, [q])
    zero = np.zeros_like(q)
    return evaluate_stacked(model, "inverse_dynamics", params, [q, zero, zero])


def reachable(
    model: Model,
    params: np.ndarray,
    q: np.ndarray,
    limits: np.ndarray,
    min_conditioning: float,
) -> np.ndarray:
    """(n,) bool: the poses ``q`` (n, 3) that the designs reach (see the module).

    Args:
        model: picks the generated variant (and the bounded coordinates: :func:`design_limits`
            of ``model``, whose bounds ``limits`` gives per design).
        params: (P,) or (P, n) parameter vectors.
        q: (n, 3) poses.
        limits: (k, 2) or (n, k, 2) bounds ``(lo, hi)`` of the bounded coordinates (the paper:
            ``lambda21`` of each leg, m).
        min_conditioning: the least ``conditioning`` accepted.
    """
    if model.structure.paper:
        found = evaluate_stacked(model, "actuator_coordinates", params, [q])
        lambda21 = piston_displacements(params, q)
        return within(found.ok(), found["conditioning"], lambda21, limits, min_conditioning)
    bounded = design_limits(model)
    found = _evaluate_coordinates(model, bounded, params, q)
    coords = coordinates(model, params, q, bounded, found)
    return within(found.ok(), found["conditioning"], coords, limits, min_conditioning)


def reachable_signed(
    model: Model,
    params: np.ndarray,
    q: np.ndarray,
    limits: np.ndarray,
    min_conditioning: float,
) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`reachable`, with the sign of ``det J`` at each pose (NaN where not evaluated).

    The sign changes across a parallel singularity, so two reachable poses on a path whose
    signs differ have an unreachable pose between them, however close they are.
    """
    found = evaluate_stacked(model, "actuator_jacobian", params, [q])
    ok = found.ok()
    if model.structure.paper:
        coords = piston_displacements(params, q)
    else:
        coords = coordinates(model, params, q, design_limits(model), rows=np.flatnonzero(ok))
    ok = within(ok, found["conditioning"], coords, limits, min_conditioning)
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
    values: np.ndarray,
    limits: np.ndarray,
    min_conditioning: float,
) -> np.ndarray:
    """(n,) bool: evaluated (``ok``), conditioning at least the threshold, limits respected.

    ``values`` is (n, k), the bounded coordinates; ``limits`` (k, 2) or (n, k, 2).
    """
    limits = np.asarray(limits, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        inside = (values >= limits[..., 0]) & (values <= limits[..., 1])
        return ok & (conditioning >= min_conditioning) & inside.all(axis=1)
