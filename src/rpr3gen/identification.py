"""Dynamic identification: the base parameters from measured motion and actuator efforts.

:func:`identify` fits the base parameters (:mod:`rpr3gen.parameters`: the efforts are linear in
the inertial parameters, ``tau = Y @ pi + tau_payload``), with viscous and Coulomb friction if
asked, by weighted least squares (docs/identification.md); it refuses data that leave a
parameter undetermined and warns where the motion inflates the standard deviations
(:mod:`rpr3gen.identifiability` gives the bounds).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen import sizes
from rpr3gen.control import actuator_jacobian
from rpr3gen.errors import IdentificationError, IdentificationWarning, InputError
from rpr3gen.identifiability import MAX_CONDITION, WARN_CONDITION, Assessment, assess, combinations
from rpr3gen.model import LEGS, Model
from rpr3gen.parameters import (
    BaseParameters,
    base_parameters,
    one_blas_thread,
    payload_efforts,
    regressor_and_codes,
    shared_matrix,
)
from rpr3gen.validation import Number, Optional, PoseRows, Reading, Sample, checked, match_width

MAX_WEIGHT_RATIO = 1e6
"""The largest ratio of two actuators' weights :func:`identify` takes: beyond it the least
weighted rows are below the others' rounding error, and the standard deviations overflow."""

__all__ = [
    "MAX_CONDITION",
    "MAX_WEIGHT_RATIO",
    "WARN_CONDITION",
    "Fit",
    "IdentificationError",
    "IdentificationWarning",
    "friction_columns",
    "friction_columns_of_rates",
    "friction_names",
    "identify",
]


def friction_names(legs: tuple[str, ...] = LEGS) -> tuple[str, ...]:
    """Friction parameters per actuator: viscous ``fv_A..`` then Coulomb ``fc_A..``."""
    return tuple(f"fv_{leg}" for leg in legs) + tuple(f"fc_{leg}" for leg in legs)


def friction_columns(
    model: Model, q: np.ndarray, qd: np.ndarray, backend: str = "numpy"
) -> np.ndarray:
    """(n, k, 2k): effort of actuator i += fv_i qa'_i + fc_i sign(qa'_i), ``qa' = J q'``."""
    rate = np.einsum("nij,nj->ni", actuator_jacobian(model, q, backend), qd)
    return friction_columns_of_rates(rate)


def friction_columns_of_rates(rate: np.ndarray) -> np.ndarray:
    """:func:`friction_columns` from the actuator rates ``qa'`` (n, k)."""
    k = rate.shape[1]
    out = np.zeros((len(rate), k, 2 * k))
    for i in range(k):
        out[:, i, i] = rate[:, i]
        out[:, i, k + i] = np.sign(rate[:, i])
    return out


@dataclass(frozen=True)
class Fit:
    """The result of :func:`identify`.

    Attributes:
        names: the estimated parameters: the base parameters (``base.names``), then with
            friction ``fv_A..`` (N m s/rad or N s/m) and ``fc_A..`` (N m or N), one per
            actuator.
        values: (len(names),) the estimates.
        std: (len(names),) their standard deviations (from the weighted residual).
        residual_rms: RMS of ``tau - predicted`` over every sample and actuator (N m or N).
        residual_rms_per_actuator: (k,) the same per actuator.
        condition_number: of the stacked regressor (base and friction columns, unweighted,
            scaled to unit norm): how well the motion excites the parameters.
        inflation: (len(names),) how much the motion inflates each standard deviation: its
            ratio to what it would be with that parameter's column orthogonal to the others
            (the square root of the variance inflation factor; 1 at best).
        weights: (k,) the weight of each actuator's rows (1 / its residual std).
        samples: the number of samples used.
        base: the base parameters (what ``values[:B]`` stand for).
        model: the model whose geometry the regressor used.
        friction: whether friction was estimated.
        identical_legs: whether the legs shared their parameters.
    """

    names: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray
    residual_rms: float
    residual_rms_per_actuator: np.ndarray
    condition_number: float
    inflation: np.ndarray
    weights: np.ndarray
    samples: int
    base: BaseParameters
    model: Model = field(repr=False)
    friction: bool = False
    identical_legs: bool = False
    backend: str = "numpy"

    @checked(q=PoseRows(), qd=PoseRows(), qdd=PoseRows(), same_length=[("q", "qd", "qdd")])
    def predict(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """The efforts (n, k) the identified parameters give for a motion (with friction)."""
        q, qd, qdd = np.asarray(q), np.asarray(qd), np.asarray(qdd)  # (n, k) each: checked
        s = self.model.structure
        match_width(s.dof, s.title, q=q, qd=qd, qdd=qdd)
        columns = _columns(self.model, q, qd, qdd, self.base, self.friction, self.backend)
        return columns @ self.values + payload_efforts(self.model, q, self.backend)

    def relative_std(self) -> np.ndarray:
        """``std / |value|`` (inf for a zero estimate): above ~0.1 a parameter is poorly known."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.values != 0, self.std / np.abs(self.values), np.inf)


def _columns(
    model: Model,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    base: BaseParameters,
    friction: bool,
    backend: str,
) -> np.ndarray:
    Y, _ = regressor_and_codes(model, q, qd, qdd, backend)
    return _design(model, Y, q, qd, base, friction, backend)


def _design(
    model: Model,
    Y: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    base: BaseParameters,
    friction: bool,
    backend: str,
) -> np.ndarray:
    """The columns of the fit (n, k, B [+ 2k]) from the per-leg regressor Y (n, k, P)."""
    if len(base.parameter_names) != Y.shape[2]:  # identical legs
        Y = Y @ shared_matrix(model)
    Yb = Y[..., list(base.columns)]
    if friction:
        Yb = np.concatenate([Yb, friction_columns(model, q, qd, backend)], axis=2)
    return Yb


def _refusal(names: tuple[str, ...], check: Assessment, max_condition: float) -> str | None:
    """Why the data cannot give the parameters (naming what they leave undetermined), or None."""
    p = len(names)
    advice = "; use a richer motion (rpr3gen excite)"
    if check.rank < p:
        s = check.singular_values  # below half the smallest non-zero one: the zero ones
        zero = s[check.rank - 1] / s[0] / 2 if check.rank else 1.0
        undetermined = "; ".join(combinations(names, check, zero))
        return (
            f"the data do not excite every parameter (rank {check.rank} of {p}): no effort "
            f"changes with {undetermined}, left undetermined{advice}"
        )
    if not check.condition_number <= max_condition:
        weak = "; ".join(combinations(names, check, 1.0 / max_condition))
        return (
            f"the data do not excite every parameter (condition number "
            f"{check.condition_number:.3g} > {max_condition:.3g}: an error of the data within "
            f"their own accuracy could make them rank-deficient): {weak} practically "
            f"undetermined{advice}"
        )
    return None


def _inflated(fit: Fit, warn_condition: float, most: int = 5) -> str:
    """The warning of a fit above ``warn_condition``: the most inflated estimates."""
    order = np.argsort(-fit.inflation, kind="stable")[:most]
    worst = ", ".join(
        f"{fit.names[k]} {fit.values[k]:.4g} ± {fit.std[k]:.3g} (std x{fit.inflation[k]:.3g})"
        for k in order
    )
    return (
        f"condition number {fit.condition_number:.3g} > {warn_condition:.3g}: the motion "
        f"excites some parameters weakly; fitted, but their standard deviations are inflated, "
        f"most of: {worst}"
    )


@checked(
    q=PoseRows(),
    qd=PoseRows(),
    qdd=PoseRows(),
    tau=PoseRows(),
    weights=Optional(Reading(None, positive=True)),
    warn_condition=Number(finite=False, greater=1.0),
    max_condition=Number(finite=False, greater=1.0),
    t=Optional(Sample()),
    same_length=[("q", "qd", "qdd", "tau", "t")],
)
@one_blas_thread
def identify(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    tau: ArrayLike,
    friction: bool = False,
    identical_legs: bool = False,
    *,
    weights: ArrayLike | None = None,
    warn_condition: float = WARN_CONDITION,
    max_condition: float = MAX_CONDITION,
    t: ArrayLike | None = None,
    backend: str = "numpy",
) -> Fit:
    """Estimate the base parameters (and friction) from measured motion and efforts.

    Weighted least squares on ``tau - tau_payload = Yb @ x`` (Gautier's method): an ordinary
    fit first, then each actuator's rows weighted by the inverse of its residual standard
    deviation (unless ``weights`` gives them), and the fit again. Standard deviations:
    ``sigma^2 (Wᵀ W)^-1`` with ``sigma^2`` the weighted residual's variance (``k n - p``
    degrees of freedom, ``k`` actuators; 3 for planar robots and Deltas, 6 for hexapods).

    Args:
        model: the robot whose geometry (and payload) the regressor uses; its masses are not.
        q: (n, k) the measured platform poses.
        qd: (n, 3) their velocities, as estimated (e.g. by a smoothing spline:
            :meth:`rpr3gen.Trajectory.from_positions`).
        qdd: (n, k) their accelerations, estimated likewise.
        tau: (n, k) the measured actuator efforts (``m10_*`` or ``f21z_*``; ``tau_*``).
        friction: also estimate viscous and Coulomb friction per actuator.
        identical_legs: the legs share one set of parameters (paper: B = 9 instead of 19).
        weights: (k,) the weight of each actuator's rows instead of the automatic ones
            (positive; only their ratios count, at most :data:`MAX_WEIGHT_RATIO`).
        warn_condition: above this condition number the fit warns (default
            :data:`WARN_CONDITION`, 1e3; :mod:`rpr3gen.identifiability` says why).
        max_condition: the largest condition number accepted (default :data:`MAX_CONDITION`,
            1e5, the hard bound).
        t: (n,) the samples' times, only to name a bad sample in an error.
        backend: ``"numpy"`` or ``"c"`` for the generated regressor.

    Raises:
        InputError: bad shapes, a value not finite, a singular pose (naming its sample).
        IdentificationError: fewer equations than unknowns, or data that do not excite every
            parameter (rank-deficient, or condition number above ``max_condition``): the
            message names the combinations of parameters left undetermined.

    Warns:
        IdentificationWarning: condition number above ``warn_condition`` (and not above
            ``max_condition``): the fit is returned, and the warning names the estimates whose
            standard deviations the motion inflates most.
    """
    q, qd, qdd, tau = (np.asarray(a) for a in (q, qd, qdd, tau))  # (n, k) each: checked
    s = model.structure
    k = s.dof
    match_width(k, s.title, q=q, qd=qd, qdd=qdd, tau=tau)
    if weights is not None and np.asarray(weights).shape != (k,):
        raise InputError(
            f"weights: must have shape ({k},) for the {s.title}, got {np.asarray(weights).shape}",
            argument="weights",
        )
    times = None if t is None else np.asarray(t)  # (n,), finite: checked
    n = q.shape[0]
    sizes.check("q", n, lambda k: k * sizes.IDENTIFY_SAMPLE, "the least-squares problem",
                unit="samples", argument="q")  # fmt: skip

    def where(i: int) -> str:
        return f"sample {i + 1}" + (f" (t = {times[i]:g} s)" if times is not None else "")

    bad = np.flatnonzero(~np.isfinite(tau).all(axis=1))
    if bad.size:
        raise InputError(f"tau: {where(int(bad[0]))}: an effort is not finite", argument="tau")
    base = base_parameters(model, identical_legs)
    Y, codes = regressor_and_codes(model, q, qd, qdd, backend)
    bad = np.flatnonzero(codes != 0)
    if bad.size:
        reason = {1: "a motion value is not finite", 2: "the pose is singular or out of reach"}
        raise InputError(
            f"{where(int(bad[0]))}: {reason.get(int(codes[bad[0]]), 'refused')} "
            f"({bad.size} of {n} samples refused)"
        )
    columns = _design(model, Y, q, qd, base, friction, backend)
    names = base.names + (friction_names(s.legs) if friction else ())
    p = len(names)
    if k * n <= p:
        raise IdentificationError(
            f"{n} samples give {k * n} equations for {p} unknowns: give more samples"
        )
    rhs = tau - payload_efforts(model, q, backend)

    def solve(w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        W = (columns * w[None, :, None]).reshape(-1, p)
        y = (rhs * w[None, :]).reshape(-1)
        x = np.linalg.lstsq(W, y, rcond=None)[0]
        return x, W, y

    check = assess(columns.reshape(-1, p))
    refusal = _refusal(names, check, max_condition)
    if refusal is not None:
        raise IdentificationError(refusal)
    if weights is None:
        x, _, _ = solve(np.ones(k))
        r = (rhs - columns @ x).reshape(n, k)
        dof = max(n - p / k, 1.0)
        sigma = np.sqrt((r**2).sum(axis=0) / dof)
        w = np.where(sigma > 0, 1.0 / np.where(sigma > 0, sigma, 1.0), 1.0)
        w = w / w.max()
    else:
        w = np.asarray(weights)  # (k,), positive and finite: checked
        w = w / w.max()  # only their ratios count; so none overflows the weighted rows
        if w.min() < 1.0 / MAX_WEIGHT_RATIO:
            raise InputError(
                f"weights: the largest is more than {MAX_WEIGHT_RATIO:g} times the smallest "
                f"({np.asarray(weights).tolist()}): the rows of the least weighted actuator "
                "would count for nothing (leave its samples out instead)",
                argument="weights",
            )
    x, W, y = solve(w)
    weighted = y - W @ x
    sigma2 = float(weighted @ weighted) / (k * n - p)
    R = np.linalg.qr(W, mode="r")
    import scipy.linalg

    Rinv = scipy.linalg.solve_triangular(R, np.eye(p))
    std = np.sqrt(sigma2 * np.sum(Rinv**2, axis=1))
    residual = rhs - columns @ x
    fit = Fit(
        names=names,
        values=x,
        std=std,
        residual_rms=float(np.sqrt(np.mean(residual**2))),
        residual_rms_per_actuator=np.sqrt(np.mean(residual**2, axis=0)),
        condition_number=check.condition_number,
        inflation=check.inflation,
        weights=w,
        samples=n,
        base=base,
        model=model,
        friction=friction,
        identical_legs=identical_legs,
        backend=backend,
    )
    if fit.condition_number > warn_condition:
        warnings.warn(_inflated(fit, warn_condition), IdentificationWarning, stacklevel=2)
    return fit
