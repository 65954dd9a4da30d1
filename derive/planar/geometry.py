"""What the derivation knows of a robot's geometry and inertia: symbolic, leg by leg.

The derivation (kinematics, dynamics, virtual work) reads a robot through :class:`Robot`: per leg
a :class:`LegGeometry` (joint points and axes when every joint coordinate is zero, the bodies'
reference vectors, masses, centres of mass, inertias), the platform, gravity and the payload.
Every number is a symbol of the parameter vector, or an expression of them, so one derivation
serves every robot of a structure.

A *parametrisation* builds a :class:`Robot` from a parameter vector: :mod:`.general` (the
general model file, any leg type) and :mod:`.paper` (the paper's 3-RPR and its parameters). The
same derivation runs on both.

Body coordinates. Each moving body of a leg has a *reference*: a vector fixed in the body, whose
value at zero joint coordinates is ``Reference.home`` (chosen by :func:`reference_joint`: the
axis of a prismatic joint of the body, else the link from its first joint point to its second).
A vector of the body is written by its coordinates ``(a, b)`` in the basis ``(h, perp(h))`` of
its reference: once the leg has moved, it is ``a c + b perp(c)``, ``c`` the reference's current
value (:func:`.vectors.along`). So no rotation matrix of a body is ever formed from an angle.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar.vectors import Vec, cross, dot, norm2, scale

LEGS: tuple[str, ...] = ("A", "B", "C")


@dataclass(frozen=True)
class Reference:
    """A vector fixed in a body: its value at zero joint coordinates (world frame).

    ``unit``: its length is 1 by construction (a prismatic joint's axis, normalised when the
    parameters are made), so no division by its length is needed. ``angle``: its angle from
    x0, when the parameters give it (the paper's ``alpha``), which saves an ``atan2`` of
    parameters when a joint angle is measured from it.
    """

    home: Vec
    unit: bool = False
    angle: sp.Expr | None = None
    squared_length: sp.Expr | None = None  # |home|^2 when named in a program

    @property
    def length2(self) -> sp.Expr:
        """``|home|^2``."""
        if self.unit:
            return sp.Integer(1)
        return self.squared_length if self.squared_length is not None else norm2(self.home)

    def coords(self, v: Vec) -> Vec:
        """Coordinates of the home vector ``v`` in the basis ``(home, perp(home))``."""
        k = 1 / self.length2
        return scale(k, (dot(self.home, v), cross(self.home, v)))


@dataclass(frozen=True)
class LegGeometry:
    """One leg, at zero joint coordinates (world frame, m, kg, kg m^2).

    Attributes:
        leg: "A", "B" or "C".
        kinds: the joint types from base to platform, e.g. ``"RPR"``.
        points: the points of joints 1, 2, 3 (a joint's point is fixed in its later body).
        axes: the unit axis of each prismatic joint, by joint number (1, 2, 3).
        platform_point: joint 3's point in the platform frame.
        sigma: the sign (+1 or -1) of the leg's serial determinant
            ``D = det d(x3, y3, phi) / d(q1, q2, q3)`` in its working mode.
        references: the reference vectors of bodies 1 and 2.
        links: body coordinates of ``points[1] - points[0]`` (in body 1) and of
            ``points[2] - points[1]`` (in body 2): where the next joint's point is, at a zero
            coordinate of that joint.
        com: body coordinates of each body's centre of mass from its first joint point.
        mass: of bodies 1 and 2.
        inertia: of bodies 1 and 2 about their centres of mass, axis z.
        inertial_x: body coordinates of the x axis of each body's frame of inertial parameters
            (identification): the world's x0 at home (general format) or the reference itself.
        serial_home: ``D`` at zero joint coordinates, or None when the parametrisation measures
            serial singularities otherwise (the paper's ``reach``).
    """

    leg: str
    kinds: str
    points: tuple[Vec, Vec, Vec]
    axes: dict[int, Vec]
    platform_point: Vec
    sigma: sp.Expr
    references: tuple[Reference, Reference]
    links: tuple[Vec, Vec]
    com: tuple[Vec, Vec]
    mass: tuple[sp.Expr, sp.Expr]
    inertia: tuple[sp.Expr, sp.Expr]
    inertial_x: tuple[Vec, Vec]
    serial_home: sp.Expr | None = None

    def axis(self, joint: int) -> Vec:
        """The unit axis of prismatic joint ``joint`` (1, 2 or 3) at zero coordinates."""
        return self.axes[joint]


@dataclass(frozen=True)
class PlatformGeometry:
    """The platform: mass (kg), centre of mass in the platform frame (m), inertia about it."""

    mass: sp.Expr
    com: Vec
    inertia: sp.Expr


@dataclass(frozen=True)
class JointNames:
    """Names of the joint coordinates, rates and accelerations (per joint 1, 2, 3)."""

    q: tuple[str, str, str]
    qd: tuple[str, str, str]
    qdd: tuple[str, str, str]


GENERAL_NAMES = JointNames(("q1", "q2", "q3"), ("qd1", "qd2", "qd3"), ("qdd1", "qdd2", "qdd3"))


@dataclass(frozen=True)
class Robot:
    """Everything the derivation reads of a robot, as symbols of its parameter vector."""

    kinds: str
    legs: dict[str, LegGeometry]
    platform: PlatformGeometry
    gravity: Vec
    payload_force: Vec
    payload_moment: sp.Expr
    names: JointNames = GENERAL_NAMES


#: Unit and meaning of the parameters every parametrisation shares: the platform's mass, gravity
#: and the payload (docs/interfaces.md).
SHARED_PARAM_DOCS: dict[str, tuple[str, str]] = {
    "m3": ("kg", "platform mass"),
    "gx": ("m/s^2", "gravity, world x0"),
    "gy": ("m/s^2", "gravity, world y0 (up)"),
    "fx": ("N", "payload force on the platform at G, x0"),
    "fy": ("N", "payload force on the platform at G, y0"),
    "mz": ("N m", "payload moment on the platform, about z0"),
}


STEP_CONSTANTS = "the model's constants: body coordinates of points, from the parameters"


def named_constants(prog: Program, robot: Robot) -> Robot:
    """``robot`` with every derived constant of its legs named in ``prog`` (``a12_A`` ...).

    The parametrisation writes body coordinates and the like as expressions of the parameters;
    named once, the derivation treats them as atoms (no expanding of products of them), and the
    generated code computes each once per call. Atoms (the paper's ``l0``, ``c1`` ...) stay.
    """

    def name(leg: str, label: str, expr: sp.Expr) -> sp.Expr:
        return prog.define(f"{label}_{leg}", expr, STEP_CONSTANTS)

    def pair(leg: str, label: str, v: Vec) -> Vec:
        return (name(leg, f"{label}a", v[0]), name(leg, f"{label}b", v[1]))

    legs = {}
    for leg, g in robot.legs.items():
        refs: tuple[Reference, ...] = tuple(
            ref
            if ref.unit
            else dataclasses.replace(ref, squared_length=name(leg, f"h{k + 1}sq", norm2(ref.home)))
            for k, ref in enumerate(g.references)
        )
        legs[leg] = dataclasses.replace(
            g,
            references=(refs[0], refs[1]),
            links=(pair(leg, "l12", g.links[0]), pair(leg, "l23", g.links[1])),
            com=(pair(leg, "c1", g.com[0]), pair(leg, "c2", g.com[1])),
            serial_home=None if g.serial_home is None else name(leg, "D0", g.serial_home),
        )
    return dataclasses.replace(robot, legs=legs)


def reference_joint(kinds: str, body: int) -> int | None:
    """Which joint's axis is body ``body``'s (1 or 2) reference, or None for its link.

    The axis of a prismatic joint is fixed in both bodies it joins: the later one's (joint
    ``body + 1``) if prismatic, else the earlier one's (joint ``body``); a body between two
    revolute joints takes the link from its first joint point to its second.
    """
    if kinds[body] == "P":
        return body + 1
    if kinds[body - 1] == "P":
        return body
    return None
