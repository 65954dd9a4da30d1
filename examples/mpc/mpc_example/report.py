"""The closed-loop run's numbers, its CSV and its figure."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mpc_example.loop import Run


@dataclass(frozen=True)
class Summary:
    """What the run measured.

    Attributes:
        solve_ms: the solve's wall time per period, median, p90 and max, ms.
        iterations: the solver's iterations, median and max.
        failed: periods whose solve failed (did not converge; a real-time iteration: its QP
            not solved).
        position_mm: the platform position error |(x, y) - (x, y)_ref|, RMS and max, mm.
        angle_mrad: the orientation error |phi - phi_ref|, RMS and max, mrad.
        peak_effort: the largest |tau_i| of each actuator over the run.
        over_limit: periods where some |tau_i| exceeded its limit (0: within at every step).
        at_limit: periods where some |tau_i| was within 1e-6 of its limit (saturated).
    """

    solve_ms: tuple[float, float, float]
    iterations: tuple[int, int]
    failed: int
    position_mm: tuple[float, float]
    angle_mrad: tuple[float, float]
    peak_effort: np.ndarray
    over_limit: int
    at_limit: int


def summarise(run: Run, limit: np.ndarray) -> Summary:
    """The :class:`Summary` of ``run`` against the effort limits ``limit`` (k,)."""
    ms = np.sort(run.seconds[~np.isnan(run.seconds)]) * 1e3
    solve = (
        (float(np.median(ms)), float(np.percentile(ms, 90)), float(ms[-1]))
        if len(ms)
        else (math.nan,) * 3
    )
    error = run.q - run.q_ref
    position = np.hypot(error[:, 0], error[:, 1]) * 1e3
    angle = np.abs(error[:, 2]) * 1e3
    magnitude = np.abs(run.tau)
    return Summary(
        solve_ms=solve,
        iterations=(int(np.median(run.iterations)), int(run.iterations.max())),
        failed=int(np.count_nonzero(~run.success)),
        position_mm=(float(np.sqrt(np.mean(position**2))), float(position.max())),
        angle_mrad=(float(np.sqrt(np.mean(angle**2))), float(angle.max())),
        peak_effort=magnitude.max(axis=0),
        over_limit=int(np.count_nonzero((magnitude > limit).any(axis=1))),
        at_limit=int(np.count_nonzero((magnitude >= limit - 1e-6).any(axis=1))),
    )


def lines(summary: Summary, limit: np.ndarray, steps: int, success: str) -> list[str]:
    """The report's lines (the tests read them); ``success`` says what a solve's success is."""
    s = summary
    peaks = ", ".join(f"{v:.3f}" for v in s.peak_effort)
    limits = ", ".join(f"{v:g}" for v in limit)
    verdict = (
        "within the limits at every step"
        if not s.over_limit
        else (f"OVER THE LIMITS at {s.over_limit} steps")
    )
    return [
        f"solve time per step: median {s.solve_ms[0]:.2f} ms, p90 {s.solve_ms[1]:.2f} ms, "
        f"max {s.solve_ms[2]:.2f} ms (solver iterations: median {s.iterations[0]}, "
        f"max {s.iterations[1]})",
        f"solver status: {steps - s.failed} of {steps} steps succeeded ({success})",
        f"tracking error: position rms {s.position_mm[0]:.4f} mm, max {s.position_mm[1]:.4f} mm;"
        f" orientation rms {s.angle_mrad[0]:.4f} mrad, max {s.angle_mrad[1]:.4f} mrad",
        f"efforts: peak |tau| {peaks} N m, limit {limits} N m: {verdict} "
        f"({s.at_limit} of {steps} steps at a limit)",
    ]


def write_csv(run: Run, path: Path) -> None:
    """One row per period: time, reference and plant pose, rate, efforts, the disturbance
    estimate, the solve's time (ms), iterations and success (1 or 0)."""
    k = run.q.shape[1]
    pose = ("x", "y", "phi")[:k] if k == 3 else tuple(f"q{i + 1}" for i in range(k))
    header = (
        ["t"]
        + [f"{c}_ref" for c in pose]
        + list(pose)
        + [f"d{c}" for c in pose]
        + [f"tau{i + 1}" for i in range(k)]
        + [f"disturbance{i + 1}" for i in range(k)]
        + ["solve_ms", "iterations", "success"]
    )
    table = np.column_stack(
        [run.t, run.q_ref, run.q, run.qd, run.tau, run.disturbance, run.seconds * 1e3,
         run.iterations, run.success.astype(int)]
    )  # fmt: skip
    np.savetxt(path, table, delimiter=",", header=",".join(header), comments="", fmt="%.9g")


def plot(run: Run, limit: np.ndarray, path: Path, title: str) -> None:
    """Reference and tracked path (x, y; mm), the tracking error, and the efforts with their
    limits, in one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_path, ax_error, ax_tau) = plt.subplots(1, 3, figsize=(15, 4.6))
    ax_path.plot(run.q_ref[:, 0] * 1e3, run.q_ref[:, 1] * 1e3, "k--", lw=1.2, label="reference")
    ax_path.plot(run.q[:, 0] * 1e3, run.q[:, 1] * 1e3, "C0", lw=1.0, label="tracked")
    ax_path.set(xlabel="x (mm)", ylabel="y (mm)", title="platform path")
    ax_path.set_aspect("equal", adjustable="datalim")
    ax_path.legend()

    error = run.q - run.q_ref
    ax_error.plot(run.t, np.hypot(error[:, 0], error[:, 1]) * 1e3, label="position (mm)")
    ax_error.plot(run.t, np.abs(error[:, 2]) * 1e3, label="orientation (mrad)")
    ax_error.set(xlabel="t (s)", title="tracking error")
    ax_error.legend()

    for i in range(run.tau.shape[1]):
        ax_tau.step(run.t - (run.t[1] - run.t[0]), run.tau[:, i], where="post",
                    color=f"C{i}", label=f"tau{i + 1}")  # fmt: skip
    for value in sorted(set(limit.tolist())):  # one line for the motors that share a limit
        ax_tau.axhline(value, color="k", ls=":", lw=1.0)
        ax_tau.axhline(-value, color="k", ls=":", lw=1.0)
    ax_tau.set(xlabel="t (s)", ylabel="N m", title="efforts and their limits (dotted)")
    ax_tau.legend(loc="lower left")

    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
