"""The generated C's own math kernels: ``sin``, ``cos``, ``atan2``, ``rint``, ``fmin``, ``fmax``.

glibc's ``sin``, ``cos`` and ``atan2`` are calls the compiler never vectorises (they may set
``errno``; glibc's vector versions need ``-ffast-math``), and ``nearbyint``, ``fmin``, ``fmax``
are calls on plain x86-64. The generated C therefore evaluates them with ``static inline``
functions of its own (``backends/c/templates/mathkernels.c.jinja``), branch-free, so that a
batch loop runs in SIMD lanes; the single-sample functions call the same kernels, so a sample
gets the same bits from both. Accuracy, measured against glibc over the whole domain by
``tests/test_c_math_kernels.py``: ``sin``, ``cos`` within 1 ulp, ``atan2`` within 2 ulp;
``rint``, ``fmin``, ``fmax`` exact.

- ``sin``, ``cos``: ``x = n pi/2 + r``, ``|r| <= pi/4``, by Cody-Waite reduction with pi/2 in
  three 33-bit parts and a 53-bit tail (exact products for ``|n| < 2^20``, i.e. ``|x| < 2^20``),
  ``r`` kept as a double-double; then ``sin(r) = r + r^3 S(r^2)``, ``cos(r) = 1 - r^2/2 + r^4
  C(r^2)`` and the quadrant ``n mod 4`` picks and signs them. Beyond ``2^20`` (and only in the
  single-sample code, behind a branch) a Payne-Hanek reduction with 24-bit chunks of 2/pi,
  exact in double arithmetic, gives ``r`` for any finite x. The batch uses the fast path only:
  it flags a sample with a larger argument and recomputes that sample with the single-sample
  kernel.
- ``atan2(y, x)``: ``t = min(|x|, |y|) / max(|x|, |y|)``, or ``(t - 1) / (t + 1)`` past
  ``tan(pi/8)``, then ``atan(t) = t + t^3 A(t^2)`` and the octant's multiple of pi/4.
- the polynomials S, C, A are minimax in relative error (:mod:`.minimax`, the Remez exchange).

Every kernel is written for ``-std=c99`` without FMA contraction (ISO C's default); it compiles
and is exact-as-documented at any optimisation level, and vectorises with ``-O3
-fno-math-errno -fno-trapping-math`` (no ``-ffast-math``: no value changes).
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import cache
from typing import Any

import mpmath
import sympy as sp
from rpr3gen_derive.codegen.functions import wrap_angle

#: Minimax coefficients (:func:`.minimax.fits`, rounded to double), lowest degree first.
SIN = (
    -0.1666666666666663,
    0.008333333333322118,
    -0.0001984126982958954,
    2.7557313621385676e-06,
    -2.5050747762850183e-08,
    1.5896230157212985e-10,
)
COS = (
    0.041666666666666595,
    -0.0013888888888873056,
    2.4801587288851704e-05,
    -2.755731417929674e-07,
    2.0875700841974726e-09,
    -1.1358536521387451e-11,
)
ATAN = (
    -0.333333333333332,
    0.19999999999953247,
    -0.14285714280166595,
    0.11111110782156533,
    -0.09090897725292857,
    0.07692059718124193,
    -0.06663099211313199,
    0.05847859326100567,
    -0.05039190655665308,
    0.03806214555561284,
    -0.017905045528408655,
)
#: 2/pi, rounded: x 2/pi gives the fast reduction's n.
TWO_OVER_PI = "0.6366197723675814"
#: pi/2 in the fast reduction's four parts (hex, exact): three of 33 bits, so that n times each
#: is exact for |n| < 2^20, and the rest rounded to double. The C kernel and the NumPy module's
#: ``_sincos`` both read them from here.
PI_OVER_2_PARTS = (
    "0x1.921fb544p+0",
    "0x1.0b4611a6p-34",
    "0x1.3198a2ep-69",
    "0x1.b839a252049c1p-104",
)
#: The fast reduction's range: |x| < 2^20, so that n |x| 2/pi| < 2^20 and n * (33-bit part) is
#: exact.
FAST_LIMIT = "0x1p20"
#: Chunks of 2/pi in the Payne-Hanek table: three leading zeros (exponents down to 2^20), then
#: enough for the largest exponent and 8 digits past it, padded to index & 63 plus 9.
TABLE_SIZE = 73


@cache
def two_over_pi_chunks(count: int = TABLE_SIZE) -> tuple[int, ...]:
    """``(0, 0, 0, C_0, C_1, ...)``: 2/pi = sum C_k 2^(-24 (k + 1)), each C_k a 24-bit integer."""
    with mpmath.workdps(count * 8 + 50):
        value = 2 / mpmath.pi
        chunks = [0, 0, 0]
        while len(chunks) < count:
            value *= 2**24
            chunk = int(mpmath.floor(value))
            chunks.append(chunk)
            value -= chunk
    return tuple(chunks)


def literal(value: float) -> str:
    """A double as a C literal that reads back exactly (Python's shortest repr)."""
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


def horner(coefficients: Iterable[float], variable: str) -> str:
    """``c0 + z * (c1 + z * (...))`` in C."""
    terms = [literal(c) for c in coefficients]
    text = terms[-1]
    for term in reversed(terms[:-1]):
        text = f"{term} + {variable} * ({text})"
    return text


def estrin(coefficients: Iterable[float], variable: str) -> str:
    """``sum c_k z^k`` in C by Estrin's scheme, with ``{variable}2``, ``{variable}4``... the
    powers ``z^2``, ``z^4``... (which the caller defines): pairs ``c_2i + c_2i+1 z`` combined
    by powers of ``z^2``, a dependency chain of log2(n) steps where Horner's is n, so a single
    call waits less on the multiply-add latency."""
    terms = [literal(c) for c in coefficients]
    level = [
        f"({terms[k]} + {variable} * {terms[k + 1]})" if k + 1 < len(terms) else terms[k]
        for k in range(0, len(terms), 2)
    ]
    power = 2
    while len(level) > 1:
        level = [
            f"({level[k]} + {variable}{power} * {level[k + 1]})" if k + 1 < len(level) else level[k]
            for k in range(0, len(level), 2)
        ]
        power *= 2
    return level[0]


def powers(count: int) -> list[int]:
    """The powers of z that :func:`estrin` uses for ``count`` coefficients: 2, 4, ..."""
    found, power, width = [], 2, (count + 1) // 2
    while width > 1:
        found.append(power)
        power *= 2
        width = (width + 1) // 2
    return found


def used(exprs: Iterable[sp.Expr]) -> set[str]:
    """The kernels printing ``exprs`` needs: ``trig``, ``atan2``, ``rint``, ``minmax``."""
    found: set[str] = set()
    for expr in exprs:
        for node in sp.preorder_traversal(expr):
            if isinstance(node, (sp.sin, sp.cos)):
                found.add("trig")
            elif isinstance(node, sp.atan2):
                found.add("atan2")
            elif isinstance(node, wrap_angle):
                found.add("rint")
            elif isinstance(node, (sp.Min, sp.Max)):
                found.add("minmax")
    return found


def context(kernels: set[str]) -> dict[str, Any]:
    """What ``mathkernels.c.jinja`` renders, for the kernels in ``kernels``."""
    return {
        "kernels": kernels,
        "sin_poly": estrin(SIN, "z"),
        "cos_poly": estrin(COS, "z"),
        "trig_powers": powers(max(len(SIN), len(COS))),
        "atan_poly": estrin(ATAN, "z"),
        "atan_powers": powers(len(ATAN)),
        "fast_limit": FAST_LIMIT,
        "two_over_pi": TWO_OVER_PI,
        "pi_over_2": PI_OVER_2_PARTS,
        "table": [f"{c}.0" for c in two_over_pi_chunks()],
        "table_size": TABLE_SIZE,
    }
