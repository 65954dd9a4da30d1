"""The generated C's math kernels (sin, cos, atan2, rint, fmin, fmax) over their whole domain.

``tests/c_math_kernels.c`` includes the generated source and compares every kernel with the C
library: dense sweeps, neighbours of multiples of pi/2, every binade (subnormals too), uniform
bit patterns (mostly huge arguments, through the Payne-Hanek reduction) and every pair of special
values. The documented accuracy (derive/codegen/mathkernels.py) is what is asserted.
A few hard arguments are checked against mpmath's correctly rounded values instead, where the
C library itself is off (glibc's cos of the hardest double for reduction is 8 ulp off).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import mpmath
import numpy as np
import pytest

from rpr3gen import cbackend

#: Largest distance from glibc, in ulps, that the kernels document.
DOCUMENTED = {"sin": 1, "cos": 1, "atan2": 2, "rint": 0, "fmin": 0, "fmax": 0}


#: Where the math kernels begin and end in the generated source: the first lines of
#: derive/codegen/backends/c/templates/mathkernels.c.jinja and of what follows it.
KERNELS = ("/* Math kernels.", "/* The batch functions run blocks")


def _kernels_only(source: str) -> str:
    """The generated source's includes and math kernels, as they are, without the generated
    functions after them: the kernels compile alone in a fraction of a second, where the
    whole source takes seven at -O3."""
    head = source[: source.index("#include <stddef.h>\n")] + "#include <stddef.h>\n\n"
    start, end = (source.index(marker) for marker in KERNELS)
    assert start < end
    return head + source[start:end]


@pytest.fixture(scope="module")
def harness(repo_root: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """tests/c_math_kernels.c built with the runtime's flags (the first extras it accepts),
    on the revolute variant's kernels (the ``rpr3.c`` it includes is the kernels alone)."""
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler is required by the test suite"
    folder = tmp_path_factory.mktemp("kernels")
    generated = repo_root / "generated" / "revolute"
    (folder / "rpr3.c").write_text(_kernels_only((generated / "rpr3.c").read_text()))
    exe = folder / "c_math_kernels"
    flags = [f for f in cbackend.CFLAGS if f not in ("-fPIC", "-shared")]
    for extra in cbackend.EXTRA_FLAGS:
        done = subprocess.run(
            [cc, *flags, *extra, "-Wall", "-Wextra", "-pedantic", "-Werror",
             "-I", str(folder), "-I", str(generated),
             str(repo_root / "tests" / "c_math_kernels.c"), "-o", str(exe), "-lm"],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        if done.returncode == 0:
            return exe
    raise AssertionError(done.stderr)


def test_kernels_against_libm_over_the_whole_domain(harness: Path) -> None:
    done = subprocess.run([str(harness)], capture_output=True, text=True, check=True)
    lines = dict(line.split(maxsplit=1) for line in done.stdout.splitlines())
    for name, limit in DOCUMENTED.items():
        worst, count, x, y = lines[name].split()
        assert int(count) >= 10**6, name
        assert float(worst) <= limit, f"{name}: {worst} ulp at x={x} (y={y})"
    assert lines["fast_mismatch"] == "0"  # the batch's fast path is the full kernel, bit for bit
    assert lines["special_mismatch"] == "0"  # NaN, infinities, signed zeros: as C99 says
    assert lines["finite_mismatch"] == "0"  # the single call's finite test is isfinite's


def _ulps(got: float, want: mpmath.mpf) -> float:
    """Distance of a double from a real value, in units of the last place of the double nearest
    to it."""
    nearest = float(want)
    return float(abs(mpmath.mpf(got) - want) / np.spacing(abs(nearest)))


def test_hard_arguments_against_mpmath(harness: Path) -> None:
    rng = np.random.default_rng(15)
    xs = [
        float.fromhex("0x1.6ac5b262ca1ffp+849"),  # 6381956970095103 2^797: closest to n pi/2
        5.0e22,
        1.0e300,
        2.0**1023,
        2.0**20,
        np.nextafter(2.0**20, 0.0),
        *(k * np.pi / 2 for k in (1, 2, 3, 1000, 10**5, 2**19)),
        *rng.uniform(-(2.0**20), 2.0**20, 20),
        *(np.ldexp(rng.uniform(1, 2), int(e)) for e in rng.integers(20, 1024, 40)),
    ]
    text = "\n".join(float(x).hex() for x in xs) + "\n"
    done = subprocess.run(
        [str(harness), "eval"], input=text, capture_output=True, text=True, check=True
    )
    with mpmath.workdps(1200):  # enough digits of pi to reduce 2^1023 exactly enough
        for line in done.stdout.splitlines():
            x, s, c = (float.fromhex(v) for v in line.split())
            exact = mpmath.mpf(x)
            assert _ulps(s, mpmath.sin(exact)) <= 1.0, (x.hex(), "sin")
            assert _ulps(c, mpmath.cos(exact)) <= 1.0, (x.hex(), "cos")


def test_polynomials_are_the_remez_fits() -> None:
    from rpr3gen_derive.codegen import mathkernels, minimax

    fits = minimax.fits()
    for name, table in (("sin", mathkernels.SIN), ("cos", mathkernels.COS),
                        ("atan", mathkernels.ATAN)):  # fmt: skip
        assert fits[name].error < 2.0**-56, name  # below half an ulp: the rounding dominates
        assert np.allclose(fits[name].coefficients, table, rtol=1e-12, atol=0.0), name


def test_estrin_is_the_polynomial() -> None:
    from rpr3gen_derive.codegen import mathkernels

    for coefficients in (mathkernels.SIN, mathkernels.ATAN, (1.0, 2.0, 3.0)):
        text = mathkernels.estrin(coefficients, "z")  # C, and Python too: numbers, +, *, ()
        for z in (0.0, 0.3, -0.7, 1.5):
            scope = {"z": z, **{f"z{p}": z**p for p in mathkernels.powers(len(coefficients))}}
            want = sum(c * z**k for k, c in enumerate(coefficients))
            assert eval(text, scope) == pytest.approx(want, rel=1e-14, abs=1e-300)


def test_the_reduction_constants_are_pi_over_2_in_exact_parts() -> None:
    """The Cody-Waite parts that the C kernel and the NumPy ``_sincos`` share: the first three
    have at most 33 significant bits (so n times each is exact for |n| < 2^20), each is pi/2's
    next piece (under an ulp of what is left), and the four sum to pi/2 within 2^-155; 2/pi is
    the nearest double."""
    from rpr3gen_derive.codegen import mathkernels

    parts = [float.fromhex(h) for h in mathkernels.PI_OVER_2_PARTS]
    with mpmath.workdps(80):
        left = mpmath.pi / 2
        for k, part in enumerate(parts):
            mantissa, _ = mpmath.mpf(part).man_exp
            if k < 3:
                assert int(abs(mantissa)).bit_length() <= 33, k
            assert abs(left - part) < abs(part) * 2.0**-32, k  # the next 33 bits, or the rest
            left -= part
        assert abs(left) < 2.0**-155
        assert float(mathkernels.TWO_OVER_PI) == float(2 / mpmath.pi)
    for part in parts[:3]:  # n * part is exact for |n| < 2^20: the product rounds to itself
        assert float(mpmath.mpf(2**20 - 1) * part) == (2**20 - 1) * part
