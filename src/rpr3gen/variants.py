"""Where a model's generated code is: the installed package, a named folder, or the cache.

The package ``rpr3gen_generated`` carries the committed variants (the paper's ``revolute`` and
``prismatic``, and ``rrr_1``). Any other structure is derived on first use into a cache:

    $RPR3GEN_CACHE_DIR/variants/<variant>-<key>/<variant>/   (default ~/.cache/rpr3gen)

``key`` is a content hash of the generator's sources (``rpr3gen_derive``, what every generated
file's header carries) and the variant: editing the derivation makes new keys, never stale code.
Deriving needs SymPy and Jinja2 (the ``derive`` extra) and takes a few seconds; a message on
stderr says so.

A first use derives the variant without the derivatives of its dynamics, which take three
quarters of a variant's derivation (a hexapod's: 18 of 23 s of CPU) and are seldom called: its
manifest lists them as ``deferred``. The first call of one derives the whole variant into a
folder of its own, ``<variant>-<key>-whole`` (its main C unit is byte-identical to the first
folder's, so its library is not built again). The committed variants and ``rpr3gen generate``
are whole. Two processes that need the same variant at once do not both derive it: a file
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
from rpr3gen.errors import GeneratedCodeError, InputError, SetupError
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


def folder(structure: Structure, whole: bool = False) -> Path:
    """The cache folder (a generated package's root) of a structure's variant: the one a first
    use derives (without the deferred functions), or with ``whole`` the one with every
    function."""
    key = hashlib.sha256(f"{generator_hash()}\0{structure.variant}".encode()).hexdigest()[:16]
    return cache_root() / (f"{structure.variant}-{key}" + ("-whole" if whole else ""))


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


def _derive(structure: Structure, root: Path, whole: bool = False) -> None:
    """Derive and write the variant's files into ``root/<variant>`` (atomically): without the
    functions the generator derives on demand unless ``whole``."""
    try:
        from rpr3gen_derive.codegen.files import write_files
        from rpr3gen_derive.planar import generate
    except ImportError as exc:
        raise SetupError(
            f"the {structure.title} is not generated yet and deriving it needs sympy and "
            f"jinja2 ({exc.name} is missing): pip install 'rpr3gen[derive]', or generate it "
            "elsewhere with `rpr3gen generate --leg ... --actuated ... --out DIR`"
        ) from exc
    what = (
        f"the derivatives of the {structure.title} (their first use, up to a minute)"
        if whole
        else f"the {structure.title} (first use, a few seconds)"
    )
    print(f"rpr3gen: deriving {what}; cached in {root}", file=sys.stderr, flush=True)
    target = generate.structure_of(structure.leg, structure.actuated, structure.paper)
    defer = () if whole else generate.ON_DEMAND
    files = generate.render((target,), package=(target,), defer=defer)
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


def ensure(structure: Structure, whole: bool = False) -> Path:
    """The cache folder holding the structure's variant (``whole``: with every function),
    deriving it first when missing."""
    root = folder(structure, whole)
    if (root / structure.variant / "manifest.json").is_file():
        return root
    if not whole and (folder(structure, True) / structure.variant / "manifest.json").is_file():
        return folder(structure, True)
    with _locked(root.with_name(root.name + ".lock")):
        if not (root / structure.variant / "manifest.json").is_file():
            _derive(structure, root, whole)
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


def load(
    structure: Structure,
    generated: str | os.PathLike[str] | None = None,
    function: str | None = None,
) -> manifest.Variant:
    """The manifest of a structure's variant: from ``generated`` when given, else the installed
    package, else the cache (derived on first use). ``function``: a function the caller will
    call; if the cache's variant defers it, the whole variant (derived on its first use).

    Raises:
        GeneratedCodeError: ``generated`` is a folder that defers ``function`` (a cache's).
    """
    if generated is not None:
        found = manifest.load(structure.variant, generated)
    elif _installed(structure.variant):
        found = manifest.load(structure.variant)
    else:
        found = manifest.load(structure.variant, ensure(structure))
    if function is None or function not in found.deferred:
        return found
    if generated is not None:
        raise GeneratedCodeError(
            f"{found.folder}: {function} is not in this folder (a cache's, derived without the "
            f"derivatives): generate the whole variant, rpr3gen generate --out {generated}"
        )
    return manifest.load(structure.variant, ensure(structure, whole=True))


def load_function(
    structure: Structure, generated: str | os.PathLike[str] | None, function: str
) -> tuple[manifest.Variant, manifest.FunctionInfo]:
    """The variant (:func:`load`) and its generated function ``function``.

    Raises:
        InputError: no such function, naming the argument and the variant's functions.
    """
    variant = load(structure, generated, function)
    if function not in variant.functions:
        known = ", ".join(variant.functions)
        raise InputError(
            f"function: no generated function {function!r} (there are: {known})",
            argument="function",
        )
    return variant, variant.function(function)
