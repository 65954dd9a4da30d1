"""Single-sample evaluation for control loops: parameters and buffers allocated once.

>>> ev = SampleEvaluator(load_model())        # compiles the generated C on first use
>>> ev.q[:] = (0.01, 0.0, 0.1); ev.qd[:] = 0; ev.qdd[:] = 0
>>> ev()                                       # 0 on success; results in ev.out
0
>>> torque = ev.out[ev.index["m10_A"]]
"""

from __future__ import annotations

import ctypes

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen import cbackend
from rpr3gen.backends import OUTPUT_NAMES, numpy_module
from rpr3gen.errors import Rpr3genError
from rpr3gen.model import Model

RETURN_CODES = {0: "ok", 1: "an input is not finite", 2: "singular or degenerate pose"}


class SampleEvaluator:
    """Evaluates the inverse dynamics of one sample into preallocated buffers.

    Write the sample into :attr:`q`, :attr:`qd`, :attr:`qdd` (float64, shape (3,)) and call the
    object; the outputs land in :attr:`out` (shape (NUM_OUTPUTS,), ordered as
    :data:`rpr3gen.OUTPUT_NAMES`; :attr:`index` maps a name to its position). With the ``c``
    backend a call makes no allocation: the generated C is called with pointers fixed at
    construction. On a non-zero return code :attr:`out` is left as it was.
    """

    def __init__(self, model: Model, backend: str = "c") -> None:
        self.model = model
        self.backend = backend
        self.q = np.zeros(3)
        self.qd = np.zeros(3)
        self.qdd = np.zeros(3)
        self.out = np.full(len(OUTPUT_NAMES), np.nan)
        self.index = {name: k for k, name in enumerate(OUTPUT_NAMES)}
        if backend == "c":
            param_names, output_names = cbackend.names(model.actuation)
            if output_names != OUTPUT_NAMES:
                raise Rpr3genError("generated C does not match this runtime; run rpr3gen generate")
            self.params = np.ascontiguousarray(model.vector(param_names))
            buffers = (self.params, self.q, self.qd, self.qdd, self.out)
            self._packed = cbackend.Call(*(b.ctypes.data for b in buffers))
            self._args = (ctypes.c_void_p(ctypes.addressof(self._packed)),)
            self._call = cbackend.library(model.actuation).rpr3_call_packed
        elif backend == "numpy":
            module = numpy_module(model.actuation)
            self.params = model.vector(module.PARAM_NAMES)
            self._numpy = module.rpr3_inverse_dynamics
            self._scratch = np.empty((len(OUTPUT_NAMES), 1))
        else:
            raise Rpr3genError(f"unknown backend {backend!r}; choose c or numpy")

    def __call__(self) -> int:
        """Evaluate the sample in q, qd, qdd; return 0, or a code of :data:`RETURN_CODES`."""
        if self.backend == "c":
            return self._call(*self._args)
        inputs = (self.q, self.qd, self.qdd)
        if not all(np.isfinite(v).all() for v in inputs):
            return 1
        self._numpy(self.params, *(v[np.newaxis, :] for v in inputs), self._scratch)
        if not np.isfinite(self._scratch).all():
            return 2
        self.out[:] = self._scratch[:, 0]
        return 0

    def evaluate(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """Copy a sample in, evaluate, and return :attr:`out`; raise on a non-zero code."""
        self.q[:], self.qd[:], self.qdd[:] = q, qd, qdd
        status = self()
        if status:
            raise Rpr3genError(f"sample q={self.q.tolist()}: {RETURN_CODES.get(status, status)}")
        return self.out
