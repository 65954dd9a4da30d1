"""The 3-RPR's registry of generated functions: one spec builder per function, per variant.

Each entry of :data:`FUNCTIONS` turns an actuation scheme into a
:class:`~rpr3gen_derive.codegen.spec.FunctionSpec`; :func:`module` gathers them, with the
parameter vector, return codes and thresholds they share, into the
:class:`~rpr3gen_derive.codegen.spec.ModuleSpec` of one variant (one folder of ``generated/``).
Adding a generated function is adding an entry here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache

import sympy as sp
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
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.dynamics import leg_wrenches
from rpr3gen_derive.rpr3.kinematics import leg_kinematics, platform_rotation, reach
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


def derive(actuation: str) -> tuple[Program, dict[str, sp.Expr]]:
    """Run the paper's algorithm (steps 1-9) symbolically; return the program and outputs."""
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    prog = Program()
    cos_phi, sin_phi = platform_rotation(prog)
    kinematics = {leg: leg_kinematics(prog, leg, cos_phi, sin_phi) for leg in LEGS}
    wrenches = {
        leg: leg_wrenches(prog, kinematics[leg], carries_platform=(leg == LEGS[0])) for leg in LEGS
    }
    loads = joint_loads(prog, actuation, kinematics, wrenches)
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


PREFIX = "rpr3"

PARAMS = Argument(
    name="params",
    symbols=tuple(syms.params[name] for name in PARAM_NAMES),
    components=tuple(Component(name, unit, meaning) for name, unit, meaning in PARAM_DOCS),
    doc="model parameters",
    table="param_names",
)

POSE = Argument(
    "q",
    tuple(syms.q),
    (
        Component("x", "m", "platform centre G, world x0"),
        Component("y", "m", "platform centre G, world y0"),
        Component("phi", "rad", "platform rotation from the central configuration"),
    ),
    "platform centre G in the world frame (m), platform angle (rad)",
)
VELOCITY = Argument(
    "qd",
    tuple(syms.qd),
    tuple(Component(f"d{c.name}", f"{c.unit}/s", f"d({c.name})/dt") for c in POSE.components),
    "its time derivative (m/s, rad/s)",
)
ACCELERATION = Argument(
    "qdd",
    tuple(syms.qdd),
    tuple(Component(f"dd{c.name}", f"{c.unit}/s^2", f"d2({c.name})/dt2") for c in POSE.components),
    "its second time derivative (m/s^2, rad/s^2)",
)

RETURN_CODES: tuple[ReturnCode, ...] = (
    ReturnCode("OK", 0, "success"),
    ReturnCode("NOT_FINITE", 1, "an input is NaN or infinite"),
    ReturnCode(
        "SINGULAR",
        2,
        "singular or degenerate pose: a piston joint on or behind its base pivot (reach below "
        "MIN_REACH), conditioning below MIN_CONDITIONING, or a result that would not be finite",
    ),
)

THRESHOLDS: tuple[Threshold, ...] = (
    Threshold(
        "MIN_REACH",
        "1e-9",
        'Output "reach" (min over legs of |A1A2| / l0; 1 in the central configuration) under '
        "which a pose is refused: a piston joint on or behind its base pivot, which also keeps "
        "every leg clear of the serial singularity |A1A3| = 0.",
    ),
    Threshold(
        "MIN_CONDITIONING",
        "1e-9",
        'Output "conditioning" (0 at a parallel singularity, 1 at best) under which a pose '
        "counts as singular: the loads there are dominated by round-off. Applications usually "
        "want a larger margin of their own (rpr3gen simulate refuses poses under 1e-3 by "
        "default).",
    ),
)

#: The failure conditions of a function of the pose, in the order they are tested.
SINGULAR_POSE_CHECKS: tuple[Check, ...] = (
    Check("inputs_not_finite", "NOT_FINITE"),
    Check("below", "SINGULAR", "out", "reach", "MIN_REACH"),
    Check("below", "SINGULAR", "out", "conditioning", "MIN_CONDITIONING"),
    Check("outputs_not_finite", "SINGULAR"),
)


def inverse_dynamics(actuation: str) -> FunctionSpec:
    """``rpr3_inverse_dynamics``: leg kinematics and every joint load (eqs. 5-17)."""
    prog, outputs = derive(actuation)
    actuated = "m10 at A1 (f21z = 0)" if actuation == "revolute" else "f21z at A2 (m10 = 0)"
    doc = (
        f"Inverse dynamics of the 3-RPR planar parallel robot, {actuation} actuation: "
        f"actuator load {actuated}. Leg kinematics (eqs. 5, 6, 9) and every joint load "
        "(eqs. 12-17) from the platform pose q = (x, y, phi), its velocity qd and acceleration qdd."
    )
    return FunctionSpec(
        name="inverse_dynamics",
        doc=doc,
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "out",
                tuple(outputs.values()),
                tuple(Component(name, unit, meaning) for name, unit, meaning in OUTPUT_DOCS),
                "row k receives OUTPUT_NAMES[k] (loads: exerted by body k-1 on body k); the rows "
                "of a singular pose hold inf or nan",
                table="output_names",
            ),
        ),
        program=prog,
        checks=SINGULAR_POSE_CHECKS,
    )


FunctionBuilder = Callable[[str], FunctionSpec]

#: Every generated function, by name: a builder from the actuation scheme to its spec.
FUNCTIONS: Mapping[str, FunctionBuilder] = {"inverse_dynamics": inverse_dynamics}


@cache
def _spec(builder: FunctionBuilder, actuation: str) -> FunctionSpec:
    return builder(actuation)


def clear_cache() -> None:
    """Forget the specs derived so far (they are derived once per process otherwise)."""
    _spec.cache_clear()


def module(actuation: str, functions: Mapping[str, FunctionBuilder] | None = None) -> ModuleSpec:
    """The generated module of one actuation scheme: every function of ``functions``."""
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    functions = FUNCTIONS if functions is None else functions
    return ModuleSpec(
        prefix=PREFIX,
        variant=actuation,
        doc=(
            f"Generated functions of the 3-RPR planar parallel robot (S. Staicu), {actuation} "
            "actuation. Model numbers are inputs (params), so one build serves every robot of "
            "this structure."
        ),
        params=PARAMS,
        functions=tuple(_spec(builder, actuation) for builder in functions.values()),
        return_codes=RETURN_CODES,
        thresholds=THRESHOLDS,
        defines=(("ACTUATION", f'"{actuation}"', ""),),
    )
