"""Identification benchmark: the generated regressor against the inverse dynamics, per sample.

    .venv/bin/python benchmarks/identification.py [--samples N] [--repeats R]

Times, in one run on this machine, the C batch (the runtime's compiled library, flags of
``rpr3gen.cbackend``) and the NumPy functions of ``regressor`` (Y, 3 x 28), ``payload_efforts``
and ``inverse_dynamics`` (53 outputs) over the same random motion of the paper's robot, both
actuations: the best of R runs, ns per sample, and the ratio regressor / inverse dynamics.
Also the time of one ``rpr3gen.identify`` and one ``base_parameters``. Not a test: figures
depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import time

import numpy as np

import rpr3gen
from rpr3gen import manifest
from rpr3gen.evaluators import evaluator

#: Time the optimised C libraries, not the quick ones a first use runs on (rpr3gen.cbackend).
os.environ.setdefault("RPR3GEN_C_BUILD", "optimised")

FUNCTIONS = ("inverse_dynamics", "regressor", "payload_efforts")


def _motion(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(1)
    q = rng.uniform([-0.03, -0.03, -0.25], [0.03, 0.03, 0.25], (n, 3))
    qd = rng.uniform(-0.3, 0.3, (n, 3))
    qdd = rng.uniform(-2.0, 2.0, (n, 3))
    return q, qd, qdd


def _best(call, repeats: int) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    n = args.samples
    q, qd, qdd = _motion(n)
    print(f"# identification benchmark: {n} samples, best of {args.repeats}")
    print(
        f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
        f"Python {platform.python_version()}, NumPy {np.__version__}"
    )
    print(
        "| actuation | backend | inverse_dynamics | regressor | payload_efforts | regressor / ID |"
    )
    print("|---|---|---|---|---|---|")
    for actuation in ("revolute", "prismatic"):
        model = dataclasses.replace(rpr3gen.load_model(), actuation=actuation)
        variant = manifest.load(actuation)
        params = model.vector(variant.param_names)
        for backend in ("c", "numpy"):
            ev = evaluator(variant, backend)
            ns = {}
            for name in FUNCTIONS:
                info = variant.function(name)
                inputs = {"inverse_dynamics": (q, qd, qdd), "regressor": (q, qd, qdd),
                          "payload_efforts": (q,)}[name]  # fmt: skip
                if backend == "numpy":  # the NumPy functions run in blocks, as the runtime does
                    block = 4096
                    outs = ev.allocate(info, block)

                    def call(
                        info=info, inputs=inputs, outs=outs, block=block, ev=ev, params=params
                    ) -> None:
                        for s in range(0, n - block + 1, block):
                            ev.run(info, params, [a[s : s + block] for a in inputs], outs)

                    done = (n // block) * block
                else:
                    outs = ev.allocate(info, n)

                    def call(info=info, inputs=inputs, outs=outs, ev=ev, params=params) -> None:
                        ev.run(info, params, inputs, outs)

                    done = n
                ns[name] = _best(call, args.repeats) / done * 1e9
            print(f"| {actuation} | {backend} | {ns['inverse_dynamics']:.0f} ns | "
                  f"{ns['regressor']:.0f} ns | {ns['payload_efforts']:.0f} ns | "
                  f"{ns['regressor'] / ns['inverse_dynamics']:.2f} |")  # fmt: skip
    model = rpr3gen.load_model()
    found = rpr3gen.excite(model, harmonics=4, period=8.0, samples=161, max_iterations=60)
    t = np.arange(0.0, 5 * found.motion.period, 0.01)
    mq, mqd, mqdd = found.motion.at(t)
    tau = rpr3gen.actuator_efforts(model, mq, mqd, mqdd)
    identify = _best(lambda: rpr3gen.identify(model, mq, mqd, mqdd, tau, friction=True), 3)
    print(f"\nidentify (friction, {len(t)} samples, numpy): {identify * 1e3:.1f} ms")
    start = time.perf_counter()
    rpr3gen.excite(model, harmonics=4, period=8.0, samples=161, max_iterations=60, seed=1)
    print(f"excite (4 harmonics, 161 samples, 60 iterations): {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
