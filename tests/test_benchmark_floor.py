"""The C benchmark's floor (``benchmarks/harness/cbench.py``): the libm calls a generated kernel
makes per sample. Nothing is timed or built here."""

from __future__ import annotations

import sys
from pathlib import Path
from types import ModuleType

import pytest


@pytest.fixture(scope="module")
def cbench(repo_root: Path) -> ModuleType:
    sys.path.insert(0, str(repo_root / "benchmarks"))
    try:
        from harness import cbench as module
    finally:
        sys.path.remove(str(repo_root / "benchmarks"))
    return module


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
