"""Dynamic identification: the inertial parameters from measured motion and actuator efforts.

The actuator efforts are linear in the inertial parameters ``pi`` (docs/identification.md,
docs/interfaces.md "Identification"): per moving body (the cylinder ``1`` and piston ``2`` of
each leg, the platform ``3``) its mass ``m``, first moments ``mcx, mcy`` and inertia ``Jzz``
about its joint point (A1, A2, G), in the body's frame (x along the leg axis e and y along its
normal n for the legs; the platform frame for the platform)::

    tau = Y(q, q', q'') @ pi + tau_payload(q)

``Y`` and ``tau_payload`` are generated (``rpr3_regressor``, ``rpr3_payload_efforts``, from the
same virtual-work derivation as the inverse dynamics, eqs. 10-17). Not every parameter can be
told from the efforts: the base parameters (Gautier's method, :func:`base_parameters`) are the
``B`` combinations the efforts determine (B = 19 per leg, 9 with identical legs, both
actuations). :func:`identify` estimates them by weighted least squares.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache, wraps
from typing import ParamSpec, TypeVar

import numpy as np
from numpy.typing import ArrayLike
from threadpoolctl import threadpool_limits

from rpr3gen import sizes, variants
from rpr3gen.backends import evaluate
from rpr3gen.control import actuator_jacobian, platform_radius
from rpr3gen.errors import IdentificationError, IdentificationWarning, InputError, Rpr3genError
from rpr3gen.identifiability import MAX_CONDITION, WARN_CONDITION, Assessment, assess, combinations
from rpr3gen.model import LEGS, Model
from rpr3gen.validation import Number, Optional, Reading, Rows, Sample, checked

MAX_WEIGHT_RATIO = 1e6
"""The largest ratio of two actuators' weights :func:`identify` takes: beyond it the least
weighted rows are below the others' rounding error, and the standard deviations overflow."""

__all__ = [
    "INERTIAL_PARAMETER_NAMES",
    "MAX_CONDITION",
    "MAX_WEIGHT_RATIO",
    "SHARED_PARAMETER_NAMES",
    "WARN_CONDITION",
    "BaseParameters",
    "Fit",
    "IdentificationError",
    "IdentificationWarning",
    "base_parameters",
    "base_regressor",
    "friction_columns",
    "friction_columns_of_rates",
    "friction_names",
    "identify",
    "inertial_parameters",
    "parameter_names",
    "payload_efforts",
    "regressor",
    "shared_matrix",
]

#: The four inertial parameters of a body, in order.
QUANTITIES: tuple[str, ...] = ("m", "mcx", "mcy", "Jzz")
#: Per leg A, B, C: its cylinder (1) and piston (2); then the platform (3).
INERTIAL_PARAMETER_NAMES: tuple[str, ...] = tuple(
    f"{q}_{body}"
    for body in (*(f"{k}{leg}" for leg in LEGS for k in "12"), "3")
    for q in QUANTITIES
)
#: With ``identical_legs``: the legs' parameters once, without the leg letter (P = 12).
SHARED_PARAMETER_NAMES: tuple[str, ...] = tuple(
    f"{q}_{body}" for body in ("1", "2", "3") for q in QUANTITIES
)


#: The order in which base parameters are chosen (the others are regrouped into them): the
#: platform's first, then per leg the cylinder's first moments and inertia, the piston's first
#: moments, its inertia and mass, the cylinder's mass last (docs/identification.md).
def _preference(identical_legs: bool) -> tuple[str, ...]:
    legs = ("",) if identical_legs else LEGS
    order = ["m_3", "mcx_3", "mcy_3", "Jzz_3"]
    for leg in legs:
        order += [f"mcx_1{leg}", f"mcy_1{leg}", f"Jzz_1{leg}", f"mcx_2{leg}", f"mcy_2{leg}"]
        order += [f"Jzz_2{leg}", f"m_2{leg}", f"m_1{leg}"]
    return tuple(order)


_P = ParamSpec("_P")
_R = TypeVar("_R")


def one_blas_thread(function: Callable[_P, _R]) -> Callable[_P, _R]:
    """Run ``function`` with one BLAS thread: its factorisations are small (a few hundred rows
    by a few dozen columns), so threads only fight over the cores (ten times slower on a
    loaded machine) and make the last bits of the results depend on their number."""

    @wraps(function)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with threadpool_limits(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return wrapper


def parameter_names(identical_legs: bool = False) -> tuple[str, ...]:
    """The P names of ``pi``: 28 per leg, or 12 with ``identical_legs``."""
    return SHARED_PARAMETER_NAMES if identical_legs else INERTIAL_PARAMETER_NAMES


def shared_matrix() -> np.ndarray:
    """``S`` (28 x 12): ``Y_shared = Y @ S`` sums each leg parameter's three columns."""
    S = np.zeros((len(INERTIAL_PARAMETER_NAMES), len(SHARED_PARAMETER_NAMES)))
    for i, name in enumerate(INERTIAL_PARAMETER_NAMES):
        quantity, body = name.split("_")
        S[i, SHARED_PARAMETER_NAMES.index(f"{quantity}_{body[0]}")] = 1.0
    return S


@checked()
def inertial_parameters(model: Model, identical_legs: bool = False) -> np.ndarray:
    """The model's ``pi`` (P,), in the order of :func:`parameter_names`.

    The paper's format: cylinder ``m1, m1 c1, m1 c1_perp, J1 + m1 (c1^2 + c1_perp^2)`` (about
    A1, x along the leg axis); piston ``m2, m2 c2, m2 c2_perp, J2 + m2 (c2^2 + c2_perp^2)``
    (about A2); platform ``m3, 0, 0, J3`` (centre of mass at G). Its model file describes one
    leg for all three, so ``identical_legs`` is accepted. The general format: per body, ``m``,
    ``m (c - P)`` (its centre of mass from its first joint point at home, world axes) and
    ``J + m |c - P|^2``; the platform's about G in the platform frame. ``identical_legs`` then
    needs the three legs' values equal (legs turned by 120 degrees are not: their first moments
    point other ways in the world's axes).

    Raises:
        InputError: ``identical_legs`` with a general model whose legs' parameters differ.
    """
    p = model.params

    def body(m: float, c: float, c_perp: float, j: float) -> list[float]:
        return [m, m * c, m * c_perp, j + m * (c**2 + c_perp**2)]

    if model.structure.paper:
        cylinder = body(p["m1"], p["c1"], p["c1_perp"], p["J1"])
        piston = body(p["m2"], p["c2"], p["c2_perp"], p["J2"])
        platform = [p["m3"], 0.0, 0.0, p["J3"]]
        legs = 1 if identical_legs else len(LEGS)
        return np.array((cylinder + piston) * legs + platform, dtype=float)
    per_leg = _general_legs(model)
    platform = body(p["m3"], p["cx3"], p["cy3"], p["J3"])
    if identical_legs:
        _check_identical_legs(model)
        return np.array(per_leg[0] + platform, dtype=float)
    return np.array([v for values in per_leg for v in values] + platform, dtype=float)


def _general_legs(model: Model) -> list[list[float]]:
    """A general model's inertial parameters of legs A, B, C (8 each: bodies 1 and 2)."""
    p = model.params
    per_leg = []
    for leg in LEGS:
        values = []
        for k in (1, 2):
            dx = p[f"cx{k}_{leg}"] - p[f"x{k}_{leg}"]
            dy = p[f"cy{k}_{leg}"] - p[f"y{k}_{leg}"]
            m, j = p[f"m{k}_{leg}"], p[f"J{k}_{leg}"]
            values += [m, m * dx, m * dy, j + m * (dx**2 + dy**2)]
        per_leg.append(values)
    return per_leg


def _check_identical_legs(model: Model) -> None:
    """Refuse ``identical_legs`` for a general model whose legs' inertial parameters differ:
    sharing them would fit, and predict with, a robot that is not this one (docs/interfaces.md,
    "Any planar 3-leg robot"). The paper's format describes one leg for all three.

    Raises:
        InputError: naming ``identical_legs`` and the first leg that differs from leg A.
    """
    if model.structure.paper:
        return
    per_leg = _general_legs(model)
    first = np.array(per_leg[0])
    for leg, values in zip(LEGS[1:], per_leg[1:], strict=True):
        if not np.allclose(values, first, rtol=1e-12, atol=1e-15):
            raise InputError(
                f"identical_legs: leg {leg}'s inertial parameters differ from leg A's "
                "(the general format's first moments are in the world's axes, so legs "
                "turned by 120 degrees differ); identify per leg",
                argument="identical_legs",
            )


def _check_names(model: Model) -> None:
    """The generated regressor's columns are :data:`INERTIAL_PARAMETER_NAMES`."""
    variant = variants.load(model.structure, model.generated)
    names = variant.tables.get(f"{variant.prefix}_inertial_parameter_names")
    if names != INERTIAL_PARAMETER_NAMES:
        raise Rpr3genError(
            f"{variant.folder}: the generated regressor's columns are not this runtime's "
            "INERTIAL_PARAMETER_NAMES (regenerate with rpr3gen generate)"
        )


def _regressor_and_codes(
    model: Model, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, backend: str
) -> tuple[np.ndarray, np.ndarray]:
    _check_names(model)
    (Y,), codes = evaluate(model, "regressor", (q, qd, qdd), backend)
    return Y.reshape(-1, 3, len(INERTIAL_PARAMETER_NAMES)), codes


@checked(q=Rows(3), qd=Rows(3), qdd=Rows(3), same_length=[("q", "qd", "qdd")])
def regressor(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    identical_legs: bool = False,
    backend: str = "numpy",
) -> np.ndarray:
    """``Y`` (n, 3, P): ``tau = Y @ pi + tau_payload`` for each sample (generated, eqs. 10-17).

    Rows: the efforts of legs A, B, C (``m10_*`` or ``f21z_*``); columns: :func:`parameter_names`.
    A singular pose gives a NaN row, as :func:`rpr3gen.inverse_dynamics` refuses it.

    Raises:
        InputError: ``identical_legs`` with a general model whose legs' parameters differ.
    """
    if identical_legs:
        _check_identical_legs(model)
    Y, _ = _regressor_and_codes(model, q, qd, qdd, backend)
    return Y @ shared_matrix() if identical_legs else Y


@checked(q=Rows(3))
def payload_efforts(model: Model, q: ArrayLike, backend: str = "numpy") -> np.ndarray:
    """``tau_payload`` (n, 3): the efforts holding the model's payload wrench at rest (generated,
    eqs. 12-17 with only the payload acting), which no inertial parameter scales."""
    (tau,), _ = evaluate(model, "payload_efforts", (q,), backend)
    return tau


# ----------------------------------------------------------------------------------------------
# Base parameters (Gautier's numerical method on the generated regressor).


@dataclass(frozen=True)
class BaseParameters:
    """The identifiable combinations of ``pi``.

    Attributes:
        names: (B,) the parameters kept as base; ``names[k]`` stands for ``matrix[k] @ pi``.
        matrix: (B, P), with ``Y @ pi == Yb @ (matrix @ pi)`` (``Yb``: :func:`base_regressor`).
        parameter_names: (P,) the columns of ``matrix``.
        unidentifiable: parameters that change no effort at all (e.g. ``m_1A``: A1 is fixed).
        regrouped: parameters that only enter base combinations of other parameters.
    """

    names: tuple[str, ...]
    matrix: np.ndarray
    parameter_names: tuple[str, ...]
    unidentifiable: tuple[str, ...]
    regrouped: tuple[str, ...]

    @property
    def columns(self) -> tuple[int, ...]:
        """The indices of the base parameters among :attr:`parameter_names`."""
        return tuple(self.parameter_names.index(n) for n in self.names)

    def expressions(self, digits: int = 6) -> tuple[str, ...]:
        """Each base parameter written out, e.g. ``Jzz_1A + Jzz_2A - 0.04 m_2A``."""
        out = []
        for k, row in enumerate(self.matrix):
            terms = []
            own = self.parameter_names.index(self.names[k])
            order = [own] + [j for j in range(len(row)) if j != own]
            for coeff, name in ((row[j], self.parameter_names[j]) for j in order):
                if coeff == 0.0:
                    continue
                sign = "-" if coeff < 0 else "+"
                size = abs(coeff)
                text = (
                    name if math.isclose(size, 1.0, rel_tol=1e-12) else f"{size:.{digits}g} {name}"
                )
                terms.append((sign, text))
            first_sign, first = terms[0]
            rest = "".join(f" {s} {t}" for s, t in terms[1:])
            out.append(("-" if first_sign == "-" else "") + first + rest)
        return tuple(out)


def _excitation_samples(model: Model, count: int) -> tuple[np.ndarray, ...]:
    """``count`` random poses near the central configuration, with random velocities and
    accelerations (a fixed seed: the same samples for the same model)."""
    rng = np.random.default_rng(20130)  # Briot and Gautier, 2013
    rho = platform_radius(model)
    q = rng.uniform(-1.0, 1.0, (count, 3)) * np.array([0.15 * rho, 0.15 * rho, 0.25])
    qd = rng.normal(0.0, 1.0, (count, 3)) * np.array([rho, rho, 1.0])
    qdd = rng.normal(0.0, 1.0, (count, 3)) * np.array([rho, rho, 1.0]) * 5.0
    return q, qd, qdd


@lru_cache(maxsize=32)
@one_blas_thread
def _base_parameters(model: Model, identical_legs: bool) -> BaseParameters:
    names = parameter_names(identical_legs)
    q, qd, qdd = _excitation_samples(model, 120)
    Y = regressor(model, q, qd, qdd, identical_legs)
    Y = Y[np.isfinite(Y).all(axis=(1, 2))]
    if len(Y) < 40:
        raise IdentificationError(
            "base parameters: the model's poses near its central configuration are singular"
        )
    W = Y.reshape(-1, len(names))
    scale = np.linalg.norm(W, axis=0)
    rtol = 1e-9
    unidentifiable = tuple(n for n, s in zip(names, scale, strict=True) if s <= rtol * scale.max())
    order = [names.index(n) for n in _preference(identical_legs)]
    # QR without pivoting in the order of preference: a column is dependent on the ones before
    # it when what remains of it is round-off against its norm.
    import scipy.linalg  # here, not at the top: `import rpr3gen` (every command) stays quick

    R = scipy.linalg.qr(W[:, order], mode="r")[0]
    base = sorted(
        order[k]
        for k in range(len(order))
        if abs(R[k, k]) > 1e-8 * max(scale[order[k]], 1e-300)
        and names[order[k]] not in unidentifiable
    )
    dependent = [j for j in range(len(names)) if j not in base]
    beta = np.linalg.lstsq(W[:, base], W[:, dependent], rcond=None)[0]
    beta[np.abs(beta) < 1e-9] = 0.0
    matrix = np.zeros((len(base), len(names)))
    matrix[np.arange(len(base)), base] = 1.0
    matrix[:, dependent] = beta
    regrouped = tuple(
        names[j] for j in dependent if names[j] not in unidentifiable and matrix[:, j].any()
    )
    matrix.setflags(write=False)
    return BaseParameters(
        names=tuple(names[j] for j in base),
        matrix=matrix,
        parameter_names=names,
        unidentifiable=unidentifiable,
        regrouped=regrouped,
    )


@checked()
def base_parameters(model: Model, identical_legs: bool = False) -> BaseParameters:
    """The base parameters of the model's geometry: Gautier's numerical method.

    The generated regressor is stacked over 120 fixed random samples near the central
    configuration (W, 360 x P); QR of W with its columns in a fixed order of preference keeps a
    column when it is independent of those before it, so the platform's parameters and the
    cylinder's are kept and the piston's mass and inertia regrouped into them; with ``W_b`` the
    kept and ``W_d`` the other columns, ``W_d = W_b beta`` exactly and ``matrix = [I beta]``.
    The regroupings this finds are stated in closed form in docs/identification.md (and
    tested equal). The matrix depends on the geometry (l2, the platform joints), not on the
    masses.

    Raises:
        InputError: ``identical_legs`` with a general model whose legs' parameters differ
            (so also :func:`base_regressor`, :func:`identify` and :func:`rpr3gen.excite`).
    """
    if identical_legs:
        _check_identical_legs(model)
    return _base_parameters(model, bool(identical_legs))


@checked(q=Rows(3), qd=Rows(3), qdd=Rows(3), same_length=[("q", "qd", "qdd")])
def base_regressor(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    identical_legs: bool = False,
    backend: str = "numpy",
) -> np.ndarray:
    """``Yb`` (n, 3, B): ``Y @ pi == Yb @ (base.matrix @ pi)``; the base parameters' columns."""
    base = base_parameters(model, identical_legs)
    Y = regressor(model, q, qd, qdd, identical_legs, backend)
    return Y[..., list(base.columns)]


# ----------------------------------------------------------------------------------------------
# Least squares.


def friction_names() -> tuple[str, ...]:
    """Friction parameters per actuator: viscous ``fv_A..C`` then Coulomb ``fc_A..C``."""
    return tuple(f"fv_{leg}" for leg in LEGS) + tuple(f"fc_{leg}" for leg in LEGS)


def friction_columns(
    model: Model, q: np.ndarray, qd: np.ndarray, backend: str = "numpy"
) -> np.ndarray:
    """(n, 3, 6): effort of actuator i += fv_i qa'_i + fc_i sign(qa'_i), ``qa' = J q'``."""
    rate = np.einsum("nij,nj->ni", actuator_jacobian(model, q, backend), qd)
    return friction_columns_of_rates(rate)


def friction_columns_of_rates(rate: np.ndarray) -> np.ndarray:
    """:func:`friction_columns` from the actuator rates ``qa'`` (n, 3)."""
    out = np.zeros((len(rate), 3, 6))
    for i in range(3):
        out[:, i, i] = rate[:, i]
        out[:, i, 3 + i] = np.sign(rate[:, i])
    return out


@dataclass(frozen=True)
class Fit:
    """The result of :func:`identify`.

    Attributes:
        names: the estimated parameters: the base parameters (``base.names``), then with
            friction ``fv_A..C`` (N m s/rad or N s/m) and ``fc_A..C`` (N m or N).
        values: (len(names),) the estimates.
        std: (len(names),) their standard deviations (from the weighted residual).
        residual_rms: RMS of ``tau - predicted`` over every sample and actuator (N m or N).
        residual_rms_per_actuator: (3,) the same per actuator.
        condition_number: of the stacked regressor (base and friction columns, unweighted,
            scaled to unit norm): how well the motion excites the parameters.
        inflation: (len(names),) how much the motion inflates each standard deviation: its
            ratio to what it would be with that parameter's column orthogonal to the others
            (the square root of the variance inflation factor; 1 at best).
        weights: (3,) the weight of each actuator's rows (1 / its residual std).
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

    @checked(q=Rows(3), qd=Rows(3), qdd=Rows(3), same_length=[("q", "qd", "qdd")])
    def predict(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """The efforts (n, 3) the identified parameters give for a motion (with friction)."""
        q, qd, qdd = np.asarray(q), np.asarray(qd), np.asarray(qdd)  # (n, 3) each: checked
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
    Y, _ = _regressor_and_codes(model, q, qd, qdd, backend)
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
    """The columns of the fit (n, 3, B [+ 6]) from the per-leg regressor Y (n, 3, 28)."""
    if base.parameter_names == SHARED_PARAMETER_NAMES:
        Y = Y @ shared_matrix()
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
    q=Rows(3),
    qd=Rows(3),
    qdd=Rows(3),
    tau=Rows(3),
    weights=Optional(Reading(3, positive=True)),
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
    ``sigma^2 (Wᵀ W)^-1`` with ``sigma^2`` the weighted residual's variance (``3n - p``
    degrees of freedom).

    Args:
        model: the robot whose geometry (and payload) the regressor uses; its masses are not.
        q: (n, 3) the measured platform poses.
        qd: (n, 3) their velocities, as estimated (e.g. by a smoothing spline:
            :meth:`rpr3gen.Trajectory.from_positions`).
        qdd: (n, 3) their accelerations, estimated likewise.
        tau: (n, 3) the measured actuator efforts (``m10_*`` or ``f21z_*``).
        friction: also estimate viscous and Coulomb friction per actuator.
        identical_legs: the legs share one set of parameters (B = 9 instead of 19).
        weights: (3,) the weight of each actuator's rows instead of the automatic ones
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
    q, qd, qdd, tau = (np.asarray(a) for a in (q, qd, qdd, tau))  # (n, 3) each: checked
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
    Y, codes = _regressor_and_codes(model, q, qd, qdd, backend)
    bad = np.flatnonzero(codes != 0)
    if bad.size:
        reason = {1: "a motion value is not finite", 2: "the pose is singular or out of reach"}
        raise InputError(
            f"{where(int(bad[0]))}: {reason.get(int(codes[bad[0]]), 'refused')} "
            f"({bad.size} of {n} samples refused)"
        )
    columns = _design(model, Y, q, qd, base, friction, backend)
    names = base.names + (friction_names() if friction else ())
    p = len(names)
    if 3 * n <= p:
        raise IdentificationError(
            f"{n} samples give {3 * n} equations for {p} unknowns: give more samples"
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
        x, _, _ = solve(np.ones(3))
        r = (rhs - columns @ x).reshape(n, 3)
        dof = max(n - p / 3, 1.0)
        sigma = np.sqrt((r**2).sum(axis=0) / dof)
        w = np.where(sigma > 0, 1.0 / np.where(sigma > 0, sigma, 1.0), 1.0)
        w = w / w.max()
    else:
        w = np.asarray(weights)  # (3,), positive and finite: checked
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
    sigma2 = float(weighted @ weighted) / (3 * n - p)
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
