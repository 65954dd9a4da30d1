"""Lower a compiled function to the lines of its graph function: loads, assignments, outputs.

The loads are the C kernel's (``m_A = params[5]``, ``x = q[0]``: only what the code reads),
the assignments the straight-line program after CSE in its order, each printed over ``ops``
(:mod:`.printer`); the outputs are returned as one list of scalars per output array, hidden ones
(the values the failure checks test) last, as in the manifest. Nothing is folded or scheduled:
the callers' own compilers (CasADi's, XLA's) do that.
"""

from __future__ import annotations

import keyword
from dataclasses import dataclass

from rpr3gen_derive.codegen.backends.graph.printer import graph_code
from rpr3gen_derive.codegen.compiled import Compiled

#: The names a generated graph function's arguments take besides its inputs'.
RESERVED = frozenset({"ops", "params"})


@dataclass(frozen=True)
class LoweredGraph:
    """The body of one graph function: ``lines`` (``name = text``) and, per output array in
    order, the texts of its components."""

    lines: tuple[tuple[str, str], ...]
    outputs: tuple[tuple[str, tuple[str, ...]], ...]


def _check_name(name: str, where: str) -> None:
    if keyword.iskeyword(name) or name in RESERVED or not name.isidentifier():
        raise ValueError(f"{where}: {name!r} cannot be a local name of a graph function")


def lower_graph(c: Compiled) -> LoweredGraph:
    """The lines and outputs of ``c``'s graph function."""
    where = c.spec.name
    arguments = {arg.name for arg in c.spec.inputs}
    lines = [(name, f"params[{k}]") for k, name in c.used_params]
    lines += [(name, f"{arg}[{k}]") for arg, k, name in c.used_inputs]
    lines += [(str(lhs), graph_code(rhs)) for lhs, rhs in c.code.assignments]
    for name, _ in lines:
        _check_name(name, where)
        if name in arguments:
            raise ValueError(f"{where}: the local {name!r} would hide an input")
    texts: dict[str, list[str]] = {o.name: [] for o in c.spec.outputs}
    for (output, _), (_, expr) in zip(c.slots, c.code.outputs, strict=True):
        texts[output].append(graph_code(expr))
    return LoweredGraph(tuple(lines), tuple((o.name, tuple(texts[o.name])) for o in c.spec.outputs))
