"""What a new user meets first: the README's Quick start, CI running it, the extras, the docs.

The README is the front page: the Quick start first, then links into the documentation
(``docs/*.md``), where every other fact lives once (tests/test_docs_site.py builds the site)."""

from __future__ import annotations

import importlib.util
import json
import re
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
    page = repo_root / "docs" / "notebooks.md"  # how to open them, linked from the README
    assert "'.[notebooks]'" in page.read_text(encoding="utf-8")


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


def _nav_pages(root: Path) -> list[str]:
    """The pages of mkdocs.yml's ``nav`` (``- Title: page.md`` lines; the file has tags a plain
    YAML loader refuses)."""
    lines = (root / "mkdocs.yml").read_text(encoding="utf-8").splitlines()
    start = lines.index("nav:")
    pages = []
    for line in lines[start + 1 :]:
        if line and not line.startswith(" "):
            break
        if m := re.match(r"^\s*- (?:[^:]+:\s*)?(\S+\.md)\s*$", line):
            pages.append(m[1])
    return pages


def test_readme_is_a_front_page_that_links_every_docs_page(repo_root: Path) -> None:
    """Short, the Quick start first, and every page of the site's navigation that is a file of
    docs/ linked from its Documentation section (a new page cannot be forgotten)."""
    text = (repo_root / "README.md").read_text(encoding="utf-8")
    lines = text.splitlines()
    assert len(lines) < 250, f"README.md has {len(lines)} lines: move sections into docs/"
    headings = [line for line in lines if line.startswith("## ")]
    assert headings[0] == "## Quick start"
    start = lines.index("## Documentation")
    end = next((k for k in range(start + 1, len(lines)) if lines[k].startswith("## ")), len(lines))
    section = "\n".join(lines[start:end])
    linked = set(re.findall(r"\]\(docs/([^)#\s]+\.md)(?:#[^)]*)?\)", section))
    pages = [p for p in _nav_pages(repo_root) if (repo_root / "docs" / p).is_file()]
    assert len(pages) >= 10, pages
    missing = [p for p in pages if p not in linked]
    assert not missing, f"pages of mkdocs.yml's nav not linked from the README: {missing}"


def test_readme_links_resolve(repo_root: Path) -> None:
    """Every relative link and image of the README names a file of the repository (as GitHub
    reads them), and every anchor one of the page's headings."""
    text = (repo_root / "README.md").read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):
            continue
        path, _, anchor = target.partition("#")
        assert path, f"README.md: in-page anchor {target}: the sections live in docs/ now"
        assert (repo_root / path).exists(), f"README.md: no {path}"
        if anchor and path.endswith(".md"):
            page = (repo_root / path).read_text(encoding="utf-8")
            slugs = {  # as Python-Markdown's toc makes them
                re.sub(r"[-\s]+", "-", re.sub(r"[^\w\s-]", "", h).strip().lower())
                for h in re.findall(r"^#+\s+(.*?)\s*$", page, re.M)
            }
            assert anchor in slugs, f"README.md: no heading #{anchor} in {path}"


def test_performance_page_shows_the_committed_results(
    repo_root: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/performance.md's block is what ``report.py --docs`` draws from the committed
    ``benchmarks/results.json``, byte for byte (nobody edits the figures by hand)."""
    monkeypatch.syspath_prepend(str(repo_root / "benchmarks"))
    spec = importlib.util.spec_from_file_location(
        "bench_report", repo_root / "benchmarks" / "report.py"
    )
    assert spec is not None
    assert spec.loader is not None
    report = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(report)
    assert repo_root / "docs" / "performance.md" == report.PAGE
    results = json.loads((repo_root / "benchmarks" / "results.json").read_text(encoding="utf-8"))
    page = report.PAGE.read_text(encoding="utf-8")
    start, end = page.index(report.BEGIN), page.index(report.END) + len(report.END)
    assert page[start:end] == report.docs_block(results)
