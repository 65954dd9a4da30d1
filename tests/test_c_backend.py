"""The generated C and the `c` backend: agreement, ABI behaviour, build cache, threads (the
batch split across threads gives the same bits as one thread)."""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import newton_euler as ne
import numpy as np
import pytest

import rpr3gen
from rpr3gen import cbackend, manifest
from rpr3gen.model import Model

ACTUATIONS = ("revolute", "prismatic")
T = np.linspace(0.0, 2.0, 201)


def _model(params: dict[str, float], actuation: str) -> Model:
    return Model(name="test", actuation=actuation, params=params, source="<test>")


def _cases():
    for seed in range(12):
        robot, q, qd, qdd = ne.random_case(seed, T)
        yield seed, _model(robot["params"], ACTUATIONS[seed % 2]), q, qd, qdd
    for actuation in ACTUATIONS:
        for kind in ("rotation", "rectilinear"):
            _, q, qd, qdd = ne.paper_motion(kind, 301, 3.0)
            yield kind, _model(ne.paper_params(), actuation), q, qd, qdd


@pytest.mark.parametrize("case", list(_cases()), ids=lambda c: f"{c[0]}-{c[1].actuation}")
def test_c_equals_numpy_to_1e_12(case) -> None:
    _, model, q, qd, qdd = case
    a = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend="numpy")
    b = rpr3gen.inverse_dynamics(model, q, qd, qdd, backend="c")
    for family in ne.FAMILIES:
        names = [f"{family}_{leg}" for leg in "ABC"]
        scale = max(np.max(np.abs(a[n])) for n in names)
        for n in names:
            error = np.max(np.abs(a[n] - b[n]))
            assert error <= 1e-12 * max(scale, 1e-300), (n, error, scale)


def _ptr(array: np.ndarray) -> ctypes.c_void_p:
    return ctypes.c_void_p(array.ctypes.data)


def _library(actuation: str):
    """The compiled library of a variant, and its parameter names."""
    variant = manifest.load(actuation)
    return cbackend.library(variant).cdll, variant.param_names


def _batch(params, q, qd, qdd, actuation: str) -> tuple[np.ndarray, int]:
    """The generated batch over n samples: row-major outputs and the number that failed."""
    lib, _ = _library(actuation)
    q, qd, qdd = (np.ascontiguousarray(a, dtype=np.float64) for a in (q, qd, qdd))
    rows = np.empty((len(q), len(rpr3gen.OUTPUT_NAMES)))
    failed = lib.rpr3_inverse_dynamics_batch(
        _ptr(params), len(q), _ptr(q), _ptr(qd), _ptr(qdd), _ptr(rows)
    )
    return rows, int(failed)


@pytest.mark.usefixtures("optimised_c_builds")
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_single_and_batch_agree_bit_for_bit(actuation: str) -> None:
    _, model, q, qd, qdd = next(c for c in _cases() if c[1].actuation == actuation)
    lib, names = _library(actuation)
    params = np.ascontiguousarray(model.vector(names))
    rows, failed = _batch(params, q, qd, qdd, actuation)
    assert failed == 0
    out = np.empty(rows.shape[1])
    for i in range(len(q)):
        args = [np.ascontiguousarray(a[i]) for a in (q, qd, qdd)]
        assert lib.rpr3_inverse_dynamics(_ptr(params), *map(_ptr, args), _ptr(out)) == 0
        assert out.tobytes() == rows[i].tobytes(), i


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bits, or both NaN (the payload of a NaN depends on its operands' order)."""
    return bool(np.all((a.view(np.int64) == b.view(np.int64)) | (np.isnan(a) & np.isnan(b))))


def _generic_inputs(model: Model, function: manifest.FunctionInfo) -> list[np.ndarray] | None:
    """A function's inputs along a motion in which x, y and phi all move; None if unknown."""
    t = np.linspace(0.0, 3.0, 301)[:, None]
    amplitude, rate = np.array([0.03, 0.025, 0.2]), np.array([2.1, 2.7, 3.6])
    q = amplitude * np.sin(rate * t + [0.0, 0.7, 1.9])
    qd = amplitude * rate * np.cos(rate * t + [0.0, 0.7, 1.9])
    motion = {"q": q, "qd": qd, "qdd": -(rate**2) * q, "qa_dot": np.cos(rate * t),
              "tau": np.sin(rate * t)}  # fmt: skip
    motion["qa"] = rpr3gen.actuator_coordinates(model, q)
    motion["q_near"] = q
    if not all(a.name in motion for a in function.inputs):
        return None
    return [np.ascontiguousarray(motion[a.name]) for a in function.inputs]


@pytest.mark.usefixtures("optimised_c_builds")
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_every_function_single_and_batch_agree_bit_for_bit(actuation: str) -> None:
    """The runtime's library (its flags: gcc's basic-block vectoriser once fused multiply-adds in
    a single call and not in the batch, issue 20), every function, a generic motion."""
    model = _model(ne.paper_params(), actuation)
    checked = []
    for name, function in manifest.load(actuation).functions.items():
        inputs = _generic_inputs(model, function)
        if inputs is None:
            continue
        batch, codes = rpr3gen.evaluate(model, name, inputs, backend="c")
        ev = rpr3gen.SampleEvaluator(model, function=name)
        for i in range(len(inputs[0])):
            for arg, values in zip(function.inputs, inputs, strict=True):
                ev.inputs[arg.name][:] = values[i]
            assert ev() == codes[i], (name, i)
            if codes[i] == 0:
                for out, rows in zip(ev.outputs.values(), batch, strict=False):
                    assert _same_bits(out, rows[i]), (name, i, out, rows[i])
        checked.append(name)
    assert {"inverse_dynamics", "assembly_modes", "forward_kinematics"} <= set(checked)


def _singular_sample(model: Model) -> np.ndarray:
    p = model.params  # platform joint B3 on the base pivot B1: leg B has zero length
    return np.array([p["xB1"] - p["xB3"], p["yB1"] - p["yB3"], 0.0])


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_failure_codes_leave_outputs_untouched(actuation: str) -> None:
    model = _model(ne.paper_params(), actuation)
    lib, names = _library(actuation)
    params = np.ascontiguousarray(model.vector(names))
    zero = np.zeros(3)
    out = np.full(len(rpr3gen.OUTPUT_NAMES), 7.0)
    for bad, code in (
        (np.array([0.0, np.nan, 0.0]), 1),
        (np.array([np.inf, 0.0, 0.0]), 1),
        (_singular_sample(model), 2),
    ):
        assert (
            lib.rpr3_inverse_dynamics(_ptr(params), _ptr(bad), *map(_ptr, (zero, zero, out)))
            == code
        )
        assert np.all(out == 7.0)
    q = np.array([[0.0, 0.0, 0.0], [0.0, np.nan, 0.0], list(_singular_sample(model)), [0.01, 0, 0]])
    z = np.zeros_like(q)
    rows, failed = _batch(params, q, z, z, actuation)
    assert failed == 2
    assert np.isnan(rows[1]).all()
    assert np.isnan(rows[2]).all()
    assert np.isfinite(rows[[0, 3]]).all()


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_generated_c_compiles_without_warnings(
    actuation: str, repo_root: Path, tmp_path: Path
) -> None:
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler is required by the test suite"
    source = repo_root / "generated" / actuation / "rpr3.c"
    result = subprocess.run(
        [cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", "-c", str(source),
         "-o", str(tmp_path / "rpr3.o")],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_generated_c_compiles_without_its_scheduling_attribute(
    actuation: str, repo_root: Path
) -> None:
    # RPR3_SCHEDULED defined empty (a user's opt-out, and what other compilers get): the same
    # source, no warning. That the scheduled kernels give the batch's bits is
    # test_every_function_single_and_batch_agree_bit_for_bit's.
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler is required by the test suite"
    source = repo_root / "generated" / actuation / "rpr3.c"
    assert source.read_text().count("\nRPR3_SCHEDULED\nstatic ") >= 10
    result = subprocess.run(
        [cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-fsyntax-only",
         "-DRPR3_SCHEDULED=", str(source)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""


def test_generated_c_needs_only_math_and_stddef(repo_root: Path) -> None:
    for path in sorted((repo_root / "generated").rglob("rpr3.[ch]")):
        includes = {
            line.split()[1] for line in path.read_text().splitlines() if line.startswith("#include")
        }
        assert includes <= {"<math.h>", "<stddef.h>", '"rpr3.h"'}, (path, includes)
        assert "malloc" not in path.read_text()
        assert "static double" not in path.read_text()  # no hidden state


def test_threads_get_the_same_results() -> None:
    model = rpr3gen.load_model()
    cases = [ne.random_case(seed, T)[1:] for seed in range(4)]
    expected = [rpr3gen.inverse_dynamics(model, *c, backend="c") for c in cases]
    results: dict[tuple[int, int], dict] = {}

    def work(thread: int) -> None:
        for repeat in range(20):
            k = (thread + repeat) % len(cases)
            results[(thread, repeat)] = rpr3gen.inverse_dynamics(model, *cases[k], backend="c")

    threads = [threading.Thread(target=work, args=(t,)) for t in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 120
    for (thread, repeat), out in results.items():
        want = expected[(thread + repeat) % len(cases)]
        for name in rpr3gen.OUTPUT_NAMES:
            assert out[name].tobytes() == want[name].tobytes()


@pytest.mark.usefixtures("quick_c_builds")
def test_build_is_cached_and_rebuilt_when_the_source_changes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("RPR3GEN_CACHE_DIR", str(tmp_path))
    variant = manifest.load("revolute")
    first = cbackend.library_path(variant)
    stamp = first.stat().st_mtime_ns
    assert cbackend.library_path(variant) == first
    assert first.stat().st_mtime_ns == stamp  # reused, not rebuilt
    source, header = cbackend.sources(variant)
    monkeypatch.setattr(
        cbackend, "sources", lambda variant, unit="": (source + b"\n/* changed */\n", header)
    )
    second = cbackend.library_path(variant)
    assert second != first
    assert second.is_file()
    libraries = [first.name, second.name]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        libraries + [f".{name}.lock" for name in libraries]  # no build folder left behind
    )


#: A process that builds the revolute library (at -O0) when told to, and prints its path and
#: the first outputs of one sample through it.
_BUILDER = """
import sys
import numpy as np
import rpr3gen
from rpr3gen import cbackend, manifest
cbackend.CFLAGS = tuple("-O0" if f == "-O3" else f for f in cbackend.CFLAGS)
variant = manifest.load("revolute")
print("ready", flush=True)
assert sys.stdin.readline() == "go\\n"
path = cbackend.library_path(variant)
model = rpr3gen.load_model()
q = np.array([[0.01, -0.02, 0.1]])
out = rpr3gen.inverse_dynamics(model, q, q, q, backend="c")
print(path, out["m10_A"][0].hex(), out["f32z_C"][0].hex(), flush=True)
"""


def test_concurrent_first_builds_compile_once(tmp_path: Path) -> None:
    """Three processes ask for the same library at once in an empty cache (as test workers do):
    one compiles it, the others wait on the lock and load the same file."""
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler is required by the test suite"
    log = tmp_path / "cc.log"
    wrapper = tmp_path / "cc-logged"  # counts the compiler's runs
    wrapper.write_text(f'#!/bin/sh\necho "$@" >> "{log}"\nexec "{cc}" "$@"\n')
    wrapper.chmod(0o755)
    cache = tmp_path / "cache"
    env = dict(os.environ, CC=str(wrapper), RPR3GEN_CACHE_DIR=str(cache))
    pipes = {"stdin": subprocess.PIPE, "stdout": subprocess.PIPE, "stderr": subprocess.PIPE}
    builders = [
        subprocess.Popen([sys.executable, "-c", _BUILDER], text=True, env=env, **pipes)
        for _ in range(3)
    ]
    for p in builders:  # every process is ready (imported, about to build) ...
        assert p.stdout is not None
        assert p.stdout.readline() == "ready\n"
    for p in builders:  # ... before any is told to build
        assert p.stdin is not None
        p.stdin.write("go\n")
        p.stdin.flush()
    results = [p.communicate() for p in builders]
    assert [p.returncode for p in builders] == [0] * 3, [err for _, err in results]
    lines = {out for out, _ in results}
    assert len(lines) == 1  # the same library, the same bits
    (path, *_values) = lines.pop().split()
    assert Path(path).parent == cache
    assert len(log.read_text().splitlines()) == 1  # compiled once
    assert sorted(p.name for p in cache.iterdir()) == sorted(
        [Path(path).name, f".{Path(path).name}.lock"]
    )


def test_missing_compiler_is_one_clear_line(tmp_path: Path) -> None:
    env = {"PATH": "/usr/bin:/bin", "CC": "no-such-cc", "RPR3GEN_CACHE_DIR": str(tmp_path)}
    result = subprocess.run(
        [sys.executable, "-m", "rpr3gen.cli", "simulate", "--backend", "c"],
        capture_output=True, text=True, env=env, check=False,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1
    assert "C compiler" in result.stderr
    assert "Traceback" not in result.stderr


def test_cli_simulate_with_c_backend_matches_numpy(tmp_path: Path) -> None:
    from rpr3gen.cli import main

    assert main(["simulate", "--backend", "c", "--out", str(tmp_path / "c.csv")]) == 0
    assert main(["simulate", "--backend", "numpy", "--out", str(tmp_path / "n.csv")]) == 0
    c = np.loadtxt(tmp_path / "c.csv", delimiter=",", skiprows=1)
    n = np.loadtxt(tmp_path / "n.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(c, n, rtol=1e-12, atol=1e-12)


def test_sample_evaluator_matches_batch() -> None:
    model = rpr3gen.load_model()
    traj = rpr3gen.paper_trajectory("rectilinear", samples=31)
    batch = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd, backend="c")
    for backend in ("c", "numpy"):
        ev = rpr3gen.SampleEvaluator(model, backend=backend)
        for i in range(31):
            out = ev.evaluate(traj.q[i], traj.qd[i], traj.qdd[i])
            for name, k in ev.index.items():
                assert out[k] == pytest.approx(batch[name][i], rel=1e-12, abs=1e-12)
        ev.q[:] = _singular_sample(model)
        before = ev.out.copy()
        assert ev() == 2
        assert np.array_equal(ev.out, before)


def _long_case(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n samples of random motion around the paper's home pose, with rows the batch handles
    apart: a NaN input, a singular pose, and angles past the trig kernels' fast path (2^20)."""
    rng = np.random.default_rng(15)  # poses about the paper's rotation, all valid
    q = np.column_stack(
        [rng.uniform(-0.01, 0.01, n), rng.uniform(-0.01, 0.01, n), rng.uniform(0.0, 1.0, n)]
    )
    qd, qdd = rng.normal(0.0, 0.1, (n, 3)), rng.normal(0.0, 1.0, (n, 3))
    q[5, 1] = np.nan
    q[7] = _singular_sample(_model(ne.paper_params(), "revolute"))
    q[11:4000:97, 2] += 2.0 * np.pi * rng.integers(2**18, 2**40, len(q[11:4000:97]))
    return q, qd, qdd


@pytest.mark.parametrize("function", ["inverse_dynamics", "actuator_jacobian"])
def test_every_thread_count_gives_the_same_bits(function: str) -> None:
    model = rpr3gen.load_model()
    q, qd, qdd = _long_case(3 * 4096 + 77)
    inputs = (q, qd, qdd)[: len(manifest.load("revolute").function(function).inputs)]
    one, codes = rpr3gen.evaluate(model, function, inputs, backend="c", threads=1)
    assert np.flatnonzero(codes).tolist() == [5, 7]
    for threads in (2, 3, None):
        out, other = rpr3gen.evaluate(model, function, inputs, backend="c", threads=threads)
        assert np.array_equal(codes, other)
        assert all(a.tobytes() == b.tobytes() for a, b in zip(one, out, strict=True)), threads


@pytest.mark.usefixtures("optimised_c_builds")
def test_batch_recomputes_huge_angles_like_the_single_call() -> None:
    model = rpr3gen.load_model()
    lib, names = _library("revolute")
    params = np.ascontiguousarray(model.vector(names))
    q, qd, qdd = (a[:40] for a in _long_case(40))
    q[[0, 3, 4], 2] = (2.0**20, 3.0e9, -1.0e300)  # past the fast path, and far past it
    rows, failed = _batch(params, q, qd, qdd, "revolute")
    assert failed == 2  # the NaN input and the singular pose
    out = np.empty(rows.shape[1])
    for i in range(len(q)):
        args = [np.ascontiguousarray(a[i]) for a in (q, qd, qdd)]
        if lib.rpr3_inverse_dynamics(_ptr(params), *map(_ptr, args), _ptr(out)) == 0:
            assert out.tobytes() == rows[i].tobytes(), i
        else:
            assert np.isnan(rows[i]).all()
    assert np.isfinite(rows[[0, 3, 4]]).all()


def test_threads_must_be_positive() -> None:
    model = rpr3gen.load_model()
    q = np.zeros((1, 3))
    for bad in (0, -1):
        with pytest.raises(rpr3gen.InputError):
            rpr3gen.inverse_dynamics(model, q, q, q, backend="c", threads=bad)
    for bad in (1.5, True):  # not integers: the wrong type (docs/errors.md, "Errors from Python")
        with pytest.raises(rpr3gen.InputTypeError):
            rpr3gen.inverse_dynamics(model, q, q, q, backend="c", threads=bad)
    from rpr3gen.cli import main

    assert main(["simulate", "--backend", "c", "--threads", "0"]) == 2


def test_sample_evaluators_share_buffers() -> None:
    """One evaluator's output as another's input, with no copy (the control loop's tick)."""
    model = _model(ne.paper_params(), "revolute")
    fk = rpr3gen.SampleEvaluator(model, function="forward_kinematics")
    vel = rpr3gen.SampleEvaluator(model, function="platform_velocity", buffers={"q": fk.q})
    assert vel.q is fk.q
    q = np.array([0.01, -0.02, 0.1])
    fk.qa[:] = rpr3gen.actuator_coordinates(model, q[None, :])[0]
    fk.q_near[:] = q
    vel.qa_dot[:] = (0.1, 0.2, 0.3)
    assert fk() == 0
    assert vel() == 0
    alone = rpr3gen.SampleEvaluator(model, function="platform_velocity")
    alone.q[:], alone.qa_dot[:] = fk.q, vel.qa_dot
    assert alone() == 0
    assert alone.qd.tobytes() == vel.qd.tobytes()
    for bad in ({"q": np.zeros(4)}, {"q": np.zeros(3, dtype=np.float32)}, {"x": np.zeros(3)}):
        with pytest.raises(rpr3gen.InputError):
            rpr3gen.SampleEvaluator(model, function="platform_velocity", buffers=bad)
