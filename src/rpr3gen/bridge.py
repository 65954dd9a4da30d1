"""What the bridges (:mod:`rpr3gen.casadi`, :mod:`rpr3gen.jax`) share: a model's function by
name, checked, with its variant and generated graph module (docs/bridges.md).

Bad input is one line each: a model of the wrong type (:class:`~rpr3gen.errors.InputTypeError`,
by the caller's ``checked``), a name no bridge offers (:class:`~rpr3gen.errors.InputError`,
with the names it does offer), a missing extra (:class:`~rpr3gen.errors.SetupError`, with the
``pip install`` that brings it).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

from rpr3gen import graph_compose
from rpr3gen.errors import InputError, SetupError, did_you_mean
from rpr3gen.loader import graph_module
from rpr3gen.manifest import FunctionInfo, Variant

__all__ = ["Target", "missing_extra", "names", "target"]


@dataclass(frozen=True)
class Target:
    """A function of a model's variant that the bridges offer."""

    variant: Variant
    info: FunctionInfo
    graph: ModuleType


def names(variant: Variant) -> tuple[str, ...]:
    """The functions of ``variant`` the bridges offer, in the manifest's order."""
    return tuple(n for n, f in variant.functions.items() if graph_compose.offered(variant, f))


def target(variant: Variant, name: str) -> Target:
    """The function ``name`` of ``variant``, or an :class:`InputError` naming those the
    bridges offer."""
    offered = names(variant)
    if name not in offered:
        raise InputError(
            f"name: no function {name!r} of the {variant.variant} variant in the bridges "
            f"(there are: {', '.join(offered)}){did_you_mean(name, offered)}",
            argument="name",
        )
    return Target(variant, variant.function(name), graph_module(variant))


def missing_extra(package: str, extra: str, error: ImportError) -> SetupError:
    """The one-line error of a bridge whose package is not installed (re-raises any other
    import error)."""
    if (error.name or "").split(".")[0] != package:
        raise error
    return SetupError(
        f"this needs {package}, which is not installed: install the extra '{extra}': "
        f"pip install 'rpr3gen[{extra}]'"
    )
