"""Exciting trajectories for identification: a finite Fourier series optimised for the regressor.

A motion identifies the base parameters well when the stacked base regressor ``W`` (every
sample's ``Yb``, :func:`rpr3gen.parameters.base_regressor`) is well conditioned (Swevers,
Ganseman, Tukel, De Schutter and Van Brussel 1997; Gautier and Khalil 1992). The paper's two
motions are not: along either, W loses a rank (docs/identification.md). :func:`excite`
optimises, per platform coordinate k (x, y, phi; a spatial robot's x, y, z and a hexapod's a, b,
c), the periodic motion

    q_k(t) = q0_k + sum_{l=1..L} ( a_kl sin(l w t) - b_kl cos(l w t) ) / (l w),   w = 2 pi / T

(so ``q_k'`` is ``sum a_kl cos + b_kl sin``: the coefficients are velocity amplitudes) to
minimise ``log cond(W)`` (columns scaled to unit norm) inside the workspace: every sample
reachable and clear of singularities (``conditioning >= min_conditioning``), piston strokes
within the model's ``[limits] stroke`` (or ``|lambda21| <= l0 / 2`` when it sets none), and the
platform's accelerations within bounds; a spatial robot's platform also within
``max_excursion`` of home. SciPy's SLSQP does the optimisation, with the constraints at every
sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from rpr3gen import sizes, variants
from rpr3gen.backends import evaluate
from rpr3gen.control import platform_radius
from rpr3gen.errors import IdentificationError, InputError
from rpr3gen.identification import friction_columns_of_rates
from rpr3gen.model import LEGS, Model
from rpr3gen.parameters import base_parameters, one_blas_thread, shared_matrix
from rpr3gen.policy import joint_limits
from rpr3gen.trajectory import Trajectory
from rpr3gen.validation import Integer, Number, Optional, Reading, checked

__all__ = ["Excitation", "FourierMotion", "excite"]


@dataclass(frozen=True)
class FourierMotion:
    """The periodic motion of the module docstring: ``offset`` (k,), ``a``, ``b`` (k, L)."""

    period: float
    offset: np.ndarray
    a: np.ndarray
    b: np.ndarray

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q, q', q''`` (n, k) at the times ``t``."""
        t = np.asarray(t, dtype=float)
        w = 2 * math.pi / self.period
        harmonics = np.arange(1, self.a.shape[1] + 1) * w  # (L,)
        s, c = np.sin(np.outer(t, harmonics)), np.cos(np.outer(t, harmonics))  # (n, L)
        q = self.offset + (s @ (self.a / harmonics).T) - (c @ (self.b / harmonics).T)
        qd = c @ self.a.T + s @ self.b.T
        qdd = -(s @ (self.a * harmonics).T) + c @ (self.b * harmonics).T
        return q, qd, qdd

    def trajectory(self, samples: int) -> Trajectory:
        """One period sampled at ``samples`` times from 0 to ``period`` (both ends)."""
        t = np.linspace(0.0, self.period, samples)
        return Trajectory(t, *self.at(t))

    @classmethod
    def from_vector(cls, z: np.ndarray, period: float, harmonics: int, k: int = 3) -> FourierMotion:
        z = np.asarray(z, dtype=float)
        L = harmonics
        return cls(period, z[:k], z[k : k + k * L].reshape(k, L), z[k + k * L :].reshape(k, L))

    def vector(self) -> np.ndarray:
        return np.concatenate([self.offset, self.a.ravel(), self.b.ravel()])


@dataclass(frozen=True)
class Excitation:
    """The result of :func:`excite`.

    Attributes:
        motion: the optimised Fourier motion.
        trajectory: one period of it, sampled.
        condition_number: cond(W) of the optimised motion (unit-norm columns).
        initial_condition_number: cond(W) of the starting motion.
        iterations: SLSQP iterations.
        min_conditioning: the smallest ``conditioning`` along the motion.
        ranges: ``{output name: (lo, hi)}``, the range along the motion of each joint
            coordinate the constraints bound (the paper's ``lambda21_A..C``; a general model's
            limited coordinates).
        min_reach: the smallest ``reach`` along the motion (away from serial singularities).
    """

    motion: FourierMotion
    trajectory: Trajectory
    condition_number: float
    initial_condition_number: float
    iterations: int
    min_conditioning: float
    ranges: dict[str, tuple[float, float]]
    min_reach: float

    @property
    def stroke(self) -> np.ndarray:
        """(k, 2): :attr:`ranges` as an array (the paper: each leg's piston displacements)."""
        return np.array(list(self.ranges.values()), dtype=float).reshape(-1, 2)


#: A general model without ``[limits]`` keeps its legs at least this far from a serial
#: singularity (``reach``, 1 at home) along an exciting motion.
MIN_REACH = 0.3
#: A spatial robot's default ``max_excursion``: its platform's translation from home within
#: this fraction of its shortest leg (joint 1 to the platform at home), and (hexapods) each
#: angle within the second value (rad).
SPATIAL_EXCURSION = (0.2, 0.3)


def _limits(model: Model) -> list[tuple[str, float, float]]:
    """``(output name, lo, hi)`` of each bounded joint coordinate: the model's limits, or the
    paper's default ``|lambda21| <= l0 / 2``."""
    limits = [(f"{family}_{leg}", lo, hi) for leg, family, lo, hi in joint_limits(model)]
    if not limits and model.structure.paper:
        half = model.params["l0"] / 2
        limits = [(f"lambda21_{leg}", -half, half) for leg in LEGS]
    return limits


@checked(
    harmonics=Integer(1),
    period=Number(greater=0.0, unit="s"),
    samples=Integer(10),
    max_acceleration=Reading(2, positive=True),
    max_excursion=Optional(Reading(2)),
    seed=Integer(0),
    max_iterations=Integer(1, 2**31 - 1),
)
@one_blas_thread
def excite(
    model: Model,
    *,
    harmonics: int = 5,
    period: float = 10.0,
    samples: int = 201,
    min_conditioning: float = 0.1,
    max_acceleration: tuple[float, float] = (2.0, 10.0),
    identical_legs: bool = False,
    friction: bool = False,
    seed: int = 0,
    max_iterations: int = 100,
    max_excursion: tuple[float, float] | None = None,
    backend: str = "numpy",
) -> Excitation:
    """Optimise an exciting Fourier motion for identifying ``model``'s base parameters.

    Args:
        model: the robot (geometry, stroke limits; its masses do not matter).
        harmonics: L, the number of harmonics per coordinate, at most ``(samples - 1) // 2``
            (the samples of a period must resolve the highest harmonic).
        period: T (s), the motion's period; the lowest harmonic is 1/T.
        samples: samples per period at which the constraints and W are evaluated, >= 10.
        min_conditioning: the floor on ``conditioning`` (1 at best, 0 singular).
        max_acceleration: the bound on the translations' accelerations (m/s^2: |x''|, |y''|, a
            spatial robot's |z''|) and on the angles' (rad/s^2: |phi''|, a hexapod's |a''|,
            |b''|, |c''|), both > 0.
        identical_legs: optimise for the legs' shared base parameters (the paper's robot: 9
            instead of 19).
        friction: include the friction columns in W.
        seed: of the random starting coefficients, >= 0.
        max_iterations: SLSQP's limit.
        max_excursion: a bound on the platform's distance from home, each translation (m)
            and each angle (rad), positive (``inf``: none); a spatial robot's default is
            :func:`default_excursion` (a fifth of its shortest leg, 0.3 rad), a planar robot's
            none (its joint limits or strokes bound it).
        backend: of the generated regressor and inverse dynamics (``"c"`` is several times
            quicker for a hexapod's 130 columns).

    Raises:
        InputTypeError, InputError: a bad argument (:mod:`rpr3gen.validation`); sizes beyond
            the memory limit (:mod:`rpr3gen.sizes`).
        IdentificationError: no feasible starting motion (the central configuration itself
            violates the constraints).
    """
    s = model.structure
    k = s.dof
    if max_excursion is not None and not all(v > 0 for v in max_excursion):  # NaN too
        raise InputError(
            f"max_excursion: must be positive (inf: no bound), got {list(max_excursion)}",
            argument="max_excursion",
        )
    if harmonics > (samples - 1) // 2:
        raise InputError(
            f"harmonics: {harmonics} harmonics need more than {2 * harmonics} samples per "
            f"period, got samples = {samples}; at most {(samples - 1) // 2}, or more samples",
            argument="harmonics",
        )
    sizes.check("samples", samples, lambda n: sizes.excite_cost(1, n), "the exciting motion",
                least=10, argument="samples")  # fmt: skip
    sizes.check("harmonics", harmonics, lambda h: sizes.excite_cost(h, samples),
                "the exciting motion's optimisation", least=1, argument="harmonics")  # fmt: skip
    base = base_parameters(model, identical_legs)
    columns = list(base.columns)
    limits = _limits(model)
    stroke = np.array([[lo, hi] for _, lo, hi in limits]).reshape(-1, 2)
    t = np.linspace(0.0, period, samples)
    angular = np.array([name in ("phi", "a", "b", "c") for name in s.pose])
    acc = np.where(angular, max_acceleration[1], max_acceleration[0]).astype(float)
    rho = _size(model)
    if max_excursion is None and s.spatial:
        max_excursion = default_excursion(model)
    excursion = (
        None
        if max_excursion is None
        else np.where(angular, max_excursion[1], max_excursion[0]).astype(float)
    )
    w = 2 * math.pi / period
    # Scale of the coefficients (velocity amplitudes): a platform excursion of about rho / 10
    # (m) and 0.2 rad at the lowest harmonic.
    amplitude = np.where(angular, 0.2, rho / 10)
    scale = np.concatenate(
        [amplitude, np.repeat(amplitude * w, harmonics), np.repeat(amplitude * w, harmonics)]
    )
    home = np.zeros(k)

    def motion(u: np.ndarray) -> FourierMotion:
        return FourierMotion.from_vector(u * scale, period, harmonics, k)

    names = _output_index(model)
    rate_family = s.rate(s.actuated)
    conditioning_column = names["conditioning"]
    min_reach = 0.0 if s.paper else MIN_REACH
    stroke_columns = [names[name] for name, _, _ in limits]
    rate_columns = [names[f"{rate_family}_{leg}"] for leg in s.legs]

    @lru_cache(maxsize=64)  # SLSQP asks for f and the constraints at the same points
    def _at(key: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        q, qd, qdd = motion(np.frombuffer(key)).at(t)
        (out,), codes = evaluate(model, "inverse_dynamics", (q, qd, qdd), backend)
        (Y,), _ = evaluate(model, "regressor", (q, qd, qdd), backend)
        Y = Y.reshape(samples, k, -1)
        if identical_legs:
            Y = Y @ shared_matrix(model)
        W = Y[..., columns]
        if friction:  # the actuator rates, from the inverse dynamics
            W = np.concatenate([W, friction_columns_of_rates(out[:, rate_columns])], axis=2)
        return W.reshape(-1, W.shape[2]), out, codes, q, qdd

    def at(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return _at(np.asarray(u, dtype=float).tobytes())

    # The best feasible point the optimiser has evaluated: SLSQP can end (or stop at its
    # iteration limit) outside the constraints, or fail its line search far from the start.
    best_value, best_u = math.inf, np.zeros(0)

    def log_cond(u: np.ndarray) -> float:
        W = at(u)[0]
        if not np.isfinite(W).all():
            return 80.0
        norms = np.linalg.norm(W, axis=0)
        if (norms == 0).any():
            return 80.0
        # cond(W) = cond(R) of W = QR: the small R's singular values cost far less.
        s = np.linalg.svd(np.linalg.qr(W / norms, mode="r"), compute_uv=False)
        value = float(np.log(s[0] / s[-1])) if s[-1] > 0 else 80.0
        nonlocal best_value, best_u
        if value < best_value and constraints(u).min() >= 0:
            best_value, best_u = value, np.array(u, dtype=float)
        return value

    def constraints(u: np.ndarray) -> np.ndarray:
        _, out, codes, q, qdd = at(u)
        cond = out[:, conditioning_column]
        lam = out[:, stroke_columns]
        ok = codes[:, None] == 0
        width = np.ptp(stroke, axis=1)
        parts = [
            np.where(codes == 0, cond - min_conditioning, -1.0),
            np.where(codes == 0, _reach(model, q, out, names, backend) - min_reach, -1.0),
            (np.where(ok, lam - stroke[:, 0], -1.0) / width).ravel(),
            (np.where(ok, stroke[:, 1] - lam, -1.0) / width).ravel(),
            (1.0 - np.abs(qdd) / acc).ravel(),
        ]
        if excursion is not None:
            parts.append((1.0 - np.abs(q - home) / excursion).ravel())
        return np.nan_to_num(np.concatenate(parts), nan=-1.0)

    rng = np.random.default_rng(seed)
    start = np.concatenate([np.zeros(k), rng.uniform(-1.0, 1.0, 2 * k * harmonics) / harmonics])
    # The optimiser sees the constraints with a margin, so that an iterate a hair outside
    # them (SLSQP's are, before it converges) still keeps the true ones.
    margin = 1e-3
    for _ in range(30):  # shrink the random start until it is feasible
        if constraints(start).min() >= margin:
            break
        start[k:] *= 0.5
    else:
        raise IdentificationError(
            "excite: the central configuration itself violates the constraints (joint "
            "limits, conditioning, reach); relax them"
        )
    initial = math.exp(log_cond(start))
    import scipy.optimize  # here, not at the top: `import rpr3gen` (every command) stays quick

    result = scipy.optimize.minimize(
        log_cond,
        start,
        method="SLSQP",
        constraints=[{"type": "ineq", "fun": lambda u: constraints(u) - margin}],
        options={"maxiter": max_iterations, "ftol": 1e-6},
    )
    log_cond(result.x)  # counted as a candidate if it keeps the constraints
    chosen = best_u if best_u.size else start
    found = motion(chosen)
    traj = found.trajectory(samples)
    (out,), _ = evaluate(model, "inverse_dynamics", (traj.q, traj.qd, traj.qdd), backend)
    lam = out[:, stroke_columns]
    return Excitation(
        motion=found,
        trajectory=traj,
        condition_number=math.exp(log_cond(chosen)),
        initial_condition_number=initial,
        iterations=int(result.nit),
        min_conditioning=float(out[:, names["conditioning"]].min()),
        ranges={
            name: (float(lo), float(hi))
            for (name, _, _), lo, hi in zip(limits, lam.min(axis=0), lam.max(axis=0), strict=True)
        },
        min_reach=float(_reach(model, traj.q, out, names, backend).min()),
    )


def default_excursion(model: Model) -> tuple[float, float]:
    """A spatial robot's default ``max_excursion``: :data:`SPATIAL_EXCURSION` scaled by its
    shortest leg (m, rad)."""
    return (SPATIAL_EXCURSION[0] * _size(model), SPATIAL_EXCURSION[1])


def _size(model: Model) -> float:
    """The platform's size (m) that scales the motion: a planar robot's platform radius, a
    spatial robot's shortest leg (joint 1's point to the platform point, at home)."""
    if not model.structure.spatial:
        return platform_radius(model)
    p = model.params
    return min(
        math.dist([p[f"p{a}_{leg}"] for a in "xyz"], [p[f"b{a}_{leg}"] for a in "xyz"])
        for leg in model.structure.legs
    )


def _reach(
    model: Model, q: np.ndarray, out: np.ndarray, names: dict[str, int], backend: str
) -> np.ndarray:
    """(n,) the smallest leg reach (1 at home, 0 at a serial singularity) of each sample: the
    inverse dynamics' ``reach``, or a spatial robot's ``pose_diagnostics``."""
    if "reach" in names:
        return out[:, names["reach"]]
    (diagnostics,), _ = evaluate(model, "pose_diagnostics", (q,), backend)
    return diagnostics[:, : len(model.structure.legs)].min(axis=1)


def _output_index(model: Model) -> dict[str, int]:
    info = variants.load(model.structure, model.generated).function("inverse_dynamics")
    return {name: k for k, name in enumerate(info.outputs[0].names)}
