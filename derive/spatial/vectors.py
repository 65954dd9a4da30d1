"""3-vectors and rotations as SymPy column matrices, and naming them in a program."""

from __future__ import annotations

from typing import TypeAlias

import sympy as sp
from rpr3gen_derive.codegen.program import Program

Vec: TypeAlias = sp.Matrix


def vec(*components: object) -> Vec:
    return sp.Matrix([sp.sympify(c) for c in components])


def dot(a: Vec, b: Vec) -> sp.Expr:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vec, b: Vec) -> Vec:
    return vec(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def rotation(axis: Vec, cos: sp.Expr, sin: sp.Expr) -> sp.Matrix:
    """Rodrigues: the rotation about the unit ``axis`` by the angle of ``cos``, ``sin``."""
    x, y, z = axis
    k = sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return cos * sp.eye(3) + sin * k + (1 - cos) * (axis * axis.T)


def inertia(entries: tuple[sp.Expr, ...]) -> sp.Matrix:
    """The tensor of ``(Ixx, Iyy, Izz, Ixy, Ixz, Iyz)``."""
    xx, yy, zz, xy, xz, yz = entries
    return sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


class Namer:
    """Defines the intermediates of a program under a common prefix (a leg's letter)."""

    def __init__(self, prog: Program, suffix: str, step: str) -> None:
        self.prog, self.suffix, self.step = prog, suffix, step

    def s(self, name: str, expr: sp.Expr) -> sp.Expr:
        return self.prog.define(f"{name}{self.suffix}", sp.sympify(expr), self.step)

    def v(self, name: str, v: Vec) -> Vec:
        return vec(*(self.s(f"{name}{a}", v[k]) for k, a in enumerate("xyz")))

    def m(self, name: str, m: sp.Matrix) -> sp.Matrix:
        return sp.Matrix(3, 3, lambda i, j: self.s(f"{name}{i + 1}{j + 1}", m[i, j]))
