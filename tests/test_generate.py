"""Regeneration: committed sources are current, output is deterministic and self-describing."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from rpr3gen_derive.codegen import files
from rpr3gen_derive.planar import generate

import rpr3gen
from rpr3gen import manifest
from rpr3gen.cli import main
from rpr3gen.evaluators import numpy_module


def test_committed_generated_tree_is_current(
    repo_root: Path, capsys: pytest.CaptureFixture
) -> None:
    assert main(["generate", "--check", "--out", str(repo_root / "generated")]) == 0
    assert "up to date" in capsys.readouterr().out


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


def test_check_detects_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["generate", "--check", "--out", str(tmp_path / "nothing")]) == 2
    assert "stale" in capsys.readouterr().err


def test_generate_then_check_round_trip(tmp_path: Path) -> None:
    out = tmp_path / "gen"
    assert main(["generate", "--out", str(out)]) == 0
    assert main(["generate", "--check", "--out", str(out)]) == 0
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted(
        generate.render()
    )


def test_generate_for_a_model_writes_its_variant_only(tmp_path: Path, repo_root: Path) -> None:
    model = tmp_path / "prismatic.toml"
    text = (repo_root / "models" / "paper.toml").read_text()
    model.write_text(text.replace('actuation = "revolute"', 'actuation = "prismatic"'))
    out = tmp_path / "gen"
    assert main(["generate", "--model", str(model), "--out", str(out)]) == 0
    assert (out / "prismatic" / "rpr3_numpy.py").is_file()
    assert not (out / "revolute").exists()


def _render_in_subprocess(out: Path, seed: str) -> None:
    env = dict(os.environ, PYTHONHASHSEED=seed)
    code = (
        "import sys; from rpr3gen.cli import main; "
        "sys.exit(main(['generate', '--out', sys.argv[1]]))"
    )
    subprocess.run([sys.executable, "-c", code, str(out)], check=True, env=env, capture_output=True)


def test_output_is_identical_across_hash_seeds(tmp_path: Path) -> None:
    first, second = tmp_path / "a", tmp_path / "b"
    _render_in_subprocess(first, "1")
    _render_in_subprocess(second, "4242")
    files = sorted(p.relative_to(first) for p in first.rglob("*") if p.is_file())
    assert files
    for rel in files:
        assert (first / rel).read_bytes() == (second / rel).read_bytes(), rel


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
    roots = (copy / "codegen", copy / "planar")
    original = files.source_hash(roots)
    assert original == generate.source_hash()
    frames = copy / "planar" / "legs.py"
    frames.write_text(frames.read_text() + "\n# edit\n")
    assert files.source_hash(roots) != original


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
