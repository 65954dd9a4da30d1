"""Generated functions over many designs at once: one parameter vector per sample.

The generated NumPy functions (``generated/<variant>/rpr3_numpy.py``) compute every output
element by element, so their ``params`` argument may hold, instead of one vector (P,), one column
per sample (P, n): ``params[k]`` is then a row of n values and every operation broadcasts. Design
studies use that to evaluate designs x samples in one call (the fast path of a sweep).
``tests/test_design_stacked.py`` checks it against one call per design.

Only the NumPy backend does this (the C functions take one parameter vector).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

import numpy as np

from rpr3gen import failures, variants
from rpr3gen.backends import BLOCK
from rpr3gen.evaluators import evaluator
from rpr3gen.model import LEGS, PARAM_NAMES, Model

__all__ = [
    "PARAM_INDEX",
    "Evaluated",
    "evaluate_stacked",
    "leg_lengths",
    "param_rows",
    "piston_displacements",
]

PARAM_INDEX: dict[str, int] = {name: k for k, name in enumerate(PARAM_NAMES)}
"""Row of each parameter in a parameter vector or matrix."""


class Evaluated:
    """Every output component of one evaluation by name, raw, and the return codes.

    Attributes:
        values: ``{component name: (n,) array}`` for every output component, the hidden ones
            (``reach``, ``conditioning`` of the ``guards``) included. Values are as computed:
            a refused sample (code not 0) may hold anything, so read them with ``codes``.
        codes: (n,) the return code of each sample (0: ok; :mod:`rpr3gen.failures`).
        groups: ``{output array name: its component names}`` (e.g. ``"tau"``).
    """

    def __init__(
        self, values: dict[str, np.ndarray], codes: np.ndarray, groups: dict[str, tuple[str, ...]]
    ) -> None:
        self.values = values
        self.codes = codes
        self.groups = groups

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[name]

    def ok(self) -> np.ndarray:
        """(n,) bool: the generated code evaluated the sample (code 0)."""
        return self.codes == 0


def param_rows(models: Sequence[Model]) -> np.ndarray:
    """The parameter vectors of ``models`` as columns: (P, len(models)), :data:`PARAM_NAMES`."""
    return np.stack([m.vector() for m in models], axis=1)


def evaluate_stacked(
    model: Model, function: str, params: np.ndarray, inputs: Sequence[np.ndarray]
) -> Evaluated:
    """Evaluate the generated NumPy function ``function`` with one parameter vector per sample.

    Args:
        model: picks the generated variant (its ``actuation`` and ``generated`` folder); its own
            numbers are not used.
        function: the function's name in the manifest (e.g. ``"inverse_dynamics"``).
        params: (P,) one vector for every sample, or (P, n) one column per sample, in the
            order of :data:`PARAM_NAMES`.
        inputs: the function's inputs, each (n, size) float64.

    Returns:
        Every output component by name, raw, and the return codes that the failure policy
        gives each sample (:func:`rpr3gen.failures.return_codes`).
    """
    variant = variants.load(model.structure, model.generated)
    info = variant.function(function)
    arrays = [np.ascontiguousarray(a, dtype=np.float64) for a in inputs]
    n = arrays[0].shape[0]
    params = np.asarray(params, dtype=np.float64)
    ev = evaluator(variant, "numpy")
    outputs = ev.allocate(info, n)
    codes = np.zeros(n, dtype=np.intc)
    for lo in range(0, n, BLOCK):
        block = slice(lo, min(lo + BLOCK, n))
        ins, outs = [a[block] for a in arrays], [o[block] for o in outputs]
        if params.ndim == 1:
            failed = ev.run(info, params, ins, outs)
        else:
            p = np.ascontiguousarray(params[:, block])
            try:
                failed = ev.run(info, p, ins, outs)
            except ValueError:
                _by_runs(ev, info, p, ins, outs)
                failed = None
        if failed != 0:  # unknown: the per-sample codes of the block
            codes[block] = failures.return_codes(info, ins, outs, applied=False)
    values = {
        name: out[:, k]
        for arg, out in zip(info.outputs, outputs, strict=True)
        for k, name in enumerate(arg.names)
    }
    return Evaluated(values, codes, {arg.name: arg.names for arg in info.outputs})


def _by_runs(
    ev: Any, info: Any, params: np.ndarray, inputs: list[np.ndarray], outputs: list[np.ndarray]
) -> None:
    """Evaluate each run of equal parameter columns with its one parameter vector.

    For generated code that is not element-wise in its parameters: a variant whose value of
    an output depends on the parameters alone writes it with ``fill`` (the 3-PPR's ``reach``),
    which takes a number, not a row, and raises ValueError on stacked parameters. A sweep's
    columns come in runs (one design's samples), so this costs one call per design.
    """
    starts = np.flatnonzero(np.any(params[:, 1:] != params[:, :-1], axis=0)) + 1
    edges = [0, *starts.tolist(), params.shape[1]]
    for a, b in itertools.pairwise(edges):
        ev.run(info, params[:, a].copy(), [x[a:b] for x in inputs], [o[a:b] for o in outputs])


def leg_lengths(params: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``|A1A3|`` of each leg (m), (n, 3), from the geometry alone (eq. 5).

    Args:
        params: (P,) or (P, n) parameter vectors, :data:`PARAM_NAMES` order.
        q: (n, 3) platform poses.
    """
    c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
    columns = []
    for leg in LEGS:
        x3, y3 = params[PARAM_INDEX[f"x{leg}3"]], params[PARAM_INDEX[f"y{leg}3"]]
        dx = q[:, 0] + c * x3 - s * y3 - params[PARAM_INDEX[f"x{leg}1"]]
        dy = q[:, 1] + s * x3 + c * y3 - params[PARAM_INDEX[f"y{leg}1"]]
        columns.append(np.hypot(dx, dy))
    return np.stack(columns, axis=1)


def piston_displacements(params: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``lambda21 = |A1A3| - l0 - l2`` of each leg (m), (n, 3) (eq. 5); arguments as
    :func:`leg_lengths`."""
    central = params[PARAM_INDEX["l0"]] + params[PARAM_INDEX["l2"]]
    return leg_lengths(params, q) - np.asarray(central)[..., np.newaxis]
