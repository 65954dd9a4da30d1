"""The generated C as a package: each variant folder is a CMake project (a library, install
rules, the exported target ``rpr3gen::<variant>``) with a pkg-config file, which a project
outside rpr3gen uses by ``find_package`` after an install, by ``add_subdirectory``, or through
pkg-config. The builds need ``cmake`` (and ``pkg-config``) and are skipped without them.

The outside program is ``tests/package_consumer.c``: it reads the parameters as ``rpr3gen
params`` prints them, evaluates the inverse dynamics at one sample and prints the outputs, which
must be the NumPy backend's.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from rpr3gen_derive.codegen.backends.c import package

import rpr3gen
from rpr3gen import manifest
from rpr3gen.model import Model

VARIANTS = ("revolute", "prismatic")
CONSUMER = Path(__file__).resolve().with_name("package_consumer.c")
Q, QD, QDD = (0.01, -0.02, 0.1), (0.1, 0.2, -0.3), (1.0, -0.5, 2.0)  # as in package_consumer.c


def _tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        pytest.skip(f"{name} is not installed")
    return path


def _run(command: list[str | Path], stdin: str | None = None, **kwargs: object) -> str:
    result = subprocess.run(
        [str(c) for c in command], input=stdin, capture_output=True, text=True, check=False,
        **kwargs,  # type: ignore[arg-type]
    )  # fmt: skip
    assert result.returncode == 0, f"{command}\n{result.stdout}\n{result.stderr}"
    return result.stdout


def _model(actuation: str) -> Model:
    paper = rpr3gen.load_model()
    return Model(name="paper", actuation=actuation, params=paper.params, source="<test>")


def _params(actuation: str) -> str:
    """The paper robot's parameters as ``rpr3gen params`` prints them."""
    names = manifest.load(actuation).param_names
    values = _model(actuation).vector(names)
    return "".join(f"{n} {float(v)!r}\n" for n, v in zip(names, values, strict=True))


def _check(stdout: str, actuation: str, repo_root: Path) -> list[str]:
    """The consumer's output is the variant's, with the NumPy backend's values; returns the
    lines after the outputs."""
    lines = stdout.splitlines()
    data = json.loads((repo_root / "generated" / actuation / "manifest.json").read_text())
    assert lines[0].split() == [actuation, data["source_hash"], "0"]
    count = len(rpr3gen.OUTPUT_NAMES)
    rows = [line.split() for line in lines[1 : 1 + count]]
    assert [name for name, _ in rows] == list(rpr3gen.OUTPUT_NAMES)
    got = np.array([float(value) for _, value in rows])
    q, qd, qdd = (np.array([v]) for v in (Q, QD, QDD))
    out = rpr3gen.inverse_dynamics(_model(actuation), q, qd, qdd)
    want = np.array([out[name][0] for name in rpr3gen.OUTPUT_NAMES])
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    return lines[1 + count :]


def _project(folder: Path, body: str) -> Path:
    """A CMake project of the consumer, ``body`` saying how it gets the package."""
    folder.mkdir(parents=True)
    shutil.copy(CONSUMER, folder / CONSUMER.name)
    (folder / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.14)\n"
        "project(consumer LANGUAGES C)\n"
        f"add_executable(consumer {CONSUMER.name})\n"
        f"{body}\n"
    )
    return folder


def _build(cmake: str, source: Path, build: Path, *options: str) -> None:
    _run([cmake, "-S", source, "-B", build, "-DCMAKE_BUILD_TYPE=Debug", *options])
    _run([cmake, "--build", build])


def test_every_variant_folder_is_a_package(repo_root: Path) -> None:
    """Whatever variants the engine writes, each has its CMake project and pkg-config file,
    with the generated files' header, named in its manifest."""
    folders = sorted(p.parent for p in (repo_root / "generated").glob("*/manifest.json"))
    assert set(VARIANTS) <= {f.name for f in folders}  # and any variant added later
    for folder in folders:
        data = json.loads((folder / "manifest.json").read_text())
        pc = f"rpr3gen_{folder.name}.pc.in"
        assert data["files"]["c_cmake"] == "CMakeLists.txt"
        assert data["files"]["c_pkgconfig"] == pc
        for name in ("CMakeLists.txt", pc):
            head = (folder / name).read_text().splitlines()[:2]
            assert "do not edit" in head[0], (folder, name)
            assert head[1] == f"# Source hash: {data['source_hash']}", (folder, name)
        cmake = (folder / "CMakeLists.txt").read_text()
        assert f"add_library(rpr3gen::{folder.name} ALIAS rpr3gen_{folder.name})" in cmake
        assert f"EXPORT_NAME {folder.name}" in cmake


def test_the_package_version_is_rpr3gens() -> None:
    assert rpr3gen.__version__ == package.VERSION


@pytest.fixture(scope="module", params=VARIANTS)
def installed(
    request: pytest.FixtureRequest, repo_root: Path, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, Path, Path]:
    """A variant configured, built (Debug: a quick build) and installed to a temporary prefix
    by its own CMakeLists.txt: (variant, build folder, prefix)."""
    cmake = _tool("cmake")
    actuation = request.param
    source = repo_root / "generated" / actuation
    before = sorted(p.name for p in source.iterdir() if p.name != "__pycache__")
    work = tmp_path_factory.mktemp(f"package-{actuation}")
    build, prefix = work / "build", work / "prefix"
    _build(cmake, source, build, f"-DCMAKE_INSTALL_PREFIX={prefix}")
    _run([cmake, "--install", build])
    assert sorted(p.name for p in source.iterdir() if p.name != "__pycache__") == before
    return actuation, build, prefix


@pytest.mark.slow
def test_find_package_after_install(
    installed: tuple[str, Path, Path], repo_root: Path, tmp_path: Path
) -> None:
    actuation, _, prefix = installed
    package_name = f"rpr3gen_{actuation}"
    assert (prefix / "include" / "rpr3gen" / actuation / "rpr3.h").is_file()
    (library,) = prefix.glob(f"*/lib{package_name}.a")
    libdir = library.parent.name
    assert (prefix / libdir / "cmake" / package_name / f"{package_name}Config.cmake").is_file()
    assert (prefix / libdir / "pkgconfig" / f"{package_name}.pc").is_file()
    source = _project(
        tmp_path / "consumer",
        f"find_package({package_name} {rpr3gen.__version__} REQUIRED)\n"
        f"target_link_libraries(consumer PRIVATE rpr3gen::{actuation})\n"
        "target_compile_definitions(consumer PRIVATE\n"
        f'  EXPECTED_SOURCE_HASH="${{{package_name}_SOURCE_HASH}}")',
    )
    cmake = _tool("cmake")
    _build(cmake, source, tmp_path / "build", f"-DCMAKE_PREFIX_PATH={prefix}")
    stdout = _run([tmp_path / "build" / "consumer"], stdin=_params(actuation))
    assert _check(stdout, actuation, repo_root) == ["package source hash matches"]


@pytest.mark.slow
def test_pkg_config_after_install_elsewhere(
    installed: tuple[str, Path, Path], repo_root: Path, tmp_path: Path
) -> None:
    """Installed to a prefix chosen at install time (not the configured one): the .pc file
    finds its folders from where it is."""
    pkg_config = _tool("pkg-config")
    cc = _tool("cc")
    actuation, build, _ = installed
    package_name = f"rpr3gen_{actuation}"
    prefix = tmp_path / "elsewhere"
    _run([_tool("cmake"), "--install", build, "--prefix", prefix])
    (pc_dir,) = prefix.glob("*/pkgconfig")
    env = dict(os.environ, PKG_CONFIG_PATH=str(pc_dir))
    assert _run([pkg_config, "--modversion", package_name], env=env).strip() == (
        rpr3gen.__version__
    )
    data = json.loads((repo_root / "generated" / actuation / "manifest.json").read_text())
    source_hash = _run([pkg_config, "--variable=source_hash", package_name], env=env).strip()
    assert source_hash == data["source_hash"]
    flags = _run([pkg_config, "--cflags", "--libs", package_name], env=env).split()
    assert any(f.startswith("-I") and str(prefix) in f for f in flags)
    exe = tmp_path / "consumer"
    _run([cc, "-std=c99", "-Wall", "-Werror", CONSUMER, "-o", exe, *flags])
    assert _check(_run([exe], stdin=_params(actuation)), actuation, repo_root) == []


@pytest.mark.slow
def test_add_subdirectory_without_installing(repo_root: Path, tmp_path: Path) -> None:
    cmake = _tool("cmake")
    generated = (repo_root / "generated" / "revolute").as_posix()
    source = _project(
        tmp_path / "consumer",
        f'add_subdirectory("{generated}" rpr3gen)\n'
        "target_link_libraries(consumer PRIVATE rpr3gen::revolute)",
    )
    _build(cmake, source, tmp_path / "build")
    cache = (tmp_path / "build" / "CMakeCache.txt").read_text()
    assert "RPR3GEN_REVOLUTE_INSTALL:BOOL=OFF" in cache  # a subproject installs nothing itself
    stdout = _run([tmp_path / "build" / "consumer"], stdin=_params("revolute"))
    assert _check(stdout, "revolute", repo_root) == []


@pytest.mark.parametrize(
    ("path", "start", "end"),
    [
        ("examples/control_loop/Makefile", "CFLAGS ?=", "VARIANTS ="),
        ("generated/revolute/CMakeLists.txt", "PRIVATE -fno-math-errno", "endif()"),
    ],
)
def test_every_speed_build_takes_the_runtimes_flags(
    repo_root: Path, path: str, start: str, end: str
) -> None:
    """The example's Makefile and the C package's NATIVE option repeat the runtime's flags
    (``rpr3gen.cbackend``: its first set, then the two it always passes that change no value);
    a flag added to one place only would make their timings differ from the runtime's."""
    from rpr3gen import cbackend

    text = (repo_root / path).read_text()
    block = text[text.index(start) : text.index(end, text.index(start))]
    flags = set(block.replace("\\", " ").replace(")", " ").split())
    wanted = {*cbackend.EXTRA_FLAGS[0], "-fno-math-errno", "-fno-trapping-math"}
    assert wanted <= flags, sorted(wanted - flags)
