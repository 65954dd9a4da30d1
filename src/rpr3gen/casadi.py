"""The CasADi bridge (extra ``casadi``): every function of a model's variant as a
``casadi.Function`` of SX graphs, built from the generated graph module (docs/bridges.md).

>>> import rpr3gen, rpr3gen.casadi as rc
>>> model = rpr3gen.load_model()
>>> f = rc.function(model, "inverse_dynamics")      # f(params, q, qd, qdd) -> out
>>> out = f(rc.parameters(model), [0, 0, 0], [0, 0, 0], [0, 0, 0])

Inputs and outputs are named and ordered as the C ABI (``params``, then the function's inputs;
its public outputs, each a flat column as the C arrays, matrices row-major). The graph is
CasADi's own, so ``casadi.jacobian``, ``Function.jacobian`` and code generation
(``Function.generate``) apply, and it saves as a ``.casadi`` file (``Function.save``). No
refusal of the C ABI applies: a graph has no return codes (docs/bridges.md, "Refusals").
CasADi is imported on the first call, not with :mod:`rpr3gen`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from rpr3gen import bridge, graph_compose, variants
from rpr3gen.manifest import Variant
from rpr3gen.model import Model
from rpr3gen.validation import Instance, checked

__all__ = ["function", "parameters"]


def _casadi() -> Any:
    try:
        import casadi
    except ImportError as exc:
        raise bridge.missing_extra("casadi", "casadi", exc) from None
    return casadi


class CasadiOps:
    """The graph protocol (docs/bridges.md) on CasADi SX scalars."""

    def __init__(self, ca: Any) -> None:
        self.ca = ca
        self._built: dict[str, Any] = {}
        self.sin, self.cos, self.atan2, self.sqrt = ca.sin, ca.cos, ca.atan2, ca.sqrt
        self.fabs, self.fmin, self.fmax, self.sign = ca.fabs, ca.fmin, ca.fmax, ca.sign
        self.power, self.if_else = ca.power, ca.if_else

    def rint(self, x: Any) -> Any:
        """``floor(x + 1/2)``: CasADi has no ``rint``; only a tie (an angle of exactly an odd
        multiple of pi) is rounded otherwise."""
        return self.ca.floor(x + 0.5)

    def vector(self, values: Sequence[Any]) -> Any:
        return self.ca.vertcat(*(self.ca.SX(v) for v in values))

    def replace(self, vector: Any, values: dict[int, Any]) -> Any:
        out = self.ca.SX(vector)
        for k, v in values.items():
            out[k] = v
        return out

    def batch(
        self, name: str, function: Callable[..., list[list[Any]]], calls: Sequence[tuple[Any, ...]]
    ) -> list[list[list[Any]]]:
        """``function`` (the generated function ``name``) on each tuple of arguments: its SX
        graph built once, as a ``casadi.Function``, then called on each (CasADi inlines the
        call into the caller's graph in C++: the hexapod's regressor, 130 inverse dynamics,
        builds in a second where tracing each takes fifteen)."""
        ca = self.ca
        if name not in self._built:
            sizes = [ca.SX(a).numel() for a in calls[0]]
            syms = [ca.SX.sym(f"a{k}", n) for k, n in enumerate(sizes)]
            outputs = function(*syms)
            self._built[name] = (
                ca.Function(name, syms, [ca.vertcat(*(ca.SX(v) for v in o)) for o in outputs]),
                [len(o) for o in outputs],
            )
        built, counts = self._built[name]
        results = []
        for args in calls:
            found = built.call([ca.SX(a) for a in args])
            results.append([[f[i] for i in range(n)] for f, n in zip(found, counts, strict=True)])
        return results

    def solve(self, rows: Sequence[Sequence[Any]], rhs: Sequence[Any]) -> list[Any]:
        A = self.ca.vertcat(*(self.ca.horzcat(*(self.ca.SX(v) for v in row)) for row in rows))
        x = self.ca.solve(A, self.vector(rhs))
        return [x[i] for i in range(len(rhs))]


_BUILT: dict[tuple[str, str, str], Any] = {}


def _function(variant: Variant, name: str) -> Any:
    """The function, built once per variant (its folder and source hash) and name."""
    key = (str(variant.folder), variant.source_hash, name)
    if key not in _BUILT:
        _BUILT[key] = _build(variant, name)
    return _BUILT[key]


def _build(variant: Variant, name: str) -> Any:
    ca = _casadi()
    t = bridge.target(variant, name)
    ins = [ca.SX.sym("params", len(variant.param_names))]
    ins += [ca.SX.sym(a.name, a.size) for a in t.info.inputs]
    result = graph_compose.evaluate(variant, t.graph, CasadiOps(ca), name, ins[0], ins[1:])
    public = [(o, values) for o, values in zip(t.info.outputs, result.outputs, strict=True)
              if not o.hidden]  # fmt: skip
    outs = [ca.vertcat(*(ca.SX(v) for v in values)) for _, values in public]
    return ca.Function(
        name,
        ins,
        outs,
        ["params", *(a.name for a in t.info.inputs)],
        [o.name for o, _ in public],
    )


@checked(name=Instance(str, "the name of a generated function"))
def function(model: Model, name: str) -> Any:
    """The function ``name`` of ``model``'s variant as a ``casadi.Function`` of SX graphs.

    Args:
        model: the robot (:func:`rpr3gen.load_model`); its structure picks the variant. Its
            numbers are not in the graph: they are the input ``params`` (:func:`parameters`),
            so one function serves every robot of the structure.
        name: a generated function (``"inverse_dynamics"``, ``"actuator_jacobian"``, ...) or
            one the bridge composes (a spatial robot's ``"forward_dynamics"``, ...; every
            structure's ``"forward_kinematics"``: docs/bridges.md).

    Returns:
        ``f(params, *inputs) -> outputs``, named and ordered as the C ABI; the same object for
        the same variant and name (built once).

    Raises:
        InputError: no such function in the bridge (the message lists those there are).
        InputTypeError: ``model`` is not a :class:`rpr3gen.Model`, or ``name`` not a string.
        SetupError: CasADi is not installed (``pip install 'rpr3gen[casadi]'``).
    """
    return _function(variants.load(model.structure, model.generated, name), name)


@checked()
def parameters(model: Model) -> np.ndarray:
    """The ``params`` input of ``model``'s functions: its numbers in the variant's order
    (float64 (P,), the C ABI's ``params`` array; ``casadi.DM(parameters(model))`` if a DM is
    wanted)."""
    return model.vector(variants.load(model.structure, model.generated).param_names)
