"""The registry of a spatial variant's generated functions: one spec builder per function.

Each entry of :data:`FUNCTIONS` turns a :class:`~.structures.SpatialStructure` into a
:class:`~rpr3gen_derive.codegen.spec.FunctionSpec`; :func:`module` gathers them with the
parameter vector, the return codes and the thresholds into the variant's
:class:`~rpr3gen_derive.codegen.spec.ModuleSpec`. The return codes, thresholds and C ABI are the
planar variants' (docs/interfaces.md), with ``q`` of 6 or 3 components.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import sympy as sp
from rpr3gen_derive.codegen import derivatives
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import (
    Argument,
    Check,
    Component,
    FunctionSpec,
    ModuleSpec,
    Output,
    ReturnCode,
    Threshold,
)
from rpr3gen_derive.spatial import virtual_work
from rpr3gen_derive.spatial.arguments import (
    c_context,
    checks,
    derivation,
    efforts,
    params_argument,
    pose_arguments,
    unit,
)
from rpr3gen_derive.spatial.regressor import inertial_parameters, regressor
from rpr3gen_derive.spatial.structures import SpatialStructure, param_names

PREFIX = "rpr3"

RETURN_CODES: tuple[ReturnCode, ...] = (
    ReturnCode("OK", 0, "success"),
    ReturnCode("NOT_FINITE", 1, "an input is NaN or infinite"),
    ReturnCode(
        "SINGULAR",
        2,
        "singular or degenerate pose: a leg at or near a serial singularity or out of reach "
        "(reach below MIN_REACH), conditioning below MIN_CONDITIONING, or a result that would "
        "not be finite",
    ),
    ReturnCode("NO_MODE", 3, "no assembly mode for these actuator coordinates"),
)

THRESHOLDS: tuple[Threshold, ...] = (
    Threshold(
        "MIN_REACH",
        "1e-9",
        "min over legs of the reach (UPS: the leg's length over its home length; the others: "
        "D / D(home), D = (S - E) . dE/dq1 the leg's serial determinant; 1 at home) under "
        "which a pose is refused: a leg at or near a serial singularity.",
    ),
    Threshold(
        "MIN_CONDITIONING",
        "1e-9",
        'Output "conditioning" (0 at a parallel singularity, 1 at best) under which a pose '
        "counts as singular.",
    ),
)


def inverse_dynamics(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_inverse_dynamics``: leg kinematics and every joint load of a spatial robot."""
    d = derivation(structure)
    return FunctionSpec(
        name="inverse_dynamics",
        doc=f"Inverse dynamics of the {structure.title}: every joint's coordinates and load "
        "(the wrench the earlier body exerts on the later, world axes, moments about the "
        "joint's point) and the actuator efforts tau, from the platform pose q, its rates qd "
        "and accelerations qdd (docs/spatial-robots.md).",
        inputs=pose_arguments(structure),
        outputs=(
            Output(
                "out",
                tuple(d.outputs.values()),
                tuple(Component(n, *unit(n, structure)) for n in d.outputs),
                "row k receives OUTPUT_NAMES[k]",
                table="output_names",
            ),
        ),
        program=d.program,
        checks=checks(d),
    )


def actuator_coordinates(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_actuator_coordinates``: the actuated joints' coordinates of a pose."""
    d = derivation(structure)
    q = pose_arguments(structure)[0]
    unit = "rad" if structure.actuated_kind == "R" else "m"
    family = f"q{structure.actuated}"
    return FunctionSpec(
        name="actuator_coordinates",
        doc=f"Actuator coordinates qa ({family} of every leg) of the platform pose q, each leg "
        "in its working mode.",
        inputs=(q,),
        outputs=(
            Output(
                "qa",
                d.actuators,
                tuple(Component(f"{family}_{leg}", unit, f"leg {leg}") for leg in structure.legs),
                f"actuator coordinates ({family} of legs {', '.join(structure.legs)})",
            ),
        ),
        program=d.program,
        checks=checks(d),
    )


def pose_diagnostics(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_pose_diagnostics``: each leg's reach and the conditioning, with no check."""
    d = derivation(structure)
    q = pose_arguments(structure)[0]
    return FunctionSpec(
        name="pose_diagnostics",
        doc="Diagnostics of a pose, with no failure check: each leg's reach (1 at home, 0 at "
        "a serial singularity; NaN out of reach) and the conditioning (0 at a parallel "
        "singularity).",
        inputs=(q,),
        outputs=(
            Output(
                "diagnostics",
                (*d.reaches, d.outputs["conditioning"]),
                (
                    *(
                        Component(f"reach_{leg}", "1", f"leg {leg}'s reach")
                        for leg in structure.legs
                    ),
                    Component("conditioning", "1", "closeness to a parallel singularity"),
                ),
                "reach of every leg, then conditioning",
            ),
        ),
        program=d.program,
        checks=(Check("inputs_not_finite", "NOT_FINITE"),),
    )


def _qa(structure: SpatialStructure, d: virtual_work.InverseDynamics) -> Output:
    unit = "rad" if structure.actuated_kind == "R" else "m"
    family = f"q{structure.actuated}"
    return Output(
        "qa",
        d.actuators,
        tuple(Component(f"{family}_{leg}", unit, f"leg {leg}") for leg in structure.legs),
        f"actuator coordinates ({family} of legs {', '.join(structure.legs)})",
    )


def _matrix(name: str, m: sp.Matrix, rows: list[str], cols: list[str], doc: str) -> Output:
    return Output(
        name,
        tuple(m[i, j] for i in range(m.rows) for j in range(m.cols)),
        tuple(
            Component(f"{name}{i + 1}{j + 1}", "", f"d {rows[i]} / d {cols[j]}")
            for i in range(m.rows)
            for j in range(m.cols)
        ),
        doc,
    )


def _qa_names(structure: SpatialStructure) -> list[str]:
    return [f"q{structure.actuated}_{leg}" for leg in structure.legs]


def actuator_jacobian(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_actuator_jacobian``: ``J = d qa / d q``, row-major (one row per leg)."""
    d = derivation(structure)
    return FunctionSpec(
        name="actuator_jacobian",
        doc="Actuator Jacobian J = d qa / d q, row-major, one row per leg: qa' = J q'. det J = 0 "
        "at a parallel singularity.",
        inputs=(pose_arguments(structure)[0],),
        outputs=(
            _matrix(
                "J",
                d.jacobian,
                _qa_names(structure),
                list(structure.pose),
                "J = d qa / d q, row-major",
            ),
        ),
        program=d.program,
        checks=checks(d),
    )


def actuator_coordinates_jacobian(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_actuator_coordinates_jacobian``: ``qa`` and ``J`` in one call."""
    d = derivation(structure)
    return FunctionSpec(
        name="actuator_coordinates_jacobian",
        doc="Actuator coordinates qa of the pose q and the actuator Jacobian J = d qa / d q "
        "there (row-major), in one call: what the forward kinematics' Newton evaluates.",
        inputs=(pose_arguments(structure)[0],),
        outputs=(
            _qa(structure, d),
            _matrix(
                "J",
                d.jacobian,
                _qa_names(structure),
                list(structure.pose),
                "J = d qa / d q, row-major",
            ),
        ),
        program=d.program,
        checks=checks(d),
    )


def actuator_efforts(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_actuator_efforts``: the efforts alone of the inverse dynamics (C: its kernel)."""
    tau = efforts(structure)
    return FunctionSpec(
        name="actuator_efforts",
        doc="Actuator efforts tau that produce the platform acceleration qdd at (q, qd): the "
        "inverse dynamics' efforts alone (the computed-torque law's efforts for a commanded "
        "qdd).",
        inputs=pose_arguments(structure),
        outputs=(
            Output(
                "tau", (sp.Integer(0),) * len(structure.legs), tau.components, "actuator efforts"
            ),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "SINGULAR")),
        c_body="spatial_efforts.c.jinja",
        c_context=c_context(structure),
    )


def efforts_matrix(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_efforts_matrix``: ``T = d tau / d q''`` (row-major) and ``tau0``, the efforts at
    ``q'' = 0``, in one pass over the efforts' program
    (:func:`rpr3gen_derive.codegen.derivatives.efforts_matrix`)."""
    return derivatives.efforts_matrix(_efforts_program(structure))


def task_space_dynamics(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_task_space_dynamics``: ``M`` (row-major) and ``c``, ``M q'' + c = J^T tau``.

    The efforts are affine in the acceleration, ``tau = T q'' + tau0``, both parts from
    :func:`efforts_matrix`' kernel; ``M = J^T T``, ``c = J^T tau0``
    (``templates/spatial_task_space.c.jinja``; the runtime composes the same in NumPy).
    """
    names = list(structure.pose)
    k = structure.dof
    return FunctionSpec(
        name="task_space_dynamics",
        doc="Dynamics in control form, M q'' + c = J^T tau in the pose's coordinates: M "
        "(row-major, symmetric positive definite) and c (Coriolis and centripetal terms, "
        "gravity, payload), from the efforts' split tau = T q'' + tau0 (efforts_matrix).",
        inputs=pose_arguments(structure)[:2],
        outputs=(
            _matrix(
                "M", sp.zeros(k, k), names, [f"dd{n}" for n in names], "mass matrix, row-major"
            ),
            Output(
                "c",
                (sp.Integer(0),) * k,
                tuple(Component(f"c_{n}", "", f"bias along {n}") for n in names),
                "bias forces",
            ),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "SINGULAR")),
        c_body="spatial_task_space.c.jinja",
        c_context=(("k", k), ("forward", False)),
    )


def forward_dynamics(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_forward_dynamics``: ``q''`` under the efforts ``tau``: ``T q'' = tau - tau0``
    (:func:`efforts_matrix`' terms), by Gaussian elimination with partial pivoting."""
    tau = efforts(structure)
    acc = pose_arguments(structure)[2]
    return FunctionSpec(
        name="forward_dynamics",
        doc="Forward dynamics: the platform acceleration q'' = M^-1 (J^T tau - c) under the "
        "actuator efforts tau, solved as T q'' = tau - tau0 (the inverse dynamics' efforts are "
        "tau = T q'' + tau0).",
        inputs=(*pose_arguments(structure)[:2], tau),
        outputs=(
            Output(
                "qdd", (sp.Integer(0),) * structure.dof, acc.components, "platform acceleration"
            ),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "SINGULAR")),
        c_body="spatial_task_space.c.jinja",
        c_context=(("k", structure.dof), ("forward", True)),
    )


def payload_efforts(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_payload_efforts``: the efforts holding the payload wrench at rest, no gravity:
    the inverse dynamics at ``(q, 0, 0)`` with the gravity zeroed (what no inertial parameter
    scales; ``templates/spatial_payload.c.jinja``)."""
    params = param_names(structure)
    context = dict(c_context(structure))
    unit = "N m" if structure.actuated_kind == "R" else "N"
    return FunctionSpec(
        name="payload_efforts",
        doc="The actuator efforts holding the model's payload wrench at rest, without gravity: "
        "the inverse dynamics at (q, 0, 0) with gravity zeroed.",
        inputs=(pose_arguments(structure)[0],),
        outputs=(
            Output(
                "tau_payload",
                (sp.Integer(0),) * len(structure.legs),
                tuple(
                    Component(f"tau_{leg}", unit, f"payload effort, leg {leg}")
                    for leg in structure.legs
                ),
                "payload efforts",
            ),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "SINGULAR")),
        c_body="spatial_payload.c.jinja",
        c_context=(
            ("k", structure.dof),
            ("outputs", context["outputs"]),
            ("tau", context["tau"]),
            ("gravity", [params.index(n) for n in ("gx", "gy", "gz")]),
            ("params", len(params)),
        ),
    )


#: Unit and meaning of each inertial quantity (docs/spatial-robots.md, "Identification").
FK_TUNING: tuple[tuple[str, object], ...] = (("max_iter", 30), ("max_halvings", 30),
                                             ("tol", "1e-12"))  # fmt: skip


def forward_kinematics(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_forward_kinematics``: the pose of the actuator coordinates ``qa`` that Newton
    reaches from the reference pose ``q_near`` (``templates/spatial_forward_kinematics.c.jinja``;
    the runtime's NumPy version is the same iteration)."""
    q = pose_arguments(structure)[0]
    d = derivation(structure)
    qa = _qa(structure, d)
    qa_arg = Argument(
        "qa",
        tuple(sp.Symbol(f"qa_{leg}", real=True) for leg in structure.legs),
        qa.components,
        qa.doc,
    )
    near = Argument(
        "q_near",
        tuple(sp.Symbol(f"{c.name}_near", real=True) for c in q.components),
        q.components,
        "the reference pose: the previous solution, or a prediction from the last two",
    )
    return FunctionSpec(
        name="forward_kinematics",
        doc="Tracked forward kinematics: the pose q with actuator coordinates qa, found by "
        "Newton from the reference pose q_near (the step halved until the largest residual "
        "decreases, at most 30 steps, converged at 1e-12 rad or m); NO_MODE when it does not "
        "converge.",
        inputs=(qa_arg, near),
        outputs=(Output("q", (sp.Integer(0),) * structure.dof, q.components, "the pose found"),),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "NO_MODE")),
        c_body="spatial_forward_kinematics.c.jinja",
        c_kernels=("rint",) if structure.actuated_kind == "R" else (),
        c_context=(("k", structure.dof), ("wrap", structure.actuated_kind == "R"), *FK_TUNING),
    )


def _efforts_program(structure: SpatialStructure) -> FunctionSpec:
    """The efforts alone as a program (not generated: the source of their derivatives)."""
    d = derivation(structure)
    tau = efforts(structure)
    return FunctionSpec(
        name="efforts_program",
        doc="the inverse dynamics' efforts",
        inputs=pose_arguments(structure),
        outputs=(
            Output(
                "tau",
                tuple(d.outputs[c.name] for c in tau.components),
                tau.components,
                "actuator efforts",
            ),
        ),
        program=d.program,
        checks=checks(d),
    )


def inverse_dynamics_derivatives(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_inverse_dynamics_derivatives``: ``tau`` and ``d tau / d(q, qd, qdd)``, by
    reverse mode through the efforts' program (:mod:`rpr3gen_derive.codegen.derivatives`)."""
    return derivatives.inverse_dynamics_derivatives(_efforts_program(structure))


def forward_dynamics_derivatives(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_forward_dynamics_derivatives``: ``qdd`` and ``d qdd / d(q, qd, tau)``."""
    return derivatives.forward_dynamics_derivatives(
        forward_dynamics(structure), _efforts_program(structure)
    )


FunctionBuilder = Callable[[SpatialStructure], FunctionSpec | None]

FUNCTIONS: Mapping[str, FunctionBuilder] = {
    "inverse_dynamics": inverse_dynamics,
    "actuator_coordinates": actuator_coordinates,
    "pose_diagnostics": pose_diagnostics,
    "actuator_jacobian": actuator_jacobian,
    "actuator_coordinates_jacobian": actuator_coordinates_jacobian,
    "actuator_efforts": actuator_efforts,
    "efforts_matrix": efforts_matrix,
    "task_space_dynamics": task_space_dynamics,
    "forward_dynamics": forward_dynamics,
    "forward_kinematics": forward_kinematics,
    "payload_efforts": payload_efforts,
    "regressor": regressor,
    "inverse_dynamics_derivatives": inverse_dynamics_derivatives,
    "forward_dynamics_derivatives": forward_dynamics_derivatives,
}


def module(
    structure: SpatialStructure, functions: Mapping[str, FunctionBuilder] | None = None
) -> ModuleSpec:
    """The generated module of one spatial structure."""
    functions = FUNCTIONS if functions is None else functions
    return ModuleSpec(
        prefix=PREFIX,
        variant=structure.variant,
        doc=f"Generated functions of the {structure.title} spatial parallel robot, in the "
        "model file's parameters. Model numbers are inputs (params), so one build serves every "
        "robot of this structure.",
        params=params_argument(structure),
        functions=tuple(spec for b in functions.values() if (spec := b(structure)) is not None),
        return_codes=RETURN_CODES,
        thresholds=THRESHOLDS,
        tables=(inertial_parameters(structure),),
        defines=(
            ("LEG", f'"{structure.kinds}"', "leg type, base to platform"),
            ("ACTUATED", str(structure.actuated), "the joint of every leg that carries its motor"),
            ("NUM_LEGS", str(len(structure.legs)), "legs"),
            ("DOF", str(structure.dof), "the platform's degrees of freedom (size of q)"),
        ),
        legs=structure.legs,
    )


def clear_cache() -> None:
    """Forget the derivations made so far (they are made once per process otherwise)."""
    derivation.cache_clear()


__all__ = ["FUNCTIONS", "Program", "module"]
