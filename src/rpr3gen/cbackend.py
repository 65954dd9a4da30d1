"""The ``c`` backend: compile a generated C variant once, cache it, and bind it through ctypes.

The shared library is built on first use with the system compiler (``$CC`` or ``cc``) into a
per-user cache folder (``$RPR3GEN_CACHE_DIR``, else ``$XDG_CACHE_HOME/rpr3gen``, else
``~/.cache/rpr3gen``), named by a SHA-256 of the C sources, the shim and the compile command, so
a changed source is rebuilt and an unchanged one is reused. Concurrent first uses (threads, or
processes such as test workers sharing the cache) are safe and build once: the build goes to a
temporary folder and is renamed into place (a reader never sees half a library), under an
exclusive lock on a file beside the library (``.{library}.lock``, kept), which a process waiting
for it takes after the build and then finds the library built. The lock is ``flock``'s, released
by the system when its holder dies, so a crashed build never blocks the next one; where
``fcntl`` is missing (Windows) builds are not serialised, only renamed atomically.

The binding is derived from the manifest (:mod:`rpr3gen.manifest`): every function takes
``params``, its inputs and its outputs as pointers, and its batch ``params, n, inputs...,
outputs...``. A shim compiled beside the generated C (which it leaves untouched) gives each
function a one-pointer entry ``{name}_packed(void *const *args)``: ctypes then passes one
argument instead of several, which halves the cost of a call from Python.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: atomic renames only
    fcntl = None  # type: ignore[assignment]

from rpr3gen.errors import SetupError
from rpr3gen.loader import check_files
from rpr3gen.manifest import Variant

#: ISO C99 (no FMA contraction), -O3; no errno from sqrt and no floating-point traps, so that
#: the batch loops vectorise (the generated C's math kernels are branch-free; these two flags
#: change no value, unlike -ffast-math).
CFLAGS: tuple[str, ...] = (
    "-std=c99",
    "-O3",
    "-fno-math-errno",
    "-fno-trapping-math",
    "-fPIC",
    "-shared",
)
#: Extra flags, tried in order until the compiler accepts them: tuned for the machine that
#: builds and uses the library, without fused multiply-adds. ISO C forbids contracting a * b + c
#: into an FMA, but gcc's basic-block (SLP) vectoriser fuses multiply-adds (``.VEC_FMADDSUB``)
#: all the same, and -mno-fma does not stop it where AVX-512 is on (gcc 12: its FMA patterns
#: are enabled by AVX512F too): the single-sample function, which must agree bit for bit with
#: the batch, then differed in the last bit (issue 20: assembly_modes, after its statements were
#: reordered). The batch loops are vectorised by the loop vectoriser, which needs no SLP.
#: -falign-functions=64 starts every function on a cache line, so that its speed does not hang
#: on the size of the code linked before it (issue 20: the same inverse dynamics batch, machine
#: code unchanged, measured 56 or 66 ns by where it landed); it changes no value.
#: -falign-loops=32 does the same for the loops inside a function: on a Zen 4 the prismatic
#: inverse dynamics' batch measured 66 ns a sample without it and 57 ns with it, and no function
#: slower (docs/performance-log.md, sixteenth stop); alignment changes no value either.
#: -mtune=generic keeps -march=native's instruction set but not the tuning it implies: gcc 12's
#: for the first-generation Zen (znver1) made the generated kernels ~20 % slower than its
#: generic tuning, or than znver3's, on such a machine (issue 20: the inverse dynamics' single
#: call 283 -> 225 ns, docs/performance-log.md); it changes no value either. The later sets
#: are for compilers that refuse -mtune (then -mno-fma), or any of these flags.
_ALIGN = ("-falign-functions=64", "-falign-loops=32")
EXTRA_FLAGS: tuple[tuple[str, ...], ...] = (
    ("-march=native", "-mtune=generic", "-mno-fma", "-fno-tree-slp-vectorize", *_ALIGN),
    ("-march=native", "-mno-fma", "-fno-tree-slp-vectorize", *_ALIGN),
    ("-march=native", "-fno-tree-slp-vectorize", *_ALIGN),
    (),
)
#: Tried first, with the first set of EXTRA_FLAGS: link-time optimisation in partitions
#: compiled side by side (``-flto=auto``: as many jobs as cores). One translation unit
#: otherwise compiles on one core, and gcc's register allocation of the large kernels is most
#: of a build (issue 20: rrr_1's library 17.7 -> 10.7 s, the paper's 10.6 -> 6.8 s and
#: 11.3 -> 6.3 s on 2 cores). Every function keeps its code's speed (the generated functions
#: through the library measured the same within 2.5 %, docs/performance-log.md) and its values:
#: no flag that changes one is added. A compiler or linker that refuses it builds with
#: EXTRA_FLAGS alone.
PARALLEL_FLAGS: tuple[str, ...] = ("-flto=auto", "-flto-partition=balanced")
#: A translation unit other than the main one (the derivatives) whose source is larger than
#: this (bytes) is compiled at -O0: a 6-leg hexapod's derivatives (1.7 MB, one kernel of 58,000
#: operations) took gcc 12 over 8 minutes and 7 GB at -O3, 260 s at -O1, and take 4 s at -O0
#: (docs/derivatives.md). Its values are the same: no flag changes one.
LARGE_UNIT = 1_000_000
LIBS: tuple[str, ...] = ("-lm",)
#: The optimisation level of a quick build, in place of -O3 (and without link-time
#: optimisation): a first use runs on it while the optimised build goes on in the background
#: (:func:`library_path`). gcc 12, 6-UPS main unit: 3 s of CPU at -O1, 25 s at -O3. The values
#: are the same bit for bit: no flag that changes one is used at any level (ISO C99: no
#: contraction; no reassociation without -ffast-math), as ``tests/test_c_build_modes.py`` checks.
QUICK_LEVEL = "-O1"
#: A unit larger than this (bytes) is built at -O0 when quick: the hexapods' main units (0.8 to
#: 1.1 MB since their forward dynamics' one-pass kernel). gcc 12, the 6-RUS's (1.08 MB): 0.9 s of
#: CPU at -O0, 11.7 s at -O1; its inverse dynamics then 2.8 us a sample, 1.2 at -O1, 0.55 at -O3,
#: for the first process only.
QUICK_LARGE = 600_000
#: The environment variable of the build mode (:func:`build_mode`).
BUILD_VARIABLE = "RPR3GEN_C_BUILD"
#: ``background`` (the default): a quick build now, the optimised one in the background;
#: ``optimised``: wait for the optimised build; ``quick``: quick builds only (tests, short runs).
BUILD_MODES: tuple[str, ...] = ("background", "optimised", "quick")


def cache_dir() -> Path:
    """Folder of compiled libraries (created on demand)."""
    if env := os.environ.get("RPR3GEN_CACHE_DIR"):
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "rpr3gen"


def _compiler() -> list[str]:
    command = shlex.split(os.environ.get("CC", "cc"))
    if not command or shutil.which(command[0]) is None:
        raise SetupError(
            f"the c backend needs a C compiler, and {command[0] if command else 'cc'!r} was not "
            "found: install one (e.g. gcc) or set CC, or use --backend numpy"
        )
    return command


def sources(variant: Variant, unit: str = "") -> tuple[bytes, dict[str, bytes]]:
    """The generated C source of a translation unit (``""``: the variant's main one) and the
    headers it includes, by file name (a unit's own and the main one), checked
    (:mod:`rpr3gen.loader`)."""
    check_files(variant)
    roles = ["c_header", *([f"c_header_{unit}"] if unit else [])]
    headers = {variant.files[role]: variant.path(role).read_bytes() for role in roles}
    return variant.path(_source_role(unit)).read_bytes(), headers


def _source_role(unit: str) -> str:
    return f"c_source_{unit}" if unit else "c_source"


def shim(variant: Variant, unit: str = "") -> bytes:
    """C source of the one-pointer entry points, one per function of the unit."""
    header = variant.files[f"c_header_{unit}" if unit else "c_header"]
    lines = [f'#include "{header}"', ""]
    for f in variant.functions.values():
        if f.unit != unit:
            continue
        count = 1 + len(f.inputs) + len(f.public_outputs)
        args = ", ".join(
            f"({'const ' if k <= len(f.inputs) else ''}double *)a[{k}]" for k in range(count)
        )
        lines += [
            f"int {f.c_symbol}_packed(void *const *a);",
            f"int {f.c_symbol}_packed(void *const *a)",
            "{",
            f"    return {f.c_symbol}({args});",
            "}",
            "",
        ]
    return "\n".join(lines).encode()


@contextlib.contextmanager
def _exclusive(lock: Path) -> Iterator[None]:
    """Hold an exclusive lock on the file ``lock`` (created if missing) for the block."""
    if fcntl is None:  # pragma: no cover
        yield
        return
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def build_mode() -> str:
    """How a first use builds a library: ``$RPR3GEN_C_BUILD`` (:data:`BUILD_MODES`), by default
    ``background``."""
    mode = os.environ.get(BUILD_VARIABLE, "").strip().lower() or "background"
    if mode not in BUILD_MODES:
        raise SetupError(
            f"{BUILD_VARIABLE}={mode!r}: must be one of {', '.join(BUILD_MODES)} (docs/c-abi.md)"
        )
    return mode


@dataclass(frozen=True)
class _Plan:
    """One build of a unit: its files, flags and the library they make."""

    target: Path
    files: dict[str, bytes]
    source: str
    command: list[str]
    cflags: tuple[str, ...]
    link: tuple[str, ...]


def _plans(variant: Variant, unit: str) -> tuple[_Plan, _Plan]:
    """The optimised build of ``unit`` and its quick one (-O1, or -O0 over :data:`QUICK_LARGE`;
    no link-time optimisation), from one reading of its sources: a library's name is a digest
    of everything that makes it."""
    source, headers = sources(variant, unit)
    glue = shim(variant, unit)
    command = _compiler()
    link: tuple[str, ...] = ()
    if unit:
        main = library_path(variant)
        link = (str(main), f"-Wl,-rpath,{main.parent}")
    name = f"{variant.prefix}_{variant.variant}" + (f"_{unit}" if unit else "")
    files = {variant.files[_source_role(unit)]: source, **headers, "shim.c": glue}

    def plan(level: str) -> _Plan:
        cflags = tuple(level if f == "-O3" else f for f in CFLAGS)
        digest = hashlib.sha256()
        flags = " ".join(command + list(cflags) + list(LIBS) + list(link)).encode()
        for part in (source, *(headers[name] for name in sorted(headers)), glue, flags):
            digest.update(part)
            digest.update(b"\0")
        target = cache_dir() / f"lib{name}_{digest.hexdigest()[:20]}.so"
        return _Plan(target, files, variant.files[_source_role(unit)], command, cflags, link)

    optimised = plan("-O0" if unit and len(source) > LARGE_UNIT else "-O3")
    quick = plan("-O0" if len(source) > QUICK_LARGE else QUICK_LEVEL)
    return optimised, quick


def _built(variant: Variant, plan: _Plan) -> Path:
    """``plan``'s library, built first if the cache lacks it (once, under its lock)."""
    if plan.target.is_file():
        return plan.target
    plan.target.parent.mkdir(parents=True, exist_ok=True)
    with _exclusive(plan.target.parent / f".{plan.target.name}.lock"):
        if not plan.target.is_file():  # else built by another process while this one waited
            _build(variant, plan.command, plan.files, plan.target, plan.source, plan.link,
                   plan.cflags, parallel=plan.cflags == CFLAGS)  # fmt: skip
    return plan.target


#: Optimised builds started in the background by this process: (variant folder, unit) -> the
#: builder process.
BACKGROUND: dict[tuple[Path, str], subprocess.Popen[bytes]] = {}


def library_path(variant: Variant, unit: str = "") -> Path:
    """Path of the compiled library of ``variant``'s translation unit ``unit`` (``""``: the
    main one), building it if it is not in the cache. A unit's library is linked to the main
    library (whose public functions it may call), which is built first.

    The optimised library (:data:`CFLAGS`) when the cache has it. Else, by the build mode
    (:func:`build_mode`): ``background`` builds a quick one (:data:`QUICK_LEVEL`: seconds, not
    tens of seconds, and the same values bit for bit) for this process and starts the
    optimised build in a process of its own, for the next first use; ``optimised`` builds the
    optimised one and waits for it; ``quick`` builds the quick one only."""
    optimised, quick = _plans(variant, unit)
    if optimised.target.is_file():
        return optimised.target
    mode = build_mode()
    if mode == "optimised" or quick.target == optimised.target:  # or: a unit at -O0 anyway
        return _built(variant, optimised)
    path = _built(variant, quick)
    if mode == "background":
        _optimise_later(variant, unit)
    return path


def _optimise_later(variant: Variant, unit: str) -> None:
    """Start ``python -m rpr3gen.cbackend FOLDER VARIANT UNIT`` (the optimised build) in a
    session of its own, quiet, once per process and unit; it outlives this process."""
    key = (variant.folder, unit)
    if key in BACKGROUND:
        return
    env = {**os.environ, BUILD_VARIABLE: "optimised"}
    command = [sys.executable, "-m", "rpr3gen.cbackend", str(variant.folder.parent),
               variant.variant, unit]  # fmt: skip
    # no process to spare (an embedded interpreter, a process limit): this process stays quick
    with contextlib.suppress(OSError):
        BACKGROUND[key] = subprocess.Popen(
            command,
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )


def _build(
    variant: Variant,
    command: list[str],
    files: dict[str, bytes],
    target: Path,
    source: str,
    link: tuple[str, ...] = (),
    cflags: tuple[str, ...] = CFLAGS,
    parallel: bool = True,
) -> None:
    """Compile ``files`` (``source`` and the shim; ``link``: libraries and flags for the
    linker) into ``target`` with ``cflags`` (and ``parallel``: :data:`PARALLEL_FLAGS` first):
    in a temporary folder beside it, then renamed."""
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=".build-") as tmp:
        for name, text in files.items():
            (Path(tmp) / name).write_bytes(text)
        built = Path(tmp) / target.name
        lto = ((*EXTRA_FLAGS[0], *PARALLEL_FLAGS),) if parallel else ()
        for extra in (*lto, *EXTRA_FLAGS):
            result = subprocess.run(
                [*command, *cflags, *extra, source, "shim.c", "-o", built.name, *link, *LIBS],
                cwd=tmp,
                capture_output=True,
                text=True,
                check=False,
            )
            if result.returncode == 0:
                break
        else:
            first = (result.stderr.strip().splitlines() or ["(no message)"])[0]
            raise SetupError(f"compiling the generated C of {variant.folder} failed: {first}")
        os.replace(built, target)


@dataclass(frozen=True)
class Entry:
    """The typed entry points of one generated function."""

    single: Any  # int f(params, inputs..., outputs...)
    packed: Any  # int f_packed(void *const *args)
    batch: Any  # size_t f_batch(params, n, inputs..., outputs...)


class _Entries(dict[str, "Entry"]):
    """The entries by function name; a function of another translation unit is looked up, its
    unit's library built and loaded, when first asked for."""

    def __init__(self, library: Library) -> None:
        super().__init__()
        self.library = library

    def __missing__(self, name: str) -> Entry:
        f = self.library.variant.functions[name]
        if not f.unit:
            raise KeyError(name)
        self.library.load(f.unit)
        return self[name]


class Library:
    """A compiled variant: the ctypes library (the main unit's) and its entries by function
    name; another unit's functions (the derivatives) load their library on first use."""

    def __init__(self, variant: Variant) -> None:
        self.variant = variant
        self.cdll = ctypes.CDLL(str(library_path(variant)))
        self.units: dict[str, ctypes.CDLL] = {"": self.cdll}
        self.entries: dict[str, Entry] = _Entries(self)
        self._bind("")

    def load(self, unit: str) -> None:
        """Build (if needed) and load the library of ``unit``, and bind its functions."""
        if unit not in self.units:
            self.units[unit] = ctypes.CDLL(str(library_path(self.variant, unit)))
            self._bind(unit)

    def _bind(self, unit: str) -> None:
        cdll = self.units[unit]
        for name, f in self.variant.functions.items():
            if f.unit != unit:
                continue
            count = len(f.inputs) + len(f.public_outputs)
            single = getattr(cdll, f.c_symbol)
            single.restype = ctypes.c_int
            single.argtypes = [ctypes.c_void_p] * (1 + count)
            packed = getattr(cdll, f"{f.c_symbol}_packed")
            packed.restype = ctypes.c_int
            packed.argtypes = [ctypes.c_void_p]
            batch = getattr(cdll, f.c_batch_symbol)
            batch.restype = ctypes.c_size_t
            batch.argtypes = [ctypes.c_void_p, ctypes.c_size_t] + [ctypes.c_void_p] * count
            self.entries[name] = Entry(single, packed, batch)

    def names(self, table: str, size: int) -> tuple[str, ...]:
        """A C name table (``rpr3_param_names``) of ``size`` entries, read from the library."""
        array = (ctypes.c_char_p * size).in_dll(self.cdll, table)
        return tuple((item or b"").decode() for item in array)


_LIBRARIES: dict[Path, Library] = {}


def library(variant: Variant) -> Library:
    """The loaded library of ``variant`` (built and loaded once per process and folder)."""
    lib = _LIBRARIES.get(variant.folder)
    if lib is None:
        lib = _LIBRARIES.setdefault(variant.folder, Library(variant))
    return lib


def _main(argv: list[str]) -> int:
    """``python -m rpr3gen.cbackend FOLDER VARIANT [UNIT]``: build that unit's optimised
    library into the cache (what a first use starts in the background)."""
    from rpr3gen import manifest

    variant = manifest.load(argv[1], argv[0])
    _built(variant, _plans(variant, argv[2] if len(argv) > 2 else "")[0])
    return 0


if __name__ == "__main__":
    raise SystemExit(_main(sys.argv[1:]))
