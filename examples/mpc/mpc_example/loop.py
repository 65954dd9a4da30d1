"""The closed loop: each period, measure the plant, ask a policy for efforts, apply them.

A policy is any callable ``(t, x) -> (tau, record)``; :class:`MpcPolicy` is the controller of
:mod:`mpc_example.controller`, and the tests pass others (zero efforts, the feedforward alone)
to show what the loop measures without it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mpc_example.controller import Mpc, Solution
from mpc_example.plant import Plant
from mpc_example.reference import Reference

Policy = Callable[[float, np.ndarray], tuple[np.ndarray, Solution | None]]


@dataclass
class Run:
    """The closed loop's record, one row per control period (n periods, k actuators).

    Attributes:
        t: (n,) the end of each period, s.
        q_ref, q: (n, k) the reference and the plant's pose at ``t``.
        qd: (n, k) the plant's rate at ``t``.
        tau: (n, k) the efforts applied over the period.
        disturbance: (n, k) the controller's estimate of the effort its model lacks (0 without).
        seconds: (n,) the solve's wall time, s (NaN for a policy with no solver).
        iterations: (n,) the solver's iterations (0 without).
        success: (n,) whether the solver converged (True without).
        status: the solver's statuses, one per period.
    """

    t: np.ndarray
    q_ref: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    disturbance: np.ndarray
    seconds: np.ndarray
    iterations: np.ndarray
    success: np.ndarray
    status: list[str]


class MpcPolicy:
    """The MPC as a policy: the reference over its horizon, then the solve."""

    def __init__(self, mpc: Mpc, reference: Reference) -> None:
        self.mpc, self.reference = mpc, reference

    def __call__(self, t: float, x: np.ndarray) -> tuple[np.ndarray, Solution | None]:
        s = self.mpc.settings
        ahead = t + s.dt * np.arange(s.horizon + 1)
        q_ref, qd_ref, tau_ref = self.reference.sample(ahead)
        solution = self.mpc.solve(x, q_ref[1:], qd_ref[1:], tau_ref[:-1])
        return solution.tau, solution


def closed_loop(
    policy: Policy,
    plant: Plant,
    reference: Reference,
    dt: float,
    steps: int,
    mpc: Mpc | None = None,
) -> Run:
    """Run ``steps`` periods of ``dt`` s from the plant's state; ``mpc``, if given, has its
    disturbance estimate updated after each period."""
    k = len(plant.q)
    rows = {name: np.zeros((steps, k)) for name in ("q", "qd", "tau", "disturbance")}
    seconds = np.full(steps, np.nan)
    iterations = np.zeros(steps, dtype=int)
    success = np.ones(steps, dtype=bool)
    status = []
    for step in range(steps):
        x = np.concatenate([plant.q, plant.qd])
        tau, solution = policy(step * dt, x)
        plant.step(tau, dt)
        if mpc is not None:
            mpc.update_disturbance(x, tau, np.concatenate([plant.q, plant.qd]))
            rows["disturbance"][step] = mpc.disturbance
        rows["q"][step], rows["qd"][step], rows["tau"][step] = plant.q, plant.qd, tau
        if solution is not None:
            seconds[step], iterations[step] = solution.seconds, solution.iterations
            success[step] = solution.success
        status.append(solution.status if solution is not None else "")
    t = dt * np.arange(1, steps + 1)
    q_ref = reference.sample(t)[0]
    return Run(t=t, q_ref=q_ref, seconds=seconds, iterations=iterations, success=success,
               status=status, **rows)  # fmt: skip
