"""Regeneration: committed sources are current, output is deterministic and self-describing."""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import pytest
from rpr3gen_derive.codegen import files
from rpr3gen_derive.planar import generate
from rpr3gen_derive.planar.structures import Structure

import rpr3gen
from rpr3gen import manifest
from rpr3gen.cli import main
from rpr3gen.evaluators import numpy_module

#: Renders of the sources in this process, by structures: a full render takes tens of seconds,
#: and most tests below check what is done with its files, not the render again.
_RENDERS: dict[tuple[str, ...], dict[str, str]] = {}
_RENDER = generate.render


def _rendered(
    structures: Iterable[Structure] = generate.COMMITTED, **kwargs: Any
) -> dict[str, str]:
    """``generate.render``, done once per process for each set of structures. The committed
    variants' render is the committed tree itself, which
    :func:`test_committed_generated_tree_is_current` shows a render gives byte for byte (the
    tests that use this check what the command does with the files; a second render on
    another worker took 45 s of it)."""
    if kwargs:
        return _RENDER(structures, **kwargs)
    key = tuple(structures)
    if key not in _RENDERS and key == tuple(generate.COMMITTED):
        root = generate.default_out_dir()
        assert root is not None
        _RENDERS[key] = {
            path.relative_to(root).as_posix(): path.read_text(encoding="utf-8")
            for path in sorted(root.rglob("*"))
            if path.is_file() and "__pycache__" not in path.parts and path.name != files.CHECKSUMS
        }
    if key not in _RENDERS:
        _RENDERS[key] = _RENDER(key)
    return dict(_RENDERS[key])


@pytest.fixture
def render_once(monkeypatch: pytest.MonkeyPatch) -> Callable[..., dict[str, str]]:
    """``generate.render``, for the command too, rendering once per process."""
    monkeypatch.setattr(generate, "render", _rendered)
    return _rendered


def test_committed_generated_tree_is_current(
    repo_root: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The check that every commit keeps, by a render of its own (kept for the other tests).

    It is also the check that the output does not depend on the hash seed (sets and dicts of
    symbols iterate in its order): the committed files were rendered by another process, with
    a random seed of its own, and this one renders them with another. Where this process's
    seed is not random (``PYTHONHASHSEED`` set), the render runs in a process whose seed differs
    from this one's."""
    if not _random_hash_seed():
        env = dict(os.environ, PYTHONHASHSEED=_other_hash_seed())
        code = (
            "import sys; from rpr3gen.cli import main; "
            "sys.exit(main(['generate', '--check', '--render', '--out', sys.argv[1]]))"
        )
        out = repo_root / "generated"
        result = subprocess.run(
            [sys.executable, "-c", code, str(out)], env=env, capture_output=True, text=True
        )
        assert result.returncode == 0, result.stderr
        assert "up to date" in result.stdout
        return

    def render(structures: Iterable[Structure] = generate.COMMITTED) -> dict[str, str]:
        key = tuple(structures)
        text = _RENDER(key)
        if key in _RENDERS:  # a second render in this process writes the same files
            assert text == _RENDERS[key]
        _RENDERS[key] = text
        return dict(text)

    monkeypatch.setattr(generate, "render", render)
    assert main(["generate", "--check", "--render", "--out", str(repo_root / "generated")]) == 0
    assert "up to date (checked by a render)" in capsys.readouterr().out


def _random_hash_seed() -> bool:
    """Whether this process's hash seed was drawn at random (``PYTHONHASHSEED`` unset or
    ``random``)."""
    return bool(sys.flags.hash_randomization) and os.environ.get("PYTHONHASHSEED", "random") in (
        "",
        "random",
    )


@pytest.mark.usefixtures("render_once")
def test_check_detects_hand_edit(
    repo_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    copy = tmp_path / "generated"
    shutil.copytree(repo_root / "generated", copy)
    target = copy / "revolute" / "rpr3_numpy.py"
    text = target.read_text()
    edited = text.replace("import numpy\n", "import numpy\nimport math\n", 1)
    assert edited != text
    target.write_text(edited)
    before = target.read_bytes()
    assert main(["generate", "--check", "--out", str(copy)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "revolute/rpr3_numpy.py" in err
    assert target.read_bytes() == before  # --check writes nothing


def _no_render(*args: Any, **kwargs: Any) -> dict[str, str]:
    raise AssertionError("rendered, where checksums.json tells")


def test_check_of_an_unchanged_tree_reads_its_checksums_without_rendering(
    repo_root: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    """checksums.json was written by a render of this generator, SymPy, Jinja2 and Python (the
    committed tree's, which test_committed_generated_tree_is_current renders): ``--check``
    reads it and renders nothing."""
    monkeypatch.setattr(generate, "render", _no_render)
    assert main(["generate", "--check", "--out", str(repo_root / "generated")]) == 0
    assert "up to date (checked by checksums.json)" in capsys.readouterr().out


def test_checksums_find_a_hand_edit_and_a_missing_file_without_rendering(
    repo_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    copy = tmp_path / "generated"
    shutil.copytree(repo_root / "generated", copy)
    (copy / "rrr_1" / "rpr3.h").write_text("/* edited */\n", encoding="utf-8")
    (copy / "ups_2" / "rpr3_derivatives.c").unlink()
    monkeypatch.setattr(generate, "render", _no_render)
    assert main(["generate", "--check", "--out", str(copy)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "rrr_1/rpr3.h" in err
    assert "ups_2/rpr3_derivatives.c" in err
    assert "revolute" not in err


@pytest.mark.usefixtures("render_once")
def test_checksums_of_another_render_key_are_not_trusted(
    repo_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Another generator, SymPy, Jinja2 or Python may render other bytes: the check renders
    (here the committed tree, what a render gives), and finds the hand edit the index hides."""
    copy = tmp_path / "generated"
    shutil.copytree(repo_root / "generated", copy)
    target = copy / "prismatic" / "rpr3.c"
    target.write_text(target.read_text() + "/* edited */\n")
    index = json.loads((copy / files.CHECKSUMS).read_text())
    index["files"]["prismatic/rpr3.c"] = hashlib.sha256(target.read_bytes()).hexdigest()
    index["render_key"] = "0" * 64
    (copy / files.CHECKSUMS).write_text(json.dumps(index))
    assert main(["generate", "--check", "--out", str(copy)]) == 2
    assert "prismatic/rpr3.c" in capsys.readouterr().err


@pytest.mark.usefixtures("render_once")
def test_check_detects_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["generate", "--check", "--out", str(tmp_path / "nothing")]) == 2
    assert "stale" in capsys.readouterr().err


def test_generate_then_check_round_trip(
    tmp_path: Path, render_once: Callable[..., dict[str, str]]
) -> None:
    out = tmp_path / "gen"
    assert main(["generate", "--out", str(out)]) == 0
    assert main(["generate", "--check", "--out", str(out)]) == 0
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted(
        [*render_once(), files.CHECKSUMS]
    )


def test_generate_for_a_model_writes_its_variant_only(tmp_path: Path, repo_root: Path) -> None:
    model = tmp_path / "prismatic.toml"
    text = (repo_root / "models" / "paper.toml").read_text()
    model.write_text(text.replace('actuation = "revolute"', 'actuation = "prismatic"'))
    out = tmp_path / "gen"
    assert main(["generate", "--model", str(model), "--out", str(out)]) == 0
    assert (out / "prismatic" / "rpr3_numpy.py").is_file()
    assert not (out / "revolute").exists()


def _other_hash_seed() -> str:
    """A PYTHONHASHSEED other than this process's (random unless the environment fixes it)."""
    if not sys.flags.hash_randomization:
        return "1"  # this process: PYTHONHASHSEED=0
    own = os.environ.get("PYTHONHASHSEED", "random")
    return str(int(own) + 1) if own.isdigit() else "4242"


def test_headers_carry_source_hash_and_nothing_volatile(repo_root: Path) -> None:
    digest = generate.source_hash()
    import jinja2
    import sympy

    for path in sorted((repo_root / "generated").rglob("*.py")):
        text = path.read_text()
        head = text.splitlines()[:3]
        assert "do not edit" in head[0], path
        assert head[1] == f"# Source hash: {digest}", path
        assert not re.search(r"\b20\d\d-\d\d-\d\d\b", text), path
        assert str(repo_root) not in text, path
        assert sympy.__version__ not in head[2]
        assert jinja2.__version__ not in head[2]


def test_cse_reduces_the_operation_count(repo_root: Path) -> None:
    for actuation in ("revolute", "prismatic"):
        head = (repo_root / "generated" / actuation / "rpr3_numpy.py").read_text().splitlines()[2]
        before, after = map(int, re.findall(r"(\d+) (?:before|after)", head))
        assert after < before


def test_source_hash_follows_the_sources(tmp_path: Path) -> None:
    copy = tmp_path / "derive"
    shutil.copytree(generate.ROBOT_DIR.parent, copy, ignore=shutil.ignore_patterns("__pycache__"))
    roots = (copy / "codegen", copy / "planar", copy / "spatial")
    original = files.source_hash(roots)
    assert original == generate.source_hash()
    frames = copy / "planar" / "legs.py"
    frames.write_text(frames.read_text() + "\n# edit\n")
    assert files.source_hash(roots) != original


@pytest.mark.usefixtures("render_once")
def test_a_generated_folder_is_used_by_simulate_and_the_api(tmp_path: Path) -> None:
    out = tmp_path / "gen"
    assert main(["generate", "--out", str(out)]) == 0
    # Mark the copy so that using it is visible: a comment in its NumPy module changes nothing.
    numpy_file = out / "revolute" / "rpr3_numpy.py"
    numpy_file.write_text(numpy_file.read_text() + "\nUSED_FROM_THE_FOLDER = True\n")
    model = rpr3gen.load_model(generated=out)
    variant = manifest.load(model.actuation, model.generated)
    assert variant.folder == (out / "revolute").resolve()
    assert numpy_module(variant).USED_FROM_THE_FOLDER
    traj = rpr3gen.paper_trajectory("rectilinear", samples=21)
    mine = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    installed = rpr3gen.inverse_dynamics(rpr3gen.load_model(), traj.q, traj.qd, traj.qdd)
    for name in rpr3gen.OUTPUT_NAMES:
        assert mine[name].tobytes() == installed[name].tobytes()
    csv = tmp_path / "r.csv"
    assert main(["simulate", "--generated", str(out), "--out", str(csv)]) == 0
    assert csv.is_file()


def test_a_missing_generated_folder_is_one_clear_line(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    assert main(["simulate", "--generated", str(tmp_path / "nothing")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "nothing" in err
    assert "rpr3gen generate" in err
