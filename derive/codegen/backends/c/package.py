"""The generated C of a module as a package: a CMake project and a pkg-config file.

Beside ``{prefix}.h`` and ``{prefix}.c``, each variant folder gets ``CMakeLists.txt``, a project
``{NAMESPACE}_{variant}`` with one library, install rules and an exported target
``{NAMESPACE}::{variant}`` (``find_package`` after ``cmake --install``, or ``add_subdirectory``
of the folder), and ``{NAMESPACE}_{variant}.pc.in``, which that project configures into the
pkg-config file it installs (its paths relative to the file's own folder, so the installed tree
may move). Both carry the generated files' header: "do not edit" and the source hash.
"""

from __future__ import annotations

from collections.abc import Sequence

import jinja2
from rpr3gen_derive.codegen.spec import ModuleSpec

#: The CMake namespace and the first part of every package name (``rpr3gen_revolute``).
NAMESPACE = "rpr3gen"
#: The packages' version: rpr3gen's (pyproject.toml; a test keeps the two equal).
VERSION = "0.1.0"


def package_name(module: ModuleSpec) -> str:
    """``{NAMESPACE}_{variant}``: the CMake project, library, package and pkg-config name."""
    return f"{NAMESPACE}_{module.variant}"


def render(
    module: ModuleSpec,
    digest: str,
    env: jinja2.Environment,
    header: str,
    source: str,
    extra_sources: Sequence[str] = (),
    extra_headers: Sequence[str] = (),
) -> dict[str, tuple[str, str]]:
    """``{"c_cmake": ("CMakeLists.txt", text), "c_pkgconfig": ("<package>.pc.in", text)}``;
    the library is built from ``source`` and ``extra_sources`` (the other translation units),
    and installs ``header`` and ``extra_headers`` (theirs)."""
    package = package_name(module)
    context = {
        "module": module,
        "source_hash": digest,
        "namespace": NAMESPACE,
        "version": VERSION,
        "package": package,
        "option": package.upper(),
        "header": header,
        "source": source,
        "sources": " ".join([source, *extra_sources]),
        "headers": " ".join([header, *extra_headers]),
        "extra_headers": list(extra_headers),
        "public_headers": ";".join([header, *extra_headers]),
    }
    return {
        "c_cmake": (
            "CMakeLists.txt",
            env.get_template("backends/c/templates/CMakeLists.txt.jinja").render(context),
        ),
        "c_pkgconfig": (
            f"{package}.pc.in",
            env.get_template("backends/c/templates/package.pc.in.jinja").render(context),
        ),
    }


__all__ = ["NAMESPACE", "VERSION", "package_name", "render"]
