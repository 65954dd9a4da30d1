"""Time-optimal retiming of a platform path with TOPP-RA (extra ``toppra``): :func:`retime`.

The modules, bottom up: :mod:`~rpr3gen.retiming.waypoints` (the path given: an array or a path
CSV file, checked), :mod:`~rpr3gen.retiming.along` (the spline through the waypoints, TOPP-RA's
grid, the efforts' coefficients from the generated inverse dynamics, the refusals of a pose the
robot cannot take and of a limit that cannot hold it at rest), :mod:`~rpr3gen.retiming.topp`
(TOPP-RA's constraints, solve and output; imported only here, when :func:`retime` runs).
docs/retime.md has the method, its accuracy and what it leaves out (friction).
"""

from __future__ import annotations

import importlib
import math
from numbers import Real
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen import sizes
from rpr3gen.errors import InputError, InputTypeError
from rpr3gen.model import Model
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.retiming.along import GRID_POINT, Grid, check_hold, profile
from rpr3gen.retiming.waypoints import PathInput, Waypoints
from rpr3gen.trajectory import DURATIONS, Trajectory
from rpr3gen.validation import Check, Integer, Number, Optional, checked, numbers

__all__ = ["DEFAULT_GRID_POINTS", "DEFAULT_SAMPLES", "Limits", "retime"]

DEFAULT_SAMPLES = 1001
"""Samples of the retimed trajectory unless told otherwise, equally spaced in time."""

DEFAULT_GRID_POINTS = 1001
"""TOPP-RA's grid points along the path unless told otherwise (at least one a waypoint)."""


class Limits(Check):
    """A limit of the actuators: one number for all, or one per actuator; each finite and > 0.
    Returned as a 1-D array (matched to the model's actuators by :func:`retime`)."""

    def __call__(self, name: str, value: Any) -> np.ndarray:
        if isinstance(value, Real) and not isinstance(value, bool | np.bool_):
            return np.array([Number(greater=0.0)(name, value)])
        if isinstance(value, bool | np.bool_):
            raise InputTypeError(
                f"{name}: must be a number > 0 or one per actuator, got {value!r} (bool)",
                argument=name,
            )
        array = numbers(name, value)
        array = array.reshape(1) if array.ndim == 0 else array
        if array.ndim != 1 or array.size == 0:
            raise InputError(
                f"{name}: must be a number > 0 or a 1-D array of one per actuator, got an array "
                f"of shape {array.shape}",
                argument=name,
            )
        bad = ~(np.isfinite(array) & (array > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(
                f"{name}: every limit must be a finite number > 0, got {float(array[k])!r} (entry "
                f"{k + 1})",
                argument=name,
            )
        return np.ascontiguousarray(array)


def _per_actuator(name: str, limit: np.ndarray, model: Model) -> np.ndarray:
    legs = model.structure.legs
    if limit.size not in (1, len(legs)):
        raise InputError(
            f"{name}: give one limit for every actuator or one per actuator (the "
            f"{model.structure.title}: {len(legs)}, legs {', '.join(legs)}), got {limit.size}",
            argument=name,
        )
    return np.broadcast_to(limit, (len(legs),)).astype(np.float64)


def _toppra() -> ModuleType:
    """:mod:`rpr3gen.retiming.topp`, which imports toppra (a :class:`~rpr3gen.errors.SetupError`
    naming the extra when it is not installed: the environment's, as a missing C compiler)."""
    return importlib.import_module("rpr3gen.retiming.topp")


def _median(values: np.ndarray) -> float:
    """The median of the finite values, NaN if none is."""
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else math.nan


def _scale(
    a: np.ndarray,
    c: np.ndarray,
    limit: np.ndarray,
    rate: np.ndarray | None,
    velocity: np.ndarray | None,
) -> float:
    """The path parameter's length ``S`` that makes TOPP-RA's state ``x = s'^2`` of order 1.

    On ``s`` in ``[0, 1]`` the squared path speed is of the order of the path acceleration the
    limits allow at rest (median along the path of ``min_j (L_j - |c_j|) / |a_j|``), or of the
    rate limit's bound on it if lower; on ``sigma = S s`` it is ``S^2`` times that. TOPP-RA's
    solver has absolute tolerances (1e-8 and below on ``x``) and bounds ``x`` and ``u`` by 1e8:
    the limits' units must not decide its accuracy.
    """
    with np.errstate(all="ignore"):  # inf where a or the rate is 0, or a limit is huge
        scales = [_median(np.min((limit - np.abs(c)) / np.abs(a), axis=1))]
        if rate is not None and velocity is not None:
            scales.append(_median(np.min(velocity / np.abs(rate), axis=1) ** 2))
    found = [x for x in scales if math.isfinite(x) and x > 0]
    return float(np.clip(1.0 / math.sqrt(min(found)), 1e-6, 1e6)) if found else 1.0


@checked(
    path=PathInput(),
    effort_limit=Limits(),
    velocity_limit=Optional(Limits()),
    samples=Integer(2, cost=lambda n: n * sizes.SIMULATED_SAMPLE, what="the retimed trajectory"),
    grid_points=Integer(3, cost=lambda n: n * GRID_POINT, what="the retiming's grid"),
)
def retime(
    model: Model,
    path: ArrayLike | str,
    effort_limit: ArrayLike,
    velocity_limit: ArrayLike | None = None,
    samples: int = DEFAULT_SAMPLES,
    grid_points: int = DEFAULT_GRID_POINTS,
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
    backend: str = "numpy",
) -> Trajectory:
    """The time-optimal motion along a platform path, rest to rest, within actuator limits
    (TOPP-RA; the extra ``toppra``; docs/retime.md).

    The path is the cubic spline through the waypoints (not-a-knot, at equally spaced path
    parameters); the efforts along it are the generated inverse dynamics,
    ``tau = a(s) s'' + b(s) s'^2 + c(s)``, and TOPP-RA finds the fastest ``s(t)`` that keeps every
    effort within ``effort_limit`` and, if given, every actuator rate ``J q'`` within
    ``velocity_limit``, at its grid points (between them, within about 1e-4 of the limits at
    the default grid: docs/retime.md). Friction is not modelled: the generated inverse dynamics
    has none; leave a margin for it.

    Args:
        model: the robot, any structure (planar or spatial).
        path: waypoints of the platform pose, (m, k), m >= 2 (k: 3 for planar robots and
            Deltas, 6 for hexapods), or a path CSV file with the pose's columns (``x,y,phi``;
            a trajectory file is one: its other columns are ignored).
        effort_limit: the largest effort of each actuator (N m for motors that turn, N for
            those that push): one number for all, or one per actuator; finite and > 0.
        velocity_limit: the largest rate of each actuator (rad/s or m/s), one number or one per
            actuator; None: no rate limit.
        samples: samples of the returned trajectory, equally spaced in time, both ends included.
        grid_points: the least number of TOPP-RA's grid points (each waypoint interval divided
            equally, so that every waypoint is one); more gives limits held more closely between
            them (the excess falls as the square of the step) for more time.
        min_conditioning: refuse a path that comes closer to a parallel singularity
            (``conditioning``, as ``rpr3gen simulate`` does).
        backend: ``"numpy"`` or ``"c"``: the generated code that evaluates the dynamics.

    Returns:
        The trajectory (``t`` from 0 to the motion's duration; ``q``, ``qd``, ``qdd``), at rest
        at both ends.

    Raises:
        InputError: a path through a pose the robot cannot take (singular, closer to a
            singularity than ``min_conditioning``, outside a joint limit: the waypoint's row or
            the two rows around it), fewer than 2 waypoints, two consecutive ones equal, a value
            not finite, waypoints of another width; a limit not > 0, or not one or one per
            actuator; an effort limit too low to hold the robot at rest somewhere on the path
            (where, and how much it needs); limits that give a motion shorter than 1e-6 s or
            longer than 1e9 s.
        TrajectoryError: the same of a path file, naming its line, or a file that cannot be
            read.
        InputTypeError: an argument of the wrong type.
        SetupError: toppra is not installed (the message names the extra to install).
    """
    # The arguments as @checked converted them: arrays of limits, a file name or an array.
    effort = _per_actuator("effort_limit", np.asarray(effort_limit), model)
    velocity = None
    if velocity_limit is not None:
        velocity = _per_actuator("velocity_limit", np.asarray(velocity_limit), model)
    structure = model.structure
    given = path if isinstance(path, str) else np.asarray(path)
    waypoints = Waypoints.of(given, structure.pose, structure.title)
    topp = _toppra()
    grid = Grid.of(len(waypoints.q), grid_points)
    prof = profile(model, waypoints, grid, min_conditioning, velocity is not None, backend)
    check_hold(model, waypoints, grid, prof, effort)
    # TOPP-RA on sigma = S s in [0, S] (S: _scale): q_sigma = q_s / S, q_sigmasigma = q_ss / S^2.
    S = _scale(prof.a, prof.c, effort, prof.rate, velocity)
    constraints = [topp.EffortConstraint(prof.a / S, prof.b / S**2, prof.c, effort)]
    if velocity is not None and prof.rate is not None:
        constraints.append(topp.RateConstraint(prof.rate / S, velocity))
    knots = S * np.linspace(0.0, 1.0, len(waypoints.q))
    sd = topp.parametrize(knots, waypoints.q, S * grid.s, constraints)
    if sd is None or not np.isfinite(sd).all():
        raise InputError(
            "effort_limit: TOPP-RA finds no motion along the path within these limits (the path "
            "is not controllable there, or badly conditioned); give higher limits or a smoother "
            "path",
            argument="effort_limit",
        )
    if sd.max() ** 2 >= 0.5 * topp.SOLVER_BOUND:
        raise InputError(
            "effort_limit: limits this high give a motion too fast for TOPP-RA's solver to "
            f"resolve along this path (path speeds beyond its bound, {topp.SOLVER_BOUND:g}); are "
            "they this robot's limits?",
            argument="effort_limit",
        )
    seconds = topp.duration(S * grid.s, sd)
    if not DURATIONS[0] <= seconds <= DURATIONS[1]:
        slow = velocity is not None and seconds > DURATIONS[1]  # then the rate limit, likely
        which = "velocity_limit" if slow else "effort_limit"
        raise InputError(
            f"{which}: the time-optimal motion along this path would last {seconds:.3g} s, "
            f"outside {DURATIONS[0]:g} to {DURATIONS[1]:g} s, the durations a trajectory may "
            "have; are they this robot's limits?",
            argument=which,
        )
    t, q, qd, qdd = topp.sample(knots, waypoints.q, S * grid.s, sd, samples)
    return Trajectory(t=t, q=q, qd=qd, qdd=qdd)
