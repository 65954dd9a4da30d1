"""The runtime's backends behind one small interface: call a generated function by name.

An :class:`Evaluator` evaluates any function of a generated variant's manifest over a block of
samples (:meth:`~Evaluator.run`) into output arrays it allocates in its own layout
(:meth:`~Evaluator.allocate`; always seen as (n, size)). ``numpy`` runs the generated NumPy
module; ``c`` the generated C, compiled and bound by :mod:`rpr3gen.cbackend`. Neither knows any
function in particular: both read the manifest.
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Sequence
from types import ModuleType
from typing import Protocol

import numpy as np

from rpr3gen.errors import InputError
from rpr3gen.manifest import FunctionInfo, Variant

BACKENDS: tuple[str, ...] = ("numpy", "c")


class Evaluator(Protocol):
    """Evaluates the functions of one generated variant.

    ``applies_checks``: the backend applies the failure conditions itself (the generated C
    does, writing NaN rows; see :func:`rpr3gen.policy.return_codes`).
    """

    variant: Variant
    applies_checks: bool

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        """Uninitialised outputs for n samples, each seen as (n, size)."""
        ...

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
    ) -> None:
        """Evaluate n samples: ``inputs`` (n, size) C-contiguous float64, ``outputs`` rows of
        arrays from :meth:`allocate`. Failed samples hold inf or NaN (see :mod:`rpr3gen.policy`)."""
        ...


def numpy_module(variant: Variant) -> ModuleType:
    """The generated NumPy module of a variant, imported from its folder."""
    path = variant.path("numpy")
    name = f"_rpr3gen_generated_{variant.variant}_{variant.source_hash[:16]}"
    module = sys.modules.get(name)
    if module is None or getattr(module, "__file__", None) != str(path):
        spec = importlib.util.spec_from_file_location(name, path)
        assert spec is not None
        assert spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[name] = module
    return module


class NumpyEvaluator:
    """The generated NumPy code; outputs are stored (size, n), so each output row is contiguous."""

    applies_checks = False

    def __init__(self, variant: Variant) -> None:
        self.variant = variant
        self.module = numpy_module(variant)

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        return [np.empty((o.size, n)).T for o in function.outputs]

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
    ) -> None:
        if function.numpy_function is None:
            raise InputError(
                f"{function.name} has no NumPy version (its generated code is C only); "
                "use backend='c'"
            )
        call = getattr(self.module, function.numpy_function)
        call(params, *inputs, *(o.T for o in outputs))


class CEvaluator:
    """The generated C, through its batch functions; outputs are row-major (n, size).

    Hidden outputs (the values the checks test) stay inside the C: they are allocated, NaN.
    """

    applies_checks = True

    def __init__(self, variant: Variant) -> None:
        from rpr3gen import cbackend

        self.variant = variant
        self.library = cbackend.library(variant)

    def allocate(self, function: FunctionInfo, n: int) -> list[np.ndarray]:
        return [np.full((n, o.size), np.nan) if o.hidden else np.empty((n, o.size))
                for o in function.outputs]  # fmt: skip

    def run(
        self,
        function: FunctionInfo,
        params: np.ndarray,
        inputs: Sequence[np.ndarray],
        outputs: Sequence[np.ndarray],
    ) -> None:
        public = [o for o, info in zip(outputs, function.outputs, strict=True) if not info.hidden]
        for out in public:
            if not out.flags.c_contiguous:
                raise InputError("outputs of the c backend must be C-contiguous (n, size) arrays")
        batch = self.library.entries[function.name].batch
        n = inputs[0].shape[0]
        batch(params.ctypes.data, n, *(a.ctypes.data for a in inputs),
              *(o.ctypes.data for o in public))  # fmt: skip


_EVALUATORS: dict[tuple[str, str], Evaluator] = {}


def evaluator(variant: Variant, backend: str) -> Evaluator:
    """The evaluator of ``variant`` for ``backend`` (``"numpy"`` or ``"c"``), made once."""
    key = (str(variant.folder), backend)
    found = _EVALUATORS.get(key)
    if found is not None and found.variant.source_hash == variant.source_hash:
        return found
    if backend == "numpy":
        made: Evaluator = NumpyEvaluator(variant)
    elif backend == "c":
        made = CEvaluator(variant)
    else:
        raise InputError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")
    _EVALUATORS[key] = made
    return made
