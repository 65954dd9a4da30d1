"""A generated kernel's chain floor: its longest chain of dependent operations, timed.

A single call cannot finish before its longest chain of dependent operations does, however
many of its other operations the processor overlaps with it. The chain floor of a kernel is that
chain's length in nanoseconds: its dependency graph, read from the generated C, each operation
weighted by its latency on this machine, which ``benchmarks/c/latency.c`` measures in the same
run (a loop of one operation feeding the next; ``LATENCIES`` names them). It is a lower bound of
the single call, as the libm floor (:mod:`harness.cbench`) is of the batch, and the two bound
different things: the libm floor is what the calls cost when nothing waits for them, the chain
floor what the call costs when it waits for nothing but its own results.

The bound is kept a lower bound where the model is unsure: inputs and parameters are ready at
time 0 (no load latency), a negation, ``fabs`` or a constant costs nothing, moving a value out of
a lane costs nothing, and the statements are evaluated as the C is written (gcc does not
re-associate floating-point arithmetic without ``-ffast-math``, so it cannot shorten a chain
except by exact rewrites of equal latency). A leg's statements in a lane loop
(``derive/codegen/backends/c/lanes.py``) run side by side, so the loop's body counts once.

A kernel that is not straight-line code (the iterative forward kinematics: loops, branches,
calls to other kernels) has no chain floor here (``None``). Nothing is timed in this module.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Mapping

from rpr3gen_derive.codegen.backends.c.lanes import LOOP

#: The operations whose latency ``latency.c`` measures, by the name it prints.
LATENCIES = ("add", "mul", "div", "sqrt", "sin", "cos", "atan2", "fmin", "rint")
#: C calls and the latency that stands for each: libm's, and the generated math kernels
#: ``PREFIX_sin`` etc. (``None``: costs nothing on a chain).
CALLS = {"sqrt": "sqrt", "fabs": None}
KERNELS = {
    "sin": "sin",
    "cos": "cos",
    "atan2": "atan2",
    "fmin": "fmin",
    "fmax": "fmin",
    "rint": "rint",
}
#: C's arithmetic operators and the latency that stands for each.
_OPERATIONS: dict[type, str] = {ast.Add: "add", ast.Sub: "add", ast.Mult: "mul", ast.Div: "div"}
_ASSIGN = re.compile(r"(?:const double )?(\w+)(\[[^\]]*\])? = (.+);$")
#: Lines of a kernel that define no value and make no chain longer: declarations (of arrays, and
#: of the sine and cosine that a ``PREFIX_sincos`` call then defines), the guards' early returns,
#: and the header of a loop over ``i`` (a lane loop, or the copy of the legs' parameters into
#: ``params_by_leg``, whose iterations are independent).
_SKIP = re.compile(
    r"(double \w+\[\d+\];|double \w+, \w+;|int i;|\{|\}|return \w+;|if \(!\(.*"
    r"|for \(i = 0; i < \d+; \+\+i\) \{)"
    r"(\s*/\*.*\*/)?$"
)


def kernel_bodies(source: str, prefix: str) -> dict[str, str]:
    """The body of each ``static int PREFIX_NAME_kernel(...)`` of a generated C source, by name."""
    bodies = {}
    for match in re.finditer(rf"^static int {prefix}_(\w+)_kernel\(", source, re.M):
        bodies[match.group(1)] = source[match.start() : source.index("\n}\n", match.start())]
    return bodies


def calls(line: str, prefix: str) -> list[str]:
    """The kernels a line of generated C calls (``PREFIX_NAME_kernel(...)``), by name."""
    return re.findall(rf"\b{prefix}_(\w+)_kernel\(", line)


def called(body: str, prefix: str) -> set[str]:
    """The other kernels a kernel's ``body`` (:func:`kernel_bodies`) calls."""
    return set(calls(body.split("{", 1)[1], prefix))


def critical_path(body: str, latency: Mapping[str, float], prefix: str = "rpr3") -> float | None:
    """The longest chain of dependent operations of a kernel's ``body``, in the units of
    ``latency`` (``{name in LATENCIES: time}``); ``None`` when the body is not straight-line
    code of assignments this model reads (see the module's docstring). ``prefix``: the
    generated C's (its math kernels are ``PREFIX_sin`` etc.)."""
    calls = {**CALLS, **{f"{prefix}_{name}": op for name, op in KERNELS.items()}}
    ready: dict[str, float] = {}
    longest = 0.0
    lines = body.split("{", 1)[1].splitlines()  # after the signature
    for line in lines:
        text = line.strip()
        if not text or LOOP.fullmatch(text) or _SKIP.fullmatch(text):
            continue
        pair = re.fullmatch(rf"{prefix}_sincos\((.+), &(\w+), &(\w+)\);", text)
        if pair is not None:  # sin and cos of one argument, side by side
            try:
                start = _finish(ast.parse(pair[1], mode="eval").body, ready, latency, calls)
            except (SyntaxError, _UnreadError):
                return None
            done = start + max(latency["sin"], latency["cos"])
            ready[pair[2]] = ready[pair[3]] = done
            longest = max(longest, done)
            continue
        match = _ASSIGN.match(text)
        if match is None:
            return None
        name, index, expression = match.groups()
        try:
            done = _finish(ast.parse(expression, mode="eval").body, ready, latency, calls)
        except (SyntaxError, _UnreadError):
            return None
        # an array (a lane's values, an output's entries) is ready when its last entry is
        ready[name] = max(done, ready.get(name, 0.0)) if index else done
        longest = max(longest, done)
    return longest


class _UnreadError(Exception):
    """An expression this model does not read."""


def _finish(
    node: ast.expr,
    ready: Mapping[str, float],
    latency: Mapping[str, float],
    calls: Mapping[str, str | None],
) -> float:
    """When the value of ``node`` is ready, its operands ready at ``ready``."""
    if isinstance(node, ast.Constant):
        return 0.0
    if isinstance(node, ast.Name):
        return ready.get(node.id, 0.0)  # an input's or parameter's name: ready at once
    if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name):
        return ready.get(node.value.id, 0.0)  # params[k], an input q[k], a lane's x_legs[k]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        return _finish(node.operand, ready, latency, calls)
    if isinstance(node, ast.BinOp) and type(node.op) in _OPERATIONS:
        a = _finish(node.left, ready, latency, calls)
        b = _finish(node.right, ready, latency, calls)
        if _constant(node.left) and _constant(node.right):
            return 0.0  # folded by the compiler
        return max(a, b) + latency[_OPERATIONS[type(node.op)]]
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "pow":
        base, exponent = node.args
        if isinstance(exponent, ast.Constant) and exponent.value == 2:
            return _finish(base, ready, latency, calls) + latency["mul"]  # gcc: pow(x, 2) is x*x
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in calls:
        done = max((_finish(a, ready, latency, calls) for a in node.args), default=0.0)
        which = calls[node.func.id]
        return done + (latency[which] if which else 0.0)
    raise _UnreadError(ast.dump(node))


def _constant(node: ast.expr) -> bool:
    if isinstance(node, ast.Constant):
        return True
    if isinstance(node, ast.UnaryOp):
        return _constant(node.operand)
    if isinstance(node, ast.BinOp):
        return _constant(node.left) and _constant(node.right)
    return False
