"""Spatial structures: a leg type and its actuated joint, the legs, the pose and the parameters.

One generated variant serves every robot of a structure (``ups_2``, ``rus_1``, ``rss2_1``, ...),
whatever its numbers: the model's numbers are the parameter vector (docs/spatial-robots.md).
"""

from __future__ import annotations

from dataclasses import dataclass

#: Leg type -> (legs, the actuated joint, the platform's degrees of freedom).
LEG_TYPES: dict[str, tuple[str, int, int]] = {
    "UPS": ("ABCDEF", 2, 6),
    "RUS": ("ABCDEF", 1, 6),
    "PUS": ("ABCDEF", 1, 6),
    "RSS2": ("ABC", 1, 3),
    "PSS2": ("ABC", 1, 3),
}

HEXAPOD_POSE: tuple[str, ...] = ("x", "y", "z", "a", "b", "c")
DELTA_POSE: tuple[str, ...] = ("x", "y", "z")


@dataclass(frozen=True)
class SpatialStructure:
    """A spatial leg type (``kinds``) and its actuated joint."""

    kinds: str
    actuated: int

    def __post_init__(self) -> None:
        if self.kinds not in LEG_TYPES:
            raise ValueError(f"leg type must be one of {', '.join(LEG_TYPES)}, got {self.kinds!r}")
        if self.actuated != LEG_TYPES[self.kinds][1]:
            raise ValueError(
                f"a {self.kinds} leg is actuated at joint {LEG_TYPES[self.kinds][1]}, "
                f"not {self.actuated!r}"
            )

    paper = False
    spatial = True

    @property
    def legs(self) -> str:
        """The legs' letters, ``ABCDEF`` or ``ABC``."""
        return LEG_TYPES[self.kinds][0]

    @property
    def dof(self) -> int:
        """The platform's degrees of freedom: 6 (hexapods) or 3 (Deltas, translation only)."""
        return LEG_TYPES[self.kinds][2]

    @property
    def delta(self) -> bool:
        return self.kinds.endswith("SS2")

    @property
    def pose(self) -> tuple[str, ...]:
        return HEXAPOD_POSE if self.dof == 6 else DELTA_POSE

    @property
    def variant(self) -> str:
        return f"{self.kinds.lower()}_{self.actuated}"

    @property
    def actuated_kind(self) -> str:
        """``"R"`` or ``"P"``: the actuated joint's type."""
        return "R" if self.kinds[self.actuated - 1] == "R" else "P"

    @property
    def title(self) -> str:
        """E.g. ``6-UPS, motors on joint 2``."""
        return f"{len(self.legs)}-{self.kinds}, motors on joint {self.actuated}"


ALL: tuple[SpatialStructure, ...] = tuple(SpatialStructure(k, v[1]) for k, v in LEG_TYPES.items())


def leg_param_names(kinds: str) -> tuple[str, ...]:
    """One leg's parameter names without the leg suffix, in order (docs/spatial-robots.md)."""
    names = ["bx", "by", "bz"]
    if kinds != "UPS":
        names += ["ax", "ay", "az"]
    if kinds in ("UPS", "RUS", "PUS"):
        names += ["u1x", "u1y", "u1z", "u2x", "u2y", "u2z"]
    if kinds != "UPS":
        names += ["ex", "ey", "ez"]
    names += ["px", "py", "pz"]
    if kinds == "PSS2":
        names += ["barx", "bary", "barz"]
    if kinds != "UPS":
        names.append("sigma")
    bodies = 1 if kinds.endswith("SS2") else 2
    names += [f"m{k}" for k in range(1, bodies + 1)]
    names += [f"c{k}{a}" for k in range(1, bodies + 1) for a in "xyz"]
    names += [f"I{k}{e}" for k in range(1, bodies + 1) for e in INERTIA_ENTRIES]
    if kinds.endswith("SS2"):
        names += ["w", "mr", "fr", "Ir"]
    return tuple(names)


#: The six entries of an inertia tensor, in the model file's order.
INERTIA_ENTRIES: tuple[str, ...] = ("xx", "yy", "zz", "xy", "xz", "yz")

PLATFORM_PARAMS: tuple[str, ...] = (
    "m3", "c3x", "c3y", "c3z", *(f"I3{e}" for e in INERTIA_ENTRIES),
    "gx", "gy", "gz", "fx", "fy", "fz", "mx", "my", "mz",
)  # fmt: skip


def param_names(structure: SpatialStructure) -> tuple[str, ...]:
    """The parameter vector of a spatial variant, in order."""
    per_leg = leg_param_names(structure.kinds)
    return (*(f"{n}_{leg}" for leg in structure.legs for n in per_leg), *PLATFORM_PARAMS)


_DOCS: dict[str, tuple[str, str]] = {
    "b": ("m", "joint 1's point at home (UPS: the U centre; else a point on its axis), world"),
    "a": ("1", "joint 1's unit axis (R or P)"),
    "u1": ("1", "the U's first unit axis at home (fixed in the earlier body)"),
    "u2": ("1", "the U's second unit axis at home (fixed in the later body)"),
    "e": ("m", "the elbow at home: the U centre (RUS, PUS), the upper S midpoint (Deltas)"),
    "p": ("m", "the S centre (hexapods) or lower S midpoint (Deltas) at home"),
    "bar": ("1", "the unit direction joining a rod pair (PSS2)"),
    "sigma": ("1", "+1 or -1: the sign of D = (S - E) . dE/dq1 at home (the working mode)"),
    "m": ("kg", "mass of the leg's body"),
    "c": ("m", "centre of mass of the leg's body at home, world"),
    "I": ("kg m^2", "inertia tensor entry about the body's centre of mass, world axes at home"),
    "w": ("m", "distance between the two rods of a leg"),
    "mr": ("kg", "mass of each rod"),
    "fr": ("1", "the rods' centre of mass as a fraction of the rod from its upper S"),
    "Ir": ("kg m^2", "each rod's inertia about its centre of mass, across the rod"),
    "m3": ("kg", "platform mass"),
    "c3": ("m", "platform centre of mass in the platform frame"),
    "I3": ("kg m^2", "platform inertia tensor entry about its centre of mass, platform axes"),
    "g": ("m/s^2", "gravity, world"),
    "f": ("N", "payload force on the platform at its frame's origin, world"),
    "mm": ("N m", "payload moment on the platform, world"),
}


def param_doc(name: str) -> tuple[str, str]:
    """``(unit, meaning)`` of a parameter name."""
    base, _, leg = name.partition("_")
    where = f", leg {leg}" if leg else ""
    if base in ("mx", "my", "mz"):
        unit, meaning = _DOCS["mm"]
        return unit, f"{meaning} ({base[1]})"
    for key in sorted(_DOCS, key=len, reverse=True):
        if base.startswith(key):
            unit, meaning = _DOCS[key]
            return unit, f"{meaning} ({base}){where}"
    raise KeyError(name)
