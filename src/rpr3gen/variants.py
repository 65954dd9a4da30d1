"""Where a model's generated code is: the installed package, a named folder, or the cache.

The package ``rpr3gen_generated`` carries the committed variants (the paper's ``revolute`` and
``prismatic``, and ``rrr_1``). Any other structure is derived on first use into a cache:

    $RPR3GEN_CACHE_DIR/variants/<variant>-<key>/<variant>/   (default ~/.cache/rpr3gen)

``key`` is a content hash of the generator's sources (``rpr3gen_derive``, what every generated
file's header carries) and the variant: editing the derivation makes new keys, never stale code.
Deriving needs SymPy and Jinja2 (the ``derive`` extra) and takes a few seconds; a message on
stderr says so. Two processes that need the same variant at once do not both derive it: a file
lock serialises them, and the variant appears by an atomic rename of a complete folder, so no
process ever reads a half-written one.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from functools import cache
from pathlib import Path

from rpr3gen import manifest
from rpr3gen.errors import InputError, SetupError
from rpr3gen.structure import Structure

__all__ = ["cache_root", "ensure", "folder", "generator_hash", "load"]


def cache_root() -> Path:
    """The folder of generated variants: ``$RPR3GEN_CACHE_DIR/variants`` (or the user cache)."""
    base = os.environ.get("RPR3GEN_CACHE_DIR") or os.path.join(
        os.path.expanduser("~"), ".cache", "rpr3gen"
    )
    return Path(base) / "variants"


@cache
def generator_hash() -> str:
    """SHA-256 of the generator's sources (standard-library code of ``rpr3gen_derive``)."""
    try:
        from rpr3gen_derive.planar.fingerprint import generator_hash as derive_hash
    except ImportError as exc:  # pragma: no cover - the wheel always carries rpr3gen_derive
        raise SetupError(f"the generator rpr3gen_derive is not installed ({exc})") from None
    return derive_hash()


def folder(structure: Structure) -> Path:
    """The cache folder (a generated package's root) of a structure's variant."""
    key = hashlib.sha256(f"{generator_hash()}\0{structure.variant}".encode()).hexdigest()[:16]
    return cache_root() / f"{structure.variant}-{key}"


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    """An exclusive lock on ``path`` (a lock file) for the duration of the block."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+b") as handle:
        try:
            import fcntl
        except ImportError:  # pragma: no cover - Windows: no lock, the rename still protects
            yield
            return
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _derive(structure: Structure, root: Path) -> None:
    """Derive and write the variant's files into ``root/<variant>`` (atomically)."""
    try:
        from rpr3gen_derive.codegen.files import write_files
        from rpr3gen_derive.planar import generate
    except ImportError as exc:
        raise SetupError(
            f"the {structure.title} is not generated yet and deriving it needs sympy and "
            f"jinja2 ({exc.name} is missing): pip install 'rpr3gen[derive]', or generate it "
            "elsewhere with `rpr3gen generate --leg ... --actuated ... --out DIR`"
        ) from exc
    print(
        f"rpr3gen: deriving the {structure.title} (first use, a few seconds); cached in {root}",
        file=sys.stderr,
        flush=True,
    )
    target = generate.structure_of(structure.leg, structure.actuated, structure.paper)
    files = generate.render((target,), package=(target,))
    root.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=root))
    try:
        write_files(staging, files)
        try:
            os.replace(staging / structure.variant, root / structure.variant)
        except OSError:
            # Where the lock does not hold, another process may have put the same variant in
            # place first (a directory is not replaced by a rename): keep it.
            if not (root / structure.variant / "manifest.json").is_file():
                raise
        if not (root / "__init__.py").exists():
            os.replace(staging / "__init__.py", root / "__init__.py")
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def ensure(structure: Structure) -> Path:
    """The cache folder holding the structure's variant, deriving it first when missing."""
    root = folder(structure)
    if (root / structure.variant / "manifest.json").is_file():
        return root
    with _locked(root.with_name(root.name + ".lock")):
        if not (root / structure.variant / "manifest.json").is_file():
            _derive(structure, root)
    return root


_INSTALLED: set[str] = set()


def _installed(variant: str) -> bool:
    """Whether the installed package holds ``variant``: one ``stat`` until it is found, then
    remembered (as :func:`manifest.load` remembers the manifest it read). Every array call asks,
    and listing the folder (:func:`manifest.available`) took ~100 µs of each."""
    if variant not in _INSTALLED:
        if not os.path.isfile(os.path.join(manifest.default_folder(), variant, "manifest.json")):
            return False
        _INSTALLED.add(variant)
    return True


def load(structure: Structure, generated: str | os.PathLike[str] | None = None) -> manifest.Variant:
    """The manifest of a structure's variant: from ``generated`` when given, else the installed
    package, else the cache (derived on first use)."""
    if generated is not None:
        return manifest.load(structure.variant, generated)
    if _installed(structure.variant):
        return manifest.load(structure.variant)
    return manifest.load(structure.variant, ensure(structure))


def load_function(
    structure: Structure, generated: str | os.PathLike[str] | None, function: str
) -> tuple[manifest.Variant, manifest.FunctionInfo]:
    """The variant (:func:`load`) and its generated function ``function``.

    Raises:
        InputError: no such function, naming the argument and the variant's functions.
    """
    variant = load(structure, generated)
    if function not in variant.functions:
        known = ", ".join(variant.functions)
        raise InputError(
            f"function: no generated function {function!r} (there are: {known})",
            argument="function",
        )
    return variant, variant.function(function)
