"""The functions of the inverse dynamics: every joint load of a pose (eqs. 5-17), why a pose is
refused (each leg's reach, the conditioning) and where every joint is, for drawing the robot."""

from __future__ import annotations

from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Check, Component, FunctionSpec, Output
from rpr3gen_derive.planar import control, outputs
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.registry.arguments import (
    ACCELERATION,
    POSE,
    SINGULAR_POSE_CHECKS,
    VELOCITY,
    pose_checks,
)
from rpr3gen_derive.planar.structures import Structure


def inverse_dynamics(structure: Structure) -> FunctionSpec:
    """``rpr3_inverse_dynamics``: leg kinematics and every joint load (eqs. 5-17)."""
    derivation = control.inverse_dynamics(structure)
    family = outputs.effort_family(structure)
    doc = (
        f"Inverse dynamics of the {structure.title}: actuator efforts {family}_A, _B, _C. Leg "
        "kinematics (eqs. 5, 6, 9) and every joint load (eqs. 12-17) from the platform pose "
        "q = (x, y, phi), its velocity qd and acceleration qdd."
    )
    return FunctionSpec(
        name="inverse_dynamics",
        doc=doc,
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "out",
                tuple(derivation.outputs.values()),
                tuple(Component(*doc_) for doc_ in outputs.output_docs(structure)),
                "row k receives OUTPUT_NAMES[k] (loads: exerted by the earlier body on the later "
                "one); the rows of a singular pose hold inf or nan",
                table="output_names",
            ),
        ),
        program=derivation.program,
        checks=SINGULAR_POSE_CHECKS,
    )


def pose_diagnostics(structure: Structure) -> FunctionSpec:
    """``rpr3_pose_diagnostics``: why a pose is refused: each leg's reach and the conditioning."""
    prog = Program()
    derivation = control.include_inverse_dynamics(prog, structure)
    reaches = outputs.leg_reaches(structure, derivation.kinematics)
    what = (
        "(l0 + lambda21) / l0, 1 in the central configuration, <= 0 with the piston joint on or "
        "behind its base pivot"
        if structure.paper
        else "D / D(home), the leg's serial determinant against its value at home: 1 at home, "
        "0 at a serial singularity"
    )
    return FunctionSpec(
        name="pose_diagnostics",
        doc="Diagnostics of a pose, with no failure check (values may be NaN or below the "
        "floors): each leg's reach, " + what + " (NaN where the leg cannot reach the pose in "
        "its working mode), and the conditioning (0 at a parallel singularity).",
        inputs=(POSE,),
        outputs=(
            Output(
                "diagnostics",
                (*reaches, derivation.outputs["conditioning"]),
                (
                    *(Component(f"reach_{leg}", "1", f"leg {leg}'s reach") for leg in LEGS),
                    Component("conditioning", "1", "closeness to a parallel singularity"),
                ),
                "reach_A, reach_B, reach_C, conditioning",
            ),
        ),
        program=prog,
        checks=(Check("inputs_not_finite", "NOT_FINITE"),),
    )


def joint_points(structure: Structure) -> FunctionSpec:
    """``rpr3_joint_points``: where every joint of every leg is, for drawing the robot."""
    prog = Program()
    derivation = control.include_inverse_dynamics(prog, structure)
    values, components = [], []
    for leg in LEGS:
        kin = derivation.kinematics[leg]
        x3 = (syms.x + kin.s[0], syms.y + kin.s[1])
        arms = [kin.pose.world(arm) for arm in kin.pose.arms]
        points = (
            (x3[0] - arms[0][0], x3[1] - arms[0][1]),
            (x3[0] - arms[1][0], x3[1] - arms[1][1]),
            x3,
        )
        for j, point in enumerate(points, start=1):
            for axis, value in zip("xy", point, strict=True):
                values.append(value)
                components.append(
                    Component(
                        f"{axis}{j}_{leg}", "m", f"leg {leg}: joint {j}'s point, world {axis}0"
                    )
                )
    return FunctionSpec(
        name="joint_points",
        doc="The current points of joints 1, 2, 3 of legs A, B, C (world frame) at the platform "
        "pose q, each leg in its working mode (eq. 5): what a drawing of the robot needs.",
        inputs=(POSE,),
        outputs=(
            Output("points", tuple(values), tuple(components), "x1_A, y1_A, ..., x3_C, y3_C"),
        ),
        program=prog,
        checks=pose_checks(prog, structure),
    )
