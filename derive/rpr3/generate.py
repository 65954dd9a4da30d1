"""Generate the 3-RPR's code: every module of the registry through the engine, into ``generated/``.

``rpr3gen generate`` calls :func:`render` and writes its files with
:func:`~rpr3gen_derive.codegen.files.write_files` (or compares them, ``--check``).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

from rpr3gen_derive.codegen.render import Generator, Stage, no_stage
from rpr3gen_derive.rpr3.registry import ACTUATIONS, FunctionBuilder, module

ROBOT_DIR = Path(__file__).resolve().parent

PACKAGE_DOC = """Generated code of rpr3gen, one folder per actuation scheme.

Each folder holds ``rpr3_numpy.py`` (needs only numpy), the C99 sources ``rpr3.h`` and
``rpr3.c`` (need only ``<math.h>`` and ``<stddef.h>``) and ``manifest.json``, which lists every
function's signature, name tables, thresholds and return codes for the runtime.
"""


def generator(stage: Stage = no_stage) -> Generator:
    """The engine, set up for this robot's sources."""
    return Generator(
        hash_roots=(ROBOT_DIR,),
        package_doc=PACKAGE_DOC,
        stage=stage,
        template_dirs=(ROBOT_DIR / "templates",),
    )


def render(
    actuations: Iterable[str] = ACTUATIONS,
    functions: Mapping[str, FunctionBuilder] | None = None,
    stage: Stage = no_stage,
) -> dict[str, str]:
    """Every generated file for the given actuation schemes, ``{relative path: text}``."""
    gen = generator(stage)
    modules = []
    for actuation in actuations:
        with stage(f"variant:{actuation}"), stage("derive"):
            modules.append(module(actuation, functions))
    return gen.render(modules, variants=ACTUATIONS)


def source_hash() -> str:
    """The hash the generated files carry: of the engine's and this robot's sources."""
    return generator().source_hash()


def default_out_dir() -> Path | None:
    """``generated/`` beside ``derive/`` in a source checkout, or None when there is none."""
    out = ROBOT_DIR.parent.parent / "generated"
    return out if (out / "__init__.py").is_file() else None
