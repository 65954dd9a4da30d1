"""NumPy against Newton-Euler, timed in turn: ``python harness/paired.py [--quick] -o FILE.json``.

The ratio of two figures timed minutes apart is the ratio of two spells of this shared machine
as much as of two codes: one busy minute can slow one side and not the other. Here both sides
are timed in the same process, in rounds: each round times ``rpr3gen.evaluate(model,
"inverse_dynamics", ..., backend="numpy")`` and the independent Newton-Euler solver
(``tests/newton_euler.py``, in chunks of :data:`NE_CHUNK` samples so that its (n, 21, 21)
systems fit) on the same samples, one right after the other, the order alternating from round
to round. A slow spell then falls on both sides of a round, and the best round of each side
comes from the same minutes.

Per paper variant, motion and size (:data:`ROUNDS`: 10^4, 10^5, 10^6 samples), the file holds
every round's seconds per call of each side (``numpy``, ``newton_euler``); ``report.py`` gives
the ratio of the two best (each side's least disturbed round) and the median of the rounds'
ratios. A side's time in a round is the mean of as many calls as last :data:`ROUND_SECONDS`
(one at least), after one untimed call of each side (first-touch of the samples and pages).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import rpr3gen
from harness import samples
from harness.samples import test_module

NE_CHUNK = 10**5
#: Rounds per size, full run / quick run (0: not measured).
ROUNDS = {10**4: (15, 3), 10**5: (9, 3), 10**6: (3, 0)}
#: The least time a side's calls take in one round (s): short calls are repeated to it.
ROUND_SECONDS = 0.05


def sides(variant: str, motion: str, n: int) -> dict[str, Callable[[], object]]:
    """The two calls timed, on the same n samples of the motion: ours and the reference."""
    model = samples.model(variant)
    params = dict(model.params)
    ne = test_module("newton_euler")
    a = samples.motion(variant, motion, n)
    q, qd, qdd = a["q"], a["qd"], a["qdd"]

    def ours() -> object:
        return rpr3gen.evaluate(model, "inverse_dynamics", [q, qd, qdd], backend="numpy")

    def reference() -> None:
        for k in range(0, n, NE_CHUNK):
            s = slice(k, k + NE_CHUNK)
            ne.solve(params, variant, q[s], qd[s], qdd[s])

    return {"numpy": ours, "newton_euler": reference}


def seconds(call: Callable[[], object], loops: int) -> float:
    """Mean seconds of ``loops`` calls."""
    start = time.perf_counter()
    for _ in range(loops):
        call()
    return (time.perf_counter() - start) / loops


def paired(calls: dict[str, Callable[[], object]], rounds: int) -> dict[str, list[float]]:
    """Every round's seconds per call of each side, the sides in turn (order alternating)."""
    loops = {}
    for name, call in calls.items():  # the untimed call, which also sizes the rounds
        once = seconds(call, 1)
        loops[name] = max(1, round(ROUND_SECONDS / max(once, 1e-9)))
    found: dict[str, list[float]] = {name: [] for name in calls}
    names = list(calls)
    for k in range(rounds):
        for name in names if k % 2 == 0 else names[::-1]:
            found[name].append(seconds(calls[name], loops[name]))
    return found


def run(quick: bool) -> dict[str, dict[str, list[float]]]:
    """``paired/VARIANT/MOTION/N`` -> each side's seconds per call, every round."""
    np.seterr(all="ignore")
    results = {}
    for variant in samples.paper_variants():
        for motion in samples.MOTIONS:
            for n, counts in ROUNDS.items():
                rounds = counts[1 if quick else 0]
                if rounds:
                    print(f"paired: {variant} {motion} 10^{len(str(n)) - 1}", file=sys.stderr)
                    key = f"paired/{variant}/{motion}/{n}"
                    results[key] = paired(sides(variant, motion, n), rounds)
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help="fewer rounds, no 10^6")
    parser.add_argument("-o", "--output", type=Path, required=True, help="the JSON written")
    args = parser.parse_args()
    args.output.write_text(json.dumps(run(args.quick)) + "\n")


if __name__ == "__main__":
    main()
