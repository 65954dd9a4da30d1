"""The generator's fingerprint: a content hash of every source the generated code comes from.

Standard library only, so that the runtime can key its cache of generated variants by it
without importing SymPy (docs/interfaces.md, "Generated code per structure").
"""

from __future__ import annotations

from pathlib import Path

from rpr3gen_derive.codegen.files import source_hash

#: The folders whose ``*.py`` and ``*.jinja`` files the generated code is derived from: the
#: engine and this derivation.
ROOTS: tuple[Path, ...] = (
    Path(__file__).resolve().parent.parent / "codegen",
    Path(__file__).resolve().parent,
    Path(__file__).resolve().parent.parent / "spatial",
)


def generator_hash() -> str:
    """SHA-256 of the engine's and the derivation's sources (what every generated file carries)."""
    return source_hash(ROOTS)
