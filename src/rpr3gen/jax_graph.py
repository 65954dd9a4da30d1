"""The JAX side of the bridges (docs/bridges.md): the graph protocol on JAX arrays, one sample
of any function the bridges offer as a pure function, and ``backend="jax"``'s evaluator
(:class:`JaxEvaluator`, which :func:`rpr3gen.evaluators.evaluator` makes). The public functions
are :mod:`rpr3gen.jax`'s. JAX is imported on first use, with float64 on.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from rpr3gen import bridge, graph_compose
from rpr3gen.buffers import OUTPUTS
from rpr3gen.manifest import FunctionInfo, Variant

__all__ = ["COMPILER_OPTIONS", "JaxEvaluator", "JaxOps", "jax_module", "single"]

#: XLA's options for compiling a bridge function: without its "fusion" pass. XLA's CPU
#: instruction fusion is superlinear on long straight-line programs of scalars (the hexapod's
#: inverse dynamics, ~10^4 operations, did not compile in five minutes; without the pass: 8 s,
#: the Delta's in 2 s instead of 10). ``backend="jax"`` compiles with them; a caller that jits a
#: function of its own passes them to its outermost ``jax.jit`` (XLA takes options there only):
#: ``jax.jit(f, compiler_options=rpr3gen.jax.COMPILER_OPTIONS)``.
COMPILER_OPTIONS: dict[str, str] = {"xla_disable_hlo_passes": "fusion"}


def jax_module() -> Any:
    """``jax``, imported with float64 on."""
    try:
        import jax
    except ImportError as exc:
        raise bridge.missing_extra("jax", "jax", exc) from None
    if not jax.config.read("jax_enable_x64"):
        jax.config.update("jax_enable_x64", True)
    return jax


class _Column(Sequence[Any]):
    """Component ``i`` of a batched output's row ``c``, read only when asked for (the
    compositions read a few of a function's many outputs)."""

    def __init__(self, array: Any, call: int) -> None:
        self.array, self.call = array, call

    def __len__(self) -> int:
        return int(self.array.shape[1])

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        return self.array[self.call, i]


class JaxOps:
    """The graph protocol (docs/bridges.md) on JAX scalars, and the compositions' helpers."""

    def __init__(self, jax: Any) -> None:
        jnp = jax.numpy
        self.jax, self.jnp = jax, jnp
        self.sin, self.cos, self.atan2, self.sqrt = jnp.sin, jnp.cos, jnp.arctan2, jnp.sqrt
        self.fabs, self.fmin, self.fmax, self.sign = jnp.abs, jnp.fmin, jnp.fmax, jnp.sign
        self.rint, self.if_else = jnp.rint, jnp.where

    def power(self, x: Any, n: int) -> Any:
        return self.jax.lax.integer_pow(self.jnp.asarray(x, self.jnp.float64), n)

    def vector(self, values: Sequence[Any]) -> Any:
        return self.jnp.stack([self.jnp.asarray(v, self.jnp.float64) for v in values])

    def replace(self, vector: Any, values: dict[int, Any]) -> Any:
        keys = self.jnp.array(list(values), dtype=int)
        return vector.at[keys].set(self.vector(list(values.values())))

    def solve(self, rows: Sequence[Sequence[Any]], rhs: Sequence[Any]) -> list[Any]:
        A = self.jnp.stack([self.vector(row) for row in rows])
        x = self.jnp.linalg.solve(A, self.vector(rhs))
        return [x[i] for i in range(len(rhs))]

    def batch(
        self, name: str, function: Callable[..., list[list[Any]]], calls: Sequence[tuple[Any, ...]]
    ) -> list[list[Any]]:
        """``function`` on each tuple of arguments, as one ``vmap`` over them."""
        if len(calls) == 1:
            return [list(function(*calls[0]))]
        stacked = [self.jnp.stack([self.jnp.asarray(a, self.jnp.float64) for a in column])
                   for column in zip(*calls, strict=True)]  # fmt: skip

        def one(*args: Any) -> list[Any]:
            return [self.vector(o) for o in function(*args)]

        outputs = self.jax.vmap(one)(*stacked)
        return [[_Column(o, c) for o in outputs] for c in range(len(calls))]


def _ops() -> JaxOps:
    return JaxOps(jax_module())


def single(variant: Variant, name: str) -> Callable[..., tuple[tuple[Any, ...], Any]]:
    """One sample of ``name``: every output of the manifest (hidden ones too) and whether the
    refusals' guards refuse it (a value below its threshold, or NaN)."""
    t = bridge.target(variant, name)
    ops = _ops()
    jnp = ops.jnp

    def single(params: Any, *inputs: Any) -> tuple[tuple[Any, ...], Any]:
        result = graph_compose.evaluate(variant, t.graph, ops, name, params, inputs)
        outputs = tuple(ops.vector(o) for o in result.outputs)
        refused = jnp.asarray(False)
        for value, least in result.guards:
            refused = refused | ~(jnp.asarray(value) >= least)
        return outputs, refused

    return single


def _bucket(n: int, block: int) -> int:
    """Samples a call is padded to, so that a jitted function is compiled for a few lengths
    only, whatever the lengths asked for: a power of two from 16 to :data:`STEP`, then a
    multiple of :data:`STEP` (at most an eighth of the block wasted: one compile per eighth of
    a block, 8 lengths beyond 1,024)."""
    size = 16
    while size < min(n, STEP):
        size *= 2
    if n > STEP:
        size = -(-n // STEP) * STEP
    return max(n, min(size, block))


#: Above this many samples, a call is padded to a multiple of it (:func:`_bucket`).
STEP = 1024


class JaxEvaluator:
    """``backend="jax"``: the pure functions of :func:`function`, mapped over the samples
    with ``jax.vmap`` and compiled with ``jax.jit`` (once per function and padded length,
    :func:`_bucket`); outputs are row-major (n, size), hidden ones included.

    The failure policy is the NumPy backend's: a generated function's samples are judged after
    the evaluation by :func:`rpr3gen.failures.apply` from its outputs, as NumPy's are; a
    composed one (a spatial robot's ``forward_dynamics`` ...) writes the refused samples as
    NaN rows here, as :mod:`rpr3gen.composed` does (the inner functions' guards, a non-finite
    input or output), and :func:`rpr3gen.evaluate` gives their codes as for the C.
    """

    applies_checks = False
    #: Samples per call: the mapped temporaries of the largest functions stay bounded.
    block = 8192

    def __init__(self, variant: Variant) -> None:
        self.variant = variant
        self._jitted: dict[str, Any] = {}

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        return [OUTPUTS.empty(n * o.size).reshape(n, o.size) for o in function.outputs]

    def _batched(self, name: str) -> Any:
        if name not in self._jitted:
            jax = jax_module()
            one = single(self.variant, name)
            inputs = len(self.variant.function(name).inputs)
            axes = (None,) + (0,) * inputs
            self._jitted[name] = jax.jit(
                jax.vmap(one, in_axes=axes), compiler_options=COMPILER_OPTIONS
            )
        return self._jitted[name]

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
        threads: int = 1,
    ) -> int | None:
        n = inputs[0].shape[0]
        size = _bucket(n, self.block)
        padded = [np.concatenate([a, np.zeros((size - n, a.shape[1]))]) for a in inputs]
        found, refused = self._batched(function.name)(params, *padded)
        for out, value in zip(outputs, found, strict=True):
            out[:] = np.asarray(value)[:n]
        if function.numpy_function is None:  # a composition: NaN rows, as composed.run
            bad = np.asarray(refused)[:n].copy()
            for array in (*inputs, *outputs):
                bad |= ~np.isfinite(array).all(axis=1)
            for out in outputs:
                out[bad] = np.nan
        return None
