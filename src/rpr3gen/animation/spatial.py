"""A spatial robot moving, in 3-D (``rpr3gen animate`` with a hexapod or a Delta).

Each frame draws the base's joints, every leg as the polyline of its joints (base joint, elbow,
platform joint; a Delta's two rods), the platform as the polygon of its joints, and with
``loads`` the force every leg exerts on the platform (its last joints' loads, one arrow per S,
scaled so that the largest over the motion is a fifth of the robot's size).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rpr3gen.model import Model
from rpr3gen.spatial_modes import elbow, point
from rpr3gen.trajectory import Trajectory

LEG_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")


def _rotation(q: np.ndarray) -> np.ndarray:
    """``Rz(c) Ry(b) Rx(a)`` of each pose, (n, 3, 3) (identity for a Delta's pose)."""
    n = len(q)
    if q.shape[1] == 3:
        return np.broadcast_to(np.eye(3), (n, 3, 3))
    a, b, c = q[:, 3], q[:, 4], q[:, 5]
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    R = np.empty((n, 3, 3))
    R[:, 0] = np.stack([cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa], axis=1)
    R[:, 1] = np.stack([sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa], axis=1)
    R[:, 2] = np.stack([-sb, cb * sa, cb * ca], axis=1)
    return R


def leg_polylines(model: Model, q: np.ndarray, out: dict[str, np.ndarray]) -> list[np.ndarray]:
    """Per leg, its polylines over the samples: a list of (n, points, 3) arrays (a Delta leg:
    the arm and its two rods)."""
    s = model.structure
    R = _rotation(q)
    origin = q[:, :3]
    lines: list[np.ndarray] = []
    for leg in s.legs:
        p = point(model, "p", leg)
        S = origin + R @ p
        B = point(model, "b", leg)
        if s.leg == "UPS":
            lines.append(np.stack([np.broadcast_to(B, S.shape), S], axis=1))
            continue
        a = point(model, "a", leg)
        q1 = out[f"q1_{leg}"]
        E = elbow(model, leg, q1)
        start = np.broadcast_to(B, E.shape) if s.actuated_kind == "R" else B + np.outer(q1, a)
        if not s.leg.endswith("SS2"):
            lines.append(np.stack([start, E, S], axis=1))
            continue
        bar = a if s.leg == "RSS2" else point(model, "bar", leg)
        half = model.params[f"w_{leg}"] / 2 * bar
        arm = np.stack([start, E], axis=1)
        rods = [np.stack([E + k * half, S + k * half], axis=1) for k in (1.0, -1.0)]
        lines.append(np.concatenate([arm, rods[0], rods[1]], axis=1))
    return lines


class SpatialDrawing:
    """The 3-D figure of a spatial robot along a trajectory; :meth:`show` draws a sample."""

    def __init__(
        self,
        model: Model,
        traj: Trajectory,
        out: dict[str, np.ndarray],
        size: tuple[int, int],
        dpi: int,
        loads: bool,
        title: str,
    ) -> None:
        import matplotlib.pyplot as plt

        self.model = model
        s = model.structure
        self.lines = leg_polylines(model, traj.q, out)
        self.t = traj.t
        self.figure = plt.figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
        self.ax: Any = self.figure.add_subplot(projection="3d")
        every = np.concatenate([line.reshape(-1, 3) for line in self.lines])
        low, high = np.nanmin(every, axis=0), np.nanmax(every, axis=0)
        centre, half = (low + high) / 2, float(np.max(high - low)) / 2 * 1.1
        for axis, c in zip("xyz", centre, strict=True):
            getattr(self.ax, f"set_{axis}lim")(c - half, c + half)
            getattr(self.ax, f"set_{axis}label")(f"{axis} [m]")
        self.ax.set_box_aspect((1, 1, 1))
        self.ax.set_title(title, fontsize=9)
        self.artists = [
            self.ax.plot([], [], [], "-o", color=LEG_COLOURS[k % 6], markersize=3, lw=1.5)[0]
            for k in range(len(self.lines))
        ]
        (self.platform,) = self.ax.plot([], [], [], "-", color="black", lw=2.0)
        self.clock = self.ax.text2D(0.02, 0.95, "", transform=self.ax.transAxes)
        self.forces: list[np.ndarray] | None = None
        self.quiver: Any = None
        if loads:
            joint = "3" if s.dof == 6 else None
            forces = []
            for leg in s.legs:
                joints = [joint] if joint else ["4", "5"]
                for j in joints:
                    forces.append(np.stack([out[f"f{a}{j}_{leg}"] for a in "xyz"], axis=1))
            peak = max(float(np.nanmax(np.linalg.norm(f, axis=1))) for f in forces)
            self.scale = (2 * half / 5) / peak if peak > 0 else 0.0
            self.forces = forces

    def _platform_points(self, k: int) -> list[np.ndarray]:
        ends = []
        for line in self.lines:
            if self.model.structure.leg.endswith("SS2"):
                ends += [line[k, 3], line[k, 5]]
            else:
                ends.append(line[k, -1])
        return ends

    def show(self, k: int) -> None:
        """Draw sample ``k``."""
        for artist, line in zip(self.artists, self.lines, strict=True):
            points = line[k]
            if self.model.structure.leg.endswith("SS2"):  # arm, then each rod apart
                nan = np.full((1, 3), np.nan)
                points = np.concatenate([points[:2], nan, points[2:4], nan, points[4:6]])
            artist.set_data_3d(points[:, 0], points[:, 1], points[:, 2])
        ends = self._platform_points(k)
        ring = np.array([*ends, ends[0]])
        self.platform.set_data_3d(ring[:, 0], ring[:, 1], ring[:, 2])
        self.clock.set_text(f"t = {self.t[k]:.3f} s")
        if self.forces is not None:
            if self.quiver is not None:
                self.quiver.remove()
            at = np.array(ends)
            arrows = np.array([f[k] for f in self.forces]) * self.scale
            self.quiver = self.ax.quiver(
                at[:, 0], at[:, 1], at[:, 2], arrows[:, 0], arrows[:, 1], arrows[:, 2],
                color="crimson", linewidth=1.0,
            )  # fmt: skip
