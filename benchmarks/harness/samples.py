"""What the benchmarks measure and on which samples: the variants, the motions, the inputs.

Every variant found in ``generated/`` (``rpr3gen.manifest.available()``) is measured, so a new
structure adds rows. Two motions of the paper's robot: the paper's platform rotation, eq. (3)
(``x = y = 0``: leg work the generated code can skip stays hidden), and a generic motion in
which ``x``, ``y`` and ``phi`` all move at incommensurate frequencies, valid throughout
(conditioning above 0.8, every piston at least 0.1 l0 ahead of its pivot).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

import rpr3gen
from rpr3gen import manifest
from rpr3gen.manifest import FunctionInfo, Variant

#: Inputs the motions give directly: the pose, its velocity and its acceleration.
MOTION_INPUTS = ("q", "qd", "qdd")
MOTIONS = ("generic", "rotation")


def variants() -> tuple[str, ...]:
    """Names of the generated variants (structures), in the order the runtime lists them."""
    return tuple(manifest.available())


def model(variant: str) -> rpr3gen.Model:
    """The paper's robot with the variant's actuation."""
    return dataclasses.replace(rpr3gen.load_model(), actuation=variant)


def motion(name: str, n: int) -> dict[str, np.ndarray]:
    """``{"q", "qd", "qdd"}``: (n, 3) C-contiguous float64 samples of a motion over 3 s."""
    if name == "rotation":
        traj = rpr3gen.paper_trajectory("rotation", samples=n, duration=3.0)
        arrays = (traj.q, traj.qd, traj.qdd)
    else:  # x, y, phi each a sum of sines, periods 3 s / (1.0, 1.3, 1.7)
        t = np.linspace(0.0, 3.0, n)
        amplitude = np.array([0.03, 0.025, 0.2])
        rate = 2.0 * math.pi / 3.0 * np.array([1.0, 1.3, 1.7])
        phase = rate * t[:, None] + np.array([0.0, 0.7, 1.9])
        arrays = (
            amplitude * np.sin(phase),
            amplitude * rate * np.cos(phase),
            -amplitude * rate**2 * np.sin(phase),
        )
    return {
        k: np.ascontiguousarray(a, dtype=np.float64)
        for k, a in zip(MOTION_INPUTS, arrays, strict=True)
    }


def producer(found: Variant, name: str, size: int) -> FunctionInfo | None:
    """The first function taking motion samples only with a public output ``name`` of ``size``
    components (``tau`` of ``actuator_efforts``, ``qa`` of ``actuator_coordinates``)."""
    for f in found.functions.values():
        direct = all(a.name in MOTION_INPUTS and a.size == 3 for a in f.inputs)
        if direct and any(o.name == name and o.size == size for o in f.public_outputs):
            return f
    return None


def measurable(found: Variant, f: FunctionInfo) -> bool:
    """Whether every input is a motion sample or another function's output, and the function
    is straight-line (has a NumPy version; the iterative forward kinematics has not)."""
    inputs = all(
        (a.name in MOTION_INPUTS and a.size == 3) or producer(found, a.name, a.size)
        for a in f.inputs
    )
    return inputs and f.numpy_function is not None


def inputs(variant: str, f: FunctionInfo, arrays: dict[str, np.ndarray]) -> list[np.ndarray]:
    """The inputs of ``f`` on the motion samples ``arrays``, in its order."""
    found = manifest.load(variant)
    result: list[Any] = []
    for a in f.inputs:
        if a.name in MOTION_INPUTS:
            result.append(arrays[a.name])
            continue
        source = producer(found, a.name, a.size)
        assert source is not None, f"no samples for {f.name}'s input {a.name}"
        outputs, _ = rpr3gen.evaluate(
            model(variant), source.name, [arrays[i.name] for i in source.inputs]
        )
        result.append(outputs[[o.name for o in source.public_outputs].index(a.name)])
    return [np.ascontiguousarray(x, dtype=np.float64) for x in result]
