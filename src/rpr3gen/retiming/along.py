"""The path and the robot's dynamics along it: the spline through the waypoints, TOPP-RA's grid,
the efforts' coefficients ``tau = a(s) s'' + b(s) s'^2 + c(s)`` and the actuator rates per unit
path speed, from the generated code; and the two refusals that need them, a pose the robot cannot
take and an effort limit that cannot hold it at rest.

The path is the not-a-knot cubic spline through the m waypoints at ``s = i / (m - 1)``, ``s`` in
``[0, 1]`` (what ``toppra.SplineInterpolator`` builds: scipy's ``CubicSpline``). Along it, with
``q(s)``, ``q_s = dq/ds`` and ``q_ss``, the platform moves with ``q' = q_s s'`` and
``q'' = q_s s'' + q_ss s'^2``, so the inverse dynamics, affine in ``q''`` and quadratic in ``q'``,
gives ``tau = a s'' + b s'^2 + c`` with ``c = tau(q, 0, 0)`` (gravity and the payload),
``a = tau(q, 0, q_s) - c`` and ``b = tau(q, q_s, q_ss) - c``: three evaluations of the generated
inverse dynamics at each grid point, in one call. The actuator rates are ``qa' = J q_s s'``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rpr3gen import sizes, variants
from rpr3gen.backends import inverse_dynamics
from rpr3gen.control import actuator_jacobian
from rpr3gen.errors import InputError
from rpr3gen.model import Model
from rpr3gen.policy import invalid_samples
from rpr3gen.retiming.waypoints import Waypoints

__all__ = ["GRID_POINT", "Grid", "Profile", "check_hold", "profile", "spline"]

#: Bytes per grid point: the spline's values, three inverse dynamics with every output (a
#: hexapod's about 150 values each), TOPP-RA's constraint tables and its Python loop's objects.
GRID_POINT = 16 * sizes.KIB


@dataclass(frozen=True)
class Grid:
    """TOPP-RA's grid on ``[0, 1]``: every waypoint interval divided into ``per`` equal steps,
    so that waypoint ``i`` is grid point ``i * per``."""

    s: np.ndarray
    per: int

    @classmethod
    def of(cls, waypoints: int, points: int) -> Grid:
        """At least ``points`` grid points for a path of ``waypoints`` waypoints.

        Raises:
            InputError: the grid (of at least one point a waypoint) beyond the memory limit.
        """
        per = max(1, -(-(points - 1) // (waypoints - 1)))
        n = (waypoints - 1) * per + 1
        what = "the retiming's grid (at least one point a waypoint)"
        sizes.check("path", n, lambda k: k * GRID_POINT, what, unit="grid points")
        return cls(np.linspace(0.0, 1.0, n), per)

    def where(self, waypoints: Waypoints, g: int, inline: bool = False) -> str:
        """Where grid point ``g`` is: its waypoint's row, or the two it lies between."""
        i, step = divmod(g, self.per)
        return waypoints.row(i, inline) if step == 0 else waypoints.between(i, inline)


def spline(waypoints: np.ndarray, knots: np.ndarray) -> object:
    """scipy's not-a-knot ``CubicSpline`` through ``waypoints`` at ``knots``."""
    from scipy.interpolate import CubicSpline

    return CubicSpline(knots, waypoints, bc_type="not-a-knot")


@dataclass(frozen=True)
class Profile:
    """The path and the dynamics at each grid point, ``s`` in ``[0, 1]``: the pose ``q``, its
    derivatives ``qs``, ``qss`` (n, k); the efforts' coefficients ``a``, ``b``, ``c`` (n,
    actuators); the actuator rates per unit path speed ``rate = J q_s`` (None unless asked)."""

    q: np.ndarray
    qs: np.ndarray
    qss: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    rate: np.ndarray | None


def _pose(model: Model, q: np.ndarray) -> str:
    return ", ".join(f"{n} = {v:.6g}" for n, v in zip(model.structure.pose, q, strict=True))


def profile(
    model: Model,
    waypoints: Waypoints,
    grid: Grid,
    min_conditioning: float,
    rates: bool,
    backend: str,
) -> Profile:
    """The dynamics along the path at each grid point (module docstring).

    Raises:
        InputError (TrajectoryError for a path file): the first grid point that is singular,
            closer to a singularity than ``min_conditioning`` or outside a joint limit, named by
            its waypoint's row or the two rows it lies between, with its pose and the reason.
    """
    path = spline(waypoints.q, np.linspace(0.0, 1.0, len(waypoints.q)))
    s = grid.s
    q, qs, qss = path(s), path(s, 1), path(s, 2)  # type: ignore[operator]
    zero = np.zeros_like(q)
    out = inverse_dynamics(
        model, np.vstack([q, q, q]), np.vstack([zero, zero, qs]), np.vstack([zero, qs, qss]),
        backend=backend,
    )  # fmt: skip
    n = len(s)
    rest = {name: value[:n] for name, value in out.items()}
    thresholds = variants.load(model.structure, model.generated).thresholds
    invalid = invalid_samples(model, q, rest, min_conditioning, thresholds)
    if invalid is not None:
        g = invalid.first
        raise waypoints._error(
            f"{grid.where(waypoints, g)}: the path reaches a pose the robot cannot take "
            f"({_pose(model, q[g])}): {invalid.reason}"
        )
    structure = model.structure
    names = [f"{structure.effort}_{leg}" for leg in structure.legs]
    tau = np.stack([out[name] for name in names], axis=1)
    c = tau[:n]
    rate = None
    if rates:
        rate = np.einsum("nij,nj->ni", actuator_jacobian(model, q, backend), qs)
    return Profile(q, qs, qss, tau[n : 2 * n] - c, tau[2 * n :] - c, c, rate)


def check_hold(
    model: Model, waypoints: Waypoints, grid: Grid, prof: Profile, limit: np.ndarray
) -> None:
    """Refuse an effort limit that cannot hold the robot at rest somewhere on the path.

    At rest the efforts are ``c`` (gravity and the payload); a limit at or below ``|c|`` leaves
    no effort to start or stop there, and TOPP-RA would find no motion.

    Raises:
        InputError: naming ``effort_limit``, the first grid point at fault (its waypoint's row
            or the two rows it lies between), its pose, the actuator and the effort it needs,
            and the largest effort at rest of that actuator along the path.
    """
    need = np.abs(prof.c)
    bad = ~(need < limit)
    if not bad.any():
        return
    g = int(np.argmax(bad.any(axis=1)))
    j = int(np.argmax(bad[g]))
    structure = model.structure
    unit = "N m" if structure.actuated_kind == "R" else "N"
    name = f"{structure.effort}_{structure.legs[j]}"
    where = grid.where(waypoints, g, inline=True)
    raise InputError(
        f"effort_limit: {limit[j]:g} {unit} cannot hold the robot at rest at {where} "
        f"({_pose(model, prof.q[g])}): {name} is {prof.c[g, j]:.6g} {unit} there (gravity and "
        f"the payload); at rest, |{name}| reaches {need[:, j].max():.6g} {unit} along the path",
        argument="effort_limit",
    )
