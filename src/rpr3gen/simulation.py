"""One trajectory's inverse dynamics, screened and written: what ``rpr3gen simulate`` and
``rpr3gen paper`` run.

:func:`simulate` evaluates the outputs over a trajectory, refuses it when a pose is too close to
a singularity or outside a stroke limit (or blanks those rows, :func:`screen`), and writes the
CSV and the figures.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rpr3gen import variants
from rpr3gen.backends import inverse_dynamics, output_names
from rpr3gen.errors import InputError, TrajectoryError
from rpr3gen.model import Model
from rpr3gen.paths import check_output
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING, Invalid, invalid_samples
from rpr3gen.trajectory import Trajectory

__all__ = ["screen", "simulate"]


def screen(
    model: Model,
    traj: Trajectory,
    out: dict[str, np.ndarray],
    min_conditioning: float,
    allow_invalid: bool,
) -> Invalid | None:
    """Refuse a trajectory through an invalid pose, or blank those rows when allowed.

    Returns:
        The samples blanked (written as NaN), or None when every sample is valid.
    """
    thresholds = variants.load(model.structure, model.generated).thresholds
    invalid = invalid_samples(model, traj.q, out, min_conditioning, thresholds)
    if invalid is None:
        return None
    if not allow_invalid:
        k = invalid.first
        raise TrajectoryError(
            f"t = {traj.t[k]:.6g} s (sample {k + 1} of {len(traj.t)}): {invalid.reason}; "
            "pass --allow-invalid to write such rows as NaN"
        )
    for name in output_names(model):
        if name != "conditioning":
            out[name] = np.where(invalid.mask, np.nan, out[name])
    return invalid


def simulate(
    model: Model,
    name: str,
    traj: Trajectory,
    backend: str,
    out_csv: str | None,
    plots_dir: str | None,
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
    allow_invalid: bool = False,
    threads: int | None = None,
) -> tuple[dict[str, np.ndarray], Invalid | None]:
    """Evaluate, screen, and write the CSV and figures of one trajectory.

    Nothing is written unless the whole trajectory is valid (or ``allow_invalid``).

    Returns:
        Every output by name, shape ``(n,)``, and the samples refused (their outputs, but
        ``conditioning``, are NaN; None when there are none, always unless ``allow_invalid``).
    """
    from rpr3gen.atomic import write_results_csv

    if not 0.0 <= min_conditioning < 1.0:
        raise InputError(f"min_conditioning: must be in [0, 1), got {min_conditioning!r}")
    if out_csv:
        check_output(out_csv, "the CSV", argument="out")
    if plots_dir:
        check_output(plots_dir, "the figures", folder=True, argument="plots")
    out = inverse_dynamics(
        model, traj.q, traj.qd, traj.qdd, backend=backend, progress=True, threads=threads
    )
    invalid = screen(model, traj, out, min_conditioning, allow_invalid)
    if out_csv:
        Path(out_csv).parent.mkdir(parents=True, exist_ok=True)
        write_results_csv(
            out_csv, traj.t, traj.q, out, output_names(model), pose=model.structure.pose
        )
    if plots_dir:
        from rpr3gen.plots import plot_families

        plot_families(
            traj.t,
            out,
            plots_dir,
            prefix=name,
            title=f"{name} ({model.name})",
            actuation=model.structure,
        )
    return out, invalid
