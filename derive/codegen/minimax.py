"""Minimax polynomials of the math kernels (:mod:`.mathkernels`), by the Remez exchange.

The generated C evaluates ``sin``, ``cos`` and ``atan2`` with its own branch-free kernels so that
the compiler can vectorise the batch loops (glibc's ``sin`` may set ``errno`` and is never
vectorised without ``-ffast-math``). Their polynomials are the best approximations, in
relative error, of degree n in ``z = r**2`` on the kernels' reduced intervals:

- ``sin(r) = r + r**3 S(z)`` on ``|r| <= pi/4``;
- ``cos(r) = 1 - z/2 + z**2 C(z)`` on ``|r| <= pi/4``;
- ``atan(t) = t + t**3 A(z)`` on ``0 <= t <= tan(pi/8)``.

Run ``python -m rpr3gen_derive.codegen.minimax`` to recompute them (mpmath, 50
digits); :mod:`.mathkernels` holds the result, rounded to double, and a test checks that the two
agree. Nothing here runs at generation time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeAlias

import mpmath as mp

Real: TypeAlias = Any  # an mpmath number


@dataclass(frozen=True)
class Fit:
    """A minimax fit: coefficients of ``P(z) = sum c[j] z**j`` and its weighted error bound."""

    coefficients: tuple[float, ...]
    error: float  # max |w(z) (P(z) - f(z))| over the interval, at the working precision


def _error(
    f: Callable[[Real], Real], weight: Callable[[Real], Real], coefficients: list[Real]
) -> Callable[[Real], Real]:
    """The weighted error ``z -> weight(z) (P(z) - f(z))`` of a polynomial."""
    return lambda z: weight(z) * (mp.polyval(coefficients[::-1], z) - f(z))


def remez(
    f: Callable[[Real], Real],
    weight: Callable[[Real], Real],
    a: float,
    b: float,
    degree: int,
    iterations: int = 30,
    grid: int = 4000,
) -> Fit:
    """The polynomial of ``degree`` minimising ``max |weight(z) (P(z) - f(z))|`` on [a, b]."""
    lo, hi = mp.mpf(a), mp.mpf(b)
    count = degree + 2
    reference = [
        (lo + hi) / 2 - (hi - lo) / 2 * mp.cos(mp.pi * k / (count - 1)) for k in range(count)
    ]
    points = [lo + (hi - lo) * k / grid for k in range(grid + 1)]
    coefficients: list[Real] = []
    level = mp.mpf(0)
    for _ in range(iterations):
        rows = [
            [z**j for j in range(degree + 1)] + [(-1) ** i / weight(z)]
            for i, z in enumerate(reference)
        ]
        solution = mp.lu_solve(mp.matrix(rows), mp.matrix([f(z) for z in reference]))
        coefficients = [solution[j] for j in range(degree + 1)]
        level = abs(solution[degree + 1])
        error = _error(f, weight, coefficients)
        values = [error(z) for z in points]
        # One extremum per run of equal sign, refined on a finer local grid.
        extrema: list[tuple[Real, Real]] = []
        for k, value in enumerate(values):
            if extrema and mp.sign(extrema[-1][1]) == mp.sign(value):
                if abs(value) > abs(extrema[-1][1]):
                    extrema[-1] = (points[k], value)
            else:
                extrema.append((points[k], value))
        refined = []
        step = (hi - lo) / grid
        for z, _ in extrema:
            fine = [min(hi, max(lo, z + step * (j - 50) / 50)) for j in range(101)]
            best = max(fine, key=lambda p: abs(error(p)))
            refined.append((best, error(best)))
        while len(refined) > count:  # drop the smaller end extremum
            refined.pop(0 if abs(refined[0][1]) < abs(refined[-1][1]) else -1)
        worst = max(abs(v) for _, v in refined)
        reference = [z for z, _ in refined]
        if len(reference) < count:
            raise ArithmeticError("the error does not equioscillate: raise the grid")
        if worst - level <= level * mp.mpf("1e-6"):
            break
    return Fit(tuple(float(c) for c in coefficients), float(worst))


def _sin_fit() -> Fit:
    def g(z: Real) -> Real:  # (sin r - r) / r**3
        if z == 0:
            return mp.mpf(-1) / 6
        r = mp.sqrt(z)
        return (mp.sin(r) - r) / r**3

    def w(z: Real) -> Real:  # relative error of sin: r**3 / sin r
        if z == 0:
            return mp.mpf(0)
        r = mp.sqrt(z)
        return r**3 / mp.sin(r)

    return remez(g, w, 1e-9, float((mp.pi / 4) ** 2), 5)


def _cos_fit() -> Fit:
    def g(z: Real) -> Real:  # (cos r - 1 + z / 2) / z**2
        if z == 0:
            return mp.mpf(1) / 24
        return (mp.cos(mp.sqrt(z)) - 1 + z / 2) / z**2

    def w(z: Real) -> Real:
        return z**2 / mp.cos(mp.sqrt(z))

    return remez(g, w, 1e-9, float((mp.pi / 4) ** 2), 5)


def _atan_fit() -> Fit:
    def g(z: Real) -> Real:  # (atan t - t) / t**3
        if z == 0:
            return mp.mpf(-1) / 3
        t = mp.sqrt(z)
        return (mp.atan(t) - t) / t**3

    def w(z: Real) -> Real:
        if z == 0:
            return mp.mpf(0)
        t = mp.sqrt(z)
        return t**3 / mp.atan(t)

    return remez(g, w, 1e-9, float(mp.tan(mp.pi / 8) ** 2), 10)


FITS: dict[str, Callable[[], Fit]] = {"sin": _sin_fit, "cos": _cos_fit, "atan": _atan_fit}


def fits() -> dict[str, Fit]:
    """Every kernel's fit, by name."""
    with mp.workdps(50):
        return {name: fit() for name, fit in FITS.items()}


def main() -> None:
    for name, fit in fits().items():
        print(f"{name}: max relative error {fit.error:.3e} (2^{float(mp.log(fit.error, 2)):.1f})")
        for c in fit.coefficients:
            print(f"    {c!r},")


if __name__ == "__main__":
    main()
