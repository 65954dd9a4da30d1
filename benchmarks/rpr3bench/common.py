"""What every part of the benchmarks shares: where things are, what is measured, on which samples.

The samples are the paper's platform rotation, eq. (3); the robot is the paper's
(``load_model()``, the ``revolute`` variant). A function of the manifest is measured when the
benchmarks can give it samples: every input named ``q``, ``qd`` or ``qdd`` (the pose and its
derivatives along the trajectory); the per-function section also takes an input that another
such function gives as an output of that name (``tau``, ``qa``).
"""

from __future__ import annotations

import hashlib
import os
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rpr3gen.manifest import FunctionInfo, Variant

BENCH = Path(__file__).resolve().parent.parent  # benchmarks/
REPO = BENCH.parent
PY = sys.executable
CC = shlex.split(os.environ.get("CC", "cc"))
VARIANT = "revolute"  # the paper's robot; bench.c builds against this variant
TRAJECTORY = "rotation"  # the paper's platform rotation, eq. (3), figs 3-8
#: Inputs the benchmarks can give: the trajectory's pose, velocity and acceleration.
SAMPLE_INPUTS = ("q", "qd", "qdd")

#: (what was measured, identity of the generated variant at that time), filled as the run goes.
CODE_IDS: list[tuple[str, str]] = []


def log(message: str) -> None:
    print(f"[bench] {message}", file=sys.stderr, flush=True)


def variant() -> Variant:
    """The manifest of the measured variant, from the generated package the runtime uses."""
    from rpr3gen import manifest

    return manifest.load(VARIANT)


def shown(path: Path) -> str:
    """``path`` relative to the repository when it is inside it."""
    try:
        return str(path.relative_to(REPO))
    except ValueError:
        return str(path)


def code_id() -> str:
    """Short SHA-256 of the measured variant's generated files, as they are on disk now.

    Others may regenerate while a run is going on; a report whose sections saw different code
    says so at the top.
    """
    found = variant()
    digest = hashlib.sha256()
    for name in ("manifest.json", *sorted(found.files.values())):
        path = found.folder / name
        digest.update(path.read_bytes() if path.is_file() else b"missing")
    return digest.hexdigest()[:12]


def trajectory(n: int) -> dict[str, Any]:
    """``{"q", "qd", "qdd"}``: (n, 3) C-contiguous float64 arrays of the paper's rotation."""
    import numpy as np

    import rpr3gen

    traj = rpr3gen.paper_trajectory(TRAJECTORY, samples=n, duration=3.0)
    arrays = (traj.q, traj.qd, traj.qdd)
    return {
        name: np.ascontiguousarray(a, dtype=np.float64)
        for name, a in zip(SAMPLE_INPUTS, arrays, strict=True)
    }


def measurable(function: FunctionInfo) -> bool:
    """Whether the benchmarks can give ``function`` samples (every input is q, qd or qdd)."""
    return all(a.name in SAMPLE_INPUTS and a.size == 3 for a in function.inputs)


def producer(name: str, size: int) -> FunctionInfo | None:
    """The first function of the measured variant that takes trajectory samples only and has a
    public output ``name`` of ``size`` components (``tau`` of ``actuator_efforts``)."""
    for function in variant().functions.values():
        if measurable(function) and any(
            o.name == name and o.size == size for o in function.public_outputs
        ):
            return function
    return None


def derivable(function: FunctionInfo) -> bool:
    """Whether every input is a trajectory sample or another function's output
    (:func:`producer`)."""
    return all(
        (a.name in SAMPLE_INPUTS and a.size == 3) or producer(a.name, a.size) is not None
        for a in function.inputs
    )


def sample_inputs(function: FunctionInfo, n: int) -> list[Any]:
    """The inputs of ``function`` for n samples of the trajectory, in its order: the trajectory's
    own, or the output of the function that gives that name (its NumPy version, on the same
    samples)."""
    import rpr3gen

    arrays = trajectory(n)
    inputs = []
    for a in function.inputs:
        if a.name in SAMPLE_INPUTS and a.size == 3:
            inputs.append(arrays[a.name])
            continue
        source = producer(a.name, a.size)
        assert source is not None, f"no samples for {function.name}'s input {a.name}"
        outputs, _ = rpr3gen.evaluate(
            rpr3gen.load_model(), source.name, [arrays[i.name] for i in source.inputs]
        )
        index = [o.name for o in source.public_outputs].index(a.name)
        inputs.append(outputs[index])
    return [np_contiguous(x) for x in inputs]


def np_contiguous(array: Any) -> Any:
    import numpy as np

    return np.ascontiguousarray(array, dtype=np.float64)


def functions() -> tuple[list[str], list[str]]:
    """Names of the measured variant's functions: (measured, skipped for want of samples)."""
    found = variant().functions
    measured = [name for name, f in found.items() if measurable(f)]
    return measured, [name for name in found if name not in measured]


def derived_functions() -> tuple[list[str], list[str]]:
    """As :func:`functions`, counting inputs that other functions give (:func:`derivable`)."""
    found = variant().functions
    measured = [name for name, f in found.items() if derivable(f)]
    return measured, [name for name in found if name not in measured]


def mem_available() -> int:
    with open("/proc/meminfo") as handle:
        for line in handle:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    return 0
