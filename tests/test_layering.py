"""Layers import one way: the runtime and the generated code never import sympy or jinja2, and
the import graph of ``src/rpr3gen``, ``derive/`` and ``generated/`` follows the layers of
docs/architecture.md, without a circle; docs/architecture.md names every package and command."""

from __future__ import annotations

import ast
import functools
import re
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pytest

BLOCKER = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('sympy', 'jinja2', 'rpr3gen_derive'):
            raise ImportError('blocked: ' + name)
        return None
sys.meta_path.insert(0, Block())
"""

RUN = """
import numpy as np
import rpr3gen
from rpr3gen.cli import main
model = rpr3gen.load_model()
traj = rpr3gen.paper_trajectory('rectilinear', samples=11)
out = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
assert np.isfinite(out['m10_A']).all()
import rpr3gen.plots, rpr3gen.atomic
assert not any(m.split('.')[0] in ('sympy', 'jinja2') for m in sys.modules)
print('ok')
"""


def test_runtime_runs_with_sympy_and_jinja2_blocked() -> None:
    result = subprocess.run(
        [sys.executable, "-c", BLOCKER + RUN], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


def test_generate_without_derive_dependencies_is_one_clear_line() -> None:
    code = BLOCKER.replace("'rpr3gen_derive'", "'nothing'") + (
        "from rpr3gen.cli import main\nsys.exit(main(['generate', '--check']))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1
    assert "rpr3gen[derive]" in result.stderr
    assert "Traceback" not in result.stderr


def test_importing_the_runtime_leaves_scipy_for_later() -> None:
    """``import rpr3gen``, which every command does, does not pay for SciPy (0.7 s of imports):
    the identification and the positions-only trajectories import it when they run."""
    code = "import sys, rpr3gen.cli; print(sorted({m.split('.')[0] for m in sys.modules}))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "'numpy'" in result.stdout
    assert "'scipy'" not in result.stdout


# -- The import graph, read statically ------------------------------------------------------------
# The layers (docs/architecture.md), each importing only the ones before it: derivation
# (``rpr3gen_derive``: ``codegen`` the engine, ``planar`` the robot) -> generated code
# (``rpr3gen_generated``) -> runtime (``rpr3gen``) -> commands (``rpr3gen.cli*``,
# ``rpr3gen.commands``). The files are parsed, not imported; every import statement counts,
# inside functions too (a circle hidden there is still a circle).

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = {
    "rpr3gen": ROOT / "src" / "rpr3gen",
    "rpr3gen_derive": ROOT / "derive",
    "rpr3gen_generated": ROOT / "generated",
}


@dataclass(frozen=True)
class Import:
    """One import statement's edge: ``source`` imports ``target`` at ``where`` (file:line)."""

    source: str
    target: str
    where: str

    def __str__(self) -> str:
        return f"{self.where}: {self.source} imports {self.target}"


@functools.cache
def _modules() -> dict[str, Path]:
    """Every module of the three packages by dotted name (a package by its ``__init__.py``)."""
    found = {}
    for package, root in PACKAGES.items():
        for path in sorted(root.rglob("*.py")):
            if "__pycache__" in path.parts:
                continue
            parts = [package, *path.relative_to(root).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts.pop()
            found[".".join(parts)] = path
    return found


def _imported_names(module: str, path: Path, node: ast.AST) -> list[str]:
    """The dotted names an import statement (or ``importlib.import_module("...")``) brings in:
    ``from a import b`` gives ``a.b`` (resolved to a module or not later)."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if isinstance(node, ast.ImportFrom):
        base = node.module or ""
        if node.level:
            package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
            package = package[: len(package) - node.level + 1]
            base = ".".join([*package, *([base] if base else [])])
        return [f"{base}.{alias.name}" for alias in node.names]
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute | ast.Name)
        and (node.func.attr if isinstance(node.func, ast.Attribute) else node.func.id)
        == "import_module"
        and node.args
        and isinstance(node.args[0], ast.Constant)
        and isinstance(node.args[0].value, str)
    ):
        return [node.args[0].value]
    return []


def _resolve(name: str, modules: Mapping[str, Path]) -> str:
    """The longest prefix of ``name`` that is one of the modules (``name`` itself if none)."""
    parts = name.split(".")
    for end in range(len(parts), 0, -1):
        if ".".join(parts[:end]) in modules:
            return ".".join(parts[:end])
    return name


def _nodes(tree: ast.AST, expressions: bool) -> Iterator[ast.AST]:
    """The nodes that may import: every node when ``expressions`` (an ``import_module`` call can
    stand anywhere), else the statements only (imports inside functions, classes, branches
    included) -- the generated modules' huge expressions are not walked."""
    if expressions:
        yield from ast.walk(tree)
        return
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        stack.extend(
            child
            for child in ast.iter_child_nodes(node)
            if isinstance(child, ast.stmt | ast.excepthandler | ast.match_case)
        )


@functools.cache
def _imports() -> tuple[Import, ...]:
    """Every import of every module of the three packages, to anything (numpy included)."""
    modules = _modules()
    edges = []
    for module, path in modules.items():
        source = path.read_text(encoding="utf-8")
        for node in _nodes(ast.parse(source, str(path)), "import_module" in source):
            for name in _imported_names(module, path, node):
                target = _resolve(name, modules)
                if target != module:
                    where = f"{path.relative_to(ROOT).as_posix()}:{getattr(node, 'lineno', 0)}"
                    edges.append(Import(module, target, where))
    return tuple(edges)


def _within(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def _offending(source: str, target: str) -> list[str]:
    """Each import from a module within ``source`` of a module within ``target``, as text."""
    return [
        str(edge)
        for edge in _imports()
        if _within(edge.source, source) and _within(edge.target, target)
    ]


def _cycles(edges: Sequence[Import]) -> list[list[Import]]:
    """One circle of imports per strongly connected component of the graph (Tarjan's)."""
    graph: dict[str, dict[str, Import]] = {}
    for edge in edges:
        graph.setdefault(edge.source, {}).setdefault(edge.target, edge)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    components: list[set[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in graph.get(node, {}):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = set()
            while True:
                member = stack.pop()
                component.add(member)
                if member == node:
                    break
            if len(component) > 1:
                components.append(component)

    for node in sorted(graph):
        if node not in index:
            visit(node)
    circles = []
    for component in components:
        start = min(component)
        paths: dict[str, list[Import]] = {start: []}
        queue = [start]
        while queue:  # the shortest way from start back to it, within the component
            node = queue.pop(0)
            for nxt, edge in sorted(graph.get(node, {}).items()):
                if nxt == start:
                    circles.append([*paths[node], edge])
                    queue = []
                    break
                if nxt in component and nxt not in paths:
                    paths[nxt] = [*paths[node], edge]
                    queue.append(nxt)
    return circles


def test_the_import_graph_has_no_circle() -> None:
    """No module imports, even inside a function, one that imports it back, directly or not."""
    modules = _modules()
    circles = _cycles([e for e in _imports() if e.target in modules])
    text = "\n".join(
        " -> ".join([circle[0].source, *(f"{e.target} ({e.where})" for e in circle)])
        for circle in circles
    )
    assert not circles, f"import circles:\n{text}"


def test_the_engine_knows_nothing_of_the_robot() -> None:
    bad = _offending("rpr3gen_derive.codegen", "rpr3gen_derive.planar")
    assert not bad, "the generic engine imports the robot's derivation:\n" + "\n".join(bad)


def test_the_backends_do_not_import_the_renderer() -> None:
    bad = _offending("rpr3gen_derive.codegen.backends", "rpr3gen_derive.codegen.render")
    assert not bad, "a backend imports the engine that drives it:\n" + "\n".join(bad)


def test_derivation_and_generated_code_do_not_import_the_runtime() -> None:
    bad = [
        *_offending("rpr3gen_derive", "rpr3gen"),
        *_offending("rpr3gen_generated", "rpr3gen"),
        *_offending("rpr3gen_generated", "rpr3gen_derive"),
    ]
    assert not bad, "an import against the layers:\n" + "\n".join(bad)


def _is_command(module: str) -> bool:
    """The commands layer: ``rpr3gen.cli``, its ``rpr3gen.cli_*`` helpers, ``rpr3gen.commands``."""
    return module.startswith(("rpr3gen.cli", "rpr3gen.commands")) and (
        module.split(".")[1] in ("cli", "commands") or module.split(".")[1].startswith("cli_")
    )


def test_the_runtime_does_not_import_the_commands() -> None:
    bad = [
        str(edge)
        for edge in _imports()
        if _within(edge.source, "rpr3gen")
        and not _is_command(edge.source)
        and _is_command(edge.target)
    ]
    assert not bad, "a runtime module imports the command line:\n" + "\n".join(bad)


def test_the_graph_is_read() -> None:
    """The scan sees what is there (so the tests above cannot pass by reading nothing)."""
    edges = {(e.source, e.target) for e in _imports()}
    assert ("rpr3gen.backends", "rpr3gen.model") in edges
    assert ("rpr3gen_derive.codegen.render", "rpr3gen_derive.codegen.backends.c") in edges
    assert any(_is_command(e.source) for e in _imports())
    sample = [Import("a", "b", "a.py:1"), Import("b", "c", "b.py:2"), Import("c", "a", "c.py:3")]
    assert [[str(e) for e in c] for c in _cycles(sample)] == [
        ["a.py:1: a imports b", "b.py:2: b imports c", "c.py:3: c imports a"]
    ]


# -- docs/architecture.md names every package, top folder and command -----------------------------

ARCHITECTURE = ROOT / "docs" / "architecture.md"


def _packages() -> list[tuple[str, str]]:
    """Each package folder of the runtime and the derivation: (its path, its dotted name)."""
    found = []
    for package, root in PACKAGES.items():
        if package == "rpr3gen_generated":  # one folder per variant, described as a whole
            continue
        for init in sorted(root.rglob("__init__.py")):
            folder = init.parent
            if "__pycache__" not in folder.parts and folder != root:
                dotted = ".".join([package, *folder.relative_to(root).parts])
                found.append((folder.relative_to(ROOT).as_posix(), dotted))
    return found


def _top_folders() -> list[str]:
    """The repository's tracked top folders (hidden ones aside)."""
    result = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=False
    )
    if result.returncode != 0:
        pytest.skip("not a git checkout")
    names = {path.split("/")[0] for path in result.stdout.split("\0") if "/" in path}
    return sorted(name for name in names if not name.startswith("."))


def _commands() -> list[str]:
    """The CLI's subcommands, from argparse's refusal of an unknown one, asked of the ``rpr3gen``
    console script's entry point (whatever module builds the parser)."""
    code = (
        "import sys; from importlib.metadata import entry_points\n"
        "(script,) = entry_points(group='console_scripts', name='rpr3gen')\n"
        "sys.argv = ['rpr3gen', 'no-such-command']; sys.exit(script.load()())\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    found = re.search(r"invalid choice: .*?\(choose from (.+?)\)", result.stderr)
    assert found, result.stderr
    return [name.strip().strip("'\"") for name in found.group(1).split(",")]


def test_the_architecture_page_names_every_package_and_folder() -> None:
    text = ARCHITECTURE.read_text(encoding="utf-8")
    folders = [f"{name}/" for name in _top_folders()]
    assert {"derive/", "generated/", "src/", "tests/"} <= set(folders)
    missing = [f for f in folders if f"`{f}" not in text]
    missing += [
        f"{path}/ ({dotted})"
        for path, dotted in _packages()
        if not any(f"`{path}{end}" in text for end in "/`") and dotted not in text
    ]
    assert "`src/rpr3gen/`" in text
    assert not missing, f"docs/architecture.md does not mention: {', '.join(missing)}"


def test_the_architecture_page_names_every_command() -> None:
    commands = _commands()
    assert {"simulate", "generate"} <= set(commands)
    text = ARCHITECTURE.read_text(encoding="utf-8")
    missing = [c for c in commands if not re.search(rf"`(rpr3gen )?{re.escape(c)}`", text)]
    assert not missing, f"docs/architecture.md does not mention the commands: {missing}"


def test_the_mkdocs_nav_holds_the_architecture_page() -> None:
    assert "architecture.md" in (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
