"""The figure of an animation (:class:`Drawing`): the base, the legs, the platform, the joint
forces, the efforts as bars and curves; posed at one sample at a time. Drawn on
:class:`matplotlib.figure.Figure` with the Agg canvas, never through ``pyplot``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from rpr3gen.animation.frames import DPI
from rpr3gen.animation.scene import Scene
from rpr3gen.structure import LEGS

if TYPE_CHECKING:  # matplotlib is imported when a movie is made, not with the CLI
    from matplotlib.patches import Polygon

LEG_COLOURS: Mapping[str, str] = {"A": "tab:blue", "B": "tab:orange", "C": "tab:green"}
PLATFORM_COLOUR = "#d9d9d9"
BASE_COLOUR = "0.45"
FORCE_COLOUR = "tab:red"
ROBOT_BOX = (0.07, 0.08, 0.5, 0.8)  # the robot's axes in the figure (left, bottom, width, height)
GROUND = [(0.0, 0.0), (-0.5, -0.8), (0.5, -0.8), (0.0, 0.0)]  # a fixed pivot: apex up, at it


def _box(corners: np.ndarray) -> tuple[float, float, float, float]:
    """``(xmin, xmax, ymin, ymax)`` of points ``(..., 2)``."""
    flat = corners.reshape(-1, 2)
    return (flat[:, 0].min(), flat[:, 0].max(), flat[:, 1].min(), flat[:, 1].max())


class Drawing:
    """The figure of an animation and its artists; :meth:`show` poses them at one sample.

    Args:
        scn: What to draw (:func:`scene`).
        size: Frame width and height, pixels.
        samples: The samples the frames will show (they fix the view and the arrows' scale).
    """

    def __init__(self, scn: Scene, size: tuple[int, int], samples: np.ndarray) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from matplotlib.patches import Polygon

        self.scene = scn
        kinds = scn.model.structure.leg
        actuated = scn.model.structure.actuated
        shown = scn.points[samples]
        xmin, xmax, ymin, ymax = _box(shown)
        span = max(xmax - xmin, ymax - ymin, 1e-3)
        self.block = (0.035 * span, 0.014 * span)  # a slide's half length and half width

        width, height = size
        self.figure = fig = Figure(figsize=(width / DPI, height / DPI), dpi=DPI)
        FigureCanvasAgg(fig)
        fig.text(0.01, 0.98, scn.title, ha="left", va="top", fontsize=9)
        robot = fig.add_axes(ROBOT_BOX)
        curves = fig.add_axes((0.64, 0.47, 0.34, 0.41))
        bars = fig.add_axes((0.64, 0.14, 0.34, 0.18))
        self.axes = {"robot": robot, "curves": curves, "bars": bars}

        # the base: fixed pivots and the rails of prismatic first joints
        for i, leg in enumerate(LEGS):
            if kinds[0] == "R":
                pivot = shown[0, i, 0]
                robot.plot(*pivot, marker=GROUND, markersize=16, color=BASE_COLOUR, zorder=1)
            else:
                u = scn.slides[(leg, 1)][0]
                along = shown[:, i, 0] @ u
                reach = 1.6 * self.block[0]
                ends = np.array([along.min() - reach, along.max() + reach])
                across = shown[0, i, 0] - (shown[0, i, 0] @ u) * u
                rail = across + ends[:, None] * u
                robot.plot(rail[:, 0], rail[:, 1], color=BASE_COLOUR, linewidth=3, zorder=1)
                xmin, xmax = min(xmin, rail[:, 0].min()), max(xmax, rail[:, 0].max())
                ymin, ymax = min(ymin, rail[:, 1].min()), max(ymax, rail[:, 1].max())

        self.platform = Polygon(
            shown[0, :, 2], closed=True, facecolor=PLATFORM_COLOUR, edgecolor="0.2", zorder=2
        )
        robot.add_patch(self.platform)
        (self.centre,) = robot.plot([], [], marker="+", markersize=5, color="0.2", zorder=3)
        self.bodies: dict[tuple[str, int], Any] = {}
        self.pivots: dict[str, Any] = {}
        self.blocks: dict[tuple[str, int], Polygon] = {}
        for leg in LEGS:
            colour = LEG_COLOURS[leg]
            for body, lw in ((1, 4.5), (2, 2.5)):
                (self.bodies[(leg, body)],) = robot.plot(
                    [], [], color=colour, linewidth=lw, solid_capstyle="round", zorder=4
                )
            for joint, kind in enumerate(kinds, start=1):
                if kind == "P":
                    block = Polygon(
                        np.zeros((4, 2)),
                        closed=True,
                        facecolor=colour if joint == actuated else "white",
                        edgecolor=colour,
                        linewidth=1.5,
                        zorder=5,
                    )
                    robot.add_patch(block)
                    self.blocks[(leg, joint)] = block
            (self.pivots[leg],) = robot.plot(
                [], [], linestyle="none", marker="o", markersize=6.5, markeredgewidth=1.5,
                markeredgecolor=colour, markerfacecolor="white", zorder=6,
            )  # fmt: skip
            (self.pivots[leg + "*"],) = robot.plot(
                [], [], linestyle="none", marker="o", markersize=6.5, markeredgewidth=1.5,
                markeredgecolor=colour, markerfacecolor=colour, zorder=6,
            )  # fmt: skip
        self.arrows = None
        self.force_scale = 0.0
        if scn.forces is not None:
            peak = float(np.max(np.linalg.norm(scn.forces[samples], axis=-1)))
            self.force_scale = 0.25 * span / peak if peak > 0 else 0.0
            tails = shown[0].reshape(-1, 2)
            self.arrows = robot.quiver(
                tails[:, 0], tails[:, 1], np.zeros(9), np.zeros(9),
                angles="xy", scale_units="xy", scale=1.0, color=FORCE_COLOUR, width=0.006,
                zorder=7,
            )  # fmt: skip
            robot.text(
                0.99, 0.01, f"joint forces: {0.25 * span:.3g} m = {peak:.3g} N",
                transform=robot.transAxes, ha="right", va="bottom", fontsize=7,
                color=FORCE_COLOUR,
            )  # fmt: skip
        # one metre is as long across as up: widen the view to the axes' shape
        pad = 0.1 * span
        box = (ROBOT_BOX[2] * width) / (ROBOT_BOX[3] * height)
        half_x, half_y = (xmax - xmin) / 2 + pad, (ymax - ymin) / 2 + pad
        half_x, half_y = max(half_x, half_y * box), max(half_y, half_x / box)
        mid_x, mid_y = (xmin + xmax) / 2, (ymin + ymax) / 2
        robot.set_xlim(mid_x - half_x, mid_x + half_x)
        robot.set_ylim(mid_y - half_y, mid_y + half_y)
        robot.set_aspect("equal", adjustable="box")
        robot.tick_params(labelsize=7)
        robot.set_title("world frame (m)", fontsize=7, loc="right")
        self.clock = robot.text(0.01, 1.01, "", transform=robot.transAxes, ha="left",
                                va="bottom", fontsize=8)  # fmt: skip
        robot.text(
            0.99, 0.99, "filled: actuated joint", transform=robot.transAxes, ha="right",
            va="top", fontsize=7, color="0.3",
        )  # fmt: skip

        # the efforts: curves with a cursor, and bars
        label = f"{scn.effort_name} ({scn.effort_unit})"
        for i, leg in enumerate(LEGS):
            curves.plot(scn.t, scn.efforts[:, i], color=LEG_COLOURS[leg], linewidth=1.3,
                        label=f"{scn.effort_name}_{leg}")  # fmt: skip
        curves.legend(fontsize=7, loc="best", frameon=False)
        curves.set_xlabel("t (s)", fontsize=8)
        curves.set_title(f"actuator efforts, {label}", fontsize=8)
        curves.tick_params(labelsize=7)
        curves.set_xlim(scn.t[0], scn.t[-1] if scn.t[-1] > scn.t[0] else scn.t[0] + 1.0)
        self.cursor = curves.axvline(scn.t[0], color="0.3", linewidth=1.0)
        self.dots = [
            curves.plot([], [], marker="o", markersize=4, color=LEG_COLOURS[leg])[0] for leg in LEGS
        ]
        peak = float(np.max(np.abs(scn.efforts))) or 1.0
        self.bars = bars.barh(
            [2, 1, 0], np.zeros(3), color=[LEG_COLOURS[leg] for leg in LEGS], height=0.6
        )
        bars.set_yticks([2, 1, 0], list(LEGS))
        bars.set_xlim(-1.05 * peak, 1.05 * peak)
        bars.axvline(0.0, color="0.3", linewidth=0.8)
        bars.set_xlabel(label, fontsize=8)
        bars.tick_params(labelsize=7)

    def _block(self, centre: np.ndarray, axis: np.ndarray) -> np.ndarray:
        half, thick = self.block
        normal = np.array([-axis[1], axis[0]])
        return np.array(
            [
                centre - half * axis - thick * normal,
                centre + half * axis - thick * normal,
                centre + half * axis + thick * normal,
                centre - half * axis + thick * normal,
            ]
        )

    def show(self, sample: int) -> None:
        """Pose every artist at trajectory sample ``sample``."""
        scn = self.scene
        kinds = scn.model.structure.leg
        actuated = scn.model.structure.actuated
        pts = scn.points[sample]
        self.platform.set_xy(pts[:, 2])
        self.centre.set_data([scn.q[sample, 0]], [scn.q[sample, 1]])
        for i, leg in enumerate(LEGS):
            for body in (1, 2):
                ends = pts[i, body - 1 : body + 1]
                self.bodies[(leg, body)].set_data(ends[:, 0], ends[:, 1])
            passive = [j for j, k in enumerate(kinds) if k == "R" and j + 1 != actuated]
            motor = [j for j, k in enumerate(kinds) if k == "R" and j + 1 == actuated]
            self.pivots[leg].set_data(pts[i, passive, 0], pts[i, passive, 1])
            self.pivots[leg + "*"].set_data(pts[i, motor, 0], pts[i, motor, 1])
            for joint in (1, 2, 3):
                if (leg, joint) in self.blocks:
                    axis = scn.slides[(leg, joint)][sample]
                    self.blocks[(leg, joint)].set_xy(self._block(pts[i, joint - 1], axis))
        if self.arrows is not None and scn.forces is not None:
            self.arrows.set_offsets(pts.reshape(-1, 2))
            uv = scn.forces[sample].reshape(-1, 2) * self.force_scale
            self.arrows.set_UVC(uv[:, 0], uv[:, 1])
        t = scn.t[sample]
        self.clock.set_text(f"t = {t:.2f} s")
        self.cursor.set_xdata([t, t])
        for i, dot in enumerate(self.dots):
            dot.set_data([t], [scn.efforts[sample, i]])
        for bar, value in zip(self.bars, scn.efforts[sample], strict=True):
            bar.set_width(value)

    def rgba(self) -> np.ndarray:
        """The figure as drawn now, ``(height, width, 4)`` uint8."""
        canvas = self.figure.canvas
        canvas.draw()
        return np.asarray(canvas.buffer_rgba()).copy()  # type: ignore[attr-defined]
