"""Structures: a leg type and the joint that carries the motors, in a parametrisation.

A *structure* is what one generated variant serves: every robot of a leg type with its motors on
one joint, whatever its numbers. Two parametrisations exist (:mod:`.general`, :mod:`.paper`):
the general model file's (any of the 21 structures) and the paper's (the 3-RPR with its motors
at the base, ``revolute``, or on the slides, ``prismatic``), whose variants keep the paper's
names and parameters.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from rpr3gen_derive.planar import general, paper
from rpr3gen_derive.planar.geometry import Robot
from rpr3gen_derive.planar.legs import LEG_TYPES

#: The paper's variants: actuation scheme -> actuated joint of its RPR legs.
PAPER_ACTUATIONS: dict[str, int] = {"revolute": 1, "prismatic": 2}


@dataclass(frozen=True)
class Structure:
    """A leg type (``kinds``), its actuated joint (1, 2 or 3) and the parametrisation."""

    kinds: str
    actuated: int
    paper: bool = False

    def __post_init__(self) -> None:
        if self.kinds not in LEG_TYPES:
            raise ValueError(f"leg type must be one of {', '.join(LEG_TYPES)}, got {self.kinds!r}")
        if self.actuated not in (1, 2, 3):
            raise ValueError(f"the actuated joint must be 1, 2 or 3, got {self.actuated!r}")
        if self.paper and (self.kinds, self.actuated) not in (("RPR", 1), ("RPR", 2)):
            raise ValueError("the paper's parametrisation is the 3-RPR with actuated joint 1 or 2")

    @property
    def variant(self) -> str:
        """The generated folder's name: ``revolute``/``prismatic`` (paper), ``rrr_1`` ..."""
        if self.paper:
            return next(k for k, v in PAPER_ACTUATIONS.items() if v == self.actuated)
        return f"{self.kinds.lower()}_{self.actuated}"

    @property
    def actuated_kind(self) -> str:
        """``"R"`` or ``"P"``: the actuated joint's type."""
        return self.kinds[self.actuated - 1]

    @property
    def title(self) -> str:
        """E.g. ``3-RRR, motors on joint 1``."""
        paper_ = " (the paper's parameters)" if self.paper else ""
        return f"3-{self.kinds}, motors on joint {self.actuated}{paper_}"

    @property
    def singular(self) -> bool:
        """Architecturally singular: both passive joints prismatic, so every motor only sees
        the platform angle and the platform's translation is not controlled."""
        return all(self.kinds[j - 1] == "P" for j in (1, 2, 3) if j != self.actuated)


def from_variant(variant: str) -> Structure:
    """The structure of a variant name (inverse of :attr:`Structure.variant`)."""
    if variant in PAPER_ACTUATIONS:
        return Structure("RPR", PAPER_ACTUATIONS[variant], paper=True)
    kinds, _, joint = variant.partition("_")
    if not joint.isdigit():
        raise ValueError(f"not a variant name: {variant!r}")
    return Structure(kinds.upper(), int(joint))


#: Every structure of the general format, singular ones included (21).
ALL: tuple[Structure, ...] = tuple(Structure(k, a) for k in LEG_TYPES for a in (1, 2, 3))
#: The ones rpr3gen derives (18): not architecturally singular.
DERIVABLE: tuple[Structure, ...] = tuple(s for s in ALL if not s.singular)
#: The paper's two.
PAPER: tuple[Structure, ...] = tuple(Structure("RPR", a, paper=True) for a in (1, 2))


@cache
def robot(structure: Structure) -> Robot:
    """The symbolic robot of a structure (its parametrisation's parameters)."""
    return paper.robot() if structure.paper else general.robot(structure.kinds)


def param_names(structure: Structure) -> tuple[str, ...]:
    """The parameter vector of a structure's variant."""
    return paper.PARAM_NAMES if structure.paper else general.param_names(structure.kinds)
