"""The JAX backend (extra ``jax``): every function of a model's variant as a pure JAX function,
built from the generated graph module (docs/bridges.md), and ``backend="jax"`` for the usual
calls.

>>> import jax, rpr3gen, rpr3gen.jax as rj
>>> model = rpr3gen.load_model()
>>> g = rj.function(model, "inverse_dynamics")      # g(params, q, qd, qdd) -> out
>>> out = jax.jit(g, compiler_options=rj.COMPILER_OPTIONS)(rj.parameters(model), q, qd, qdd)
>>> dtau_dq = jax.jacfwd(g, argnums=1)(rj.parameters(model), q, qd, qdd)

The functions take one sample (``jax.vmap`` maps them over many) and return the public outputs
of the C ABI, flat (matrices row-major): one array, or a tuple when there are several. Importing
JAX through this module turns on float64 (``jax_enable_x64``) for the whole process: the
generated code is double precision. JAX is imported on the first call, not with :mod:`rpr3gen`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from rpr3gen import variants
from rpr3gen.errors import InputTypeError
from rpr3gen.jax_graph import COMPILER_OPTIONS, jax_module, single
from rpr3gen.model import Model
from rpr3gen.validation import Instance, checked

__all__ = ["COMPILER_OPTIONS", "function", "parameters"]


@checked(name=Instance(str, "the name of a generated function"))
def function(model: Model, name: str) -> Callable[..., Any]:
    """The function ``name`` of ``model``'s variant as a pure JAX function of one sample.

    Args:
        model: the robot; its structure picks the variant. Its numbers are the argument
            ``params`` (:func:`parameters`), so one function serves every robot of the
            structure.
        name: a generated function or one the bridges compose (docs/bridges.md).

    Returns:
        ``g(params, *inputs)``, arguments as the C ABI (float64 arrays (P,), (k,) ...), giving
        the public outputs (one array, or a tuple of them); ``jax.jit``, ``jax.vmap``,
        ``jax.grad`` and ``jax.jacfwd`` accept it. Jit the outermost function with
        :data:`COMPILER_OPTIONS` (a hexapod's inverse dynamics compiles in seconds with them,
        in many minutes without). No refusal applies: at a singular pose it
        gives what the formulas give (docs/bridges.md, "Refusals").

    Raises:
        InputError: no such function in the bridges (the message lists those there are).
        InputTypeError: ``model`` is not a :class:`rpr3gen.Model`, or ``name`` not a string.
        SetupError: JAX is not installed (``pip install 'rpr3gen[jax]'``).
    """
    variant = variants.load(model.structure, model.generated, name)
    one = single(variant, name)
    info = variant.function(name)
    public = [k for k, o in enumerate(info.outputs) if not o.hidden]
    count = 1 + len(info.inputs)
    jnp = jax_module().numpy

    def g(params: Any, *inputs: Any) -> Any:
        if len(inputs) + 1 != count:
            names = ", ".join(["params", *(a.name for a in info.inputs)])
            raise InputTypeError(f"{name} takes {count} arguments ({names}), got {len(inputs) + 1}")
        arrays = [jnp.asarray(a, jnp.float64) for a in (params, *inputs)]
        outputs, _ = one(*arrays)
        found = tuple(outputs[k] for k in public)
        return found[0] if len(found) == 1 else found

    g.__name__ = g.__qualname__ = name
    g.__doc__ = f"{info.doc}\n\nArguments: params, {', '.join(a.name for a in info.inputs)}."
    return g


@checked()
def parameters(model: Model) -> np.ndarray:
    """The ``params`` argument of ``model``'s functions: its numbers in the variant's order,
    float64 (P,)."""
    return model.vector(variants.load(model.structure, model.generated).param_names)
