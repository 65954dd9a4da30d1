"""MkDocs hooks of the documentation site (``mkdocs.yml``): pages drawn from their sources.

The site is built from files that live elsewhere in the repository, so that each fact has one
source:

- ``<!-- include FILE#HEADING -->`` in a page is replaced by that section of FILE (a path from
  the repository's root; the section runs to the next heading of its level or above): the
  README's Quick start, the one section the README (the front page) and the site both show;
  ``include-intro`` stops at the section's first subheading.
- ``commands.md`` is generated from the command line's own ``--help`` (argparse), one section
  per command.
- ``<!-- file PATH -->`` becomes the whole file as a code block (a gallery model ...).
- ``<!-- header-excerpt VARIANT -->`` becomes the defines and the inverse dynamics' prototypes
  of ``generated/VARIANT/rpr3.h``.
- The notebooks (``notebooks/*.ipynb``) and the benchmark reports (``benchmarks/*.md`` but its
  README) become pages, whatever files exist; their navigation entries are added here, after
  the page that introduces them when the navigation has it (``notebooks.md``,
  ``performance.md``: that entry becomes a section), else as sections of their own.
- A link to a file of the repository outside ``docs/`` (``../notebooks/simulation.ipynb``, as
  GitHub reads it) goes to its page when the site shows it (a notebook, a benchmark report);
  any other cannot work on the site: it becomes the file's path as code. Links within ``docs/``
  are MkDocs' to check (``--strict``).
- Every public function and class of ``rpr3gen`` (its ``__all__``) and of the modules the API
  page documents must have a docstring: one missing is a warning, so a strict build fails.
"""

from __future__ import annotations

import contextlib
import inspect
import io
import logging
import os
import posixpath
import re
from pathlib import Path
from typing import Any

from markdown.extensions.toc import slugify
from mkdocs.plugins import event_priority
from mkdocs.structure.files import File, Files

log = logging.getLogger("mkdocs.plugins.rpr3gen")

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
INCLUDE = re.compile(r"<!--\s*include(-intro)?\s+(\S+?)#(.+?)\s*-->")
HEADER = re.compile(r"<!--\s*header-excerpt\s+(\S+)\s*-->")
WHOLE = re.compile(r"<!--\s*file\s+(\S+)\s*-->")
LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*$")

#: Modules whose public names the API page documents, beside the package itself.
DOCUMENTED_MODULES = ("rpr3gen.animation",)


def _notebooks() -> list[Path]:
    return sorted((ROOT / "notebooks").glob("*.ipynb"))


def _benchmark_reports() -> list[Path]:
    return sorted(p for p in (ROOT / "benchmarks").glob("*.md") if p.name != "README.md")


def _site_pages() -> dict[Path, str]:
    """The files outside ``docs/`` that the site shows as pages: path -> the page's source URI."""
    pages = {p: f"notebooks/{p.name}" for p in _notebooks()}
    pages.update({p: f"benchmarks/{p.name}" for p in _benchmark_reports()})
    return pages


#: The pages that introduce the generated sections: section title -> page.
SECTION_PAGES = {"Notebooks": "notebooks.md", "Benchmarks": "performance.md"}


def _title(path: Path) -> str:
    """A page's title: its first heading, or its name."""
    if path.suffix == ".md":
        for line in path.read_text(encoding="utf-8").splitlines():
            if m := HEADING.match(line):
                return m[2]
    return path.stem.replace("-", " ").capitalize()


#: Where each included section is shown: ``(file, heading) -> page``, from the pages' includes.
SHOWN: dict[tuple[str, str], str] = {}


def on_config(config: Any) -> Any:
    """Add the notebooks and the benchmark reports to the navigation, whatever files exist;
    note which page shows each included section (for links into it)."""
    SHOWN.clear()
    for page in sorted(DOCS.glob("*.md")):
        for m in INCLUDE.finditer(page.read_text(encoding="utf-8")):
            if not m[1]:  # an intro shows no subsection
                SHOWN.setdefault((m[2], m[3].strip()), page.name)
    nav = config["nav"]
    notebooks = [{_title(p): f"notebooks/{p.name}"} for p in _notebooks()]
    reports = [{_title(p): f"benchmarks/{p.name}"} for p in _benchmark_reports()]
    for title, entries in (("Notebooks", notebooks), ("Benchmarks", reports)):
        if not entries:
            continue
        page = SECTION_PAGES[title]
        for k, item in enumerate(nav):
            if isinstance(item, dict) and list(item.values()) == [page]:
                (name,) = item
                nav[k] = {name: [{"Overview": page}, *entries]}
                break
        else:
            nav.append({title: entries})
    return config


@event_priority(100)  # before mkdocs-jupyter turns the notebooks into pages
def on_files(files: Files, config: Any) -> Files:
    """The pages that are drawn from files outside ``docs/``."""
    files.append(File.generated(config, "commands.md", content=_commands_page()))
    for path in _notebooks():  # a real file whose source folder is the repository's root
        files.append(
            File(
                f"notebooks/{path.name}",
                src_dir=str(ROOT),
                dest_dir=config["site_dir"],
                use_directory_urls=config["use_directory_urls"],
            )
        )
    for path in _benchmark_reports():
        text = _rewrite_links(path.read_text(encoding="utf-8"), path, f"benchmarks/{path.name}")
        files.append(File.generated(config, f"benchmarks/{path.name}", content=text))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    """Expand the includes and header excerpts; make links out of ``docs/`` plain paths."""
    page_uri = page.file.src_uri
    source = Path(page.file.abs_src_path) if page.file.abs_src_path else DOCS / page_uri

    def include(m: re.Match[str]) -> str:
        intro, name, heading = bool(m[1]), m[2], m[3]
        path = ROOT / name
        if not path.is_file():
            log.warning(f"{page_uri}: include: no file {name}")
            return ""
        section = _section(path.read_text(encoding="utf-8"), heading, intro=intro)
        if section is None:
            log.warning(f"{page_uri}: include: no heading {heading!r} in {name}")
            return ""
        return _rewrite_links(section, path, page_uri, anchors=_anchors(name, page_uri))

    markdown = INCLUDE.sub(include, markdown)
    markdown = HEADER.sub(lambda m: _header_excerpt(m[1], page_uri), markdown)
    markdown = WHOLE.sub(lambda m: _whole_file(m[1], page_uri), markdown)
    if source.is_relative_to(DOCS):
        markdown = _rewrite_links(markdown, source, page_uri)
    return markdown


def on_pre_build(config: Any) -> None:
    """Warn about every public function or class without a docstring."""
    import importlib

    import rpr3gen

    modules = [(rpr3gen, rpr3gen.__all__)]
    for name in DOCUMENTED_MODULES:
        module = importlib.import_module(name)
        modules.append((module, getattr(module, "__all__", [])))
    for module, names in modules:
        for name in names:
            obj = getattr(module, name)
            if not (inspect.isclass(obj) or inspect.isfunction(obj)):
                continue
            if not (obj.__doc__ or "").strip():  # its own: a class inherits its base's
                log.warning(f"{module.__name__}.{name}: no docstring")
            if inspect.isclass(obj):
                for attr, member in vars(obj).items():
                    if attr.startswith("_") or not inspect.isfunction(member):
                        continue
                    if not (member.__doc__ or "").strip():
                        log.warning(f"{module.__name__}.{name}.{attr}: no docstring")


def _section(text: str, heading: str, intro: bool = False) -> str | None:
    """The body of the section under ``heading`` (its text, without the heading's hashes); with
    ``intro``, only what comes before its first subheading."""
    lines = text.splitlines()
    fenced = False
    start = level = None
    for k, line in enumerate(lines):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        m = None if fenced else HEADING.match(line)
        if m is None:
            continue
        if start is None:
            if m[2] == heading.strip():
                start, level = k + 1, len(m[1])
        elif intro or len(m[1]) <= level:  # type: ignore[operator]
            return "\n".join(lines[start:k]).strip("\n") + "\n"
    if start is None:
        return None
    return "\n".join(lines[start:]).strip("\n") + "\n"


def _anchors(name: str, page_uri: str) -> dict[str, str]:
    """Where the anchors of file ``name``'s headings are on the site, seen from ``page_uri``.

    A heading inside a section some page includes is on that page (the included section's own
    heading is not: the link then goes to the page); the others are nowhere (absent).
    """
    text = (ROOT / name).read_text(encoding="utf-8")
    out: dict[str, str] = {}
    stack: list[tuple[int, str]] = []  # the enclosing headings: (level, text)
    fenced = False
    for line in text.splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        m = None if fenced else HEADING.match(line)
        if m is None:
            continue
        level, heading = len(m[1]), m[2]
        stack = [(lv, h) for lv, h in stack if lv < level]
        for depth, (_, outer) in enumerate([*stack, (level, heading)]):
            page = SHOWN.get((name, outer))
            if page is None:
                continue
            here = (
                ""
                if page == page_uri
                else posixpath.relpath(page, posixpath.dirname(page_uri) or ".")
            )
            own = depth == len(stack)  # the included section's heading itself: not on the page
            out[slugify(heading, "-")] = here if own else f"{here}#{slugify(heading, '-')}"
            break
        stack.append((level, heading))
    return out


def _rewrite_links(
    text: str, source: Path, page_uri: str, anchors: dict[str, str] | None = None
) -> str:
    """Links of ``source`` (a file of the repository) as they must read on page ``page_uri``.

    A target inside ``docs/``, or a notebook or benchmark report (the site shows them as pages),
    is made relative to the page; any other file of the repository becomes its path as code (the
    site has no copy of it). An anchor of an included file goes
    where ``anchors`` says its heading is shown, or the link becomes its label when it is
    shown nowhere. External links stay.
    """
    page_dir = posixpath.dirname(page_uri)

    def fix(m: re.Match[str]) -> str:
        bang, label, target = m[1], m[2], m[3]
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):
            return m[0]
        if target.startswith("#"):
            if anchors is None:
                return m[0]
            where = anchors.get(target[1:])
            if where is None:
                return label
            return f"[{label}]({where or '#'})" if where else m[0]
        path, _, anchor = target.partition("#")
        resolved = (source.parent / path).resolve()
        shown_as = _site_pages().get(resolved)
        if shown_as is not None and not bang:
            new = posixpath.relpath(shown_as, page_dir or ".") + (f"#{anchor}" if anchor else "")
            return f"[{label}]({new})"
        if resolved.is_relative_to(DOCS):
            inside = resolved.relative_to(DOCS).as_posix()
            new = posixpath.relpath(inside, page_dir or ".") + (f"#{anchor}" if anchor else "")
            return f"{bang}[{label}]({new})"
        if bang:
            log.warning(f"{page_uri}: image {target} is outside docs/")
            return m[0]
        shown = resolved.relative_to(ROOT).as_posix() if resolved.is_relative_to(ROOT) else path
        label = label.strip("`")
        return f"`{shown}`" if label in (shown, path, Path(shown).name) else f"{label} (`{shown}`)"

    out, fenced = [], False
    for line in text.splitlines(keepends=True):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        out.append(line if fenced else LINK.sub(fix, line))
    return "".join(out)


def _commands_page() -> str:
    """One section per command of ``rpr3gen``, its ``--help`` as argparse prints it."""
    from rpr3gen import cli

    parser = cli.build_parser()
    parts = [
        "# Commands\n",
        "Every command of `rpr3gen`, with its options, defaults and units. This page is "
        "**generated** when the site is built, from the command line's own `--help` "
        "(`rpr3gen COMMAND --help` prints the same text); nothing here is written by hand.\n",
        "```text\n" + _help(parser) + "```\n",
    ]
    subparsers = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, sub in subparsers.choices.items():  # type: ignore[attr-defined]
        parts.append(f"## `rpr3gen {name}`\n")
        parts.append("```text\n" + _help(sub) + "```\n")
    return "\n".join(parts)


def _help(parser: Any) -> str:
    """``parser``'s help, wrapped at 100 columns whatever the terminal (argparse reads COLUMNS)."""
    out = io.StringIO()
    columns = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "100"
    try:
        with contextlib.redirect_stdout(out):
            parser.print_help()
    finally:
        if columns is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = columns
    return out.getvalue()


def _header_excerpt(variant: str, page_uri: str) -> str:
    """The defines and the inverse dynamics' declarations of a generated header, as C."""
    path = ROOT / "generated" / variant / "rpr3.h"
    if not path.is_file():
        log.warning(f"{page_uri}: header-excerpt: no {path.relative_to(ROOT)}")
        return ""
    lines = path.read_text(encoding="utf-8").splitlines()
    defines = [line for line in lines if line.startswith(("#define RPR3_", "extern const"))]
    defines = [line for line in defines if not line.startswith("#define RPR3_H")]
    start = next(k for k, line in enumerate(lines) if line.startswith("int rpr3_inverse_dynamics("))
    comment = start
    while comment > 0 and lines[comment - 1].strip() and not lines[comment - 1].startswith("#"):
        comment -= 1
    end = next(k for k in range(start + 1, len(lines)) if not lines[k].strip())
    excerpt = "\n".join([*defines, "", *lines[comment:end]])
    return f"```c\n/* generated/{variant}/rpr3.h (excerpt) */\n{excerpt}\n```\n"


def _whole_file(name: str, page_uri: str) -> str:
    """A file of the repository as a code block, in the language of its suffix."""
    path = ROOT / name
    if not path.is_file():
        log.warning(f"{page_uri}: file: no {name}")
        return ""
    language = {".toml": "toml", ".csv": "text", ".py": "python", ".c": "c"}.get(path.suffix, "")
    return f"```{language}\n# {name}\n{path.read_text(encoding='utf-8')}```\n"
