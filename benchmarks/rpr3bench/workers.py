"""The measurements that run in a fresh interpreter, and the parent's side that starts them.

Each worker takes a dict of arguments and returns a JSON-able dict; :func:`run_worker` starts
``python benchmarks/run.py --worker NAME --args JSON`` and reads the result from the last line
of its stdout. A fresh interpreter keeps caches cold (regeneration) and one measurement's memory
out of another's (each NumPy size).
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import resource
import subprocess
import time
import timeit
from collections import defaultdict
from collections.abc import Callable, Iterator
from typing import Any

from rpr3bench.common import (
    BENCH,
    CODE_IDS,
    PY,
    REPO,
    VARIANT,
    code_id,
    sample_inputs,
    variant,
)
from rpr3bench.speedworkers import WORKERS as SPEED_WORKERS

SHARED = "shared"  # the stages of regeneration outside any variant


class StageTimer:
    """The engine's stage hook: seconds per (variant, stage), from the nesting of stages.

    ``render(stage=timer.stage)`` enters ``"variant:NAME"`` around the work on one variant and
    the stages ``"derive"``, ``"cse"``, ``"print"`` and ``"render"`` inside it (outside any
    variant they count as :data:`SHARED`). A stage may be entered several times; its time is
    what it spends outside the stages nested in it, so no second is counted twice. ``"total"``
    of a variant is its wall time in ``"variant:NAME"``.
    """

    def __init__(self) -> None:
        self.seconds: dict[str, dict[str, float]] = defaultdict(lambda: defaultdict(float))
        self._variants: list[str] = []
        self._nested: list[float] = []  # per open stage: seconds of the stages inside it

    @property
    def current(self) -> str:
        return self._variants[-1] if self._variants else SHARED

    @contextlib.contextmanager
    def stage(self, name: str) -> Iterator[None]:
        is_variant = name.startswith("variant:")
        if is_variant:
            self._variants.append(name.removeprefix("variant:"))
        self._nested.append(0.0)
        start = time.perf_counter()
        try:
            yield
        finally:
            elapsed = time.perf_counter() - start
            inner = self._nested.pop()
            if is_variant:
                variant_name = self._variants.pop()
                if variant_name not in self._variants:  # outermost entry of this variant
                    self.seconds[variant_name]["total"] += elapsed
            else:
                self.seconds[self.current][name] += elapsed - inner
            if self._nested:
                self._nested[-1] += elapsed

    def result(self) -> dict[str, dict[str, float]]:
        return {v: dict(stages) for v, stages in self.seconds.items()}


def worker_regen(_: dict[str, Any]) -> dict[str, Any]:
    """One cold regeneration (``generate.render()``, both actuations), timed by stage.

    Afterwards (not timed) every function is compiled again for its op counts.
    """
    t0 = time.perf_counter()
    from rpr3gen_derive.codegen.files import stale_files
    from rpr3gen_derive.codegen.render import compile_function
    from rpr3gen_derive.rpr3 import generate, registry

    imports = time.perf_counter() - t0
    registry.clear_cache()
    timer = StageTimer()
    start = time.perf_counter()
    files = generate.render(stage=timer.stage)
    total = time.perf_counter() - start
    out_dir = generate.default_out_dir()
    ops: dict[str, dict[str, dict[str, int]]] = {}
    for actuation in registry.ACTUATIONS:
        module = registry.module(actuation)  # the specs derived above, from the cache
        ops[actuation] = {}
        for spec in module.functions:
            code = compile_function(spec, module.params).code
            ops[actuation][spec.name] = {
                "before": int(code.ops_before),
                "after": int(code.ops_after),
                "assignments": len(code.assignments),
            }
    return {
        "imports": imports,
        "total": total,
        "times": timer.result(),
        "ops": ops,
        "files": len(files),
        "stale": stale_files(out_dir, files) if out_dir is not None else None,
    }


# ---------------------------------------------------------------------------------------------
# Memory of this process
# ---------------------------------------------------------------------------------------------


def _rss_bytes() -> int:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def _peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: kilobytes


# ---------------------------------------------------------------------------------------------
# The generated NumPy code, as users call it and on its own
# ---------------------------------------------------------------------------------------------


class NumpyCalls:
    """One function of the measured variant, through the NumPy backend and directly.

    ``backend(*inputs)``: ``rpr3gen.evaluate(model, name, inputs, backend="numpy")``, the
    public call (it allocates the outputs, evaluates in blocks of ``rpr3gen.backends.BLOCK``
    samples and applies the failure policy). ``direct(*inputs, *outputs)``: the generated
    function ``numpy_function(params, inputs..., outputs...)`` of the generated module, outputs
    (size, n) preallocated by the caller (:meth:`allocate`).
    """

    def __init__(self, name: str) -> None:
        import rpr3gen
        from rpr3gen.evaluators import numpy_module

        self.model = rpr3gen.load_model()
        self.variant = variant()
        self.info = self.variant.function(name)
        self.params = self.model.vector(self.variant.param_names)
        self.module = numpy_module(self.variant)
        self.function = getattr(self.module, self.info.numpy_function)
        self.sizes = [o.size for o in self.info.outputs]
        self._evaluate = rpr3gen.evaluate

    def backend(self, *inputs: Any) -> list[Any]:
        outputs, _ = self._evaluate(self.model, self.info.name, inputs, backend="numpy")
        return outputs

    def allocate(self, n: int) -> list[Any]:
        import numpy as np

        return [np.empty((size, n)) for size in self.sizes]

    def direct(self, inputs: list[Any], outputs: list[Any]) -> None:
        self.function(self.params, *inputs, *outputs)

    def named(self, outputs: list[Any]) -> dict[str, Any]:
        """``{component name: (n,) array}`` of outputs from :meth:`backend`."""
        return {
            name: out[:, k]
            for info, out in zip(self.info.outputs, outputs, strict=True)
            for k, name in enumerate(info.names)
        }


def worker_numpy(args: dict[str, Any]) -> dict[str, Any]:
    """NumPy at one size: best time, peak RSS and tracemalloc peak of one call.

    ``mode`` "backend": the public ``rpr3gen.evaluate(..., backend="numpy")``; "direct": the
    generated function in one call over all samples (``chunk``: in calls of that many) into
    preallocated outputs.
    """
    import tracemalloc

    n, repeats, chunk = int(args["n"]), int(args["repeats"]), args.get("chunk")
    limit = int(args["mem_limit"])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))  # fail with MemoryError, not the OOM
    calls = NumpyCalls(args["function"])
    warm = sample_inputs(calls.info, 1000)
    calls.direct(warm, calls.allocate(1000))  # import and warm up the code paths
    calls.backend(*warm)
    inputs = sample_inputs(calls.info, n)
    direct = args["mode"] == "direct"
    outputs = calls.allocate(n if direct else 0)
    for out in outputs:
        out.fill(0.0)  # touch the output pages before timing
    rss_before = _rss_bytes()
    step = int(chunk) if chunk else n

    def call(stop: int = n) -> None:
        if not direct:
            calls.backend(*(a[:stop] for a in inputs))
            return
        for a in range(0, stop, step):
            b = min(stop, a + step)
            calls.direct([x[a:b] for x in inputs], [out[:, a:b] for out in outputs])

    times = []
    usage = resource.getrusage(resource.RUSAGE_SELF)
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    after = resource.getrusage(resource.RUSAGE_SELF)
    peak_rss = _peak_rss_bytes()
    tracemalloc.start()
    call(step)
    _, traced_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {
        "function": calls.info.name,
        "n": n,
        "mode": args["mode"],
        "chunk": step if chunk else None,
        "times": times,
        "rss_before": rss_before,
        "peak_rss": peak_rss,
        "traced_peak": traced_peak,
        "traced_samples": step,
        "minor_faults": after.ru_minflt - usage.ru_minflt,
        "user": after.ru_utime - usage.ru_utime,
        "system": after.ru_stime - usage.ru_stime,
        "outputs": sum(calls.sizes),
        "inputs": sum(a.size for a in calls.info.inputs),
    }


def _relative_difference(got: dict[str, Any], ref: dict[str, Any]) -> tuple[float, int]:
    """Largest |got - ref| / max(1, max |ref|) over the names both have, and how many."""
    import numpy as np

    worst, compared = 0.0, 0
    for name, value in got.items():
        if name not in ref:
            continue
        compared += 1
        scale = max(1.0, float(np.max(np.abs(ref[name]))))
        worst = max(worst, float(np.max(np.abs(value - ref[name]))) / scale)
    return worst, compared


# ---------------------------------------------------------------------------------------------
# Peers
# ---------------------------------------------------------------------------------------------


def _import_newton_euler() -> Any:
    import importlib.util

    path = REPO / "tests" / "newton_euler.py"
    spec = importlib.util.spec_from_file_location("rpr3_bench_newton_euler", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def worker_newton_euler(args: dict[str, Any]) -> dict[str, Any]:
    """The reference Newton-Euler batched solve against the NumPy backend, interleaved."""
    ne = _import_newton_euler()
    ne_params = ne.paper_params()
    calls = NumpyCalls("inverse_dynamics")
    param_diff = max(abs(ne_params[k] - calls.model.params[k]) for k in ne_params)
    results = []
    for n in args["sizes"]:
        q, qd, qdd = sample_inputs(calls.info, n)
        outputs = calls.allocate(n)
        t_ne, t_np, t_direct = [], [], []
        ref, got = {}, {}
        # Interleaved, each timed right after an untimed run of itself: every candidate is
        # measured warm, none just after another one's cache footprint (NE's is ~35 MB at 10^4).
        for _ in range(int(args["repeats"])):
            ne.solve(ne_params, VARIANT, q, qd, qdd)
            start = time.perf_counter()
            ref = ne.solve(ne_params, VARIANT, q, qd, qdd)
            t_ne.append(time.perf_counter() - start)
            calls.backend(q, qd, qdd)
            start = time.perf_counter()
            got = calls.named(calls.backend(q, qd, qdd))
            t_np.append(time.perf_counter() - start)
            calls.direct([q, qd, qdd], outputs)
            start = time.perf_counter()
            calls.direct([q, qd, qdd], outputs)
            t_direct.append(time.perf_counter() - start)
        worst, compared = _relative_difference(got, ref)
        results.append(
            {
                "n": n,
                "ne": t_ne,
                "numpy": t_np,
                "direct": t_direct,
                "max_rel_diff": worst,
                "compared": compared,
            }
        )
    return {"sizes": results, "param_diff": param_diff}


def worker_lambdify(args: dict[str, Any]) -> dict[str, Any]:
    """``sympy.lambdify`` (numpy, no CSE) of one function's fully expanded outputs, against the
    NumPy backend."""
    import numpy as np
    import sympy as sp
    from rpr3gen_derive.codegen.backends.python.printer import NumpyPrinter
    from rpr3gen_derive.rpr3 import registry

    name = args["function"]
    module = registry.module(VARIANT)
    spec = next(f for f in module.functions if f.name == name)
    flat = spec.flat_outputs()
    start = time.perf_counter()
    expanded = [spec.program.expand(expr) for _, _, expr in flat]
    t_expand = time.perf_counter() - start
    arguments = [*module.params.symbols, *(s for arg in spec.inputs for s in arg.symbols)]
    # The derivation uses functions of its own (``wrap_angle``); the project's NumPy printer
    # (SymPy's, plus those) prints them. Everything else is plain lambdify.
    printer = NumpyPrinter()
    start = time.perf_counter()
    # SymPy's NumPy printer folds Min/Max with functools.reduce: the namespace needs functools.
    func = sp.lambdify(
        arguments, expanded, modules=[{"functools": functools}, "numpy"], cse=False,
        printer=printer,
    )  # fmt: skip
    t_lambdify = time.perf_counter() - start
    expanded_ops = sum(int(sp.count_ops(e)) for e in expanded)

    n = int(args["n"])
    calls = NumpyCalls(name)
    if [str(s) for s in module.params.symbols] != list(calls.variant.param_names):
        raise RuntimeError("the registry's parameters and the manifest's differ in order")
    inputs = sample_inputs(calls.info, n)
    values = [float(v) for v in calls.params] + [a[:, k] for a in inputs for k in range(a.shape[1])]
    start = time.perf_counter()
    result = func(*values)
    t_first = time.perf_counter() - start
    t_lam, t_gen = [], []
    got: list[Any] = []
    for _ in range(int(args["repeats"])):
        start = time.perf_counter()
        func(*values)
        t_lam.append(time.perf_counter() - start)
        start = time.perf_counter()
        got = calls.backend(*inputs)
        t_gen.append(time.perf_counter() - start)
    index = {o.name: k for k, o in enumerate(spec.public_outputs)}  # evaluate() returns these
    lam = {
        f"{o}[{k}]": np.broadcast_to(np.asarray(value, dtype=float), (n,))
        for (o, k, _), value in zip(flat, result, strict=True)
    }
    gen = {f"{o}[{k}]": got[index[o]][:, k] for o, k, _ in flat if o in index}
    worst, compared = _relative_difference(lam, gen)
    return {
        "function": name,
        "n": n,
        "printer": f"{type(printer).__module__}.{type(printer).__name__}",
        "outputs": len(expanded),
        "compared": compared,
        "expand": t_expand,
        "lambdify": t_lambdify,
        "expanded_ops": expanded_ops,
        "first_call": t_first,
        "lambdified": t_lam,
        "generated": t_gen,
        "max_rel_diff": worst,
        "peak_rss": _peak_rss_bytes(),
    }


# ---------------------------------------------------------------------------------------------
# The Python single-sample call
# ---------------------------------------------------------------------------------------------


def worker_python_single(args: dict[str, Any]) -> dict[str, Any]:
    """``SampleEvaluator`` calls of each function: the C backend, its ctypes floor, NumPy."""
    import numpy as np

    import rpr3gen
    from rpr3gen import cbackend

    model = rpr3gen.load_model()
    number, repeats = int(args["number"]), int(args["repeats"])
    mid = 150

    def best(func: Callable[[], Any], count: int) -> float:
        return min(timeit.repeat(func, number=count, repeat=repeats)) / count

    def empty() -> None:
        pass

    results = {}
    for name in args["functions"]:
        evaluator = rpr3gen.SampleEvaluator(model, backend="c", function=name)
        sample = [a[mid] for a in sample_inputs(evaluator.function, 301)]
        for buffer, value in zip(evaluator.inputs.values(), sample, strict=True):
            buffer[:] = value
        status = evaluator()
        # The same entry point with a NaN input returns at the first check (inputs not
        # finite): what is left of its time is the cost of getting into C and back (ctypes,
        # interpreter).
        rejected = rpr3gen.SampleEvaluator(model, backend="c", function=name)
        next(iter(rejected.inputs.values()))[:] = np.nan
        rejected_status = rejected()
        slow = rpr3gen.SampleEvaluator(model, backend="numpy", function=name)
        for buffer, value in zip(slow.inputs.values(), sample, strict=True):
            buffer[:] = value
        results[name] = {
            "c_call": best(evaluator, number),
            "c_rejected": best(rejected, number),
            "c_evaluate": best(lambda ev=evaluator, s=sample: ev.evaluate(*s), number // 4),
            "numpy_call": best(slow, max(10, int(args["numpy_number"]))),
            "status": status,
            "rejected_status": rejected_status,
            "rejected_meaning": evaluator.codes.get(rejected_status, "?"),
        }
        slow()
        results[name]["agree"] = all(
            bool(np.allclose(evaluator.outputs[o], slow.outputs[o], rtol=1e-9, atol=1e-9))
            for o in evaluator.outputs
        )
    return {
        "functions": results,
        "python_call": best(empty, number),
        # The flags the runtime tries first (it drops extras the compiler refuses).
        "cflags": [*cbackend.CFLAGS, *cbackend.EXTRA_FLAGS[0]],
        "number": number,
        "repeats": repeats,
    }


# ---------------------------------------------------------------------------------------------
# The control model (section "Control model")
# ---------------------------------------------------------------------------------------------

#: Gains of the control tick (as examples/control_loop): a = q*'' + KD (q*' - q') + KP (q* - q).
KP, KD = 900.0, 60.0
#: The efforts of each actuation among the outputs of the inverse dynamics.
EFFORT = {"revolute": "m10", "prismatic": "f21z"}


def _control_model(actuation: str) -> Any:
    import dataclasses

    import rpr3gen

    return dataclasses.replace(rpr3gen.load_model(), actuation=actuation)


def _control_samples(model: Any) -> dict[str, Any]:
    """The paper's trajectories at 1 ms, one after the other, and what a controller reads on
    them: encoders ``qa`` and ``qa_dot = J q'``, and the efforts ``tau`` of the inverse
    dynamics (all through the generated C), with ``starts``, the first sample of each."""
    import numpy as np

    import rpr3gen
    from rpr3bench.charness import CONTROL_SAMPLES, CONTROL_TRAJECTORIES

    runs = [
        rpr3gen.paper_trajectory(name, samples=CONTROL_SAMPLES, duration=3.0)
        for name in CONTROL_TRAJECTORIES
    ]
    q, qd, qdd = (np.concatenate([getattr(r, k) for r in runs]) for k in ("q", "qd", "qdd"))
    (qa,), _ = rpr3gen.evaluate(model, "actuator_coordinates", (q,), backend="c")
    (J,), _ = rpr3gen.evaluate(model, "actuator_jacobian", (q,), backend="c")
    (out,), _ = rpr3gen.evaluate(model, "inverse_dynamics", (q, qd, qdd), backend="c")
    names = list(
        rpr3gen.manifest.load(model.actuation).function("inverse_dynamics").outputs[0].names
    )
    effort = [names.index(f"{EFFORT[model.actuation]}_{leg}") for leg in "ABC"]
    return {
        "q": q,
        "qd": qd,
        "qdd": qdd,
        "qa": qa,
        "qa_dot": np.einsum("nij,nj->ni", J.reshape(-1, 3, 3), qd),
        "tau": out[:, effort],
        "effort": effort,
        "starts": [k * CONTROL_SAMPLES for k in range(len(runs))],
    }


def _python_ticks(model: Any, data: dict[str, Any]) -> dict[str, Callable[[], Any]]:
    """Python control ticks over the trajectories, each a function that runs one pass (every
    sample, tracking FK from each trajectory's start) and returns the efforts (n, 3).

    - ``generated``: generated calls only: FK, ``platform_velocity`` (J q' = qa') and
      ``actuator_efforts`` at the commanded acceleration (tau = J^-T (M a + c), the law in C);
    - ``numpy``: the generated calls (``SampleEvaluator``, c backend) and ``numpy.linalg.solve``
      for the velocity and the torque solves;
    - ``floats``: the same calls, the 3x3 algebra on Python floats (J^-1 by cofactors, once);
    - ``inverse_dynamics``: FK, J, ``numpy.linalg.solve`` for q', then the generated inverse
      dynamics at (q, q', a) in place of the task-space dynamics and the torque solve.
    """
    import numpy as np

    import rpr3gen

    fk = rpr3gen.SampleEvaluator(model, backend="c", function="forward_kinematics")
    vel = rpr3gen.SampleEvaluator(model, backend="c", function="platform_velocity")
    eff = rpr3gen.SampleEvaluator(model, backend="c", function="actuator_efforts")
    jac = rpr3gen.SampleEvaluator(model, backend="c", function="actuator_jacobian")
    tsd = rpr3gen.SampleEvaluator(model, backend="c", function="task_space_dynamics")
    idy = rpr3gen.SampleEvaluator(model, backend="c", function="inverse_dynamics")
    J, M, c = jac.J.reshape(3, 3), tsd.M.reshape(3, 3), tsd.c
    effort = data["effort"]
    n = len(data["q"])
    starts = set(data["starts"])
    rows = {k: data[k] for k in ("q", "qd", "qdd", "qa", "qa_dot")}
    lists = {k: v.tolist() for k, v in rows.items()}

    def generated_tick() -> Any:
        q_des, qd_des, qdd_des, qa, qa_dot = (rows[k] for k in ("q", "qd", "qdd", "qa", "qa_dot"))
        taus = np.empty((n, 3))
        q1 = q2 = q_des[0]
        for k in range(n):
            if k in starts:
                q1 = q2 = q_des[k]
            fk.qa[:] = qa[k]
            fk.q_near[:] = 2.0 * q1 - q2
            if fk():
                raise RuntimeError(f"forward kinematics failed at sample {k}")
            q = fk.q.copy()
            vel.q[:] = q
            vel.qa_dot[:] = qa_dot[k]
            vel()
            eff.q[:] = q
            eff.qd[:] = vel.qd
            eff.qdd[:] = qdd_des[k] + KD * (qd_des[k] - vel.qd) + KP * (q_des[k] - q)
            eff()
            taus[k] = eff.tau
            q1, q2 = q, q1
        return taus

    def numpy_tick() -> Any:
        q_des, qd_des, qdd_des, qa, qa_dot = (rows[k] for k in ("q", "qd", "qdd", "qa", "qa_dot"))
        taus = np.empty((n, 3))
        q1 = q2 = q_des[0]
        for k in range(n):
            if k in starts:
                q1 = q2 = q_des[k]
            fk.qa[:] = qa[k]
            fk.q_near[:] = 2.0 * q1 - q2
            if fk():
                raise RuntimeError(f"forward kinematics failed at sample {k}")
            q = fk.q.copy()
            jac.q[:] = q
            jac()
            qd = np.linalg.solve(J, qa_dot[k])
            tsd.q[:] = q
            tsd.qd[:] = qd
            tsd()
            a = qdd_des[k] + KD * (qd_des[k] - qd) + KP * (q_des[k] - q)
            taus[k] = np.linalg.solve(J.T, M @ a + c)
            q1, q2 = q, q1
        return taus

    def floats_tick() -> Any:
        q_des, qd_des, qdd_des, qa, qa_dot = (lists[k] for k in ("q", "qd", "qdd", "qa", "qa_dot"))
        taus = [None] * n
        x1 = x2 = q_des[0]
        for k in range(n):
            if k in starts:
                x1 = x2 = q_des[k]
            fk.qa[:] = qa[k]
            fk.q_near[:] = (2 * x1[0] - x2[0], 2 * x1[1] - x2[1], 2 * x1[2] - x2[2])
            if fk():
                raise RuntimeError(f"forward kinematics failed at sample {k}")
            jac.q[:] = fk.q
            jac()
            j0, j1, j2, j3, j4, j5, j6, j7, j8 = jac.J.tolist()
            c0, c1, c2 = j4 * j8 - j5 * j7, j5 * j6 - j3 * j8, j3 * j7 - j4 * j6
            c3, c4, c5 = j2 * j7 - j1 * j8, j0 * j8 - j2 * j6, j1 * j6 - j0 * j7
            c6, c7, c8 = j1 * j5 - j2 * j4, j2 * j3 - j0 * j5, j0 * j4 - j1 * j3
            inv = 1.0 / (j0 * c0 + j1 * c1 + j2 * c2)
            w0, w1, w2 = qa_dot[k]
            qd = (
                (c0 * w0 + c3 * w1 + c6 * w2) * inv,
                (c1 * w0 + c4 * w1 + c7 * w2) * inv,
                (c2 * w0 + c5 * w1 + c8 * w2) * inv,
            )
            tsd.q[:] = fk.q
            tsd.qd[:] = qd
            tsd()
            q = fk.q.tolist()
            m0, m1, m2, m3, m4, m5, m6, m7, m8 = tsd.M.tolist()
            b0, b1, b2 = tsd.c.tolist()
            qs, vs, acc = q_des[k], qd_des[k], qdd_des[k]
            a0 = acc[0] + KD * (vs[0] - qd[0]) + KP * (qs[0] - q[0])
            a1 = acc[1] + KD * (vs[1] - qd[1]) + KP * (qs[1] - q[1])
            a2 = acc[2] + KD * (vs[2] - qd[2]) + KP * (qs[2] - q[2])
            r0 = m0 * a0 + m1 * a1 + m2 * a2 + b0
            r1 = m3 * a0 + m4 * a1 + m5 * a2 + b1
            r2 = m6 * a0 + m7 * a1 + m8 * a2 + b2
            taus[k] = (
                (c0 * r0 + c1 * r1 + c2 * r2) * inv,
                (c3 * r0 + c4 * r1 + c5 * r2) * inv,
                (c6 * r0 + c7 * r1 + c8 * r2) * inv,
            )
            x1, x2 = q, x1
        return np.array(taus)

    def id_tick() -> Any:
        q_des, qd_des, qdd_des, qa, qa_dot = (rows[k] for k in ("q", "qd", "qdd", "qa", "qa_dot"))
        taus = np.empty((n, 3))
        q1 = q2 = q_des[0]
        for k in range(n):
            if k in starts:
                q1 = q2 = q_des[k]
            fk.qa[:] = qa[k]
            fk.q_near[:] = 2.0 * q1 - q2
            if fk():
                raise RuntimeError(f"forward kinematics failed at sample {k}")
            q = fk.q.copy()
            jac.q[:] = q
            jac()
            qd = np.linalg.solve(J, qa_dot[k])
            idy.q[:] = q
            idy.qd[:] = qd
            idy.qdd[:] = qdd_des[k] + KD * (qd_des[k] - qd) + KP * (q_des[k] - q)
            idy()
            taus[k] = idy.out[effort]
            q1, q2 = q, q1
        return taus

    return {
        "generated": generated_tick,
        "numpy": numpy_tick,
        "floats": floats_tick,
        "inverse_dynamics": id_tick,
    }


def worker_control_python(args: dict[str, Any]) -> dict[str, Any]:
    """Per actuation: ``SampleEvaluator`` calls of the control functions (c backend) and the
    Python control ticks of :func:`_python_ticks` along the paper's trajectories at 1 ms."""
    import numpy as np

    import rpr3gen

    number, repeats, passes = int(args["number"]), int(args["repeats"]), int(args["passes"])
    results: dict[str, Any] = {}
    for actuation in args["actuations"]:
        model = _control_model(actuation)
        data = _control_samples(model)
        k = len(data["q"]) // 4  # a sample in the middle of the rotation
        near = 2 * data["q"][k - 1] - data["q"][k - 2]  # the tracked case: one Newton step
        sample = {
            "q": data["q"][k],
            "qd": data["qd"][k],
            "qdd": data["qdd"][k],
            "tau": data["tau"][k],
            "qa": data["qa"][k],
            "q_near": near,
        }
        calls = {}
        for name in args["functions"]:
            ev = rpr3gen.SampleEvaluator(model, backend="c", function=name)
            for key, buffer in ev.inputs.items():
                buffer[:] = sample[key]
            status = ev()
            rejected = rpr3gen.SampleEvaluator(model, backend="c", function=name)
            next(iter(rejected.inputs.values()))[:] = np.nan
            calls[name] = {
                "call": min(timeit.repeat(ev, number=number, repeat=repeats)) / number,
                "rejected": min(timeit.repeat(rejected, number=number, repeat=repeats)) / number,
                "status": status,
                "rejected_status": rejected(),
            }
        ticks = {}
        for name, tick in _python_ticks(model, data).items():
            taus = tick()  # warm-up, and the check
            times = []
            for _ in range(passes):
                start = time.perf_counter()
                tick()
                times.append((time.perf_counter() - start) / len(data["q"]))
            err = float(np.max(np.abs(taus - data["tau"])) / np.max(np.abs(data["tau"])))
            ticks[name] = {"times": times, "tau_err": err}
        results[actuation] = {"calls": calls, "ticks": ticks, "samples": len(data["q"])}
    # What one numpy.linalg.solve of a 3x3 system costs (the numpy tick makes two).
    matrix, vector, count = np.eye(3) + 0.1 * np.arange(9.0).reshape(3, 3), np.ones(3), number // 4
    solve = (
        min(timeit.repeat(lambda: np.linalg.solve(matrix, vector), number=count, repeat=repeats))
        / count
    )
    return {
        "actuations": results,
        "number": number,
        "repeats": repeats,
        "passes": passes,
        "numpy_solve": solve,
    }


def _import_test_helper(name: str) -> Any:
    import importlib.util
    import sys

    path = REPO / "tests" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"rpr3_bench_{name}", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


def worker_fk_iterations(args: dict[str, Any]) -> dict[str, Any]:
    """Newton steps of the reference tracked forward kinematics (``tests/fk_reference.py``),
    whose path the generated C follows step for step, along the paper's trajectories at 1 ms."""
    import numpy as np

    import rpr3gen
    from rpr3bench.charness import CONTROL_SAMPLES, CONTROL_TRAJECTORIES

    fk = _import_test_helper("fk_reference")
    geom = fk.Geometry.from_params(rpr3gen.load_model().params)
    rows = []
    for name in CONTROL_TRAJECTORIES:
        q = rpr3gen.paper_trajectory(name, samples=CONTROL_SAMPLES, duration=3.0).q
        for actuation in args["actuations"]:
            for reference in ("predicted", "previous"):
                prev = prev2 = tuple(q[0])
                steps, fallbacks, error = [], 0, 0.0
                for k in range(len(q)):
                    qa = fk.actuator_coordinates(geom, actuation, q[k])
                    near = prev
                    if reference == "predicted":
                        near = tuple(2 * a - b for a, b in zip(prev, prev2, strict=True))
                    found = fk.tracked_forward_kinematics(geom, actuation, qa, near)
                    steps.append(found.iterations)
                    fallbacks += found.status != "newton"
                    error = max(error, fk.distance(geom, found.q, q[k]))
                    prev2, prev = prev, found.q
                rows.append(
                    {
                        "trajectory": name,
                        "actuation": actuation,
                        "reference": reference,
                        "samples": len(q),
                        "mean": float(np.mean(steps)),
                        "max": int(max(steps)),
                        "histogram": {str(s): steps.count(s) for s in sorted(set(steps))},
                        "fallbacks": fallbacks,
                        "error": error,
                    }
                )
    return {"rows": rows}


def worker_mujoco(args: dict[str, Any]) -> dict[str, Any]:
    """``mj_forward`` and ``mj_step`` (RK4) of the MuJoCo peer (``tests/mujoco_peer.py``) on the
    paper's robot, from Python (``timeit``) and from C (``bench_mujoco.c``)."""
    import statistics
    import tempfile
    from pathlib import Path

    try:
        import mujoco
    except ImportError as error:
        return {"skipped": f"MuJoCo is not installed ({error}); `pip install -e '.[peers]'`"}
    import rpr3gen
    from rpr3bench import charness

    peer = _import_test_helper("mujoco_peer")
    q, qd = (0.02, -0.03, 0.1), (0.05, 0.02, 0.1)  # as benchmarks/mujoco_peer.py
    number, repeats = int(args["number"]), int(args["repeats"])
    results: dict[str, Any] = {"version": mujoco.__version__, "actuations": {}}
    with tempfile.TemporaryDirectory(prefix="rpr3bench-mujoco-") as tmp:
        build = Path(tmp)
        for actuation in args["actuations"]:
            model = _control_model(actuation)
            xml = peer.build_mjcf(model.params, actuation, integrator="RK4")
            mj_model = mujoco.MjModel.from_xml_string(xml)
            data = mujoco.MjData(mj_model)
            peer.set_state(mj_model, data, q, qd)
            # Efforts that hold the motion gently: the inverse dynamics at q'' = 0.
            (out,), _ = rpr3gen.evaluate(model, "inverse_dynamics", ([q], [qd], [(0.0,) * 3]))
            names = rpr3gen.manifest.load(actuation).function("inverse_dynamics").outputs[0].names
            data.ctrl[:] = [
                out[0, list(names).index(f"{EFFORT[actuation]}_{leg}")] for leg in "ABC"
            ]
            qpos, qvel, ctrl = data.qpos.copy(), data.qvel.copy(), data.ctrl.copy()
            timings = {}
            for name, call in (("mj_forward", mujoco.mj_forward), ("mj_step", mujoco.mj_step)):
                data.qpos[:], data.qvel[:] = qpos, qvel
                mujoco.mj_forward(mj_model, data)
                times = [
                    t / number
                    for t in timeit.repeat(
                        lambda c=call, m=mj_model, d=data: c(m, d), number=number, repeat=repeats
                    )
                ]
                timings[name] = {"median": statistics.median(times), "best": min(times)}
            (build / f"{actuation}.xml").write_text(xml)
            state = build / f"{actuation}.state"
            values = " ".join(repr(float(v)) for v in [*qpos, *qvel, *ctrl])
            state.write_text(f"{mj_model.nq} {mj_model.nv} {mj_model.nu}\n{values}\n")
            c_run = charness.run_mujoco(build, build / f"{actuation}.xml", state, number, repeats)
            results["actuations"][actuation] = {
                "python": timings,
                "c": c_run,
                "timestep": float(mj_model.opt.timestep),
                "integrator": str(mujoco.mjtIntegrator(mj_model.opt.integrator).name),
                "nq": int(mj_model.nq),
            }
    return results


WORKERS: dict[str, Callable[[dict[str, Any]], dict[str, Any]]] = {
    "regen": worker_regen,
    "numpy": worker_numpy,
    "newton_euler": worker_newton_euler,
    "lambdify": worker_lambdify,
    "python_single": worker_python_single,
    "control_python": worker_control_python,
    "fk_iterations": worker_fk_iterations,
    "mujoco": worker_mujoco,
    **SPEED_WORKERS,
}


def work(name: str, args: dict[str, Any]) -> dict[str, Any]:
    """Run worker ``name`` in this process (``run.py --worker``), with the code ids it saw."""
    before = code_id()
    result = WORKERS[name](args)
    result["code_ids"] = [before, code_id()]
    return result


def run_worker(
    name: str, timeout: float = 900.0, env: dict[str, str] | None = None, **args: Any
) -> dict[str, Any]:
    """Run one worker in a fresh interpreter; return its JSON result (or an "error")."""
    command = [PY, str(BENCH / "run.py"), "--worker", name, "--args", json.dumps(args)]
    try:
        done = subprocess.run(
            command,
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
            cwd=REPO,
            env={**os.environ, **(env or {})},
        )
    except subprocess.TimeoutExpired:
        return {"error": f"timed out after {timeout:.0f} s"}
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines:
        tail = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        return {"error": f"exit status {done.returncode}: {tail}"}
    result: dict[str, Any] = json.loads(lines[-1])
    label = f"{name} " + ", ".join(f"{k}={v}" for k, v in args.items() if k != "mem_limit")
    if env:
        label += " (" + " ".join(f"{k}={v}" for k, v in env.items()) + ")"
    if name != "regen":  # regeneration renders from derive/ and does not run generated/
        CODE_IDS.extend((label.strip(), cid) for cid in result.get("code_ids", []))
    return result
