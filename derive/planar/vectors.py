"""Plane vectors as pairs of SymPy expressions: the few operations the derivation needs.

A vector is a tuple ``(x, y)``; ``perp`` turns it by +90 degrees (``z0 x v``), ``cross`` is the
z component of the cross product. Kept as tuples rather than ``sympy.Matrix`` so that the
derivation's expressions stay small and its code reads like the formulas.
"""

from __future__ import annotations

import sympy as sp

Vec = tuple[sp.Expr, sp.Expr]

ZERO: Vec = (sp.Integer(0), sp.Integer(0))


def vec(x: object, y: object) -> Vec:
    """``(x, y)`` with both entries sympified."""
    return (sp.sympify(x), sp.sympify(y))


def add(*vectors: Vec) -> Vec:
    """The sum of ``vectors``."""
    return (sp.Add(*(v[0] for v in vectors)), sp.Add(*(v[1] for v in vectors)))


def sub(a: Vec, b: Vec) -> Vec:
    """``a - b``."""
    return (a[0] - b[0], a[1] - b[1])


def scale(k: sp.Expr, a: Vec) -> Vec:
    """``k a``."""
    return (k * a[0], k * a[1])


def dot(a: Vec, b: Vec) -> sp.Expr:
    """``a . b``."""
    return a[0] * b[0] + a[1] * b[1]


def cross(a: Vec, b: Vec) -> sp.Expr:
    """``a x b`` (z component): ``a_x b_y - a_y b_x``."""
    return a[0] * b[1] - a[1] * b[0]


def perp(a: Vec) -> Vec:
    """``a`` turned by +90 degrees: ``(-a_y, a_x)``."""
    return (-a[1], a[0])


def norm2(a: Vec) -> sp.Expr:
    """``|a|^2``."""
    return a[0] ** 2 + a[1] ** 2


def rotate(cos_angle: sp.Expr, sin_angle: sp.Expr, a: Vec) -> Vec:
    """``rot(z, angle) a`` given the cosine and sine of the angle."""
    return (cos_angle * a[0] - sin_angle * a[1], sin_angle * a[0] + cos_angle * a[1])


def along(coords: Vec, reference: Vec) -> Vec:
    """The vector whose coordinates in the basis ``(reference, perp(reference))`` are
    ``coords``: ``coords[0] reference + coords[1] perp(reference)``."""
    return add(scale(coords[0], reference), scale(coords[1], perp(reference)))
