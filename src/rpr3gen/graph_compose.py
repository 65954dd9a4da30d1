"""Any function of a generated variant as a symbolic graph, for the bridges (rpr3gen.casadi,
rpr3gen.jax; docs/bridges.md).

The functions with a program are the generated graph module's (``rpr3_graph.py``: scalar Python
over a math namespace ``ops``). The spatial robots' hand-written C bodies are composed here from
them exactly as :mod:`rpr3gen.composed` does in NumPy (``tau = T q'' + tau0``: ``T``'s columns
are the inverse dynamics at ``q'' = e_j`` with the platform at rest and the loads' parameters
zeroed; ``M = J^T T``, ``c = J^T tau0``; the forward dynamics solves ``T q'' = tau - tau0``).
The tracked forward kinematics (planar and spatial) is :data:`NEWTON_STEPS` plain Newton steps
from ``q_near`` on the generated ``actuator_coordinates_jacobian``: no step halving, no
fallback to another assembly mode.

Values are lists of scalars of the caller's kind; ``ops`` is the namespace the generated graph
functions call (``sin``, ``cos``, ``atan2``, ...: docs/bridges.md) with :class:`Ops`'s three
array helpers, and optionally ``batch`` (several calls of one generated function at once).
Nothing here refuses a sample: :class:`Result` carries the values the refusals test (the inner
functions' ``below`` checks, the Newton residual), which the JAX backend applies and a CasADi
graph cannot.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Protocol

from rpr3gen import composed, spatial_inertia
from rpr3gen.manifest import FunctionInfo, Variant

__all__ = ["NEWTON_STEPS", "Ops", "Result", "evaluate", "offered"]

#: Newton steps of the bridges' forward kinematics (from a ``q_near`` a control period away,
#: Newton converges in 3 to 5; the rest change nothing).
NEWTON_STEPS = 12
#: The largest residual (rad or m) of a forward kinematics pose that is not refused.
NEWTON_TOL = 1e-9
#: The functions with a hand-written C body the bridges compose: the spatial robots'
#: (:data:`rpr3gen.composed.COMPOSED`) and every structure's tracked forward kinematics.
FORWARD_KINEMATICS = ("forward_kinematics", "forward_kinematics_jacobian")


class Ops(Protocol):
    """The namespace a graph is built over: the generated graph module's math (``sin``, ``cos``,
    ``atan2``, ``sqrt``, ``fabs``, ``fmin``, ``fmax``, ``rint``, ``power``, ``sign``,
    ``if_else``) and three array helpers for the compositions."""

    def vector(self, values: Sequence[Any]) -> Any:
        """A vector of the caller's kind, indexable by component, from scalars."""
        ...

    def replace(self, vector: Any, values: dict[int, Any]) -> Any:
        """A copy of ``vector`` with some components replaced."""
        ...

    def solve(self, rows: Sequence[Sequence[Any]], rhs: Sequence[Any]) -> list[Any]:
        """``x`` with ``A x = rhs``, ``A`` given by its rows."""
        ...


@dataclass
class Result:
    """The outputs of a function (every output of the manifest, hidden ones last), each a list
    of scalars, and ``guards``: ``(value, least)`` pairs; a sample is refused where a value is
    below its least (or NaN)."""

    outputs: list[list[Any]]
    guards: list[tuple[Any, float]] = field(default_factory=list)


def offered(variant: Variant, info: FunctionInfo) -> bool:
    """Whether the bridges offer ``info``: a generated program, or a composition here."""
    if info.numpy_function is not None:
        return True
    return info.name in FORWARD_KINEMATICS or composed.composable(variant, info)


def evaluate(
    variant: Variant,
    graph: ModuleType,
    ops: Any,
    name: str,
    params: Any,
    inputs: Sequence[Any],
) -> Result:
    """The function ``name`` of ``variant`` on symbolic (or numeric) ``params`` and inputs."""
    info = variant.function(name)
    if info.numpy_function is not None:
        return _generated(variant, graph, ops, name, params, inputs)
    call = _Calls(variant, graph, ops)
    if name == "forward_dynamics_derivatives":
        return _forward_derivatives(variant, graph, ops, call, params, inputs)
    if name in FORWARD_KINEMATICS:
        return _forward_kinematics(call, variant, ops, name, params, inputs)
    return _spatial(call, variant, ops, name, params, inputs)


def _forward_derivatives(
    variant: Variant,
    graph: ModuleType,
    ops: Any,
    call: _Calls,
    params: Any,
    inputs: Sequence[Any],
) -> Result:
    """``q''`` and its Jacobians, as :func:`rpr3gen.composed.run`: ``T X = [-d tau / d q,
    -d tau / d q', I]`` with the inverse dynamics derivatives at the forward dynamics' ``q''``
    (derive/codegen/derivatives.py)."""
    q, qd, tau = inputs
    forward = evaluate(variant, graph, ops, "forward_dynamics", params, [q, qd, tau])
    qdd = forward.outputs[0]
    k = len(qdd)
    _, dq, dqd, dqdd = call("inverse_dynamics_derivatives", params, [q, qd, ops.vector(qdd)])[:4]
    T = _rows(dqdd, k)
    blocks = []
    for block in (dq, dqd, None):
        columns = [
            ops.solve(T, [-block[i * k + j] for i in range(k)])
            if block is not None
            else ops.solve(T, [1.0 if i == j else 0.0 for i in range(k)])
            for j in range(k)
        ]
        blocks.append([columns[j][i] for i in range(k) for j in range(k)])
    return Result([list(qdd), *blocks], forward.guards + call.guards)


def _guards(info: FunctionInfo, outputs: list[list[Any]]) -> list[tuple[Any, float]]:
    """The values of ``outputs`` that ``info``'s ``below`` checks test, with their thresholds."""
    return [
        (outputs[c.output][c.component], float(c.threshold))
        for c in info.checks
        if c.kind == "below"
        and c.output is not None
        and c.component is not None
        and c.threshold is not None
    ]


def _generated(
    variant: Variant, graph: ModuleType, ops: Any, name: str, params: Any, inputs: Sequence[Any]
) -> Result:
    outputs = [list(o) for o in getattr(graph, name)(ops, params, *inputs)]
    return Result(outputs, _guards(variant.function(name), outputs))


@dataclass
class _Calls:
    """Calls of the generated functions that gather their guards."""

    variant: Variant
    graph: ModuleType
    ops: Any
    guards: list[tuple[Any, float]] = field(default_factory=list)

    def __call__(self, name: str, params: Any, inputs: Sequence[Any]) -> list[list[Any]]:
        return self.many(name, [(params, *inputs)])[0]

    def many(self, name: str, calls: Sequence[tuple[Any, ...]]) -> list[list[list[Any]]]:
        """The generated function ``name`` on each tuple of arguments of ``calls``: through
        ``ops.batch(name, function, calls)`` when the namespace has it (CasADi builds the function's
        graph once and calls it, JAX maps it with ``vmap``), else one call after the other."""
        function = getattr(self.graph, name)

        def run(params: Any, *inputs: Any) -> list[list[Any]]:
            return [list(o) for o in function(self.ops, params, *inputs)]

        batch = getattr(self.ops, "batch", None)
        results = batch(name, run, calls) if batch else [run(*args) for args in calls]
        info = self.variant.function(name)
        for outputs in results:
            self.guards += _guards(info, outputs)
        return results


def _rows(flat: Sequence[Any], k: int) -> list[list[Any]]:
    """A row-major k x k matrix's rows."""
    return [list(flat[i * k : (i + 1) * k]) for i in range(k)]


def _zeroed(variant: Variant, ops: Any, params: Any, names: Sequence[str]) -> Any:
    return ops.replace(params, {variant.param_names.index(n): 0.0 for n in names})


def _spatial(
    call: _Calls, variant: Variant, ops: Any, name: str, params: Any, inputs: Sequence[Any]
) -> Result:
    """The spatial robots' hand-written C bodies, as :func:`rpr3gen.composed.run`."""
    rows = composed._tau_rows(variant)
    k = len(rows)
    q = inputs[0]
    zero = ops.vector([0.0] * k)

    def efforts(p: Any, ins: Sequence[Any]) -> list[Any]:
        return many([(p, *ins)])[0]

    def many(calls: Sequence[tuple[Any, ...]]) -> list[list[Any]]:
        """The efforts of the inverse dynamics on each tuple of arguments."""
        return [[out[0][r] for r in rows] for out in call.many("inverse_dynamics", calls)]

    if name == "actuator_efforts":
        return Result([efforts(params, inputs)], call.guards)
    if name == "payload_efforts":
        return Result([efforts(_zeroed(variant, ops, params, ("gx", "gy", "gz")), [q, zero, zero])],
                      call.guards)  # fmt: skip
    if name == "regressor":
        units = _unit_columns(variant, params, ops.sqrt)
        found = many([(ops.replace(params, edits), *inputs) for _, edits in units])
        columns: list[list[Any]] = []
        mass: list[Any] = []
        for (role, _), tau in zip(units, found, strict=True):
            if role == "moment":  # less its body's mass column, as composed._regressor
                tau = [t - m for t, m in zip(tau, mass, strict=True)]
            elif role == "mass":
                mass = tau
            columns.append(tau)
        flat = [columns[j][i] for i in range(k) for j in range(len(columns))]
        return Result([flat], call.guards)
    tau0 = efforts(params, [q, inputs[1], zero])
    p0 = _zeroed(variant, ops, params, composed.LOAD_PARAMS)
    unit = [ops.vector([1.0 if i == j else 0.0 for i in range(k)]) for j in range(k)]
    columns = many([(p0, q, zero, e) for e in unit])
    T = [[columns[j][i] for j in range(k)] for i in range(k)]
    if name == "task_space_dynamics":
        J = _rows(call("actuator_jacobian", params, [q])[0], k)
        M = [sum(J[r][i] * T[r][j] for r in range(k)) for i in range(k) for j in range(k)]
        c = [sum(J[r][i] * tau0[r] for r in range(k)) for i in range(k)]
        return Result([M, c], call.guards)
    if name != "forward_dynamics":  # pragma: no cover - offered() lists what is composed
        raise ValueError(f"{name}: not composed")
    tau = inputs[2]
    return Result([ops.solve(T, [tau[i] - tau0[i] for i in range(k)])], call.guards)


def _unit_columns(
    variant: Variant, params: Any, sqrt: Callable[[Any], Any]
) -> list[tuple[str, dict[int, Any]]]:
    """:func:`rpr3gen.spatial_inertia.unit_edits` of ``variant`` on symbolic ``params``."""
    kinds = variant.defines["LEG"].strip('"')
    legs = "ABCDEF"[: int(variant.defines["NUM_LEGS"])]
    return spatial_inertia.unit_edits(kinds, legs, variant.param_names, params, sqrt)


def _forward_kinematics(
    call: _Calls, variant: Variant, ops: Any, name: str, params: Any, inputs: Sequence[Any]
) -> Result:
    """:data:`NEWTON_STEPS` Newton steps on ``qa(q) = qa`` from ``q_near``; the guards of the
    pose reached and its largest residual (refused above :data:`NEWTON_TOL`)."""
    leg = variant.defines.get("LEG", '""').strip('"')
    wrap = leg[int(variant.defines.get("ACTUATED", "1")) - 1] == "R"
    qa, near = inputs
    k = len(variant.function(name).inputs[0].names)
    two_pi = 6.283185307179586

    def residual(q: list[Any]) -> tuple[list[Any], list[list[Any]]]:
        value, J = call("actuator_coordinates_jacobian", params, [ops.vector(q)])[:2]
        r = [value[i] - qa[i] for i in range(k)]
        if wrap:
            r = [x - two_pi * ops.rint(x * (1.0 / two_pi)) for x in r]
        return r, _rows(J, k)

    q = [near[i] for i in range(k)]
    for _ in range(NEWTON_STEPS):
        r, J = residual(q)
        call.guards.clear()  # only the pose reached is judged
        step = ops.solve(J, r)
        q = [q[i] - step[i] for i in range(k)]
    r, J = residual(q)
    worst = ops.fabs(r[0])
    for x in r[1:]:
        worst = ops.fmax(worst, ops.fabs(x))
    guards = [*call.guards, (-worst, -NEWTON_TOL)]
    flat_J = [J[i][j] for i in range(k) for j in range(k)]
    outputs = [q, flat_J] if len(variant.function(name).outputs) > 1 else [q]
    return Result(outputs, guards)
