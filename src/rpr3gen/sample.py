"""Single-sample evaluation for control loops: parameters and buffers allocated once.

>>> ev = SampleEvaluator(load_model())        # compiles the generated C on first use
>>> ev.q[:] = (0.01, 0.0, 0.1); ev.qd[:] = 0; ev.qdd[:] = 0
>>> ev()                                       # 0 on success; results in ev.out
0
>>> torque = ev.out[ev.index["m10_A"]]

Any generated function can be bound the same way by name (``function="..."``): its inputs and
outputs become attributes named as in the manifest.
"""

from __future__ import annotations

import ctypes

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen import policy, variants
from rpr3gen.errors import InputError, Rpr3genError
from rpr3gen.evaluators import evaluator
from rpr3gen.model import Model
from rpr3gen.validation import Instance, Reading, checked


class SampleEvaluator:
    """Evaluates one sample of a generated function into preallocated buffers.

    Write the sample into the input buffers (for the inverse dynamics :attr:`q`, :attr:`qd`,
    :attr:`qdd`: float64, shape (3,)) and call the object; the outputs land in the output
    buffers (for the inverse dynamics :attr:`out`, shape (NUM_OUTPUTS,), ordered as
    :data:`rpr3gen.OUTPUT_NAMES`; :attr:`index` maps a name of the first output to its
    position). With the ``c`` backend a call makes no allocation: the generated C is called
    with pointers fixed at construction. On a non-zero return code the outputs are left as they
    were; :attr:`codes` maps each code to its meaning (from the manifest).
    """

    @checked(function=Instance(str, "the name of a generated function"))
    def __init__(self, model: Model, backend: str = "c", function: str = "inverse_dynamics"):
        self.model = model
        self.backend = backend
        variant = variants.load(model.structure, model.generated)
        if function not in variant.functions:
            known = ", ".join(variant.functions)
            raise InputError(
                f"function: no generated function {function!r} (there are: {known})",
                argument="function",
            )
        self.function = variant.function(function)
        self.codes = dict(variant.code_meanings)
        self.params = np.ascontiguousarray(model.vector(variant.param_names))
        self.inputs = {a.name: np.zeros(a.size) for a in self.function.inputs}
        self.outputs = {o.name: np.full(o.size, np.nan) for o in self.function.public_outputs}
        for name, buffer in (*self.inputs.items(), *self.outputs.items()):
            setattr(self, name, buffer)
        first = self.function.outputs[0]
        self.index = {name: k for k, name in enumerate(first.names)}
        ev = evaluator(variant, backend)  # also checks the backend's name
        if backend == "c":
            buffers = [self.params, *self.inputs.values(), *self.outputs.values()]
            self._pointers = (ctypes.c_void_p * len(buffers))(*(b.ctypes.data for b in buffers))
            self._args = (ctypes.c_void_p(ctypes.addressof(self._pointers)),)
            self._call = ev.library.entries[self.function.name].packed  # type: ignore[attr-defined]
        else:
            self._evaluator = ev
            self._scratch = ev.allocate(self.function, 1)

    def __call__(self) -> int:
        """Evaluate the sample in the input buffers; return 0, or a code of :attr:`codes`."""
        if self.backend == "c":
            return int(self._call(*self._args))
        inputs = [v[np.newaxis, :] for v in self.inputs.values()]
        self._evaluator.run(self.function, self.params, inputs, self._scratch)
        code = int(policy.return_codes(self.function, inputs, self._scratch)[0])
        if code == 0:
            for out, scratch in zip(self.outputs.values(), self._scratch, strict=False):
                out[:] = scratch[0]  # the public outputs come first
        return code

    def evaluate(self, *inputs: ArrayLike) -> np.ndarray:
        """Copy a sample in, evaluate, and return the first output; raise on a non-zero code."""
        if len(inputs) != len(self.inputs):
            names = ", ".join(self.inputs)
            raise InputError(f"inputs: {self.function.name} takes {len(self.inputs)} ({names}), "
                             f"got {len(inputs)}", argument="inputs")  # fmt: skip
        for (name, buffer), value in zip(self.inputs.items(), inputs, strict=True):
            buffer[:] = Reading(buffer.size)(name, value)
        status = self()
        if status:
            first = next(iter(self.inputs))
            raise Rpr3genError(
                f"sample {first}={self.inputs[first].tolist()}: {self.codes.get(status, status)}"
            )
        return next(iter(self.outputs.values()))
