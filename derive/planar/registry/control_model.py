"""The functions of the control model: actuator coordinates (eq. 5), the actuator Jacobian and
its rate (eqs. 6, 9), the velocity map backwards, the actuator efforts, the task-space and the
forward dynamics (docs/control-model.md)."""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Argument, Component, FunctionSpec, Output
from rpr3gen_derive.planar import control
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.registry.arguments import (
    ACCELERATION,
    POSE,
    VELOCITY,
    actuator_argument,
    coordinate_unit,
    effort_argument,
    matrix_output,
    output_like,
    pose_checks,
    vector_output,
)
from rpr3gen_derive.planar.structures import Structure


def actuator_coordinates(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_coordinates``: ``qa`` of a pose, the inverse kinematics of eq. (5)."""
    prog = Program()
    values = sp.Matrix(control.actuator_values(prog, structure, "q"))
    qa = actuator_argument(structure)
    return FunctionSpec(
        name="actuator_coordinates",
        doc=f"Actuator coordinates qa ({qa.doc}) of the platform pose q, in each leg's working "
        "mode (eq. 5).",
        inputs=(POSE,),
        outputs=(output_like("qa", values, qa, qa.doc),),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def jacobian_output(
    structure: Structure, J: sp.Matrix, name: str = "J", hidden: bool = False
) -> Output:
    """The output ``J = d qa / d q`` (row-major, components ``J11`` ... ``J33``) of the matrix
    ``J``: :func:`actuator_jacobian`'s, and the forward kinematics' (named ``jacobian``,
    hidden)."""
    units = ("1/m", "1/m", "1") if structure.actuated_kind == "R" else ("1", "1", "m")
    qa_names = [c.name for c in actuator_argument(structure).components]
    return matrix_output(
        "J",
        J,
        units,
        "J = d qa / d q, row-major",
        lambda i, j: f"d {qa_names[i]} / d {POSE.components[j].name}",
        output=name,
        hidden=hidden,
    )


def actuator_jacobian(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_jacobian``: ``J = d qa / d q``, row-major, so that ``qa' = J q'``."""
    prog = Program()
    J = control.actuator_jacobian(prog, structure)
    return FunctionSpec(
        name="actuator_jacobian",
        doc="Actuator Jacobian J = d qa / d q (eq. 6 differentiated), row-major, one row per "
        "leg A, B, C: qa' = J q'. det J = 0 at a parallel singularity.",
        inputs=(POSE,),
        outputs=(jacobian_output(structure, J),),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def actuator_coordinates_jacobian(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_coordinates_jacobian``: ``qa`` and ``J = d qa / d q`` of a pose in one
    call (eqs. 5, 6), their common terms (the platform's rotation, each leg's geometry)
    evaluated once: the values of :func:`actuator_coordinates` and :func:`actuator_jacobian` to
    round-off (one common subexpression elimination over both may group a sum differently).
    The tracked forward kinematics' Newton evaluates both at every iterate with it."""
    prog = Program()
    values = sp.Matrix(control.actuator_values(prog, structure, "q"))
    J = control.actuator_jacobian(prog, structure)
    qa = actuator_argument(structure)
    return FunctionSpec(
        name="actuator_coordinates_jacobian",
        doc=f"Actuator coordinates qa ({qa.doc}) of the platform pose q (eq. 5) and the actuator "
        "Jacobian J = d qa / d q there (eq. 6 differentiated), row-major, in one call, their "
        "common terms evaluated once: actuator_coordinates' and actuator_jacobian's values to "
        "round-off.",
        inputs=(POSE,),
        outputs=(output_like("qa", values, qa, qa.doc), jacobian_output(structure, J)),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def hessian_output(structure: Structure, H: list[list[sp.Expr]]) -> Output:
    """The output ``H``: ``d2 qa_i / dq_j dq_k`` for ``j <= k`` (18 components ``H{i}{j}{k}``,
    1-based, row by row of ``qa``), the pairs of :data:`control.HESSIAN_PAIRS`."""
    qa_names = [c.name for c in actuator_argument(structure).components]
    q_names = [c.name for c in POSE.components]
    # the unit of qa over those of q_j and q_k (m, m, rad), by how many of j, k are phi
    units = ("1/m^2", "1/m", "1") if structure.actuated_kind == "R" else ("1/m", "1", "m")

    def unit(j: int, k: int) -> str:
        return units[(j == 2) + (k == 2)]

    return Output(
        "H",
        tuple(H[i][p] for i in range(3) for p in range(len(control.HESSIAN_PAIRS))),
        tuple(
            Component(
                f"H{i + 1}{j + 1}{k + 1}",
                unit(j, k),
                f"d2 {qa_names[i]} / d {q_names[j]} d {q_names[k]}",
            )
            for i in range(3)
            for j, k in control.HESSIAN_PAIRS
        ),
        "H = d2 qa / dq2, the pairs j <= k of each row i (H[i][k][j] = H[i][j][k])",
    )


def actuator_coordinates_hessian(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_coordinates_hessian``: ``qa``, ``J = d qa / d q`` and the second
    derivatives ``H = d2 qa / dq2`` of a pose in one call (eqs. 5, 6, 9), their common terms
    evaluated once. ``J' q' = H[q', q']``. The tracked forward kinematics' Newton evaluates it at
    its start, so that its third-order correction ``H[dq, dq]`` needs no other kernel."""
    prog = Program()
    values = sp.Matrix(control.actuator_values(prog, structure, "q"))
    J = control.actuator_jacobian(prog, structure)
    H = control.actuator_hessian(prog, structure)
    qa = actuator_argument(structure)
    return FunctionSpec(
        name="actuator_coordinates_hessian",
        doc=f"Actuator coordinates qa ({qa.doc}) of the platform pose q (eq. 5), the actuator "
        "Jacobian J = d qa / d q (eq. 6 differentiated, row-major) and the second derivatives "
        "H = d2 qa / dq2 there (eq. 9: J' q' = H[q', q']), in one call, their common terms "
        "evaluated once. H has 18 components, H{i}{j}{k} = d2 qa_i / dq_j dq_k for j <= k "
        "(11, 12, 13, 22, 23, 33 for each leg i).",
        inputs=(POSE,),
        outputs=(
            output_like("qa", values, qa, qa.doc),
            jacobian_output(structure, J),
            hessian_output(structure, H),
        ),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def jacobian_rate(structure: Structure) -> FunctionSpec:
    """``rpr3_jacobian_rate``: ``J' q'``, so that ``qa'' = J q'' + J' q'`` (eq. 9)."""
    prog = Program()
    rate = control.jacobian_rate_term(prog, structure)
    qa = actuator_argument(structure)
    return FunctionSpec(
        name="jacobian_rate",
        doc="J' q': the actuator accelerations at zero platform acceleration (eq. 9), so that "
        "qa'' = J q'' + J' q'.",
        inputs=(POSE, VELOCITY),
        outputs=(
            vector_output(
                "Jdqd",
                rate,
                tuple(f"dd{c.name}" for c in qa.components),
                (f"{coordinate_unit(structure)}/s^2",) * 3,
                "J' q'",
            ),
        ),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def platform_velocity(structure: Structure) -> FunctionSpec:
    """``rpr3_platform_velocity``: ``q' = J^-1 qa'``, the velocity map backwards."""
    prog = Program()
    qd = control.platform_velocity(prog, structure)
    qa = actuator_argument(structure)
    rates = Argument(
        "qa_dot",
        tuple(syms.qa_dot),
        tuple(Component(f"d{c.name}", f"{c.unit}/s", f"rate of {c.name}") for c in qa.components),
        "actuator rates",
    )
    return FunctionSpec(
        name="platform_velocity",
        doc="Platform velocity q' = J^-1 qa' from the actuator rates (a generated 3 x 3 solve by "
        "cofactors): the velocity a controller reconstructs from its encoders.",
        inputs=(POSE, rates),
        outputs=(output_like("qd", qd, VELOCITY, "platform velocity"),),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def actuator_efforts(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_efforts``: the actuator efforts alone of the inverse dynamics."""
    prog = Program()
    values = sp.Matrix(control.actuator_efforts(prog, structure))
    tau = effort_argument(structure)
    return FunctionSpec(
        name="actuator_efforts",
        doc=f"Actuator efforts ({tau.doc}) that produce the platform acceleration qdd at "
        "(q, qd): the inverse dynamics' actuator loads (eqs. 12-17) alone, which is also "
        "tau = J^-T (M qdd + c), the computed-torque law's efforts for a commanded qdd.",
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(output_like("tau", values, tau, "actuator efforts"),),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def task_space_dynamics(structure: Structure) -> FunctionSpec:
    """``rpr3_task_space_dynamics``: ``M`` (row-major) and ``c`` with ``M q'' + c = J^T tau``."""
    prog = Program()
    M, c = control.task_space_dynamics(prog, structure)
    return FunctionSpec(
        name="task_space_dynamics",
        doc="Dynamics in control form, M q'' + c = J^T tau, from the virtual work of the "
        "required wrenches of eqs. (10)-(17): M (row-major, symmetric positive definite) and c "
        "(Coriolis and centripetal terms, gravity, payload).",
        inputs=(POSE, VELOCITY),
        outputs=(
            matrix_output(
                "M",
                M,
                ("kg", "kg", "kg m", "kg", "kg", "kg m", "kg m", "kg m", "kg m^2"),
                "mass matrix in platform coordinates, row-major",
            ),
            vector_output("c", c, ("c_x", "c_y", "c_phi"), ("N", "N", "N m"), "bias forces"),
        ),
        program=prog,
        checks=pose_checks(prog, structure),
    )


def forward_dynamics(structure: Structure) -> FunctionSpec:
    """``rpr3_forward_dynamics``: ``q'' = M^-1 (J^T tau - c)``, by an LDL^T solve."""
    prog = Program()
    qdd = control.forward_dynamics(prog, structure)
    return FunctionSpec(
        name="forward_dynamics",
        doc="Forward dynamics: the platform acceleration q'' = M^-1 (J^T tau - c) under the "
        "actuator efforts tau, by an explicit LDL^T solve of the task-space dynamics.",
        inputs=(POSE, VELOCITY, effort_argument(structure)),
        outputs=(output_like("qdd", qdd, ACCELERATION, "platform acceleration"),),
        program=prog,
        checks=pose_checks(prog, structure),
    )
