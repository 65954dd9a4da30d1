"""The reference the controller tracks: a platform path, timed within the effort limits.

The path is the gallery's loop (``models/loop-path.csv``: x, y, phi on a closed loop inside the
3-RRR's workspace, docs/retime.md) driven round ``laps`` times. :func:`rpr3gen.retime` times it
as fast as the **nominal** model allows within a fraction of the controller's effort limit, at
rest at both ends, so that the reference is feasible by construction and the remaining effort
is the feedback's: what the controller has to reject the plant's unmodelled payload and
friction with.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

import rpr3gen


@dataclass(frozen=True)
class Reference:
    """A timed platform motion, sampled equally in time, and held at rest after its end.

    Attributes:
        t: (n,) times from 0, s.
        q, qd, qdd: (n, k) the platform pose (x, y in m, phi in rad for a planar robot) and its
            first two time derivatives.
        tau: (n, k) the nominal model's actuator efforts along it (N m for motors that turn),
            the controller's feedforward.
        hold: (k,) the nominal efforts that hold the last pose at rest.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    hold: np.ndarray

    @property
    def duration(self) -> float:
        """The motion's duration, s (the reference rests at ``q[-1]`` after it)."""
        return float(self.t[-1])

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The pose, rate and feedforward efforts at ``times`` (m,), each (m, k).

        Linear interpolation between the samples; after the end, the last pose at rest with the
        efforts that hold it there.
        """
        after = times > self.duration
        times = np.clip(times, 0.0, self.duration)
        cols = range(self.q.shape[1])
        q = np.stack([np.interp(times, self.t, self.q[:, i]) for i in cols], axis=1)
        qd = np.stack([np.interp(times, self.t, self.qd[:, i]) for i in cols], axis=1)
        tau = np.stack([np.interp(times, self.t, self.tau[:, i]) for i in cols], axis=1)
        qd[after] = 0.0
        tau[after] = self.hold
        return q, qd, tau


def loop_reference(
    model: rpr3gen.Model,
    path: Path,
    effort_limit: float,
    laps: int = 2,
    samples: int = 2001,
) -> Reference:
    """The path of ``path`` (a path CSV), ``laps`` times round, timed within ``effort_limit``.

    Args:
        model: the controller's (nominal) robot.
        path: a path CSV file (``x,y,phi``); a closed path (last row = first) is driven round.
        effort_limit: the largest effort of the nominal motion, N m (every actuator).
        laps: how many times round; the waypoints are repeated, the joins not doubled.
        samples: samples of the timed motion (more than enough for a 10 ms controller).
    """
    waypoints = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    closed = np.allclose(waypoints[0], waypoints[-1])
    tail = waypoints[1:] if closed else waypoints
    route = np.vstack([waypoints, *([tail] * (laps - 1))])
    traj = rpr3gen.retime(model, route, effort_limit, samples=samples)
    # retime's samples are the spline's; recompute the efforts at them (the feedforward)
    tau = rpr3gen.actuator_efforts(model, traj.q, traj.qd, traj.qdd)
    rest = np.zeros((1, traj.q.shape[1]))
    hold = rpr3gen.actuator_efforts(model, traj.q[-1:], rest, rest)[0]
    return Reference(t=traj.t, q=traj.q, qd=traj.qd, qdd=traj.qdd, tau=tau, hold=hold)
