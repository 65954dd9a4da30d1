"""An animation's frames, checked before any work: format, frame rate, speed, size, and which
trajectory sample each frame shows (:func:`plan`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rpr3gen.errors import InputError

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
    if writer == "ffmpeg" and ffmpeg_path() is None:
        raise InputError(
            f"{path}: MP4 needs ffmpeg, which is not installed (pip install 'rpr3gen[video]', "
            "or apt-get install ffmpeg); or write a .gif"
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


def ffmpeg_path() -> str | None:
    """The ffmpeg that writes MP4: matplotlib's (its ``animation.ffmpeg_path``, by default the
    ``ffmpeg`` on the PATH) when that runs, else the build that the ``video`` extra installs
    (imageio-ffmpeg's), else ``None``."""
    import matplotlib as mpl
    from matplotlib import animation as mpl_animation

    if mpl_animation.writers.is_available("ffmpeg"):
        return str(mpl.rcParams["animation.ffmpeg_path"])
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    try:
        return str(imageio_ffmpeg.get_ffmpeg_exe())
    except RuntimeError:  # a platform it has no build for
        return None
