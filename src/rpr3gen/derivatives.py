"""Velocities and accelerations from positions, and a check of given ones against positions.

A planned or measured platform motion often comes as positions alone, ``t, x, y, phi``.
:func:`differentiate` then takes the velocities and accelerations as the first and second time
derivatives of a quintic smoothing spline through the positions, one spline per coordinate,
fitted by SciPy's ``make_splrep`` (the FITPACK algorithm, ``k = 5``) with the smoothing
condition ``sum((spline(t_i) - q_i)**2) <= n * smoothing**2``: ``smoothing`` is the RMS
deviation allowed between the spline and the positions, in the positions' units (m for x and y,
rad for phi). With 0, the default, the spline passes through every sample (right for a planned
motion); for measured positions give the noise level, since a spline that follows the noise
has derivatives that amplify it.

When a file gives velocities and accelerations too, :func:`mismatch` checks them against its
positions by integrating them over time, which, unlike differentiating, does not amplify noise.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from rpr3gen.errors import TrajectoryError, TrajectoryWarning
from rpr3gen.validation import Number

__all__ = [
    "MAX_SMOOTHING",
    "MIN_SAMPLES",
    "MISMATCH_TOLERANCE",
    "SPLINE_DEGREE",
    "check_smoothing",
    "differentiate",
    "mismatch",
]

SPLINE_DEGREE = 5
"""Degree of the smoothing spline: quintic, so accelerations are smooth (C² up to the ends)."""

MIN_SAMPLES = SPLINE_DEGREE + 1
"""Fewest samples a quintic spline can be fitted through."""

MISMATCH_TOLERANCE = 0.05
"""Largest deviation :func:`mismatch` lets pass, as a fraction of the motion it is measured on."""

_POSITION_NAMES = ("x", "y", "phi")


MAX_SMOOTHING = 1e100
"""The largest smoothing (m, rad): far beyond any motion, and ``n smoothing²`` stays a float."""


def check_smoothing(smoothing: object) -> float:
    """Return ``smoothing`` as a float, or raise for a value that is not a number in
    ``[0, MAX_SMOOTHING]``.

    Raises:
        InputTypeError: If it is not a real number.
        InputError: If it is negative, not finite or above :data:`MAX_SMOOTHING`.
    """
    return float(Number(least=0.0, most=MAX_SMOOTHING)("smoothing", smoothing))


def differentiate(
    t: np.ndarray,
    q: np.ndarray,
    smoothing: float = 0.0,
    *,
    source: str = "positions",
    names: tuple[str, ...] = _POSITION_NAMES,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, velocities and accelerations of the quintic smoothing spline through ``q``.

    Args:
        t: Sample times, s, strictly increasing, shape ``(n,)`` with ``n >= MIN_SAMPLES``.
        q: Platform poses ``(x, y, phi)`` (m, m, rad), shape ``(n, 3)``.
        smoothing: RMS deviation allowed between the spline and ``q`` (m for x and y, rad for
            phi); 0 interpolates.
        source: Where the positions come from, for messages.

    Returns:
        ``(q, qd, qdd)`` at the times ``t``, each of shape ``(n, 3)``: with ``smoothing = 0``,
        ``q`` is the input unchanged (the spline passes through it), else the spline's values.

    Raises:
        TrajectoryError: With fewer than :data:`MIN_SAMPLES` samples.
        InputTypeError, InputError: For a ``smoothing`` that is not a number >= 0.

    Warns:
        TrajectoryWarning: If the spline of a coordinate could not meet the smoothing
            condition (a ``smoothing`` too small for noisy data); it is used as fitted.
    """
    from scipy.interpolate import make_splrep

    smoothing = check_smoothing(smoothing)
    n = t.size
    if n < MIN_SAMPLES:
        raise TrajectoryError(
            f"{source}: {n} samples of positions only; derivatives need at least {MIN_SAMPLES} "
            "(a quintic spline), or give the velocity and acceleration columns"
        )
    fitted, qd, qdd = np.empty_like(q), np.empty_like(q), np.empty_like(q)
    for j, name in enumerate(names):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            spline = make_splrep(t, q[:, j], k=SPLINE_DEGREE, s=n * smoothing**2)
        for caught_one in caught:
            if not issubclass(caught_one.category, RuntimeWarning):  # not FITPACK's report
                warnings.warn_explicit(
                    caught_one.message, caught_one.category, caught_one.filename, caught_one.lineno
                )
                continue
            reason = " ".join(str(caught_one.message).split())
            warnings.warn(
                f"{source}: the spline of {name} could not meet smoothing {smoothing:g} and is "
                f"used as fitted (SciPy: {reason})",
                TrajectoryWarning,
                stacklevel=2,
            )
        fitted[:, j] = spline(t)
        qd[:, j] = spline(t, 1)
        qdd[:, j] = spline(t, 2)
    return (q.copy() if smoothing == 0.0 else fitted), qd, qdd


def mismatch(
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    names: tuple[str, ...] = _POSITION_NAMES,
) -> str | None:
    """Say where given velocities and accelerations disagree with the positions, if they do.

    The velocities are integrated from the first sample by the trapezoid rule corrected with the
    accelerations (``q[i+1] - q[i] = h (qd[i] + qd[i+1]) / 2 - h² (qdd[i+1] - qdd[i]) / 12``,
    exact for cubics), the accelerations by the trapezoid rule. Each integral must stay within
    :data:`MISMATCH_TOLERANCE` of the column it integrates to, relative to the larger of that
    column's range and the integral's own scale (its largest value times the duration), so a
    coordinate that does not move is judged on what its derivatives claim. That catches wrong
    units, signs, columns and missing derivatives, not small lags.

    Args:
        t: Sample times, s, strictly increasing, shape ``(n,)``.
        q, qd, qdd: Poses, velocities and accelerations, shape ``(n, 3)``.

    Returns:
        One line naming the columns at fault and the worst deviation, or None if they agree
        (always None with fewer than 2 samples).
    """
    if t.size < 2:
        return None
    h = np.diff(t)[:, np.newaxis]
    found: list[tuple[float, str, str, float, float]] = []  # ratio, rate, column, by, when
    with np.errstate(all="ignore"):  # absurd values overflow: they are then reported
        integrals = (
            ("d", q, qd, h / 2 * (qd[1:] + qd[:-1]) - h**2 / 12 * (qdd[1:] - qdd[:-1])),
            ("dd", qd, qdd, h / 2 * (qdd[1:] + qdd[:-1])),
        )
        for prefix, given, rate, steps in integrals:
            zero = np.zeros((1, given.shape[1]))
            integral = given[0] + np.concatenate([zero, np.cumsum(steps, axis=0)])
            deviation = np.nan_to_num(np.abs(integral - given), nan=np.inf)
            scale = np.maximum(np.ptp(given, axis=0), np.max(np.abs(rate), axis=0) * np.ptp(t))
            for j, name in enumerate(names):
                worst = int(np.argmax(deviation[:, j]))
                by = float(deviation[worst, j])
                if not (math.isfinite(by) and by <= MISMATCH_TOLERANCE * scale[j]):
                    ratio = by / scale[j] if scale[j] > 0 else math.inf
                    column = name if prefix == "d" else f"d{name}"
                    found.append((ratio, f"{prefix}{name}", column, by, float(t[worst])))
    if not found:
        return None
    ratio, rate_name, column, by, when = max(found, key=lambda f: f[0])
    share = f"{ratio:.0%} of its motion" if math.isfinite(ratio) else "beyond measure"
    pairs = ", ".join(f"{f[1]} with {f[2]}" for f in found)
    return (
        f"velocities or accelerations disagree with the positions ({pairs}): integrated over "
        f"time, {rate_name} gives {column} off by {by:.3g} at t = {when:.6g} s, {share} (over "
        f"{MISMATCH_TOLERANCE:.0%} is reported); the file's values are used as given"
    )
