"""Spatial robots' C timings (one run, on demand): single call and batch of the inverse dynamics,
the forward dynamics and the tracked forward kinematics of the committed 6-UPS and Delta, and
MuJoCo's ``mj_forward`` on the same robots (``rpr3gen export``), the peer.

    python benchmarks/spatial.py            # prints a Markdown table and the machine

Builds ``generated/<variant>/rpr3.c`` with the runtime's flags (``rpr3gen.cbackend``) and a small
timing loop (below), on the gallery's model and a motion of 1024 samples of its trajectory.
Single calls are timed back to back over the samples (the median of 7 rounds of 200,000 calls);
a batch call's time is divided by its samples. A figure is of this machine, in one run: compare
rows with each other, not with other runs.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import rpr3gen
from rpr3gen import cbackend, control

ROOT = Path(__file__).resolve().parent.parent

HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "rpr3.h"
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}
static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static double *take(FILE *f, size_t count)
{
    double *a = malloc(count * sizeof *a);
    return fread(a, sizeof *a, count, f) == count ? a : NULL;
}
int main(int argc, char **argv)
{
    FILE *f = fopen(argv[1], "rb");
    int k, np, n, which, round, i;
    double *p, *q, *qd, *qdd, *tau, *qa, *out, r[7], sink = 0;
    const int calls = 200000;
    const char *names[4] = {"inverse_dynamics", "forward_dynamics", "forward_kinematics",
                            "inverse_dynamics_batch"};
    if (argc < 2 || !f || fread(&k, sizeof k, 1, f) != 1 || fread(&np, sizeof np, 1, f) != 1
        || fread(&n, sizeof n, 1, f) != 1)
        return 2;
    p = take(f, np);
    q = take(f, (size_t)n * k);
    qd = take(f, (size_t)n * k);
    qdd = take(f, (size_t)n * k);
    tau = take(f, (size_t)n * k);
    qa = take(f, (size_t)n * k);
    if (!p || !q || !qd || !qdd || !tau || !qa)
        return 2;
    out = malloc((size_t)n * RPR3_NUM_OUTPUTS * sizeof *out);
    for (which = 0; which < 4; ++which) {
        for (round = 0; round < 7; ++round) {
            double t0 = now();
            if (which == 3) {
                for (i = 0; i < 20; ++i) {
                    rpr3_inverse_dynamics_batch(p, n, q, qd, qdd, out);
                    sink += out[0];
                }
                r[round] = (now() - t0) / (20.0 * n);
                continue;
            }
            for (i = 0; i < calls; ++i) {
                int s = i % n;
                if (which == 0)
                    rpr3_inverse_dynamics(p, q + s * k, qd + s * k, qdd + s * k, out);
                else if (which == 1)
                    rpr3_forward_dynamics(p, q + s * k, qd + s * k, tau + s * k, out);
                else
                    rpr3_forward_kinematics(p, qa + s * k, q + (s ? s - 1 : 0) * k, out);
                sink += out[0];
            }
            r[round] = (now() - t0) / calls;
        }
        qsort(r, 7, sizeof r[0], cmp);
        printf("%s %.1f\n", names[which], r[3] * 1e9);
    }
    fprintf(stderr, "%g\n", sink);
    return 0;
}
"""


def measure(model_file: str, trajectory: str) -> dict[str, float]:
    model = rpr3gen.load_model(ROOT / "models" / model_file)
    traj = rpr3gen.read_trajectory_csv(ROOT / "models" / trajectory, pose=model.structure.pose)
    idx = np.linspace(0, len(traj.t) - 1, 1024).astype(int)
    q, qd, qdd = traj.q[idx], traj.qd[idx], traj.qdd[idx]
    tau = control.actuator_efforts(model, q, qd, qdd)
    qa = control.actuator_coordinates(model, q)
    folder = ROOT / "generated" / model.variant
    params = model.vector()
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "in.bin"
        with open(data, "wb") as f:
            np.array([q.shape[1], len(params), len(q)], dtype=np.intc).tofile(f)
            for a in (params, q, qd, qdd, tau, qa):
                np.ascontiguousarray(a, dtype=np.float64).tofile(f)
        (Path(tmp) / "bench.c").write_text(HARNESS)
        flags = [f for f in cbackend.CFLAGS if f not in ("-shared", "-fPIC")]
        extra = next(iter(cbackend.EXTRA_FLAGS))
        exe = Path(tmp) / "bench"
        subprocess.run([os.environ.get("CC", "cc"), *flags, *extra, "-I", str(folder),
                        str(folder / "rpr3.c"), str(Path(tmp) / "bench.c"), "-o", str(exe), "-lm"],
                       check=True)  # fmt: skip
        result = subprocess.run([str(exe), str(data)], check=True, capture_output=True, text=True)
    return {line.split()[0]: float(line.split()[1]) for line in result.stdout.splitlines()}


def mj_forward_ns(model_file: str, steps: int = 20000) -> float:
    """MuJoCo's cost of one ``mj_forward`` on the exported robot: ``steps`` semi-implicit
    Euler steps (one forward pass each, and an update of the state) run in C by
    ``mujoco.rollout`` from home at rest, the time divided by the steps (median of 5)."""
    import time

    import mujoco
    from mujoco import rollout

    from rpr3gen.export import mjcf

    model = rpr3gen.load_model(ROOT / "models" / model_file)
    mm = mujoco.MjModel.from_xml_string(mjcf(model))
    mm.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    data = mujoco.MjData(mm)
    state = np.zeros((1, mujoco.mj_stateSize(mm, mujoco.mjtState.mjSTATE_FULLPHYSICS)))
    mujoco.mj_getState(mm, data, state[0], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        rollout.rollout(mm, data, state, nstep=steps)
        times.append((time.perf_counter() - t0) / steps)
    return float(np.median(times)) * 1e9


def main() -> int:
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.2f}")  # fmt: skip
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
        cpu = next(line.split(":", 1)[1].strip() for line in lines if line.startswith("model name"))
        print(f"cpu: {cpu}")
    except (OSError, StopIteration):
        pass
    print(
        "| robot | ID single (ns) | ID batch (ns/sample) | FD single (ns) | tracked FK (ns) "
        "| mj_forward (ns) |"
    )
    print("|---|---|---|---|---|---|")
    for model, traj in (("tsai-ups.toml", "tsai-ups.csv"), ("delta.toml", "delta.csv")):
        r = measure(model, traj)
        mj = mj_forward_ns(model)
        cells = [r["inverse_dynamics"], r["inverse_dynamics_batch"], r["forward_dynamics"]]
        cells += [r["forward_kinematics"], mj]
        print(f"| {model[:-5]} | " + " | ".join(f"{c:.0f}" for c in cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
