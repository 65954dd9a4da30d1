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


def test_every_spatial_robot_of_the_gallery_is_measured_on_its_trajectory(
    samples: ModuleType,
) -> None:
    """The hexapods and Deltas of ``models/``, on their trajectories; the tracked forward
    kinematics' reference is the pose one tick before. Only the committed variants are
    evaluated (no derivation)."""
    assert samples.spatial() == ("ups_2", "rus_1", "pus_1", "rss2_1", "pss2_1")
    assert samples.gallery()["ups_2"].name == "tsai-ups.toml"
    for variant in ("ups_2", "rss2_1"):
        assert samples.motions(variant) == ("trajectory",)
        arrays = samples.trajectory(variant, 401)
        dof = 6 if variant == "ups_2" else 3
        assert all(a.shape == (401, dof) and a.flags.c_contiguous for a in arrays.values())
        assert np.all(np.ptp(arrays["q"], axis=0) > 0)  # every coordinate moves
        step = np.abs(arrays["q"] - arrays["q_near"]).max()
        assert 0 < step < np.abs(np.diff(arrays["q"], axis=0)).max() * 2  # a tick, not a sample
        assert samples.measured(variant) == list(samples.SPATIAL_FUNCTIONS)
        found, robot = samples.code(variant), samples.model(variant)
        for name in samples.measured(variant):
            f = found.function(name)
            given = samples.inputs(variant, f, arrays)
            assert [a.shape for a in given] == [(401, x.size) for x in f.inputs]
            _, codes = rpr3gen.evaluate(robot, name, given, backend="c")
            assert not np.any(codes), name
