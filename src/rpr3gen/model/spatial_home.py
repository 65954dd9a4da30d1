"""The geometry behind the spatial reader's checks (:mod:`rpr3gen.model.spatial`): unit
vectors, the symmetric designs' turns about z, inertia tensors, and the conditioning at home.

Pure numpy on arrays; nothing here raises: the reader turns each result into its one-line
:class:`~rpr3gen.errors.ModelError`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from rpr3gen.structure import Structure

__all__ = [
    "INERTIA_TOL",
    "conditioning",
    "home_conditioning",
    "inertia_entries",
    "inertia_matrix",
    "inertia_problem",
    "turn_z",
    "turned",
    "unit",
]

#: Relative tolerance of an inertia tensor's checks: its smallest principal moment above this
#: times its largest (positive definite), and the triangle inequality up to this fraction.
INERTIA_TOL = 1e-6
#: Below this fraction of the largest principal moment, the smallest counts as zero.
_DEFINITE_TOL = 1e-12


def unit(v: Sequence[float] | np.ndarray) -> np.ndarray | None:
    """``v / |v|``, free of overflow and underflow for any finite ``v``; None for zero."""
    a = np.asarray(v, dtype=float)
    largest = float(np.abs(a).max())
    if largest == 0.0:
        return None
    a = a / largest
    return a / float(np.linalg.norm(a))


def inertia_matrix(entries: Sequence[float]) -> np.ndarray:
    """The symmetric tensor of ``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]``."""
    xx, yy, zz, xy, xz, yz = (float(v) for v in entries)
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def inertia_entries(matrix: np.ndarray) -> tuple[float, ...]:
    """``(Ixx, Iyy, Izz, Ixy, Ixz, Iyz)`` of a tensor."""
    m = np.asarray(matrix, dtype=float)
    return tuple(float(v) for v in (m[0, 0], m[1, 1], m[2, 2], m[0, 1], m[0, 2], m[1, 2]))


def inertia_problem(matrix: np.ndarray) -> str | None:
    """Why ``matrix`` is not a rigid body's inertia tensor about its centre of mass (not
    positive definite, or its principal moments break the triangle inequality), or None."""
    largest = float(np.abs(matrix).max())
    if largest == 0.0:
        return "it is zero (a body has positive principal moments)"
    moments = np.linalg.eigvalsh(matrix / largest)  # ascending; scaled against overflow
    shown = ", ".join(f"{m * largest:.6g}" for m in moments)
    if not moments[0] > _DEFINITE_TOL * moments[2]:
        return f"not positive definite: its principal moments are {shown} (each must be positive)"
    if moments[0] + moments[1] < moments[2] * (1.0 - INERTIA_TOL):
        return (
            f"its principal moments {shown} break the triangle inequality (the largest must not "
            "exceed the sum of the other two)"
        )
    return None


def turn_z(degrees: int) -> np.ndarray:
    """The rotation about the world z axis by 0, 120 or 240 degrees (exact sines)."""
    s = {0: 0.0, 120: math.sqrt(3.0) / 2.0, 240: -math.sqrt(3.0) / 2.0}[degrees]
    c = 1.0 if degrees == 0 else -0.5
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def turned(leg: Mapping[str, Any], R: np.ndarray) -> dict[str, Any]:
    """A leg turned by ``R``: its points, directions and centres of mass (arrays of shape
    ``(3,)`` or ``(n, 3)``) and its inertia tensors (``(n, 3, 3)``, as ``R I R^T``)."""
    out: dict[str, Any] = {}
    for key, value in leg.items():
        if key in ("base", "axis", "elbow", "platform", "bar", "u_axes", "com"):
            out[key] = None if value is None else np.asarray(value) @ R.T
        elif key == "inertia":
            out[key] = np.array([R @ m @ R.T for m in value])
        else:
            out[key] = value
    return out


def conditioning(points: np.ndarray, directions: np.ndarray) -> float:
    """``|det A| / prod |a_k|`` of the constraint matrix whose columns are the unit wrenches
    ``(w_k, (p_k x w_k) / rho)`` of forces along ``directions`` (unit, ``(6, 3)``) at
    ``points`` (``(6, 3)``, platform frame), ``rho`` the points' RMS distance from the origin:
    1 for orthogonal wrenches, 0 at a parallel singularity (docs/spatial-robots.md)."""
    rho = math.sqrt(float(np.mean(np.sum(points * points, axis=1))))
    if rho == 0.0:
        return 0.0
    A = np.vstack([directions.T, np.cross(points, directions).T / rho])
    norms = np.linalg.norm(A, axis=0)
    if float(norms.min()) == 0.0:
        return 0.0
    return abs(float(np.linalg.det(A / norms)))


def home_conditioning(structure: Structure, params: Mapping[str, float]) -> float:
    """The conditioning at home (:func:`conditioning`) of a spatial model's parameters
    ``params`` (:meth:`Structure.param_names`): hexapods, a force along each leg (UPS) or rod
    at its platform point; Deltas, one along each rod at its lower joint."""
    points: list[np.ndarray] = []
    directions: list[Any] = []
    for leg in structure.legs:

        def get(name: str, leg: str = leg) -> np.ndarray:
            return np.array([params[f"{name}{a}_{leg}"] for a in "xyz"])

        p = get("p")
        w = unit(p - get("b" if structure.leg == "UPS" else "e"))
        if structure.leg in ("RSS2", "PSS2"):
            half = 0.5 * params[f"w_{leg}"] * get("bar" if structure.leg == "PSS2" else "a")
            points += [p + half, p - half]
            directions += [w, w]
        else:
            points.append(p)
            directions.append(w)
    return conditioning(np.array(points), np.array(directions))
