"""Where the generated NumPy code spends its time: a profile per generated statement.

The generated module is not touched: :func:`instrumented` parses its source, takes one function
and inserts a clock reading after every statement of its body (the ufunc calls inside
``with numpy.errstate(...)`` too), then compiles that copy. Running it on a block of samples
gives the time of every statement, which :func:`profile` groups by what the statement does
(``numpy.multiply``, ``numpy.sin``, the input transposes, the work array...). The cost of the
clock itself is measured on an empty statement and subtracted. A ufunc's fixed cost per call
is measured apart, on one-element arrays: that part of a statement's time is the interpreter
and NumPy's dispatch, the rest is the pass over the block's arrays.
"""

from __future__ import annotations

import ast
import time
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

CLOCK = "_rpr3bench_clock"
TIMES = "_rpr3bench_times"


def _timed(body: list[ast.stmt], labels: list[str], source: str) -> list[ast.stmt]:
    """``body`` with ``TIMES[k] += CLOCK() - t; t = CLOCK()`` after its k-th statement."""
    out: list[ast.stmt] = []
    for stmt in body:
        if isinstance(stmt, ast.With):
            stmt.body = _timed(stmt.body, labels, source)
            out.append(stmt)
            continue
        k = len(labels)
        labels.append(
            (ast.get_source_segment(source, stmt) if source else None) or ast.unparse(stmt)
        )
        tick = ast.parse(f"_t1 = {CLOCK}()\n{TIMES}[{k}] += _t1 - _t0\n_t0 = _t1").body
        out += [stmt, *tick]
    return out


def instrumented(path: Path, name: str) -> tuple[Callable[..., Any], list[str], list[float]]:
    """The function ``name`` of the module at ``path``, timed statement by statement: the
    function, each statement's source, and the list its times accumulate into (seconds)."""
    source = path.read_text()
    tree = ast.parse(source)
    function = next(
        node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == name
    )
    labels: list[str] = []
    body = _timed(function.body[1:], labels, source)  # [0] is the docstring
    function.body = [function.body[0], *ast.parse(f"_t0 = {CLOCK}()").body, *body]
    module = ast.Module(body=[n for n in tree.body if n is not function] + [function],
                        type_ignores=[])  # fmt: skip
    times = [0.0] * len(labels)
    namespace: dict[str, Any] = {CLOCK: time.perf_counter, TIMES: times}
    exec(compile(ast.fix_missing_locations(module), str(path), "exec"), namespace)
    return namespace[name], labels, times


def kind(label: str) -> str:
    """What a generated statement does: the ufunc it calls, or a coarser name."""
    text = label.strip()
    if text.startswith("numpy.") and "(" in text:
        head = text.split("(", 1)[0]
        if head == "numpy.ascontiguousarray" or ".T)" in text:
            return "inputs: transpose to rows"
        return head
    if text.startswith("_") and "(" in text:  # a helper of the generated module
        return text.split("(", 1)[0]
    if "numpy.empty" in text:
        return "work array: numpy.empty"
    if "params[" in text:
        return "parameters: read"
    if "numpy.ascontiguousarray" in text:
        return "inputs: transpose to rows"
    return "scalar expressions of parameters"


@dataclass
class Profile:
    """Seconds per sample by kind of statement, calls per sample-block, fixed costs."""

    samples: int  # per call of the function
    calls: int  # timed calls
    by_kind: dict[str, float] = field(default_factory=dict)  # seconds per sample
    count: dict[str, int] = field(default_factory=dict)  # statements of each kind
    total: float = 0.0  # seconds per sample, all statements
    dispatch: dict[str, float] = field(default_factory=dict)  # s per call, one-element arrays
    top: list[tuple[float, str]] = field(default_factory=list)  # the costliest statements


def _dispatch_cost(kinds: list[str], repeats: int = 20000) -> dict[str, float]:
    """Seconds per call of each ufunc kind on one-element arrays (its fixed cost)."""
    import numpy

    a, b, out = numpy.ones(1), numpy.ones(1), numpy.empty(1)
    costs = {}
    for name in kinds:
        ufunc = getattr(numpy, name.removeprefix("numpy."), None)
        if not isinstance(ufunc, numpy.ufunc):
            continue
        args = (a, b)[: ufunc.nin]
        best = float("inf")
        for _ in range(5):
            start = time.perf_counter()
            for _ in range(repeats):
                ufunc(*args, out=out)
            best = min(best, (time.perf_counter() - start) / repeats)
        costs[name] = best
    return costs


def profile(
    path: Path, name: str, arguments: Callable[[], list[Any]], samples: int, calls: int
) -> Profile:
    """Profile ``name`` of the generated module ``path`` over ``calls`` calls on the
    ``arguments()`` of a block of ``samples`` samples."""
    function, labels, times = instrumented(path, name)
    args = arguments()
    function(*args)  # warm up
    for k in range(len(times)):
        times[k] = 0.0
    empty, _, empty_times = _empty_statement()
    for _ in range(calls):
        function(*args)
        empty()
    overhead = empty_times[0] / calls  # one clock tick, seconds per statement
    result = Profile(samples=samples, calls=calls)
    by_kind: dict[str, float] = defaultdict(float)
    count: dict[str, int] = defaultdict(int)
    per_statement = []
    for label, spent in zip(labels, times, strict=True):
        seconds = max(0.0, spent / calls - overhead) / samples
        by_kind[kind(label)] += seconds
        count[kind(label)] += 1
        per_statement.append((seconds, label.strip()))
    result.by_kind = dict(sorted(by_kind.items(), key=lambda item: -item[1]))
    result.count = dict(count)
    result.total = sum(by_kind.values())
    result.dispatch = _dispatch_cost([k for k in by_kind if k.startswith("numpy.")])
    result.top = sorted(per_statement, reverse=True)[:8]
    return result


def _empty_statement() -> tuple[Callable[[], None], list[str], list[float]]:
    """A function of one ``pass`` statement, timed the same way (the clock's own cost)."""
    tree = ast.parse("def empty():\n    pass\n")
    function = tree.body[0]
    assert isinstance(function, ast.FunctionDef)
    labels: list[str] = []
    function.body = [*ast.parse(f"_t0 = {CLOCK}()").body, *_timed(function.body, labels, "")]
    times = [0.0]
    namespace: dict[str, Any] = {CLOCK: time.perf_counter, TIMES: times}
    exec(compile(ast.fix_missing_locations(tree), "<empty>", "exec"), namespace)
    return namespace["empty"], labels, times
