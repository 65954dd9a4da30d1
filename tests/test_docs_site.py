"""The documentation site (extra `docs`): built strictly, so a broken link or a missing
docstring fails; skipped when MkDocs and its plugins are not installed."""

from __future__ import annotations

import importlib.util
import logging
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

for _module in ("mkdocs", "material", "mkdocstrings_handlers.python", "mkdocs_jupyter"):
    pytest.importorskip(_module, reason="the docs extra is not installed: pip install -e '.[docs]'")

ROOT = Path(__file__).resolve().parent.parent


def _hooks():
    spec = importlib.util.spec_from_file_location("site_hooks", ROOT / "docs" / "hooks" / "site.py")
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_site_builds_strictly(tmp_path: Path) -> None:
    """Notebooks are converted unexecuted here (tests/test_notebooks.py runs them); a published
    build executes them (RPR3GEN_DOCS_EXECUTE unset)."""
    site = tmp_path / "site"
    cache = ROOT / ".cache" / "mkdocs-jupyter"
    cached = cache.exists()
    env = {
        **os.environ,
        "RPR3GEN_DOCS_EXECUTE": "false",
        "RPR3GEN_DOCS_CACHE": str(tmp_path / "cache"),
        "NO_MKDOCS_2_WARNING": "1",
    }
    result = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    commands = (site / "commands" / "index.html").read_text(encoding="utf-8")
    assert "rpr3gen animate" in commands
    assert "--min-conditioning" in commands
    for notebook in (ROOT / "notebooks").glob("*.ipynb"):
        assert (site / "notebooks" / notebook.stem / "index.html").is_file(), notebook.name
    for report in (ROOT / "benchmarks").glob("*.md"):
        if report.name != "README.md":
            assert (site / "benchmarks" / report.stem / "index.html").is_file(), report.name
    assert (site / "animation" / "paper-rotation.gif").is_file()
    start = (site / "getting-started" / "index.html").read_text(encoding="utf-8")
    assert "pip install" in re.sub(r"<[^>]+>", "", start)  # the README's Quick start, included
    errors = (site / "errors" / "index.html").read_text(encoding="utf-8")
    assert "RPR3GEN_MAX_MEMORY" in errors  # the README's former sections, now pages of their own
    assert "<!-- end of performance -->" in (site / "performance" / "index.html").read_text(
        encoding="utf-8"
    )
    notebooks = (site / "notebooks" / "index.html").read_text(encoding="utf-8")
    assert 'href="derivation/"' in notebooks  # ../notebooks/derivation.ipynb: the notebook's page
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert 'id="rpr3gen.inverse_dynamics"' in api
    assert 'id="rpr3gen.animation.write_animation"' in api
    assert cache.exists() == cached, "the build left its notebook cache in the tree"


def test_a_missing_docstring_is_a_warning(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    import rpr3gen

    hooks = _hooks()
    monkeypatch.setattr(rpr3gen.load_model, "__doc__", None)
    with caplog.at_level(logging.WARNING, logger="mkdocs.plugins.rpr3gen"):
        hooks.on_pre_build(None)
    assert [r.getMessage() for r in caplog.records] == ["rpr3gen.load_model: no docstring"]


def test_links_out_of_the_docs_and_includes() -> None:
    hooks = _hooks()
    readme = ROOT / "README.md"
    text = "See [the model](docs/conventions.md#frames), [code](src/rpr3gen/cli.py) and [w](https://x.org)."
    out = hooks._rewrite_links(text, readme, "getting-started.md")
    assert "[the model](conventions.md#frames)" in out
    assert "code (`src/rpr3gen/cli.py`)" in out
    assert "[w](https://x.org)" in out
    page = ROOT / "docs" / "notebooks.md"  # files the site shows as pages: links to the pages
    out = hooks._rewrite_links("[nb](../notebooks/simulation.ipynb)", page, "notebooks.md")
    assert out == "[nb](notebooks/simulation.ipynb)"
    out = hooks._rewrite_links("[r](../benchmarks/results.md#x)", page, "performance.md")
    assert out == "[r](benchmarks/results.md#x)"
    out = hooks._rewrite_links("[b](../benchmarks/README.md)", page, "performance.md")
    assert out == "b (`benchmarks/README.md`)"
    section = hooks._section("# A\n\n## B\nb text\n```\n# not a heading\n```\n## C\nc\n", "B")
    assert section == "b text\n```\n# not a heading\n```\n"
    assert hooks._section("# A\n", "Z") is None


def test_each_fact_lives_in_one_page() -> None:
    """The pages hold their text: of the README, only the Quick start is included (the one
    section the front page and the site both show)."""
    for page in sorted((ROOT / "docs").glob("*.md")):
        for m in _hooks().INCLUDE.finditer(page.read_text(encoding="utf-8")):
            if m[2] == "README.md":
                assert m[3].strip() == "Quick start", f"{page.name} includes README.md#{m[3]}"
