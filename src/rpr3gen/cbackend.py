"""The ``c`` backend: compile the generated C once, cache it, and call it through ctypes.

The shared library is built on first use with the system compiler (``$CC`` or ``cc``) into a
per-user cache folder (``$RPR3GEN_CACHE_DIR``, else ``$XDG_CACHE_HOME/rpr3gen``, else
``~/.cache/rpr3gen``), named by a SHA-256 of the C sources and the compile command, so a changed
source is rebuilt and an unchanged one is reused. The build goes to a temporary file renamed
into place, so concurrent first uses are safe.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shlex
import shutil
import subprocess
import tempfile
from functools import cache
from importlib import resources
from pathlib import Path

import numpy as np

from rpr3gen.errors import Rpr3genError

CFLAGS: tuple[str, ...] = ("-std=c99", "-O3", "-fPIC", "-shared")
#: Extra flags, tried in order until the compiler accepts them: tuned for the machine that
#: builds and uses the library; gcc's basic-block (SLP) vectoriser off, because with FMA it
#: fuses multiply-adds differently in the single and the batch function (the batch's loop
#: vectorisation is unaffected), and the two must agree bit for bit.
EXTRA_FLAGS: tuple[tuple[str, ...], ...] = (
    ("-march=native", "-fno-tree-slp-vectorize"),
    ("-march=native",),
    (),
)
LIBS: tuple[str, ...] = ("-lm",)

#: Built into the library beside the generated C (which it leaves untouched): one pointer for
#: ctypes to pass instead of five, which halves the cost of a call from Python.
SHIM = b"""#include "rpr3.h"

struct rpr3_call {
    const double *params, *q, *qd, *qdd;
    double *out;
};

int rpr3_call_packed(const struct rpr3_call *call)
{
    return rpr3_inverse_dynamics(call->params, call->q, call->qd, call->qdd, call->out);
}
"""


def cache_dir() -> Path:
    """Folder of compiled libraries (created on demand)."""
    if env := os.environ.get("RPR3GEN_CACHE_DIR"):
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "rpr3gen"


def _compiler() -> list[str]:
    command = shlex.split(os.environ.get("CC", "cc"))
    if not command or shutil.which(command[0]) is None:
        raise Rpr3genError(
            f"the c backend needs a C compiler, and {command[0] if command else 'cc'!r} was not "
            "found: install one (e.g. gcc) or set CC, or use --backend numpy"
        )
    return command


def sources(actuation: str) -> tuple[bytes, bytes]:
    """The generated ``rpr3.c`` and ``rpr3.h`` of one actuation scheme."""
    folder = resources.files("rpr3gen_generated") / actuation
    return (folder / "rpr3.c").read_bytes(), (folder / "rpr3.h").read_bytes()


def library_path(actuation: str) -> Path:
    """Path of the compiled library, building it if it is not in the cache."""
    source, header = sources(actuation)
    command = _compiler()
    digest = hashlib.sha256()
    for part in (source, header, SHIM, " ".join(command + list(CFLAGS) + list(LIBS)).encode()):
        digest.update(part)
        digest.update(b"\0")
    folder = cache_dir()
    target = folder / f"librpr3_{actuation}_{digest.hexdigest()[:20]}.so"
    if target.is_file():
        return target
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder, prefix=".build-") as tmp:
        for name, text in (("rpr3.c", source), ("rpr3.h", header), ("shim.c", SHIM)):
            (Path(tmp) / name).write_bytes(text)
        built = Path(tmp) / target.name
        for extra in EXTRA_FLAGS:
            result = subprocess.run(
                [*command, *CFLAGS, *extra, "rpr3.c", "shim.c", "-o", built.name, *LIBS],
                cwd=tmp,
                capture_output=True,
                text=True,
                check=False,
            )
            if result.returncode == 0:
                break
        else:
            first = (result.stderr.strip().splitlines() or ["(no message)"])[0]
            raise Rpr3genError(f"compiling the generated C for {actuation!r} failed: {first}")
        os.replace(built, target)
    return target


@cache
def library(actuation: str) -> ctypes.CDLL:
    """The loaded library of one actuation scheme, with typed entry points."""
    lib = ctypes.CDLL(str(library_path(actuation)))
    lib.rpr3_inverse_dynamics.restype = ctypes.c_int
    lib.rpr3_inverse_dynamics.argtypes = [ctypes.c_void_p] * 5
    lib.rpr3_call_packed.restype = ctypes.c_int
    lib.rpr3_call_packed.argtypes = [ctypes.c_void_p]
    lib.rpr3_inverse_dynamics_batch.restype = ctypes.c_size_t
    lib.rpr3_inverse_dynamics_batch.argtypes = [
        ctypes.c_void_p,
        ctypes.c_size_t,
        ctypes.c_void_p,
        ctypes.c_void_p,
        ctypes.c_void_p,
        ctypes.c_void_p,
    ]
    return lib


class Call(ctypes.Structure):
    """Arguments of one ``rpr3_inverse_dynamics`` call, for ``rpr3_call_packed``."""

    _fields_ = [(name, ctypes.c_void_p) for name in ("params", "q", "qd", "qdd", "out")]


def _macro(header: bytes, name: str) -> int:
    return int(header.decode().split(f"#define {name} ", 1)[1].split()[0])


@cache
def names(actuation: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """``rpr3_param_names`` and ``rpr3_output_names``, read from the compiled library."""
    lib, header = library(actuation), sources(actuation)[1]
    tables = []
    for table, macro in (("rpr3_param_names", "RPR3_NUM_PARAMS"),
                         ("rpr3_output_names", "RPR3_NUM_OUTPUTS")):  # fmt: skip
        array = (ctypes.c_char_p * _macro(header, macro)).in_dll(lib, table)
        tables.append(tuple((item or b"").decode() for item in array))
    return tables[0], tables[1]


def batch(
    params: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    actuation: str,
    out: np.ndarray | None = None,
) -> tuple[np.ndarray, int]:
    """Evaluate n samples (float64 arrays; q, qd, qdd (n, 3) C-contiguous).

    Args:
        out: optional C-contiguous (n, NUM_OUTPUTS) array to write into.

    Returns:
        ``out`` of shape (n, NUM_OUTPUTS), row-major as the C ABI, and the number of failed
        samples (their rows are NaN).
    """
    lib = library(actuation)
    _, output_names = names(actuation)
    if out is None:
        out = np.empty((q.shape[0], len(output_names)))
    if not out.flags.c_contiguous or out.shape != (q.shape[0], len(output_names)):
        raise ValueError(f"out must be C-contiguous of shape {(q.shape[0], len(output_names))}")
    params = np.ascontiguousarray(params, dtype=np.float64)
    q, qd, qdd = (np.ascontiguousarray(a, dtype=np.float64) for a in (q, qd, qdd))
    failed = lib.rpr3_inverse_dynamics_batch(
        params.ctypes.data, q.shape[0], q.ctypes.data, qd.ctypes.data, qdd.ctypes.data,
        out.ctypes.data,
    )  # fmt: skip
    return out, int(failed)
