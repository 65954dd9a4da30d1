"""A sine and a cosine of one argument as one ``PREFIX_sincos`` call
(``rpr3gen_derive.codegen.backends.c.sincos``): which statements pair, and that the committed
kernels use it.

That the pair gives the bits of the two calls (the same function computes both) is tested on
every function by ``test_c_backend.py`` and ``test_planar_runtime.py``: single calls against the
batch, whose loops call the kernels' branch-free ``PREFIX_sin_fast`` and ``PREFIX_cos_fast``.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from rpr3gen_derive.codegen.backends.c.sincos import pair


def test_a_sine_and_a_cosine_of_one_argument_become_one_call_where_the_first_stood() -> None:
    lines = [
        "    const double c = p_cos(phi);",
        "    const double u = 2.0*x;",
        "    const double s = p_sin(phi);",
        "    const double v = s*c;",
    ]
    assert pair(lines, "p") == [
        "    double s, c;",
        "    p_sincos(phi, &s, &c);",
        "    const double u = 2.0*x;",
        "    const double v = s*c;",
    ]


def test_the_sine_first_pairs_as_well() -> None:
    lines = ["    const double s = p_sin(a);", "    const double c = p_cos(a);"]
    assert pair(lines, "p") == ["    double s, c;", "    p_sincos(a, &s, &c);"]


@pytest.mark.parametrize(
    "lines",
    [
        # two arguments
        ["    const double c = p_cos(a);", "    const double s = p_sin(b);"],
        # two sines
        ["    const double s = p_sin(a);", "    const double t = p_sin(a);"],
        # another prefix's kernels
        ["    const double c = q_cos(a);", "    const double s = q_sin(a);"],
        # an argument that is not a name
        ["    const double c = p_cos(a + b);", "    const double s = p_sin(a + b);"],
        # one in a lane loop, one after it: different blocks
        [
            "    for (i = 0; i < 4; ++i) {",
            "        const double c = p_cos(a);",
            "    }",
            "    const double s = p_sin(a);",
        ],
        # two loops' bodies: the first loop ends between them
        [
            "    for (i = 0; i < 4; ++i) {",
            "        const double c_i = p_cos(a);",
            "    }",
            "    for (i = 0; i < 4; ++i) {",
            "        const double s_i = p_sin(a);",
            "    }",
        ],
    ],
)
def test_statements_that_are_not_one_blocks_pair_stay_as_they_are(lines: list[str]) -> None:
    assert pair(lines, "p") == lines


def test_a_pair_inside_one_loop_body_is_paired_there() -> None:
    lines = [
        "    for (i = 0; i < 4; ++i) {",
        "        const double c_i = p_cos(t_i);",
        "        const double s_i = p_sin(t_i);",
        "    }",
    ]
    assert pair(lines, "p") == [
        "    for (i = 0; i < 4; ++i) {",
        "        double s_i, c_i;",
        "        p_sincos(t_i, &s_i, &c_i);",
        "    }",
    ]


@pytest.mark.parametrize("variant", ["revolute", "prismatic", "rrr_1"])
def test_no_committed_kernel_computes_a_sincos_twice(repo_root: Path, variant: str) -> None:
    """The single-sample kernels call ``rpr3_sin`` or ``rpr3_cos`` nowhere (each has its angles'
    pairs), and the inverse dynamics computes the platform's angle's pair once."""
    source = (repo_root / "generated" / variant / "rpr3.c").read_text()
    calls = re.findall(r"= rpr3_(sin|cos)\((\w+)\);", source)
    assert calls == []
    kernel = source[source.index("static int rpr3_inverse_dynamics_kernel(") :]
    kernel = kernel[: kernel.index("\n}\n")]
    assert kernel.count("rpr3_sincos(phi, &sin_phi, &cos_phi);") == 1
