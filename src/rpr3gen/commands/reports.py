"""What the commands print besides their results: warnings as one line each, the samples a
simulation refused, and a simulation's summary of peak values.
"""

from __future__ import annotations

import contextlib
import sys
import warnings
from collections.abc import Iterator
from typing import TextIO

import numpy as np

from rpr3gen.errors import Rpr3genWarning
from rpr3gen.model import Model
from rpr3gen.policy import Invalid
from rpr3gen.trajectory import Trajectory


def warn(message: str) -> None:
    """Print ``rpr3gen: warning: <message>`` on stderr."""
    print(f"rpr3gen: warning: {message}", file=sys.stderr)


@contextlib.contextmanager
def warnings_as_lines() -> Iterator[None]:
    """Show the package's warnings as one line each, ``rpr3gen: warning: <msg>``, every time."""
    with warnings.catch_warnings():
        warnings.simplefilter("always", Rpr3genWarning)
        show = warnings.showwarning

        def show_ours(
            message: Warning | str,
            category: type[Warning],
            filename: str,
            lineno: int,
            file: TextIO | None = None,
            line: str | None = None,
        ) -> None:
            if issubclass(category, Rpr3genWarning):
                warn(str(message))
            else:
                show(message, category, filename, lineno, file, line)

        warnings.showwarning = show_ours
        yield


def _spans(t: np.ndarray, mask: np.ndarray, most: int = 3) -> str:
    """When ``mask`` holds, e.g. ``"t = 0.2 s, 1.17 to 3 s"``: its runs, the first ``most``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    runs = list(zip(edges[::2], edges[1::2] - 1, strict=True))  # first and last sample of each
    parts = [f"{t[a]:.6g} s" if a == b else f"{t[a]:.6g} to {t[b]:.6g} s" for a, b in runs[:most]]
    more = f" and {len(runs) - most} more spans" if len(runs) > most else ""
    return "t = " + ", ".join(parts) + more


def refused(traj: Trajectory, invalid: Invalid) -> str:
    """One line: how many samples were refused, when, and why the first one was."""
    count = int(np.count_nonzero(invalid.mask))
    return (
        f"{count} of {len(traj.t)} samples refused and written as NaN, "
        f"{_spans(traj.t, invalid.mask)} (first: {invalid.reason})"
    )


def summary(
    name: str,
    model: Model,
    traj: Trajectory,
    out: dict[str, np.ndarray],
    invalid: Invalid | None = None,
) -> str:
    """A simulation in a few lines: its samples and duration, and each family's peak |value|
    per leg (over the samples not refused)."""
    n = len(traj.t)
    lines = [f"{name}: {n} samples over {traj.t[-1] - traj.t[0]:g} s, model {model.name}"]
    if invalid is not None:
        valid = n - int(np.count_nonzero(invalid.mask))
        lines.append(f"  {refused(traj, invalid)}; the peaks are of the {valid} others")
    legs = model.structure.legs
    lines.append(f"  {'peak |value|':<12} " + " ".join(f"{'leg ' + leg:>12}" for leg in legs))
    if model.structure.paper:
        families: tuple[str, ...] = ("m10", "f21z", "f10x", "f10y", "f21y", "m21", "f32y", "f32z")
    elif model.structure.spatial:
        joints = range(1, 6 if model.structure.leg.endswith("SS2") else 4)
        families = ("tau", *(f"{f}{j}" for j in joints for f in ("fx", "fy", "fz", "mx", "my",
                                                                  "mz")))  # fmt: skip
    else:
        families = ("tau", *(f"{f}{j}" for j in (1, 2, 3) for f in ("fx", "fy", "m")))
    for family in families:
        peaks = [float(np.nanmax(np.abs(out[f"{family}_{leg}"]), initial=0.0)) for leg in legs]
        lines.append(f"  {family:<12} " + " ".join(f"{p:12.5g}" for p in peaks))
    return "\n".join(lines)
