"""TOPP-RA's side of the retiming: the constraints in its canonical linear form, its solve, and
the trajectory it gives (imported only by :func:`rpr3gen.retime`, when it runs: ``import rpr3gen``
does not import toppra; without it, a one-line error names the extra to install).

TOPP-RA (Pham & Pham, "A new approach to time-optimal path parameterization based on
reachability analysis", IEEE T-RO 2018) works on a grid ``s_0 < ... < s_N`` of the path with the
state ``x = s'^2`` and the control ``u = s''``, constant between grid points, so that
``x_{i+1} = x_i + 2 (s_{i+1} - s_i) u_i``. Each constraint is given as TOPP-RA's
``LinearConstraint``: here the efforts ``a u + b x + c`` within ``[-L, L]`` (the ``F v <= g`` of
its canonical form, identical at every grid point) and the actuator rates as a bound on ``x``.
The efforts use the interpolation discretisation: each step's control must keep them within the
limits at both its ends, not only at its start.
"""

from __future__ import annotations

import numpy as np

from rpr3gen.errors import SetupError

EXTRA = "pip install 'rpr3gen[toppra]'"
"""How to install TOPP-RA, for the message of its absence."""

try:
    import toppra
    import toppra.algorithm
    from toppra.constraint import DiscretizationType, LinearConstraint
    from toppra.constraint.linear_constraint import canlinear_colloc_to_interpolate
except ImportError as exc:  # the extra is not installed: one line that names it
    if (exc.name or "").split(".")[0] != "toppra":
        raise
    raise SetupError(
        "retime needs TOPP-RA (the package toppra), which is not installed: install the extra "
        f"'toppra': {EXTRA}"
    ) from None

__all__ = [
    "EXTRA",
    "SOLVER_BOUND",
    "EffortConstraint",
    "RateConstraint",
    "duration",
    "parametrize",
    "sample",
]

#: The bound that TOPP-RA's seidel solver puts on ``x`` and ``u`` (``VAR_MAX`` of its
#: ``cy_seidel_solverwrapper``): a solution that reaches it is the solver's, not the robot's.
SOLVER_BOUND = 1e8


class EffortConstraint(LinearConstraint):  # type: ignore[misc]
    """``-L <= a u + b x + c <= L`` at every grid point, interpolation discretisation."""

    def __init__(self, a: np.ndarray, b: np.ndarray, c: np.ndarray, limit: np.ndarray) -> None:
        super().__init__()
        self.a, self.b, self.c, self.limit = a, b, c, limit
        self.dof = a.shape[1]
        self.identical = True  # F and g are the same at every grid point
        self.set_discretization_type(DiscretizationType.Interpolation)
        self._format_string = f"    Actuator efforts within +/- {limit}\n"

    def compute_constraint_params(
        self, path: object, gridpoints: np.ndarray, *args: object, **kwargs: object
    ) -> tuple:
        F = np.vstack([np.eye(self.dof), -np.eye(self.dof)])
        g = np.concatenate([self.limit, self.limit])
        return canlinear_colloc_to_interpolate(
            self.a, self.b, self.c, F, g, None, None, gridpoints, identical=True
        )


class RateConstraint(LinearConstraint):  # type: ignore[misc]
    """``|rate| s' <= V`` at every grid point: ``x <= min_j (V_j / |rate_j|)^2``."""

    def __init__(self, rate: np.ndarray, limit: np.ndarray) -> None:
        super().__init__()
        self.rate, self.limit = rate, limit
        self.dof = rate.shape[1]
        self._format_string = f"    Actuator rates within +/- {limit}\n"

    def compute_constraint_params(
        self, path: object, gridpoints: np.ndarray, *args: object, **kwargs: object
    ) -> tuple:
        with np.errstate(divide="ignore", over="ignore"):
            speed = np.min(self.limit / np.abs(self.rate), axis=1)
        xbound = np.zeros((len(gridpoints), 2))
        xbound[:, 1] = np.minimum(speed, 1e8) ** 2  # a path speed of 1e8: unbounded
        return None, None, None, None, None, None, xbound


def parametrize(
    knots: np.ndarray,
    waypoints: np.ndarray,
    grid: np.ndarray,
    constraints: list[LinearConstraint],
) -> np.ndarray | None:
    """The time-optimal path speeds ``s'`` at the grid points, rest to rest, or None when TOPP-RA
    finds no parametrisation."""
    path = toppra.SplineInterpolator(knots, waypoints)
    instance = toppra.algorithm.TOPPRA(constraints, path, gridpoints=grid, solver_wrapper="seidel")
    with np.errstate(all="ignore"):  # an overflow is a NaN speed, refused by the caller
        _, sd, _ = instance.compute_parameterization(0.0, 0.0)
    ok = instance.problem_data.return_code == toppra.algorithm.ParameterizationReturnCode.Ok
    return np.asarray(sd, dtype=np.float64) if ok and sd is not None else None


def duration(grid: np.ndarray, sd: np.ndarray) -> float:
    """The motion's duration, ``sum 2 (s_{i+1} - s_i) / (s'_i + s'_{i+1})`` (``s''`` constant
    between grid points); infinite where two consecutive path speeds are 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        steps = 2.0 * np.diff(grid) / (sd[1:] + sd[:-1])
    return float(np.sum(steps)) if np.isfinite(steps).all() else float("inf")


def sample(
    knots: np.ndarray, waypoints: np.ndarray, grid: np.ndarray, sd: np.ndarray, samples: int
) -> tuple[np.ndarray, ...]:
    """``t, q, q', q''`` at ``samples`` equally spaced times of the parametrisation (of a finite
    :func:`duration`): ``s''`` constant between grid points (TOPP-RA's
    ``ParametrizeConstAccel``)."""
    path = toppra.SplineInterpolator(knots, waypoints)
    trajectory = toppra.parametrizer.ParametrizeConstAccel(path, grid, sd)
    start, end = trajectory.path_interval
    t = np.linspace(start, end, samples)
    q, qd, qdd = (np.asarray(trajectory(t, order), dtype=np.float64) for order in (0, 1, 2))
    qd[0] = qd[-1] = 0.0  # rest to rest: round-off of sqrt(x) = 0 aside
    return t - start, q, qd, qdd
