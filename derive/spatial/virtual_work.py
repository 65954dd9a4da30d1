"""The inverse dynamics: the platform's balance fixes the legs' free forces, then every joint
load follows down each leg (the method of the paper, eqs. 10-17, in three dimensions).

The principle of virtual work for a virtual displacement of each passive joint of a leg (the U's
two turns, a rod's turns about its upper S) leaves one unknown per connector, the force ``t``
along the leg or rod (:mod:`.legs`). For a virtual displacement of the platform (three
translations, three turns) the virtual work of the platform's demand (:func:`.platform.demand`)
and of the connectors' forces must cancel: ``A t = b`` with ``A``'s columns the unit wrenches
``(w, (r x w) / rho)`` of the connectors (``rho``: the platform points' RMS distance from the
origin at home, so that both halves of a column are lengths of one scale). ``A`` is solved by
modified Gram–Schmidt, ``A = Q R``, in straight-line code (no pivoting is needed: the columns'
norms are the pivots); ``conditioning = prod R_kk / prod |a_k|`` is ``|det A|`` over the
columns' lengths: 1 for orthogonal columns, 0 at a parallel singularity.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.spatial import legs as leg_types
from rpr3gen_derive.spatial.platform import PlatformMotion, demand, motion, param
from rpr3gen_derive.spatial.structures import SpatialStructure
from rpr3gen_derive.spatial.vectors import Namer, Vec, cross, dot, vec


@dataclass(frozen=True)
class InverseDynamics:
    """The outputs by name (docs/spatial-robots.md, in order), the legs' reaches, the
    actuator coordinates and efforts and the actuator Jacobian ``J = d qa / d q`` (rows by leg),
    all in symbols of ``program``."""

    program: Program
    outputs: dict[str, sp.Expr]
    reaches: tuple[sp.Expr, ...]
    actuators: tuple[sp.Expr, ...]
    efforts: tuple[sp.Expr, ...]
    jacobian: sp.Matrix


def home_scale(structure: SpatialStructure) -> sp.Expr:
    """``rho^2``: the mean squared distance of the connectors' points from the platform's
    origin at home."""
    total = sp.Integer(0)
    count = 0
    for leg in structure.legs:
        p = vec(*(param(f"p{a}_{leg}") for a in "xyz"))
        if structure.delta:
            a = vec(*(param(f"{'a' if structure.kinds == 'RSS2' else 'bar'}{c}_{leg}")
                      for c in "xyz"))  # fmt: skip
            half = param(f"w_{leg}") / 2
            points = [p + half * a, p - half * a]
        else:
            points = [p]
        for point in points:
            total += dot(point, point)
            count += 1
    return total / count


def solve(
    prog: Program,
    columns: list[list[sp.Expr]],
    rhs: list[sp.Expr],
    prefix: str = "g",
    step: str = "platform balance",
) -> tuple[list[sp.Expr], sp.Expr]:
    """Solve ``A t = b`` (``columns`` of ``A``) by modified Gram–Schmidt in ``prog``; returns
    ``t`` and ``prod R_kk / prod |a_k|`` (named ``{prefix}conditioning``)."""
    n = Namer(prog, "", step)
    size = len(columns)
    norms = [
        n.s(f"{prefix}an{k}", sp.sqrt(sum(x**2 for x in col))) for k, col in enumerate(columns)
    ]
    V = [list(col) for col in columns]
    Qs: list[list[sp.Expr]] = []
    Rm: dict[tuple[int, int], sp.Expr] = {}
    for k in range(size):
        Rm[k, k] = n.s(f"{prefix}R{k}{k}", sp.sqrt(sum(x**2 for x in V[k])))
        inv = n.s(f"{prefix}iR{k}", 1 / Rm[k, k])
        Qs.append([n.s(f"{prefix}Q{k}_{i}", V[k][i] * inv) for i in range(size)])
        for j in range(k + 1, size):
            Rm[k, j] = n.s(f"{prefix}R{k}{j}", sum(Qs[k][i] * V[j][i] for i in range(size)))
            V[j] = [
                n.s(f"{prefix}V{j}_{k}_{i}", V[j][i] - Rm[k, j] * Qs[k][i]) for i in range(size)
            ]
    y = [n.s(f"{prefix}y{k}", sum(Qs[k][i] * rhs[i] for i in range(size))) for k in range(size)]
    t: list[sp.Expr] = [sp.Integer(0)] * size
    for k in reversed(range(size)):
        rest = sum((Rm[k, j] * t[j] for j in range(k + 1, size)), sp.Integer(0))
        t[k] = n.s(
            f"{prefix}t{k}", (y[k] - rest) * n.prog.define(f"{prefix}iRt{k}", 1 / Rm[k, k], n.step)
        )
    ratio = sp.Mul(*(Rm[k, k] for k in range(size))) / sp.Mul(*norms)
    return t, n.s(f"{prefix}conditioning", ratio)


def derive(structure: SpatialStructure) -> InverseDynamics:
    """The inverse dynamics of a spatial structure, as a program."""
    prog = Program()
    pm = motion(prog, structure)
    legs = []
    for letter in structure.legs:
        n = Namer(prog, f"_{letter}", f"leg {letter}")
        legs.append(leg_types.leg(n, structure.kinds, letter, pm))
    F, M = demand(prog, pm)
    rho = Namer(prog, "", "platform balance").s("rho", sp.sqrt(home_scale(structure)))
    irho = prog.define("irho", 1 / rho, "platform balance")
    connectors = [c for leg in legs for c in leg.connectors]
    columns = [[*c.w, *(cross(c.offset, c.w) * irho)] for c in connectors]
    F0 = sum((c.F0 for c in connectors), vec(0, 0, 0))
    M0 = sum((cross(c.offset, c.F0) for c in connectors), vec(0, 0, 0))
    rhs = [*(F - F0), *((M - M0) * irho)]
    t, conditioning = solve(prog, columns, rhs)
    forces: list[Vec] = []
    for k, c in enumerate(connectors):
        letter = structure.legs[k // len(legs[0].connectors)]
        suffix = f"{k % len(legs[0].connectors) + 1}" if structure.delta else ""
        forces.append(Namer(prog, f"_{letter}", "joint loads").v(f"Fc{suffix}", c.F0 + t[k] * c.w))
    per = len(legs[0].connectors)
    families: dict[str, dict[str, sp.Expr]] = {}
    for k, (letter, leg) in enumerate(zip(structure.legs, legs, strict=True)):
        for family, expr in leg.coordinates:
            families.setdefault(family, {})[letter] = expr
        loads, tau = leg.loads(forces[k * per : (k + 1) * per])
        for load in loads:
            for kind, v in (("f", load.force), ("m", load.moment)):
                for i, axis in enumerate("xyz"):
                    families.setdefault(f"{kind}{axis}{load.joint}", {})[letter] = v[i]
        families.setdefault("tau", {})[letter] = tau
    outputs = {
        f"{family}_{letter}": by_leg[letter]
        for family, by_leg in families.items()
        for letter in structure.legs
    }
    outputs["conditioning"] = conditioning
    return InverseDynamics(
        prog,
        outputs,
        tuple(leg.reach for leg in legs),
        tuple(leg.actuator for leg in legs),
        tuple(outputs[f"tau_{letter}"] for letter in structure.legs),
        jacobian(prog, structure, pm, legs),
    )


def jacobian(
    prog: Program, structure: SpatialStructure, pm: PlatformMotion, legs: list[leg_types.Leg]
) -> sp.Matrix:
    """``J = d qa / d q``: leg ``i``'s row is ``(g_i, ((r_i x g_i) . e_j)_j)`` with
    ``qa_i' = g_i . S_i'``, ``S_i' = o' + omega x r_i`` and ``omega = sum_j q_j' e_j`` over the
    angles (hexapods)."""
    rows = []
    for letter, leg in zip(structure.legs, legs, strict=True):
        n = Namer(prog, f"_{letter}", "actuator jacobian")
        row = list(leg.gradient)
        if pm.axes:
            rg = cross(leg.offset, leg.gradient)
            row += [n.s(f"J{j + 4}", dot(rg, e)) for j, e in enumerate(pm.axes)]
        rows.append(row)
    return sp.Matrix(rows)
