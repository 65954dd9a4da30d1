"""Evaluate generated functions over arrays of samples: the inverse dynamics, and any function by
name (:func:`evaluate`).

This module shapes arrays, picks the model's generated variant (:mod:`rpr3gen.manifest`), runs
it in blocks through an evaluator (:mod:`rpr3gen.evaluators`) and applies the failure policy
(:mod:`rpr3gen.failures`), so every backend gives the same NaN rows and return codes.
"""

from __future__ import annotations

import itertools
import os
import sys
from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen import failures, manifest, sizes, variants
from rpr3gen.errors import InputError, InputTypeError
from rpr3gen.evaluators import BACKENDS, NumpyEvaluator, evaluator, thread_count
from rpr3gen.model import Model
from rpr3gen.validation import (
    Check,
    Instance,
    PoseRows,
    Rows,
    check_same_length,
    checked,
    describe,
    match_width,
)

__all__ = ["BACKENDS", "OUTPUT_NAMES", "evaluate", "inverse_dynamics", "output_names"]

#: Output names of the inverse dynamics, family-major (``phi10_A, phi10_B, phi10_C,
#: lambda21_A, ...``) as docs/conventions.md, then ``conditioning``: closeness to a parallel
#: singularity, 0 (singular) to 1.
OUTPUT_NAMES: tuple[str, ...] = (
    manifest.load("revolute").function("inverse_dynamics").outputs[0].names
)
#: Samples per call of the generated NumPy code: the temporaries of one block stay in cache
#: and memory stays bounded however long the trajectory (benchmarks/ measures this). The C
#: backend takes larger blocks (``CEvaluator.block``), split across threads.
BLOCK = NumpyEvaluator.block
#: Seconds before the progress bar shows (tqdm's ``delay``).
PROGRESS_DELAY = 0.5


def samples(name: str, value: ArrayLike, size: int) -> np.ndarray:
    """``value`` as a C-contiguous float64 (n, size) array; one sample may be given as (size,)
    (:class:`rpr3gen.validation.Rows`)."""
    return Rows(size)(name, value)


class _Inputs(Check):
    """``evaluate``'s ``inputs``: a list or tuple, one array per input of the function."""

    def __call__(self, name: str, value: object) -> Sequence[ArrayLike]:
        if not isinstance(value, list | tuple):
            raise InputTypeError(
                f"{name}: must be a list or tuple of arrays, one per input of the function, "
                f"got {describe(value)}",
                argument=name,
            )
        return value


def _evaluation_bytes(n: int, info: manifest.FunctionInfo) -> int:
    """Bytes of n samples of ``info``'s inputs and outputs."""
    values = sum(a.size for a in info.inputs) + sum(o.size for o in info.outputs)
    return n * values * sizes.EVALUATED_VALUE


def _blocks(n: int, progress: bool, block: int = BLOCK) -> Iterator[slice]:
    """Consecutive blocks of at most ``block`` samples, as equal as can be (10^4 samples are one
    block of 10^4, not 8,192 and 1,808: every block costs the same fixed dispatch), with a
    progress bar on request.

    The bar goes to stderr, only when it is a terminal and the run lasts over
    :data:`PROGRESS_DELAY` seconds.
    """
    count = max(1, -(-n // block))
    bounds = [n * k // count for k in range(count + 1)]
    blocks = [slice(lo, hi) for lo, hi in itertools.pairwise(bounds)]
    if progress and sys.stderr.isatty() and count > 1:
        from tqdm import tqdm

        try:  # a terminal that reports no size (serial consoles, some CI) gets 80 x 24
            size = os.get_terminal_size(sys.stderr.fileno())
        except OSError:
            size = os.terminal_size((0, 0))
        bar = tqdm(
            total=n,
            unit="sample",
            unit_scale=True,
            delay=PROGRESS_DELAY,
            leave=False,
            ncols=size.columns or 80,
            nrows=size.lines or 24,
        )
        for part in blocks:
            yield part
            bar.update(part.stop - part.start)
        bar.close()
    else:
        yield from blocks


@checked(function=Instance(str, "the name of a generated function"), inputs=_Inputs())
def evaluate(
    model: Model,
    function: str,
    inputs: Sequence[ArrayLike],
    backend: str = "numpy",
    progress: bool = False,
    threads: int | None = None,
) -> tuple[list[np.ndarray], np.ndarray]:
    """Evaluate the generated function ``function`` of the model's variant over n samples.

    Args:
        model: the robot; its ``actuation`` (and ``generated`` folder) pick the variant.
        function: the function's name in the manifest (e.g. ``"inverse_dynamics"``).
        inputs: one array per input of the function, each (n, size) (or (size,) for one sample).
        backend: ``"numpy"``, ``"c"`` or ``"jax"`` (the extra ``jax``: docs/bridges.md).
        progress: show a progress bar on stderr when it is a terminal (long runs).
        threads: threads of the ``"c"`` backend (default: every core this process may use);
            the results do not depend on it, bit for bit. The NumPy backend uses one.

    Returns:
        The outputs of the function's interface, each seen as (n, size), and the (n,) return
        codes (0: ok). The outputs of a failed sample are NaN, whatever the backend. Large
        outputs reuse the memory of earlier results that no one refers to any more
        (:mod:`rpr3gen.buffers`; :func:`rpr3gen.buffers.release` gives it back).
    """
    variant, info = variants.load_function(model.structure, model.generated, function)
    if len(inputs) != len(info.inputs):
        names = ", ".join(arg.name for arg in info.inputs)
        raise InputError(
            f"inputs: {function} takes {len(info.inputs)} ({names}), got {len(inputs)}",
            argument="inputs",
        )
    arrays = [samples(f"inputs: {arg.name}", a, arg.size)
              for arg, a in zip(info.inputs, inputs, strict=True)]  # fmt: skip
    check_same_length({arg.name: a for arg, a in zip(info.inputs, arrays, strict=True)}, "inputs")
    first = info.inputs[0].name
    sizes.check(first, len(arrays[0]), lambda n: _evaluation_bytes(n, info),
                f"the inputs and outputs of {function}", unit="samples")  # fmt: skip
    count = thread_count(threads)
    ev = evaluator(variant, backend)
    params = model.vector(variant.param_names)
    n = arrays[0].shape[0]
    outputs = ev.allocate(info, n)
    codes = np.zeros(n, dtype=np.intc)
    for block in _blocks(n, progress, ev.block):
        ins, outs = [a[block] for a in arrays], [o[block] for o in outputs]
        failed = ev.run(info, params, ins, outs, count)
        if failed != 0:  # unknown (NumPy could not tell), or some failed: find them in cache
            # a C-only function's NumPy composition (rpr3gen.composed) writes NaN rows as the C
            applied = ev.applies_checks or info.numpy_function is None
            codes[block] = failures.apply(info, ins, outs, applied=applied)
    public = [o for o, arg in zip(outputs, info.outputs, strict=True) if not arg.hidden]
    return public, codes


def output_names(model: Model) -> tuple[str, ...]:
    """The inverse dynamics' output names of a model's variant, in order (the paper's
    :data:`OUTPUT_NAMES`, or the general format's ``q1_A ... tau_C, conditioning, reach``)."""
    info = variants.load(model.structure, model.generated).function("inverse_dynamics")
    return info.outputs[0].names


@checked(q=PoseRows(), qd=PoseRows(), qdd=PoseRows(), same_length=[("q", "qd", "qdd")])
def inverse_dynamics(
    model: Model,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    backend: str = "numpy",
    progress: bool = False,
    threads: int | None = None,
) -> dict[str, np.ndarray]:
    """Leg kinematics, actuator loads and every joint load for n platform samples.

    Args:
        model: the robot (:func:`rpr3gen.load_model`); its structure picks the variant.
        q: (n, 3) platform pose (x, y, phi) of the centre G, in m, m, rad (eq. 3 or a file);
            a spatial robot's (docs/spatial-robots.md): (n, 6) ``(x, y, z, a, b, c)`` for a
            hexapod, (n, 3) ``(x, y, z)`` for a Delta.
        qd: (n, 3) velocity (dx, dy, dphi), or the spatial pose's rates.
        qdd: (n, 3) acceleration (ddx, ddy, ddphi), or the spatial pose's accelerations.
        backend: ``"numpy"`` (generated NumPy), ``"jax"`` (docs/bridges.md) or ``"c"``
            (generated C, compiled on first use and cached; see :mod:`rpr3gen.cbackend`).
        progress: show a progress bar on stderr when it is a terminal (long trajectories).
        threads: threads of the ``"c"`` backend (default: every core); same results whatever.

    Returns:
        ``{name: (n,) array}`` for every name of :data:`OUTPUT_NAMES` (docs/conventions.md:
        loads exerted by body k-1 on body k, SI units). A sample whose input is not finite or
        whose pose is singular (``conditioning`` under the generated code's ``MIN_CONDITIONING``,
        1e-9, or a result not finite) gives NaN in every output, with either backend; no error
        is raised, so callers decide (``rpr3gen simulate`` refuses such a trajectory). The
        arrays are views of one block (strided with ``"c"``).
    """
    arrays = {"q": np.asarray(q), "qd": np.asarray(qd), "qdd": np.asarray(qdd)}
    match_width(model.structure.dof, model.structure.title, **arrays)
    (out,), _ = evaluate(model, "inverse_dynamics", (q, qd, qdd), backend, progress, threads)
    names = variants.load(model.structure, model.generated).function("inverse_dynamics")
    return dict(zip(names.outputs[0].names, out.T, strict=True))
