"""The inertial parameters of a spatial robot and how its regressor is composed
(docs/spatial-robots.md, "Identification").

The efforts are linear in the inertial parameters ``pi`` (docs/interfaces.md): per body ``m``,
``mcx, mcy, mcz`` and ``Ixx, Iyy, Izz, Ixy, Ixz, Iyz`` about its first joint point (world axes at
home, moving with the body; the platform's about its frame's origin, platform axes); per rod of a
Delta (both rods of a leg share them) ``m``, ``mc`` (along the rod from its upper S) and ``I``
(across the rod, about its upper S). The inverse dynamics is written in the model's numbers
(mass, centre of mass, inertia about the centre of mass), which map onto ``pi`` by the parallel
axis theorem; since the map is onto, column ``j`` of ``Y`` is the inverse dynamics' efforts for
model numbers whose ``pi`` is the unit vector ``e_j`` (every other body massless, no payload,
gravity kept):

- ``m``: ``m = 1``, the centre of mass on the reference point, no inertia;
- ``mcx``: ``m = 1``, the centre of mass one metre along x from the reference point, inertia about
  it ``-(E - x x^T)`` so that the inertia about the reference point is zero; minus the ``m``
  column;
- ``Ixx`` ...: ``m = 0``, the one tensor entry 1;
- a rod's ``mc``: ``m = 1``, ``fr = 1 / L``, ``Ir = -1``, minus its ``m`` column.

The C body (``templates/spatial_regressor.c.jinja``) and the runtime's NumPy composition
(``rpr3gen.composed``) evaluate these ``P`` inverse dynamics.
"""

from __future__ import annotations

from dataclasses import dataclass

from rpr3gen_derive.spatial.structures import (
    INERTIA_ENTRIES,
    PLATFORM_PARAMS,
    SpatialStructure,
    param_names,
)

#: A body's ten quantities, in order.
BODY_QUANTITIES: tuple[str, ...] = ("m", "mcx", "mcy", "mcz", *(f"I{e}" for e in INERTIA_ENTRIES))
#: A rod's three quantities (both rods of a Delta's leg share them).
ROD_QUANTITIES: tuple[str, ...] = ("m", "mc", "I")
#: The payload's parameters (zeroed: the payload's efforts are apart, ``tau_payload``).
PAYLOAD: tuple[str, ...] = ("fx", "fy", "fz", "mx", "my", "mz")


@dataclass(frozen=True)
class Body:
    """One body's place in ``pi`` and in the parameter vector.

    ``name``: ``1A``, ``2A``, ``rA`` (a Delta leg's rods) or ``3`` (the platform); ``rod``:
    whether it is a rod pair; ``mass``, ``com`` (3), ``inertia`` (6): the indices of its model
    numbers (a rod: ``mr``, ``fr``, ``Ir``); ``reference``: the indices of its reference point's
    coordinates (None: the origin); a rod's ``reference`` is its upper S midpoint ``e`` and
    ``tip`` its lower ``p`` (``L = |p - e|``).
    """

    name: str
    rod: bool
    mass: int
    com: tuple[int, ...]
    inertia: tuple[int, ...]
    reference: tuple[int, ...] | None
    tip: tuple[int, ...] | None = None

    @property
    def quantities(self) -> tuple[str, ...]:
        return ROD_QUANTITIES if self.rod else BODY_QUANTITIES


def bodies(structure: SpatialStructure) -> tuple[Body, ...]:
    """The moving bodies in ``pi``'s order: per leg its bodies 1 and 2 (hexapods) or 1 and its
    rods (Deltas), then the platform."""
    names = param_names(structure)

    def at(*keys: str) -> tuple[int, ...]:
        return tuple(names.index(k) for k in keys)

    out = []
    for leg in structure.legs:

        def p(key: str, leg: str = leg) -> str:
            return f"{key}_{leg}"

        b = at(*(p(f"b{a}") for a in "xyz"))
        e = at(*(p(f"e{a}") for a in "xyz")) if structure.kinds != "UPS" else b
        for k in (1, 2) if not structure.delta else (1,):
            out.append(
                Body(
                    name=f"{k}{leg}",
                    rod=False,
                    mass=names.index(p(f"m{k}")),
                    com=at(*(p(f"c{k}{a}") for a in "xyz")),
                    inertia=at(*(p(f"I{k}{x}") for x in INERTIA_ENTRIES)),
                    reference=b if k == 1 else e,
                )
            )
        if structure.delta:
            out.append(
                Body(
                    name=f"r{leg}",
                    rod=True,
                    mass=names.index(p("mr")),
                    com=at(p("fr")),
                    inertia=at(p("Ir")),
                    reference=e,
                    tip=at(*(p(f"p{a}") for a in "xyz")),
                )
            )
    out.append(
        Body(
            name="3",
            rod=False,
            mass=names.index("m3"),
            com=at(*(f"c3{a}" for a in "xyz")),
            inertia=at(*(f"I3{x}" for x in INERTIA_ENTRIES)),
            reference=None,
        )
    )
    return tuple(out)


def parameter_names(structure: SpatialStructure) -> tuple[str, ...]:
    """``pi``'s names: ``m_1A, mcx_1A, ..., Iyz_1A, ...`` (rods ``m_rA, mc_rA, I_rA``), then
    the platform's ``m_3 ... Iyz_3``."""
    return tuple(f"{q}_{b.name}" for b in bodies(structure) for q in b.quantities)


def zeroed(structure: SpatialStructure) -> tuple[int, ...]:
    """The parameters zeroed in every evaluation: every body's mass and inertia, the payload."""
    names = param_names(structure)
    out = [names.index(n) for n in PAYLOAD]
    for b in bodies(structure):
        out += [b.mass, *b.inertia]
    assert set(PAYLOAD) <= set(PLATFORM_PARAMS)
    return tuple(sorted(out))
