"""Generate code: every module of the registry through the engine.

``rpr3gen generate`` calls :func:`render` and writes its files with
:func:`~rpr3gen_derive.codegen.files.write_files` (or compares them, ``--check``). The committed
variants (:data:`COMMITTED`) live in the repository's ``generated/``; any other structure is
generated on demand (``rpr3gen generate --leg RRR --actuated 2``, or by the runtime into its
cache on first use).
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import os
from collections.abc import Iterable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from rpr3gen_derive.codegen import derivatives
from rpr3gen_derive.codegen.render import Generator, Stage, no_stage
from rpr3gen_derive.codegen.spec import ModuleSpec
from rpr3gen_derive.planar import registry
from rpr3gen_derive.planar.registry import FunctionBuilder
from rpr3gen_derive.planar.structures import PAPER, Structure
from rpr3gen_derive.spatial import registry as spatial_registry
from rpr3gen_derive.spatial.structures import LEG_TYPES as SPATIAL_LEG_TYPES
from rpr3gen_derive.spatial.structures import SpatialStructure

ROBOT_DIR = Path(__file__).resolve().parent
SPATIAL_DIR = ROBOT_DIR.parent / "spatial"

#: The variants committed in ``generated/``: the paper's two, the 3-RRR with base motors, the
#: 6-UPS hexapod and the Delta.
COMMITTED: tuple[Structure | SpatialStructure, ...] = (
    *PAPER,
    Structure("RRR", 1),
    SpatialStructure("UPS", 2),
    SpatialStructure("RSS2", 1),
)


#: The functions that the runtime's cache derives apart, when one is first called: the
#: derivatives of the dynamics, three quarters of a variant's derivation (docs/derivatives.md).
ON_DEMAND: tuple[str, ...] = derivatives.NAMES


def structure_of(leg: str, actuated: int, paper: bool = False) -> Structure | SpatialStructure:
    """The derivation's structure of a leg type and actuated joint, planar or spatial."""
    if leg in SPATIAL_LEG_TYPES:
        return SpatialStructure(leg, actuated)
    return Structure(leg, actuated, paper)


def module(
    structure: Structure | SpatialStructure,
    functions: Mapping[str, FunctionBuilder] | None = None,
    defer: Sequence[str] = (),
) -> ModuleSpec:
    """The generated module of a planar or spatial structure, without the functions ``defer``
    names (listed as deferred: the runtime's cache derives them on first use)."""
    if isinstance(structure, SpatialStructure):
        every: Mapping[str, Any] = spatial_registry.FUNCTIONS if functions is None else functions
        kept = {name: f for name, f in every.items() if name not in defer}
        found = spatial_registry.module(structure, kept)
    else:
        every = registry.FUNCTIONS if functions is None else functions
        found = registry.module(structure, {n: f for n, f in every.items() if n not in defer})
    deferred = tuple(name for name in every if name in defer)
    return dataclasses.replace(found, deferred=deferred) if deferred else found


PACKAGE_DOC = """Generated code of rpr3gen, one folder per variant (a leg type, its actuated joint).

Each folder holds ``rpr3_numpy.py`` (needs only numpy), the C99 sources ``rpr3.h`` and
``rpr3.c`` (need only ``<math.h>`` and ``<stddef.h>``) and ``manifest.json``, which lists every
function's signature, name tables, thresholds and return codes for the runtime.
"""


def generator(stage: Stage = no_stage) -> Generator:
    """The engine, set up for this derivation's sources."""
    return Generator(
        hash_roots=(ROBOT_DIR, SPATIAL_DIR),
        package_doc=PACKAGE_DOC,
        stage=stage,
        template_dirs=(ROBOT_DIR / "templates", SPATIAL_DIR / "templates"),
    )


def render(
    structures: Iterable[Structure | SpatialStructure] = COMMITTED,
    functions: Mapping[str, FunctionBuilder] | None = None,
    stage: Stage = no_stage,
    package: Iterable[Structure | SpatialStructure] | None = None,
    defer: Sequence[str] = (),
) -> dict[str, str]:
    """Every generated file for ``structures``, ``{relative path: text}``.

    ``package``: the variants the folder's ``__init__.py`` lists (default: ``structures``).
    ``defer``: functions left out, listed as deferred (the runtime's cache derives a variant
    without :data:`ON_DEMAND`, then those when one is first called).
    Several structures are rendered side by side, one process each (forked, so they share the
    parent's hash seed and imports), on as many cores as there are; each variant's files depend
    on its structure alone, so the result is the same as one after the other.
    """
    structures = tuple(structures)
    listed = structures if package is None else tuple(package)
    workers = min(len(structures), os.cpu_count() or 1)
    if workers > 1 and functions is None and not defer and stage is no_stage and _can_fork():
        files: dict[str, str] = {}
        context = multiprocessing.get_context("fork")
        # the costliest first (revolute joints give the longest expressions), so that the
        # last one to start is a short one
        order = sorted(structures, key=lambda s: -s.kinds.count("R"))
        with ProcessPoolExecutor(workers, mp_context=context) as pool:
            for part in pool.map(_render_one, order, [listed] * len(order)):
                files.update(part)
        return dict(sorted(files.items()))
    return _render(structures, functions, stage, listed, defer)


def _render(
    structures: tuple[Structure | SpatialStructure, ...],
    functions: Mapping[str, FunctionBuilder] | None,
    stage: Stage,
    listed: tuple[Structure | SpatialStructure, ...],
    defer: Sequence[str] = (),
) -> dict[str, str]:
    """:func:`render` in this process, one structure after the other."""
    gen = generator(stage)
    modules = []
    for structure in structures:
        with stage(f"variant:{structure.variant}"), stage("derive"):
            modules.append(module(structure, functions, defer))
    return gen.render(modules, variants=tuple(s.variant for s in listed))


def _render_one(
    structure: Structure | SpatialStructure, listed: tuple[Structure | SpatialStructure, ...]
) -> dict[str, str]:
    return _render((structure,), None, no_stage, listed)


def _can_fork() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


def source_hash() -> str:
    """The hash the generated files carry: of the engine's and this derivation's sources."""
    return generator().source_hash()


def default_out_dir() -> Path | None:
    """``generated/`` beside ``derive/`` in a source checkout, or None when there is none."""
    out = ROBOT_DIR.parent.parent / "generated"
    return out if (out / "__init__.py").is_file() else None
