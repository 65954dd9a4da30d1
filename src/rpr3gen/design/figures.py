"""The four workspace figures: reachable region, conditioning with the singularity curves, peak
static effort, orientation range.

Drawn as :mod:`rpr3gen.plots` draws: a :class:`~matplotlib.figure.Figure` on the Agg canvas (no
``pyplot`` state), fixed size, resolution and PNG metadata, written atomically; the same map
gives the same files.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from matplotlib import colormaps, patheffects
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.figure import Figure
from matplotlib.image import AxesImage
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter

from rpr3gen.atomic import atomic_write
from rpr3gen.design.maps import WorkspaceMap
from rpr3gen.model import LEGS
from rpr3gen.plots import DPI

__all__ = ["CLIP_PERCENTILE", "FIGSIZE", "FIGURES", "OVER_COLOR", "write_figures"]

FIGSIZE = (6.4, 6.4)
"""Figure size, inches."""

LEG_COLORS = {"A": "tab:blue", "B": "tab:orange", "C": "tab:green"}
"""Colour of each leg's pivot and stroke-limit curves."""


CLIP_PERCENTILE = 95.0
"""The peak-effort map's colour scale ends at this percentile of the reachable points' efforts
(when the tail above it is long: :data:`CLIP_RATIO`)."""

CLIP_RATIO = 10.0
"""The scale is clipped only when the largest effort exceeds the percentile this many times (a
parallel singularity nearby); else it spans every point."""

OVER_COLOR = "#33b5e5"
"""Colour of the points above the peak-effort map's colour scale (not in its colour map)."""


def _frame(wmap: WorkspaceMap, title: str) -> tuple[Figure, Axes]:
    fig = Figure(figsize=FIGSIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.set_aspect("equal")
    ax.set_xlabel("x of G [m]")
    ax.set_ylabel("y of G [m]")
    phi = f"φ = {math.degrees(wmap.phi):.4g}°"
    ax.set_title(f"{title}\n{wmap.model.name}, {phi}")
    return fig, ax


def _legend(fig: Figure, handles: Sequence[Artist], ncols: int = 3) -> None:
    """The legend below the map, where it hides nothing."""
    fig.legend(handles=handles, loc="outside lower center", ncols=ncols, fontsize="small")


def _tick(value: float, _position: int | None = None) -> str:
    """A log colour bar's tick label: the values 1, 2, 5 times a power of ten, in plain digits."""
    if value <= 0:
        return ""
    digit = round(value / 10 ** math.floor(math.log10(value)), 6)
    return _amount(value) if digit in (1, 2, 5) else ""


def _amount(value: float) -> str:
    """``24,658`` or ``835`` or ``0.0123``: three significant digits at least, no exponent."""
    return f"{value:,.0f}" if value >= 100 else f"{value:.3g}"


def _extent(wmap: WorkspaceMap) -> tuple[float, float, float, float]:
    dx = (wmap.x[1] - wmap.x[0]) / 2 if wmap.x.size > 1 else 0.0
    dy = (wmap.y[1] - wmap.y[0]) / 2 if wmap.y.size > 1 else 0.0
    return (wmap.x[0] - dx, wmap.x[-1] + dx, wmap.y[0] - dy, wmap.y[-1] + dy)


def _image(ax: Axes, wmap: WorkspaceMap, values: np.ndarray, **kw: Any) -> AxesImage:
    return ax.imshow(
        np.ma.masked_invalid(values),
        origin="lower",
        extent=_extent(wmap),
        interpolation="nearest",
        **kw,
    )


def _outline(ax: Axes, wmap: WorkspaceMap, color: str = "k") -> list[Line2D]:
    """The edge of the reachable region (a white line gets a black rim, to show in the legend)."""
    if not (wmap.reachable.any() and not wmap.reachable.all()):
        return []
    rim = [patheffects.withStroke(linewidth=2.5, foreground="k")] if color == "white" else None
    contours = ax.contour(wmap.x, wmap.y, wmap.reachable.astype(float), levels=[0.5],
                          colors=color, linewidths=1.0)  # fmt: skip
    contours.set(path_effects=rim)
    return [Line2D([], [], color=color, linewidth=1.0, path_effects=rim,
                   label="edge of the reachable region")]  # fmt: skip


def _pivots(ax: Axes, wmap: WorkspaceMap) -> list[Line2D]:
    """The base pivots A1, B1, C1 (inside the box or not; the axes keep the grid's limits); a
    general model's base joints at home and the rails of prismatic ones, in the legend when
    they are in the map."""
    x0, x1, y0, y1 = _extent(wmap)
    general = not wmap.model.structure.paper
    slide = general and wmap.model.structure.leg[0] == "P"
    rails = [_rail(wmap, leg) for leg in LEGS] if slide else []
    handles = []
    if any(_inside((x0, x1, y0, y1), *rail) for rail in rails):  # one entry, legs' colours
        handles.append(Line2D([], [], color="0.5", linewidth=3.0, alpha=0.6,
                              label="rails (travel of A1, B1, C1)"))  # fmt: skip
    for k, (leg, x, y) in enumerate(wmap.base_points()):
        if slide:
            ax.plot(*rails[k], color=LEG_COLORS[leg], linewidth=3.0, alpha=0.6,
                    solid_capstyle="butt")  # fmt: skip
        (h,) = ax.plot(
            x,
            y,
            marker="^",
            markersize=9,
            linestyle="none",
            color=LEG_COLORS[leg],
            markeredgecolor="k",
            label=f"slide {leg}1 at home" if slide else f"base pivot {leg}1",
        )
        if not general or _inside((x0, x1, y0, y1), [x], [y]):
            handles.append(h)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    return handles


def _inside(box: tuple[float, float, float, float], xs: list[float], ys: list[float]) -> bool:
    """Some point of the polyline ``xs, ys`` (sampled) is inside ``box``."""
    t = np.linspace(0.0, 1.0, 65)[:, np.newaxis]
    points = np.column_stack([xs, ys])
    path = points[:-1] + t[..., np.newaxis] * np.diff(points, axis=0) if len(xs) > 1 else points
    px, py = np.reshape(path, (-1, 2)).T
    return bool(np.any((px >= box[0]) & (px <= box[1]) & (py >= box[2]) & (py <= box[3])))


def _rail(wmap: WorkspaceMap, leg: str) -> tuple[list[float], list[float]]:
    """The segment that a general model's prismatic base joint ``leg`` 1 travels along."""
    p = wmap.model.params
    lo, hi = next((lo, hi) for k, family, lo, hi in wmap.limits if (k, family) == (leg, "q1"))
    x, y, ux, uy = (p[f"{c}1_{leg}"] for c in ("x", "y", "ux", "uy"))
    return [x + lo * ux, x + hi * ux], [y + lo * uy, y + hi * uy]


def reachable_figure(wmap: WorkspaceMap) -> Figure:
    """The reachable region, with its area."""
    fig, ax = _frame(wmap, f"Reachable workspace: {wmap.area:.4g} m²")
    cmap = ListedColormap(["#f2f2f2", "#4c8bc9"])
    _image(ax, wmap, wmap.reachable.astype(float), cmap=cmap, vmin=0.0, vmax=1.0)
    handles = _outline(ax, wmap) + _pivots(ax, wmap)
    ax.text(0.01, 0.01, f"{wmap.limits_text()}; conditioning ≥ {wmap.min_conditioning:g}",
            transform=ax.transAxes, fontsize="small", va="bottom")  # fmt: skip
    _legend(fig, handles)
    return fig


def conditioning_figure(wmap: WorkspaceMap) -> Figure:
    """Conditioning heat map with the parallel singularity (conditioning 0) and the joint limits
    (the paper's strokes: its serial singularities)."""
    fig, ax = _frame(wmap, "Conditioning and singularity curves")
    image = _image(ax, wmap, wmap.conditioning, cmap="viridis", vmin=0.0, vmax=1.0)
    fig.colorbar(image, ax=ax, label="conditioning (0 = parallel singularity)", shrink=0.8)
    handles = []
    signed = np.ma.masked_invalid(wmap.jacobian_sign * wmap.conditioning)
    if signed.count() and signed.min() < 0 < signed.max():
        ax.contour(wmap.x, wmap.y, signed, levels=[0.0], colors="red", linewidths=2.0)
        handles.append(Line2D([], [], color="red", linewidth=2.0,
                              label="parallel singularity (conditioning 0)"))  # fmt: skip
    drawn: set[str] = set()
    for k, (leg, family, lo, hi) in enumerate(wmap.limits):
        lam = np.ma.masked_invalid(wmap.coordinates[..., k])
        levels = [v for v in (lo, hi) if lam.count() and lam.min() < v < lam.max()]
        if levels:
            style: Literal["--", ":"] = (
                "--" if family in ("lambda21", wmap.model.structure.actuator) else ":"
            )
            ax.contour(wmap.x, wmap.y, lam, levels=levels, colors=LEG_COLORS[leg],
                       linestyles=style, linewidths=1.5)  # fmt: skip
            if family == "lambda21":  # the paper's: one entry per leg
                handles.append(Line2D([], [], color=LEG_COLORS[leg], linestyle=style,
                                      label=f"stroke limit, leg {leg}"))  # fmt: skip
            elif family not in drawn:  # one entry per coordinate, in the legs' colours
                drawn.add(family)
                handles.append(Line2D([], [], color="0.3", linestyle=style,
                                      label=f"limit of {family}, each leg"))  # fmt: skip
    handles += _outline(ax, wmap, color="white")
    handles += _pivots(ax, wmap)
    _legend(fig, handles)
    return fig


def effort_figure(wmap: WorkspaceMap) -> Figure:
    """The largest static actuator effort of the three legs at each reachable point.

    Loads grow as 1/conditioning towards a parallel singularity, so the few points just above
    the conditioning floor reach efforts orders of magnitude above the rest (24,658 N·m on the
    paper robot, 37 N·m at the median). The colour scale (log) then ends at the
    :data:`CLIP_PERCENTILE` th percentile of the reachable points' efforts, when the largest
    exceeds it :data:`CLIP_RATIO` times; the points above it are drawn in :data:`OVER_COLOR`,
    and the legend says where the scale ends and up to what the points above it go. A map
    without such a tail (the gallery's 3-RRR: 20 N·m at most) keeps its whole range.
    """
    unit = wmap.effort_unit
    fig, ax = _frame(wmap, f"Peak static effort max |{wmap.effort}| over legs A, B, C")
    peak = np.max(np.abs(wmap.tau), axis=2)
    finite = peak[np.isfinite(peak) & (peak > 0)]
    handles: list[Artist] = [*_outline(ax, wmap), *_pivots(ax, wmap)]
    if finite.size:
        low, high = float(finite.min()), float(finite.max())
        top = float(np.percentile(finite, CLIP_PERCENTILE))
        clipped = low < top and high > CLIP_RATIO * top
        cmap = colormaps["magma"].with_extremes(over=OVER_COLOR)
        norm = LogNorm(vmin=low, vmax=top if clipped else high)
        image = _image(ax, wmap, np.where(peak > 0, peak, np.nan), cmap=cmap, norm=norm)
        label = f"max |{wmap.effort}| [{unit}] (log scale"
        label += f", to the {CLIP_PERCENTILE:g}th percentile)" if clipped else ")"
        bar = fig.colorbar(
            image, ax=ax, label=label, shrink=0.8, extend="max" if clipped else "neither"
        )
        plain = FuncFormatter(_tick)  # 20, 50, 100, 200 ..., not 2 x 10^1
        bar.ax.yaxis.set_major_formatter(plain)
        bar.ax.yaxis.set_minor_formatter(plain)
        if clipped:
            share = np.count_nonzero(finite > top) / finite.size
            handles.append(
                Patch(
                    facecolor=OVER_COLOR,
                    label=f"above the scale: {_amount(top)} to {_amount(high)} {unit} "
                    f"({share:.1%} of the points)",
                )
            )
    _legend(fig, handles, ncols=2)
    return fig


def orientation_figure(wmap: WorkspaceMap) -> Figure:
    """The width of the reachable orientation interval through each point."""
    fig, ax = _frame(wmap, "Reachable orientation range φ_max − φ_min")
    width = np.degrees(wmap.phi_max - wmap.phi_min)
    if np.isfinite(width).any():
        image = _image(ax, wmap, width, cmap="cividis", vmin=0.0)
        fig.colorbar(image, ax=ax, label="φ_max − φ_min [°]", shrink=0.8)
    handles = _outline(ax, wmap) + _pivots(ax, wmap)
    _legend(fig, handles)
    return fig


FIGURES: dict[str, Callable[[WorkspaceMap], Figure]] = {
    "reachable": reachable_figure,
    "conditioning": conditioning_figure,
    "peak_effort": effort_figure,
    "orientation_range": orientation_figure,
}
"""The figures by file name (without ``.png``)."""


def write_figures(wmap: WorkspaceMap, outdir: str | os.PathLike[str]) -> list[Path]:
    """Write the four figures as ``outdir/<name>.png`` (:data:`FIGURES`), atomically.

    Returns:
        The paths written, in the order of :data:`FIGURES`.
    """
    folder = Path(outdir)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, draw in FIGURES.items():
        path = folder / f"{name}.png"
        fig = draw(wmap)
        with atomic_write(path, "wb") as f:
            fig.savefig(f, format="png", dpi=DPI, metadata={"Software": None})
        written.append(path)
    return written
