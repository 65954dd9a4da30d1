"""Whether measured data determine the parameters of a linear fit, and how well.

:func:`rpr3gen.identify` fits ``tau = W x``; before it does, :func:`assess` looks at the stacked
columns ``W`` (each scaled to unit norm, so that the parameters' units do not matter) through
their singular values ``s_1 >= ... >= s_p`` and right singular vectors:

- **rank**: the combinations of parameters along which no effort changes at all, those with
  ``s_k <= s_1 max(rows, p) eps`` (NumPy's ``matrix_rank`` tolerance: zero but for rounding).
  They are undetermined whatever the noise: :func:`identify` refuses and names them
  (:func:`combinations`).
- **condition number** ``s_1 / s_p``, against two bounds (docs/identification.md, "Bounds"):

  - :data:`WARN_CONDITION` (1e3), the documented bound for a good exciting motion: to first
    order the relative error of the estimates is at most the condition number times the
    relative error of the efforts, so above it 0.1 % of noise in the efforts can move the
    least well determined combination by its own size. :func:`identify` fits and warns
    (:class:`~rpr3gen.errors.IdentificationWarning`), naming the estimates whose standard
    deviation the motion inflates most.
  - :data:`MAX_CONDITION` (1e5), the hard bound: the columns are computed from measured motion,
    whose relative accuracy is at best about 1e-5 (an encoder of 2^17 counts per turn resolves
    7.6e-6 of a turn; velocities and accelerations differentiated from positions are less
    accurate). A singular value under ``1e-5 s_1`` is then within what an error of the data
    themselves can make zero (the numerical rank at that tolerance, Golub and Van Loan,
    *Matrix Computations*, 4th ed., sec. 5.4.1): such data cannot be told from data that
    leave a combination undetermined, and :func:`identify` refuses, naming it.

- **inflation** of each estimate's standard deviation: ``sqrt`` of its variance inflation
  factor, ``[(Wᵀ W)⁻¹]_jj`` with unit-norm columns (Belsley, Kuh and Welsch, *Regression
  Diagnostics*, 1980): how much larger the standard deviation is than if the motion excited
  that parameter with columns orthogonal to all the others (1 at best).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["MAX_CONDITION", "WARN_CONDITION", "Assessment", "assess", "combinations"]

#: Above this condition number :func:`rpr3gen.identify` fits and warns (see the module).
WARN_CONDITION = 1e3
#: Above this condition number :func:`rpr3gen.identify` refuses (see the module).
MAX_CONDITION = 1e5
#: Smallest coefficient, in unit-norm columns, of a parameter named in a combination.
_SMALLEST_TERM = 1e-2


@dataclass(frozen=True)
class Assessment:
    """What the stacked columns ``W`` (rows x p) say about a fit.

    Attributes:
        condition_number: ``s_1 / s_p`` of ``W`` with unit-norm columns (inf when rank-deficient).
        rank: the number of singular values above ``s_1 max(rows, p) eps``.
        inflation: (p,) each estimate's standard deviation over what it would be with columns
            orthogonal to the others (inf for an undetermined parameter).
        singular_values: (p,) of ``W`` with unit-norm columns, decreasing.
        directions: (p, p) the right singular vectors, one per row, in unit-norm columns.
        scale: (p,) the norms of the columns (1 for a zero column).
    """

    condition_number: float
    rank: int
    inflation: np.ndarray
    singular_values: np.ndarray
    directions: np.ndarray
    scale: np.ndarray

    def below(self, fraction: float) -> np.ndarray:
        """The directions (rows) whose singular value is at most ``fraction`` of the largest."""
        s = self.singular_values
        return self.directions[s <= fraction * s[0]]


def assess(W: np.ndarray) -> Assessment:
    """Rank, condition number and standard deviation inflation of the columns of ``W``."""
    scale = np.linalg.norm(W, axis=0)
    scale[scale == 0] = 1.0
    _, s, vt = np.linalg.svd(W / scale, full_matrices=False)
    rank = int(np.sum(s > s[0] * max(W.shape) * np.finfo(float).eps))
    if rank == len(s):
        condition = float(s[0] / s[-1])
        inflation = np.sqrt(np.sum((vt / s[:, None]) ** 2, axis=0))
    else:
        condition, inflation = math.inf, np.full(len(s), math.inf)
    return Assessment(
        condition_number=condition,
        rank=rank,
        inflation=inflation,
        singular_values=s,
        directions=vt,
        scale=scale,
    )


def combinations(names: Sequence[str], assessment: Assessment, fraction: float) -> list[str]:
    """The combinations of parameters along the directions whose singular value is at most
    ``fraction`` of the largest, each written with its own leading parameter, e.g.
    ``Jzz_3 - 0.0225 m_3``: moving the parameters by ``t`` times those coefficients changes the
    efforts by at most ``fraction`` of the best determined direction (by none for a rank
    deficiency).

    The directions are put in echelon form first (each leads with a parameter the others do
    not contain, chosen by pivoted QR), so that a parameter the data do not see at all is
    named alone.
    """
    directions = assessment.below(fraction)
    if not len(directions):
        return []
    import scipy.linalg  # here, not at the top: `import rpr3gen` (every command) stays quick

    _, _, pivots = scipy.linalg.qr(directions, pivoting=True, mode="economic")
    lead = pivots[: len(directions)]
    echelon = np.linalg.solve(directions[:, lead], directions)
    out = []
    for row, j in sorted(zip(echelon, lead, strict=True), key=lambda item: item[1]):
        # In the parameters' own units: a step of 1 in unit-norm columns is 1 / scale.
        coefficients = row * assessment.scale[j] / assessment.scale
        terms = [names[j]]
        for k in sorted(range(len(row)), key=lambda k: (-round(abs(row[k]), 3), k)):
            if k == j or abs(row[k]) < _SMALLEST_TERM:
                continue
            sign = "-" if coefficients[k] < 0 else "+"
            size = abs(coefficients[k])
            factor = "" if math.isclose(size, 1.0, rel_tol=1e-6) else f"{size:.3g} "
            terms.append(f"{sign} {factor}{names[k]}")
        out.append(" ".join(terms))
    return out
