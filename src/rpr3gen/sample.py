"""Single-sample evaluation for control loops: parameters and buffers allocated once.

>>> ev = SampleEvaluator(load_model())        # compiles the generated C on first use
>>> ev.q[:] = (0.01, 0.0, 0.1); ev.qd[:] = 0; ev.qdd[:] = 0
>>> ev()                                       # 0 on success; results in ev.out
0
>>> torque = ev.out[ev.index["m10_A"]]

Any generated function can be bound the same way by name (``function="..."``): its inputs and
outputs become attributes named as in the manifest. Evaluators can share buffers
(``buffers={"q": fk.q}``), so that one function's output is another's input with no copy: a
control tick then moves no data between its generated calls.
"""

from __future__ import annotations

import ctypes
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from rpr3gen import failures, variants
from rpr3gen.errors import InputError
from rpr3gen.evaluators import evaluator
from rpr3gen.model import Model
from rpr3gen.validation import Instance, Optional, Reading, checked


class SampleEvaluator:
    """Evaluates one sample of a generated function into preallocated buffers.

    Write the sample into the input buffers (for the inverse dynamics :attr:`q`, :attr:`qd`,
    :attr:`qdd`: float64, shape (3,)) and call the object; the outputs land in the output
    buffers (for the inverse dynamics :attr:`out`, shape (NUM_OUTPUTS,), ordered as
    :data:`rpr3gen.OUTPUT_NAMES`; :attr:`index` maps a name of the first output to its
    position). With the ``c`` backend a call makes no allocation: the generated C is called
    with pointers fixed at construction. On a non-zero return code the outputs are left as they
    were; :attr:`codes` maps each code to its meaning (from the manifest).

    ``buffers`` maps input or output names to arrays to use as those buffers instead of new ones
    (float64, C-contiguous, of the argument's size), e.g. another evaluator's output.
    """

    @checked(
        function=Instance(str, "the name of a generated function"),
        buffers=Optional(Instance(Mapping, "a mapping of argument names to float64 buffers")),
    )
    def __init__(
        self,
        model: Model,
        backend: str = "c",
        function: str = "inverse_dynamics",
        buffers: Mapping[str, np.ndarray] | None = None,
    ):
        self.model = model
        self.backend = backend
        variant, self.function = variants.load_function(model.structure, model.generated, function)
        self.codes = dict(variant.code_meanings)
        self.params = np.ascontiguousarray(model.vector(variant.param_names))
        given = dict(buffers or {})
        self.inputs = {
            a.name: _buffer(given, a.name, np.zeros(a.size)) for a in self.function.inputs
        }
        self.outputs = {
            o.name: _buffer(given, o.name, np.full(o.size, np.nan))
            for o in self.function.public_outputs
        }
        if given:
            raise InputError(f"{function}: no input or output named {sorted(given)}")
        for name, buffer in (*self.inputs.items(), *self.outputs.items()):
            setattr(self, name, buffer)
        first = self.function.outputs[0]
        self.index = {name: k for k, name in enumerate(first.names)}
        ev = evaluator(variant, backend)  # also checks the backend's name
        if backend == "c":
            arrays = [self.params, *self.inputs.values(), *self.outputs.values()]
            self._pointers = (ctypes.c_void_p * len(arrays))(*(b.ctypes.data for b in arrays))
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
        if self._evaluator.run(self.function, self.params, inputs, self._scratch) == 0:
            code = 0  # the evaluator's own checks found no failure
        else:
            code = int(failures.return_codes(self.function, inputs, self._scratch)[0])
        if code == 0:
            for out, scratch in zip(self.outputs.values(), self._scratch, strict=False):
                out[:] = scratch[0]  # the public outputs come first
        return code

    def evaluate(self, *inputs: ArrayLike) -> np.ndarray:
        """Copy a sample in, evaluate, and return the first output; a non-zero code (a singular
        pose, a non-finite input) raises an :class:`~rpr3gen.errors.InputError` naming it."""
        if len(inputs) != len(self.inputs):
            names = ", ".join(self.inputs)
            raise InputError(f"inputs: {self.function.name} takes {len(self.inputs)} ({names}), "
                             f"got {len(inputs)}", argument="inputs")  # fmt: skip
        for (name, buffer), value in zip(self.inputs.items(), inputs, strict=True):
            buffer[:] = Reading(buffer.size)(name, value)
        status = self()
        if status:
            first = next(iter(self.inputs))
            raise InputError(
                f"sample {first}={self.inputs[first].tolist()}: {self.codes.get(status, status)}"
            )
        return next(iter(self.outputs.values()))


def _buffer(given: dict[str, np.ndarray], name: str, default: np.ndarray) -> np.ndarray:
    """``given[name]`` (removed from ``given``) checked to replace ``default``, else ``default``."""
    if name not in given:
        return default
    buffer = given.pop(name)
    ok = isinstance(buffer, np.ndarray) and buffer.dtype == np.float64
    if not (ok and buffer.shape == default.shape and buffer.flags.c_contiguous):
        raise InputError(
            f"buffer {name!r}: need a C-contiguous float64 array of shape {default.shape}"
        )
    return buffer
