"""Evaluate the generated inverse dynamics over arrays of samples.

The generated modules live in the package ``rpr3gen_generated`` (folder ``generated/``), one
sub-package per actuation scheme; this module only shapes arrays and picks the variant.
"""

from __future__ import annotations

import importlib
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen.errors import Rpr3genError
from rpr3gen.model import Model

BACKENDS: tuple[str, ...] = ("numpy", "c")

_FAMILIES = (
    "phi10", "lambda21", "phi32", "omega10", "v21", "omega32", "eps10", "gamma21", "eps32",
    "m10", "f10x", "f10y", "f21y", "f21z", "m21", "f32y", "f32z",
)  # fmt: skip
#: Output names, family-major (``phi10_A, phi10_B, phi10_C, lambda21_A, ...``), as conventions.md,
#: then ``conditioning``: closeness to a parallel singularity, 0 (singular) to 1.
OUTPUT_NAMES: tuple[str, ...] = (
    *(f"{f}_{leg}" for f in _FAMILIES for leg in "ABC"),
    "conditioning",
)
#: Below this conditioning a pose is singular: its outputs are NaN (as RPR3_MIN_CONDITIONING).
SINGULAR_CONDITIONING = 1e-9


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
        raise Rpr3genError(f"{name} must have shape (n, 3), got {np.shape(value)}")
    return np.ascontiguousarray(array)


def _evaluate(
    model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, backend: str
) -> np.ndarray:
    """All outputs as a (NUM_OUTPUTS, n) array; rows of a singular sample are inf or nan."""
    if backend == "numpy":
        module = numpy_module(model.actuation)
        out = np.empty((len(OUTPUT_NAMES), q.shape[0]))
        module.rpr3_inverse_dynamics(model.vector(module.PARAM_NAMES), q, qd, qdd, out)
        return out
    if backend == "c":
        from rpr3gen import cbackend

        param_names, output_names = cbackend.names(model.actuation)
        if output_names != OUTPUT_NAMES:
            raise Rpr3genError("generated C does not match this runtime; run `rpr3gen generate`")
        rows, _ = cbackend.batch(model.vector(param_names), q, qd, qdd, model.actuation)
        return rows.T
    raise Rpr3genError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")


def inverse_dynamics(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    backend: str = "numpy",
) -> dict[str, np.ndarray]:
    """Leg kinematics, actuator loads and every joint load for n platform samples.

    Args:
        model: the robot (:func:`rpr3gen.load_model`); its ``actuation`` picks the variant.
        q: (n, 3) platform pose (x, y, phi) of the centre G, in m, m, rad (eq. 3 or a file).
        qd: (n, 3) velocity (dx, dy, dphi).
        qdd: (n, 3) acceleration (ddx, ddy, ddphi).
        backend: ``"numpy"`` (generated NumPy) or ``"c"`` (generated C, compiled on first use
            and cached; see :mod:`rpr3gen.cbackend`).

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
        raise Rpr3genError(f"q, qd, qdd differ in shape: {q.shape}, {qd.shape}, {qdd.shape}")
    out = _evaluate(model, q, qd, qdd, backend)
    with np.errstate(invalid="ignore"):
        singular = ~(out[-1] >= SINGULAR_CONDITIONING) | ~np.isfinite(out).all(axis=0)
        singular |= ~np.isfinite(np.stack([q, qd, qdd], axis=0)).all(axis=(0, 2))
    if singular.any():
        out[:, singular] = np.nan
    return dict(zip(OUTPUT_NAMES, out, strict=True))
