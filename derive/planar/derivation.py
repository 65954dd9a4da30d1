"""The inverse dynamics, eqs. (1)-(17), as one program, for any structure: the derivation itself.

:func:`algorithm` runs the paper's method on a :class:`~.geometry.Robot` (the leg kinematics of
eqs. 5, 6 and 9, the required wrenches and their recursion, eqs. 10-11, the virtual work of eqs.
7-8 and 12-17); :func:`derive` names its outputs as a structure's outputs (:mod:`.outputs`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import structures
from rpr3gen_derive.planar.dynamics import (
    Inertia,
    InertiaBuilder,
    LegWrenches,
    leg_inertias,
    leg_wrenches,
    platform_inertia,
    platform_wrench,
)
from rpr3gen_derive.planar.geometry import LEGS, Robot, named_constants
from rpr3gen_derive.planar.kinematics import LegKinematics, leg_kinematics, platform_rotation
from rpr3gen_derive.planar.structures import Structure
from rpr3gen_derive.planar.virtual_work import Loads, joint_loads, platform_radius2


@dataclass(frozen=True)
class Derivation:
    """The inverse-dynamics program of a structure, with the structure the control model uses.

    ``kinematics`` and ``wrenches`` are the per-leg objects of eqs. (5)-(11), ``loads`` those of
    eqs. (12)-(17); their symbols are assignments of ``program``. ``outputs``: the function's
    outputs by name, in order.
    """

    structure: Structure
    robot: Robot
    program: Program
    kinematics: dict[str, LegKinematics]
    wrenches: dict[str, LegWrenches]
    loads: Loads
    outputs: dict[str, sp.Expr]


def algorithm(
    prog: Program,
    robot: Robot,
    actuated: int,
    inertias: InertiaBuilder = leg_inertias,
    tag: str = "",
    platform_body: Callable[[Robot, sp.Expr, sp.Expr], Inertia] = platform_inertia,
) -> tuple[dict[str, LegKinematics], dict[str, LegWrenches], Loads]:
    """The paper's algorithm on ``prog``: the leg kinematics (eqs. 5, 6, 9), each leg's wrenches
    (eqs. 10-11; leg A carries the platform) and every joint load by virtual work (eqs. 7-8,
    12-17). ``inertias`` and ``platform_body`` give the bodies' inertial data (the regressor
    passes symbols); ``tag`` marks the names of the wrenches and loads that depend on them."""
    robot = named_constants(prog, robot)
    platform = platform_rotation(prog)
    kinematics = {leg: leg_kinematics(prog, robot, leg, platform) for leg in LEGS}
    carried = platform_wrench(robot, platform_body(robot, platform.cos_phi, platform.sin_phi))
    wrenches = {
        leg: leg_wrenches(
            prog, kinematics[leg], carried if leg == LEGS[0] else None, robot, inertias, tag
        )
        for leg in LEGS
    }
    rho2 = platform_radius2([robot.legs[leg].platform_point for leg in LEGS])
    return kinematics, wrenches, joint_loads(prog, actuated, kinematics, wrenches, rho2, tag)


def derive(structure: Structure) -> Derivation:
    """Run the algorithm symbolically for ``structure``; name its outputs."""
    from rpr3gen_derive.planar import outputs

    prog = Program()
    robot = structures.robot(structure)
    kinematics, wrenches, loads = algorithm(prog, robot, structure.actuated)
    values = outputs.inverse_dynamics_outputs(prog, structure, robot, kinematics, loads)
    return Derivation(structure, robot, prog, kinematics, wrenches, loads, values)
