"""The order of a single-sample kernel's statements: few values live at once.

gcc does not reorder a long straight-line function before register allocation on x86 (there is
no pre-allocation scheduler there), so the order of the C statements is the order of the
machine code, and every value computed early and read late holds a register, or is spilled to
the stack and loaded again. The derivation's order (every leg's kinematics, then every leg's
dynamics, then the closure, then the outputs, the outputs stored last) keeps hundreds of values
live: the inverse dynamics spilled ~290 times a call, and its single call was bound by those
loads and stores, not by its arithmetic.

:func:`schedule` is a greedy list scheduler over the kernel's dependency graph (parameter and
input loads, assignments, output stores): among the statements whose operands are all computed,
it emits the one that ends the most live values net of the one it starts (an output store
starts none; a load starts one). Ties go to the statement with the longest chain of work still
to run after it (:func:`_heights`: a division or square root weighs 20, a sin, cos or atan2 60,
anything else 1, roughly their latencies in additions), so that the long chains start early and
the processor overlaps them with the rest; then to a depth-first order from the outputs. The
tie-break by chain length took the 3-RPR's inverse dynamics from 139 to 123 ns a call
(revolute; 143 to 129 ns prismatic) in a scratch harness on the benchmarks' machine; the
depth-first tie-break alone follows the outputs' order, whatever the latencies. Values are
unchanged, only their order: the kernel gives the same bits (no statement is re-associated), and
the batch, which runs the same statements in its own loops, still agrees with it bit for bit.
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class Line:
    """One statement of a kernel: ``kind`` is ``"load"``, ``"assign"`` or ``"store"``; it
    defines ``name`` (``""`` for a store) and reads ``reads`` (names defined by other lines)."""

    kind: str
    name: str
    reads: frozenset[str]
    payload: tuple[str, ...]  # what the template prints, by kind


def schedule(lines: Sequence[Line]) -> list[Line]:
    """``lines`` in an order that keeps few values live (see the module's docstring).

    Every line comes after the lines defining what it reads, as in ``lines`` (which must be in
    a valid order); stores keep their relative order. Deterministic: no set order leaks.
    """
    index = {line.name: k for k, line in enumerate(lines) if line.name}
    deps = [sorted({index[r] for r in line.reads if r in index}) for line in lines]
    users: list[list[int]] = [[] for _ in lines]
    for k, ds in enumerate(deps):
        for d in ds:
            users[d].append(k)
    rank = _depth_first(lines, deps)
    height = _heights(lines, users)
    remaining = [len(u) for u in users]  # users of each value not yet emitted
    waiting = [len(d) for d in deps]  # operands of each line not yet emitted
    freed = [0] * len(lines)  # operands whose last user the line is
    starts = [0 if line.kind == "store" or not users[k] else 1 for k, line in enumerate(lines)]
    emitted = [False] * len(lines)
    heap: list[tuple[int, int, int, int]] = []

    def push(k: int) -> None:
        heapq.heappush(heap, (starts[k] - freed[k], -height[k], rank[k], k))

    for k in range(len(lines)):
        if waiting[k] == 0:
            push(k)
    order: list[int] = []
    while heap:
        key, _, _, k = heapq.heappop(heap)
        if emitted[k] or key != starts[k] - freed[k]:
            continue  # emitted already, or an entry older than the line's current key
        emitted[k] = True
        order.append(k)
        for d in deps[k]:
            remaining[d] -= 1
            if remaining[d] == 1:  # its one user left now ends it
                last = next(u for u in users[d] if not emitted[u])
                freed[last] += 1
                if waiting[last] == 0:
                    push(last)
        for u in users[k]:
            waiting[u] -= 1
            if waiting[u] == 0:
                push(u)
    assert len(order) == len(lines), "the kernel's statements have a cycle"
    return [lines[k] for k in order]


#: The calls that make a statement weigh 60 in :func:`_heights` (the math kernels' names end so).
SLOW_CALLS = ("sin(", "cos(", "atan2(")


def _weight(line: Line) -> int:
    """A statement's weight in :func:`_heights`: its costliest operation, in additions."""
    text = " ".join(line.payload)
    if any(call in text for call in SLOW_CALLS):
        return 60
    if "/" in text or "sqrt(" in text:
        return 20
    return 1


def _heights(lines: Sequence[Line], users: list[list[int]]) -> list[int]:
    """Per line, its weight (:func:`_weight`) plus the largest height among its users: the
    chain of work that still waits on it. ``lines`` is in a valid order, so users come later."""
    height = [0] * len(lines)
    for k in range(len(lines) - 1, -1, -1):
        height[k] = _weight(lines[k]) + max((height[u] for u in users[k]), default=0)
    return height


def _depth_first(lines: Sequence[Line], deps: list[list[int]]) -> list[int]:
    """Rank of each line in a depth-first post-order from the stores, in their order (then any
    line no store needs, in order): the tie-break, which keeps a value's producers together."""
    rank = [-1] * len(lines)
    count = 0
    roots = [k for k, line in enumerate(lines) if line.kind == "store"]
    for root in [*roots, *range(len(lines))]:
        stack = [(root, 0)]
        while stack:
            k, child = stack.pop()
            if rank[k] >= 0:
                continue
            if child < len(deps[k]):
                stack.append((k, child + 1))
                d = deps[k][child]
                if rank[d] < 0:
                    stack.append((d, 0))
                continue
            rank[k] = count
            count += 1
    return rank
