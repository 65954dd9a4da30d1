"""The movie writers: Pillow's GIF writer with one palette for the whole file, or ffmpeg's MP4
(the system's ffmpeg, or imageio-ffmpeg's build: :func:`~.frames.ffmpeg_path`)."""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING, Any

from rpr3gen.animation.frames import Plan, ffmpeg_path

if TYPE_CHECKING:  # matplotlib and Pillow are imported when a movie is made, not with the CLI
    from matplotlib.animation import AbstractMovieWriter, FFMpegWriter

PALETTE_COLOURS = 128
"""Colours of the GIF's one palette (the drawing uses a few dozen, plus antialiasing)."""


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


def writer(plan_: Plan) -> AbstractMovieWriter:
    if plan_.writer == "pillow":
        return _gif_writer()(fps=plan_.fps)
    return _ffmpeg_writer(ffmpeg_path())(
        fps=plan_.fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"]
    )


def _ffmpeg_writer(path: str | None) -> type[FFMpegWriter]:
    """matplotlib's ffmpeg writer running ``path`` (:func:`~.frames.ffmpeg_path`), which may be
    imageio-ffmpeg's build, without changing the user's ``rcParams``."""
    from matplotlib.animation import FFMpegWriter

    class Writer(FFMpegWriter):  # type: ignore[misc]
        @classmethod
        def bin_path(cls) -> str:
            return path or str(super().bin_path())

    return Writer
