"""A function spec compiled for the backends: common subexpressions eliminated, the inputs and
parameters it reads recorded; and the stage hook that times the engine's work.

The engine (:mod:`.render`) compiles every spec once and hands the result to each backend; the
backends import this module, never the engine.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass

import sympy as sp
from rpr3gen_derive.codegen.cse import StraightLine, straight_line
from rpr3gen_derive.codegen.spec import Argument, FunctionSpec, ModuleSpec, Output

Stage = Callable[[str], AbstractContextManager[object]]


def no_stage(name: str) -> AbstractContextManager[object]:
    """The default stage hook: does nothing."""
    return contextlib.nullcontext()


def table_count(table: str) -> str:
    """The count macro's suffix of a name table: ``output_names`` -> ``NUM_OUTPUTS``."""
    return f"NUM_{table.removesuffix('_names').upper()}S"


@dataclass(frozen=True)
class Compiled:
    """A function spec after common subexpression elimination, with what the backends need."""

    spec: FunctionSpec
    code: StraightLine
    used_params: tuple[tuple[int, str], ...]  # (index in params, name)
    used_inputs: tuple[tuple[str, int, str], ...]  # (input, index, symbol name)
    slots: tuple[tuple[str, int], ...]  # flat output index -> (output, component index)

    @property
    def input_symbols(self) -> set[sp.Symbol]:
        return {s for arg in self.spec.inputs for s in arg.symbols}

    def param_symbols(self, params: Argument) -> set[sp.Symbol]:
        """The symbols of ``params`` (the module's, compiled against) that the code reads."""
        return {params.symbols[k] for k, _ in self.used_params}


def compile_function(spec: FunctionSpec, params: Argument, legs: str = "") -> Compiled:
    """Eliminate common subexpressions of ``spec`` and record which inputs it reads; ``legs``:
    the module's legs' letters (:attr:`~rpr3gen_derive.codegen.spec.ModuleSpec.legs`)."""
    flat = spec.flat_outputs()
    if spec.c_body is not None:  # a hand-written kernel body: nothing to eliminate
        return Compiled(spec, StraightLine((), (), 0, 0), (), (), tuple((o, k) for o, k, _ in flat))
    reserved = frozenset(str(s) for arg in (params, *spec.inputs) for s in arg.symbols)
    code = straight_line(
        spec.program,
        [(f"{o}[{k}]", e) for o, k, e in flat],
        reserved,
        eliminate=not spec.straight,
        legs=legs,
    )
    used = set().union(*(rhs.free_symbols for _, rhs in code.assignments + code.outputs))
    names = {str(s) for s in used}
    unknown = names - {str(s) for s in params.symbols} - {str(s) for s, _ in code.assignments}
    unknown -= {str(s) for arg in spec.inputs for s in arg.symbols}
    if unknown:
        raise ValueError(f"{spec.name}: symbols neither inputs nor parameters: {sorted(unknown)}")
    return Compiled(
        spec=spec,
        code=code,
        used_params=tuple((k, str(s)) for k, s in enumerate(params.symbols) if str(s) in names),
        used_inputs=tuple(
            (arg.name, k, str(s))
            for arg in spec.inputs
            for k, s in enumerate(arg.symbols)
            if str(s) in names
        ),
        slots=tuple((o, k) for o, k, _ in flat),
    )


def name_tables(
    module: ModuleSpec, compiled: list[Compiled]
) -> list[tuple[str, Argument | Output]]:
    """Every name table of a module with its count macro's suffix: the parameters', the extra
    tables, then those of the functions' outputs."""
    tables: list[tuple[str, Argument | Output]] = [
        (table_count(module.params.table or "param_names"), module.params)
    ]
    tables += [(table_count(str(t.table)), t) for t in module.tables]
    for c in compiled:
        tables += [(table_count(o.table), o) for o in c.spec.outputs if o.table]
    return tables
