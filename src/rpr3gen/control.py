"""The control model: forward kinematics from the actuators, Jacobian, dynamics in control form.

For a controller that reads the three actuator encoders and commands the actuators
(docs/interfaces.md, "Control model"). Actuator coordinates ``qa`` are ``phi10_A..C`` (rad,
revolute actuation) or ``lambda21_A..C`` (m, prismatic), measured from the central
configuration; efforts ``tau`` are ``m10_A..C`` (N m) or ``f21z_A..C`` (N).

Every function evaluates generated code (:func:`rpr3gen.evaluate`), with ``backend="numpy"`` or
``"c"``, and takes arrays of n samples (or one sample as a vector). A singular pose (a piston joint
on or behind its base pivot, or ``conditioning`` under the generated floor, as
:func:`rpr3gen.inverse_dynamics` refuses them) gives a NaN row, not an exception; so does forward
kinematics with no assembly mode.

Assembly modes (:func:`assembly_modes`) come from the generated closed forms: both roots of
``A cos(phi) + B sin(phi) + C = 0`` with revolute actuation; with prismatic actuation the real
roots of the generated sextic in ``t = tan(phi/2)`` (``numpy.roots``), turned into poses by the
generated back substitution and polished by Newton steps on ``qa(q) = qa`` with the generated
Jacobian. The tracked forward kinematics (:func:`forward_kinematics`) is, with ``backend="c"``,
the generated C (damped Newton from the reference, with a fallback to every mode); with
``"numpy"``, every mode and the nearest.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen.backends import evaluate
from rpr3gen.model import LEGS, Model
from rpr3gen.validation import Instance, PoseRows, Reading, Rows, checked, match_width

__all__ = [
    "actuator_coordinates",
    "actuator_coordinates_hessian",
    "actuator_coordinates_jacobian",
    "actuator_efforts",
    "actuator_jacobian",
    "assembly_modes",
    "forward_dynamics",
    "forward_kinematics",
    "jacobian_rate",
    "platform_radius",
    "platform_velocity",
    "task_space_dynamics",
]

#: The (j, k) pairs, j <= k, of the generated ``H`` output's 6 entries per leg, in order.
HESSIAN_PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
#: Newton polish of a prismatic mode: converged when every actuator residual is below this (m).
POLISH_TOL = 1e-11
#: Newton steps allowed to polish a root of the sextic into a mode.
POLISH_STEPS = 8
#: Two modes closer than this (in (x, y, rho phi), m) are one.
SAME_MODE = 1e-9


@checked()
def platform_radius(model: Model) -> float:
    """``rho``: the platform's RMS joint radius (m), which turns ``phi`` into a distance."""
    p = model.params
    names = (
        [(f"x{leg}3", f"y{leg}3") for leg in LEGS]
        if model.structure.paper
        else [(f"x3_{leg}", f"y3_{leg}") for leg in LEGS]
    )
    return math.sqrt(sum(p[x] ** 2 + p[y] ** 2 for x, y in names) / 3)


def _width(model: Model, **arrays: np.ndarray) -> int:
    """The model's pose width (3 or 6), the arrays checked against it."""
    match_width(model.structure.dof, model.structure.title, **arrays)
    return model.structure.dof


@checked(q=PoseRows())
def actuator_coordinates(model: Model, q: ArrayLike, backend: str = "numpy") -> np.ndarray:
    """``qa`` of each pose, (n, 3): the actuator part of the inverse kinematics (eq. 5); a
    spatial robot's (n, 6) or (n, 3) (docs/spatial-robots.md)."""
    _width(model, q=np.asarray(q))
    (qa,), _ = evaluate(model, "actuator_coordinates", (q,), backend)
    return qa


@checked(q=PoseRows())
def actuator_jacobian(model: Model, q: ArrayLike, backend: str = "numpy") -> np.ndarray:
    """``J = d qa / d q``, (n, 3, 3), so that ``qa' = J q'`` (eq. 6 differentiated); a
    hexapod's (n, 6, 6)."""
    k = _width(model, q=np.asarray(q))
    (J,), _ = evaluate(model, "actuator_jacobian", (q,), backend)
    return J.reshape(-1, k, k)


@checked(q=PoseRows())
def actuator_coordinates_jacobian(
    model: Model, q: ArrayLike, backend: str = "numpy"
) -> tuple[np.ndarray, np.ndarray]:
    """``qa`` (n, 3) and ``J = d qa / d q`` (n, 3, 3) of each pose in one evaluation (eqs. 5,
    6), their common terms computed once: :func:`actuator_coordinates`' and
    :func:`actuator_jacobian`'s values to round-off."""
    k = _width(model, q=np.asarray(q))
    (qa, J), _ = evaluate(model, "actuator_coordinates_jacobian", (q,), backend)
    return qa, J.reshape(-1, k, k)


@checked(q=Rows(3))
def actuator_coordinates_hessian(
    model: Model, q: ArrayLike, backend: str = "numpy"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``qa`` (n, 3), ``J = d qa / d q`` (n, 3, 3) and ``H = d2 qa / dq2`` (n, 3, 3, 3,
    ``H[n, i, j, k] = d2 qa_i / dq_j dq_k``, symmetric in ``j, k``) of each pose in one
    evaluation (eqs. 5, 6, 9), their common terms computed once: ``J' q' = H[q', q']``
    (:func:`jacobian_rate`'s values to round-off). The generated function returns the 18
    entries ``j <= k``; here they are unpacked into the full symmetric tensor."""
    (qa, J, h), _ = evaluate(model, "actuator_coordinates_hessian", (q,), backend)
    h = h.reshape(-1, 3, 6)
    H = np.empty((h.shape[0], 3, 3, 3))
    for p, (j, k) in enumerate(HESSIAN_PAIRS):
        H[:, :, j, k] = h[:, :, p]
        H[:, :, k, j] = h[:, :, p]
    return qa, J.reshape(-1, 3, 3), H


@checked(q=Rows(3), qd=Rows(3), same_length=[("q", "qd")])
def jacobian_rate(model: Model, q: ArrayLike, qd: ArrayLike, backend: str = "numpy") -> np.ndarray:
    """``J' q'``, (n, 3): ``qa'' = J q'' + J' q'`` (eq. 9 at zero platform acceleration)."""
    (rate,), _ = evaluate(model, "jacobian_rate", (q, qd), backend)
    return rate


@checked(q=Rows(3), qa_dot=Rows(3), same_length=[("q", "qa_dot")])
def platform_velocity(
    model: Model, q: ArrayLike, qa_dot: ArrayLike, backend: str = "numpy"
) -> np.ndarray:
    """``q' = J^-1 qa'``, (n, 3): the platform velocity from the actuator rates (a generated
    3 x 3 solve)."""
    (qd,), _ = evaluate(model, "platform_velocity", (q, qa_dot), backend)
    return qd


@checked(q=PoseRows(), qd=PoseRows(), qdd=PoseRows(), same_length=[("q", "qd", "qdd")])
def actuator_efforts(
    model: Model, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, backend: str = "numpy"
) -> np.ndarray:
    """The actuator efforts (n, 3) for the platform motion (q, q', q''): the inverse dynamics'
    actuator loads alone, which is ``tau = J^-T (M q'' + c)``, the task-space computed-torque
    law's efforts for a commanded acceleration ``q''``."""
    _width(model, q=np.asarray(q), qd=np.asarray(qd), qdd=np.asarray(qdd))
    (tau,), _ = evaluate(model, "actuator_efforts", (q, qd, qdd), backend)
    return tau


@checked(q=PoseRows(), qd=PoseRows(), same_length=[("q", "qd")])
def task_space_dynamics(
    model: Model, q: ArrayLike, qd: ArrayLike, backend: str = "numpy"
) -> tuple[np.ndarray, np.ndarray]:
    """``M`` (n, 3, 3) and ``c`` (n, 3) with ``M q'' + c = J^T tau``.

    ``M`` is symmetric positive definite (platform coordinates: kg, kg m, kg m^2); ``c`` holds
    the Coriolis and centripetal terms, gravity and the payload (N, N, N m).
    """
    k = _width(model, q=np.asarray(q), qd=np.asarray(qd))
    (M, c), _ = evaluate(model, "task_space_dynamics", (q, qd), backend)
    return M.reshape(-1, k, k), c


@checked(q=PoseRows(), qd=PoseRows(), tau=PoseRows(), same_length=[("q", "qd", "tau")])
def forward_dynamics(
    model: Model, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, backend: str = "numpy"
) -> np.ndarray:
    """``q'' = M^-1 (J^T tau - c)``, (n, 3): the platform's acceleration under the efforts."""
    _width(model, q=np.asarray(q), qd=np.asarray(qd), tau=np.asarray(tau))
    (qdd,), _ = evaluate(model, "forward_dynamics", (q, qd, tau), backend)
    return qdd


def _wrap(angle: np.ndarray) -> np.ndarray:
    return angle - 2 * np.pi * np.rint(angle / (2 * np.pi))


def _residual(model: Model, q: np.ndarray, qa: np.ndarray, backend: str) -> np.ndarray:
    """``qa(q) - qa`` for each row of q, angles wrapped (NaN where a pose is refused)."""
    r = actuator_coordinates(model, q, backend) - qa
    return _wrap(r) if model.structure.actuated_kind == "R" else r


def _polish(model: Model, q: np.ndarray, qa: np.ndarray, backend: str) -> np.ndarray:
    """Newton steps on ``qa(q) = qa`` for candidate poses (k, 3); rows that do not converge
    to :data:`POLISH_TOL` become NaN."""
    if not len(q):
        return q.reshape(0, 3)
    q = q.copy()
    for _ in range(POLISH_STEPS):
        r = _residual(model, q, qa, backend)
        done = np.abs(r).max(axis=1) <= POLISH_TOL
        if done.all():
            return q
        J = actuator_jacobian(model, q, backend)
        with np.errstate(invalid="ignore"):
            step = np.linalg.solve(J, r[..., np.newaxis])[..., 0]
        q = np.where(done[:, np.newaxis], q, q - step)
    r = _residual(model, q, qa, backend)
    with np.errstate(invalid="ignore"):
        q[~(np.abs(r).max(axis=1) <= POLISH_TOL)] = np.nan
    return q


def _sextic_angles(a: np.ndarray) -> list[float]:
    """Real roots of ``sum a_j t^j`` as angles ``phi = 2 atan(t)``; ``phi = pi`` (``t``
    infinite) when the leading coefficient vanishes. Nearly real roots are kept: the Newton
    polish decides."""
    scale = float(np.max(np.abs(a)))
    if not scale > 0 or not np.isfinite(scale):
        return []
    coefficients = np.trim_zeros(a[::-1] / scale, "f")  # highest degree first
    angles = [math.pi] if abs(a[6]) <= 1e-12 * scale else []
    if len(coefficients) > 1:
        for t in np.roots(coefficients):
            if abs(t.imag) <= 1e-6 * (1 + abs(t)):
                angles.append(2 * math.atan(t.real))
    return angles


def _distinct(model: Model, modes: np.ndarray) -> np.ndarray:
    """The rows of ``modes`` with phi wrapped to (-pi, pi], duplicates merged, sorted by phi."""
    rho = platform_radius(model)
    kept: list[np.ndarray] = []
    for m in modes[np.isfinite(modes).all(axis=1)]:
        m = np.array([m[0], m[1], -_wrap(-m[2])])  # -wrap(-x) is in (-pi, pi]
        if all(
            math.hypot(m[0] - k[0], m[1] - k[1], rho * _wrap(m[2] - k[2])) > SAME_MODE for k in kept
        ):
            kept.append(m)
    kept.sort(key=lambda m: m[2])
    return np.array(kept).reshape(-1, 3)


@checked(qa=Instance(object, "an array of actuator coordinates"))
def assembly_modes(model: Model, qa: ArrayLike, backend: str = "numpy") -> np.ndarray:
    """Every assembly mode of the actuator coordinates ``qa`` (3,): (k, 3) poses, ``phi`` in
    ``(-pi, pi]``, sorted by ``phi``.

    ``k <= 2`` where the locked legs hold the platform on lines (closed form: the paper's
    revolute actuation), ``k <= 6`` on circles (the sextic: the paper's prismatic actuation, the
    3-RRR with base motors...). A mode has every leg in its working mode (docs/interfaces.md)
    and, as everywhere in rpr3gen, is a pose the generated code evaluates: ``reach`` above the
    generated ``MIN_REACH`` (the paper: every piston joint in front of its base pivot) and
    ``conditioning`` above ``MIN_CONDITIONING`` (a mode at a parallel singularity, a double one,
    is refused as :func:`rpr3gen.inverse_dynamics` refuses it); joint limits are not applied.
    """
    if model.structure.spatial:
        from rpr3gen.spatial_modes import assembly_modes as spatial_modes

        return spatial_modes(model, Reading(model.structure.dof, finite=True)("qa", qa), backend)
    row = Reading(3)("qa", qa)
    if model.structure.hold != "circle":
        (modes, margins), _ = evaluate(model, "assembly_modes", (row,), backend)
        # A candidate is a mode where every leg is in its working mode: Newton, from an exact
        # candidate, converges at once; from one with a leg in another mode it does not.
        found = _polish(model, modes.reshape(2, 3)[margins[0] >= 0], row, backend)
    else:
        (a,), _ = evaluate(model, "assembly_modes", (row,), backend)
        angles = _sextic_angles(a[0])
        if not angles:
            return np.empty((0, 3))
        phi = np.array(angles)
        cos_sin = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        (xy,), _ = evaluate(
            model, "pose_from_angle", (np.tile(row, (len(phi), 1)), cos_sin), backend
        )
        candidates = np.column_stack([xy, phi])
        found = _polish(model, candidates, row, backend)
    modes = _distinct(model, found)
    if not len(modes):
        return modes
    # Only poses the generated code evaluates: reach and conditioning above their floors.
    return modes[np.isfinite(actuator_coordinates(model, modes, backend)).all(axis=1)]


@checked(qa=PoseRows(), near=PoseRows(), same_length=[("qa", "near")])
def forward_kinematics(
    model: Model, qa: ArrayLike, near: ArrayLike, backend: str = "numpy"
) -> np.ndarray:
    """Per row, the assembly mode of ``qa`` nearest ``near`` (the tracked solution), (n, 3).

    "Nearest" is the distance in ``(x, y, rho phi)``, ``rho`` the platform's RMS joint radius
    (:func:`platform_radius`); ``phi`` is unwrapped next to ``near``'s. A row with no mode is NaN.
    ``backend="c"``: the generated C (damped Newton from ``near`` with the generated Jacobian, and
    every mode as a fallback; fast, for control loops). ``"numpy"``: every mode
    (:func:`assembly_modes`), then the nearest.

    A spatial robot (docs/spatial-robots.md), both backends: the pose Newton reaches from
    ``near`` (the step halved until the largest residual decreases; NaN when it does not
    converge), (n, 6) or (n, 3).
    """
    qa, near = np.asarray(qa), np.asarray(near)  # (n, 3) float64 each: checked
    _width(model, qa=qa, near=near)
    if backend == "c" or model.structure.spatial:
        (q,), _ = evaluate(model, "forward_kinematics", (qa, near), backend)
        return q
    rho = platform_radius(model)
    out = np.full(qa.shape, np.nan)
    for i, (row, ref) in enumerate(zip(qa, near, strict=True)):
        if not (np.isfinite(row).all() and np.isfinite(ref).all()):
            continue
        modes = assembly_modes(model, row, backend)
        if not len(modes):
            continue
        modes[:, 2] = ref[2] + _wrap(modes[:, 2] - ref[2])
        d = np.hypot(
            np.hypot(modes[:, 0] - ref[0], modes[:, 1] - ref[1]), rho * (modes[:, 2] - ref[2])
        )
        out[i] = modes[int(np.argmin(d))]
    return out
