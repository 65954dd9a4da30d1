"""The cache of variants generated on first use (``rpr3gen.variants``), in a fresh folder.

- Two processes that need the same new variant at once (started while this test holds the
  variant's lock, released once both have imported rpr3gen and are about to evaluate) both
  succeed with the same numbers, and only one derives it: one progress message on stderr, one
  folder, no staging folder left. Afterwards the variant loads from the cache without a message,
  and its files carry the generator's hash, which keys the folder.
- A variant of another generator (a folder under another hash's key) is never reused: the
  current generator derives its own, next to it.
- Where the lock does not hold, a second derivation that finds the variant already in place
  keeps it instead of failing.

No sleeps and no timing: the order of events is fixed by the lock and by the processes' output.
One real derivation, of ``ppr_2``, the quickest (about 3 s of CPU); the other tests stand in
for SymPy with the committed ``rrr_1``'s files.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen import manifest, variants
from rpr3gen.model import model_from_dict
from rpr3gen.structure import Structure

try:
    from . import planar_models as pm
    from . import planar_reference as pr
except ImportError:
    import planar_models as pm
    import planar_reference as pr

fcntl = pytest.importorskip("fcntl")  # the lock is POSIX's

STRUCTURE = Structure("PPR", 2)

CHILD = """
import json, sys
import numpy as np
import rpr3gen
from rpr3gen.model import model_from_dict
model = model_from_dict(json.loads(sys.argv[1]))
q = np.array(json.loads(sys.argv[2]))
print("ready", flush=True)
out = rpr3gen.inverse_dynamics(model, q, 0.1 * q, -q)
print(json.dumps({k: v.tolist() for k, v in out.items()}))
"""


def _case() -> tuple[dict, np.ndarray]:
    rng = np.random.default_rng(8)
    data = pm.random_model(rng, STRUCTURE.leg, STRUCTURE.actuated)
    q, _, _ = pm.random_motion(rng, pr.parse_model(data), np.linspace(0, 1, 5))
    return data, q


@pytest.mark.slow
def test_two_processes_derive_a_new_variant_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("RPR3GEN_CACHE_DIR", str(tmp_path))
    root = variants.folder(STRUCTURE)
    assert root.parent == tmp_path / "variants"
    assert not root.exists()
    data, q = _case()
    env = {**os.environ, "RPR3GEN_CACHE_DIR": str(tmp_path)}
    argv = [sys.executable, "-c", CHILD, json.dumps(data), json.dumps(q.tolist())]
    lock = root.with_name(root.name + ".lock")
    lock.parent.mkdir(parents=True)
    with lock.open("a+b") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        children = [
            subprocess.Popen(
                argv, env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE
            )
            for _ in range(2)
        ]
        for child in children:  # both about to need the variant; neither can derive it yet
            assert child.stdout is not None
            assert child.stdout.readline() == "ready\n"
        assert not root.exists()
        fcntl.flock(handle, fcntl.LOCK_UN)
    results = [child.communicate(timeout=900) for child in children]
    for child, (_, err) in zip(children, results, strict=True):
        assert child.returncode == 0, err
    errs = sorted(err for _, err in results)
    assert errs[0] == ""
    assert errs[1].count("\n") == 1
    assert errs[1].startswith("rpr3gen: deriving the 3-PPR, motors on joint 2 (first use")
    assert str(root) in errs[1]
    first, second = (json.loads(out) for out, _ in results)
    assert first == second
    assert np.all(np.isfinite(first["tau_A"]))
    # One folder, complete, nothing staged left; its files carry the key's generator hash.
    assert sorted(p.name for p in (tmp_path / "variants").iterdir()) == [
        root.name,
        lock.name,
    ]
    assert sorted(p.name for p in root.iterdir()) == ["__init__.py", STRUCTURE.variant]
    assert manifest.load(STRUCTURE.variant, root).source_hash == variants.generator_hash()
    # Afterwards: from the cache, silently, the same numbers.
    capfd.readouterr()
    model = model_from_dict(data)
    assert variants.ensure(STRUCTURE) == root
    out = rpr3gen.inverse_dynamics(model, q, 0.1 * q, -q)
    assert capfd.readouterr().err == ""
    assert {k: v.tolist() for k, v in out.items()} == first


def test_a_variant_of_another_generator_is_not_reused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A complete folder of the same variant under another generator's key (what an older
    rpr3gen left) sits in the cache: the current generator does not take it; it derives its
    own (here a stand-in that copies the committed files, and records the call)."""
    monkeypatch.setenv("RPR3GEN_CACHE_DIR", str(tmp_path))
    structure = Structure("RRR", 1)
    committed = manifest.default_folder() / structure.variant
    current = variants.folder(structure)
    with monkeypatch.context() as old:
        old.setattr(variants, "generator_hash", lambda: "0" * 64)
        stale = variants.folder(structure)
    assert stale != current
    assert stale.name.startswith(f"{structure.variant}-")
    assert current.name.startswith(f"{structure.variant}-")
    shutil.copytree(committed, stale / structure.variant)
    (stale / "__init__.py").touch()
    calls: list[Path] = []

    def derive(s: Structure, root: Path, whole: bool = False) -> None:
        calls.append(root)
        shutil.copytree(committed, root / s.variant)

    monkeypatch.setattr(variants, "_derive", derive)
    assert variants.ensure(structure) == current
    assert calls == [current]
    assert variants.ensure(structure) == current  # and from the cache now
    assert calls == [current]
    assert (stale / structure.variant / "manifest.json").is_file()  # left alone


def test_a_derivation_that_finds_its_variant_already_there_keeps_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where the lock does not hold (no ``fcntl``, a file system without ``flock``), two
    processes may both derive a new variant: the second to finish finds the first's complete
    folder in place and keeps it, rather than failing on the rename. Here the two derivations
    run one after the other, each writing the committed ``rrr_1``'s files (a stand-in for
    SymPy)."""
    from rpr3gen_derive.planar import generate

    monkeypatch.setenv("RPR3GEN_CACHE_DIR", str(tmp_path))
    structure = Structure("RRR", 1)
    committed = manifest.default_folder()
    files = {
        path.relative_to(committed).as_posix(): path.read_text()
        for path in [committed / "__init__.py", *(committed / structure.variant).iterdir()]
        if path.is_file() and path.suffix in (".py", ".c", ".h", ".json")
    }
    monkeypatch.setattr(generate, "render", lambda *args, **kwargs: files)
    root = variants.folder(structure)
    variants._derive(structure, root)
    first = manifest.load(structure.variant, root)
    variants._derive(structure, root)  # the other process, finishing second
    assert manifest.load(structure.variant, root) == first
    assert sorted(p.name for p in root.iterdir()) == ["__init__.py", structure.variant]
