"""Structures: a leg type and the joint that carries the motors, as the runtime knows them.

A structure selects a generated variant: one folder of generated code serves every robot of a
leg type with its motors on one joint, whatever its numbers. The runtime knows the naming rules
(variant folders, parameter and output names, docs/interfaces.md); what the generated code
computes, it learns from the variant's manifest.

Two model formats exist: the paper's (the 3-RPR, ``actuation = "revolute"`` or
``"prismatic"``, the paper's parameter and output names) and the general one (any leg type,
everything given at home, names ``q1_A``, ``fx2_B``, ``tau_C``).
"""

from __future__ import annotations

from dataclasses import dataclass

from rpr3gen.errors import ModelError

LEGS: tuple[str, ...] = ("A", "B", "C")

#: Every leg type, joint types from base to platform (PPP cannot turn the platform).
LEG_TYPES: tuple[str, ...] = ("RRR", "RPR", "RRP", "PRR", "PPR", "PRP", "RPP")

#: The spatial leg types (docs/spatial-robots.md): leg type -> (legs, actuated joint, the
#: platform's degrees of freedom).
SPATIAL_LEG_TYPES: dict[str, tuple[str, int, int]] = {
    "UPS": ("ABCDEF", 2, 6),
    "RUS": ("ABCDEF", 1, 6),
    "PUS": ("ABCDEF", 1, 6),
    "RSS2": ("ABC", 1, 3),
    "PSS2": ("ABC", 1, 3),
}

#: The six entries of an inertia tensor, in the model file's order.
INERTIA_ENTRIES: tuple[str, ...] = ("xx", "yy", "zz", "xy", "xz", "yz")

#: The spatial platform's parameters, after the legs'.
SPATIAL_PLATFORM_PARAMS: tuple[str, ...] = (
    "m3", "c3x", "c3y", "c3z", *(f"I3{e}" for e in INERTIA_ENTRIES),
    "gx", "gy", "gz", "fx", "fy", "fz", "mx", "my", "mz",
)  # fmt: skip


def spatial_leg_params(leg: str) -> tuple[str, ...]:
    """One spatial leg's parameter names without the leg suffix, in order."""
    names = ["bx", "by", "bz"]
    if leg != "UPS":
        names += ["ax", "ay", "az"]
    if leg in ("UPS", "RUS", "PUS"):
        names += ["u1x", "u1y", "u1z", "u2x", "u2y", "u2z"]
    if leg != "UPS":
        names += ["ex", "ey", "ez"]
    names += ["px", "py", "pz"]
    if leg == "PSS2":
        names += ["barx", "bary", "barz"]
    if leg != "UPS":
        names.append("sigma")
    bodies = 1 if leg.endswith("SS2") else 2
    names += [f"m{k}" for k in range(1, bodies + 1)]
    names += [f"c{k}{a}" for k in range(1, bodies + 1) for a in "xyz"]
    names += [f"I{k}{e}" for k in range(1, bodies + 1) for e in INERTIA_ENTRIES]
    if leg.endswith("SS2"):
        names += ["w", "mr", "fr", "Ir"]
    return tuple(names)


#: The paper's variants: actuation scheme -> actuated joint of its RPR legs.
PAPER_ACTUATIONS: dict[str, int] = {"revolute": 1, "prismatic": 2}

#: How a leg locked at its motor holds the platform, by its passive joints in chain order.
_HOLD = {"RR": "circle", "PR": "line", "RP": "platform_line", "PP": "angle"}


@dataclass(frozen=True)
class Structure:
    """A leg type (``leg``), its actuated joint (1, 2 or 3) and the model format (``paper``)."""

    leg: str
    actuated: int
    paper: bool = False

    def __post_init__(self) -> None:
        if self.leg in SPATIAL_LEG_TYPES:
            joint = SPATIAL_LEG_TYPES[self.leg][1]
            if self.actuated != joint:
                raise ModelError(
                    f"actuated: a {self.leg} leg carries its motor on joint {joint}, got "
                    f"{self.actuated!r}"
                )
            return
        if self.leg not in LEG_TYPES:
            every = (*LEG_TYPES, *SPATIAL_LEG_TYPES)
            raise ModelError(f"leg: must be one of {', '.join(every)}, got {self.leg!r}")
        if self.actuated not in (1, 2, 3):
            raise ModelError(f"actuated: must be 1, 2 or 3, got {self.actuated!r}")

    @property
    def spatial(self) -> bool:
        """A spatial robot (a hexapod or a Delta; docs/spatial-robots.md)."""
        return self.leg in SPATIAL_LEG_TYPES

    @property
    def legs(self) -> tuple[str, ...]:
        """The legs' letters: A, B, C (planar robots and Deltas) or A to F (hexapods)."""
        return tuple(SPATIAL_LEG_TYPES[self.leg][0]) if self.spatial else LEGS

    @property
    def dof(self) -> int:
        """The platform's degrees of freedom, the size of ``q``: 3 (planar robots and Deltas)
        or 6 (hexapods)."""
        return SPATIAL_LEG_TYPES[self.leg][2] if self.spatial else 3

    @property
    def pose(self) -> tuple[str, ...]:
        """The pose coordinates' names: ``x, y, phi``; ``x, y, z, a, b, c``; or ``x, y, z``."""
        if not self.spatial:
            return ("x", "y", "phi")
        return ("x", "y", "z", "a", "b", "c") if self.dof == 6 else ("x", "y", "z")

    @classmethod
    def of_variant(cls, variant: str) -> Structure:
        """The structure of a variant's folder name (``revolute``, ``rrr_1``, ...)."""
        if variant in PAPER_ACTUATIONS:
            return cls("RPR", PAPER_ACTUATIONS[variant], paper=True)
        leg, _, joint = variant.partition("_")
        if not joint.isdigit():
            raise ModelError(f"not a variant name: {variant!r}")
        return cls(leg.upper(), int(joint))

    @property
    def variant(self) -> str:
        """The generated folder's name: ``revolute``/``prismatic`` (paper), else ``rrr_1`` ..."""
        if self.paper:
            return next(k for k, v in PAPER_ACTUATIONS.items() if v == self.actuated)
        return f"{self.leg.lower()}_{self.actuated}"

    @property
    def actuated_kind(self) -> str:
        """``"R"`` or ``"P"``: the actuated joint's type."""
        return "R" if self.leg[self.actuated - 1] == "R" else "P"

    @property
    def actuation(self) -> str:
        """``"revolute"`` or ``"prismatic"``: the kind of the motors (the paper's names)."""
        return "revolute" if self.actuated_kind == "R" else "prismatic"

    @property
    def title(self) -> str:
        """E.g. ``3-RRR, motors on joint 1`` or ``6-UPS, motors on joint 2``."""
        return f"{len(self.legs)}-{self.leg}, motors on joint {self.actuated}"

    @property
    def hold(self) -> str:
        """How a locked leg holds the platform: ``circle``, ``line``, ``platform_line`` or
        ``angle`` (architecturally singular)."""
        if self.spatial:
            return "spatial"
        return _HOLD["".join(self.leg[j - 1] for j in (1, 2, 3) if j != self.actuated)]

    @property
    def singular(self) -> bool:
        """Both passive joints prismatic: every motor only sees the platform angle, so the
        platform's translation is not controlled (PPR/3, PRP/2, RPP/1)."""
        return self.hold == "angle"

    @property
    def max_modes(self) -> int:
        """The most assembly modes of one set of actuator coordinates."""
        return 6 if self.hold == "circle" else 2

    def coordinate(self, joint: int) -> str:
        """The output family of joint ``joint``'s coordinate (``q2``; the paper's ``lambda21``)."""
        if self.paper:
            return ("phi10", "lambda21", "phi32")[joint - 1]
        return f"q{joint}"

    def rate(self, joint: int) -> str:
        """The output family of joint ``joint``'s rate (``qd2``; the paper's ``v21``)."""
        if self.paper:
            return ("omega10", "v21", "omega32")[joint - 1]
        return f"qd{joint}"

    def acceleration(self, joint: int) -> str:
        """The output family of joint ``joint``'s acceleration (``qdd2``; ``gamma21``)."""
        if self.paper:
            return ("eps10", "gamma21", "eps32")[joint - 1]
        return f"qdd{joint}"

    @property
    def effort(self) -> str:
        """The output family of the actuator efforts (``tau``; the paper's ``m10``, ``f21z``)."""
        if self.paper:
            return "m10" if self.actuated == 1 else "f21z"
        return "tau"

    @property
    def actuator(self) -> str:
        """The output family of the actuator coordinates."""
        return self.coordinate(self.actuated)

    def limited_coordinates(self) -> tuple[str, ...]:
        """The joint coordinates a model's ``[limits]`` may bound, per leg (``q2``; a U's
        ``q1a``, ``q1b``): every R, P and U joint's (a spatial robot's S joints have none).
        The paper's format bounds its pistons with ``stroke`` instead: none."""
        if self.paper:
            return ()
        if not self.spatial:
            return ("q1", "q2", "q3")
        if self.leg.endswith("SS2"):
            return ("q1",)
        out: list[str] = []
        for j, kind in enumerate(self.leg[:2], start=1):
            out += [f"q{j}a", f"q{j}b"] if kind == "U" else [f"q{j}"]
        return tuple(out)

    def param_names(self) -> tuple[str, ...]:
        """The parameter vector of the structure's variant, in order (docs/interfaces.md)."""
        if self.paper:
            return PAPER_PARAM_NAMES
        if self.spatial:
            per_leg = spatial_leg_params(self.leg)
            legs = [f"{n}_{leg}" for leg in self.legs for n in per_leg]
            return (*legs, *SPATIAL_PLATFORM_PARAMS)
        names: list[str] = []
        for leg in LEGS:
            names += [f"{a}{j}_{leg}" for j in (1, 2, 3) for a in "xy"]
            names += [f"u{a}{j}_{leg}" for j in (1, 2, 3) if self.leg[j - 1] == "P" for a in "xy"]
            names.append(f"sigma_{leg}")
            names += [f"m1_{leg}", f"m2_{leg}"]
            names += [f"c{a}{k}_{leg}" for k in (1, 2) for a in "xy"]
            names += [f"J1_{leg}", f"J2_{leg}"]
        return (*names, "m3", "cx3", "cy3", "J3", "gx", "gy", "fx", "fy", "mz")


#: The paper's parameter vector (docs/interfaces.md, "Generated C").
PAPER_PARAM_NAMES: tuple[str, ...] = (
    "xA1", "yA1", "xB1", "yB1", "xC1", "yC1",
    "xA3", "yA3", "xB3", "yB3", "xC3", "yC3",
    "alpha_A", "alpha_B", "alpha_C",
    "l0", "l2", "c1", "c2", "m1", "m2", "m3", "J1", "J2", "J3",
    "gx", "gy", "fx", "fy", "mz",
    "c1_perp", "c2_perp",
)  # fmt: skip

#: Every structure of the general format (21), singular ones included.
ALL: tuple[Structure, ...] = tuple(Structure(leg, a) for leg in LEG_TYPES for a in (1, 2, 3))


def planar_only(structure: Structure, what: str) -> None:
    """Refuse a spatial robot where ``what`` serves planar robots only so far.

    Raises:
        ModelError: naming ``what`` and the structure (a ``ValueError``).
    """
    if structure.spatial:
        raise ModelError(
            f"{what}: not available for spatial robots yet (the {structure.title}); "
            "docs/spatial-robots.md lists what is"
        )


#: The spatial structures (5).
SPATIAL: tuple[Structure, ...] = tuple(Structure(k, v[1]) for k, v in SPATIAL_LEG_TYPES.items())
