"""A small code-generation engine: specs in, NumPy and C99 out. Knows nothing of any robot.

- :mod:`.program`: a derivation as an ordered program of named assignments;
- :mod:`.spec`: :class:`FunctionSpec` and :class:`ModuleSpec`, the one source of each function;
- :mod:`.cse`: common subexpression elimination over a program;
- :mod:`.functions`: functions every printer knows beyond SymPy's (``wrap_angle``);
- :mod:`.backends`: one folder per language (``python/``: NumPy, ``c/``: C99), each with its
  printer, lowering and templates;
- :mod:`.render`: the :class:`Generator` that drives them and writes the manifest;
- :mod:`.files`: source hash, atomic writes and the regeneration check.

The names below are imported on first use, so that :mod:`.files` (standard library only) can be
imported without SymPy: the runtime hashes the generator's sources with it.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "Assignment": "program",
    "Program": "program",
    "Generator": "render",
    "Argument": "spec",
    "Check": "spec",
    "Component": "spec",
    "FunctionSpec": "spec",
    "ModuleSpec": "spec",
    "Output": "spec",
    "ReturnCode": "spec",
    "Threshold": "spec",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
