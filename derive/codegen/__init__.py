"""A small code-generation engine: specs in, NumPy and C99 out. Knows nothing of any robot.

- :mod:`.program`: a derivation as an ordered program of named assignments;
- :mod:`.spec`: :class:`FunctionSpec` and :class:`ModuleSpec`, the one source of each function;
- :mod:`.cse`: common subexpression elimination over a program;
- :mod:`.functions`: functions every printer knows beyond SymPy's (``wrap_angle``);
- :mod:`.backends`: one folder per language (``python/``: NumPy, ``c/``: C99), each with its
  printer, lowering and templates;
- :mod:`.render`: the :class:`Generator` that drives them and writes the manifest;
- :mod:`.files`: source hash, atomic writes and the regeneration check.
"""

from rpr3gen_derive.codegen.program import Assignment, Program
from rpr3gen_derive.codegen.render import Generator
from rpr3gen_derive.codegen.spec import (
    Argument,
    Check,
    Component,
    FunctionSpec,
    ModuleSpec,
    Output,
    ReturnCode,
    Threshold,
)

__all__ = [
    "Argument",
    "Assignment",
    "Check",
    "Component",
    "FunctionSpec",
    "Generator",
    "ModuleSpec",
    "Output",
    "Program",
    "ReturnCode",
    "Threshold",
]
