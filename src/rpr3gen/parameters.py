"""The actuator efforts linear in the inertial parameters, and the base parameters.

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
actuations). :func:`rpr3gen.identification.identify` estimates them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache, wraps
from typing import ParamSpec, TypeVar

import numpy as np
from numpy.typing import ArrayLike
from threadpoolctl import threadpool_limits

from rpr3gen import spatial_inertia, variants
from rpr3gen.backends import evaluate
from rpr3gen.control import platform_radius
from rpr3gen.errors import GeneratedCodeError, IdentificationError, InputError
from rpr3gen.model import LEGS, Model
from rpr3gen.validation import PoseRows, checked, match_width

__all__ = [
    "INERTIAL_PARAMETER_NAMES",
    "SHARED_PARAMETER_NAMES",
    "BaseParameters",
    "base_parameters",
    "base_regressor",
    "inertial_parameter_names",
    "inertial_parameters",
    "one_blas_thread",
    "parameter_names",
    "payload_efforts",
    "regressor",
    "regressor_and_codes",
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
#: moments, its inertia and mass, the cylinder's mass last (docs/identification.md). A spatial
#: robot's: the platform's, then per leg each body's first moments and inertia, then its
#: bodies' masses from the platform down (docs/spatial-robots.md).
def _preference(model: Model, identical_legs: bool) -> tuple[str, ...]:
    names = inertial_parameter_names(model, identical_legs)
    if model.structure.spatial:
        platform = [n for n in names if n.endswith("_3")]
        bodies = [n for n in names if not n.endswith("_3")]
        masses = sorted((n for n in bodies if n.startswith("m_")), key=lambda n: n[2] == "1")
        return tuple(platform + [n for n in bodies if not n.startswith("m_")] + masses)
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
    """The P names of a planar robot's ``pi``: 28 per leg, or 12 with ``identical_legs``."""
    return SHARED_PARAMETER_NAMES if identical_legs else INERTIAL_PARAMETER_NAMES


def _shared(name: str) -> str:
    """``mcx_1A`` -> ``mcx_1``: the name of a leg parameter shared by the legs."""
    quantity, body = name.split("_")
    return f"{quantity}_{body[:-1]}" if len(body) > 1 else name


@checked()
def inertial_parameter_names(model: Model, identical_legs: bool = False) -> tuple[str, ...]:
    """The P names of ``model``'s ``pi``: a planar robot's :func:`parameter_names`; a spatial
    robot's per body ``m, mcx, mcy, mcz, Ixx, Iyy, Izz, Ixy, Ixz, Iyz`` (``_1A``, ``_2A``, ...),
    per rod pair of a Delta's leg ``m, mc, I`` (``_rA``), then the platform's (``_3``); with
    ``identical_legs`` each leg parameter once, without the leg letter."""
    s = model.structure
    if not s.spatial:
        return parameter_names(identical_legs)
    names = spatial_inertia.parameter_names(s.leg, "".join(s.legs))
    return tuple(dict.fromkeys(_shared(n) for n in names)) if identical_legs else names


def shared_matrix(model: Model | None = None) -> np.ndarray:
    """``S`` (P x P_shared; planar 28 x 12): ``Y_shared = Y @ S`` sums each leg parameter's
    columns over the legs."""
    full = INERTIAL_PARAMETER_NAMES if model is None else inertial_parameter_names(model)
    shared = SHARED_PARAMETER_NAMES if model is None else inertial_parameter_names(model, True)
    S = np.zeros((len(full), len(shared)))
    for i, name in enumerate(full):
        S[i, shared.index(_shared(name))] = 1.0
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

    A spatial robot's (docs/spatial-robots.md): per body ``m``, ``m (c - P)`` and the inertia
    tensor about ``P`` (its first joint point at home; world axes), per rod pair ``m``,
    ``m fr L`` and ``Ir + m (fr L)^2``, the platform's about its frame's origin.

    Raises:
        InputError: ``identical_legs`` with a general model whose legs' parameters differ.
    """
    p = model.params
    s = model.structure
    if s.spatial:
        pi = spatial_inertia.inertial_parameters(s.leg, "".join(s.legs), p)
        if identical_legs:
            _check_identical_legs(model)
            S = shared_matrix(model)
            return np.array([pi[np.flatnonzero(S[:, j])[0]] for j in range(S.shape[1])])
        return pi

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
    if model.structure.spatial:
        s = model.structure
        pi = spatial_inertia.inertial_parameters(s.leg, "".join(s.legs), model.params)
        per = len(pi) - 10  # the platform's ten last
        per_leg = [list(row) for row in pi[:per].reshape(len(s.legs), -1)]
        letters: tuple[str, ...] = s.legs
    else:
        per_leg, letters = _general_legs(model), LEGS
    first = np.array(per_leg[0])
    for leg, values in zip(letters[1:], per_leg[1:], strict=True):
        if not np.allclose(values, first, rtol=1e-12, atol=1e-15):
            raise InputError(
                f"identical_legs: leg {leg}'s inertial parameters differ from leg A's "
                "(the general format's first moments are in the world's axes, so legs "
                "turned by 120 degrees differ); identify per leg",
                argument="identical_legs",
            )


def _check_names(model: Model) -> tuple[str, ...]:
    """The generated regressor's columns are :func:`inertial_parameter_names`' (returned)."""
    variant = variants.load(model.structure, model.generated)
    names = variant.tables.get(f"{variant.prefix}_inertial_parameter_names")
    expected = inertial_parameter_names(model)
    if names != expected:
        raise GeneratedCodeError(
            f"{variant.folder}: the generated regressor's columns are not this runtime's "
            "inertial parameter names (regenerate with rpr3gen generate)"
        )
    return expected


def regressor_and_codes(
    model: Model, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, backend: str
) -> tuple[np.ndarray, np.ndarray]:
    """The per-leg regressor ``Y`` (n, k, P) and each sample's return code (0: evaluated)."""
    names = _check_names(model)
    (Y,), codes = evaluate(model, "regressor", (q, qd, qdd), backend)
    return Y.reshape(-1, model.structure.dof, len(names)), codes


@checked(q=PoseRows(), qd=PoseRows(), qdd=PoseRows(), same_length=[("q", "qd", "qdd")])
def regressor(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    identical_legs: bool = False,
    backend: str = "numpy",
) -> np.ndarray:
    """``Y`` (n, k, P): ``tau = Y @ pi + tau_payload`` for each sample (generated, eqs. 10-17).

    Rows: the efforts of legs A, B, C (``m10_*`` or ``f21z_*``; a hexapod's A to F); columns:
    :func:`inertial_parameter_names`. A singular pose gives a NaN row, as
    :func:`rpr3gen.inverse_dynamics` refuses it. A spatial robot's column ``j`` is its inverse
    dynamics' efforts for the model numbers whose ``pi`` is ``e_j`` (``P`` evaluations).

    Raises:
        InputError: ``identical_legs`` with a general model whose legs' parameters differ.
    """
    s = model.structure
    match_width(s.dof, s.title, q=np.asarray(q), qd=np.asarray(qd), qdd=np.asarray(qdd))
    if identical_legs:
        _check_identical_legs(model)
    Y, _ = regressor_and_codes(model, q, qd, qdd, backend)
    return Y @ shared_matrix(model) if identical_legs else Y


@checked(q=PoseRows())
def payload_efforts(model: Model, q: ArrayLike, backend: str = "numpy") -> np.ndarray:
    """``tau_payload`` (n, 3): the efforts holding the model's payload wrench at rest (generated,
    eqs. 12-17 with only the payload acting), which no inertial parameter scales; a spatial
    robot's (n, 6) or (n, 3), from its inverse dynamics at rest without gravity."""
    match_width(model.structure.dof, model.structure.title, q=np.asarray(q))
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
    """``count`` random poses near the central configuration (a spatial robot's: near home),
    with random velocities and accelerations (a fixed seed: the same samples for the same
    model)."""
    rng = np.random.default_rng(20130)  # Briot and Gautier, 2013
    if model.structure.spatial:
        return _spatial_samples(model, count, rng)
    rho = platform_radius(model)
    q = rng.uniform(-1.0, 1.0, (count, 3)) * np.array([0.15 * rho, 0.15 * rho, 0.25])
    qd = rng.normal(0.0, 1.0, (count, 3)) * np.array([rho, rho, 1.0])
    qdd = rng.normal(0.0, 1.0, (count, 3)) * np.array([rho, rho, 1.0]) * 5.0
    return q, qd, qdd


def _spatial_samples(
    model: Model, count: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A spatial robot's: translations within a tenth of its shortest leg (home to platform
    point) and, for a hexapod, turns within 0.15 rad, around home."""
    s = model.structure
    p = model.params
    size = min(
        float(np.linalg.norm([p[f"p{a}_{leg}"] - p[f"b{a}_{leg}"] for a in "xyz"]))
        for leg in s.legs
    )
    scale = np.array([0.1 * size] * 3 + [0.15] * (s.dof - 3))
    q = rng.uniform(-1.0, 1.0, (count, s.dof)) * scale
    qd = rng.normal(0.0, 1.0, (count, s.dof)) * scale * 10.0
    qdd = rng.normal(0.0, 1.0, (count, s.dof)) * scale * 50.0
    return q, qd, qdd


@lru_cache(maxsize=32)
@one_blas_thread
def _base_parameters(model: Model, identical_legs: bool) -> BaseParameters:
    names = inertial_parameter_names(model, identical_legs)
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
    # A column that is round-off (a translating platform's first moments: ~1e-16 of the
    # others) would take a direction of its own in the QR below: left out of it.
    order = [names.index(n) for n in _preference(model, identical_legs) if n not in unidentifiable]
    # QR without pivoting in the order of preference: a column is dependent on the ones before
    # it when what remains of it is round-off against its norm.
    import scipy.linalg  # here, not at the top: `import rpr3gen` (every command) stays quick

    R = scipy.linalg.qr(W[:, order], mode="r")[0]
    base = sorted(
        order[k] for k in range(len(order)) if abs(R[k, k]) > 1e-8 * max(scale[order[k]], 1e-300)
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


@checked(q=PoseRows(), qd=PoseRows(), qdd=PoseRows(), same_length=[("q", "qd", "qdd")])
def base_regressor(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    identical_legs: bool = False,
    backend: str = "numpy",
) -> np.ndarray:
    """``Yb`` (n, k, B): ``Y @ pi == Yb @ (base.matrix @ pi)``; the base parameters' columns."""
    base = base_parameters(model, identical_legs)
    Y = regressor(model, q, qd, qdd, identical_legs, backend)
    return Y[..., list(base.columns)]
