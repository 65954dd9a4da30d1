"""The arguments and outputs the generated functions share: the pose, its rates, the actuator
coordinates and efforts, the 3-vector and 3 x 3 matrix outputs, and the failure checks of a
function of the pose (docs/interfaces.md)."""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Argument, Check, Component, Output
from rpr3gen_derive.planar import control, general, outputs, paper, structures
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.structures import Structure


def _param_doc(structure: Structure, name: str) -> tuple[str, str]:
    return paper.param_doc(name) if structure.paper else general.param_doc(name)


def params_argument(structure: Structure) -> Argument:
    """The parameter vector of a structure's variant (C table ``rpr3_param_names``)."""
    names = structures.param_names(structure)
    symbol = paper.params.__getitem__ if structure.paper else general.param_symbol
    return Argument(
        name="params",
        symbols=tuple(symbol(n) for n in names),
        components=tuple(Component(n, *_param_doc(structure, n)) for n in names),
        doc="model parameters",
        table="param_names",
    )


POSE = Argument(
    "q",
    tuple(syms.q),
    (
        Component("x", "m", "platform centre G, world x0"),
        Component("y", "m", "platform centre G, world y0"),
        Component("phi", "rad", "platform rotation from the central configuration (home)"),
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

#: The failure conditions of a function of the pose, in the order they are tested.
SINGULAR_POSE_CHECKS: tuple[Check, ...] = (
    Check("inputs_not_finite", "NOT_FINITE"),
    Check("below", "SINGULAR", "out", "reach", "MIN_REACH"),
    Check("below", "SINGULAR", "out", "conditioning", "MIN_CONDITIONING"),
    Check("outputs_not_finite", "SINGULAR"),
)


def coordinate_unit(structure: Structure) -> str:
    """Unit of an actuator coordinate: rad for a revolute motor, m for a prismatic one."""
    return "rad" if structure.actuated_kind == "R" else "m"


def effort_unit(structure: Structure) -> str:
    """Unit of an actuator effort: N m for a revolute motor, N for a prismatic one."""
    return "N m" if structure.actuated_kind == "R" else "N"


def actuator_argument(structure: Structure) -> Argument:
    """``qa``: the actuator coordinates (docs/interfaces.md, "Control model")."""
    family = outputs.coordinate_family(structure, structure.actuated)[0]
    unit = coordinate_unit(structure)
    return Argument(
        "qa",
        tuple(syms.qa),
        tuple(
            Component(f"{family}_{leg}", unit, f"actuated joint {structure.actuated}, leg {leg}")
            for leg in LEGS
        ),
        f"actuator coordinates ({family}_A, _B, _C, from home)",
    )


def effort_argument(structure: Structure) -> Argument:
    """``tau``: the actuator efforts."""
    family = outputs.effort_family(structure)
    unit = effort_unit(structure)
    return Argument(
        "tau",
        tuple(syms.tau),
        tuple(Component(f"{family}_{leg}", unit, f"actuator effort, leg {leg}") for leg in LEGS),
        f"actuator efforts ({family}_A, _B, _C)",
    )


def pose_checks(prog: Program, structure: Structure) -> tuple[Check, ...]:
    """The failure conditions of the inverse dynamics, on the same values, as guards."""
    values = control.include_inverse_dynamics(prog, structure).outputs
    return (
        Check("inputs_not_finite", "NOT_FINITE"),
        Check("below", "SINGULAR", threshold="MIN_REACH", guard=("reach", values["reach"])),
        Check(
            "below",
            "SINGULAR",
            threshold="MIN_CONDITIONING",
            guard=("conditioning", values["conditioning"]),
        ),
        Check("outputs_not_finite", "SINGULAR"),
    )


def matrix_output(
    name: str,
    m: sp.Matrix,
    units: tuple[str, ...],
    meaning: str,
    entry: Callable[[int, int], str] = lambda i, j: "",
    *,
    output: str | None = None,
    hidden: bool = False,
) -> Output:
    """A 3 x 3 matrix output, row-major, components ``{name}11`` ... ``{name}33``; ``units`` per
    column (3) or per entry (9); ``output``: the output's name when it is not ``name``."""
    return Output(
        output or name,
        tuple(m[i, j] for i in range(3) for j in range(3)),
        tuple(
            Component(
                f"{name}{i + 1}{j + 1}",
                units[j] if len(units) == 3 else units[3 * i + j],
                entry(i, j),
            )
            for i in range(3)
            for j in range(3)
        ),
        meaning,
        hidden=hidden,
    )


def vector_output(
    name: str, v: sp.Matrix, names: tuple[str, ...], units: tuple[str, ...], doc: str
) -> Output:
    """A 3-vector output, one component per name and unit."""
    return Output(
        name,
        tuple(v[k] for k in range(3)),
        tuple(Component(n, u) for n, u in zip(names, units, strict=True)),
        doc,
    )


def output_like(name: str, v: sp.Matrix, like: Argument, doc: str) -> Output:
    """A 3-vector output with the names and units of ``like``'s components (not its meanings)."""
    return vector_output(
        name,
        v,
        tuple(c.name for c in like.components),
        tuple(c.unit for c in like.components),
        doc,
    )
