"""What the benchmarks measure and on which samples: the variants, their models, the motions.

Three kinds of variant are measured:

- **the paper's** (``revolute``, ``prismatic``: the paper-format variants found in
  ``generated/``), on the paper's robot and two motions: the paper's platform rotation, eq. (3)
  (``x = y = 0``: leg work the generated code can skip stays hidden), and the generic motion;
- **every structure** (:func:`structures`: the 18 general-format variants ``rrr_1`` ...
  ``rpp_3``, each a leg type with its motors on one joint), each on a model of its own and the
  generic motion. The model is the gallery's file of that structure where ``models/`` has one
  (``rrr.toml`` is ``rrr_1``, ``paper-general.toml`` is ``rpr_1``, ...), else a random model of
  ``tests/planar_models.py`` drawn from the seed :data:`SEED`. A variant that ``generated/``
  does not carry comes from the runtime's cache (``rpr3gen.variants``: derived on first use);
- **every spatial robot of the gallery** (:func:`spatial`: the hexapods ``ups_2``, ``rus_1``,
  ``pus_1``, the Deltas ``rss2_1``, ``pss2_1``), each on its file of ``models/`` and the
  trajectory beside it (``tsai-ups.toml`` and ``tsai-ups.csv``, ...): the motion ``trajectory``
  (:func:`trajectory`), with the pose one control tick (:data:`TICK`) earlier as the tracked
  forward kinematics' reference ``q_near``.

The generic motion: ``x``, ``y`` and ``phi`` each a sine, at incommensurate frequencies (periods
3 s / (1, 1.3, 1.7)), amplitudes 30 mm, 25 mm and 0.2 rad times the variant's :func:`scale`:
the largest of 1, 0.8, 0.64, ... at which every sample is valid (:func:`valid`: every measured
function returns 0, the legs keep at least half their serial margin ``reach`` and the closure at
least half its ``conditioning`` at home). The paper's robot takes 1: its own bounds hold
(conditioning above 0.8, every piston at least 0.1 l0 ahead of its pivot), and its figures stay
comparable with earlier runs.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import sys
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

import rpr3gen
from rpr3gen import manifest, structure, variants
from rpr3gen.manifest import FunctionInfo, Variant
from rpr3gen.structure import Structure

REPO = Path(__file__).resolve().parents[2]
#: Inputs the motions give directly: the pose, its velocity and its acceleration.
MOTION_INPUTS = ("q", "qd", "qdd")
MOTIONS = ("generic", "rotation")
#: The tracked forward kinematics' reference: the pose this long before the sample's (s), as a
#: 1 kHz control loop passes its previous solution.
TICK = 1e-3
#: The seed of the random models (``tests/planar_models.random_model``).
SEED = 20
#: The generic motion at scale 1: amplitudes (m, m, rad), rates (rad/s), phases (rad).
AMPLITUDE = np.array([0.03, 0.025, 0.2])
RATE = 2.0 * math.pi / 3.0 * np.array([1.0, 1.3, 1.7])
PHASE = np.array([0.0, 0.7, 1.9])
#: Samples (over 3 s) on which :func:`valid` checks a motion; its smallest margins.
CHECK_SAMPLES = 3001
MIN_REACH = 0.5
MIN_CONDITIONING = 0.5  # of its value at home


def paper_variants() -> tuple[str, ...]:
    """The paper-format variants in ``generated/`` (``prismatic``, ``revolute``)."""
    return tuple(v for v in manifest.available() if Structure.of_variant(v).paper)


def structures() -> tuple[str, ...]:
    """The 18 structures' variants, in the runtime's order (``rrr_1``, ``rrr_2``, ...)."""
    return tuple(s.variant for s in structure.ALL if not s.singular)


@cache
def spatial() -> tuple[str, ...]:
    """The spatial robots' variants of the gallery (one model file each), in the runtime's order
    of their leg types (``ups_2``, ``rus_1``, ``pus_1``, ``rss2_1``, ``pss2_1``)."""
    order = list(structure.SPATIAL_LEG_TYPES)
    found = [v for v in gallery() if Structure.of_variant(v).spatial]
    return tuple(sorted(found, key=lambda v: (order.index(Structure.of_variant(v).leg), v)))


def motions(variant: str) -> tuple[str, ...]:
    """The motions a variant is measured on: both for the paper's, the generic one for a planar
    structure, the gallery's trajectory for a spatial robot."""
    found = Structure.of_variant(variant)
    return MOTIONS if found.paper else ("trajectory",) if found.spatial else ("generic",)


def code(variant: str) -> Variant:
    """The variant's manifest (and folder): ``generated/`` or the cache, as the runtime finds it."""
    return variants.load(Structure.of_variant(variant))


@cache
def test_module(name: str) -> Any:
    """``tests/NAME.py``, imported by path (the tests are no package; they import each other
    as top-level modules, as under pytest, so ``tests/`` goes on the path)."""
    if str(REPO / "tests") not in sys.path:
        sys.path.append(str(REPO / "tests"))
    spec = importlib.util.spec_from_file_location(
        f"rpr3bench_{name}", REPO / "tests" / f"{name}.py"
    )
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@cache
def gallery() -> dict[str, Path]:
    """The general-format model files of ``models/``, by the variant of their structure."""
    found: dict[str, Path] = {}
    for path in sorted((REPO / "models").glob("*.toml")):
        robot = rpr3gen.load_model(path)
        if not robot.structure.paper:
            found.setdefault(robot.variant, path)
    return found


def model_source(variant: str) -> str:
    """Where :func:`model` takes the variant's robot from, for the report."""
    if Structure.of_variant(variant).paper:
        return "the paper's robot"
    path = gallery().get(variant)
    return f"models/{path.name}" if path else f"random_model, seed {SEED}"


@cache
def model(variant: str) -> rpr3gen.Model:
    """The robot measured with ``variant``: the paper's for its variants; for a structure, the
    gallery's file or a random model (``tests/planar_models.random_model``, seed :data:`SEED`),
    read by ``rpr3gen.model_from_dict`` as any model dict is."""
    found = Structure.of_variant(variant)
    if found.paper:
        return dataclasses.replace(rpr3gen.load_model(), actuation=variant)
    path = gallery().get(variant)
    if path is not None:
        return rpr3gen.load_model(path)
    sys.modules.setdefault("planar_reference", test_module("planar_reference"))
    draw = test_module("planar_models").random_model
    robot = rpr3gen.model_from_dict(
        draw(np.random.default_rng(SEED), found.leg, found.actuated), source=f"random {variant}"
    )
    assert robot.variant == variant, (robot.variant, variant)
    return robot


def generic(n: int, factor: float) -> dict[str, np.ndarray]:
    """The generic motion, amplitudes times ``factor``: ``{"q", "qd", "qdd"}`` (n, 3)."""
    t = np.linspace(0.0, 3.0, n)
    amplitude = factor * AMPLITUDE
    phase = RATE * t[:, None] + PHASE
    arrays = (
        amplitude * np.sin(phase),
        amplitude * RATE * np.cos(phase),
        -amplitude * RATE**2 * np.sin(phase),
    )
    return {k: np.ascontiguousarray(a) for k, a in zip(MOTION_INPUTS, arrays, strict=True)}


def valid(variant: str, arrays: dict[str, np.ndarray]) -> bool:
    """Whether every sample of ``arrays`` is valid for ``variant``'s robot: every measured
    function returns 0, ``reach`` is at least :data:`MIN_REACH` and ``conditioning`` at least
    :data:`MIN_CONDITIONING` of its value at home (the inverse dynamics' last outputs)."""
    robot, found = model(variant), code(variant)
    names = found.function("inverse_dynamics").outputs[0].names
    home, _ = rpr3gen.evaluate(robot, "inverse_dynamics", [np.zeros(3)] * 3)
    (out,), codes = rpr3gen.evaluate(robot, "inverse_dynamics", [arrays[k] for k in MOTION_INPUTS])
    cond, reach = names.index("conditioning"), names.index("reach")
    if np.any(codes != 0) or np.min(out[:, reach]) < MIN_REACH:
        return False
    if np.min(out[:, cond]) < MIN_CONDITIONING * home[0][0, cond]:
        return False
    for f in found.functions.values():
        if measurable(found, f):
            _, codes = rpr3gen.evaluate(robot, f.name, inputs(variant, f, arrays))
            if np.any(codes != 0):
                return False
    return True


@cache
def scale(variant: str) -> float:
    """The generic motion's amplitude factor for ``variant``: 1 for the paper's robot, else the
    largest of 1, 0.8, 0.64, ... at which it is :func:`valid` on :data:`CHECK_SAMPLES` samples."""
    if Structure.of_variant(variant).paper:
        return 1.0
    for k in range(15):
        if valid(variant, generic(CHECK_SAMPLES, 0.8**k)):
            return 0.8**k
    raise RuntimeError(f"{variant}: no valid generic motion for {model_source(variant)}")


def trajectory(variant: str, n: int) -> dict[str, np.ndarray]:
    """The gallery's trajectory of a spatial robot (``models/NAME.csv`` beside its model file),
    linearly interpolated at ``n`` instants over its whole duration: ``{"q", "qd", "qdd"}``, and
    ``"q_near"``, the pose :data:`TICK` earlier (the first instant's own pose at the start)."""
    path = gallery()[variant]
    traj = rpr3gen.read_trajectory_csv(path.with_suffix(".csv"), pose=model(variant).structure.pose)
    t = np.linspace(traj.t[0], traj.t[-1], n)

    def at(times: np.ndarray, a: np.ndarray) -> np.ndarray:
        columns = [np.interp(times, traj.t, a[:, k]) for k in range(a.shape[1])]
        return np.ascontiguousarray(np.stack(columns, axis=1))

    arrays = {k: at(t, a) for k, a in zip(MOTION_INPUTS, (traj.q, traj.qd, traj.qdd), strict=True)}
    arrays["q_near"] = at(np.maximum(t - TICK, traj.t[0]), traj.q)
    return arrays


def motion(variant: str, name: str, n: int) -> dict[str, np.ndarray]:
    """``{"q", "qd", "qdd"}``: (n, dof) C-contiguous float64 samples of a motion (a spatial
    robot's ``trajectory`` also gives ``q_near``)."""
    if name == "trajectory":
        return trajectory(variant, n)
    if name == "generic":
        return generic(n, scale(variant))
    traj = rpr3gen.paper_trajectory(name, samples=n, duration=3.0)
    arrays = (traj.q, traj.qd, traj.qdd)
    return {k: np.ascontiguousarray(a) for k, a in zip(MOTION_INPUTS, arrays, strict=True)}


def dof(found: Variant) -> int:
    """The size of the variant's pose ``q``: 3 (planar robots, Deltas) or 6 (hexapods)."""
    return found.function("inverse_dynamics").inputs[0].size


def direct(found: Variant, a: Any) -> bool:
    """Whether the input ``a`` is given by the motion: the pose, its rates, the reference pose."""
    return a.name in (*MOTION_INPUTS, "q_near") and a.size == dof(found)


def producer(found: Variant, name: str, size: int) -> FunctionInfo | None:
    """The first function taking motion samples only with a public output ``name`` of ``size``
    components (``tau`` of ``actuator_efforts``, ``qa`` of ``actuator_coordinates``)."""
    for f in found.functions.values():
        given = all(a.name in MOTION_INPUTS and a.size == dof(found) for a in f.inputs)
        if given and any(o.name == name and o.size == size for o in f.public_outputs):
            return f
    return None


def measurable(found: Variant, f: FunctionInfo) -> bool:
    """Whether every input is a motion sample or another function's output, and the function
    is straight-line (has a NumPy version; the iterative forward kinematics has not)."""
    return f.numpy_function is not None and all(
        (a.name in MOTION_INPUTS and a.size == dof(found)) or producer(found, a.name, a.size)
        for a in f.inputs
    )


#: The spatial robots' measured functions (issue 49): the inverse dynamics with every joint
#: load, the forward dynamics and the tracked forward kinematics (``q_near`` the pose one tick
#: before).
SPATIAL_FUNCTIONS = ("inverse_dynamics", "forward_dynamics", "forward_kinematics")


def measured(variant: str) -> list[str]:
    """The functions measured on ``variant``: every :func:`measurable` one of a planar variant,
    :data:`SPATIAL_FUNCTIONS` of a spatial one."""
    found = code(variant)
    if Structure.of_variant(variant).spatial:
        return [n for n in SPATIAL_FUNCTIONS if n in found.functions]
    return [n for n, f in found.functions.items() if measurable(found, f)]


def inputs(variant: str, f: FunctionInfo, arrays: dict[str, np.ndarray]) -> list[np.ndarray]:
    """The inputs of ``f`` on the motion samples ``arrays``, in its order."""
    found = code(variant)
    result: list[Any] = []
    for a in f.inputs:
        if direct(found, a):
            result.append(arrays[a.name])
            continue
        source = producer(found, a.name, a.size)
        assert source is not None, f"no samples for {f.name}'s input {a.name}"
        outputs, _ = rpr3gen.evaluate(
            model(variant), source.name, [arrays[i.name] for i in source.inputs]
        )
        result.append(outputs[[o.name for o in source.public_outputs].index(a.name)])
    return [np.ascontiguousarray(x, dtype=np.float64) for x in result]
