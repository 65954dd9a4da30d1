"""Evaluate the generated inverse dynamics over arrays of samples.

The generated modules live in the package ``rpr3gen_generated`` (folder ``generated/``), one
sub-package per actuation scheme; this module only shapes arrays and picks the variant.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Iterator
from types import ModuleType

import numpy as np
import rpr3gen_generated as generated
from numpy.typing import ArrayLike

from rpr3gen.errors import InputError, Rpr3genError
from rpr3gen.model import Model

BACKENDS: tuple[str, ...] = ("numpy", "c")

#: Output names, family-major (``phi10_A, phi10_B, phi10_C, lambda21_A, ...``), as conventions.md,
#: then ``conditioning``: closeness to a parallel singularity, 0 (singular) to 1.
OUTPUT_NAMES: tuple[str, ...] = generated.OUTPUT_NAMES
#: Below this conditioning a pose is singular: its outputs are NaN (as RPR3_MIN_CONDITIONING).
SINGULAR_CONDITIONING = 1e-9
#: Samples evaluated per call of the generated code: the NumPy temporaries of one block stay
#: in cache and memory stays bounded however long the trajectory (benchmarks/ measures this).
BLOCK = 8192


def numpy_module(actuation: str) -> ModuleType:
    """The generated NumPy module of one actuation scheme."""
    module = importlib.import_module(f"rpr3gen_generated.{actuation}.rpr3_numpy")
    if tuple(module.OUTPUT_NAMES) != OUTPUT_NAMES:
        raise Rpr3genError(
            f"generated code for {actuation!r} does not match this runtime; run `rpr3gen generate`"
        )
    return module


def _samples(name: str, value: ArrayLike) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.ndim == 1 and array.shape == (3,):
        array = array[np.newaxis, :]
    if array.ndim != 2 or array.shape[1] != 3:
        raise InputError(f"{name} must have shape (n, 3), got {np.shape(value)}")
    return np.ascontiguousarray(array)


def _blocks(n: int, progress: bool) -> Iterator[slice]:
    """Consecutive blocks of at most :data:`BLOCK` samples, with a progress bar on request.

    The bar goes to stderr, only when it is a terminal and the run lasts over half a second.
    """
    starts = range(0, n, BLOCK)
    if progress and sys.stderr.isatty() and n > BLOCK:
        from tqdm import tqdm

        try:  # a terminal that reports no size (serial consoles, some CI) gets 80 x 24
            size = os.get_terminal_size(sys.stderr.fileno())
        except OSError:
            size = os.terminal_size((0, 0))
        bar = tqdm(
            total=n,
            unit="sample",
            unit_scale=True,
            delay=0.5,
            leave=False,
            ncols=size.columns or 80,
            nrows=size.lines or 24,
        )
        for lo in starts:
            yield slice(lo, min(lo + BLOCK, n))
            bar.update(min(BLOCK, n - lo))
        bar.close()
    else:
        for lo in starts:
            yield slice(lo, min(lo + BLOCK, n))


def _evaluate(
    model: Model,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    backend: str,
    progress: bool = False,
) -> np.ndarray:
    """All outputs as a (NUM_OUTPUTS, n) array; rows of a singular sample are inf or nan."""
    n = q.shape[0]
    if backend == "numpy":
        module = numpy_module(model.actuation)
        params = model.vector(module.PARAM_NAMES)
        out = np.empty((len(OUTPUT_NAMES), n))
        for block in _blocks(n, progress):
            module.rpr3_inverse_dynamics(params, q[block], qd[block], qdd[block], out[:, block])
        return out
    if backend == "c":
        from rpr3gen import cbackend

        param_names, output_names = cbackend.names(model.actuation)
        if output_names != OUTPUT_NAMES:
            raise Rpr3genError("generated C does not match this runtime; run `rpr3gen generate`")
        params = model.vector(param_names)
        rows = np.empty((n, len(OUTPUT_NAMES)))
        for block in _blocks(n, progress):
            cbackend.batch(
                params, q[block], qd[block], qdd[block], model.actuation, out=rows[block]
            )
        return rows.T
    raise InputError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")


def inverse_dynamics(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    backend: str = "numpy",
    progress: bool = False,
) -> dict[str, np.ndarray]:
    """Leg kinematics, actuator loads and every joint load for n platform samples.

    Args:
        model: the robot (:func:`rpr3gen.load_model`); its ``actuation`` picks the variant.
        q: (n, 3) platform pose (x, y, phi) of the centre G, in m, m, rad (eq. 3 or a file).
        qd: (n, 3) velocity (dx, dy, dphi).
        qdd: (n, 3) acceleration (ddx, ddy, ddphi).
        backend: ``"numpy"`` (generated NumPy) or ``"c"`` (generated C, compiled on first use
            and cached; see :mod:`rpr3gen.cbackend`).
        progress: show a progress bar on stderr when it is a terminal (long trajectories).

    Returns:
        ``{name: (n,) array}`` for every name of :data:`OUTPUT_NAMES` (conventions.md: loads
        exerted by body k-1 on body k, SI units). A sample whose input is not finite or whose
        pose is singular (``conditioning`` under :data:`SINGULAR_CONDITIONING`, or a result
        not finite) gives NaN in every output, with either backend; no error is raised, so
        callers decide (``rpr3gen simulate`` refuses such a trajectory). With ``"c"`` the arrays
        are strided views of one row-major block.
    """
    q, qd, qdd = _samples("q", q), _samples("qd", qd), _samples("qdd", qdd)
    if not q.shape == qd.shape == qdd.shape:
        raise InputError(f"q, qd, qdd differ in shape: {q.shape}, {qd.shape}, {qdd.shape}")
    out = _evaluate(model, q, qd, qdd, backend, progress)
    with np.errstate(invalid="ignore"):
        singular = ~(out[-1] >= SINGULAR_CONDITIONING) | ~np.isfinite(out).all(axis=0)
        singular |= ~np.isfinite(np.stack([q, qd, qdd], axis=0)).all(axis=(0, 2))
    if singular.any():
        out[:, singular] = np.nan
    return dict(zip(OUTPUT_NAMES, out, strict=True))
