"""Operation counts and numeric statistics of the control model (docs/control-model.md).

Run with the project's interpreter (``dev`` extra)::

    python benchmarks/control_ops.py

It prints Markdown: for each control-model function and actuation, the operations of its live
program before and after ``sympy.cse`` (``order="canonical"``, counted by ``sympy.count_ops``, as
the engine counts them); the number of assembly modes over random robots and poses; and the
Newton iterations of the tracked forward kinematics on the paper's trajectories sampled at 1 ms.
Needs SymPy and NumPy only (not the code-generation engine).
"""

from __future__ import annotations

import collections
import sys
from pathlib import Path

import numpy as np
import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import control, registry, structures

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import fk_reference as fk  # the numeric prototype, a test helper
import newton_euler as ne  # the independent reference, a test helper

#: The paper's two actuations, by variant name.
ACTUATIONS = ("revolute", "prismatic")


def ops(program: Program, outputs: list[sp.Expr]) -> tuple[int, int]:
    """Operations of the live assignments and ``outputs``, before and after CSE."""
    needed: set[sp.Symbol] = set()
    for expr in outputs:
        needed |= sp.sympify(expr).free_symbols
    live = []
    for a in reversed(program.assignments):
        if a.symbol in needed:
            live.append(a.expr)
            needed |= a.expr.free_symbols
    exprs = live[::-1] + [sp.sympify(e) for e in outputs]
    before = sum(int(sp.count_ops(e)) for e in exprs)
    temporaries, reduced = sp.cse(
        exprs, symbols=sp.numbered_symbols("x", real=True), order="canonical"
    )
    after = sum(int(sp.count_ops(e)) for _, e in temporaries) + sum(
        int(sp.count_ops(e)) for e in reduced
    )
    return before, after


def track(
    geom: fk.Geometry, actuation: str, q: np.ndarray, reference: str
) -> tuple[list[int], int, float]:
    """The tracked forward kinematics along the poses ``q``, from the previous solution or
    (``reference="predicted"``) ``2 q[k-1] - q[k-2]``: the Newton steps of each sample, the
    fallbacks, and the largest distance from the true pose."""
    prev = prev2 = tuple(q[0])
    steps, fallbacks, error = [], 0, 0.0
    for row in q:
        qa = fk.actuator_coordinates(geom, actuation, row)
        near = prev
        if reference == "predicted":
            near = tuple(2 * a - b for a, b in zip(prev, prev2, strict=True))
        result = fk.tracked_forward_kinematics(geom, actuation, qa, near)
        steps.append(result.iterations)
        fallbacks += result.status != "newton"
        error = max(error, fk.distance(geom, result.q, row))
        prev2, prev = prev, result.q
    return steps, fallbacks, error


def main() -> None:
    print("| function | actuation | ops before CSE | ops after CSE |")
    print("|---|---|---|---|")
    for actuation in ACTUATIONS:
        for spec in registry.module(structures.from_variant(actuation)).functions:
            if spec.c_body is None:  # guards (the failure checks' values) are counted too
                exprs = [e for _, _, e in spec.flat_outputs()]
                before, after = ops(spec.program, exprs)
                print(f"| {spec.name} | {actuation} | {before} | {after} |")
        for method in ("efforts",):
            prog = Program()
            M, c = control.task_space_dynamics(
                prog, structures.from_variant(actuation), method=method
            )
            before, after = ops(prog, [*M, *c])
            print(f"| task_space_dynamics (method={method}) | {actuation} | {before} | {after} |")

    print("\n| actuation | modes: samples with k modes |")
    print("|---|---|")
    rng = np.random.default_rng(0)
    counts: dict[str, collections.Counter] = {a: collections.Counter() for a in ACTUATIONS}
    for trial in range(1000):
        params = ne.paper_params() if trial == 0 else ne.random_robot(rng)["params"]
        geom = fk.Geometry.from_params(params)
        q = (rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(-0.6, 0.6))
        for actuation in ACTUATIONS:
            qa = fk.actuator_coordinates(geom, actuation, q)
            counts[actuation][len(fk.assembly_modes(geom, actuation, qa))] += 1
    for actuation, counter in counts.items():
        cells = ", ".join(f"{k}: {counter[k]}" for k in sorted(counter))
        print(f"| {actuation} | {cells} |")

    print(
        "\n| trajectory | actuation | reference | mean Newton steps | max | fallbacks "
        "| max error (m) |"
    )
    print("|---|---|---|---|---|---|---|")
    params = ne.paper_params()
    geom = fk.Geometry.from_params(params)
    for kind in ("rotation", "rectilinear"):
        _, q, _, _ = ne.paper_motion(kind, samples=3001)  # 1 ms
        for actuation in ACTUATIONS:
            for reference in ("previous", "predicted"):
                steps, fallbacks, error = track(geom, actuation, q, reference)
                print(
                    f"| {kind} | {actuation} | {reference} | {np.mean(steps):.3f} | {max(steps)} "
                    f"| {fallbacks} | {error:.1e} |"
                )


def random_motions() -> None:
    """Tracking on ten random robots and motions (``newton_euler.random_case``), 2 s at 1 ms."""
    print(
        "\n| random motions, 1 ms | actuation | reference | mean Newton steps | max "
        "| fallbacks | max error (m) | motions crossing det J = 0 |"
    )
    print("|---|---|---|---|---|---|---|---|")
    t = np.arange(0.0, 2.0, 1e-3)
    cases = [ne.random_case(seed, t) for seed in range(10)]
    for actuation in ACTUATIONS:
        for reference in ("previous", "predicted"):
            steps, fallbacks, error, crossing = [], 0, 0.0, 0
            for robot, q, _, _ in cases:
                geom = fk.Geometry.from_params(robot["params"])
                dets = [fk.det3(fk.actuator_jacobian(geom, actuation, row)) for row in q]
                crossing += min(dets) < 0 < max(dets)
                case_steps, case_fallbacks, case_error = track(geom, actuation, q, reference)
                steps += case_steps
                fallbacks += case_fallbacks
                error = max(error, case_error)
            print(
                f"| | {actuation} | {reference} | {np.mean(steps):.3f} | {max(steps)} "
                f"| {fallbacks} | {error:.1e} | {crossing} of {len(cases)} |"
            )


if __name__ == "__main__":
    main()
    random_motions()
