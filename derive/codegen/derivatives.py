"""The derivatives of the dynamics, for any robot: function specs built from its efforts' spec.

``inverse_dynamics_derivatives``: ``d tau / d(q, q', q'')`` by reverse mode through the efforts'
own program (:mod:`.adjoint`): exact, one adjoint lane per actuator.

``forward_dynamics_derivatives``: with ``T = d tau / d q''`` (the efforts are affine in ``q''``)
and the forward dynamics' ``q''``, ``tau_ID(q, q', q''(q, q', tau)) = tau`` gives ``d q''/d q =
-T^-1 d tau/d q``, ``d q''/d q' = -T^-1 d tau/d q'`` and ``d q''/d tau = T^-1``. A C body
(``templates/dynamics_derivatives.c.jinja``) calls the forward dynamics (the main unit's public
function), then the inverse dynamics derivatives' kernel at that ``q''``, and solves ``T X =
[-d tau/d q, -d tau/d q', I]`` by Gaussian elimination with partial pivoting; the runtime
composes the same in NumPy.

``efforts_matrix``: ``T = d tau / d q''`` and ``tau0``, the efforts at ``q'' = 0``, in one pass
over the efforts' program (:mod:`.tangent`: the statements that read ``q''`` with one tangent
per acceleration, the others once): the forward dynamics' and the control form's kernel, in the
variant's main C unit.

The derivatives are in the C translation unit ``derivatives`` (:data:`UNIT`), with a header of
their own, compiled apart and only when first called: they are several times the inverse
dynamics' size.
The runtime's cache derives them apart too, when one is first called (:data:`NAMES`).
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.adjoint import reverse_mode
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Argument, Check, Component, FunctionSpec, Output
from rpr3gen_derive.codegen.tangent import affine_parts

#: The derivative functions, in the registries' order: a variant's derivation leaves them out
#: when the runtime's cache asks it to (:attr:`ModuleSpec.deferred`), for a first use of one.
NAMES = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives")
#: The C translation unit of the derivatives (:attr:`FunctionSpec.unit`): compiled apart, on
#: first use.
UNIT = "derivatives"
#: The C body of ``forward_dynamics_derivatives`` (found in the engine's template folder).
FORWARD_BODY = "templates/dynamics_derivatives.c.jinja"


def _block(
    name: str, rows: Argument, cols: Argument, exprs: list[list[sp.Expr]] | None, doc: str
) -> Output:
    """A ``k x k`` row-major block ``d rows / d cols``."""
    k, m = len(rows.components), len(cols.components)
    values = (
        tuple(exprs[i][j] for i in range(k) for j in range(m))
        if exprs is not None
        else (sp.Integer(0),) * (k * m)
    )
    return Output(
        name,
        values,
        tuple(
            Component(
                f"d{r.name}_d{c.name}",
                _ratio(r.unit, c.unit),
                f"d {r.name} / d {c.name}",
            )
            for r in rows.components
            for c in cols.components
        ),
        f"{doc}, row-major ({k} x {m}; row: output, column: input)",
    )


def _ratio(top: str, bottom: str) -> str:
    if not bottom or bottom == "1":
        return top
    return f"{top} / ({bottom})" if " " in bottom else f"{top} / {bottom}"


def _guard_checks(source: FunctionSpec, values: dict[sp.Expr, sp.Expr]) -> tuple[Check, ...]:
    """``source``'s checks, their guards' expressions replaced by ``values``."""
    guards: dict[str, sp.Expr] = {}
    for output in source.outputs:
        if output.name == "guards":
            guards = {c.name: e for c, e in zip(output.components, output.exprs, strict=True)}
    out = []
    for c in source.checks:
        if c.output == "guards":
            guard = (str(c.component), values[guards[str(c.component)]])
            out.append(Check(c.kind, c.code, threshold=c.threshold, guard=guard))
        else:
            out.append(Check(c.kind, c.code, c.output, c.component, c.threshold))
    return tuple(out)


def _guards(spec: FunctionSpec) -> list[sp.Expr]:
    """The expressions of ``spec``'s hidden output ``guards`` (none: empty)."""
    return [e for o in spec.outputs if o.name == "guards" for e in o.exprs]


def inverse_dynamics_derivatives(efforts: FunctionSpec) -> FunctionSpec:
    """``{prefix}_inverse_dynamics_derivatives``: the efforts of ``efforts`` (a function of
    ``q, qd, qdd`` with one output, the efforts, computed by its program) and their Jacobians by
    ``q``, ``qd`` and ``qdd``, with ``efforts``' checks."""
    q, qd, qdd = efforts.inputs
    tau = efforts.public_outputs[0]
    guard_exprs = _guards(efforts)
    wrt = [*q.symbols, *qd.symbols, *qdd.symbols]
    prog, values, jacobian = reverse_mode(
        efforts.program, list(tau.exprs), wrt, extra=guard_exprs, prefix="d"
    )
    k, n = len(tau.exprs), len(q.symbols)
    renamed = dict(zip(guard_exprs, values[k:], strict=True))
    tau_arg = Argument(
        tau.name, tuple(sp.Symbol(c.name) for c in tau.components), tau.components, tau.doc
    )
    blocks = [[row[j * n : (j + 1) * n] for row in jacobian] for j in range(3)]
    return FunctionSpec(
        name="inverse_dynamics_derivatives",
        doc="The actuator efforts tau of the inverse dynamics and their exact derivatives by the "
        "pose q, its rates qd and accelerations qdd (reverse mode through the efforts' own "
        "program: one adjoint per actuator); d tau / d qdd is T, with tau = T qdd + tau0.",
        inputs=efforts.inputs,
        outputs=(
            Output(tau.name, tuple(values[:k]), tau.components, tau.doc),
            _block("dtau_dq", tau_arg, q, blocks[0], "d tau / d q"),
            _block("dtau_dqd", tau_arg, qd, blocks[1], "d tau / d qd"),
            _block("dtau_dqdd", tau_arg, qdd, blocks[2], "d tau / d qdd"),
        ),
        program=prog,
        checks=_guard_checks(efforts, renamed),
        unit=UNIT,
        straight=True,
    )


def efforts_matrix(efforts: FunctionSpec) -> FunctionSpec:
    """``{prefix}_efforts_matrix``: the efforts of ``efforts`` (a function of ``q, qd, qdd``
    with one output, the efforts, computed by its program) split as ``tau = T qdd + tau0``:
    ``T = d tau / d qdd`` (row-major) and ``tau0`` (the efforts at ``qdd = 0``), from ``q`` and
    ``qd`` in one pass (:func:`.tangent.affine_parts`), with ``efforts``' checks."""
    q, qd, qdd = efforts.inputs
    tau = efforts.public_outputs[0]
    guard_exprs = _guards(efforts)
    prog, values, jacobian = affine_parts(
        efforts.program, list(tau.exprs), list(qdd.symbols), extra=guard_exprs
    )
    k = len(tau.exprs)
    renamed = dict(zip(guard_exprs, values[k:], strict=True))
    tau_arg = Argument(
        tau.name, tuple(sp.Symbol(c.name) for c in tau.components), tau.components, tau.doc
    )
    return FunctionSpec(
        name="efforts_matrix",
        doc="The inverse dynamics' efforts split as tau = T qdd + tau0 (they are affine in the "
        "accelerations): T = d tau / d qdd and tau0, the efforts at qdd = 0, from the pose q "
        "and its rates qd in one pass (the statements that read qdd differentiated by it, the "
        "kinematics shared).",
        inputs=(q, qd),
        outputs=(
            _block("T", tau_arg, qdd, jacobian, "T = d tau / d qdd"),
            Output(
                "tau0",
                tuple(values[:k]),
                tuple(
                    Component(f"{c.name}_0", c.unit, f"{c.meaning} at qdd = 0")
                    for c in tau.components
                ),
                "the efforts at qdd = 0",
            ),
        ),
        program=prog,
        checks=_guard_checks(efforts, renamed),
    )


def forward_dynamics_derivatives(forward: FunctionSpec, efforts: FunctionSpec) -> FunctionSpec:
    """``{prefix}_forward_dynamics_derivatives``: ``q''`` of ``forward`` (``q, qd, tau ->
    qdd``) and its Jacobians by ``q``, ``qd`` and ``tau``, from the inverse dynamics
    derivatives (:func:`inverse_dynamics_derivatives` of ``efforts``) at that ``q''``."""
    q, qd, tau = forward.inputs
    qdd = forward.public_outputs[0]
    qdd_arg = Argument(
        qdd.name, tuple(sp.Symbol(c.name) for c in qdd.components), qdd.components, qdd.doc
    )
    k = len(q.symbols)
    return FunctionSpec(
        name="forward_dynamics_derivatives",
        doc="The platform acceleration qdd of the forward dynamics and its exact derivatives by "
        "q, qd and the efforts tau: with T = d tau / d qdd of the inverse dynamics at that qdd, "
        "d qdd / d q = -T^-1 d tau / d q, d qdd / d qd = -T^-1 d tau / d qd, d qdd / d tau = "
        "T^-1 (Gaussian elimination with partial pivoting).",
        inputs=forward.inputs,
        outputs=(
            Output(qdd.name, (sp.Integer(0),) * k, qdd.components, qdd.doc),
            _block("dqdd_dq", qdd_arg, q, None, "d qdd / d q"),
            _block("dqdd_dqd", qdd_arg, qd, None, "d qdd / d qd"),
            _block("dqdd_dtau", qdd_arg, tau, None, "d qdd / d tau"),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "SINGULAR")),
        c_body=FORWARD_BODY,
        unit=UNIT,
        c_context=(
            ("k", k),
            ("derivative_guards", len(_guards(efforts))),
        ),
    )
