"""The paper's figures: one PNG per output family, the three legs A, B, C in each.

Each leg has its own line style, width and hollow marker, the markers at staggered samples, so
legs whose curves coincide (as phi10 and lambda21 do in the paper's rotation) all stay visible;
the title then says which legs coincide.

Figures are drawn on :class:`matplotlib.figure.Figure` with the Agg canvas directly, never
through ``pyplot``, so no global matplotlib state (backend, open figures) is touched. Size,
resolution and PNG metadata are fixed, so the same data give the same files.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from rpr3gen.atomic import atomic_write
from rpr3gen.errors import InputError
from rpr3gen.model import ACTUATIONS, LEGS
from rpr3gen.structure import Structure

__all__ = [
    "DPI",
    "FIGSIZE",
    "LEG_STYLES",
    "FamilyPlot",
    "coinciding_legs",
    "family_figure",
    "plot_families",
    "plotted_families",
]

DPI = 120
"""Resolution of the PNG files, dots per inch."""

FIGSIZE = (6.4, 4.0)
"""Figure size, inches (768 x 480 pixels at :data:`DPI`)."""

LEG_STYLES: Mapping[str, Mapping[str, Any]] = MappingProxyType(
    {
        "A": {"linestyle": "-", "linewidth": 3.0, "marker": "o", "markersize": 8},
        "B": {"linestyle": "--", "linewidth": 2.0, "marker": "s", "markersize": 6},
        "C": {"linestyle": ":", "linewidth": 1.5, "marker": "^", "markersize": 5},
        "D": {"linestyle": "-.", "linewidth": 1.5, "marker": "v", "markersize": 5},
        "E": {"linestyle": "-", "linewidth": 1.0, "marker": "D", "markersize": 4},
        "F": {"linestyle": "--", "linewidth": 1.0, "marker": "x", "markersize": 4},
    }
)
"""Line and marker of each leg: drawn in this order, wide to narrow, with hollow markers at
staggered samples, so that legs whose curves coincide all stay visible."""

MARKERS_PER_CURVE = 12
"""About how many markers each curve carries."""

COINCIDE_RTOL = 1e-9
"""Two legs' curves coincide when they differ by at most this times the family's peak value."""


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


def _general_families(structure: Structure) -> tuple[FamilyPlot, ...]:
    """The general format's figures: every joint's force components, the moments that are not
    zero by construction (a passive revolute joint transmits none), the actuator efforts and
    the joint coordinates."""
    out = []
    for j in (1, 2, 3):
        out.append(FamilyPlot(f"fx{j}", f"Joint {j} forces", rf"$f_{{x{j}}}$", "N"))
        out.append(FamilyPlot(f"fy{j}", f"Joint {j} forces", rf"$f_{{y{j}}}$", "N"))
        if structure.leg[j - 1] == "P" or j == structure.actuated:
            out.append(FamilyPlot(f"m{j}", f"Joint {j} moments", rf"$m_{{{j}}}$", "N·m"))
    unit = "N·m" if structure.actuated_kind == "R" else "N"
    out.append(FamilyPlot("tau", "Actuator efforts", r"$\tau$", unit))
    for j in (1, 2, 3):
        kind = "rotations" if structure.leg[j - 1] == "R" else "displacements"
        unit = "rad" if structure.leg[j - 1] == "R" else "m"
        out.append(FamilyPlot(f"q{j}", f"Joint {j} {kind}", rf"$q_{{{j}}}$", unit))
    return tuple(out)


def _spatial_families(structure: Structure) -> tuple[FamilyPlot, ...]:
    """A spatial robot's figures (docs/spatial-robots.md): every joint's force components, the
    moments of the joints that transmit one (not the S joints), the efforts and the actuated
    and prismatic joints' coordinates."""
    delta = structure.leg.endswith("SS2")
    out = []
    for j in range(1, 6 if delta else 4):
        for a in "xyz":
            out.append(FamilyPlot(f"f{a}{j}", f"Joint {j} forces", rf"$f_{{{a}{j}}}$", "N"))
        if j == 1 or (not delta and j == 2):
            for a in "xyz":
                out.append(FamilyPlot(f"m{a}{j}", f"Joint {j} moments", rf"$m_{{{a}{j}}}$", "N·m"))
    unit = "N·m" if structure.actuated_kind == "R" else "N"
    out.append(FamilyPlot("tau", "Actuator efforts", r"$\tau$", unit))
    joint = structure.actuated
    kind, unit = ("rotations", "rad") if structure.actuated_kind == "R" else ("displacements", "m")
    out.append(FamilyPlot(f"q{joint}", f"Joint {joint} {kind}", rf"$q_{{{joint}}}$", unit))
    return tuple(out)


def plotted_families(actuation: str | Structure) -> tuple[FamilyPlot, ...]:
    """The families :func:`plot_families` draws for a robot, in order.

    Args:
        actuation: The paper's ``"revolute"`` or ``"prismatic"``, or a model's structure (a
            paper structure draws the paper's figures, a general one the general outputs').

    Raises:
        InputError: If ``actuation`` is not one of these.
    """
    if isinstance(actuation, Structure):
        if actuation.spatial:
            return _spatial_families(actuation)
        if not actuation.paper:
            return _general_families(actuation)
        actuation = actuation.variant
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
    actuation: str | Structure,
) -> list[Path]:
    """Write one PNG per output family, the legs A, B, C as three curves against time.

    Families: f10x, f10y, f21y, m21, f32y, f32z (the paper's figs 3-8 / 9-14), the actuator
    load (m10 for revolute, f21z for prismatic actuation), phi10 and lambda21; for a general
    model, every joint's forces and non-zero moments, tau and the joint coordinates. Each file is
    ``{outdir}/{prefix}_{family}.png``, written atomically.

    Args:
        t: Sample times, s, shape ``(n,)``.
        outputs: Output arrays by CSV name (``"f10x_A"`` ...), each of shape ``(n,)``.
        outdir: Folder for the PNG files; created if missing.
        prefix: Start of every file name (e.g. the trajectory's name).
        title: Appended to every figure title after a dash (e.g. ``"rotation"``).
        actuation: ``"revolute"`` or ``"prismatic"`` (the paper's figures, with that actuator
            load), or a model's :class:`~rpr3gen.structure.Structure`.

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
    legs = actuation.legs if isinstance(actuation, Structure) else LEGS
    curves: dict[str, np.ndarray] = {}
    for spec in families:
        for leg in legs:
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
        fig = family_figure(t, [curves[f"{spec.family}_{leg}"] for leg in legs], spec, title)
        with atomic_write(path, "wb") as f:
            fig.savefig(f, format="png", dpi=DPI, metadata={"Software": None})
        written.append(path)
    return written


def coinciding_legs(curves: Sequence[np.ndarray]) -> tuple[tuple[str, ...], ...]:
    """Groups of two or more legs whose curves coincide, e.g. ``(("A", "B", "C"),)``.

    Curves coincide when they differ nowhere by more than :data:`COINCIDE_RTOL` times the
    largest magnitude of all of them (NaN where they are both NaN); all-zero curves coincide.

    Args:
        curves: One curve per leg A, B, C, each of shape ``(n,)``.
    """
    with np.errstate(invalid="ignore"):
        peak = max((float(np.nanmax(np.abs(y), initial=0.0)) for y in curves), default=0.0)
    tolerance = COINCIDE_RTOL * peak
    groups: list[tuple[str, ...]] = []
    placed: set[int] = set()
    for i in range(len(curves)):
        if i in placed:
            continue
        group = [i] + [
            j
            for j in range(i + 1, len(curves))
            if j not in placed
            and np.allclose(curves[i], curves[j], rtol=0.0, atol=tolerance, equal_nan=True)
        ]
        placed.update(group)
        if len(group) > 1:
            groups.append(tuple("ABCDEF"[k] for k in group))
    return tuple(groups)


def _coincide_note(groups: tuple[tuple[str, ...], ...]) -> str:
    """``"legs A, B and C coincide"``; groups joined by ``"; "``."""
    return "; ".join(f"legs {', '.join(group[:-1])} and {group[-1]} coincide" for group in groups)


def family_figure(
    t: np.ndarray, legs: Sequence[np.ndarray], spec: FamilyPlot, title: str
) -> Figure:
    """The figure of one family: the legs A, B, C against time, in :data:`LEG_STYLES`.

    When legs coincide (:func:`coinciding_legs`), a second title line says which.

    Args:
        t: Sample times, s, shape ``(n,)``.
        legs: The family's curve for each leg A, B, C, each of shape ``(n,)``.
        spec: How the family is named and labelled.
        title: Appended to the title after a dash.
    """
    fig = Figure(figsize=FIGSIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    step = max(1, len(t) // MARKERS_PER_CURVE)
    for k, (leg, y) in enumerate(zip("ABCDEF", legs, strict=False)):
        ax.plot(
            t,
            y,
            label=f"leg {leg}",
            markevery=(k * step // len(legs), step),  # staggered: markers never overlap
            markerfacecolor="none",
            **LEG_STYLES[leg],
        )
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"{spec.symbol} [{spec.unit}]")
    heading = spec.title(title)
    groups = coinciding_legs(legs)
    if groups:
        heading += f"\n({_coincide_note(groups)})"
    ax.set_title(heading)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig
