"""The NumPy backend: one module ``{prefix}_numpy.py`` per variant, needing only numpy.

Each function is lowered to ufunc calls into reused buffers (:mod:`.lowering`) and takes
``params`` (P,), its inputs as (n, size) arrays and writes its outputs into (size, n) arrays.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import jinja2
from rpr3gen_derive.codegen import mathkernels
from rpr3gen_derive.codegen.backends.python.lowering import lower_numpy
from rpr3gen_derive.codegen.compiled import name_tables, table_count
from rpr3gen_derive.codegen.spec import ModuleSpec

#: The ufuncs the module's ``_sincos`` helper calls (through the same module-level names).
SINCOS_UFUNCS = frozenset({"absolute", "add", "cos", "multiply", "rint", "sin", "subtract"})
#: The ufuncs the module's ``_atan2`` helper calls.
ATAN2_UFUNCS = frozenset({"add", "arctan", "arctan2", "copysign", "divide", "isnan", "multiply",
                          "signbit"})  # fmt: skip

if TYPE_CHECKING:
    from rpr3gen_derive.codegen.compiled import Compiled, Stage


def render(
    module: ModuleSpec,
    compiled: list[Compiled],
    digest: str,
    env: jinja2.Environment,
    stage: Stage,
) -> dict[str, tuple[str, str]]:
    """``{"numpy": (file name, text)}`` of one module."""

    functions = []
    constants: dict[str, str] = {}  # the module's number constants, shared by its functions
    with stage("print"):
        for c in compiled:
            if c.spec.c_body is not None:  # C only: the runtime composes it from the others
                continue
            inputs = {s: str(s) for arg in c.spec.inputs for s in arg.symbols}
            params = c.param_symbols(module.params)
            rows = {f"{o}[{k}]": f"{o}[{k}]" for o, k in c.slots}
            functions.append(
                {
                    "c": c,
                    "spec": c.spec,
                    "name": f"{module.prefix}_{c.spec.name}",
                    "lowered": lower_numpy(c.code, inputs, params, rows, constants, module.legs),
                    "first_input": c.spec.inputs[0].name,
                    "sizes": {
                        o.name: table_count(o.table) if o.table else str(o.size)
                        for o in c.spec.outputs
                    },
                }
            )
    tables = name_tables(module, compiled)
    sincos = any(f["lowered"].sincos for f in functions)
    ufuncs = set().union(*(f["lowered"].ufuncs for f in functions))
    if sincos:  # _sincos calls its ufuncs by the same names
        ufuncs |= SINCOS_UFUNCS
    atan2 = any(f["lowered"].atan2 for f in functions)
    if atan2:
        ufuncs |= ATAN2_UFUNCS
    with stage("render"):
        text = env.get_template("backends/python/templates/module.py.jinja").render(
            module=module,
            functions=functions,
            tables=tables,
            source_hash=digest,
            sincos=sincos,
            atan2=atan2,
            ufuncs=sorted(ufuncs),
            constants=[(name, text) for text, name in constants.items()],
            sin_coefficients=[mathkernels.literal(c) for c in mathkernels.SIN],
            cos_coefficients=[mathkernels.literal(c) for c in mathkernels.COS],
            two_over_pi=mathkernels.TWO_OVER_PI,
            pi_over_2=[mathkernels.literal(float.fromhex(h)) for h in mathkernels.PI_OVER_2_PARTS],
            ops_before=sum(c.code.ops_before for c in compiled),
            ops_after=sum(c.code.ops_after for c in compiled),
            assignments=sum(len(c.code.assignments) for c in compiled),
        )
    return {"numpy": (f"{module.prefix}_numpy.py", text)}
