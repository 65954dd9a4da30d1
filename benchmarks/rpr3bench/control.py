"""The section "Control model" (issue 12): the generated control functions in C and from Python,
one whole control tick, the exactness of the forward dynamics, MuJoCo as the peer, and the
Newton steps of the tracked forward kinematics.

- C (``bench_control.c`` through :func:`rpr3bench.charness.run_control`): ns per call of every
  control function and of one control tick, both variants, built with the runtime's flags and
  with -O2; the batches' ns/sample; floors of the libm calls; the forward dynamics of the
  inverse dynamics' efforts against the trajectory's acceleration.
- Python (worker ``control_python``): ``SampleEvaluator`` calls, and control ticks in Python.
- MuJoCo (worker ``mujoco``): ``mj_forward`` and ``mj_step`` (RK4) from Python and from C.
- Newton steps (worker ``fk_iterations``): the reference implementation's count.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

from rpr3bench import charness
from rpr3bench.common import CODE_IDS, code_id, log
from rpr3bench.report import ratio, table, verdict
from rpr3bench.workers import KD, KP, run_worker

ACTUATIONS = ("revolute", "prismatic")
#: Goals of issue 12 (scored in the report's targets table too).
GOALS = {
    "fd_ns": 300.0,  # C forward dynamics, one call
    "fd_exact": 1e-12,  # forward dynamics of the inverse dynamics' efforts: max relative error
    "tick_ns": 1000.0,  # one whole control tick in C
    "python_tick_us": 10.0,  # one control tick in Python
}
#: The straight-line functions: harness key, and the kernel whose libm calls it makes.
STRAIGHT = (
    "actuator_coordinates",
    "actuator_jacobian",
    "jacobian_rate",
    "task_space_dynamics",
    "forward_dynamics",
    "inverse_dynamics",
)
#: The floors of bench_control.c: the libm calls each stands for.
FLOORS = {
    "floor_trig": {"sin": 1, "cos": 1, "sqrt": 4},
    "floor_atan2": {"sin": 1, "cos": 1, "sqrt": 4, "atan2": 3},
}
#: Python ticks of workers._python_ticks, by key: label.
PY_TICKS = {
    "generated": "generated calls only: FK, `platform_velocity`, `actuator_efforts` (the law in C)",
    "numpy": "generated calls + `numpy.linalg.solve` (velocity and torque solves)",
    "floats": "generated calls + the 3x3 algebra on Python floats (J^-1 by cofactors)",
    "inverse_dynamics": "generated FK, J, `numpy.linalg.solve`, then `inverse_dynamics(q, q', a)`",
}


def _calls_text(calls: dict[str, int]) -> str:
    return ", ".join(f"{n} {f}" if n > 1 else f for f, n in calls.items()) or "none"


def _floor_of(calls: dict[str, int]) -> str | None:
    """The floor of bench_control.c whose libm calls are exactly ``calls``."""
    return next((key for key, want in FLOORS.items() if want == calls), None)


def _cell(values: dict[str, Any] | str | None, key: str) -> str:
    if not isinstance(values, dict) or f"{key}_med" not in values:
        return "n/a"
    return f"{values[f'{key}_med']:.1f} ({values[f'{key}_best']:.1f})"


def _med(values: dict[str, Any] | str | None, key: str) -> float | None:
    if not isinstance(values, dict):
        return None
    return values.get(f"{key}_med")


def _goal(measured: float | None, limit: float, unit: str) -> str:
    status, margin = verdict(measured, limit)
    if measured is None:
        return "n/a"
    return f"{measured / limit:.2f}x the {limit:g} {unit} goal: {status.strip('*')} ({margin})"


# ---------------------------------------------------------------------------------------------
# C
# ---------------------------------------------------------------------------------------------


def _c_runs(quick: bool) -> dict[tuple[str, str], dict[str, Any] | str]:
    repeats = 11 if quick else 41
    runs: dict[tuple[str, str], dict[str, Any] | str] = {}
    CODE_IDS.append(("control harness build", code_id()))
    with tempfile.TemporaryDirectory(prefix="rpr3bench-control-") as tmp:
        build = Path(tmp)
        charness.control_inputs(build)
        for flags in charness.CONTROL_BUILDS:
            for actuation in ACTUATIONS:
                log(f"control: bench_control.c, {actuation}, {flags}, {repeats} repeats")
                runs[actuation, flags] = charness.run_control(build, actuation, flags, repeats)
    CODE_IDS.append(("control harness end", code_id()))
    return runs


def _c_table(runs: dict[tuple[str, str], Any]) -> tuple[str, dict[str, Any]]:
    libm = {a: charness.kernel_calls(a) for a in ACTUATIONS}
    o3 = {a: runs[a, "O3"] for a in ACTUATIONS}
    o2 = {a: runs.get((a, "O2")) for a in ACTUATIONS}
    rows = []

    def libm_text(kernel: str | None) -> str:
        if kernel is None:
            return ""
        texts = {a: _calls_text(libm[a].get(kernel, {})) for a in ACTUATIONS}
        if len(set(texts.values())) == 1:
            return texts["revolute"]
        return "; ".join(f"{a[:3]}.: {t}" for a, t in texts.items())

    def vs_floor(key: str, kernel: str | None) -> str:
        cells = []
        for a in ACTUATIONS:
            floor = _floor_of(libm[a].get(kernel or "", {})) if kernel else None
            value, base = _med(o3[a], key), _med(o3[a], floor) if floor else None
            cells.append(ratio(value / base) if value and base else "–")
        return " / ".join(cells)

    def add(label: str, key: str, kernel: str | None, goal: str = "") -> None:
        rows.append(
            [
                label,
                libm_text(kernel),
                *(_cell(o3[a], key) for a in ACTUATIONS),
                *(_cell(o2[a], key) for a in ACTUATIONS),
                vs_floor(key, kernel),
                goal,
            ]
        )

    for key, calls in FLOORS.items():
        rows.append(
            [
                f"floor: {_calls_text(calls)}",
                "",
                *(_cell(o3[a], key) for a in ACTUATIONS),
                *(_cell(o2[a], key) for a in ACTUATIONS),
                "1x",
                "",
            ]
        )
    for name in STRAIGHT:
        goal = ""
        if name == "forward_dynamics":
            goal = _goal(_med(o3["revolute"], "single_forward_dynamics"), GOALS["fd_ns"], "ns")
        label = f"`rpr3_{name}`" + (" (for comparison)" if name == "inverse_dynamics" else "")
        add(label, f"single_{name}", name, goal)
    add("`rpr3_forward_kinematics`, tracked: q_near = 2 q[k-1] - q[k-2]", "fk_predicted", None)
    add("`rpr3_forward_kinematics`, q_near = q[k-1]", "fk_previous", None)
    add(
        "**control tick**: FK + J + q' solve + task-space dynamics + torque solve",
        "tick",
        None,
        _goal(_med(o3["revolute"], "tick"), GOALS["tick_ns"], "ns"),
    )
    add("control tick with `rpr3_inverse_dynamics` (FK + J + q' solve + ID)", "tick_id", None)
    for name in STRAIGHT:
        add(f"`rpr3_{name}_batch`, ns/sample", f"batch_{name}", name)
    header = [
        "call",
        "libm calls per call",
        "revolute ns",
        "prismatic ns",
        "revolute -O2 ns",
        "prismatic -O2 ns",
        "vs floor (rev. / pri.)",
        "goal (revolute)",
    ]
    text = table(header, rows)
    first = next(v for v in o3.values() if isinstance(v, dict))
    o2_first = next((v for v in o2.values() if isinstance(v, dict)), None)
    # One tracked call with one Newton step: the residual (actuator_coordinates) at q_near and at
    # the step, J at q_near for the step, and J at q_near and at the result for the aspect test.
    sums = {
        a: (
            2 * (_med(o3[a], "single_actuator_coordinates") or 0)
            + 3 * (_med(o3[a], "single_actuator_jacobian") or 0)
        )
        for a in ACTUATIONS
    }
    parts = {
        a: sum(
            _med(o3[a], k) or 0
            for k in ("fk_predicted", "single_actuator_jacobian", "single_task_space_dynamics")
        )
        for a in ACTUATIONS
    }
    trajectories = " and ".join(charness.CONTROL_TRAJECTORIES)
    text += (
        f"\n\nns per call, median (best) of {int(first['repeats'])} passes over "
        f"{int(first['samples']):,} samples: the paper's {trajectories} trajectories, "
        f"{charness.CONTROL_SAMPLES:,} samples each (3 s at 1 ms); batches in "
        "ns/sample over all of them. Columns *revolute*, *prismatic*: "
        f"`{first['command']}` (the runtime's flags, without `-fPIC -shared`)"
        + (f"; *-O2*: `{o2_first['command']}`" if o2_first else "")
        + ". Single calls of the straight-line functions run back to back on independent "
        "samples (throughput: the CPU may overlap consecutive calls); the tracked forward "
        "kinematics and the ticks wait for the previous result (each tick's q_near is predicted "
        "from the two previous poses), as in a control loop. The control tick (bench_control.c "
        f"`tick`): q = FK(qa, q_near); J; J^-1 by cofactors; q' = J^-1 qa'; M, c; "
        f"a = q*'' + {KD:g} (q*' - q') + {KP:g} (q* - q); tau = J^-T (M a + c). Encoders qa and "
        "qa' = J q' and the desired motion come from the trajectory (computed before timing).\n\n"
        "Floors (in the spirit of section 3): the libm calls of the function and nothing else, "
        "with the multiply-adds that form their arguments. The straight-line control functions "
        "call sin and cos of phi, sqrt for the three leg lengths and one more for their "
        "conditioning guard (*floor: sin, cos, 4 sqrt*); the inverse dynamics and the revolute "
        "actuator coordinates add the 3 atan2 of the leg angles. *vs floor* divides the "
        "function's median by its floor's. The forward kinematics and the ticks have no floor "
        "(iterative): one tracked call that takes one Newton step (the case here: see *FK Newton "
        "steps* below) "
        "evaluates the actuator coordinates twice (the residual at q_near and after the step) "
        "and the Jacobian three times (the step, and det J at q_near and at the result for the "
        "aspect test); those single calls add up to "
        + " / ".join(f"{sums[a]:.0f}" for a in ACTUATIONS)
        + " ns (revolute / prismatic), against the measured "
        + " / ".join(f"{_med(o3[a], 'fk_predicted') or 0:.0f}" for a in ACTUATIONS)
        + "; the rest is the Newton algebra and the acceptance test's own libm calls (revolute: "
        "sin and cos of phi and of the three leg angles). The tick's calls (tracked FK, J, "
        "task-space dynamics) add up to "
        + " / ".join(f"{parts[a]:.0f}" for a in ACTUATIONS)
        + " ns; the rest of the tick is its 3x3 algebra and the dependency between ticks.\n"
    )
    return text, {"o3": o3, "o2": o2}


def _c_checks(runs: dict[tuple[str, str], Any]) -> tuple[str, dict[str, Any]]:
    rows, fd_rows = [], []
    worst: dict[str, float] = {}
    for (actuation, flags), v in runs.items():
        if not isinstance(v, dict):
            continue
        mismatch = sum(int(v.get(f"mismatch_{name}", 0)) for name in STRAIGHT)
        failed = sum(int(val) for key, val in v.items() if key.endswith("_failed"))
        rows.append(
            [
                actuation,
                flags,
                f"{v['fk_err_xy']:.1e} m, {v['fk_err_phi']:.1e} rad",
                f"{v['tick_tau_err']:.1e}",
                f"{v['tick_id_tau_err']:.1e}",
                "bit for bit" if mismatch == 0 else f"**{mismatch} samples differ**",
                str(failed),
            ]
        )
        for s, name in enumerate(charness.CONTROL_TRAJECTORIES):
            err, scale = v[f"fd_abs_err.{s}"], v[f"fd_qdd_max.{s}"]
            rel = err / scale
            worst[actuation, flags] = max(worst.get((actuation, flags), 0.0), rel)
            status, margin = verdict(rel, GOALS["fd_exact"])
            fd_rows.append(
                [
                    actuation,
                    flags,
                    name,
                    f"{err:.1e}",
                    f"{scale:.3g}",
                    f"**{rel:.1e}**",
                    f"{status} ({margin})",
                    str(int(v[f"fd_failed.{s}"])),
                ]
            )
    text = (
        "Exactness of the forward dynamics: `rpr3_forward_dynamics(q, q', tau)` with tau the "
        "efforts of `rpr3_inverse_dynamics(q, q', q'')`, against the trajectory's q'', every "
        "sample (bench_control.c, same runs):\n\n"
        + table(
            [
                "variant",
                "build",
                "trajectory",
                "max abs. error",
                "max \\|q''\\|",
                "relative error",
                "goal 1e-12",
                "failed calls",
            ],
            fd_rows,
        )
        + "\n\nRelative error: the largest |component of the error| over the largest |component "
        "of q''| of the trajectory (∞-norms over the whole trajectory; m/s² and rad/s² "
        "together). Per sample it is not defined where q'' = 0 (mid-trajectory, and x, y of the "
        "rotation).\n\nOther checks of the same runs:\n\n"
        + table(
            [
                "variant",
                "build",
                "tracked FK vs true pose",
                "tick tau vs ID",
                "tick with ID vs ID",
                "single call vs batch",
                "failed calls",
            ],
            rows,
        )
        + "\n\n*tick tau vs ID*: max |tau_tick - tau_ID| / max |tau_ID| on the trajectory (the "
        "PD terms vanish there). *Single call vs batch*: the outputs of every straight-line "
        "function, compared bit for bit on every sample. *Failed calls*: non-zero return codes "
        "over every timed loop.\n"
    )
    return text, {"fd_rel_err": worst}


def _latency_table(o3: dict[str, Any]) -> str:
    rows = [
        [
            a,
            f"{v['tick_p50']:.0f}",
            f"{v['tick_p99']:.0f}",
            f"{v['tick_max']:,.0f}",
            f"{v['clock_ns']:.0f}",
        ]
        for a, v in o3.items()
        if isinstance(v, dict)
    ]
    return (
        "Latency of single ticks (the runtime's flags), each timed on its own by a pair of "
        "`clock_gettime` calls (included; its cost in the last column), the last of three "
        "passes:\n\n"
        + table(["variant", "p50 ns", "p99 ns", "max ns", "clock pair ns"], rows)
        + "\n\nThe maximum is the machine's (interrupts, the hypervisor), not the code's: the "
        "code's path is fixed on this trajectory (one Newton step, no fallback).\n"
    )


# ---------------------------------------------------------------------------------------------
# Python, MuJoCo, Newton steps
# ---------------------------------------------------------------------------------------------


def _median(values: list[float]) -> float:
    ordered = sorted(values)
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else 0.5 * (ordered[mid - 1] + ordered[mid])


def _python(quick: bool) -> tuple[str, dict[str, Any]]:
    functions = [
        "forward_kinematics",
        "actuator_jacobian",
        "task_space_dynamics",
        "forward_dynamics",
        "inverse_dynamics",
    ]
    log("control: Python SampleEvaluator calls and control ticks")
    r = run_worker(
        "control_python",
        actuations=list(ACTUATIONS),
        functions=functions,
        number=20_000 if quick else 100_000,
        repeats=3 if quick else 5,
        passes=3 if quick else 7,
    )
    if "error" in r:
        return f"Python control measurements failed: {r['error']}\n", {}
    us = 1e6
    rows = []
    for name in functions:
        cells = []
        for a in ACTUATIONS:
            f = r["actuations"][a]["calls"][name]
            cells += [f"{f['call'] * us:.3f}", f"{(f['call'] - f['rejected']) * us:.3f}"]
        rows.append([f"`{name}`", *cells])
    calls = table(
        [
            '`SampleEvaluator(model, backend="c", function=...)()`',
            "revolute µs",
            "of which C",
            "prismatic µs",
            "of which C",
        ],
        rows,
    )
    tick_rows = []
    scored: dict[str, float] = {}
    for key, label in PY_TICKS.items():
        cells = []
        for a in ACTUATIONS:
            t = r["actuations"][a]["ticks"][key]
            median = _median(t["times"]) * us
            if key == "generated":
                scored[a] = median
            cells += [f"{median:.2f} ({min(t['times']) * us:.2f})", f"{t['tau_err']:.1e}"]
        goal = _goal(
            _median(r["actuations"]["revolute"]["ticks"][key]["times"]) * us,
            GOALS["python_tick_us"],
            "µs",
        )
        tick_rows.append([label, *cells, goal])
    ticks = table(
        [
            "Python control tick",
            "revolute µs",
            "tau vs ID",
            "prismatic µs",
            "tau vs ID",
            "goal (revolute)",
        ],
        tick_rows,
    )
    samples = r["actuations"]["revolute"]["samples"]
    text = (
        calls + f"\n\nBest of {r['repeats']} x {r['number']:,} calls (`timeit`), one sample in the "
        "middle of the rotation; the forward kinematics from the predicted reference (one "
        "Newton step, as when tracking). *Of which C*: minus the same call with a NaN input, "
        "which C rejects at once (the cost of getting into C and back through ctypes).\n\n"
        + ticks
        + f"\n\nµs per tick, median (best) of {r['passes']} passes along both trajectories "
        f"({samples:,} ticks), forward kinematics tracked as in C; the tick as in C (its inputs "
        "read from prepared arrays, its efforts stored). Every call is a `SampleEvaluator` of "
        "the c backend (inputs written into its buffers, outputs read from them). The targets "
        "score the first row (the way `examples/control_loop/control_loop.py` ticks) and the "
        "third; the second's two `numpy.linalg.solve` calls on 3x3 "
        f"systems cost {r['numpy_solve'] * us:.2f} µs each (`timeit`, same process). "
        "*tau vs ID*: as for C.\n"
    )
    floats = {a: _median(r["actuations"][a]["ticks"]["floats"]["times"]) * us for a in ACTUATIONS}
    return text, {"python_tick_us": scored, "python_tick_floats_us": floats, "raw": r}


def _mujoco(quick: bool, c_fd: dict[str, float | None]) -> tuple[str, dict[str, Any]]:
    log("control: MuJoCo mj_forward and mj_step (RK4), Python and C")
    r = run_worker(
        "mujoco",
        actuations=list(ACTUATIONS),
        number=2000,
        repeats=3 if quick else 9,
    )
    if "error" in r:
        return f"MuJoCo measurements failed: {r['error']}\n", {}
    if "skipped" in r:
        return f"MuJoCo: skipped, {r['skipped']}.\n", {}
    rows = []
    first: dict[str, Any] = {}
    for a, v in r["actuations"].items():
        py, c = v["python"], v["c"]
        c_ok = isinstance(c, dict)
        first = first or v
        for name in ("mj_forward", "mj_step"):
            c_med = c[f"{name}_med"] if c_ok else None
            fd = c_fd.get(a)
            label = f"`{name}`"
            if name == "mj_step":
                label += f" ({v['integrator'].removeprefix('mjINT_')})"
            rows.append(
                [
                    a,
                    label,
                    f"{py[name]['median'] * 1e6:.2f} ({py[name]['best'] * 1e6:.2f})",
                    f"{c_med / 1e3:.2f} ({c[f'{name}_best'] / 1e3:.2f})" if c_ok else str(c),
                    ratio(c_med / (fd * (4 if name == "mj_step" else 1)))
                    if c_med and fd
                    else "n/a",
                ]
            )
    c_any = next((v["c"] for v in r["actuations"].values() if isinstance(v["c"], dict)), None)
    text = (
        table(
            [
                "actuation",
                "call",
                "Python µs/call",
                "C µs/call",
                "C vs `rpr3_forward_dynamics` (x4 for RK4)",
            ],
            rows,
        )
        + f"\n\nMuJoCo {r['version']}, the robot as `tests/mujoco_peer.py` builds it (nq = "
        f"{first.get('nq')}, closed by three `connect` equality constraints, timestep "
        f"{first.get('timestep')} s), at q = (0.02, -0.03, 0.1), q' = (0.05, 0.02, 0.1) with the "
        "efforts of the inverse dynamics at q'' = 0 (as `benchmarks/mujoco_peer.py`). Median "
        "(best) µs per call over the repeats of 2,000 calls; `mj_step` advances 2,000 steps "
        "(2 s) from that state. *Python*: the bindings (`timeit`). *C*: "
        + (f"`{c_any['command']}` (bench_mujoco.c). " if c_any else "not built. ")
        + "`mj_forward` computes the forward dynamics of the whole mechanism (9 joints and the "
        "loop-closure constraints); the last column divides it by `rpr3_forward_dynamics` of "
        "this run (runtime's flags), which gives the platform's acceleration of the same robot, "
        "and an RK4 `mj_step` by four of them (an RK4 step evaluates the dynamics four "
        "times).\n"
    )
    return text, {"raw": r}


def _fk_iterations() -> tuple[str, dict[str, Any]]:
    log("control: Newton steps of the reference tracked forward kinematics")
    r = run_worker("fk_iterations", actuations=list(ACTUATIONS))
    if "error" in r:
        return f"Newton steps: the reference failed: {r['error']}\n", {}
    rows = [
        [
            row["trajectory"],
            row["actuation"],
            row["reference"],
            f"{row['mean']:.3f}",
            str(row["max"]),
            ", ".join(f"{k}: {n}" for k, n in row["histogram"].items()),
            str(row["fallbacks"]),
            f"{row['error']:.1e}",
        ]
        for row in r["rows"]
    ]
    text = (
        table(
            [
                "trajectory",
                "actuation",
                "q_near",
                "mean Newton steps",
                "max",
                "steps: samples",
                "fallbacks",
                "max error (m)",
            ],
            rows,
        )
        + "\n\nThe generated C keeps no state and cannot report its Newton steps. These are the "
        "counts of the reference implementation, `tests/fk_reference.py` "
        "`tracked_forward_kinematics`, on the same trajectories at 1 ms (its own inverse "
        "kinematics for qa; q_near predicted, 2 q[k-1] - q[k-2], or the previous pose; the first "
        "pose from the true one). The C takes the same path, step for step: "
        "`tests/test_forward_kinematics_c.py` checks that with a traced build. *Max error*: the "
        "largest distance in (x, y, rho phi) from the true pose.\n"
    )
    return text, {"rows": r["rows"]}


# ---------------------------------------------------------------------------------------------
# The section
# ---------------------------------------------------------------------------------------------


def section_control(quick: bool) -> tuple[str, dict[str, Any]]:
    runs = _c_runs(quick)
    failed = {k: v for k, v in runs.items() if isinstance(v, str)}
    result: dict[str, Any] = {}
    parts = []
    if failed:
        parts += [f"bench_control.c ({a}, {f}): {msg}" for (a, f), msg in failed.items()]
    if all(isinstance(runs.get((a, "O3")), dict) for a in ACTUATIONS):
        c_text, c = _c_table(runs)
        checks_text, checks = _c_checks(runs)
        parts += [c_text, checks_text, _latency_table(c["o3"])]
        result["fd_ns"] = {a: _med(c["o3"][a], "single_forward_dynamics") for a in ACTUATIONS}
        result["tick_ns"] = {a: _med(c["o3"][a], "tick") for a in ACTUATIONS}
        result["fd_rel_err"] = max(checks["fd_rel_err"].values(), default=None)
        result["c"] = {f"{a} {f}": v for (a, f), v in runs.items()}
    py_text, py = _python(quick)
    result["python_tick_us"] = py.get("python_tick_us", {})
    result["python_tick_floats_us"] = py.get("python_tick_floats_us", {})
    mj_text, mj = _mujoco(quick, result.get("fd_ns", {}))
    fk_text, fk = _fk_iterations()
    result["mujoco"] = mj.get("raw")
    result["fk_iterations"] = fk.get("rows")
    parts += ["### Python", py_text, "### MuJoCo (peer)", mj_text, "### FK Newton steps", fk_text]
    summary = _summary(result)
    return "\n\n".join(part.strip("\n") for part in [summary, "### C", *parts]) + "\n", result


def _summary(result: dict[str, Any]) -> str:
    """The figures of issue 12, each against its goal."""
    fd, tick = result.get("fd_ns", {}), result.get("tick_ns", {})
    py = result.get("python_tick_us", {})
    floats = result.get("python_tick_floats_us", {})
    c = result.get("c", {})
    mj = (result.get("mujoco") or {}).get("actuations", {})
    lines = []

    def c_ns(actuation: str, key: str) -> str:
        value = _med(c.get(f"{actuation} O3"), key)
        return f"{value:.0f} ns" if value is not None else "n/a"

    for a in ACTUATIONS:
        if a not in fd:
            continue
        items = [
            f"FK (tracked) {c_ns(a, 'fk_predicted')}",
            f"Jacobian {c_ns(a, 'single_actuator_jacobian')}",
            f"task-space dynamics {c_ns(a, 'single_task_space_dynamics')}",
            f"forward dynamics {fd[a]:.0f} ns = {fd[a] / GOALS['fd_ns']:.2f}x the 300 ns goal",
            f"control tick {tick[a]:.0f} ns = {tick[a] / GOALS['tick_ns']:.2f}x the 1 µs goal",
        ]
        if a in py:
            items.append(
                f"Python tick {py[a]:.1f} µs with generated calls only = "
                f"{py[a] / GOALS['python_tick_us']:.2f}x the 10 µs goal"
            )
        if a in floats:
            items.append(
                f"{floats[a]:.1f} µs with the 3x3 algebra on floats = "
                f"{floats[a] / GOALS['python_tick_us']:.2f}x"
            )
        if a in mj:
            m = mj[a]
            items.append(
                f"MuJoCo `mj_forward` {m['python']['mj_forward']['median'] * 1e6:.1f} µs from "
                "Python"
                + (
                    f", {m['c']['mj_forward_med'] / 1e3:.1f} µs from C"
                    if isinstance(m["c"], dict)
                    else ""
                )
                + f", RK4 `mj_step` {m['python']['mj_step']['median'] * 1e6:.1f} µs from Python"
            )
        lines.append(f"- **{a}**: " + "; ".join(items) + ".")
    if result.get("fd_rel_err") is not None:
        err = result["fd_rel_err"]
        lines.append(
            f"- forward dynamics of the inverse dynamics' efforts: max relative error {err:.1e} "
            f"= {err / GOALS['fd_exact']:.2f}x the 1e-12 goal (both variants, both builds, both "
            "trajectories)."
        )
    tracked = [r for r in result.get("fk_iterations") or [] if r["reference"] == "predicted"]
    if tracked:
        lines.append(
            "- FK Newton steps per sample, tracked (q_near predicted): "
            + "; ".join(
                f"{r['actuation']} {r['trajectory']} mean {r['mean']:.3f}, max {r['max']}, "
                f"{r['fallbacks']} fallbacks"
                for r in tracked
            )
            + " (the reference implementation's count, which the C follows step for step)."
        )
    return (
        "Issue 12's figures, measured in this run (C: median ns per call, the runtime's flags; "
        "details below):\n\n" + "\n".join(lines) + "\n"
    )
