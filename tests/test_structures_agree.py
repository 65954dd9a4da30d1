"""The derivation and the runtime each know the structures (they may not import each other:
docs/architecture.md): their two descriptions must agree, so that a new leg type added to
``derive/planar/legs.py`` and not to ``src/rpr3gen/structure.py`` (or the reverse) fails here."""

from __future__ import annotations

import planar_reference as pr
import pytest
from rpr3gen_derive.planar import direct_kinematics, legs
from rpr3gen_derive.planar import structures as derived

from rpr3gen import structure as runtime


def test_the_leg_types_are_the_same_everywhere() -> None:
    assert tuple(legs.LEG_TYPES) == runtime.LEG_TYPES == pr.LEG_TYPES
    assert derived.PAPER_ACTUATIONS == runtime.PAPER_ACTUATIONS


@pytest.mark.parametrize("d", derived.ALL + derived.PAPER, ids=lambda s: s.variant)
def test_each_structure_is_described_alike(d: derived.Structure) -> None:
    r = runtime.Structure.of_variant(d.variant)
    assert (r.leg, r.actuated, r.paper) == (d.kinds, d.actuated, d.paper)
    assert r.variant == d.variant
    assert r.actuated_kind == d.actuated_kind
    assert r.singular == d.singular
    assert r.hold == direct_kinematics.locked_kind(d.kinds, d.actuated)
    assert r.title == d.title.removesuffix(" (the paper's parameters)")


def test_the_runtime_lists_every_structure_of_the_derivation() -> None:
    assert [s.variant for s in runtime.ALL] == [s.variant for s in derived.ALL]
