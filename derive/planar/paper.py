"""The paper's 3-RPR in its own parameters: the paper's derivation as one planar instance.

The parameter vector is the paper's (docs/interfaces.md, "Generated C"): base pivots
``xA1..yC1`` (world), platform joints ``xA3..yC3`` (platform frame), leg angles
``alpha_A..C``, ``l0 l2 c1 c2 m1 m2 m3 J1 J2 J3 gx gy fx fy mz c1_perp c2_perp``. Each leg is an
RPR chain: the cylinder (body 1) turns about ``A1``; the piston (body 2) slides in it along the
leg axis, ``|A1A2| = l0 + lambda21``, ``|A2A3| = l2``; joint 3 is the platform joint ``A3``. Both
bodies take the leg axis as their reference, so their points are given along it and across it:
the centres of mass ``(c1, c1_perp)`` from A1 and ``(c2, c2_perp)`` from A2. The joint
coordinates are the paper's ``phi10`` (from ``alpha``), ``lambda21`` and ``phi32``, measured
from the central configuration.

Unlike the general format, the legs need not meet the platform at one common pose when their
joint coordinates are zero (the explicit form of the paper's model file): each leg's chain is
given from its own base pivot and angle, and the platform joint from the platform frame.
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.planar.geometry import (
    LEGS,
    SHARED_PARAM_DOCS,
    JointNames,
    LegGeometry,
    PlatformGeometry,
    Reference,
    Robot,
)
from rpr3gen_derive.planar.vectors import add, scale

#: Model parameters, in the order of the generated parameter vector (docs/interfaces.md).
PARAM_NAMES: tuple[str, ...] = (
    "xA1", "yA1", "xB1", "yB1", "xC1", "yC1",
    "xA3", "yA3", "xB3", "yB3", "xC3", "yC3",
    "alpha_A", "alpha_B", "alpha_C",
    "l0", "l2", "c1", "c2", "m1", "m2", "m3", "J1", "J2", "J3",
    "gx", "gy", "fx", "fy", "mz",
    "c1_perp", "c2_perp",
)  # fmt: skip

_POSITIVE = {"l0", "l2", "m1", "m2", "m3", "J1", "J2", "J3"}

params: dict[str, sp.Symbol] = {
    name: sp.Symbol(name, real=True, positive=True)
    if name in _POSITIVE
    else sp.Symbol(name, real=True)
    for name in PARAM_NAMES
}

#: The paper's names of the joint coordinates, rates and accelerations.
NAMES = JointNames(
    ("phi10", "lambda21", "phi32"), ("omega10", "v21", "omega32"), ("eps10", "gamma21", "eps32")
)


def param_doc(name: str) -> tuple[str, str]:
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
        "J1": ("kg m^2", "cylinder inertia about its centre of mass, axis z"),
        "J2": ("kg m^2", "piston inertia about its centre of mass, axis z"),
        "J3": ("kg m^2", "platform inertia about G, axis z"),
        **SHARED_PARAM_DOCS,
    }
    if name in fixed:
        return fixed[name]
    if name.startswith("alpha_"):
        return "rad", f"leg {name[-1]} angle where phi10 = 0"
    axis, leg, point = name[0], name[1], name[2]
    if point == "1":
        return "m", f"base pivot {leg}1, world {axis}0"
    return "m", f"platform joint {leg}3, platform frame {axis}G"


def base_pivot(leg: str) -> tuple[sp.Symbol, sp.Symbol]:
    """World position of the fixed pivot ``A1`` of ``leg`` (m)."""
    return params[f"x{leg}1"], params[f"y{leg}1"]


def platform_joint(leg: str) -> tuple[sp.Symbol, sp.Symbol]:
    """Position of the platform joint ``A3`` of ``leg`` in the platform frame (m)."""
    return params[f"x{leg}3"], params[f"y{leg}3"]


def leg_geometry(leg: str) -> LegGeometry:
    """Leg ``leg`` as an RPR chain in the paper's parameters."""
    alpha = params[f"alpha_{leg}"]
    u = (sp.cos(alpha), sp.sin(alpha))
    axis = Reference(u, unit=True, angle=alpha)
    a1 = base_pivot(leg)
    l0, l2 = params["l0"], params["l2"]
    return LegGeometry(
        leg=leg,
        kinds="RPR",
        points=(a1, add(a1, scale(l0, u)), add(a1, scale(l0 + l2, u))),
        axes={2: u},
        platform_point=platform_joint(leg),
        sigma=sp.Integer(-1),  # D = -|A1A3| < 0
        references=(axis, axis),
        links=((l0, sp.Integer(0)), (l2, sp.Integer(0))),
        com=((params["c1"], params["c1_perp"]), (params["c2"], params["c2_perp"])),
        mass=(params["m1"], params["m2"]),
        inertia=(params["J1"], params["J2"]),
        inertial_x=((sp.Integer(1), sp.Integer(0)), (sp.Integer(1), sp.Integer(0))),
    )


def robot() -> Robot:
    """The paper's robot, in its parameters."""
    return Robot(
        kinds="RPR",
        legs={leg: leg_geometry(leg) for leg in LEGS},
        platform=PlatformGeometry(params["m3"], (sp.Integer(0), sp.Integer(0)), params["J3"]),
        gravity=(params["gx"], params["gy"]),
        payload_force=(params["fx"], params["fy"]),
        payload_moment=params["mz"],
        names=NAMES,
    )
