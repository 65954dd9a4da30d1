"""Assembly modes of spatial robots: every platform pose with given actuator coordinates in which
every leg is in the model's working mode (docs/spatial-robots.md).

Deltas, in closed form: with the arms (or carriages) locked, each leg holds its platform point
``P_i = o + p_i`` on a sphere about its elbow ``E_i`` of radius ``L_i``, so the platform's
origin ``o`` is on the three spheres about ``E_i - p_i``: their intersection has at most two
points (trilateration). A candidate is a mode where the generated actuator coordinates give
``qa`` back (a leg in its other working mode gives another ``qa``).

Hexapods, by a documented search: Newton (the tracked forward kinematics) from
:data:`SEARCH_STARTS` deterministic starts around home, the distinct poses it converges to.
The general hexapod has up to 40 modes; the search finds those near the starts, always
including the one reached from home.
"""

from __future__ import annotations

import math

import numpy as np

from rpr3gen.backends import evaluate
from rpr3gen.model import Model

#: Newton starts of the hexapods' search: home, then this many more around it.
SEARCH_STARTS = 64
#: Two modes closer than this (m, and rad times the platform's size) are one.
SAME_MODE = 1e-7
#: A candidate is a mode where every actuator coordinate comes back within this (m or rad).
MODE_TOL = 1e-9


def point(model: Model, name: str, leg: str) -> np.ndarray:
    """A spatial model's home point or axis ``name`` of ``leg`` (``"b"``, ``"e"``, ``"p"``,
    ``"a"``, ``"bar"``, ``"u1"`` ...), (3,)."""
    return model.vector([f"{name}{a}_{leg}" for a in "xyz"])


def elbow(model: Model, leg: str, q1: np.ndarray) -> np.ndarray:
    """The elbow of ``leg`` (RUS, PUS, RSS2, PSS2) at joint 1's coordinates ``q1``, (n, 3):
    turned about the R axis through ``base``, or slid along the P axis."""
    B, a, E = (point(model, n, leg) for n in ("b", "a", "e"))
    q1 = np.atleast_1d(np.asarray(q1, dtype=float))
    if model.structure.actuated_kind == "P":
        return E + np.outer(q1, a)
    c0 = B + (a @ (E - B)) * a
    r0 = E - c0
    return c0 + np.outer(np.cos(q1), r0) + np.outer(np.sin(q1), np.cross(a, r0))


def delta_candidates(model: Model, qa: np.ndarray) -> np.ndarray:
    """The (at most two) origins on the three spheres of the locked legs, (k, 3)."""
    centres, radii = [], []
    for leg, q1 in zip(model.structure.legs, qa, strict=True):
        p, e = point(model, "p", leg), point(model, "e", leg)
        centres.append(elbow(model, leg, q1)[0] - p)
        radii.append(float(np.linalg.norm(p - e)))
    c1, c2, c3 = centres
    d = float(np.linalg.norm(c2 - c1))
    if not d > 0:
        return np.empty((0, 3))
    ex = (c2 - c1) / d
    i = float(ex @ (c3 - c1))
    ey = c3 - c1 - i * ex
    j = float(np.linalg.norm(ey))
    if not j > 0:
        return np.empty((0, 3))
    ey = ey / j
    ez = np.cross(ex, ey)
    r1, r2, r3 = radii
    x = (r1**2 - r2**2 + d**2) / (2 * d)
    y = (r1**2 - r3**2 + i**2 + j**2) / (2 * j) - i * x / j
    z2 = r1**2 - x**2 - y**2
    if z2 < 0:
        return np.empty((0, 3))
    z = math.sqrt(z2)
    base = c1 + x * ex + y * ey
    return np.array([base - z * ez, base + z * ez])


def _starts(model: Model) -> np.ndarray:
    """Home and :data:`SEARCH_STARTS` deterministic poses around it (a fixed seed)."""
    size = math.sqrt(
        sum(float(point(model, "p", leg) @ point(model, "p", leg))
            for leg in model.structure.legs) / len(model.structure.legs)
    )  # fmt: skip
    rng = np.random.default_rng(20261128)
    scale = np.array([size, size, size, 0.6, 0.6, 0.6]) * 0.5
    return np.vstack([np.zeros(6), rng.uniform(-1.0, 1.0, (SEARCH_STARTS, 6)) * scale])


def assembly_modes(model: Model, qa: np.ndarray, backend: str = "numpy") -> np.ndarray:
    """Every mode found of the actuator coordinates ``qa`` (k,): (m, k) poses, sorted by their
    coordinates (hexapods: by distance from home first)."""
    k = model.structure.dof
    if k == 3:
        candidates = delta_candidates(model, qa)
    else:
        starts = _starts(model)
        (candidates,), _ = evaluate(
            model, "forward_kinematics", (np.tile(qa, (len(starts), 1)), starts), backend
        )
    candidates = candidates[np.isfinite(candidates).all(axis=1)]
    if not len(candidates):
        return np.empty((0, k))
    (back,), _ = evaluate(model, "actuator_coordinates", (candidates,), backend)
    diff = back - qa
    if model.structure.actuated_kind == "R":
        diff = diff - 2 * np.pi * np.rint(diff / (2 * np.pi))
    with np.errstate(invalid="ignore"):
        good = np.abs(diff).max(axis=1) <= MODE_TOL
    kept: list[np.ndarray] = []
    for c in candidates[good]:
        if all(np.max(np.abs(c - m)) > SAME_MODE for m in kept):
            kept.append(c)
    kept.sort(key=lambda m: (float(np.linalg.norm(m)), tuple(m)))
    return np.array(kept).reshape(-1, k)
