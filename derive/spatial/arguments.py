"""The arguments, checks and units that a spatial variant's functions share: the pose and its
rates, the parameter vector, the efforts, the derivation they all read and its failure checks.
"""

from __future__ import annotations

from functools import cache

import sympy as sp
from rpr3gen_derive.codegen.spec import Argument, Check, Component
from rpr3gen_derive.spatial import virtual_work
from rpr3gen_derive.spatial.platform import param, pose_symbols
from rpr3gen_derive.spatial.structures import SpatialStructure, param_doc, param_names

_UNITS = {"x": "m", "y": "m", "z": "m", "a": "rad", "b": "rad", "c": "rad"}
_MEANINGS = {
    "x": "platform origin, world x",
    "y": "platform origin, world y",
    "z": "platform origin, world z",
    "a": "platform orientation R = Rz(c) Ry(b) Rx(a): angle about x",
    "b": "platform orientation: angle about y",
    "c": "platform orientation: angle about z",
}


def pose_arguments(structure: SpatialStructure) -> tuple[Argument, Argument, Argument]:
    """``q``, ``qd``, ``qdd``: the pose (docs/spatial-robots.md), its rates and accelerations."""
    q, qd, qdd = pose_symbols(structure)
    names = structure.pose
    return (
        Argument(
            "q",
            q,
            tuple(Component(n, _UNITS[n], _MEANINGS[n]) for n in names),
            "platform pose: origin (m)" + (", angles (rad)" if structure.dof == 6 else ""),
        ),
        Argument(
            "qd",
            qd,
            tuple(Component(f"d{n}", f"{_UNITS[n]}/s", f"d({n})/dt") for n in names),
            "its time derivative",
        ),
        Argument(
            "qdd",
            qdd,
            tuple(Component(f"dd{n}", f"{_UNITS[n]}/s^2", f"d2({n})/dt2") for n in names),
            "its second time derivative",
        ),
    )


def params_argument(structure: SpatialStructure) -> Argument:
    names = param_names(structure)
    return Argument(
        name="params",
        symbols=tuple(param(n) for n in names),
        components=tuple(Component(n, *param_doc(n)) for n in names),
        doc="model parameters",
        table="param_names",
    )


@cache
def derivation(structure: SpatialStructure) -> virtual_work.InverseDynamics:
    return virtual_work.derive(structure)


def checks(derivation: virtual_work.InverseDynamics) -> tuple[Check, ...]:
    return (
        Check("inputs_not_finite", "NOT_FINITE"),
        Check(
            "below", "SINGULAR", threshold="MIN_REACH", guard=("reach", sp.Min(*derivation.reaches))
        ),
        Check(
            "below",
            "SINGULAR",
            threshold="MIN_CONDITIONING",
            guard=("conditioning", derivation.outputs["conditioning"]),
        ),
        Check("outputs_not_finite", "SINGULAR"),
    )


def unit(name: str, structure: SpatialStructure) -> tuple[str, str]:
    family, _, leg = name.rpartition("_")
    if name == "conditioning":
        return "1", "closeness to a parallel singularity: 1 at best, 0 singular"
    head = family.rstrip("0123456789xyzab")
    joint = "".join(ch for ch in family if ch.isdigit())
    where = f"leg {leg}, joint {joint}"
    if family == "tau":
        unit = "N m" if structure.actuated_kind == "R" else "N"
        return unit, f"actuator effort along its coordinate, leg {leg}"
    if family[0] == "f":
        return "N", f"force of the earlier body on the later, world {family[1]}, {where}"
    if family[0] == "m":
        return "N m", f"moment of the earlier body on the later about the joint, {where}"
    kind = structure.kinds[int(joint) - 1] if not structure.delta or joint == "1" else "S"
    unit = "m" if kind == "P" else "rad"
    deriv = {"q": "", "qd": "/s", "qdd": "/s^2"}[head]
    return unit + deriv, f"joint coordinate {family}, {where}"


def efforts(structure: SpatialStructure) -> Argument:
    unit = "N m" if structure.actuated_kind == "R" else "N"
    return Argument(
        "tau",
        tuple(sp.Symbol(f"tau_{leg}", real=True) for leg in structure.legs),
        tuple(
            Component(f"tau_{leg}", unit, f"actuator effort, leg {leg}") for leg in structure.legs
        ),
        "actuator efforts",
    )


def c_context(structure: SpatialStructure) -> tuple:
    d = derivation(structure)
    names = list(d.outputs)
    params = param_names(structure)
    return (
        ("k", structure.dof),
        ("outputs", len(names)),
        ("tau", [names.index(f"tau_{leg}") for leg in structure.legs]),
        ("params", len(params)),
    )
