"""The derivatives of the dynamics (docs/derivatives.md): exact, generated from the derivation.

``inverse_dynamics_derivatives(model, q, qd, qdd)``: the efforts ``tau`` and ``d tau / d q``,
``d tau / d q'``, ``d tau / d q''`` (the last is ``T``, with ``tau = T q'' + tau0``), by reverse
mode through the efforts' own program (one adjoint per actuator;
``derive/codegen/adjoint.py``). ``forward_dynamics_derivatives(model, q, qd, tau)``: the
acceleration ``q''`` and ``d q'' / d q = -T^-1 d tau / d q``, ``d q'' / d q' = -T^-1 d tau / d
q'``, ``d q'' / d tau = T^-1``, with ``T`` of the inverse dynamics derivatives at that ``q''``.
Both generated per variant, in NumPy and C (the C in a library of their own, built on first
use); a refused pose is a NaN row, as for the inverse dynamics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen.backends import evaluate
from rpr3gen.model import Model
from rpr3gen.validation import PoseRows, checked, match_width

__all__ = [
    "ForwardDynamicsDerivatives",
    "InverseDynamicsDerivatives",
    "forward_dynamics_derivatives",
    "inverse_dynamics_derivatives",
]


@dataclass(frozen=True)
class InverseDynamicsDerivatives:
    """The efforts and their Jacobians, per sample.

    Attributes:
        tau: (n, k) the actuator efforts (N m or N).
        dq: (n, k, k) ``d tau / d q`` (row: effort, column: pose coordinate).
        dqd: (n, k, k) ``d tau / d q'``.
        dqdd: (n, k, k) ``d tau / d q''`` (``T``: ``tau = T q'' + tau0``).
    """

    tau: np.ndarray
    dq: np.ndarray
    dqd: np.ndarray
    dqdd: np.ndarray


@dataclass(frozen=True)
class ForwardDynamicsDerivatives:
    """The acceleration and its Jacobians, per sample.

    Attributes:
        qdd: (n, k) the platform's acceleration.
        dq: (n, k, k) ``d q'' / d q`` (row: acceleration, column: pose coordinate).
        dqd: (n, k, k) ``d q'' / d q'``.
        dtau: (n, k, k) ``d q'' / d tau`` (``T^-1``).
    """

    qdd: np.ndarray
    dq: np.ndarray
    dqd: np.ndarray
    dtau: np.ndarray


def _blocks(model: Model, outputs: list[np.ndarray]) -> list[np.ndarray]:
    k = model.structure.dof
    return [outputs[0], *(o.reshape(-1, k, k) for o in outputs[1:])]


@checked(q=PoseRows(), qd=PoseRows(), qdd=PoseRows(), same_length=[("q", "qd", "qdd")])
def inverse_dynamics_derivatives(
    model: Model, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, backend: str = "numpy"
) -> InverseDynamicsDerivatives:
    """``tau`` and its derivatives by ``q``, ``q'``, ``q''`` (exact; module docstring)."""
    s = model.structure
    match_width(s.dof, s.title, q=np.asarray(q), qd=np.asarray(qd), qdd=np.asarray(qdd))
    outputs, _ = evaluate(model, "inverse_dynamics_derivatives", (q, qd, qdd), backend)
    return InverseDynamicsDerivatives(*_blocks(model, list(outputs)))


@checked(q=PoseRows(), qd=PoseRows(), tau=PoseRows(), same_length=[("q", "qd", "tau")])
def forward_dynamics_derivatives(
    model: Model, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, backend: str = "numpy"
) -> ForwardDynamicsDerivatives:
    """``q''`` and its derivatives by ``q``, ``q'``, ``tau`` (exact; module docstring)."""
    s = model.structure
    match_width(s.dof, s.title, q=np.asarray(q), qd=np.asarray(qd), tau=np.asarray(tau))
    outputs, _ = evaluate(model, "forward_dynamics_derivatives", (q, qd, tau), backend)
    return ForwardDynamicsDerivatives(*_blocks(model, list(outputs)))
