"""The spatial robots' identification regressor's spec: ``Y`` with ``tau = Y pi + tau_payload``
(docs/spatial-robots.md, "Identification"; the columns' evaluation: :mod:`.identification`).
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Argument, Check, Component, FunctionSpec, Output
from rpr3gen_derive.spatial import identification
from rpr3gen_derive.spatial.arguments import c_context, pose_arguments
from rpr3gen_derive.spatial.structures import SpatialStructure

_PI_DOCS: dict[str, tuple[str, str]] = {
    "m": ("kg", "mass"),
    "mc": ("kg m", "first moment along the rod, about its upper S"),
    "I": ("kg m^2", "inertia across the rod, about its upper S"),
    **{f"mc{a}": ("kg m", f"first moment {a}") for a in "xyz"},
    **{
        f"I{e}": ("kg m^2", f"inertia tensor entry {e}")
        for e in ("xx", "yy", "zz", "xy", "xz", "yz")
    },
}


def _pi_component(name: str) -> Component:
    quantity, _, body = name.partition("_")
    unit, meaning = _PI_DOCS[quantity]
    if body == "3":
        where = "the platform, about its frame's origin, platform axes"
    elif body[0] == "r":
        where = f"each rod of leg {body[1:]}"
    else:
        where = f"body {body[0]} of leg {body[1:]}, about its first joint point, world axes at home"
    return Component(name, unit, f"{meaning} of {where}")


def inertial_parameters(structure: SpatialStructure) -> Argument:
    """The inertial parameters pi, the columns of Y: C table ``rpr3_inertial_parameter_names``."""
    names = identification.parameter_names(structure)
    return Argument(
        "pi",
        tuple(sp.Symbol(f"pi_{n}", real=True) for n in names),
        tuple(_pi_component(n) for n in names),
        "inertial parameters (per body m, m c, the inertia tensor about its first joint point; "
        "per rod m, m c, I about its upper S)",
        table="inertial_parameter_names",
    )


def regressor(structure: SpatialStructure) -> FunctionSpec:
    """``rpr3_regressor``: ``Y`` (k x P, row-major) with ``tau = Y pi + tau_payload``, from ``P``
    evaluations of the inverse dynamics (``templates/spatial_regressor.c.jinja``)."""
    names = identification.parameter_names(structure)
    context = dict(c_context(structure))
    unit = "N m" if structure.actuated_kind == "R" else "N"
    bodies, first = [], 0
    for b in identification.bodies(structure):
        bodies.append(
            {
                "name": b.name,
                "rod": b.rod,
                "mass": b.mass,
                "com": list(b.com),
                "inertia": list(b.inertia),
                "reference": list(b.reference) if b.reference else None,
                "tip": list(b.tip) if b.tip else None,
                "first": first,
            }
        )
        first += len(b.quantities)
    return FunctionSpec(
        name="regressor",
        doc=f"Identification regressor Y ({structure.dof} x {len(names)}, row-major; row i: "
        "the effort of leg i; column j: INERTIAL_PARAMETER_NAMES[j]) with tau = Y pi + "
        "tau_payload: column j is the inverse dynamics' efforts for the model numbers whose "
        "inertial parameters are the unit vector e_j (every other body massless, no payload).",
        inputs=pose_arguments(structure),
        outputs=(
            Output(
                "Y",
                (sp.Integer(0),) * (len(structure.legs) * len(names)),
                tuple(
                    Component(
                        f"Y_{leg}__{name}",
                        f"{unit} / ({_PI_DOCS[name.partition('_')[0]][0]})",
                        f"d tau_{leg} / d {name}",
                    )
                    for leg in structure.legs
                    for name in names
                ),
                f"Y = d tau / d pi, row-major ({len(structure.legs)} x {len(names)}; columns: "
                "rpr3_inertial_parameter_names)",
            ),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "SINGULAR")),
        c_body="spatial_regressor.c.jinja",
        c_context=(
            ("k", structure.dof),
            ("outputs", context["outputs"]),
            ("tau", context["tau"]),
            ("params", context["params"]),
            ("zeroed", list(identification.zeroed(structure))),
            ("columns", len(names)),
            ("bodies", bodies),
        ),
    )


#: The tracked forward kinematics' numbers: Newton steps, halvings of a step, convergence on
#: the largest residual |qa(q) - qa| (rad or m).
