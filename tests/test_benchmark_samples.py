"""The benchmarks' samples (``benchmarks/harness/samples.py``): a model of every structure, of
that structure, and a generic motion that the runtime evaluates at every sample. Nothing is
timed here, and no variant is derived (the motion is checked on ``rrr_1``, which the package
carries)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

import rpr3gen


@pytest.fixture(scope="module")
def samples(repo_root: Path) -> ModuleType:
    path = repo_root / "benchmarks" / "harness" / "samples.py"
    spec = importlib.util.spec_from_file_location("rpr3bench_samples", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_structure_has_a_model_of_its_own(samples: ModuleType) -> None:
    names = samples.structures()
    assert len(names) == 18
    assert {"rpr_1", "rrr_1", "ppr_2", "rpp_3"} <= set(names)
    assert not {"ppr_3", "prp_2", "rpp_1"} & set(names)  # the architecturally singular ones
    for variant in names:
        model = samples.model(variant)
        assert model.variant == variant
        assert not model.structure.paper
    gallery = samples.gallery()
    assert gallery["rrr_1"].name == "rrr.toml"
    assert gallery["rpr_1"].name == "paper-general.toml"  # the paper's robot, general format
    for variant, path in gallery.items():
        assert samples.model_source(variant) == f"models/{path.name}"
        assert samples.model(variant).params == rpr3gen.load_model(path).params
    assert samples.model_source("prp_3").startswith("random_model")


def test_generic_motion_moves_every_coordinate_and_is_valid(samples: ModuleType) -> None:
    arrays = samples.motion("rrr_1", "generic", 301)
    assert all(a.shape == (301, 3) and a.flags.c_contiguous for a in arrays.values())
    assert np.all(np.ptp(arrays["q"], axis=0) > 0.01)  # x, y and phi all move
    assert samples.valid("rrr_1", arrays)
    assert not samples.valid("rrr_1", samples.generic(301, 6.0))  # out of reach
