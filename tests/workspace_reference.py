"""Brute-force inverse kinematics of the 3-RPR robot for the design-study tests.

Written from ``docs/conventions.md`` and ``docs/interfaces.md`` with NumPy alone (nothing from
``rpr3gen``): the legs' lengths straight from the geometry, the closure matrix of the
conditioning, and the reachability rule of the design studies (docs/design-studies.md).

Leg i: base pivot ``A1_i`` (world), platform joint ``p_i`` (platform frame),
``A3_i = G + R(phi) p_i``, ``|A1A3| = l0 + l2 + lambda21_i``. Conditioning: the Hadamard ratio
``|det W| / prod |row_i W|`` with rows ``(u_i, ((A3_i - G) x u_i) / rho)``, ``u_i = n_i`` (the
leg axis ``e_i`` turned by +90 degrees) with motors at A1, ``u_i = e_i`` with actuated slides;
``rho`` the platform's RMS joint radius.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

LEGS = ("A", "B", "C")
MIN_REACH = 1e-9  # the generated floor of reach = min (l0 + lambda21) / l0


def legs(params: Mapping[str, float], q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A3_i - A1_i`` (n, 3, 2) and ``A3_i - G`` (n, 3, 2) of the poses ``q`` (n, 3)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    out_leg, out_arm = [], []
    for leg in LEGS:
        px, py = params[f"x{leg}3"], params[f"y{leg}3"]
        arm = np.stack(
            [
                np.cos(q[:, 2]) * px - np.sin(q[:, 2]) * py,
                np.sin(q[:, 2]) * px + np.cos(q[:, 2]) * py,
            ],
            axis=1,
        )
        base = np.array([params[f"x{leg}1"], params[f"y{leg}1"]])
        out_leg.append(q[:, :2] + arm - base)
        out_arm.append(arm)
    return np.stack(out_leg, axis=1), np.stack(out_arm, axis=1)


def lambda21(params: Mapping[str, float], q: np.ndarray) -> np.ndarray:
    """Piston displacements (n, 3), m."""
    leg, _ = legs(params, q)
    return np.hypot(leg[..., 0], leg[..., 1]) - params["l0"] - params["l2"]


def conditioning(params: Mapping[str, float], actuation: str, q: np.ndarray) -> np.ndarray:
    """The Hadamard ratio of the closure matrix (n,), and nothing but geometry."""
    leg, arm = legs(params, q)
    e = leg / np.hypot(leg[..., 0], leg[..., 1])[..., None]
    u = np.stack([-e[..., 1], e[..., 0]], axis=-1) if actuation == "revolute" else e
    rho = np.sqrt(sum(params[f"x{k}3"] ** 2 + params[f"y{k}3"] ** 2 for k in LEGS) / 3)
    moment = (arm[..., 0] * u[..., 1] - arm[..., 1] * u[..., 0]) / rho
    W = np.concatenate([u, moment[..., None]], axis=-1)  # (n, 3, 3), one row per leg
    return np.abs(np.linalg.det(W)) / np.prod(np.linalg.norm(W, axis=-1), axis=-1)


def reachable(
    params: Mapping[str, float],
    actuation: str,
    q: np.ndarray,
    stroke: Sequence[Sequence[float]],
    min_conditioning: float,
) -> np.ndarray:
    """(n,) bool: piston joints in front of their pivots, within the strokes, conditioning at
    least ``min_conditioning``."""
    lam = lambda21(params, q)
    lo = np.array([s[0] for s in stroke])
    hi = np.array([s[1] for s in stroke])
    reach = ((params["l0"] + lam) / params["l0"]).min(axis=1)
    inside = ((lam >= lo) & (lam <= hi)).all(axis=1)
    return (reach >= MIN_REACH) & inside & (conditioning(params, actuation, q) >= min_conditioning)


def margin(
    params: Mapping[str, float],
    actuation: str,
    q: np.ndarray,
    stroke: Sequence[Sequence[float]],
    min_conditioning: float,
) -> np.ndarray:
    """(n,) how far each pose is from changing its reachability: the least distance of a
    stroke bound (m) and of the conditioning threshold (dimensionless)."""
    lam = lambda21(params, q)
    gaps = [np.abs(lam[:, k] - b) for k, s in enumerate(stroke) for b in s]
    gaps.append(np.abs(conditioning(params, actuation, q) - min_conditioning))
    return np.min(gaps, axis=0)
