"""Cost and loop-closure drift of the MuJoCo peer model (issue 12); a script, not a test.

Run with the project's interpreter and the ``peers`` extra (``pip install -e '.[dev,peers]'``)::

    python benchmarks/mujoco_peer.py            # about half a minute
    python benchmarks/mujoco_peer.py --quick    # fewer repeats, no agreement table

It prints Markdown on stdout:

1. the machine;
2. the time per call of ``mujoco.mj_forward`` and ``mujoco.mj_step`` (RK4, and Euler for
   context) on the paper's robot as ``tests/mujoco_peer.py`` builds it, from the Python bindings
   (``timeit``: the median over repeats of the mean over a loop of calls);
3. the loop-closure drift, ``max_L |A3 (piston end) - A3 (platform joint)|``, over 3 s of the
   mechanism falling with zero control under gravity from rest in the central configuration, at
   dt = 1e-4 s and at MuJoCo's default dt (2e-3 s), with the peer's constraint settings and with
   MuJoCo's defaults;
4. (not with ``--quick``) the agreement with rpr3gen over 1 s of the rectilinear motion driven
   open-loop by rpr3gen's efforts, against dt, solref and solimp.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib.util
import math
import os
import platform
import statistics
import sys
import timeit
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

import rpr3gen

REPO = Path(__file__).resolve().parent.parent
MUJOCO_DEFAULT_DT = 0.002
MUJOCO_DEFAULT_SOLREF = (0.02, 1.0)
MUJOCO_DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
EFFORT = {"revolute": "m10", "prismatic": "f21z"}


def _import_peer() -> Any:
    path = REPO / "tests" / "mujoco_peer.py"
    spec = importlib.util.spec_from_file_location("rpr3_bench_mujoco_peer", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


peer = _import_peer()


def machine() -> list[str]:
    cpu = "unknown"
    with contextlib.suppress(OSError), open("/proc/cpuinfo") as handle:
        for line in handle:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    load = " ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    return [
        f"- CPU: {cpu}, {cores} cores available",
        f"- Python {platform.python_version()}, NumPy {np.__version__}, "
        f"MuJoCo {mujoco.__version__}, {platform.system()} {platform.release()}",
        f"- load average at start: {load}",
    ]


def _per_call(stmt: Any, number: int, repeats: int) -> tuple[float, float]:
    """(median, best) seconds per call over ``repeats`` timings of ``number`` calls."""
    times = [t / number for t in timeit.repeat(stmt, number=number, repeat=repeats)]
    return statistics.median(times), min(times)


def timings(repeats: int) -> list[str]:
    model = rpr3gen.load_model()
    rows = [
        "| call | integrator | dt (s) | median (µs/call) | best (µs/call) |",
        "|---|---|---|---|---|",
    ]
    for integrator in ("RK4", "Euler"):
        mj_model = peer.compile_model(model.params, model.actuation, integrator=integrator)
        data = mujoco.MjData(mj_model)
        peer.set_state(mj_model, data, (0.02, -0.03, 0.1), (0.05, 0.02, 0.1))
        qpos, qvel = data.qpos.copy(), data.qvel.copy()
        data.ctrl[:] = (-2.9, -20.4, 20.9)  # about the static efforts: a gentle motion
        calls = []
        if integrator == "RK4":
            calls.append(("mj_forward", lambda m=mj_model, d=data: mujoco.mj_forward(m, d)))
        calls.append(("mj_step", lambda m=mj_model, d=data: mujoco.mj_step(m, d)))
        for name, call in calls:
            data.qpos[:], data.qvel[:] = qpos, qvel
            median, best = _per_call(call, number=2000, repeats=repeats)
            shown = integrator if name == "mj_step" else "-"
            rows.append(
                f"| `{name}` | {shown} | {mj_model.opt.timestep:g} | {median * 1e6:.1f} | "
                f"{best * 1e6:.1f} |"
            )
    rows.append(
        "\nAn RK4 `mj_step` evaluates the dynamics at four stages (four forward passes, each "
        "with its constraint solve); every figure includes the Python bindings' call overhead."
    )
    return rows


WINDOWS = ((0.0, 0.1), (0.1, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 3.0))


def _fall(dt: float, solref: Any, solimp: Any, integrator: str) -> dict[str, Any]:
    """Closure error (m), max in each of :data:`WINDOWS`, and where the platform ends up."""
    model = rpr3gen.load_model()
    mj_model = peer.compile_model(
        model.params,
        model.actuation,
        timestep=dt,
        solref=solref,
        solimp=solimp,
        integrator=integrator,
    )
    data = mujoco.MjData(mj_model)
    peer.set_state(mj_model, data, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    worst = [0.0] * len(WINDOWS)
    for k in range(1, round(WINDOWS[-1][1] / dt) + 1):
        mujoco.mj_step(mj_model, data)
        t = k * dt
        window = next(i for i, (lo, hi) in enumerate(WINDOWS) if t <= hi + dt / 2)
        worst[window] = max(worst[window], peer.closure_error(mj_model, data))
    return {"closure": worst, "pose": data.qpos[-3:].copy(), "speed": np.hypot(*data.qvel[-3:-1])}


def drift() -> list[str]:
    ours = (peer.SOLREF, peer.SOLIMP)
    cases = [
        ("peer: RK4, solref (2 dt, 1), d = 0.9999", 1e-4, "RK4", None),
        ("peer: RK4, solref (2 dt, 1), d = 0.9999", MUJOCO_DEFAULT_DT, "RK4", None),
        ("peer: RK4, solref (2 ms, 1), d = 0.9999", 1e-4, "RK4", ours),
        ("MuJoCo default solref/solimp, RK4", 1e-4, "RK4", "default"),
        ("MuJoCo default solref/solimp, RK4", MUJOCO_DEFAULT_DT, "RK4", "default"),
        ("MuJoCo defaults (Euler)", MUJOCO_DEFAULT_DT, "Euler", "default"),
    ]
    windows = " | ".join(f"{lo:g}-{hi:g} s" for lo, hi in WINDOWS)
    rows = [
        f"| settings | dt (s) | {windows} | G at 3 s (m) | speed at 3 s (m/s) |",
        "|---|---|" + "---|" * len(WINDOWS) + "---|---|",
    ]
    for label, dt, integrator, constraint in cases:
        if constraint is None:
            solref, solimp = (2 * dt, 1.0), peer.SOLIMP
        elif constraint == "default":
            solref, solimp = MUJOCO_DEFAULT_SOLREF, MUJOCO_DEFAULT_SOLIMP
        else:
            solref, solimp = constraint
        fall = _fall(dt, solref, solimp, integrator)
        cells = " | ".join(f"{v:.1e}" for v in fall["closure"])
        x, y, _ = fall["pose"]
        rows.append(f"| {label} | {dt:g} | {cells} | ({x:.2f}, {y:.2f}) | {fall['speed']:.2f} |")
    rows.append(
        "\nClosure error: the largest `max_L |A3 (piston end) - A3 (platform joint)|` within each "
        "time window. Zero control, gravity (0, -9.81), from rest in the central configuration. "
        "Nothing holds the platform up (the pistons have no stroke limit), so it falls, the legs "
        "swinging down and stretching; the loads on the loops are largest in the first swing."
    )
    return rows


def _track(actuation: str, dt: float, solref: Any, solimp: Any) -> tuple[float, float, float]:
    model = dataclasses.replace(rpr3gen.load_model(), actuation=actuation)
    mj_model = peer.compile_model(
        model.params, actuation, timestep=dt, solref=solref, solimp=solimp
    )
    data = mujoco.MjData(mj_model)
    traj = rpr3gen.paper_trajectory("rectilinear", samples=round(3.0 / (dt / 2)) + 1)
    n = round(1.0 / dt)
    part = slice(0, 2 * n + 1)
    out = rpr3gen.inverse_dynamics(model, traj.q[part], traj.qd[part], traj.qdd[part])
    tau = np.stack([out[f"{EFFORT[actuation]}_{L}"] for L in peer.LEGS], axis=1)
    peer.set_state(mj_model, data, traj.q[0], traj.qd[0])
    position = orientation = closure = 0.0
    for k in range(n):
        data.ctrl[:] = tau[2 * k + 1]  # the step's midpoint
        mujoco.mj_step(mj_model, data)
        pose = data.qpos[-3:]
        position = max(position, math.hypot(*(pose[:2] - traj.q[2 * k + 2, :2])))
        orientation = max(orientation, abs(pose[2] - traj.q[2 * k + 2, 2]))
        closure = max(closure, peer.closure_error(mj_model, data))
    return position, orientation, closure


def agreement() -> list[str]:
    rows = [
        "| actuation | dt (s) | solref[0] (s) | solimp d | G error (m) | phi error (rad) "
        "| closure (m) |",
        "|---|---|---|---|---|---|---|",
    ]
    cases = [
        (1e-3, 2e-3, 0.9999),
        (1e-4, 2e-4, 0.9999),
        (1e-4, 2e-3, 0.9999),
        (1e-3, 2e-2, 0.9999),
        (1e-3, 2e-3, 0.999),
        (1e-3, 2e-3, 0.99),
    ]
    for actuation in EFFORT:
        for dt, timeconst, d in cases:
            solimp = (d, d, *peer.SOLIMP[2:])
            values = _track(actuation, dt, (timeconst, 1.0), solimp)
            cells = " | ".join(f"{v:.1e}" for v in values)
            rows.append(f"| {actuation} | {dt:g} | {timeconst:g} | {d} | {cells} |")
    rows.append(
        "\nRK4; efforts from `rpr3gen.inverse_dynamics` at each step's midpoint, held over the "
        "step; errors are maxima over 1 s of the paper's rectilinear motion."
    )
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, no agreement table")
    args = parser.parse_args(argv)
    sections = [
        ("Machine", machine()),
        ("Time per call (paper robot, revolute, Python bindings)", timings(3 if args.quick else 9)),
        ("Loop-closure drift over 3 s, zero control", drift()),
    ]
    if not args.quick:
        sections.append(("Agreement with rpr3gen (1 s, rectilinear, open loop)", agreement()))
    print("# MuJoCo peer\n")
    for title, lines in sections:
        print(f"## {title}\n")
        print("\n".join(lines))
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
