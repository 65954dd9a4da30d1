"""The inverse dynamics' outputs of a structure: names, units, meanings and expressions.

General format (docs/interfaces.md, "Any planar 3-leg robot"), family-major, legs A, B, C in
each family: ``q1 q2 q3`` (joint coordinates), ``qd1..3``, ``qdd1..3``; per joint j ``fxj fyj``
(force of the earlier body on the later through joint j, world components) and ``mj`` (its
moment about joint j's point, z0); ``tau`` (the actuator effort); then ``conditioning`` and
``reach``.

The paper's variants keep the paper's outputs (docs/conventions.md): ``phi10 lambda21 phi32``
and their rates and accelerations, ``m10 f10x f10y f21y f21z m21 f32y f32z`` (loads in the leg's
frames: ``y`` along ``n``, ``z`` along the leg axis ``e``; ``m21`` along ``x2 = -z0``), then
``conditioning`` and ``reach`` (``min (l0 + lambda21) / l0``).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import paper
from rpr3gen_derive.planar.geometry import LEGS, Robot
from rpr3gen_derive.planar.kinematics import STEP_POSE, LegKinematics
from rpr3gen_derive.planar.structures import Structure
from rpr3gen_derive.planar.virtual_work import Loads


@dataclass(frozen=True)
class OutputFamily:
    """One output, for each of the three legs (``name_A``, ...) or once (``per_leg=False``)."""

    name: str
    unit: str
    meaning: str
    per_leg: bool = True


PAPER_FAMILIES: tuple[OutputFamily, ...] = (
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

CONDITIONING = OutputFamily(
    "conditioning",
    "1",
    "closeness to a parallel singularity, 0 (singular) to 1 (see virtual_work.conditioning)",
    per_leg=False,
)
PAPER_REACH = OutputFamily(
    "reach",
    "1",
    "min over legs of (l0 + lambda21) / l0: 1 central, <= 0 with a piston joint on or behind its "
    "base pivot",
    per_leg=False,
)
GENERAL_REACH = OutputFamily(
    "reach",
    "1",
    "min over legs of D / D(home), D the leg's serial determinant: 1 at home, 0 at a serial "
    "singularity",
    per_leg=False,
)

_BODY = {1: "the base", 2: "body 1", 3: "body 2"}
_LATER = {1: "body 1", 2: "body 2", 3: "the platform"}


def _coordinate_unit(kind: str, per: str = "") -> str:
    return ("rad" if kind == "R" else "m") + per


def general_families(structure: Structure) -> tuple[OutputFamily, ...]:
    """The general format's output families for a structure (units follow the joint types)."""
    kinds = structure.kinds
    out = []
    for suffix, per, what in (("", "", "coordinate"), ("d", "/s", "rate"), ("dd", "/s^2", "acc")):
        for j in (1, 2, 3):
            kind = "revolute" if kinds[j - 1] == "R" else "prismatic"
            meaning = {
                "coordinate": f"joint {j} ({kind}) coordinate from home",
                "rate": f"d(q{j})/dt",
                "acc": f"d2(q{j})/dt2",
            }[what]
            out.append(OutputFamily(f"q{suffix}{j}", _coordinate_unit(kinds[j - 1], per), meaning))
    for j in (1, 2, 3):
        by = f"of {_BODY[j]} on {_LATER[j]} through joint {j}"
        out.append(OutputFamily(f"fx{j}", "N", f"force {by}, world x0"))
        out.append(OutputFamily(f"fy{j}", "N", f"force {by}, world y0"))
        out.append(OutputFamily(f"m{j}", "N m", f"moment {by}, about joint {j}'s point, z0"))
    effort = "torque (N m)" if structure.actuated_kind == "R" else "force (N)"
    unit = "N m" if structure.actuated_kind == "R" else "N"
    out.append(
        OutputFamily(
            "tau",
            unit,
            f"actuator effort: the {effort} of joint {structure.actuated} on its later body, "
            "along its coordinate",
        )
    )
    return tuple(out)


def families(structure: Structure) -> tuple[OutputFamily, ...]:
    """Every output family of a structure's inverse dynamics, in order."""
    if structure.paper:
        return (*PAPER_FAMILIES, CONDITIONING, PAPER_REACH)
    return (*general_families(structure), CONDITIONING, GENERAL_REACH)


def output_docs(structure: Structure) -> tuple[tuple[str, str, str], ...]:
    """``(name, unit, meaning)`` of every output, in order."""
    return tuple(
        (f"{f.name}_{leg}" if f.per_leg else f.name, f.unit, f.meaning)
        for f in families(structure)
        for leg in (LEGS if f.per_leg else ("",))
    )


def output_names(structure: Structure) -> tuple[str, ...]:
    """The inverse dynamics' output names, in order."""
    return tuple(name for name, _, _ in output_docs(structure))


def effort_family(structure: Structure) -> str:
    """The family of the actuator efforts (``tau``; the paper: ``m10`` or ``f21z``)."""
    if structure.paper:
        return "m10" if structure.actuated == 1 else "f21z"
    return "tau"


def coordinate_family(structure: Structure, joint: int) -> tuple[str, str, str]:
    """Families of joint ``joint``'s coordinate, rate and acceleration."""
    if structure.paper:
        names = paper.NAMES
        return names.q[joint - 1], names.qd[joint - 1], names.qdd[joint - 1]
    return f"q{joint}", f"qd{joint}", f"qdd{joint}"


def _paper_values(loads: Loads, leg: str) -> dict[str, sp.Expr]:
    """The paper's loads of one leg from the joint loads (conventions.md's frames).

    The leg frame of the paper's RPR leg is its axis ``e`` (and ``n = perp(e)``): the
    revolute joint 3's components are already along ``e`` and ``n``, the slide's along its axis
    and across it.
    """
    j1, j2, j3 = (loads.joints[(leg, j)] for j in (1, 2, 3))
    f10 = j1.world
    return {
        "m10": j1.moment,
        "f10x": f10[0],
        "f10y": f10[1],
        "f21y": j2.force[1],
        "f21z": j2.force[0],
        "m21": -j2.moment,
        "f32y": j3.force[1],
        "f32z": j3.force[0],
    }


def _general_values(
    structure: Structure, kin: LegKinematics, loads: Loads, leg: str
) -> dict[str, sp.Expr]:
    values: dict[str, sp.Expr] = {}
    for j in (1, 2, 3):
        load = loads.joints[(leg, j)]
        values[f"fx{j}"], values[f"fy{j}"] = load.world
        values[f"m{j}"] = load.moment
    actuated = loads.joints[(leg, structure.actuated)]
    values["tau"] = actuated.moment if structure.actuated_kind == "R" else actuated.force[0]
    return values


def leg_reaches(structure: Structure, kinematics: dict[str, LegKinematics]) -> list[sp.Expr]:
    """Each leg's serial measure, whose minimum is ``reach``: ``(l0 + lambda21) / l0`` for the
    paper's legs, ``D / D(home)`` for the general format's."""
    if structure.paper:
        l0 = paper.params["l0"]
        return [(l0 + kin.q[1]) / l0 for kin in kinematics.values()]
    out = []
    for leg, kin in kinematics.items():
        home = kin.geometry.serial_home
        if home is None:
            raise ValueError(f"leg {leg}: no serial determinant at home to measure against")
        out.append(kin.pose.D / home)
    return out


def inverse_dynamics_outputs(
    prog: Program,
    structure: Structure,
    robot: Robot,
    kinematics: dict[str, LegKinematics],
    loads: Loads,
) -> dict[str, sp.Expr]:
    """Every output of the inverse dynamics, by name, in order (named in ``prog`` as needed)."""
    values: dict[str, sp.Expr] = {}
    for leg, kin in kinematics.items():
        for j in (1, 2, 3):
            q, qd, qdd = coordinate_family(structure, j)
            values[f"{q}_{leg}"] = kin.q[j - 1]
            values[f"{qd}_{leg}"] = kin.qd[j - 1]
            values[f"{qdd}_{leg}"] = kin.qdd[j - 1]
        own = (
            _paper_values(loads, leg)
            if structure.paper
            else _general_values(structure, kin, loads, leg)
        )
        for name, expr in own.items():
            values[f"{name}_{leg}"] = expr
    values["conditioning"] = loads.conditioning
    values["reach"] = prog.define("reach", sp.Min(*leg_reaches(structure, kinematics)), STEP_POSE)
    return {name: values[name] for name in output_names(structure)}
