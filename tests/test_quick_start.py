"""What a new user meets first: the README's Quick start, CI running it, the extras, the docs."""

from __future__ import annotations

import importlib.util
import tomllib
from pathlib import Path

import pytest


def _quick_start(root: Path) -> list[str]:
    lines = (root / "README.md").read_text(encoding="utf-8").splitlines()
    assert lines[:4] == ["# rpr3gen", "", "## Quick start", ""], lines[:4]
    assert lines[4] == "```bash"
    end = lines.index("```", 5)
    return lines[5:end]


def test_quick_start_is_one_environment_for_the_main_job_and_the_tests(repo_root: Path) -> None:
    setup_and_run, test = _quick_start(repo_root)
    assert setup_and_run.startswith(
        "python3 -m venv .venv && .venv/bin/pip install -q -e '.[dev,peers,docs]'"
    )
    assert setup_and_run.endswith(" && .venv/bin/rpr3gen paper --out docs/paper")
    assert test == ".venv/bin/python -m pytest"  # the same .venv, not built a second time


def test_ci_runs_the_quick_start_verbatim(repo_root: Path) -> None:
    script = (repo_root / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    commands = [line for line in script if line and not line.startswith("#")]
    assert commands[0] == "set -euo pipefail"
    assert commands[-2:] == _quick_start(repo_root)


def test_notebooks_extra_brings_a_jupyter_front_end(repo_root: Path) -> None:
    project = tomllib.loads((repo_root / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extra = {
        req.split("=")[0].split(">")[0] for req in project["optional-dependencies"]["notebooks"]
    }
    assert {"jupyterlab", "ipykernel", "sympy", "jinja2"} <= extra
    assert "'.[notebooks]'" in (repo_root / "README.md").read_text(encoding="utf-8")


def test_quick_benchmark_run_keeps_the_committed_full_results(
    repo_root: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(repo_root / "benchmarks"))  # as when run as a script
    spec = importlib.util.spec_from_file_location("bench_run", repo_root / "benchmarks" / "run.py")
    assert spec is not None
    assert spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.results_path(quick=False) == repo_root / "benchmarks" / "results.json"
    quick = bench.results_path(quick=True)
    assert quick == repo_root / "benchmarks" / "results-quick.json"
    ignored = (repo_root / ".gitignore").read_text(encoding="utf-8").splitlines()
    for suffix in (".json", ".md"):  # report.py writes the Markdown beside the results
        assert f"/benchmarks/{quick.with_suffix(suffix).name}" in ignored
