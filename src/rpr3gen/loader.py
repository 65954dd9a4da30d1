"""The loader check of generated code: one place that refuses a damaged or foreign folder.

A generated folder (the installed ``rpr3gen_generated``, or one that ``rpr3gen generate --out
DIR`` wrote, given as ``--generated DIR`` or ``load_model(..., generated=DIR)``) is used only
after these checks, each failing in one line that names the file and how to regenerate it:

- ``manifest.json`` readable, JSON, of this runtime's format, with every key
  (:mod:`rpr3gen.manifest` parses it);
- every file it lists present, each stamped with the manifest's source hash (its second line,
  ``Source hash: ...``): files of two generations mixed are refused;
- the parameters it takes are this runtime's (:data:`rpr3gen.model.PARAM_NAMES`, the ABI of the
  ``params`` array);
- ``rpr3_numpy.py`` imports (no syntax error, no missing module) and defines what the manifest
  lists, for the same variant and parameters.

The errors are :class:`~rpr3gen.errors.GeneratedCodeError` (an :class:`OSError`): the environment
is at fault, not an argument's value.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

from rpr3gen import manifest
from rpr3gen.errors import GeneratedCodeError
from rpr3gen.manifest import Variant, regenerate_hint

__all__ = ["check_folder", "graph_module", "numpy_module"]

_HASH_LINE = "Source hash: "


def _fail(path: Path, what: str, variant: Variant) -> GeneratedCodeError:
    return GeneratedCodeError(f"{path}: {what}; {regenerate_hint(variant.folder.parent)}")


def _stamp(path: Path) -> str | None:
    """The source hash on the second line of a generated file, or None."""
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = [f.readline(), f.readline()]
    _, found, rest = lines[1].partition(_HASH_LINE)
    return rest.strip() if found else None


def check_files(variant: Variant) -> None:
    """Every file the manifest lists is there, stamped with the manifest's source hash."""
    for role, name in sorted(variant.files.items()):
        path = variant.folder / name
        try:
            stamp = _stamp(path)
        except FileNotFoundError:
            raise _fail(path, f"missing (the manifest lists it as {role})", variant) from None
        except OSError as exc:
            raise _fail(path, f"cannot read it: {exc.strerror or exc}", variant) from None
        if stamp != variant.source_hash:
            found = "no source hash" if stamp is None else f"source hash {stamp[:12]}..."
            raise _fail(
                path,
                f"{found}, but manifest.json's is {variant.source_hash[:12]}...: files of "
                "different generations",
                variant,
            )


def _imported(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise GeneratedCodeError(f"{path}: not a Python module")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def numpy_module(variant: Variant) -> ModuleType:
    """The generated NumPy module of a variant, imported from its folder and checked against
    the manifest.

    Raises:
        GeneratedCodeError: it does not import (a syntax error: its line; a missing module), or it
            is another variant's, or it lacks a function the manifest lists.
    """
    path = variant.path("numpy")
    name = f"_rpr3gen_generated_{variant.variant}_{variant.source_hash[:16]}"
    module = sys.modules.get(name)
    if module is not None and getattr(module, "__file__", None) == str(path):
        return module
    check_files(variant)
    try:
        module = _imported(path, name)
    except SyntaxError as exc:
        raise _fail(path, f"line {exc.lineno}: {exc.msg} (syntax error)", variant) from None
    except ImportError as exc:
        raise _fail(path, f"cannot import it: {exc}", variant) from None
    except GeneratedCodeError:
        raise
    except Exception as exc:
        raise _fail(path, f"fails on import: {type(exc).__name__}: {exc}", variant) from None
    if getattr(module, "VARIANT", None) != variant.variant:
        raise _fail(path, f"not the {variant.variant} variant of its manifest", variant)
    if tuple(getattr(module, "PARAM_NAMES", ())) != variant.param_names:
        raise _fail(path, "takes other parameters than its manifest lists", variant)
    for info in variant.functions.values():
        if info.numpy_function is not None and not callable(
            getattr(module, info.numpy_function, None)
        ):
            raise _fail(path, f"no function {info.numpy_function} (the manifest lists it)", variant)
    sys.modules[name] = module
    return module


def graph_module(variant: Variant) -> ModuleType:
    """The generated graph module of a variant (``rpr3_graph.py``, scalar Python over a math
    namespace: the bridges' source, docs/bridges.md), imported and checked as
    :func:`numpy_module` is.

    Raises:
        GeneratedCodeError: the folder has no graph module (generated before it), or it does not
            import, or it is another variant's, or it lacks a function the manifest lists.
    """
    if "graph" not in variant.files:
        raise _fail(
            variant.folder / "manifest.json",
            "lists no graph module (rpr3_graph.py: generated before the bridges)",
            variant,
        )
    path = variant.path("graph")
    name = f"_rpr3gen_graph_{variant.variant}_{variant.source_hash[:16]}"
    module = sys.modules.get(name)
    if module is not None and getattr(module, "__file__", None) == str(path):
        return module
    check_files(variant)
    try:
        module = _imported(path, name)
    except SyntaxError as exc:
        raise _fail(path, f"line {exc.lineno}: {exc.msg} (syntax error)", variant) from None
    except Exception as exc:
        raise _fail(path, f"fails on import: {type(exc).__name__}: {exc}", variant) from None
    if getattr(module, "VARIANT", None) != variant.variant:
        raise _fail(path, f"not the {variant.variant} variant of its manifest", variant)
    if tuple(getattr(module, "PARAM_NAMES", ())) != variant.param_names:
        raise _fail(path, "takes other parameters than its manifest lists", variant)
    for info in variant.functions.values():
        if info.numpy_function is not None and not callable(getattr(module, info.name, None)):
            raise _fail(path, f"no function {info.name} (the manifest lists it)", variant)
    sys.modules[name] = module
    return module


def check_folder(
    variant_name: str, generated: str | os.PathLike[str], param_names: tuple[str, ...]
) -> Variant:
    """Every check of the module docstring on a generated folder, for a model of the variant
    ``variant_name`` (``revolute``, ``rrr_1``, ...) whose parameters are ``param_names``."""
    variant = manifest.load(variant_name, generated)
    if variant.param_names != param_names:
        raise _fail(
            variant.folder / "manifest.json",
            "generated for other model parameters than this runtime's (another version)",
            variant,
        )
    numpy_module(variant)
    return variant
