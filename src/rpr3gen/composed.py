"""The NumPy versions of the spatial robots' hand-written C functions, composed from the
generated ones: the efforts, the payload's efforts, the control form, the forward dynamics and
the tracked forward kinematics (docs/spatial-robots.md).

The inverse dynamics' efforts are affine in the platform's acceleration, ``tau = T q'' +
tau0``: ``tau0`` is the inverse dynamics at ``q'' = 0`` and column ``j`` of ``T`` the inverse
dynamics at ``q'' = e_j`` with the platform at rest, without gravity and payload (their
parameters zeroed). Then ``M = J^T T``, ``c = J^T tau0``, and the forward dynamics solves
``T q'' = tau - tau0``: what the generated C bodies compute, sample by sample. A failed sample
is a row of NaN, as the C batch writes it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from rpr3gen import spatial_inertia
from rpr3gen.manifest import FunctionInfo, Variant

#: ``run(function name, params, inputs) -> outputs (n, size) each``: the generated NumPy code.
Runner = Callable[[str, np.ndarray, Sequence[np.ndarray]], list[np.ndarray]]

COMPOSED: tuple[str, ...] = (
    "actuator_efforts",
    "task_space_dynamics",
    "forward_dynamics",
    "forward_kinematics",
    "payload_efforts",
    "regressor",
)

#: The parameters of the loads that do not come from the motion: gravity and the payload.
LOAD_PARAMS = ("gx", "gy", "gz", "fx", "fy", "fz", "mx", "my", "mz")
#: The tracked forward kinematics' numbers (the generated C's: derive/spatial/registry.py).
MAX_ITER, MAX_HALVINGS, TOL = 30, 30, 1e-12


#: Composed for every robot, planar or spatial.
EVERY_ROBOT: tuple[str, ...] = ("forward_dynamics_derivatives",)


def composable(variant: Variant, function: FunctionInfo) -> bool:
    """Whether ``function`` of ``variant`` has a NumPy composition here."""
    if function.name in EVERY_ROBOT:
        return True
    return function.name in COMPOSED and "DOF" in variant.defines


def run(
    variant: Variant,
    function: FunctionInfo,
    params: np.ndarray,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
    generated: Runner,
) -> None:
    """Evaluate ``function`` into ``outputs`` (each (n, size)); failed samples are NaN rows."""
    if function.name == "forward_dynamics_derivatives":
        for out, value in zip(
            outputs, _forward_derivatives(params, inputs, generated), strict=True
        ):
            out[:] = value
        return
    tau_rows = _tau_rows(variant)
    if function.name == "forward_kinematics":
        outputs[0][:] = _forward_kinematics(params, inputs[0], inputs[1], generated, variant)
        return
    q = inputs[0]
    n, k = q.shape
    zero = np.zeros_like(q)
    if function.name == "payload_efforts":
        p0 = params.copy()
        for name in ("gx", "gy", "gz"):
            p0[variant.param_names.index(name)] = 0.0
        (out,) = generated("inverse_dynamics", p0, [q, zero, zero])
        outputs[0][:] = out[:, tau_rows]
        return
    if function.name == "regressor":
        outputs[0][:] = _regressor(variant, params, inputs, generated, tau_rows)
        return
    if function.name == "actuator_efforts":
        (out,) = generated("inverse_dynamics", params, inputs)
        outputs[0][:] = out[:, tau_rows]
        return
    (out,) = generated("inverse_dynamics", params, [q, inputs[1], zero])
    tau0 = out[:, tau_rows]
    T = _efforts_matrix(variant, params, q, generated, tau_rows)
    if function.name == "task_space_dynamics":
        (J,) = generated("actuator_jacobian", params, [q])
        J = J.reshape(n, k, k)
        Jt = np.swapaxes(J, 1, 2)
        outputs[0][:] = (Jt @ T).reshape(n, k * k)
        outputs[1][:] = (Jt @ tau0[:, :, np.newaxis])[:, :, 0]
        return
    rhs = inputs[2] - tau0
    result = np.full((n, k), np.nan)
    ok = np.isfinite(T).all(axis=(1, 2)) & np.isfinite(rhs).all(axis=1)
    if ok.any():
        with np.errstate(all="ignore"):
            solved = np.linalg.solve(T[ok], rhs[ok][:, :, np.newaxis])[:, :, 0]
        result[ok] = solved
    result[~np.isfinite(result).all(axis=1)] = np.nan
    outputs[0][:] = result


def _forward_derivatives(
    params: np.ndarray, inputs: Sequence[np.ndarray], generated: Runner
) -> list[np.ndarray]:
    """``q''`` of the forward dynamics and its Jacobians by ``q, q', tau`` (each (n, k*k)):
    with ``T = d tau / d q''`` of the inverse dynamics derivatives at that ``q''``, ``T X =
    [-d tau / d q, -d tau / d q', I]`` (derive/codegen/derivatives.py)."""
    q, qd, tau = inputs
    n, k = q.shape
    (qdd,) = generated("forward_dynamics", params, [q, qd, tau])
    _, dq, dqd, T = generated("inverse_dynamics_derivatives", params, [q, qd, qdd])
    rhs = np.concatenate(
        [-dq.reshape(n, k, k), -dqd.reshape(n, k, k), np.broadcast_to(np.eye(k), (n, k, k))],
        axis=2,
    )
    X = np.full((n, k, 3 * k), np.nan)
    T = T.reshape(n, k, k)
    ok = np.isfinite(T).all(axis=(1, 2)) & np.isfinite(rhs).all(axis=(1, 2))
    if ok.any():
        with np.errstate(all="ignore"):
            X[ok] = np.linalg.solve(T[ok], rhs[ok])
    bad = np.asarray(~np.isfinite(X).all(axis=(1, 2)))
    X[bad] = np.nan
    qdd = np.where(bad[:, np.newaxis], np.nan, qdd)
    return [qdd, *(X[:, :, j * k : (j + 1) * k].reshape(n, k * k) for j in range(3))]


def _tau_rows(variant: Variant) -> list[int]:
    names = variant.function("inverse_dynamics").outputs[0].names
    legs = [n.rpartition("_")[2] for n in names if n.startswith("tau_")]
    return [names.index(f"tau_{leg}") for leg in legs]


def _regressor(
    variant: Variant,
    params: np.ndarray,
    inputs: Sequence[np.ndarray],
    generated: Runner,
    rows: list[int],
) -> np.ndarray:
    """``Y`` (n, k * P, row-major): column ``j`` is the inverse dynamics' efforts for the model
    numbers whose ``pi`` is ``e_j`` (:func:`rpr3gen.spatial_inertia.unit_columns`)."""
    kinds = variant.defines["LEG"].strip('"')
    legs = "ABCDEF"[: int(variant.defines["NUM_LEGS"])]
    columns = []
    mass_column = np.zeros((len(inputs[0]), len(rows)))
    for p, role in spatial_inertia.unit_columns(kinds, legs, variant.param_names, params):
        (out,) = generated("inverse_dynamics", p, inputs)
        tau = out[:, rows]
        if role == "moment":
            tau = tau - mass_column
        elif role == "mass":
            mass_column = tau
        columns.append(tau)
    Y = np.stack(columns, axis=2)  # (n, k, P)
    return Y.reshape(len(Y), -1)


def _efforts_matrix(
    variant: Variant, params: np.ndarray, q: np.ndarray, generated: Runner, rows: list[int]
) -> np.ndarray:
    """``T = d tau / d q''`` per sample, (n, k, k)."""
    n, k = q.shape
    p0 = params.copy()
    for name in LOAD_PARAMS:
        p0[variant.param_names.index(name)] = 0.0
    zero = np.zeros_like(q)
    T = np.empty((n, k, k))
    for j in range(k):
        unit = np.zeros_like(q)
        unit[:, j] = 1.0
        (out,) = generated("inverse_dynamics", p0, [q, zero, unit])
        T[:, :, j] = out[:, rows]
    return T


def _forward_kinematics(
    params: np.ndarray,
    qa: np.ndarray,
    near: np.ndarray,
    generated: Runner,
    variant: Variant,
) -> np.ndarray:
    """Newton from ``near`` with the step halved until the largest residual decreases."""
    leg = variant.defines.get("LEG", '""').strip('"')
    wrap = leg[int(variant.defines.get("ACTUATED", "1")) - 1] == "R"
    n, k = qa.shape
    result = np.full((n, k), np.nan)

    def residual(q: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        value, J = generated("actuator_coordinates_jacobian", params, [q[np.newaxis]])
        if not (np.isfinite(value).all() and np.isfinite(J).all()):
            return None
        r = value[0] - target
        if wrap:
            r = r - 2 * np.pi * np.rint(r / (2 * np.pi))
        return r, J[0].reshape(k, k)

    for s in range(n):
        if not (np.isfinite(qa[s]).all() and np.isfinite(near[s]).all()):
            continue
        q = near[s].copy()
        first = residual(q, qa[s])
        if first is None:
            continue
        r, J = first
        worst = float(np.max(np.abs(r)))
        for _ in range(MAX_ITER):
            if worst <= TOL:
                break
            try:
                dq = np.linalg.solve(J, r)
            except np.linalg.LinAlgError:
                break
            step, accepted = 1.0, False
            for _ in range(MAX_HALVINGS + 1):
                trial = q - step * dq
                found = residual(trial, qa[s])
                if found is not None and float(np.max(np.abs(found[0]))) < worst:
                    q, (r, J), accepted = trial, found, True
                    worst = float(np.max(np.abs(r)))
                    break
                step *= 0.5
            if not accepted:
                break
        if worst <= TOL:
            result[s] = q
    return result
