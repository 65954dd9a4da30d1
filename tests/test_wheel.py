"""A wheel built from the repository runs `rpr3gen simulate` in a fresh venv, no source tree, and
the runtime imports nothing that the wheel does not declare."""

from __future__ import annotations

import ast
import importlib.metadata
import re
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest
from packaging.requirements import Requirement

#: Not part of a build: environments, caches, build products.
_NOT_SOURCES = shutil.ignore_patterns(
    ".git", ".venv", "build", "dist", "*.egg-info", "__pycache__", ".*_cache", ".hypothesis"
)
#: rpr3gen's own packages: the runtime, the generated code, and the derivation (imported only
#: by `rpr3gen generate`, which names the `derive` extra when it is missing).
OWN = {"rpr3gen", "rpr3gen_generated", "rpr3gen_derive"}
#: The extras whose modules the runtime may import, each only where an ImportError is caught
#: (``video``: imageio-ffmpeg's ffmpeg for MP4 movies, rpr3gen.animation; ``toppra``: TOPP-RA for
#: rpr3gen.retime, rpr3gen.retiming.topp).
RUNTIME_EXTRAS = ("video", "toppra", "casadi", "jax")

#: Run in the fresh venv: every requirement the installed wheel declares is met, by version.
_REQUIREMENTS_MET = """
import importlib.metadata as md
from packaging.requirements import Requirement
for text in md.requires("rpr3gen") or []:
    req = Requirement(text)
    if req.marker is not None and not req.marker.evaluate({"extra": ""}):
        continue
    version = md.version(req.name)
    assert req.specifier.contains(version, prereleases=True), (text, version)
print("met")
"""


def _normal(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _declared(extra: str = "") -> set[str]:
    """The distributions rpr3gen's runtime may import: its requirements, with their extras'
    (``extra``: those that rpr3gen's own extra of that name adds instead)."""
    names = set()
    for text in importlib.metadata.requires("rpr3gen") or []:
        req = Requirement(text)
        required = req.marker is None or req.marker.evaluate({"extra": ""})
        if extra and (required or not req.marker or not req.marker.evaluate({"extra": extra})):
            continue
        if not extra and not required:
            continue
        names.add(_normal(req.name))
        for wanted in req.extras:
            for sub in importlib.metadata.requires(req.name) or []:
                inner = Requirement(sub)  # what the extra adds: needed with it, not without
                with_it = inner.marker is not None and inner.marker.evaluate({"extra": wanted})
                if with_it and not inner.marker.evaluate({"extra": ""}):
                    names.add(_normal(inner.name))
    return names


def _imports(root: Path, guarded: bool = False) -> set[str]:
    """Top-level names of every absolute import under ``root``, at any depth of the code
    (``guarded``: only those inside a ``try`` that catches ImportError)."""
    found = set()
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        nodes = ast.walk(tree)
        if guarded:
            tries = [n for n in ast.walk(tree) if isinstance(n, ast.Try) and _catches_import(n)]
            nodes = (inner for t in tries for stmt in t.body for inner in ast.walk(stmt))
        for node in nodes:
            if isinstance(node, ast.Import):
                found.update(alias.name.split(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
    return found


def _catches_import(node: ast.Try) -> bool:
    caught = set()
    for handler in node.handlers:
        types = handler.type.elts if isinstance(handler.type, ast.Tuple) else [handler.type]
        caught |= {t.id for t in types if isinstance(t, ast.Name)}
    return bool(caught & {"ImportError", "ModuleNotFoundError"})


def test_the_runtime_imports_only_what_it_declares(repo_root: Path) -> None:
    """Every module src/rpr3gen and generated/ import, at the top or inside a function, is the
    standard library's, rpr3gen's own, or from a distribution the wheel requires; or from one
    of :data:`RUNTIME_EXTRAS`, imported only where an ImportError is caught (the runtime works
    without it)."""
    roots = (repo_root / "src" / "rpr3gen", repo_root / "generated")
    modules = _imports(roots[0]) | _imports(roots[1])
    guarded = _imports(roots[0], guarded=True) | _imports(roots[1], guarded=True)
    assert {"numpy", "scipy", "matplotlib"} <= modules  # the walk sees them
    third_party = modules - set(sys.stdlib_module_names) - OWN
    providers = importlib.metadata.packages_distributions()
    optional = set().union(*(_declared(extra) for extra in RUNTIME_EXTRAS))
    assert optional, f"rpr3gen's extras {RUNTIME_EXTRAS} add nothing"

    def allowed(module: str) -> bool:
        dists = {_normal(d) for d in providers.get(module, [])}
        return bool(dists & _declared()) or (module in guarded and bool(dists & optional))

    undeclared = {
        module: providers.get(module, ["(not installed)"])
        for module in sorted(third_party)
        if not allowed(module)
    }
    assert not undeclared, f"imported but not in pyproject.toml's dependencies: {undeclared}"


@pytest.mark.slow
def test_wheel_runs_simulate_in_a_fresh_venv(repo_root: Path, tmp_path: Path) -> None:
    # Built from a copy of the sources: the build writes no build/ into the checkout, and no
    # stale build/lib of an earlier build can slip into the wheel.
    sources = tmp_path / "sources"
    shutil.copytree(repo_root, sources, ignore=_NOT_SOURCES, symlinks=True)
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(sources)],
        check=True,
        capture_output=True,
    )
    (wheel,) = wheels.glob("rpr3gen-*.whl")
    # A venv without pip of its own, where this environment's pip installs the wheel alone. Its
    # dependencies are this environment's, seen through a .pth file: installing numpy, SciPy,
    # matplotlib, Dask and pyarrow anew would write 440 MB each run. That the wheel declares all
    # it needs is test_the_runtime_imports_only_what_it_declares, and that they are met here by
    # version is checked in the venv below.
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    paths = {"base": str(env_dir), "platbase": str(env_dir)}
    site = Path(sysconfig.get_path("purelib", vars=paths))
    assert site.is_dir()
    (site / "dependencies.pth").write_text(sysconfig.get_path("purelib") + "\n")
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
         "--no-compile", str(wheel)],
        check=True, capture_output=True,
    )  # fmt: skip
    work = tmp_path / "elsewhere"
    work.mkdir()
    met = subprocess.run(
        [str(python), "-c", _REQUIREMENTS_MET], cwd=work, capture_output=True, text=True
    )
    assert met.stdout.strip() == "met", met.stderr
    result = subprocess.run(
        [str(env_dir / "bin" / "rpr3gen"), "simulate", "--trajectory", "rectilinear",
         "--out", "r.csv", "--plots", "figs"],
        cwd=work, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert (work / "r.csv").read_text().startswith("t,x,y,phi,phi10_A")
    assert (work / "figs" / "rectilinear_m10.png").is_file()
    where = subprocess.run(
        [str(python), "-c",
         "import rpr3gen_generated, rpr3gen; print(rpr3gen_generated.__file__, rpr3gen.__file__)"],
        cwd=work, capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    assert str(repo_root) not in where
    assert all(path.startswith(str(site)) for path in where.split()), where


def test_every_package_folder_is_in_the_wheel(repo_root: Path) -> None:
    """Each folder with an ``__init__.py`` under the three package roots is listed in
    ``pyproject.toml``'s ``packages`` (a new subpackage left out installs editable, yet its
    wheel would lack it)."""
    import tomllib

    setup = tomllib.loads((repo_root / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setup["packages"])
    found = set()
    for name, folder in setup["package-dir"].items():
        for init in (repo_root / folder).rglob("__init__.py"):
            parts = init.parent.relative_to(repo_root / folder).parts
            if "__pycache__" not in parts:
                found.add(".".join((name, *parts)))
    assert found - listed == set(), "not in pyproject.toml's packages"
    assert listed - found == set(), "listed but not a package"
