"""The engine's driver: compile each function spec, hand it to every backend, write a manifest.

Output is byte-identical for identical sources: no dates, versions, paths or hash-seed order.
Every file carries the SHA-256 of the sources it was derived from (:func:`files.source_hash`).

Stages can be timed: pass ``stage``, a callable that returns a context manager for a stage name:
``"variant:NAME"`` around all the work on one module, inside it ``"cse"``, ``"print"`` and
``"render"`` (a robot's own driver adds ``"derive"``); a stage may be entered several times.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import jinja2
from rpr3gen_derive.codegen.backends import c, graph, python
from rpr3gen_derive.codegen.backends.c import comment
from rpr3gen_derive.codegen.compiled import Stage, compile_function, no_stage
from rpr3gen_derive.codegen.files import source_hash
from rpr3gen_derive.codegen.spec import ModuleSpec

__all__ = ["ENGINE_DIR", "Generator", "Stage", "environment", "manifest", "no_stage"]

ENGINE_DIR = Path(__file__).resolve().parent


def environment(template_dirs: Sequence[Path] = ()) -> jinja2.Environment:
    """Strict Jinja2: an undefined name is an error, whitespace is the template's own.

    Templates are found in the engine's folder, then in ``template_dirs`` (a robot's own, for
    the bodies of hand-written kernels).
    """
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader([ENGINE_DIR, *template_dirs]),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )
    env.filters["c_comment"] = comment
    return env


def _components(arg: Any) -> list[dict[str, str]]:
    return [{"name": c.name, "unit": c.unit, "meaning": c.meaning} for c in arg.components]


def manifest(module: ModuleSpec, digest: str, files: dict[str, str]) -> str:
    """The module's manifest (JSON): what the runtime needs to call every function by name."""
    prefix = module.prefix
    data = {
        "generated": "by rpr3gen from derive/ (`rpr3gen generate`): do not edit",
        "source_hash": digest,
        "format": 1,
        "prefix": prefix,
        "variant": module.variant,
        "files": files,
        "params": _components(module.params),
        "return_codes": [
            {"name": c.name, "value": c.value, "meaning": c.meaning} for c in module.return_codes
        ],
        "thresholds": [
            {"name": t.name, "value": t.value, "meaning": t.meaning} for t in module.thresholds
        ],
        "tables": {f"{prefix}_{t.table}": _components(t) for t in module.tables},
        "defines": {name: literal for name, literal, _ in module.defines},
        "deferred": list(module.deferred),
        "functions": [
            {
                "name": f.name,
                "c_symbol": f"{prefix}_{f.name}",
                "c_batch_symbol": f"{prefix}_{f.name}_batch",
                "numpy_function": None if f.c_body else f"{prefix}_{f.name}",
                "unit": f.unit,
                "doc": f.doc,
                "inputs": [
                    {"name": a.name, "doc": a.doc, "components": _components(a)} for a in f.inputs
                ],
                "outputs": [
                    {
                        "name": o.name,
                        "doc": o.doc,
                        "table": f"{prefix}_{o.table}" if o.table else None,
                        "hidden": o.hidden,
                        "components": _components(o),
                    }
                    for o in f.outputs
                ],
                "checks": [
                    {
                        "kind": c.kind,
                        "code": c.code,
                        "output": c.output,
                        "component": c.component,
                        "threshold": c.threshold,
                    }
                    for c in f.checks
                ],
            }
            for f in module.functions
        ],
    }
    return json.dumps(data, indent=2) + "\n"


class Generator:
    """Renders modules through every backend.

    Args:
        hash_roots: folders whose ``*.py`` and ``*.jinja`` files the output is derived from (the
            engine's own folder is always included).
        template_dirs: folders of the templates that specs name (``FunctionSpec.c_body``).
        package_doc: docstring of the generated package's ``__init__.py``.
        stage: timing hook, see the module docstring.
    """

    def __init__(
        self,
        hash_roots: Sequence[Path],
        package_doc: str,
        stage: Stage = no_stage,
        template_dirs: Sequence[Path] = (),
    ) -> None:
        self.hash_roots = (ENGINE_DIR, *hash_roots)
        self.package_doc = package_doc
        self.stage = stage
        self.env = environment(template_dirs)

    def source_hash(self) -> str:
        return source_hash(self.hash_roots)

    def render_module(self, module: ModuleSpec, digest: str) -> dict[str, str]:
        """Every file of one module, ``{relative path: text}``, under ``{variant}/``."""
        with self.stage(f"variant:{module.variant}"):
            return self._render_module(module, digest)

    def _render_module(self, module: ModuleSpec, digest: str) -> dict[str, str]:
        with self.stage("cse"):
            compiled = [compile_function(f, module.params, module.legs) for f in module.functions]
        files: dict[str, str] = {}
        roles: dict[str, str] = {}
        for backend in (python, c, graph):
            for role, (name, text) in backend.render(
                module, compiled, digest, self.env, self.stage
            ).items():
                files[name] = text
                roles[role] = name
        with self.stage("render"):
            files["__init__.py"] = self.env.get_template("templates/variant_init.py.jinja").render(
                module=module, source_hash=digest
            )
            files["manifest.json"] = manifest(module, digest, roles)
        return {f"{module.variant}/{name}": text for name, text in sorted(files.items())}

    def render(
        self, modules: Iterable[ModuleSpec], variants: Sequence[str] | None = None
    ) -> dict[str, str]:
        """Every generated file, ``{relative path: text}``, and the package's ``__init__.py``.

        ``variants`` lists every variant of the package (default: those of ``modules``), so that
        rendering some of them writes the same package ``__init__.py`` as rendering all.
        """
        digest = self.source_hash()
        files: dict[str, str] = {}
        rendered = []
        for module in modules:
            files.update(self.render_module(module, digest))
            rendered.append(module.variant)
        variants = list(variants) if variants is not None else rendered
        with self.stage("render"):
            files["__init__.py"] = self.env.get_template("templates/package_init.py.jinja").render(
                doc=self.package_doc, source_hash=digest, variants=variants
            )
        return dict(sorted(files.items()))
