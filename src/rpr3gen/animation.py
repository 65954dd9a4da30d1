"""See the robot move: an animation of a model along a trajectory (``rpr3gen animate``).

One drawing serves every structure and both model formats. The generated function
``joint_points`` gives the points of joints 1, 2 and 3 of every leg at a pose (eq. 5, each leg in
its working mode); the model's leg type says which joints are revolute or prismatic and which
one carries the motor. Each frame shows

- the base: a fixed pivot under each revolute joint 1, a rail under each prismatic joint 1;
- the legs: body 1 (joint 1 to joint 2, wide) and body 2 (joint 2 to joint 3, narrow), a circle
  at each revolute joint and a block along its axis at each prismatic one, the actuated joint
  filled in its leg's colour;
- the platform: the triangle through the three joint-3 points, and its centre G;
- optionally (``loads=True``), the force that the earlier body exerts on the later one at every
  joint, as arrows on one scale;
- beside the robot, the actuator efforts as bars, and their curves over the whole motion with a
  cursor at the frame's time.

The movie plays in real time at ``fps`` frames per second (``speed`` times faster); each frame
shows the trajectory's sample nearest its time. GIF goes through Pillow (a dependency of
matplotlib), MP4 through ffmpeg when it is installed. The number of frames and the image size are
bounded (:data:`MAX_FRAMES`, :data:`MIN_SIDE`, :data:`MAX_SIDE`, :data:`MAX_GIF_PIXELS`) and
checked by :func:`plan` before any work; the file is written atomically. Figures are drawn on
:class:`matplotlib.figure.Figure` with the Agg canvas, never through ``pyplot``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rpr3gen import variants
from rpr3gen.atomic import atomic_path
from rpr3gen.backends import evaluate, inverse_dynamics
from rpr3gen.errors import InputError, Rpr3genError
from rpr3gen.model import Model
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING, invalid_samples
from rpr3gen.structure import LEGS
from rpr3gen.trajectory import Trajectory

if TYPE_CHECKING:  # matplotlib and Pillow are imported when a movie is made, not with the CLI
    from matplotlib.animation import AbstractMovieWriter
    from matplotlib.patches import Polygon

__all__ = [
    "DEFAULT_FPS",
    "DEFAULT_SIZE",
    "FORMATS",
    "MAX_FPS",
    "MAX_FRAMES",
    "MAX_GIF_PIXELS",
    "MAX_SIDE",
    "MIN_SIDE",
    "Drawing",
    "Plan",
    "Scene",
    "parse_size",
    "plan",
    "scene",
    "write_animation",
]

DEFAULT_FPS = 20
"""Frames per second of the movie."""

MAX_FPS = 60
"""The most frames per second accepted."""

DEFAULT_SIZE = (800, 400)
"""Width and height of a frame, pixels."""

MIN_SIDE = 240
"""The smallest width or height accepted, pixels (below it the labels overlap)."""

MAX_SIDE = 1920
"""The largest width or height accepted, pixels."""

MAX_FRAMES = 1000
"""The most frames of one movie (50 s at the default 20 frames per second)."""

MAX_GIF_PIXELS = 300_000_000
"""The most pixels (frames x width x height) of a GIF: its frames are held in memory, one byte
per pixel, until the file is written (1000 frames of 800 x 375, or 300 MB)."""

DPI = 100
"""Dots per inch of the figure: sizes are given in pixels, so this only scales the fonts."""

FORMATS: Mapping[str, str] = {".gif": "pillow", ".mp4": "ffmpeg"}
"""Output suffix -> matplotlib movie writer."""

PALETTE_COLOURS = 128
"""Colours of the GIF's one palette (the drawing uses a few dozen, plus antialiasing)."""

LEG_COLOURS: Mapping[str, str] = {"A": "tab:blue", "B": "tab:orange", "C": "tab:green"}
PLATFORM_COLOUR = "#d9d9d9"
BASE_COLOUR = "0.45"
FORCE_COLOUR = "tab:red"
ROBOT_BOX = (0.07, 0.08, 0.5, 0.8)  # the robot's axes in the figure (left, bottom, width, height)
GROUND = [(0.0, 0.0), (-0.5, -0.8), (0.5, -0.8), (0.0, 0.0)]  # a fixed pivot: apex up, at it


@dataclass(frozen=True)
class Plan:
    """What a movie will be, checked before anything is computed or drawn.

    Attributes:
        path: The output file (``.gif`` or ``.mp4``).
        writer: The matplotlib movie writer, ``"pillow"`` or ``"ffmpeg"``.
        fps: Frames per second of the movie.
        speed: Trajectory seconds per movie second.
        size: Width and height of each frame, pixels.
        samples: For each frame, the index of the trajectory sample it shows, shape
            ``(frames,)``.
    """

    path: Path
    writer: str
    fps: int
    speed: float
    size: tuple[int, int]
    samples: np.ndarray

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.samples.size)


def parse_size(text: str) -> tuple[int, int]:
    """``"800x400"`` -> ``(800, 400)``: width and height in pixels.

    Raises:
        InputError: If ``text`` is not two positive integers joined by ``x``.
    """
    parts = str(text).lower().split("x")
    try:
        width, height = (int(p) for p in parts)
    except ValueError:
        raise InputError(
            f"size: expected WIDTHxHEIGHT in pixels, e.g. 800x400, got {text!r}"
        ) from None
    return width, height


def plan(
    t: np.ndarray,
    out: str | Path,
    *,
    fps: int = DEFAULT_FPS,
    speed: float = 1.0,
    size: tuple[int, int] = DEFAULT_SIZE,
) -> Plan:
    """Check an animation's request and fix its frames, before any work.

    Frame ``k`` is at trajectory time ``t[0] + k * speed / fps`` up to the last sample, and shows
    the sample nearest that time.

    Args:
        t: The trajectory's sample times, s, shape ``(n,)``, increasing.
        out: The file to write; its suffix picks the format (:data:`FORMATS`).
        fps: Frames per second of the movie, an integer from 1 to :data:`MAX_FPS`.
        speed: Trajectory seconds per movie second (1: real time), > 0.
        size: Frame width and height, pixels, each in [:data:`MIN_SIDE`, :data:`MAX_SIDE`]
            (even for MP4).

    Raises:
        InputError: For an unknown suffix, MP4 without ffmpeg, or a size, frame rate, speed or
            number of frames out of bounds; the message is one line.
    """
    path = Path(out)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise InputError(
            f"{path}: the movie's suffix must be {' or '.join(FORMATS)}, got {suffix or 'none'!r}"
        )
    writer = FORMATS[suffix]
    if writer == "ffmpeg" and not _ffmpeg_available():
        raise InputError(
            f"{path}: MP4 needs ffmpeg, which is not installed (e.g. apt-get install ffmpeg); "
            "or write a .gif"
        )
    if isinstance(fps, bool) or not (isinstance(fps, int) and 1 <= fps <= MAX_FPS):
        raise InputError(f"fps: must be an integer from 1 to {MAX_FPS} frames/s, got {fps!r}")
    if not (isinstance(speed, int | float) and math.isfinite(speed) and speed > 0):
        raise InputError(f"speed: must be a positive number, got {speed!r}")
    width, height = size
    for name, side in (("width", width), ("height", height)):
        if not (isinstance(side, int) and MIN_SIDE <= side <= MAX_SIDE):
            raise InputError(
                f"size: the {name} must be {MIN_SIDE} to {MAX_SIDE} pixels, got {side!r}"
            )
        if writer == "ffmpeg" and side % 2:
            raise InputError(f"size: the {name} of an MP4 must be even, got {side}")
    t = np.asarray(t, dtype=np.float64)
    duration = float(t[-1] - t[0])
    count = math.floor(duration * fps / speed * (1 + 1e-12)) + 1
    if count > MAX_FRAMES:
        raise InputError(
            f"the movie would have {count} frames ({duration:g} s of trajectory at {fps:g} "
            f"frames/s, speed {speed:g}), more than {MAX_FRAMES}: lower fps or raise speed"
        )
    if writer == "pillow" and count * width * height > MAX_GIF_PIXELS:
        raise InputError(
            f"the GIF would hold {count} frames of {width} x {height} pixels, more than "
            f"{MAX_GIF_PIXELS:.3g} pixels in all: make it smaller, lower fps or write an .mp4"
        )
    times = t[0] + np.arange(count) * (speed / fps)
    if t.size == 1:
        samples = np.zeros(count, dtype=np.intp)
    else:  # the nearer of the samples around each time, the earlier on a tie
        after = np.clip(np.searchsorted(t, times), 1, t.size - 1)
        before = after - 1
        samples = np.where(np.abs(t[after] - times) < np.abs(times - t[before]), after, before)
    return Plan(path, writer, fps, float(speed), (width, height), samples)


def _ffmpeg_available() -> bool:
    from matplotlib import animation as mpl_animation

    return bool(mpl_animation.writers.is_available("ffmpeg"))


@dataclass(frozen=True)
class Scene:
    """Everything an animation draws, for every sample of the trajectory.

    Attributes:
        model: The robot.
        title: The figure's title.
        t: Sample times, s, shape ``(n,)``.
        q: Platform poses ``(x, y, phi)``, shape ``(n, 3)``.
        points: Joint points, world frame (m), shape ``(n, 3, 3, 2)``: sample, leg (A, B, C),
            joint (1, 2, 3), ``(x, y)``: the generated ``joint_points``.
        efforts: Actuator efforts of legs A, B, C, shape ``(n, 3)``.
        effort_name: Their output family (``tau``; the paper's ``m10`` or ``f21z``).
        effort_unit: ``"N m"`` or ``"N"``.
        slides: The current unit axis (world) of each prismatic joint, shape ``(n, 2)``, by
            ``(leg, joint)``.
        forces: With joint loads, the force of the earlier body on the later one at each joint
            (world, N), shape ``(n, 3, 3, 2)`` like ``points``; else None.
    """

    model: Model
    title: str
    t: np.ndarray
    q: np.ndarray
    points: np.ndarray
    efforts: np.ndarray
    effort_name: str
    effort_unit: str
    slides: Mapping[tuple[str, int], np.ndarray]
    forces: np.ndarray | None = None


def scene(
    model: Model,
    traj: Trajectory,
    *,
    title: str | None = None,
    loads: bool = False,
    backend: str = "numpy",
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
) -> Scene:
    """Evaluate what an animation of ``model`` along ``traj`` draws.

    Args:
        model: The robot, of any structure or format.
        traj: The platform's motion.
        title: The figure's title (default: the model's name and structure).
        loads: Also compute every joint's force (drawn as arrows).
        backend: ``"numpy"`` or ``"c"``, for the generated functions.
        min_conditioning: Refuse poses whose ``conditioning`` is below this, as ``rpr3gen
            simulate`` does.

    Raises:
        Rpr3genError: If a sample is singular, too close to a singularity or outside a joint
            limit (the message names the first one and why).
    """
    out = inverse_dynamics(model, traj.q, traj.qd, traj.qdd, backend=backend)
    thresholds = variants.load(model.structure, model.generated).thresholds
    invalid = invalid_samples(model, traj.q, out, min_conditioning, thresholds)
    if invalid is not None:
        k = invalid.first
        raise Rpr3genError(
            f"t = {traj.t[k]:.6g} s (sample {k + 1} of {len(traj.t)}): {invalid.reason}; "
            "the animation draws valid poses only"
        )
    (flat,), _ = evaluate(model, "joint_points", (traj.q,), backend=backend)
    points = flat.reshape(-1, 3, 3, 2).copy()
    structure = model.structure
    family = structure.effort
    efforts = np.column_stack([out[f"{family}_{leg}"] for leg in LEGS])
    unit = "N m" if structure.actuated_kind == "R" else "N"
    if title is None:
        title = f"{model.name}: {structure.title}"
    forces = _joint_forces(model, out, points) if loads else None
    return Scene(
        model, title, traj.t, traj.q, points, efforts, family, unit, _slides(model, out), forces
    )


def _home_axis(model: Model, leg: str, joint: int) -> np.ndarray:
    """Prismatic joint ``joint``'s unit axis when every joint coordinate is zero (world)."""
    p = model.params
    if model.structure.paper:  # the slide along the leg, at alpha from x0
        angle = p[f"alpha_{leg}"]
        return np.array([math.cos(angle), math.sin(angle)])
    return np.array([p[f"ux{joint}_{leg}"], p[f"uy{joint}_{leg}"]])


def _slides(model: Model, out: Mapping[str, np.ndarray]) -> dict[tuple[str, int], np.ndarray]:
    """The current axis of every prismatic joint: its home axis turned with the body that
    carries it, by the revolute coordinates before it in the chain."""
    structure = model.structure
    slides = {}
    for leg in LEGS:
        turn = np.zeros_like(out["conditioning"])
        for joint, kind in enumerate(structure.leg, start=1):
            if kind == "P":
                u = _home_axis(model, leg, joint)
                c, s = np.cos(turn), np.sin(turn)
                slides[(leg, joint)] = np.column_stack([c * u[0] - s * u[1], s * u[0] + c * u[1]])
            else:
                turn = turn + out[f"{structure.coordinate(joint)}_{leg}"]
    return slides


def _joint_forces(model: Model, out: Mapping[str, np.ndarray], points: np.ndarray) -> np.ndarray:
    """The force at every joint (world, N), ``(n, 3, 3, 2)``.

    The general format gives them in world components (``fxj``, ``fyj``); the paper's gives the
    slide's and the platform joint's along the leg axis ``e`` (``f21z``, ``f32z``) and its normal
    ``n`` (``f21y``, ``f32y``), with ``e`` from A1 to A3.
    """
    forces = np.zeros_like(points)
    for i, leg in enumerate(LEGS):
        if not model.structure.paper:
            for j in (1, 2, 3):
                forces[:, i, j - 1] = np.column_stack([out[f"fx{j}_{leg}"], out[f"fy{j}_{leg}"]])
            continue
        axis = points[:, i, 2] - points[:, i, 0]
        e = axis / np.linalg.norm(axis, axis=1, keepdims=True)
        n = np.column_stack([-e[:, 1], e[:, 0]])
        forces[:, i, 0] = np.column_stack([out[f"f10x_{leg}"], out[f"f10y_{leg}"]])
        forces[:, i, 1] = out[f"f21z_{leg}"][:, None] * e + out[f"f21y_{leg}"][:, None] * n
        forces[:, i, 2] = out[f"f32z_{leg}"][:, None] * e + out[f"f32y_{leg}"][:, None] * n
    return forces


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


@cache
def _gif_writer() -> type[AbstractMovieWriter]:
    """Pillow's GIF writer, each frame reduced to the first frame's palette as it is grabbed:
    one byte per pixel held until the file is written instead of four, one colour table for the
    whole file, and no dithering, so the unchanged parts of consecutive frames stay identical
    and Pillow stores only what changed."""
    from matplotlib.animation import PillowWriter
    from PIL import Image

    class GifWriter(PillowWriter):  # type: ignore[misc]
        def setup(self, fig: Any, outfile: Any, dpi: float | None = None) -> None:
            super().setup(fig, outfile, dpi=dpi)
            self._palette: Image.Image | None = None

        def grab_frame(self, **savefig_kwargs: Any) -> None:
            super().grab_frame(**savefig_kwargs)
            frames = self._frames  # type: ignore[attr-defined]
            frame = frames[-1].convert("RGB")
            if self._palette is None:
                self._palette = frame.quantize(
                    colors=PALETTE_COLOURS,
                    method=Image.Quantize.MEDIANCUT,
                    dither=Image.Dither.NONE,
                )
                frames[-1] = self._palette
            else:
                frames[-1] = frame.quantize(palette=self._palette, dither=Image.Dither.NONE)

        def finish(self) -> None:
            if self._frames:  # type: ignore[attr-defined]  # nothing to write when the first frame failed (the file is dropped)
                super().finish()

    return GifWriter


def _writer(plan_: Plan) -> AbstractMovieWriter:
    if plan_.writer == "pillow":
        return _gif_writer()(fps=plan_.fps)
    from matplotlib.animation import FFMpegWriter

    return FFMpegWriter(fps=plan_.fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])


def write_animation(
    model: Model,
    traj: Trajectory,
    out: str | Path,
    *,
    fps: int = DEFAULT_FPS,
    speed: float = 1.0,
    size: tuple[int, int] = DEFAULT_SIZE,
    loads: bool = False,
    title: str | None = None,
    backend: str = "numpy",
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
) -> Plan:
    """Write a movie of ``model`` moving along ``traj``: GIF or MP4 by the suffix of ``out``.

    Everything is checked first (:func:`plan`: format, ffmpeg for MP4, size, frame rate,
    number of frames; :func:`scene`: every pose valid), then drawn; the file appears only
    complete, and a failure leaves no partial file (an existing one is untouched).

    Args:
        model: The robot, any structure and format.
        traj: The platform's motion.
        out: ``*.gif`` (Pillow) or ``*.mp4`` (ffmpeg); its folder is created if missing.
        fps: Frames per second of the movie.
        speed: Trajectory seconds per movie second (1: real time).
        size: Frame width and height, pixels.
        loads: Draw the force at every joint as an arrow.
        title: The figure's title (default: the model's name and structure).
        backend: ``"numpy"`` or ``"c"``, for the generated functions.
        min_conditioning: Refuse poses whose ``conditioning`` is below this.

    Returns:
        The plan that was written (its path, frames and size).

    Raises:
        InputError: For a request out of bounds (see :func:`plan`).
        Rpr3genError: For a trajectory through an invalid pose.
        OSError: If the file cannot be written.
    """
    the_plan = plan(traj.t, out, fps=fps, speed=speed, size=size)
    scn = scene(
        model, traj, title=title, loads=loads, backend=backend, min_conditioning=min_conditioning
    )
    drawing = Drawing(scn, the_plan.size, the_plan.samples)
    the_plan.path.parent.mkdir(parents=True, exist_ok=True)
    writer = _writer(the_plan)
    with atomic_path(the_plan.path) as tmp, writer.saving(drawing.figure, tmp, dpi=DPI):
        for sample in the_plan.samples:
            drawing.show(int(sample))
            writer.grab_frame()
    return the_plan
