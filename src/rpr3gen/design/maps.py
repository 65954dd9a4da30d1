"""The workspace map of one design at a fixed platform angle.

On a grid of positions of G at the angle ``phi``: whether the pose is reachable
(:mod:`rpr3gen.design.reach`), its ``conditioning`` (0 at a parallel singularity), the static
actuator efforts that hold the robot at rest there against gravity and the payload, and the
interval of platform angles ``[phi_min, phi_max]`` reachable through the point that contains
``phi``.

The interval is found for all points at once: march away from ``phi`` in steps of
:data:`ORIENTATION_STEP`, both ways, until a pose is not reachable (or half a turn is), then
bisect the last step :data:`BISECTIONS` times. A gap narrower than the step can be missed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rpr3gen import sizes
from rpr3gen.design.reach import (
    Limit,
    bounds,
    coordinates,
    design_limits,
    jacobian_sign,
    pose_box,
    reachable_signed,
    within,
)
from rpr3gen.design.stacked import evaluate_stacked, leg_lengths, piston_displacements
from rpr3gen.errors import ModelError
from rpr3gen.model import LEGS, Model
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.validation import Integer, Number, checked

__all__ = [
    "BISECTIONS",
    "COLUMNS",
    "DEFAULT_RESOLUTION",
    "ORIENTATION_STEP",
    "WorkspaceMap",
    "workspace",
]

DEFAULT_RESOLUTION = 200
"""Grid points along x and along y."""

ORIENTATION_STEP = math.radians(0.5)
"""Step of the march over platform angles (rad)."""

BISECTIONS = 30
"""Halvings of the last step at each edge of the orientation interval: to about 1e-11 rad."""

_MARCH = 16  # angle steps evaluated per point at a time

COLUMNS: tuple[str, ...] = (
    "x",
    "y",
    "phi",
    "reachable",
    "conditioning",
    "tau_A",
    "tau_B",
    "tau_C",
    "phi_min",
    "phi_max",
)
"""Columns of ``workspace.parquet`` (docs/interfaces.md, "Design studies")."""


@dataclass(frozen=True, eq=False)
class WorkspaceMap:
    """The maps of one design at one platform angle; arrays (ny, nx) unless said otherwise.

    Attributes:
        model: the design.
        phi: the platform angle of the map, rad.
        min_conditioning: the least ``conditioning`` counted reachable.
        limits: the bounded joint coordinates used, ``(leg, family, lo, hi)``
            (:func:`rpr3gen.design.reach.design_limits`: the paper's strokes on ``lambda21``,
            a general model's ``[limits]`` and the default travel of its prismatic joints).
        x: (nx,) positions of G along x0, the centres of the grid's cells (m).
        y: (ny,) along y0 (m).
        reachable: bool.
        conditioning: the generated ``conditioning`` of the pose, 0 at a parallel singularity
            and 1 at best, wherever every leg reaches the pose (the paper's format: wherever
            every leg has a length; NaN elsewhere), reachable or not.
        jacobian_sign: the sign of ``det J`` (the actuator Jacobian): it changes across a
            parallel singularity, where ``conditioning`` touches 0.
        coordinates: (ny, nx, k) the bounded joint coordinates, in the order of ``limits``
            (m or rad; NaN, or anything, where a leg does not reach the pose).
        tau: (ny, nx, 3) static actuator efforts of legs A, B, C holding the robot at rest
            (``tau``, or the paper's ``m10`` (N m) or ``f21z`` (N)), NaN where not reachable.
        phi_min, phi_max: the reachable interval of platform angles through the point that
            contains ``phi`` (rad), NaN where not reachable; at most half a turn each way.
        effort: the output family of ``tau``: ``m10``, ``f21z`` or ``tau``.
    """

    model: Model
    phi: float
    min_conditioning: float
    limits: tuple[Limit, ...]
    x: np.ndarray
    y: np.ndarray
    reachable: np.ndarray
    conditioning: np.ndarray
    jacobian_sign: np.ndarray
    coordinates: np.ndarray
    tau: np.ndarray
    phi_min: np.ndarray
    phi_max: np.ndarray
    effort: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "effort", self.model.structure.effort)

    @property
    def effort_unit(self) -> str:
        """``N·m`` (motors on revolute joints) or ``N`` (on prismatic joints)."""
        return "N·m" if self.model.structure.actuated_kind == "R" else "N"

    @property
    def stroke(self) -> tuple[tuple[float, float], ...] | None:
        """The paper's format: the strokes ``((lo, hi), ...)`` of legs A, B, C (m); else None."""
        if not self.model.structure.paper:
            return None
        return tuple((lo, hi) for _, _, lo, hi in self.limits)

    @property
    def lambda21(self) -> np.ndarray | None:
        """The paper's format: (ny, nx, 3) piston displacement of each leg (m); else None."""
        return self.coordinates if self.model.structure.paper else None

    @property
    def cell_area(self) -> float:
        """Area of one grid cell (m²)."""
        return _spacing(self.x) * _spacing(self.y)

    @property
    def area(self) -> float:
        """Reachable area (m²): the reachable cells times their area."""
        return float(np.count_nonzero(self.reachable)) * self.cell_area

    def limits_text(self, unicode: bool = True) -> str:
        """The limits in a line: ``strokes λ21 (m): [lo, hi], ...`` (the paper's format), or
        ``limits q1 [-0.25, 0.25] m`` per coordinate, once for the three legs when they show
        the same bounds (else ``q1_A [...] m, q1_B ...``)."""
        if self.model.structure.paper:
            strokes = ", ".join(f"[{lo:.3g}, {hi:.3g}]" for _, _, lo, hi in self.limits)
            return f"strokes {'λ21' if unicode else 'lambda21'} (m): {strokes}"
        if not self.limits:
            return "no joint limits"
        by_family: dict[str, list[Limit]] = {}
        for limit in self.limits:
            by_family.setdefault(limit[1], []).append(limit)
        parts = []
        for family, found in by_family.items():
            unit = "rad" if self.model.structure.leg[int(family[1]) - 1] == "R" else "m"
            shown = {leg: f"[{lo:.3g}, {hi:.3g}] {unit}" for leg, _, lo, hi in found}
            if len(shown) == len(LEGS) and len(set(shown.values())) == 1:
                parts.append(f"{family} {shown[LEGS[0]]}")
            else:
                parts += [f"{family}_{leg} {text}" for leg, text in shown.items()]
        return "limits " + ", ".join(parts)

    def base_points(self) -> list[tuple[str, float, float]]:
        """``(leg, x, y)``: each leg's base joint (the paper's pivot A1; a general model's joint
        1 at home)."""
        p = self.model.params
        if self.model.structure.paper:
            return [(leg, p[f"x{leg}1"], p[f"y{leg}1"]) for leg in LEGS]
        return [(leg, p[f"x1_{leg}"], p[f"y1_{leg}"]) for leg in LEGS]

    def columns(self) -> dict[str, np.ndarray]:
        """The grid as the columns :data:`COLUMNS`, one row per point, x fastest."""
        xx, yy = np.meshgrid(self.x, self.y)
        flat = {
            "x": xx.ravel(),
            "y": yy.ravel(),
            "phi": np.full(xx.size, self.phi),
            "reachable": self.reachable.ravel(),
            "conditioning": self.conditioning.ravel(),
        }
        for k, leg in enumerate(LEGS):
            flat[f"tau_{leg}"] = self.tau[..., k].ravel()
        flat["phi_min"] = self.phi_min.ravel()
        flat["phi_max"] = self.phi_max.ravel()
        return flat


def _spacing(centres: np.ndarray) -> float:
    return float(centres[1] - centres[0]) if centres.size > 1 else 0.0


def cell_centres(lo: float, hi: float, n: int) -> np.ndarray:
    """``n`` centres of equal cells between ``lo`` and ``hi``."""
    return lo + (np.arange(n) + 0.5) * ((hi - lo) / n)


@checked(
    phi=Number(unit="rad"),
    resolution=Integer(
        2, cost=lambda n: n * n * sizes.WORKSPACE_POINT, what="the workspace map's points"
    ),
)
def workspace(
    model: Model,
    phi: float = 0.0,
    resolution: int = DEFAULT_RESOLUTION,
    *,
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
) -> WorkspaceMap:
    """The workspace map of ``model`` at the platform angle ``phi``.

    The grid has ``resolution`` x ``resolution`` cells over the box that holds every position
    reachable at ``phi`` (:func:`rpr3gen.design.reach.pose_box`); each point is a cell's
    centre.

    Args:
        model: the design, of either format (its limits, or the defaults of
            :func:`rpr3gen.design.reach.design_limits`).
        phi: platform angle, rad.
        resolution: grid points along each axis, at least 2, at most what the memory limit
            allows (:mod:`rpr3gen.sizes`: about 2 KiB a point).
        min_conditioning: the least ``conditioning`` counted reachable, in [0, 1).

    Raises:
        InputError, InputTypeError: for a bad argument (:mod:`rpr3gen.validation`).
    """
    if model.structure.spatial:
        raise ModelError(
            f"workspace: the {model.structure.title} is spatial; its constant-orientation "
            "workspace is rpr3gen.design.spatial_workspace(model, ...)"
        )
    params = model.vector()
    limits = design_limits(model)
    bound = bounds(limits)
    x0, x1, y0, y1 = pose_box(model, phi)
    x, y = cell_centres(x0, x1, resolution), cell_centres(y0, y1, resolution)
    xx, yy = np.meshgrid(x, y)
    q = np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, phi)])
    zero = np.zeros_like(q)

    if model.structure.paper:
        statics = evaluate_stacked(model, "actuator_efforts", params, [q, zero, zero])
        lengths = leg_lengths(params, q)
        coords = piston_displacements(params, q)
        defined = np.isfinite(statics["conditioning"]) & (lengths > 0).all(axis=1)
        efforts = np.stack([statics[name] for name in statics.groups["tau"]], axis=1)
    else:  # the inverse dynamics at rest: joint coordinates, efforts, conditioning
        statics = evaluate_stacked(model, "inverse_dynamics", params, [q, zero, zero])
        coords = coordinates(model, params, q, limits, statics)
        defined = np.isfinite(statics["conditioning"])  # NaN where a leg does not reach
        efforts = np.stack([statics[f"tau_{leg}"] for leg in LEGS], axis=1)
    jacobian = evaluate_stacked(model, "actuator_jacobian", params, [q])
    conditioning = np.where(defined, statics["conditioning"], np.nan)
    ok = within(statics.ok(), conditioning, coords, bound, min_conditioning)
    sign = jacobian_sign(jacobian.values)
    tau = np.where(ok[:, np.newaxis], efforts, np.nan)

    phi_min = np.full(q.shape[0], np.nan)
    phi_max = np.full(q.shape[0], np.nan)
    inside = np.flatnonzero(ok)
    if inside.size:
        origin = (q[inside, :2], sign[inside])
        phi_min[inside] = phi - _edge(model, params, origin, phi, -1.0, bound, min_conditioning)
        phi_max[inside] = phi + _edge(model, params, origin, phi, +1.0, bound, min_conditioning)

    shape = xx.shape
    return WorkspaceMap(
        model=model,
        phi=phi,
        min_conditioning=float(min_conditioning),
        limits=tuple((leg, family, float(lo), float(hi)) for leg, family, lo, hi in limits),
        x=x,
        y=y,
        reachable=ok.reshape(shape),
        conditioning=conditioning.reshape(shape),
        jacobian_sign=sign.reshape(shape),
        coordinates=coords.reshape(*shape, len(limits)),
        tau=tau.reshape(*shape, 3),
        phi_min=phi_min.reshape(shape),
        phi_max=phi_max.reshape(shape),
    )


def _edge(
    model: Model,
    params: np.ndarray,
    origin: tuple[np.ndarray, np.ndarray],
    phi: float,
    direction: float,
    limits: np.ndarray,
    min_conditioning: float,
) -> np.ndarray:
    """How far (rad, in [0, pi]) the platform turns from ``phi`` in ``direction`` at each
    position, every pose on the way reachable.

    ``origin``: the positions (k, 2) and the sign of ``det J`` there at ``phi`` (k,). A pose
    counts as reached on the way only with the same sign: a change means that a parallel
    singularity lies between two steps, even one narrower than a step.
    """
    xy, sign = origin
    k = xy.shape[0]
    steps = math.ceil(math.pi / ORIENTATION_STEP)
    offsets = np.minimum(ORIENTATION_STEP * np.arange(1, steps + 1), math.pi)
    good = np.zeros(k)  # the largest offset known reachable
    bad = np.full(k, np.nan)  # the smallest offset known not reachable
    open_ = np.arange(k)

    def reaches(rows: np.ndarray, offset: np.ndarray) -> np.ndarray:
        q = np.column_stack([xy[rows], phi + direction * offset])
        ok, signs = reachable_signed(model, params, q, limits, min_conditioning)
        return ok & (signs == sign[rows])

    for start in range(0, steps, _MARCH):
        if not open_.size:
            break
        block = offsets[start : start + _MARCH]
        rows = np.repeat(open_, block.size)
        ok = reaches(rows, np.tile(block, open_.size)).reshape(open_.size, block.size)
        failed = ~ok.all(axis=1)
        first = np.argmin(ok, axis=1)
        hit = open_[failed]
        bad[hit] = block[first[failed]]
        after = first[failed] > 0
        good[hit[after]] = block[first[failed][after] - 1]
        good[open_[~failed]] = block[-1]
        open_ = open_[~failed]

    closed = np.flatnonzero(np.isfinite(bad))
    lo, hi = good[closed], bad[closed]
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        ok = reaches(closed, mid)
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    good[closed] = lo
    return good
