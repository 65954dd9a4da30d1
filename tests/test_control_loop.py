"""Smoke tests of examples/control_loop: the C programs and the Python loop, 0.4 s runs.

The loop is closed on quantised encoders only. The bounds come from what the example measures
(examples/control_loop/README.md): the plant's masses and inertias 3-5 % off leave a tracking
error of 0.17-0.18 mm (the same with exact sensors: the nominal model's weight is wrong, and the
PD correction settles against it); the encoders add at most 0.012 mm (exact plant, encoders). A
wrong sign, Jacobian or solve, a lost velocity estimate, would show as millimetres or an
unstable run. The pose estimate from the encoders is within about one count's worth: 14 um per
count (revolute, 2^17 counts/rev, legs about 0.3 m) or 1 um (prismatic). Latencies are checked
for their format only.
"""

from __future__ import annotations

import contextlib
import io
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rpr3gen.cli import main

CASES = [
    ("revolute", "rectilinear"),
    ("revolute", "rotation"),
    ("prismatic", "rectilinear"),
    ("prismatic", "rotation"),
]
ESTIMATE_BOUND_MM = {"revolute": 0.05, "prismatic": 0.005}


def _report(text: str) -> dict[str, float]:
    """The numbers of the report that the tests check."""
    numbers = {}
    for label in ("after 50 ms", "overall"):
        m = re.search(
            rf"tracking error {label}: position rms ([\d.]+) mm, max ([\d.]+) mm; "
            r"angle rms ([\d.]+) mrad, max ([\d.]+) mrad",
            text,
        )
        assert m, text
        keys = ("pos_rms", "pos_max", "ang_rms", "ang_max")
        for key, value in zip(keys, m.groups(), strict=True):
            numbers[f"{label} {key}"] = float(value)
    m = re.search(r"estimate error: pose max ([\d.]+) mm, ([\d.]+) mrad; velocity rms", text)
    assert m, text
    numbers["estimate mm"], numbers["estimate mrad"] = map(float, m.groups())
    assert "failed calls: forward kinematics 0, jacobian 0, dynamics 0" in text, text
    for label in ("forward kinematics", "rest of the tick", "whole tick"):
        pattern = rf"latency {label}: p50 [\d.]+ (ns|us), p99 [\d.]+ \1, max [\d.]+ \1\n"
        assert re.search(pattern, text), text
    return numbers


def _check_tracking(text: str, actuation: str, trajectory: str) -> dict[str, float]:
    assert f"400 ticks at 1000 Hz, {actuation} actuation" in text, text
    assert text.startswith(f"trajectory {trajectory},"), text
    numbers = _report(text)
    assert numbers["after 50 ms pos_max"] < 0.3, text  # measured 0.174-0.180
    assert numbers["after 50 ms ang_max"] < 0.3, text  # measured 0.006-0.083
    assert numbers["overall pos_max"] < 0.3, text  # starts on the trajectory
    assert numbers["estimate mm"] < ESTIMATE_BOUND_MM[actuation], text
    return numbers


@pytest.fixture(scope="module", params=["make", "cmake"])
def c_build(
    request: pytest.FixtureRequest, repo_root: Path, tmp_path_factory: pytest.TempPathFactory
) -> Path:
    """Both C programs, built with -Werror by the Makefile or by CMakeLists.txt (each variant
    through its CMake package), and the paper robot's parameter file, in one folder."""
    work = tmp_path_factory.mktemp(f"control_loop_{request.param}")
    example = repo_root / "examples" / "control_loop"
    warnings = "-Wall -Wextra -pedantic -Werror"
    if request.param == "make":
        for name in ("Makefile", "control_loop.c"):
            shutil.copy(example / name, work / name)
        flags = f"CFLAGS=-std=c99 -O2 {warnings}"
        generated = f"GENERATED={repo_root / 'generated'}"
        commands = [["make", "-s", generated, flags]]
    else:
        cmake = shutil.which("cmake")
        if cmake is None:
            pytest.skip("cmake is not installed")
        # Debug (no optimisation): the build is what is tested here, the make build is -O2.
        configure = [cmake, "-S", str(example), "-B", str(work), "-DCMAKE_BUILD_TYPE=Debug",
                     f"-DCMAKE_C_FLAGS={warnings}"]  # fmt: skip
        commands = [configure, [cmake, "--build", str(work)]]
    for command in commands:
        result = subprocess.run(command, cwd=work, capture_output=True, text=True, check=False)
        assert result.returncode == 0, result.stdout + result.stderr
        assert result.stderr == "", result.stderr  # no warnings either
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["params"]) == 0
    (work / "paper.params").write_text(out.getvalue())
    return work


def _run_c(work: Path, actuation: str, *args: str) -> str:
    result = subprocess.run(
        [f"./control_loop_{actuation}", *args],
        cwd=work, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def _run_python(repo_root: Path, actuation: str, *args: str, cwd: Path | None = None) -> str:
    script = repo_root / "examples" / "control_loop" / "control_loop.py"
    result = subprocess.run(
        [sys.executable, str(script), "--actuation", actuation, *args],
        cwd=cwd, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


@pytest.mark.parametrize(("actuation", "trajectory"), CASES)
def test_c_control_loop(c_build: Path, actuation: str, trajectory: str) -> None:
    text = _run_c(c_build, actuation, "--trajectory", trajectory, "--seconds", "0.4")
    _check_tracking(text, actuation, trajectory)


@pytest.mark.parametrize(("actuation", "trajectory"), CASES)
def test_python_control_loop(repo_root: Path, actuation: str, trajectory: str) -> None:
    text = _run_python(repo_root, actuation, "--trajectory", trajectory, "--seconds", "0.4")
    _check_tracking(text, actuation, trajectory)


def test_c_and_python_close_the_same_loop(repo_root: Path, c_build: Path) -> None:
    c = _report(_run_c(c_build, "revolute", "--trajectory", "rotation", "--seconds", "0.4"))
    py = _report(_run_python(repo_root, "revolute", "--trajectory", "rotation", "--seconds", "0.4"))
    assert c == pytest.approx(py, abs=2e-4)  # same plant, sensors and law; 4 decimals printed


@pytest.mark.parametrize(
    "args",
    [
        ("rotation", "--seconds", "0.4"),
        ("--trajectory", "rotation", "--seconds=0.4"),
        ("--params", "paper.params", "--seconds", "0.4", "--offset", "0", "rotation"),
    ],
)
def test_c_and_python_take_the_same_arguments(
    repo_root: Path, c_build: Path, args: tuple[str, ...]
) -> None:
    """Issue 21: the same command line runs either program (the trajectory positional or as
    --trajectory, the model's numbers from --params), and both report the same loop."""
    c = _run_c(c_build, "revolute", *args)
    py = _run_python(repo_root, "revolute", *args, cwd=c_build)
    assert (
        c.splitlines()[0]
        == py.splitlines()[0]
        == (
            "trajectory rotation, 400 ticks at 1000 Hz, revolute actuation, "
            "start offset (0.000, 0.000) mm"
        )
    )
    assert _report(c) == pytest.approx(_report(py), abs=2e-4)


def test_a_bad_argument_is_refused_by_both(repo_root: Path, c_build: Path) -> None:
    script = repo_root / "examples" / "control_loop" / "control_loop.py"
    for command in (["./control_loop_revolute"], [sys.executable, str(script)]):
        result = subprocess.run(
            [*command, "--seconds", "soon"], cwd=c_build, capture_output=True, text=True
        )
        assert result.returncode == 2, result.stdout + result.stderr
        assert "usage:" in result.stderr


def test_c_control_loop_start_offset(repo_root: Path, c_build: Path) -> None:
    """The plant starts 1 mm off in x and -1 mm in y; the controller's first reference is home.

    The example's README explains the largest error this prints: the start itself.
    """
    text = _run_c(c_build, "revolute", "rectilinear", "--seconds", "0.4", "--offset", "1")
    assert "start offset (1.000, -1.000) mm" in text, text
    numbers = _report(text)  # no failed forward kinematics from 1.4 mm off
    assert numbers["overall pos_max"] == pytest.approx(2**0.5, abs=0.01), text  # the offset
    assert numbers["estimate mm"] < ESTIMATE_BOUND_MM["revolute"], text
    readme = (repo_root / "examples" / "control_loop" / "README.md").read_text(encoding="utf-8")
    assert "starts 1 mm off in x" in readme
    assert f"largest position error, {numbers['overall pos_max']:.4f} mm" in readme


def test_the_ticks_alternate_between_the_split_and_the_whole_measure(
    repo_root: Path, c_build: Path
) -> None:
    """The first tick is split at the end of its forward kinematics (a clock read inside it), the
    second is timed whole (no clock read inside): one tick gives the two parts and no whole tick,
    two ticks give each measure once (p50 = p99 = max, a single value)."""
    for run in (
        lambda *a: _run_c(c_build, "prismatic", *a),
        lambda *a: _run_python(repo_root, "prismatic", *a, cwd=c_build),
    ):
        one = run("rotation", "--seconds", "0.001")
        assert "latency whole tick: no tick measured" in one, one
        for label in ("forward kinematics", "rest of the tick"):
            assert re.search(rf"latency {label}: p50 [\d.]+ (ns|us), p99", one), one
        two = run("rotation", "--seconds", "0.002")
        for label in ("forward kinematics", "rest of the tick", "whole tick"):
            m = re.search(
                rf"latency {label}: p50 ([\d.]+) (ns|us), p99 ([\d.]+) \2, max ([\d.]+)", two
            )
            assert m, two
            assert m.group(1) == m.group(3) == m.group(4), two
