"""The graph backend: one module ``{prefix}_graph.py`` per variant, plain scalar Python over a
math namespace, for the bridges that build a symbolic graph from it (``rpr3gen.casadi``:
CasADi's SX; ``rpr3gen.jax``: JAX's traced arrays).

Each function with a program is ``def name(ops, params, *inputs) -> tuple of output lists``:
``params`` and every input indexable by component (a CasADi column, a JAX array, a list),
``ops`` the namespace of :data:`.printer.OPS`. The functions with a hand-written C body have no
graph function; the bridges compose them from the others (``rpr3gen.graph_compose``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import jinja2
from rpr3gen_derive.codegen.backends.graph.lowering import lower_graph
from rpr3gen_derive.codegen.backends.graph.printer import OPS
from rpr3gen_derive.codegen.spec import ModuleSpec

if TYPE_CHECKING:
    from rpr3gen_derive.codegen.compiled import Compiled, Stage


def render(
    module: ModuleSpec,
    compiled: list[Compiled],
    digest: str,
    env: jinja2.Environment,
    stage: Stage,
) -> dict[str, tuple[str, str]]:
    """``{"graph": (file name, text)}`` of one module."""
    with stage("print"):
        functions = [
            {"spec": c.spec, "lowered": lower_graph(c)} for c in compiled if c.spec.c_body is None
        ]
    with stage("render"):
        text = env.get_template("backends/graph/templates/graph.py.jinja").render(
            module=module, functions=functions, source_hash=digest, ops=sorted(OPS.items())
        )
    return {"graph": (f"{module.prefix}_graph.py", text)}


__all__ = ["render"]
