"""The paper's figures: one PNG per output family, the three legs A, B, C in each.

Figures are drawn on :class:`matplotlib.figure.Figure` with the Agg canvas directly, never
through ``pyplot``, so no global matplotlib state (backend, open figures) is touched. Size,
resolution and PNG metadata are fixed, so the same data give the same files.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from rpr3gen.atomic import atomic_write
from rpr3gen.errors import InputError
from rpr3gen.model import ACTUATIONS, LEGS

__all__ = ["DPI", "FIGSIZE", "FamilyPlot", "plot_families", "plotted_families"]

DPI = 120
"""Resolution of the PNG files, dots per inch."""

FIGSIZE = (6.4, 4.0)
"""Figure size, inches (768 x 480 pixels at :data:`DPI`)."""


@dataclass(frozen=True)
class FamilyPlot:
    """How one output family is drawn.

    Attributes:
        family: Output name without the leg suffix, e.g. ``"f10x"`` (columns ``f10x_A`` ...).
        what: Words starting the title, e.g. ``"Joint forces"``.
        symbol: Matplotlib mathtext for the y label.
        unit: SI unit for the y label.
        paper_figs: The paper's figure numbers (rotation/rectilinear), or ``""``.
    """

    family: str
    what: str
    symbol: str
    unit: str
    paper_figs: str = ""

    def title(self, suffix: str) -> str:
        """Figure title, e.g. ``"Joint forces f10x (paper fig. 3) — rotation (paper)"``.

        The figure number is the example's own when ``suffix`` names one of the paper's
        examples (rotation: figs 3-8, rectilinear: figs 9-14), else both are cited.
        """
        text = f"{self.what} {self.family}"
        if self.paper_figs:
            rotation, rectilinear = self.paper_figs.split("/")
            example = suffix.split(" ", 1)[0]
            figs = {"rotation": rotation, "rectilinear": rectilinear}.get(example)
            text += (
                f" (paper fig. {figs})" if figs else f" (cf. paper figs {rotation}, {rectilinear})"
            )
        return f"{text} — {suffix}" if suffix else text


# The paper's figures 3-8 (rotation) and 9-14 (rectilinear), in order.
_PAPER_FAMILIES = (
    FamilyPlot("f10x", "Joint forces", r"$f_{10x}$", "N", "3/9"),
    FamilyPlot("f10y", "Joint forces", r"$f_{10y}$", "N", "4/10"),
    FamilyPlot("f21y", "Joint forces", r"$f_{21y}$", "N", "5/11"),
    FamilyPlot("m21", "Joint torques", r"$m_{21}$", "N·m", "6/12"),
    FamilyPlot("f32y", "Joint forces", r"$f_{32y}$", "N", "7/13"),
    FamilyPlot("f32z", "Joint forces", r"$f_{32z}$", "N", "8/14"),
)
_ACTUATOR = {
    "revolute": FamilyPlot("m10", "Motor torques", r"$m_{10}$", "N·m"),
    "prismatic": FamilyPlot("f21z", "Actuator forces", r"$f_{21z}$", "N"),
}
_LEG_VARIABLES = (
    FamilyPlot("phi10", "Cylinder rotations", r"$\varphi_{10}$", "rad"),
    FamilyPlot("lambda21", "Piston displacements", r"$\lambda_{21}$", "m"),
)


def plotted_families(actuation: str) -> tuple[FamilyPlot, ...]:
    """The families :func:`plot_families` draws for a robot with the given actuation, in order.

    Raises:
        InputError: If ``actuation`` is not ``"revolute"`` or ``"prismatic"``.
    """
    if actuation not in ACTUATIONS:
        raise InputError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    return (*_PAPER_FAMILIES, _ACTUATOR[actuation], *_LEG_VARIABLES)


def plot_families(
    t: np.ndarray,
    outputs: Mapping[str, np.ndarray],
    outdir: str | os.PathLike[str],
    *,
    prefix: str,
    title: str,
    actuation: str,
) -> list[Path]:
    """Write one PNG per output family, the legs A, B, C as three curves against time.

    Families: f10x, f10y, f21y, m21, f32y, f32z (the paper's figs 3-8 / 9-14), the actuator
    load (m10 for revolute, f21z for prismatic actuation), phi10 and lambda21. Each file is
    ``{outdir}/{prefix}_{family}.png``, written atomically.

    Args:
        t: Sample times, s, shape ``(n,)``.
        outputs: Output arrays by CSV name (``"f10x_A"`` ...), each of shape ``(n,)``.
        outdir: Folder for the PNG files; created if missing.
        prefix: Start of every file name (e.g. the trajectory's name).
        title: Appended to every figure title after a dash (e.g. ``"rotation"``).
        actuation: ``"revolute"`` or ``"prismatic"``; selects the actuator-load figure.

    Returns:
        The paths written, in the order of :func:`plotted_families`.

    Raises:
        InputError: If ``actuation`` is unknown, an output is missing or a shape is wrong.
        OSError: If a folder or file cannot be written.
    """
    t = np.asarray(t, dtype=np.float64)
    if t.ndim != 1:
        raise InputError(f"t must have shape (n,), got {t.shape}")
    families = plotted_families(actuation)
    curves: dict[str, np.ndarray] = {}
    for spec in families:
        for leg in LEGS:
            key = f"{spec.family}_{leg}"
            if key not in outputs:
                raise InputError(f"no output named {key!r} to plot")
            y = np.asarray(outputs[key], dtype=np.float64)
            if y.shape not in (t.shape, ()):
                raise InputError(f"output {key!r} must have shape {t.shape}, got {y.shape}")
            curves[key] = np.broadcast_to(y, t.shape)

    folder = Path(outdir)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for spec in families:
        path = folder / f"{prefix}_{spec.family}.png"
        fig = _figure(t, [curves[f"{spec.family}_{leg}"] for leg in LEGS], spec, title)
        with atomic_write(path, "wb") as f:
            fig.savefig(f, format="png", dpi=DPI, metadata={"Software": None})
        written.append(path)
    return written


def _figure(t: np.ndarray, legs: list[np.ndarray], spec: FamilyPlot, title: str) -> Figure:
    fig = Figure(figsize=FIGSIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for leg, y in zip(LEGS, legs, strict=True):
        ax.plot(t, y, label=f"leg {leg}")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"{spec.symbol} [{spec.unit}]")
    ax.set_title(spec.title(title))
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig
