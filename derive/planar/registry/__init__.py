"""The registry of generated functions: one spec builder per function, for any structure.

Each entry of :data:`FUNCTIONS` turns a :class:`~rpr3gen_derive.planar.structures.Structure` into a
:class:`~rpr3gen_derive.codegen.spec.FunctionSpec` (or None where a structure has no such
function); :func:`module` gathers them, with the parameter vector, return codes and thresholds
they share, into the :class:`~rpr3gen_derive.codegen.spec.ModuleSpec` of one variant (one
folder of generated code). Adding a generated function is adding an entry here.

The builders live by concept: :mod:`.arguments` (the inputs, outputs and checks they share),
:mod:`.dynamics` (the inverse dynamics), :mod:`.control_model`, :mod:`.direct_kinematics` and
:mod:`.identification`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from functools import cache

from rpr3gen_derive.codegen.spec import FunctionSpec, ModuleSpec, ReturnCode, Threshold
from rpr3gen_derive.planar import control
from rpr3gen_derive.planar import direct_kinematics as dk
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.registry.arguments import params_argument
from rpr3gen_derive.planar.registry.control_model import (
    actuator_coordinates,
    actuator_coordinates_hessian,
    actuator_coordinates_jacobian,
    actuator_efforts,
    actuator_jacobian,
    forward_dynamics,
    jacobian_rate,
    platform_velocity,
    task_space_dynamics,
)
from rpr3gen_derive.planar.registry.derivatives import (
    forward_dynamics_derivatives,
    inverse_dynamics_derivatives,
)
from rpr3gen_derive.planar.registry.direct_kinematics import (
    assembly_modes,
    fk_kind,
    forward_kinematics,
    forward_kinematics_jacobian,
    locked_circles,
    pose_from_angle,
)
from rpr3gen_derive.planar.registry.dynamics import (
    inverse_dynamics,
    joint_points,
    pose_diagnostics,
)
from rpr3gen_derive.planar.registry.identification import (
    inertial_parameters,
    payload_efforts,
    regressor,
)
from rpr3gen_derive.planar.structures import Structure

PREFIX = "rpr3"

RETURN_CODES: tuple[ReturnCode, ...] = (
    ReturnCode("OK", 0, "success"),
    ReturnCode("NOT_FINITE", 1, "an input is NaN or infinite"),
    ReturnCode(
        "SINGULAR",
        2,
        "singular or degenerate pose: a serial singularity of a leg or a pose outside its "
        "reach (reach below MIN_REACH), conditioning below MIN_CONDITIONING, or a result that "
        "would not be finite",
    ),
    ReturnCode("NO_MODE", 3, "no assembly mode for these actuator coordinates"),
)


def thresholds(structure: Structure) -> tuple[Threshold, ...]:
    """The failure thresholds of a variant (their meaning of ``reach`` differs by format)."""
    reach = (
        'Output "reach" (min over legs of |A1A2| / l0; 1 in the central configuration) under '
        "which a pose is refused: a piston joint on or behind its base pivot, which also keeps "
        "every leg clear of the serial singularity |A1A3| = 0."
        if structure.paper
        else 'Output "reach" (min over legs of D / D(home), D the leg\'s serial determinant; 1 '
        "at home) under which a pose is refused: a leg at or near a serial singularity."
    )
    return (
        Threshold("MIN_REACH", "1e-9", reach),
        Threshold(
            "MIN_CONDITIONING",
            "1e-9",
            'Output "conditioning" (0 at a parallel singularity, 1 at best) under which a pose '
            "counts as singular: the loads there are dominated by round-off. Applications "
            "usually want a larger margin of their own (rpr3gen simulate refuses poses under "
            "1e-3 by default).",
        ),
    )


FunctionBuilder = Callable[[Structure], FunctionSpec | None]

#: Every generated function, by name: a builder from the structure to its spec. A builder may
#: return None for a structure that has no such function.
FUNCTIONS: Mapping[str, FunctionBuilder] = {
    "inverse_dynamics": inverse_dynamics,
    "actuator_coordinates": actuator_coordinates,
    "pose_diagnostics": pose_diagnostics,
    "joint_points": joint_points,
    "actuator_jacobian": actuator_jacobian,
    "actuator_coordinates_jacobian": actuator_coordinates_jacobian,
    "actuator_coordinates_hessian": actuator_coordinates_hessian,
    "jacobian_rate": jacobian_rate,
    "platform_velocity": platform_velocity,
    "actuator_efforts": actuator_efforts,
    "task_space_dynamics": task_space_dynamics,
    "forward_dynamics": forward_dynamics,
    "assembly_modes": assembly_modes,
    "pose_from_angle": pose_from_angle,
    "locked_circles": locked_circles,
    "forward_kinematics": forward_kinematics,
    "forward_kinematics_jacobian": forward_kinematics_jacobian,
    "regressor": regressor,
    "payload_efforts": payload_efforts,
    "inverse_dynamics_derivatives": inverse_dynamics_derivatives,
    "forward_dynamics_derivatives": forward_dynamics_derivatives,
}


@cache
def _spec(builder: FunctionBuilder, structure: Structure) -> FunctionSpec | None:
    return builder(structure)


def clear_cache() -> None:
    """Forget the specs derived so far (they are derived once per process otherwise)."""
    _spec.cache_clear()
    control.inverse_dynamics.cache_clear()


def module(
    structure: Structure, functions: Mapping[str, FunctionBuilder] | None = None
) -> ModuleSpec:
    """The generated module of one structure: every function of ``functions``."""
    if structure.singular:
        raise ValueError(
            f"{structure.title}: every motor measures only the platform's angle; the platform's "
            "translation is not controlled (architecturally singular), so nothing is generated"
        )
    functions = FUNCTIONS if functions is None else functions
    defines = [
        ("LEG", f'"{structure.kinds}"', "joint types of every leg, base to platform"),
        ("ACTUATED", str(structure.actuated), "the joint of every leg that carries its motor"),
        ("FK_KIND", f'"{fk_kind(structure)}"', "how a locked leg holds the platform"),
        (
            "MAX_MODES",
            str(dk.MAX_MODES[fk_kind(structure)]),
            "most assembly modes of one qa",
        ),
    ]
    if structure.paper:
        defines.insert(0, ("ACTUATION", f'"{structure.variant}"', ""))
    model = "the paper's parameters" if structure.paper else "the general model file's parameters"
    return ModuleSpec(
        prefix=PREFIX,
        variant=structure.variant,
        doc=(
            f"Generated functions of the {structure.title} planar parallel robot, in {model}. "
            "Model numbers are inputs (params), so one build serves every robot of this "
            "structure."
        ),
        params=params_argument(structure),
        functions=tuple(
            spec
            for builder in functions.values()
            if (spec := _spec(builder, structure)) is not None
        ),
        return_codes=RETURN_CODES,
        thresholds=thresholds(structure),
        tables=(inertial_parameters(structure),),
        defines=tuple(defines),
        legs="".join(LEGS),
    )
