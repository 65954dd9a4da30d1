"""MuJoCo's ``mj_forward``, the spatial robots' peer, timed in C on the same robot and motion.

The robot is the gallery's model as ``rpr3gen export --format mjcf`` writes it (``rpr3gen.export``:
its solver settings, Newton to 1e-12); the states are the spatial motion's samples
(:func:`harness.samples.trajectory`), each made consistent in MuJoCo's coordinates by the test
suite's ``tests/mujoco_spatial.state`` (the legs' joints from the generated inverse dynamics, their
rates from MuJoCo's loop constraints), with the generated actuator efforts as controls.
``benchmarks/c/mujoco.c`` is built with the runtime's flags against the ``mujoco`` package's own
headers and library, and calls ``mj_forward`` on each state in turn, as a simulation does: no
Python between the calls.
"""

from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from harness import cbench, samples
from rpr3gen import control
from rpr3gen.export import mjcf

#: States of the motion, and the passes over them a round makes.
STATES = 500
PASSES = 10


def library() -> tuple[Path, Path]:
    """The ``mujoco`` package's include folder and its shared library."""
    import mujoco

    folder = Path(mujoco.__file__).resolve().parent
    found = sorted(folder.glob("libmujoco.so*")) or sorted(folder.glob("libmujoco*.dylib"))
    if not found:
        raise FileNotFoundError(f"no libmujoco in {folder}")
    return folder / "include", found[0]


def states(variant: str, n: int) -> tuple[str, np.ndarray, dict[str, int]]:
    """The exported model's XML and ``n`` states of the motion, (n, nq + nv + nu)."""
    import mujoco

    model = samples.model(variant)
    xml = mjcf(model)
    mm = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(mm)
    state = samples.test_module("mujoco_spatial").state
    arrays = samples.trajectory(variant, n)
    tau = control.actuator_efforts(model, arrays["q"], arrays["qd"], arrays["qdd"])
    rows = []
    for k in range(n):
        state(model, mm, d, arrays["q"][k], arrays["qd"][k])
        rows.append(np.concatenate([d.qpos, d.qvel, tau[k]]))
    return xml, np.array(rows), {"nq": mm.nq, "nv": mm.nv, "nu": mm.nu, "neq": mm.neq}


def run(variant: str, repeats: int, n: int = STATES, passes: int = PASSES) -> dict[str, Any]:
    """``mj_forward``'s time per call on ``variant``'s robot: ``{"results": {"mj_forward/single",
    "mj_forward/copy": {"min", "p50", ...}}, "model": {nq, nv, nu, neq}, "version"}``."""
    import mujoco

    include, lib = library()
    xml, rows, sizes = states(variant, n)
    with tempfile.TemporaryDirectory(prefix="rpr3bench-mujoco-") as tmp:
        build = Path(tmp)
        (build / "model.xml").write_text(xml)
        rows.astype("=f8").tofile(build / "states.bin")
        exe = build / "mujoco"
        subprocess.run(
            [*cbench.CC, *cbench.FLAGS, "-I", str(cbench.C_DIR), "-I", str(include),
             str(cbench.C_DIR / "mujoco.c"), str(lib), f"-Wl,-rpath,{lib.parent}", "-o", str(exe)],
            check=True,
        )  # fmt: skip
        done = subprocess.run(
            [str(exe), str(build / "model.xml"), str(build / "states.bin"), str(n), str(passes),
             str(repeats)],
            capture_output=True, text=True, check=True,
        )  # fmt: skip
    results = cbench.parse(done.stdout)
    results.pop("mj_forward/model", None)
    return {"results": results, "model": sizes, "version": mujoco.__version__, "states": n}
