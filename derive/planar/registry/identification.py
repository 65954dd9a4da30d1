"""The functions of dynamic identification: the regressor and the payload's efforts, with
``tau = Y pi + tau_payload`` (docs/identification.md)."""

from __future__ import annotations

from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Argument, Component, FunctionSpec, Output
from rpr3gen_derive.planar import identification, outputs
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.registry.arguments import (
    ACCELERATION,
    POSE,
    VELOCITY,
    effort_argument,
    output_like,
    pose_checks,
)
from rpr3gen_derive.planar.structures import Structure

#: Unit of each inertial quantity (docs/identification.md).
_PI_UNITS = {"m": "kg", "mcx": "kg m", "mcy": "kg m", "Jzz": "kg m^2"}
_QUANTITY = {"m": "mass", "mcx": "first moment x", "mcy": "first moment y", "Jzz": "inertia"}


def _y_unit(structure: Structure, quantity: str) -> str:
    """Unit of Y's entries: the effort's unit over the parameter's."""
    if structure.actuated_kind == "R":
        return {"m": "m^2/s^2", "mcx": "m/s^2", "mcy": "m/s^2", "Jzz": "1/s^2"}[quantity]
    return {"m": "m/s^2", "mcx": "1/s^2", "mcy": "1/s^2", "Jzz": "1/(m s^2)"}[quantity]


def _pi_component(structure: Structure, name: str) -> Component:
    """``mcx_2B`` -> unit and meaning (docs/identification.md)."""
    quantity, body = name.split("_")
    if structure.paper:
        bodies = {"1": "cylinder", "2": "piston", "3": "platform"}
    else:
        bodies = {"1": "body 1", "2": "body 2", "3": "platform"}
    leg = f" of leg {body[1]}" if len(body) > 1 else ""
    return Component(
        name, _PI_UNITS[quantity], f"{_QUANTITY[quantity]} of the {bodies[body[0]]}{leg}"
    )


def inertial_parameters(structure: Structure) -> Argument:
    """The inertial parameters pi, the columns of Y: C table ``rpr3_inertial_parameter_names``."""
    names = identification.INERTIAL_PARAMETER_NAMES
    return Argument(
        "pi",
        tuple(identification.pi_symbols[n] for n in names),
        tuple(_pi_component(structure, n) for n in names),
        "inertial parameters (per moving body: m, m cx, m cy, Jzz about its first joint point)",
        table="inertial_parameter_names",
    )


def regressor(structure: Structure) -> FunctionSpec:
    """``rpr3_regressor``: ``Y`` (3 x P, row-major) with ``tau = Y pi + tau_payload``."""
    prog = Program()
    checks = pose_checks(prog, structure)
    Y = identification.regressor(prog, structure)
    family = outputs.effort_family(structure)
    names = identification.INERTIAL_PARAMETER_NAMES
    return FunctionSpec(
        name="regressor",
        doc=f"Identification regressor Y (3 x {len(names)}, row-major; row i: {family} of leg "
        "A, B, C; column j: INERTIAL_PARAMETER_NAMES[j]) with tau = Y pi + tau_payload: the "
        "actuator efforts of eqs. (10)-(17) differentiated by the inertial parameters pi (per "
        "moving body m, m cx, m cy, Jzz about its first joint point; docs/identification.md).",
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "Y",
                tuple(Y[i, j] for i in range(3) for j in range(len(names))),
                tuple(
                    Component(
                        f"Y_{leg}__{name}",
                        _y_unit(structure, name.split("_")[0]),
                        f"d {family}_{leg} / d {name} ({_PI_UNITS[name.split('_')[0]]})",
                    )
                    for leg in LEGS
                    for name in names
                ),
                f"Y = d tau / d pi, row-major (3 x {len(names)}; columns: "
                "rpr3_inertial_parameter_names)",
            ),
        ),
        program=prog,
        checks=checks,
    )


def payload_efforts(structure: Structure) -> FunctionSpec:
    """``rpr3_payload_efforts``: the efforts that hold the payload wrench at rest."""
    prog = Program()
    checks = pose_checks(prog, structure)
    tau = identification.payload_efforts(prog, structure)
    arg = effort_argument(structure)
    return FunctionSpec(
        name="payload_efforts",
        doc="tau_payload: the actuator efforts holding the payload wrench (fx, fy at G, mz) at "
        "rest, the part of tau = Y pi + tau_payload that scales with no inertial parameter "
        "(eqs. 12-17 with only the payload acting); a function of the pose alone.",
        inputs=(POSE,),
        outputs=(output_like("tau_payload", tau, arg, "efforts holding the payload"),),
        program=prog,
        checks=checks,
    )
