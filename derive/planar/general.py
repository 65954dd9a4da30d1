"""The general model file's parametrisation: any leg type, everything given at home.

Home (docs/interfaces.md, "Any planar 3-leg robot"): platform pose (0, 0, 0), so the platform
frame is the world frame, and every joint coordinate 0. Per leg L, the parameter vector holds
(world frame, SI units):

- ``x1_L y1_L x2_L y2_L x3_L y3_L``: the points of joints 1, 2, 3 at home (joint 3's is also
  its point in the platform frame);
- ``uxj_L uyj_L`` for each prismatic joint j: its unit axis at home (the runtime normalises the
  model file's ``axes``);
- ``sigma_L``: +1 or -1, the sign at home of the leg's serial determinant, which picks the
  working mode (the runtime computes it from the joints and axes);
- ``m1_L m2_L``, ``cx1_L cy1_L cx2_L cy2_L``, ``J1_L J2_L``: mass, centre of mass at home and
  inertia about it of bodies 1 and 2;

then the platform's ``m3 cx3 cy3 J3`` (centre of mass in the platform frame, inertia about it),
gravity ``gx gy`` and the payload ``fx fy mz`` (at G).
"""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.planar.geometry import (
    LEGS,
    SHARED_PARAM_DOCS,
    LegGeometry,
    PlatformGeometry,
    Reference,
    Robot,
    reference_joint,
)
from rpr3gen_derive.planar.vectors import Vec, perp, sub

ONE = sp.Integer(1)


def param_names(kinds: str) -> tuple[str, ...]:
    """The parameter vector of a leg type, in order (see the module's docstring)."""
    names: list[str] = []
    for leg in LEGS:
        names += [f"{a}{j}_{leg}" for j in (1, 2, 3) for a in "xy"]
        names += [f"u{a}{j}_{leg}" for j in (1, 2, 3) if kinds[j - 1] == "P" for a in "xy"]
        names.append(f"sigma_{leg}")
        names += [f"m1_{leg}", f"m2_{leg}"]
        names += [f"c{a}{k}_{leg}" for k in (1, 2) for a in "xy"]
        names += [f"J1_{leg}", f"J2_{leg}"]
    return (*names, "m3", "cx3", "cy3", "J3", "gx", "gy", "fx", "fy", "mz")


_POSITIVE = ("m1_", "m2_", "J1_", "J2_")


def param_symbol(name: str) -> sp.Symbol:
    """The symbol of a parameter, with its assumptions (masses and inertias positive)."""
    if name.startswith(_POSITIVE) or name in ("m3", "J3"):
        return sp.Symbol(name, real=True, positive=True)
    return sp.Symbol(name, real=True)


def param_doc(name: str) -> tuple[str, str]:
    """Unit and meaning of a parameter."""
    fixed = {
        "cx3": ("m", "platform centre of mass, platform frame x"),
        "cy3": ("m", "platform centre of mass, platform frame y"),
        "J3": ("kg m^2", "platform inertia about its centre of mass, axis z"),
        **SHARED_PARAM_DOCS,
    }
    if name in fixed:
        return fixed[name]
    base, leg = name.rsplit("_", 1)
    if base == "sigma":
        return "1", f"leg {leg}: sign of its serial determinant at home (the working mode)"
    if base[0] in "xy" and len(base) == 2:
        return "m", f"leg {leg}: joint {base[1]}'s point at home, world {base[0]}0"
    if base.startswith("u"):
        return "1", f"leg {leg}: joint {base[2]}'s unit axis at home, world {base[1]}0"
    if base[0] == "m":
        return "kg", f"leg {leg}: body {base[1]} mass"
    if base[0] == "c":
        return "m", f"leg {leg}: body {base[2]} centre of mass at home, world {base[1]}0"
    return "kg m^2", f"leg {leg}: body {base[1]} inertia about its centre of mass, axis z"


def serial_determinant_at_home(kinds: str, points: tuple[Vec, Vec, Vec], axes: dict) -> sp.Expr:
    """``D`` at home: the determinant of the columns ``(perp(P3 - Pj), 1)`` (revolute j) and
    ``(u_j, 0)`` (prismatic j)."""
    columns = []
    for j in (1, 2, 3):
        if kinds[j - 1] == "R":
            arm = perp(sub(points[2], points[j - 1]))
            columns.append([arm[0], arm[1], ONE])
        else:
            u = axes[j]
            columns.append([u[0], u[1], sp.Integer(0)])
    return sp.expand(sp.Matrix(columns).T.det())


def leg_geometry(kinds: str, leg: str) -> LegGeometry:
    """One leg of the general parametrisation, in its parameter symbols."""
    p = {n: param_symbol(n) for n in param_names(kinds) if n.endswith(f"_{leg}")}
    points = tuple((p[f"x{j}_{leg}"], p[f"y{j}_{leg}"]) for j in (1, 2, 3))
    axes = {j: (p[f"ux{j}_{leg}"], p[f"uy{j}_{leg}"]) for j in (1, 2, 3) if kinds[j - 1] == "P"}
    refs = []
    for body in (1, 2):
        joint = reference_joint(kinds, body)
        if joint is None:
            refs.append(Reference(sub(points[body], points[body - 1])))
        else:
            refs.append(Reference(axes[joint], unit=True))
    coms = [(p[f"cx{k}_{leg}"], p[f"cy{k}_{leg}"]) for k in (1, 2)]
    return LegGeometry(
        leg=leg,
        kinds=kinds,
        points=points,  # type: ignore[arg-type]
        axes=axes,
        platform_point=points[2],
        sigma=p[f"sigma_{leg}"],
        references=(refs[0], refs[1]),
        links=(
            refs[0].coords(sub(points[1], points[0])),
            refs[1].coords(sub(points[2], points[1])),
        ),
        com=(refs[0].coords(sub(coms[0], points[0])), refs[1].coords(sub(coms[1], points[1]))),
        mass=(p[f"m1_{leg}"], p[f"m2_{leg}"]),
        inertia=(p[f"J1_{leg}"], p[f"J2_{leg}"]),
        inertial_x=(refs[0].coords((ONE, sp.Integer(0))), refs[1].coords((ONE, sp.Integer(0)))),
        serial_home=serial_determinant_at_home(kinds, points, axes),  # type: ignore[arg-type]
    )


def robot(kinds: str) -> Robot:
    """A robot of leg type ``kinds`` in the general parametrisation."""
    s = {n: param_symbol(n) for n in ("m3", "cx3", "cy3", "J3", "gx", "gy", "fx", "fy", "mz")}
    return Robot(
        kinds=kinds,
        legs={leg: leg_geometry(kinds, leg) for leg in LEGS},
        platform=PlatformGeometry(s["m3"], (s["cx3"], s["cy3"]), s["J3"]),
        gravity=(s["gx"], s["gy"]),
        payload_force=(s["fx"], s["fy"]),
        payload_moment=s["mz"],
    )
