"""The model-predictive controller: multiple shooting of the CasADi bridge's forward dynamics.

The model is ``rpr3gen.casadi.function(model, "forward_dynamics")``, ``q'' = FD(params, q, q',
tau)``, with ``params = rpr3gen.casadi.parameters(model)``: the generated derivation as a CasADi
SX graph. The state is ``x = (q, q')`` (2k: the platform pose and its rate), the control the k
actuator efforts ``tau``, held over each period ``dt`` as the plant holds them.

Each period, the controller solves

    min   sum_{i=1..N} |q_i - q_ref,i|^2_Q + |q'_i - q'_ref,i|^2_V   (terminal term x ``terminal``)
        + sum_{i=0..N-1} |tau_i - tau_ref,i|^2_R
    s.t.  x_0 = the measured state
          x_{i+1} = RK4(x_i, tau_i + d)      (one RK4 step of FD over dt, per interval)
          -limit <= tau_i <= limit

over the horizon of N periods (``tau_ref``: the nominal model's efforts along the reference, so
that R weighs the feedback, not the effort) and applies ``tau_0``. ``d`` is an estimate of the
effort the model lacks (the plant's payload and friction, as a constant effort at the motors),
updated from each period's prediction error (:meth:`Mpc.update_disturbance`): without it a
gravity-loaded robot with an unknown payload settles off its path (no integral action).

**Why multiple shooting of the forward dynamics**: the effort limits are then bounds on
decision variables, which both solvers keep exactly (qrqp's active set puts an effort on its
bound; IPOPT with ``bound_relax_factor = 0`` and ``honor_original_bounds``), and the efforts
are held constant over a period as the drive holds them, so the model integrates what the plant
receives. The alternative, the platform's acceleration as the control and the inverse dynamics
as an equality (or the efforts as a nonlinear inequality), avoids the forward dynamics' solve
but turns the limits into nonlinear constraints that hold only at the grid points, and makes
the applied effort a function of the solution rather than a variable. For a planar robot the
forward dynamics is a closed form in the generated code (955 operations for the 3-RRR against
759 for its efforts), so nothing would be saved either.

**Why a real-time iteration by default**: the cost is a sum of squares of residuals linear in
the variables, so its Hessian is a constant (Gauss-Newton: the dynamics' curvature left out;
the exact Lagrangian Hessian through four forward dynamics per interval is 2.4 million SX
instructions at N = 20). Warm-started from the last solution shifted by one period, one
Gauss-Newton SQP step a period (CasADi's ``sqpmethod``, ``max_iter = 1``) lands where IPOPT
converges to (the same tracking error to four digits on the default run) in a fraction of
the time: most of it is the constraints' Jacobian in CasADi's virtual machine, the QP takes a
fifth of a millisecond in qrqp (CasADi's own sparse active-set solver; qpOASES in the wheel
took 15 ms dense or sparse on the 186-variable QP, OSQP's ADMM stops within its tolerance of
the limits, not on them). ``solver = "ipopt"`` solves each period to convergence: slower, and
its status says the problem was solved, where a real-time iteration's says only that its step
was taken.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

import rpr3gen
import rpr3gen.casadi as rc


@dataclass(frozen=True)
class Settings:
    """The controller's tuning.

    Attributes:
        horizon: N, the number of periods predicted.
        dt: the control period, s.
        effort_limit: the largest |tau_i| of each actuator (N m for motors that turn), (k,).
        position_weight: Q's diagonal for x, y (1/m^2) and the angle (1/rad^2): 1 mm or
            1 mrad of error costs 1 at the defaults.
        velocity_weight: V's diagonal (s^2/m^2, s^2/rad^2).
        effort_weight: R's diagonal (1/(N m)^2), on the deviation from the feedforward.
        terminal: the last predicted state's weight, a multiple of Q and V.
        rk4_steps: RK4 steps of the model per period.
        disturbance_gain: the estimate's filter gain in (0, 1]; 0 turns the estimate off.
        hessian: ``"gauss-newton"`` (the cost's Hessian only) or ``"exact"`` (the Lagrangian's,
            through the dynamics: 2.4 million instructions for the 3-RRR at N = 20).
        solver: ``"rti"`` (a real-time iteration: one Gauss-Newton SQP step a period, CasADi's
            ``sqpmethod`` with its QP solver qrqp) or ``"ipopt"`` (solved to convergence).
    """

    horizon: int = 20
    dt: float = 0.01
    effort_limit: np.ndarray = field(default_factory=lambda: np.full(3, 12.0))
    position_weight: tuple[float, ...] = (1e6, 1e6, 1e6)
    velocity_weight: tuple[float, ...] = (1e2, 1e2, 1e2)
    effort_weight: tuple[float, ...] = (1.0, 1.0, 1.0)
    terminal: float = 10.0
    rk4_steps: int = 1
    disturbance_gain: float = 0.5
    hessian: str = "gauss-newton"
    solver: str = "rti"


@dataclass
class Solution:
    """One period's solve.

    Attributes:
        tau: the efforts to apply now, (k,).
        success: IPOPT's own verdict (``Solve_Succeeded`` or ``Solved_To_Acceptable_Level``);
            for a real-time iteration, that its one SQP step was taken (its QP solved).
        status: the solver's return status.
        iterations: the solver's iterations (a real-time iteration's: 1).
        seconds: the wall time of the solve, s (the call, including CasADi's Python wrapper).
    """

    tau: np.ndarray
    success: bool
    status: str
    iterations: int
    seconds: float


def rk4_step(model: rpr3gen.Model, dt: float, steps: int) -> tuple[ca.Function, int]:
    """``x+ = step(x, tau)``: ``steps`` RK4 steps over ``dt`` of ``x' = (q', FD(q, q', tau))``,
    FD the bridge's ``forward_dynamics`` at the model's numbers; and k, the pose's size."""
    fd = rc.function(model, "forward_dynamics")
    params = ca.DM(rc.parameters(model))
    k = fd.size1_in(1)
    x, tau = ca.SX.sym("x", 2 * k), ca.SX.sym("tau", k)

    def rate(state: Any) -> Any:
        q, qd = state[:k], state[k:]
        return ca.vertcat(qd, fd(params, q, qd, tau))

    h = dt / steps
    state = x
    for _ in range(steps):
        k1 = rate(state)
        k2 = rate(state + h / 2 * k1)
        k3 = rate(state + h / 2 * k2)
        k4 = rate(state + h * k3)
        state = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return ca.Function("step", [x, tau], [state], ["x", "tau"], ["x_next"]), k


class Mpc:
    """Nonlinear MPC of a parallel robot's platform, efforts within limits (module docstring).

    Call :meth:`solve` each period with the measured state and the reference over the horizon;
    then :meth:`update_disturbance` with the next measurement.
    """

    def __init__(self, model: rpr3gen.Model, settings: Settings) -> None:
        self.settings = s = settings
        self.step, k = rk4_step(model, s.dt, s.rk4_steps)
        self.k, n = k, s.horizon
        limit = np.broadcast_to(np.asarray(s.effort_limit, dtype=float), (k,)).copy()
        self.limit = limit

        X = ca.SX.sym("X", 2 * k, n + 1)
        U = ca.SX.sym("U", k, n)
        x0 = ca.SX.sym("x0", 2 * k)
        q_ref = ca.SX.sym("q_ref", k, n)  # at i = 1..N
        qd_ref = ca.SX.sym("qd_ref", k, n)
        tau_ref = ca.SX.sym("tau_ref", k, n)  # at i = 0..N-1
        d = ca.SX.sym("d", k)
        Q, V, R = (ca.DM(w[:k]) for w in (s.position_weight, s.velocity_weight, s.effort_weight))

        cost: Any = 0
        gaps = [X[:, 0] - x0]
        for i in range(n):
            gaps.append(X[:, i + 1] - self.step(X[:, i], U[:, i] + d))
            weight = s.terminal if i == n - 1 else 1.0
            eq = X[:k, i + 1] - q_ref[:, i]
            ev = X[k:, i + 1] - qd_ref[:, i]
            eu = U[:, i] - tau_ref[:, i]
            cost += weight * (ca.dot(Q * eq, eq) + ca.dot(V * ev, ev)) + ca.dot(R * eu, eu)

        w = ca.vertcat(ca.vec(X), ca.vec(U))
        p = ca.vertcat(x0, ca.vec(q_ref), ca.vec(qd_ref), ca.vec(tau_ref), d)
        nlp: dict[str, Any] = {"x": w, "p": p, "f": cost, "g": ca.vertcat(*gaps)}
        options: dict[str, Any] = {"print_time": False}
        if s.hessian == "gauss-newton":
            # the cost's Hessian (constant: its residuals are linear in w), the dynamics'
            # curvature left out: 365 instructions against the exact one's 2.4 million
            lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", nlp["g"].numel())
            hessian = ca.triu(lam_f * ca.hessian(cost, w)[0])
            options["hess_lag"] = ca.Function(
                "nlp_hess_l", [w, p, lam_f, lam_g], [hessian],
                ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"],
            )  # fmt: skip
        elif s.hessian != "exact":
            raise ValueError(f"hessian must be 'gauss-newton' or 'exact', not {s.hessian!r}")
        if s.solver == "ipopt":
            options["ipopt"] = {
                "print_level": 0,
                "sb": "yes",
                "tol": 1e-8,
                "max_iter": 100,
                "bound_relax_factor": 0.0,  # the limits exactly, not relaxed by 1e-8
                "honor_original_bounds": "yes",
            }
            self.solver = ca.nlpsol("mpc", "ipopt", nlp, options)
        elif s.solver == "rti":
            # one SQP step a period, its QP solved by qrqp (CasADi's own sparse active-set
            # solver): the step ends on the limits, never past them
            options.update(
                max_iter=1, qpsol="qrqp", qpsol_options={"print_iter": False,
                "print_header": False, "print_info": False, "error_on_fail": False},
                print_header=False, print_iteration=False, print_status=False,
                error_on_fail=False,
            )  # fmt: skip
            self.solver = ca.nlpsol("mpc", "sqpmethod", nlp, options)
        else:
            raise ValueError(f"solver must be 'ipopt' or 'rti', not {s.solver!r}")
        self.nx, self.nu = 2 * k * (n + 1), k * n
        inf = np.full(self.nx, np.inf)
        self.lbw = np.concatenate([-inf, -np.tile(limit, n)])
        self.ubw = np.concatenate([inf, np.tile(limit, n)])
        self.ng = 2 * k * (n + 1)
        self.w0: np.ndarray | None = None
        self.disturbance = np.zeros(k)
        # d x+ / d tau: how the next velocity answers an effort, for the estimate
        self.sensitivity = ca.Function(
            "sensitivity",
            [X[:, 0], U[:, 0]],
            [ca.jacobian(self.step(X[:, 0], U[:, 0])[k:], U[:, 0])],
        )

    def solve(
        self, x: np.ndarray, q_ref: np.ndarray, qd_ref: np.ndarray, tau_ref: np.ndarray
    ) -> Solution:
        """The efforts to apply now.

        Args:
            x: the measured state (q, q'), (2k,).
            q_ref, qd_ref: the reference pose and rate at the ends of the N periods ahead,
                (N, k).
            tau_ref: the feedforward efforts at the starts of the N periods, (N, k).
        """
        k, n = self.k, self.settings.horizon
        p = np.concatenate(
            [x, q_ref.ravel(), qd_ref.ravel(), tau_ref.ravel(), self.disturbance]
        )  # each (N, k) C-ordered is (k, N) column-major: CasADi's vec
        if self.w0 is None:  # the first period: the reference, and its efforts
            guess = np.hstack([q_ref, qd_ref]).ravel()
            feedforward = np.clip(tau_ref, -self.limit, self.limit).ravel()
            self.w0 = np.concatenate([x, guess, feedforward])
        start = time.perf_counter()
        result = self.solver(x0=self.w0, p=p, lbx=self.lbw, ubx=self.ubw, lbg=0, ubg=0)
        seconds = time.perf_counter() - start
        stats = self.solver.stats()
        w = np.asarray(result["x"]).ravel()
        status = str(stats["return_status"])
        if self.settings.solver == "rti":  # its one step done, the QP solved
            success = status == "Maximum_Iterations_Exceeded" and bool(np.isfinite(w).all())
        else:
            success = bool(stats["success"])
        states = w[: self.nx].reshape(n + 1, 2 * k)
        efforts = w[self.nx :].reshape(n, k)  # row i: tau_i
        # next period's start: the solution shifted by one period, its last step repeated
        self.w0 = np.concatenate([states[1:].ravel(), states[-1], efforts[1:].ravel(), efforts[-1]])
        return Solution(
            tau=efforts[0].copy(),
            success=success,
            status=status,
            iterations=int(stats["iter_count"]),
            seconds=seconds,
        )

    def update_disturbance(self, x: np.ndarray, tau: np.ndarray, x_next: np.ndarray) -> None:
        """Update the estimate ``d`` from one period: the state ``x`` at its start, the efforts
        ``tau`` applied, the state ``x_next`` measured at its end.

        The velocity the model predicted with ``tau + d`` misses the measured one by ``e``; to
        first order an effort change ``B^-1 e`` (``B = d q'+ / d tau``) explains it. The
        estimate moves by ``disturbance_gain`` of that (a first-order filter).
        """
        gain = self.settings.disturbance_gain
        if not gain:
            return
        k, u = self.k, tau + self.disturbance
        predicted = np.asarray(self.step(x, u)).ravel()
        B = np.asarray(self.sensitivity(x, u))
        miss = np.linalg.solve(B, x_next[k:] - predicted[k:])
        self.disturbance = self.disturbance + gain * miss
