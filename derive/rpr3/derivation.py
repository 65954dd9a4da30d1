"""The inverse dynamics of the paper, eqs. (1)-(17), as one program: the derivation itself.

:func:`derive` runs the paper's algorithm symbolically (frames, leg kinematics, inertia wrenches
and their recursion, virtual work); the names, units and meanings of its outputs and of the model
parameters (docs/conventions.md, docs/interfaces.md) are here too.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3.dynamics import LegWrenches, leg_wrenches
from rpr3gen_derive.rpr3.kinematics import (
    LegKinematics,
    leg_kinematics,
    platform_rotation,
    reach,
)
from rpr3gen_derive.rpr3.symbols import LEGS, PARAM_NAMES
from rpr3gen_derive.rpr3.virtual_work import joint_loads

ACTUATIONS: tuple[str, ...] = ("revolute", "prismatic")


@dataclass(frozen=True)
class OutputFamily:
    """One output of docs/conventions.md, for each of the three legs."""

    name: str
    unit: str
    meaning: str


OUTPUT_FAMILIES: tuple[OutputFamily, ...] = (
    OutputFamily("phi10", "rad", "cylinder rotation about z0 from the central configuration"),
    OutputFamily("lambda21", "m", "piston displacement from the central configuration"),
    OutputFamily("phi32", "rad", "platform rotation relative to the leg, phi - phi10"),
    OutputFamily("omega10", "rad/s", "d(phi10)/dt"),
    OutputFamily("v21", "m/s", "d(lambda21)/dt"),
    OutputFamily("omega32", "rad/s", "d(phi32)/dt"),
    OutputFamily("eps10", "rad/s^2", "d2(phi10)/dt2"),
    OutputFamily("gamma21", "m/s^2", "d2(lambda21)/dt2"),
    OutputFamily("eps32", "rad/s^2", "d2(phi32)/dt2"),
    OutputFamily("m10", "N m", "torque of the base on the cylinder at A1 about +z0 (motor)"),
    OutputFamily("f10x", "N", "force of the base on the cylinder at A1, along x0"),
    OutputFamily("f10y", "N", "force of the base on the cylinder at A1, along y0"),
    OutputFamily("f21y", "N", "force of the cylinder on the piston, along y2 = n"),
    OutputFamily("f21z", "N", "force of the cylinder on the piston, along z2 = e (actuator)"),
    OutputFamily("m21", "N m", "moment of the cylinder on the piston about A2, along x2 = -z0"),
    OutputFamily("f32y", "N", "force of the piston on the platform at A3, along y2 = n"),
    OutputFamily("f32z", "N", "force of the piston on the platform at A3, along z2 = e"),
)

#: Outputs that are one per sample, not per leg.
SAMPLE_OUTPUTS: tuple[OutputFamily, ...] = (
    OutputFamily(
        "conditioning",
        "1",
        "closeness to a parallel singularity, 0 (singular) to 1 (see virtual_work.conditioning)",
    ),
    OutputFamily(
        "reach",
        "1",
        "min over legs of (l0 + lambda21) / l0: 1 central, <= 0 with a piston joint on or behind "
        "its base pivot (see kinematics.reach)",
    ),
)

OUTPUT_NAMES: tuple[str, ...] = tuple(
    f"{f.name}_{leg}" for f in OUTPUT_FAMILIES for leg in LEGS
) + tuple(f.name for f in SAMPLE_OUTPUTS)


def _param_doc(name: str) -> tuple[str, str]:
    """Unit and meaning of a model parameter (docs/interfaces.md)."""
    fixed = {
        "l0": ("m", "|A1A2| = l0 + lambda21"),
        "l2": ("m", "|A2A3|"),
        "c1": ("m", "cylinder centre of mass at A1 + c1 e"),
        "c2": ("m", "piston centre of mass at A2 + c2 e"),
        "c1_perp": ("m", "cylinder centre of mass off the leg axis: A1 + c1 e + c1_perp n"),
        "c2_perp": ("m", "piston centre of mass off the leg axis: A2 + c2 e + c2_perp n"),
        "m1": ("kg", "cylinder mass"),
        "m2": ("kg", "piston mass"),
        "m3": ("kg", "platform mass"),
        "J1": ("kg m^2", "cylinder inertia about its centre of mass, axis z"),
        "J2": ("kg m^2", "piston inertia about its centre of mass, axis z"),
        "J3": ("kg m^2", "platform inertia about G, axis z"),
        "gx": ("m/s^2", "gravity, world x0"),
        "gy": ("m/s^2", "gravity, world y0 (up)"),
        "fx": ("N", "payload force on the platform at G, x0"),
        "fy": ("N", "payload force on the platform at G, y0"),
        "mz": ("N m", "payload moment on the platform, about z0"),
    }
    if name in fixed:
        return fixed[name]
    if name.startswith("alpha_"):
        return "rad", f"leg {name[-1]} angle where phi10 = 0"
    axis, leg, point = name[0], name[1], name[2]
    if point == "1":
        return "m", f"base pivot {leg}1, world {axis}0"
    return "m", f"platform joint {leg}3, platform frame {axis}G"


PARAM_DOCS: tuple[tuple[str, str, str], ...] = tuple(
    (name, *_param_doc(name)) for name in PARAM_NAMES
)
OUTPUT_DOCS: tuple[tuple[str, str, str], ...] = tuple(
    (f"{f.name}_{leg}", f.unit, f.meaning) for f in OUTPUT_FAMILIES for leg in LEGS
) + tuple((f.name, f.unit, f.meaning) for f in SAMPLE_OUTPUTS)


WrenchBuilder = Callable[[Program, LegKinematics, bool], LegWrenches]


def algorithm(
    prog: Program, actuation: str, wrench_builder: WrenchBuilder = leg_wrenches
) -> tuple[dict[str, LegKinematics], dict[str, sp.Expr]]:
    """The paper's algorithm on ``prog``: the leg kinematics (eqs. 5, 6, 9), each leg's wrenches
    (eqs. 10-11, by ``wrench_builder(prog, kinematics, carries_platform)``) and every joint load
    by virtual work (eqs. 7-8, 12-17). Returns the kinematics and the loads."""
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    cos_phi, sin_phi = platform_rotation(prog)
    kinematics = {leg: leg_kinematics(prog, leg, cos_phi, sin_phi) for leg in LEGS}
    wrenches = {leg: wrench_builder(prog, kinematics[leg], leg == LEGS[0]) for leg in LEGS}
    return kinematics, joint_loads(prog, actuation, kinematics, wrenches)


def derive(actuation: str) -> tuple[Program, dict[str, sp.Expr]]:
    """Run the paper's algorithm (steps 1-9) symbolically; return the program and outputs."""
    prog = Program()
    kinematics, loads = algorithm(prog, actuation)
    values: dict[str, sp.Expr] = {}
    for leg, kin in kinematics.items():
        for name in ("phi10", "lambda21", "phi32", "omega10", "v21", "omega32"):
            values[f"{name}_{leg}"] = getattr(kin, name)
        for name in ("eps10", "gamma21", "eps32"):
            values[f"{name}_{leg}"] = getattr(kin, name)
    values.update(loads)
    values["reach"] = reach(prog, kinematics)
    for name in OUTPUT_NAMES:  # the load of the free joint: m10 or f21z, identically zero
        values.setdefault(name, sp.Integer(0))
    return prog, {name: values[name] for name in OUTPUT_NAMES}
