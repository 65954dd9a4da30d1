"""Functions the printers of every backend know beyond SymPy's own."""

from __future__ import annotations

import sympy as sp


class wrap_angle(sp.Function):  # noqa: N801  (a function, named like sympy's)
    """An angle wrapped into [-pi, pi]: ``x - 2 pi round(x / 2 pi)``.

    Printed as ``x - 2 pi nearbyint(x / 2 pi)`` in C99 and with ``numpy.rint`` in NumPy (see the
    backends' printers); within an ulp or two of C99 ``remainder(x, 2 pi)``, and much cheaper.
    """

    nargs = 1

    def _eval_evalf(self, prec: int) -> sp.Expr:
        x = self.args[0].evalf(prec)
        two_pi = 2 * sp.pi.evalf(prec)
        return (x - two_pi * sp.floor(x / two_pi + sp.Rational(1, 2))).evalf(prec)


TWO_PI = "6.283185307179586"  # 2 pi, correctly rounded
INV_TWO_PI = "0.15915494309189535"  # 1 / (2 pi)
