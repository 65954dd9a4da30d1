"""Generation time per structure: its variant's first use with an empty cache, then with a warm one.

:func:`run` starts this file twice as a script, each time a fresh interpreter on the same new,
empty cache folder (``RPR3GEN_CACHE_DIR``): **cold**, the first use, which derives the variant
(SymPy), writes its files (the emitters) and compiles its C library; **cached**, a second first
use, which finds and loads what the first left. The script times each step of a first use:

- ``import``: ``import rpr3gen`` (and the modules below);
- ``derive``: finding the variant's folder (the generator's hash, the manifest), deriving and
  writing it first when the cache lacks it. Cold, it derives every variant, even one that
  ``generated/`` carries (``rrr_1``; the runtime would not derive it), so that every structure
  has the figure; cached, it finds the variant as the runtime does (``variants.load``);
- ``numpy``: importing the variant's generated NumPy module (cold: compiling it to bytecode);
- ``c``: the C library (``rpr3gen.cbackend``): compiling it when the cache lacks it, loading it
  through ctypes.

The parent also times the whole process (``wall``: the interpreter's start included).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

STEPS = ("import", "derive", "numpy", "c")


def first_use(variant: str, cold: bool) -> dict[str, float]:
    """Seconds of each step of the variant's first use in this process (see the module)."""
    start = time.perf_counter()
    from rpr3gen import cbackend, loader, manifest, variants
    from rpr3gen.structure import Structure

    times = {"import": time.perf_counter() - start}
    structure = Structure.of_variant(variant)
    start = time.perf_counter()
    # Cold: derived into the cache even when generated/ carries it; cached: as the runtime finds it.
    found = manifest.load(variant, variants.ensure(structure)) if cold else variants.load(structure)
    times["derive"] = time.perf_counter() - start
    start = time.perf_counter()
    loader.numpy_module(found)
    times["numpy"] = time.perf_counter() - start
    start = time.perf_counter()
    cbackend.library(found)
    times["c"] = time.perf_counter() - start
    return times


def run(variant: str, keep: Path | None = None) -> dict[str, Any]:
    """``{"cold": {step: s, "wall": s}, "cached": {...}}`` of ``variant``, each a fresh
    interpreter; the cache they filled is then copied into ``keep`` (the run's cache) if given,
    so that the other benchmarks find the variant there."""
    found: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="rpr3bench-generation-") as cache:
        # A first use waits for the quick C build (rpr3gen.cbackend); the optimised one, which
        # it would start in the background, would run during the measurements that follow.
        env = {**os.environ, "RPR3GEN_CACHE_DIR": cache, "RPR3GEN_C_BUILD": "quick"}
        for kind in ("cold", "cached"):
            start = time.perf_counter()
            done = subprocess.run(
                [sys.executable, __file__, variant, kind],
                env=env, capture_output=True, text=True, check=False,
            )  # fmt: skip
            wall = time.perf_counter() - start
            if done.returncode != 0:
                raise RuntimeError(f"{variant}, {kind} first use failed:\n{done.stderr}")
            found[kind] = {**json.loads(done.stdout.splitlines()[-1]), "wall": wall}
        if keep is not None:
            shutil.copytree(cache, keep, dirs_exist_ok=True)
    return found


if __name__ == "__main__":
    print(json.dumps(first_use(sys.argv[1], cold=sys.argv[2] == "cold")))
