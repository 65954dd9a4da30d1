"""The robot the controller drives: rpr3gen's own forward dynamics, with what the model lacks.

The plant is the model file's robot with two things the controller does not know:

- a **payload** on the platform: ``payload`` kg more platform mass, its inertia about G scaled
  by the same ratio (a payload spread as the platform is; its centre at G);
- **viscous friction** at every motor, ``friction`` N m s/rad: the motors deliver
  ``tau - friction * qa'``, ``qa' = J q'`` the actuator rates (``J`` the generated actuator
  Jacobian).

Its state (the platform pose ``q`` and rate ``q'``) is integrated by RK4 of the generated
``forward_dynamics`` (the C, through :class:`rpr3gen.SampleEvaluator`) in substeps, the
commanded efforts held over each control period (zero-order hold), as a drive holds a setpoint.
"""

from __future__ import annotations

import dataclasses

import numpy as np

import rpr3gen


def with_payload(model: rpr3gen.Model, payload: float) -> rpr3gen.Model:
    """The robot with ``payload`` kg added to its platform at G (platform inertia scaled).

    Planar models name the platform's mass ``m3`` and its inertia about G ``J3``.
    """
    params = dict(model.params)
    ratio = (params["m3"] + payload) / params["m3"]
    params["m3"] *= ratio
    params["J3"] *= ratio
    return dataclasses.replace(model, params=params)


class Plant:
    """The true robot: its platform state, advanced under the commanded efforts.

    Attributes:
        q, qd: the platform pose (x, y in m, phi in rad) and its rate, (k,).
    """

    def __init__(
        self,
        truth: rpr3gen.Model,
        q: np.ndarray,
        friction: float = 0.0,
        substeps: int = 10,
    ) -> None:
        """Args:
        truth: the true robot (e.g. :func:`with_payload` of the controller's model).
        q: the initial pose, at rest.
        friction: viscous friction at each motor, N m s/rad (N s/m for a linear one).
        substeps: RK4 steps per control period.
        """
        self.dynamics = rpr3gen.SampleEvaluator(truth, function="forward_dynamics")
        self.jacobian = rpr3gen.SampleEvaluator(truth, function="actuator_jacobian")
        self.q = np.asarray(q, dtype=float).copy()
        self.qd = np.zeros_like(self.q)
        self.friction = friction
        self.substeps = substeps

    def acceleration(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The platform's acceleration (k,) at the state ``(q, qd)`` under the commanded
        efforts ``tau`` (k,), friction included."""
        k = len(q)
        if self.friction:
            jac = self.jacobian
            jac.q[:] = q
            if jac():
                raise RuntimeError(f"the plant reached a singular pose, q = {q.tolist()}")
            tau = tau - self.friction * (jac.J.reshape(k, k) @ qd)
        fd = self.dynamics
        fd.q[:], fd.qd[:], fd.tau[:] = q, qd, tau
        if fd():
            raise RuntimeError(f"the plant reached a singular pose, q = {q.tolist()}")
        return fd.qdd.copy()

    def step(self, tau: np.ndarray, dt: float) -> None:
        """Advance by ``dt`` s under the efforts ``tau`` (k,) held constant: RK4 in
        :attr:`substeps` steps."""
        h = dt / self.substeps
        q, qd = self.q, self.qd
        for _ in range(self.substeps):
            a1 = self.acceleration(q, qd, tau)
            v2 = qd + 0.5 * h * a1
            a2 = self.acceleration(q + 0.5 * h * qd, v2, tau)
            v3 = qd + 0.5 * h * a2
            a3 = self.acceleration(q + 0.5 * h * v2, v3, tau)
            v4 = qd + h * a3
            a4 = self.acceleration(q + h * v3, v4, tau)
            q = q + h / 6.0 * (qd + 2.0 * v2 + 2.0 * v3 + v4)
            qd = qd + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        self.q, self.qd = q, qd
