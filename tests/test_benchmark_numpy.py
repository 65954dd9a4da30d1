"""The NumPy benchmarks' pure parts: the eager floor's record of a generated kernel's calls
(``benchmarks/harness/numpy_parts.py``), the rounds of NumPy against Newton-Euler in turn
(``benchmarks/harness/paired.py``) and the report's figures from them (``benchmarks/report.py``).
Nothing is timed here."""

from __future__ import annotations

import collections
import importlib
import re
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest


def harness(repo_root: Path, name: str) -> ModuleType:
    """``benchmarks/NAME.py`` (``harness.paired``, ``report``), imported as the benchmarks do.

    ``sys.path`` is restored after: the scripts put ``benchmarks/`` first on it, where its
    ``mujoco_peer.py`` would shadow the tests' own for the rest of the session."""
    saved = list(sys.path)
    sys.path.insert(0, str(repo_root / "benchmarks"))
    try:
        return importlib.import_module(name)
    finally:
        sys.path[:] = saved


def _body(source: str, name: str) -> list[str]:
    """The lines of function ``name`` of a module's source."""
    lines = source.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith(f"def {name}("))
    end = next((k for k in range(start + 1, len(lines)) if lines[k].startswith(("def ", "_"))),
               len(lines))  # fmt: skip
    return lines[start:end]


def _ufunc_calls(lines: list[str]) -> collections.Counter[str]:
    """The calls of ufuncs (``_multiply(``, ``_add.reduce(``) and of ``numpy.copyto`` in a
    function's lines, by name (``multiply``, ``add.reduce``, ``copyto``)."""
    found: collections.Counter[str] = collections.Counter()
    for line in lines:
        for name, reduce in re.findall(r"(?<![\w.])_([a-z][a-z0-9]*)(\.reduce)?\(", line):
            if name not in ("sincos", "atan2"):
                found[name + reduce] += 1
        found["copyto"] += line.count("numpy.copyto(")
    return found


def _name(call: object) -> str:
    """A recorded call's name as :func:`_ufunc_calls` gives it."""
    name = getattr(call, "__name__", "")
    return f"{call.__self__.__name__}.reduce" if name == "reduce" else name  # type: ignore[attr-defined]


@pytest.mark.parametrize("variant", ["revolute", "prismatic"])
def test_the_floor_records_every_call_of_the_kernel(repo_root: Path, variant: str) -> None:
    # The eager floor replays the calls the recorder saw: it must see each ufunc call of the
    # generated function's text, and those of its _sincos and _atan2 helpers once per call of
    # them (their usual path, not the fallbacks indented under an ``if``), counted here from
    # the module's source, not by the recorder.
    parts = harness(repo_root, "harness.numpy_parts")
    samples = harness(repo_root, "harness.samples")
    model = samples.model(variant)
    found, info = parts.variants.load_function(model.structure, None, "inverse_dynamics")
    ev = parts.backends.evaluator(found, "numpy")
    n = 64
    motion = samples.motion(variant, "generic", n)
    inputs = [motion["q"], motion["qd"], motion["qdd"]]
    params = model.vector(found.param_names)
    outputs = ev.allocate(info, n)
    log = parts.record(ev.module, lambda: ev.run(info, params, inputs, outputs), n)
    source = Path(ev.module.__file__).read_text()
    body = _body(source, info.numpy_function)
    want = _ufunc_calls(body)
    for helper in ("_sincos", "_atan2"):
        times = sum(line.strip().startswith(f"{helper}(") for line in body)
        usual = [line for line in _body(source, helper) if not line.startswith(" " * 8)]
        for name, count in _ufunc_calls(usual).items():
            want[name] += times * count
    got = collections.Counter(_name(call) for call, _, _ in log)
    assert +got == +want
    summed = sum(int(np.prod(kinds[0][2])) for call, kinds, _ in log
                 if _name(call) == "add.reduce" and kinds[0][0] == "row")  # fmt: skip
    assert summed >= info.outputs[0].size  # the output rows' sums among them (a triple: 3)
    parts.replay(log, n)()  # and the replay makes them all, on rows of the block's length


def test_the_rounds_go_in_turn_and_alternate(
    repo_root: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    paired = harness(repo_root, "harness.paired")
    monkeypatch.setattr(paired, "ROUND_SECONDS", 0.0)  # one call a side a round
    order: list[str] = []
    calls = {"numpy": lambda: order.append("a"), "newton_euler": lambda: order.append("b")}
    times = paired.paired(calls, 4)
    assert [len(times["numpy"]), len(times["newton_euler"])] == [4, 4]
    # the untimed call of each side, then four rounds, the order alternating
    assert "".join(order) == "ab" + "ab" + "ba" + "ab" + "ba"


def test_the_report_takes_each_sides_best_round_and_the_median_ratio(repo_root: Path) -> None:
    report = harness(repo_root, "report")
    n = 10**4
    rounds = {"numpy": [4e-3, 3e-3, 5e-3], "newton_euler": [60e-3, 90e-3, 50e-3]}
    r = {"paired": {f"paired/revolute/generic/{n}": rounds}}
    ((motion, size, ours, ne, within),) = report.ne_ratios(r, "revolute")
    assert (motion, size) == ("generic", n)
    assert ours == pytest.approx(3e-3 / n * 1e9)  # the best NumPy round
    assert ne == pytest.approx(50e-3 / n * 1e9)  # the best Newton-Euler round
    assert within == pytest.approx(np.median([15.0, 30.0, 10.0]))  # the rounds' own ratios
    assert report.ne_ratios(r, "prismatic") == []


CPUINFO = """processor\t: 0
vendor_id\t: AuthenticAMD
cpu family\t: {family}
model\t\t: {model}
model name\t: AMD EPYC
cpu MHz\t\t: 2596.144
flags\t\t: fpu sse2 avx {flags}

processor\t: 1
cpu family\t: 99
"""


@pytest.mark.parametrize(
    ("family", "model", "flags", "expected"),
    [
        (25, 17, "avx2 avx512f", "family 25 model 17, 2596 MHz, AVX-512"),
        (23, 1, "avx2", "family 23 model 1, 2596 MHz, AVX2"),
        (25, 1, "", "family 25 model 1, 2596 MHz, AVX"),
    ],
)
def test_the_report_tells_cpus_of_one_model_name_apart(
    repo_root: Path, family: int, model: int, flags: str, expected: str
) -> None:
    run = harness(repo_root, "run")
    report = harness(repo_root, "report")
    info = CPUINFO.format(family=family, model=model, flags=flags)
    assert run.cpu_id(info) == expected
    r = {"machine": {"cpu": "AMD EPYC", "cpu_id": expected, "cores": 2, "usable_cores": 2,
                     "cc": "cc", "python": "3.11", "numpy": "2", "pyperf": "2", "commit": "x",
                     "date": "d"}, "quick": False, "seconds": 1,
         "load_start": [0, 0, 0], "load_end": [0, 0, 0]}  # fmt: skip
    assert f"AMD EPYC ({expected}), 2 logical cores" in report.header(r)
    del r["machine"]["cpu_id"]  # a run from before the field
    assert "AMD EPYC, 2 logical cores" in report.header(r)


def test_no_cpu_id_without_a_family(repo_root: Path) -> None:
    assert harness(repo_root, "run").cpu_id("model name\t: Apple M2\n") == ""
