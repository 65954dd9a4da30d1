"""The benchmark harness's pure parts (``benchmarks/harness/``): the libm calls a generated
kernel makes per sample (``cbench.py``), its longest chain of dependent operations
(``chain.py``), and the control-loop examples' reports (``examples.py``). Nothing is timed or
built here."""

from __future__ import annotations

import importlib
import itertools
import sys
from pathlib import Path
from types import ModuleType

import pytest


def harness(repo_root: Path, name: str) -> ModuleType:
    """``benchmarks/harness/NAME.py``, imported as the benchmarks import it."""
    sys.path.insert(0, str(repo_root / "benchmarks"))
    try:
        return importlib.import_module(f"harness.{name}")
    finally:
        sys.path.remove(str(repo_root / "benchmarks"))


@pytest.fixture(scope="module")
def cbench(repo_root: Path) -> ModuleType:
    return harness(repo_root, "cbench")


SOURCE = """
static int p_f_kernel(const double *restrict params)
{
    const double c = p_cos(params[0]);
    for (i = 0; i < 4; ++i) { /* legs A, B, C; lane 3 unused */
        const double t_i = p_atan2(params[1 + 2*i], c);
        const double L_i = sqrt(t_i);
    }
    const double s = sqrt(c);
    return 0;
}

static void p_f_values(const double *restrict params)
{
    const double c = p_cos(params[0]);
}

int p_f(const double *params)
"""


def test_a_call_in_a_loop_over_the_legs_counts_once_per_leg(cbench: ModuleType) -> None:
    assert cbench.kernel_calls(SOURCE, "p") == {"f": {"cos": 1, "sqrt": 4, "atan2": 3}}


def test_a_sincos_call_counts_as_a_sin_and_a_cos(cbench: ModuleType) -> None:
    source = SOURCE.replace(
        "    const double c = p_cos(params[0]);\n    for",
        "    double s0, c;\n    p_sincos(params[0], &s0, &c);\n    for",
    )
    assert "p_sincos" in source
    assert cbench.kernel_calls(source, "p")["f"] == {"sin": 1, "cos": 1, "sqrt": 4, "atan2": 3}


@pytest.mark.parametrize("variant", ["revolute", "prismatic"])
def test_the_inverse_dynamics_floor_has_each_legs_calls(
    cbench: ModuleType, repo_root: Path, variant: str
) -> None:
    """Three legs: an atan2 (the leg's angle) and a sqrt (its length) each; the platform's sin
    and cos; the conditioning's sqrt."""
    source = (repo_root / "generated" / variant / "rpr3.c").read_text()
    calls = cbench.kernel_calls(source, "rpr3")["inverse_dynamics"]
    assert calls["sin"] == calls["cos"] == 1
    assert calls["sqrt"] == 4
    assert calls["atan2"] == 3


# The chain floor (benchmarks/harness/chain.py): a kernel's longest chain of dependent
# operations, on latencies given here (the benchmark measures them; nothing is timed here).

UNIT = dict.fromkeys(("add", "mul", "div", "sqrt", "sin", "cos", "atan2", "fmin", "rint"), 0.0)


@pytest.fixture(scope="module")
def chain(repo_root: Path) -> ModuleType:
    return harness(repo_root, "chain")


def latencies(**given: float) -> dict[str, float]:
    return {**UNIT, **given}


CHAIN = """
static int p_g_kernel(const double *restrict params, const double *restrict q)
{
    int i;
    double L_i_legs[4];
    const double c = p_cos(q[2]);
    const double third = (1.0/3.0)*params[0];
    for (i = 0; i < 4; ++i) { /* legs A, B, C; lane 3 unused */
        const double rx_i = c*params[1 + 2*i] - q[0];
        const double L_i = sqrt(rx_i*rx_i + third);
        L_i_legs[i] = L_i;
    }
    const double L_A = L_i_legs[0];
    const double L_B = L_i_legs[1];
    const double side = params[7] + params[8];
    r_out[0] = 1.0/(L_A + L_B) - side;
    if (!(r_out[0] >= 0.0)) { /* also catches NaN */
        return P_SINGULAR;
    }
    return P_OK;
}
"""


def test_the_chain_is_the_longest_path_of_latencies(chain: ModuleType) -> None:
    """cos -> mul -> add (rx) -> mul -> add -> sqrt (L) -> add -> div -> add; the leg loop once,
    the constant 1/3 folded, ``side`` off the path."""
    body = chain.kernel_bodies(CHAIN, "p")["g"]
    lat = latencies(add=1.0, mul=10.0, div=100.0, sqrt=1000.0, cos=10000.0)
    assert chain.critical_path(body, lat, "p") == 10000 + 10 + 1 + 10 + 1 + 1000 + 1 + 100 + 1


def test_a_sincos_call_takes_the_longer_of_its_two_latencies(chain: ModuleType) -> None:
    """The pair's values are ready together, after the sine's or the cosine's latency,
    whichever is longer; what reads either waits for both."""
    body = chain.kernel_bodies(CHAIN, "p")["g"].replace(
        "    const double c = p_cos(q[2]);",
        "    double s, c;\n    p_sincos(q[2], &s, &c);",
    )
    assert "p_sincos" in body
    for sin, cos in ((1.0, 5.0), (7.0, 2.0)):
        lat = latencies(add=1.0, mul=10.0, div=100.0, sqrt=1000.0, sin=sin, cos=cos)
        assert (
            chain.critical_path(body, lat, "p")
            == max(sin, cos) + 10 + 1 + 10 + 1 + 1000 + 1 + 100 + 1
        )


@pytest.mark.parametrize("op", ["add", "mul", "div", "sqrt", "cos"])
def test_each_latency_counts_as_often_as_the_path_takes_it(chain: ModuleType, op: str) -> None:
    body = chain.kernel_bodies(CHAIN, "p")["g"]
    times = {"add": 4, "mul": 2, "div": 1, "sqrt": 1, "cos": 1}[op]
    assert chain.critical_path(body, latencies(**{op: 1.0}), "p") == times


@pytest.mark.parametrize(
    "line",
    [
        "    const double t = a > b ? a : b;",  # a branch
        "    for (k = 0; k < 3; ++k) {",  # a loop that is not over the legs
        "    const double t = p_forward_kinematics_kernel(params, q);",  # another kernel
        "    const double t = pow(a, 3);",  # a power gcc does not make a product
        "    t += 1.0;",  # not an assignment of a value
    ],
)
def test_code_that_is_not_straight_line_has_no_chain(chain: ModuleType, line: str) -> None:
    body = CHAIN.replace("    return P_OK;", line + "\n    return P_OK;")
    assert chain.critical_path(chain.kernel_bodies(body, "p")["g"], latencies(add=1.0), "p") is None


@pytest.mark.parametrize("variant", ["revolute", "prismatic"])
def test_the_forward_dynamics_chain_runs_through_its_long_operations(
    chain: ModuleType, repo_root: Path, variant: str
) -> None:
    """On its longest paths: the platform's angle (one sin or cos), then a leg's length and the
    conditioning guard's root (two sqrt), or the leg's 1/L and the LDL^T solve's three pivots
    (four divisions); the forward kinematics, a loop, has no chain."""
    source = (repo_root / "generated" / variant / "rpr3.c").read_text()
    bodies = chain.kernel_bodies(source, "rpr3")
    fd = bodies["forward_dynamics"]
    assert chain.critical_path(fd, latencies(sin=1.0, cos=1.0)) == 1
    assert chain.critical_path(fd, latencies(sqrt=1.0)) == 2
    assert chain.critical_path(fd, latencies(div=1.0)) == 4
    assert chain.critical_path(bodies["forward_kinematics"], latencies(add=1.0)) is None


# The control-loop examples (benchmarks/harness/examples.py): the programs' latency lines
# parsed, and the best of several runs kept with every run's tick p50.

REPORT = """\
failed calls: forward kinematics 0, jacobian 0, dynamics 0
latency forward kinematics: p50 {fk} ns, p99 521 ns, max 6362 ns
latency rest of the tick: p50 210 ns, p99 431 ns, max 4062455 ns
latency whole tick: p50 {tick} ns, p99 982 ns, max 4.06 ms
"""


@pytest.fixture(scope="module")
def examples(repo_root: Path) -> ModuleType:
    return harness(repo_root, "examples")


def test_latency_lines_are_parsed_in_their_units(examples: ModuleType) -> None:
    found = examples.parse(REPORT.format(fk=260, tick=461).replace("4.06 ms", "4062705 ns"))
    assert found["forward kinematics"] == {"p50": 260.0, "p99": 521.0, "max": 6362.0}
    assert found["whole tick"]["max"] == 4062705.0
    micro = examples.parse("latency whole tick: p50 9.57 us, p99 32.46 us, max 120.5 us\n")
    assert micro["whole tick"] == {"p50": 9570.0, "p99": 32460.0, "max": 120500.0}
    # a line in mixed units is not a latency line
    assert examples.parse(REPORT.format(fk=260, tick=461)).keys() == {
        "forward kinematics",
        "rest of the tick",
    }


def test_the_run_with_the_lowest_tick_p50_is_kept_with_every_run(examples: ModuleType) -> None:
    runs = [examples.parse(REPORT.format(fk=fk, tick=tick).replace("4.06 ms", "5000 ns"))
            for fk, tick in [(321, 601), (251, 461), (300, 531)]]  # fmt: skip
    best = examples.best_run(runs)
    assert best["whole tick"]["p50"] == 461.0
    assert best["forward kinematics"]["p50"] == 251.0  # that run's, not the lowest of each
    assert best["runs"] == [601.0, 461.0, 531.0]


def test_the_runs_go_round_the_cases(examples: ModuleType) -> None:
    """Each case runs ``runs`` times, and between two runs of one case every other case runs
    once, so that a slow spell of the shared machine spoils at most one run of each."""
    cases = [("prismatic", "rectilinear"), ("prismatic", "rotation"), ("revolute", "rotation")]
    order = examples.rounds(cases, 3)
    for case in cases:
        at = [k for k, c in enumerate(order) if c == case]
        assert len(at) == 3
        assert all(b - a == len(cases) for a, b in itertools.pairwise(at))


# A spatial forward dynamics calls the inverse dynamics' kernel k + 1 times (once, then in a
# loop over the unit accelerations); a tracked forward kinematics evaluates its kinematics once,
# then in Newton steps that stop early (its floor: one step, two evaluations).

CALLER = """
static int p_inner_kernel(const double *restrict params, double *restrict out)
{
    out[0] = sqrt(params[0]) + p_atan2(params[1], params[2]);
    return 0;
}

static int p_fd_kernel(const double *restrict params, double *restrict out)
{
    int j;
    status = p_inner_kernel(params, out);
    for (j = 0; j < 6; ++j) {
        status = p_inner_kernel(params, out);
    }
    return 0;
}

static int p_fk_kernel(const double *restrict params, double *restrict out)
{
    int iter;
    int h;
    if (p_inner_kernel(params, out) != 0) {
        return 1;
    }
    for (iter = 0; iter < 30; ++iter) {
        if (out[0] <= 1e-12) {
            break;
        }
        for (h = 0; h <= 30; ++h) {
            if (p_inner_kernel(params, out) == 0) {
                break;
            }
        }
    }
    return 0;
}
"""


def test_a_kernel_counts_the_calls_of_the_kernels_it_calls(cbench: ModuleType) -> None:
    calls = cbench.kernel_calls(CALLER, "p")
    assert calls["inner"] == {"sqrt": 1, "atan2": 1}
    assert calls["fd"] == {"sqrt": 7, "atan2": 7}  # once, then six turns of a constant loop
    assert calls["fk"] == {"sqrt": 2, "atan2": 2}  # loops that can stop early: one turn each


def test_a_kernel_that_is_not_straight_line_takes_the_chain_of_the_kernels_it_calls(
    cbench: ModuleType,
) -> None:
    lat = latencies(add=1.0, sqrt=10.0, atan2=100.0)
    found = cbench.chains(CALLER, "p", lat, ["inner", "fd", "fk"])
    assert found["inner/chain"] == {"min": 101.0}  # sqrt and atan2 side by side, then the add
    assert found["fd/chain"] == {"min": 101.0, "kernel": "inner"}
    assert found["fk/chain"] == {"min": 101.0, "kernel": "inner"}


@pytest.mark.parametrize("variant", ["ups_2", "rss2_1"])
def test_the_spatial_floors_follow_the_generated_program(
    cbench: ModuleType, chain: ModuleType, repo_root: Path, variant: str
) -> None:
    """The forward dynamics makes one call of the efforts' matrix and free terms
    (``efforts_matrix``, one pass), whose libm calls are those of the inverse dynamics' efforts
    at most; the tracked forward kinematics two evaluations of its kinematics; each has a chain
    floor, its callee's."""
    source = (repo_root / "generated" / variant / "rpr3.c").read_text()
    calls = cbench.kernel_calls(source, "rpr3")
    inverse = calls["inverse_dynamics"]
    assert inverse["sqrt"] > 0
    assert calls["forward_dynamics"] == calls["efforts_matrix"]
    assert all(0 < k <= inverse[f] for f, k in calls["efforts_matrix"].items())
    kinematics = calls["actuator_coordinates_jacobian"]
    assert calls["forward_kinematics"] == {f: 2 * k for f, k in kinematics.items()}
    found = cbench.chains(source, "rpr3", latencies(add=1.0), list(calls))
    assert found["forward_dynamics/chain"]["kernel"] == "efforts_matrix"
    assert found["forward_dynamics/chain"]["min"] == found["efforts_matrix/chain"]["min"]
    assert found["forward_kinematics/chain"]["kernel"] == "actuator_coordinates_jacobian"


def test_the_latency_probe_times_the_math_kernels_a_source_defines(
    cbench: ModuleType, repo_root: Path
) -> None:
    """A Delta's C has no sine: ``latency.c`` leaves it out rather than fail to link."""
    hexapod = cbench.latency_kernels(repo_root / "generated" / "ups_2" / "rpr3.c")
    delta = cbench.latency_kernels(repo_root / "generated" / "rss2_1" / "rpr3.c")
    assert {"sin", "cos", "atan2", "fmin", "rint"} <= hexapod
    assert "sin" not in delta
    assert "atan2" in delta
