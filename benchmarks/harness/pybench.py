"""The Python benchmarks, on pyperf: ``python harness/pybench.py GROUP -o FILE.json``.

pyperf runs each benchmark in fresh worker processes, calibrates the loop count, discards
warm-ups and records the machine (CPU, load average, versions) with every value; this script
only says what to time. Each benchmark is a pyperf *time function* whose setup (samples,
evaluators) happens before its clock starts. Groups (one pyperf run each, so that each has its
own repeat counts):

- ``functions``: ``evaluate(..., backend="numpy")`` of every measurable function at 10^5;
- ``structures``: the same for the structures named by ``--structures`` (every one by default),
  each on its own model and generic motion (``harness/samples.py``);
- ``calls``: ``SampleEvaluator`` single calls (the C through ctypes) of every function, at the
  generic motion's first pose, and the same call with a NaN input (the ctypes floor);
- ``peers``: MuJoCo's ``mj_forward`` on the same robot (skipped without MuJoCo);
- ``regen``: ``rpr3gen generate --check``, a fresh interpreter end to end.

NumPy against the Newton-Euler solver is not here: ``harness/paired.py`` times the two in turn,
in one process, so that a spell of this shared machine falls on both.

The groups but ``structures`` measure the paper's variants. Benchmark names are
``group/variant/...`` (see :func:`names`; ``structures`` names its own ``functions/...``);
``benchmarks/run.py`` reads them.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyperf

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import rpr3gen
from harness import samples
from harness.samples import test_module

GROUPS = ("functions", "structures", "calls", "peers", "regen")


def timed(setup: Callable[[], Callable[[], object]]) -> Callable[[int], float]:
    """A pyperf time function: ``setup()`` (untimed, once per worker) returns the call to time."""
    made: list[Callable[[], object]] = []

    def run(loops: int) -> float:
        if not made:
            made.append(setup())
        call = made[0]
        start = time.perf_counter()
        for _ in range(loops):
            call()
        return time.perf_counter() - start

    return run


def function_benchmarks(variant: str) -> dict[str, Callable[[int], float]]:
    found_variant = samples.code(variant)
    found: dict[str, Callable[[int], float]] = {}
    for name, f in found_variant.functions.items():
        if not samples.measurable(found_variant, f):
            continue

        def setup(f: Any = f) -> Callable[[], object]:
            model = samples.model(variant)
            inputs = samples.inputs(variant, f, samples.motion(variant, "generic", 10**5))
            return lambda: rpr3gen.evaluate(model, f.name, inputs, backend="numpy")

        found[f"functions/{variant}/{name}"] = timed(setup)
    return found


def call_benchmarks(variant: str) -> dict[str, Callable[[int], float]]:
    found_variant = samples.code(variant)
    model = samples.model(variant)
    pose = samples.motion(variant, "generic", 3001)  # 1 ms apart, as a control loop's ticks
    found: dict[str, Callable[[int], float]] = {}
    for name, f in found_variant.functions.items():
        if not all(a.name in samples.MOTION_INPUTS or a.name in ("qa", "q_near", "tau", "qa_dot")
                   for a in f.inputs):  # fmt: skip
            continue
        for nan in (False, True):

            def setup(name: str = name, f: Any = f, nan: bool = nan) -> Callable[[], object]:
                ev = rpr3gen.SampleEvaluator(model, function=name)
                for a in f.inputs:  # a valid sample: the motion's pose, or what it gives
                    if a.name in samples.MOTION_INPUTS:
                        ev.inputs[a.name][:] = pose[a.name][1500]
                    elif a.name == "qa":
                        ev.inputs[a.name][:] = rpr3gen.actuator_coordinates(
                            model, pose["q"][1500:1501]
                        )[0]
                    elif a.name == "q_near":  # tracked: predicted from the last two poses
                        ev.inputs[a.name][:] = 2.0 * pose["q"][1499] - pose["q"][1498]
                    else:
                        ev.inputs[a.name][:] = (1.0, -2.0, 0.5)
                if nan:
                    ev.inputs[f.inputs[0].name][0] = math.nan
                assert (ev() != 0) == nan, f"{name}: unexpected return code"
                return ev

            found[f"calls/{variant}/{name}{'/nan' if nan else ''}"] = timed(setup)
    for name in ("inverse_dynamics", "forward_dynamics"):  # the array API on one sample

        def array_setup(name: str = name) -> Callable[[], object]:
            last = (1.0, -2.0, 0.5) if name == "forward_dynamics" else pose["qdd"][1500]
            args = (pose["q"][1500], pose["qd"][1500], last)
            call = getattr(rpr3gen, name)
            return lambda: call(model, *args, backend="c")

        found[f"array/{variant}/{name}"] = timed(array_setup)
    return found


def peer_benchmarks(variant: str) -> dict[str, Callable[[int], float]]:
    try:
        import mujoco
    except ImportError:
        return {}
    peer = test_module("mujoco_peer")
    model = samples.model(variant)

    def setup() -> Callable[[], object]:
        mj_model = mujoco.MjModel.from_xml_string(peer.build_mjcf(model.params, variant))
        data = mujoco.MjData(mj_model)
        peer.set_state(mj_model, data, (0.02, -0.03, 0.1), (0.05, 0.02, 0.1))
        return lambda: mujoco.mj_forward(mj_model, data)

    return {f"peers/{variant}/mj_forward": timed(setup)}


def names(group: str, structures: tuple[str, ...] = ()) -> dict[str, Callable[[int], float]]:
    """Every benchmark of ``group``, by name: over the paper's variants in ``generated/``, or
    (``structures``) over the variants ``structures``."""
    if group == "structures":
        return {k: v for s in structures for k, v in function_benchmarks(s).items()}
    found: dict[str, Callable[[int], float]] = {}
    for variant in samples.paper_variants():
        make = {"functions": function_benchmarks, "calls": call_benchmarks,
                "peers": peer_benchmarks}[group]  # fmt: skip
        found.update(make(variant))
    return found


def add_group(cmd: list[str], args: Any) -> None:
    """Forward the group and the structures to pyperf's worker processes."""
    cmd += [args.group, "--structures", args.structures]


def main() -> None:
    runner = pyperf.Runner(add_cmdline_args=add_group)
    runner.argparser.add_argument("group", choices=GROUPS)
    runner.argparser.add_argument(
        "--structures", default=",".join(samples.structures()),
        help="the group structures: these variants (comma-separated)",
    )  # fmt: skip
    args = runner.parse_args()
    if args.group == "regen":
        runner.bench_command(
            "regen/generate_check", [sys.executable, "-m", "rpr3gen.cli", "generate", "--check"]
        )
        return
    for name, func in names(args.group, tuple(args.structures.split(","))).items():
        runner.bench_time_func(name, func)
    np.seterr(all="ignore")


if __name__ == "__main__":
    main()
