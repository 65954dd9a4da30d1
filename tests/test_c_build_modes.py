"""The C build of a first use (``rpr3gen.cbackend.library_path``, docs/c-abi.md): a quick
library (-O1, or -O0 for a large unit) at once and the optimised one (-O3, link-time
optimisation) in a process of its own, for the next first use; the three give the same bits for
every function. And the build modes of ``RPR3GEN_C_BUILD``."""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen import cbackend, manifest
from rpr3gen.manifest import FunctionInfo, Variant


@pytest.fixture
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty cache, and no library or background build of this process's in sight."""
    monkeypatch.setenv("RPR3GEN_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(cbackend, "_LIBRARIES", {})
    monkeypatch.setattr(cbackend, "BACKGROUND", {})
    return tmp_path


def _motion(model: rpr3gen.Model, n: int = 211) -> dict[str, np.ndarray]:
    """Inputs by name along a motion in which x, y and phi all move."""
    t = np.linspace(0.0, 3.0, n)[:, None]
    amplitude, rate = np.array([0.03, 0.025, 0.2]), np.array([2.1, 2.7, 3.6])
    q = amplitude * np.sin(rate * t + [0.0, 0.7, 1.9])
    qd = amplitude * rate * np.cos(rate * t + [0.0, 0.7, 1.9])
    motion = {"q": q, "qd": qd, "qdd": -(rate**2) * q, "qa_dot": np.cos(rate * t),
              "tau": np.sin(rate * t), "q_near": q + 1e-3}  # fmt: skip
    motion["qa"] = rpr3gen.actuator_coordinates(model, q)
    return motion


def _batch(
    library: cbackend.Library, info: FunctionInfo, params: np.ndarray, inputs: list[np.ndarray]
) -> list[np.ndarray]:
    """``info``'s batch through ``library``: its outputs, rows of NaN where a sample failed."""
    n = len(inputs[0])
    outputs = [np.empty((n, o.size)) for o in info.public_outputs]
    ptr = ctypes.c_void_p
    library.entries[info.name].batch(
        ptr(params.ctypes.data), n, *(ptr(a.ctypes.data) for a in (*inputs, *outputs))
    )
    return outputs


def _outputs(library: cbackend.Library, variant: Variant, model: rpr3gen.Model) -> dict:
    motion = _motion(model)
    params = np.ascontiguousarray(model.vector(variant.param_names))
    found = {}
    for name, info in variant.functions.items():
        if info.unit or not all(a.name in motion for a in info.inputs):
            continue
        inputs = [np.ascontiguousarray(motion[a.name], dtype=float) for a in info.inputs]
        found[name] = _batch(library, info, params, inputs)
    return found


def test_a_first_use_runs_quick_and_optimises_in_the_background(
    own_cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("RPR3GEN_C_BUILD", "background")
    variant = manifest.load("revolute")
    model = rpr3gen.load_model()
    quick = cbackend.library_path(variant)
    quick_library = cbackend.Library(variant)
    builder = cbackend.BACKGROUND[(variant.folder, "")]
    assert builder.wait() == 0  # the optimised build, in a process of its own
    optimised = cbackend.library_path(variant)
    assert optimised != quick
    assert {quick.name, optimised.name} <= {p.name for p in own_cache.iterdir()}
    assert cbackend.library_path(variant) == optimised  # found, not built again
    assert len(cbackend.BACKGROUND) == 1  # and nothing more started
    optimised_library = cbackend.Library(variant)
    monkeypatch.setattr(cbackend, "QUICK_LARGE", 0)  # a quick build at -O0, as of a large unit
    unoptimised = cbackend._plans(variant, "")[1]
    assert "-O0" in unoptimised.cflags
    monkeypatch.setattr(cbackend, "library_path", lambda variant, unit="": unoptimised.target)
    cbackend._built(variant, unoptimised)
    unoptimised_library = cbackend.Library(variant)
    b = _outputs(optimised_library, variant, model)
    assert {"inverse_dynamics", "forward_dynamics", "assembly_modes"} <= set(b)
    for library in (quick_library, unoptimised_library):
        a = _outputs(library, variant, model)
        for name in b:
            for x, y in zip(a[name], b[name], strict=True):
                assert np.isfinite(x).any(), name
                assert x.tobytes() == y.tobytes(), name


def test_the_quick_mode_starts_nothing_and_the_optimised_mode_waits(
    own_cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    variant = manifest.load("prismatic")
    monkeypatch.setenv("RPR3GEN_C_BUILD", "quick")
    quick = cbackend.library_path(variant)
    assert quick.is_file()
    assert not cbackend.BACKGROUND
    assert "-O1" in cbackend._plans(variant, "")[1].cflags
    assert cbackend.library_path(variant) == quick


@pytest.mark.parametrize("value", ["fast", "O3", "1"])
def test_an_unknown_build_mode_is_one_line_naming_the_variable(
    own_cache: Path, monkeypatch: pytest.MonkeyPatch, value: str
) -> None:
    monkeypatch.setenv("RPR3GEN_C_BUILD", value)
    with pytest.raises(rpr3gen.SetupError, match="RPR3GEN_C_BUILD") as info:
        cbackend.library_path(manifest.load("revolute"))
    assert "\n" not in str(info.value)
    assert isinstance(info.value, OSError)
