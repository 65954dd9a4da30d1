"""The derivatives' cost against the functions they differentiate, in C (one run, on demand).

    python benchmarks/derivatives.py        # prints a Markdown table and the machine

Per committed variant (the paper's revolute, the 3-RRR, the Delta, the 6-UPS): single calls and
batch of ``inverse_dynamics``, ``inverse_dynamics_derivatives``, ``forward_dynamics`` and
``forward_dynamics_derivatives``, on the gallery's model and 1024 samples of its trajectory.
Built as the runtime builds them (``rpr3gen.cbackend``): ``rpr3.c`` with its flags, and
``rpr3_derivatives.c`` with the same, or -O0 for a unit over ``cbackend.LARGE_UNIT`` (the
6-UPS's). Single calls are timed back to back over the samples (the median of 7 rounds); a
batch call's time is divided by its samples. Compare rows of one run with each other.
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
#include "rpr3_derivatives.h" /* includes rpr3.h */
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
    int k, np, n, which, round, i, calls;
    double *p, *q, *qd, *qdd, *tau, *o1, *o2, *o3, *o4, r[7], sink = 0;
    const char *names[8] = {"ID", "IDd", "FD", "FDd", "ID_batch", "IDd_batch", "FD_batch",
                            "FDd_batch"};
    if (argc < 3 || !f || fread(&k, sizeof k, 1, f) != 1 || fread(&np, sizeof np, 1, f) != 1
        || fread(&n, sizeof n, 1, f) != 1)
        return 2;
    calls = atoi(argv[2]);
    p = take(f, np);
    q = take(f, (size_t)n * k);
    qd = take(f, (size_t)n * k);
    qdd = take(f, (size_t)n * k);
    tau = take(f, (size_t)n * k);
    if (!p || !q || !qd || !qdd || !tau)
        return 2;
    o1 = malloc((size_t)n * (RPR3_NUM_OUTPUTS + k) * sizeof *o1);
    o2 = malloc((size_t)n * k * k * sizeof *o2);
    o3 = malloc((size_t)n * k * k * sizeof *o3);
    o4 = malloc((size_t)n * k * k * sizeof *o4);
    for (which = 0; which < 8; ++which) {
        for (round = 0; round < 7; ++round) {
            double t0 = now();
            if (which >= 4) {
                for (i = 0; i < 3; ++i) {
                    if (which == 4)
                        rpr3_inverse_dynamics_batch(p, n, q, qd, qdd, o1);
                    else if (which == 5)
                        rpr3_inverse_dynamics_derivatives_batch(p, n, q, qd, qdd, o1, o2, o3, o4);
                    else if (which == 6)
                        rpr3_forward_dynamics_batch(p, n, q, qd, tau, o1);
                    else
                        rpr3_forward_dynamics_derivatives_batch(p, n, q, qd, tau, o1, o2, o3, o4);
                    sink += o1[0];
                }
                r[round] = (now() - t0) / (3.0 * n);
                continue;
            }
            for (i = 0; i < calls; ++i) {
                int s = i % n;
                if (which == 0)
                    rpr3_inverse_dynamics(p, q + s * k, qd + s * k, qdd + s * k, o1);
                else if (which == 1)
                    rpr3_inverse_dynamics_derivatives(p, q + s * k, qd + s * k, qdd + s * k, o1,
                                                      o2, o3, o4);
                else if (which == 2)
                    rpr3_forward_dynamics(p, q + s * k, qd + s * k, tau + s * k, o1);
                else
                    rpr3_forward_dynamics_derivatives(p, q + s * k, qd + s * k, tau + s * k, o1,
                                                      o2, o3, o4);
                sink += o1[0];
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

ROBOTS = (
    ("paper (revolute)", None, None),
    ("3-RRR", "rrr.toml", "loop.csv"),
    ("Delta", "delta.toml", "delta.csv"),
    ("6-UPS", "tsai-ups.toml", "tsai-ups.csv"),
)


def _motion(model_file: str | None, trajectory: str | None) -> tuple:
    if model_file is None:
        model = rpr3gen.load_model()
        traj = rpr3gen.paper_trajectory("rotation")
    else:
        model = rpr3gen.load_model(ROOT / "models" / model_file)
        assert trajectory is not None
        traj = rpr3gen.read_trajectory_csv(ROOT / "models" / trajectory, pose=model.structure.pose)
    idx = np.linspace(0, len(traj.t) - 1, 1024).astype(int)
    return model, traj.q[idx], traj.qd[idx], traj.qdd[idx]


def measure(model_file: str | None, trajectory: str | None) -> dict[str, float]:
    model, q, qd, qdd = _motion(model_file, trajectory)
    tau = control.actuator_efforts(model, q, qd, qdd)
    folder = ROOT / "generated" / model.variant
    params = model.vector()
    derivatives = folder / "rpr3_derivatives.c"
    large = derivatives.stat().st_size > cbackend.LARGE_UNIT
    base = [f for f in cbackend.CFLAGS if f not in ("-shared", "-fPIC")]
    extra = list(next(iter(cbackend.EXTRA_FLAGS)))
    cc = os.environ.get("CC", "cc")
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "in.bin"
        with open(data, "wb") as f:
            np.array([q.shape[1], len(params), len(q)], dtype=np.intc).tofile(f)
            for a in (params, q, qd, qdd, tau):
                np.ascontiguousarray(a, dtype=np.float64).tofile(f)
        (Path(tmp) / "bench.c").write_text(HARNESS)
        objects = []
        for source, flags in (
            (folder / "rpr3.c", base),
            (derivatives, ["-O0" if x == "-O3" else x for x in base] if large else base),
            (Path(tmp) / "bench.c", base),
        ):
            obj = Path(tmp) / f"{source.stem}.o"
            subprocess.run([cc, *flags, *extra, "-I", str(folder), "-c", str(source), "-o",
                            str(obj)], check=True)  # fmt: skip
            objects.append(str(obj))
        exe = Path(tmp) / "bench"
        subprocess.run([cc, *objects, "-o", str(exe), "-lm"], check=True)
        calls = "20000" if large else "100000"
        result = subprocess.run([str(exe), str(data), calls], check=True, capture_output=True,
                                text=True)  # fmt: skip
    return {line.split()[0]: float(line.split()[1]) for line in result.stdout.splitlines()}


def main() -> int:
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.2f}")  # fmt: skip
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
        cpu = next(line.split(":", 1)[1].strip() for line in lines if line.startswith("model name"))
        family = next(line.split(":", 1)[1].strip() for line in lines if "cpu family" in line)
        print(f"cpu: {cpu}, family {family}")
    except (OSError, StopIteration):
        pass
    print("| robot | ID (ns) | ID derivatives (ns) | ratio | FD (ns) | FD derivatives (ns) | ratio "
          "| batch: ID, IDd, FD, FDd (ns/sample) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for name, model, traj in ROBOTS:
        r = measure(model, traj)
        batch = ", ".join(f"{r[x]:.0f}" for x in ("ID_batch", "IDd_batch", "FD_batch", "FDd_batch"))
        print(
            f"| {name} | {r['ID']:.0f} | {r['IDd']:.0f} | {r['IDd'] / r['ID']:.1f}x | "
            f"{r['FD']:.0f} | {r['FDd']:.0f} | {r['FDd'] / r['FD']:.1f}x | {batch} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
