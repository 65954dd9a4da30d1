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

from pathlib import Path

from rpr3gen.animation.drawing import Drawing
from rpr3gen.animation.frames import (
    DEFAULT_FPS,
    DEFAULT_SIZE,
    DPI,
    FORMATS,
    MAX_FPS,
    MAX_FRAMES,
    MAX_GIF_PIXELS,
    MAX_SIDE,
    MIN_SIDE,
    Plan,
    parse_size,
    plan,
)
from rpr3gen.animation.scene import Scene, scene
from rpr3gen.animation.spatial import SpatialDrawing
from rpr3gen.animation.writers import writer
from rpr3gen.atomic import atomic_path
from rpr3gen.backends import inverse_dynamics
from rpr3gen.model import Model
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.trajectory import Trajectory

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


def _spatial_drawing(
    model: Model,
    traj: Trajectory,
    the_plan: Plan,
    loads: bool,
    title: str | None,
    backend: str,
    min_conditioning: float,
) -> SpatialDrawing:
    """A spatial robot's 3-D drawing, its trajectory refused where a pose is invalid (as
    ``rpr3gen simulate`` refuses it)."""
    from rpr3gen.simulation import screen

    out = inverse_dynamics(model, traj.q, traj.qd, traj.qdd, backend=backend)
    screen(model, traj, out, min_conditioning, allow_invalid=False)
    heading = title or f"{model.name}: {model.structure.title}"
    return SpatialDrawing(model, traj, out, the_plan.size, DPI, loads, heading)


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
        TrajectoryError: For a trajectory through an invalid pose.
        OSError: If the file cannot be written.
    """
    the_plan = plan(traj.t, out, fps=fps, speed=speed, size=size)
    drawing: Drawing | SpatialDrawing
    if model.structure.spatial:
        drawing = _spatial_drawing(model, traj, the_plan, loads, title, backend, min_conditioning)
    else:
        scn = scene(
            model, traj, title=title, loads=loads, backend=backend,
            min_conditioning=min_conditioning,
        )  # fmt: skip
        drawing = Drawing(scn, the_plan.size, the_plan.samples)
    the_plan.path.parent.mkdir(parents=True, exist_ok=True)
    movie = writer(the_plan)
    with atomic_path(the_plan.path) as tmp, movie.saving(drawing.figure, tmp, dpi=DPI):
        for sample in the_plan.samples:
            drawing.show(int(sample))
            movie.grab_frame()
    return the_plan
