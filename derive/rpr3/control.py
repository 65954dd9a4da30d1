"""The control model of the 3-RPR robot: actuator Jacobian, task-space dynamics, forward kinematics.

Everything here appends named assignments to a :class:`~rpr3gen_derive.codegen.program.Program`,
as the inverse dynamics does, so that the code-generation engine can turn it into NumPy and C.

- Actuator coordinates ``qa`` (:data:`qa`): ``phi10_A..C`` (revolute actuation) or
  ``lambda21_A..C`` (prismatic), measured from the central configuration; actuator efforts
  ``tau`` (:data:`tau`): ``m10_A..C`` or ``f21z_A..C`` (conventions.md).
- :func:`actuator_jacobian` and :func:`jacobian_rate_term`: ``qa' = J q'``,
  ``qa'' = J q'' + J' q'``, by differentiating the leg kinematics of eqs. (6) and (9).
- :func:`task_space_dynamics`: ``M q'' + c = J^T tau``, from the virtual-work derivation of the
  loads (eqs. 10-17), which is affine in ``q''``.
- :func:`forward_dynamics`: ``q'' = M^-1 (J^T tau - c)`` by an explicit LDL^T solve.
- The direct kinematics (every assembly mode) is in :mod:`.direct_kinematics`.

The numeric side (all modes from the sextic, tracked Newton FK) is in the runtime
(``src/rpr3gen/control.py``) and the generated C (``templates/forward_kinematics.c.jinja``); its
NumPy prototype is ``tests/fk_reference.py``. See ``docs/control-model.md`` for the mathematics
and the operation counts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.derivation import ACTUATIONS, derive
from rpr3gen_derive.rpr3.dynamics import BodyMotion, LegWrenches, leg_wrenches, required_wrench
from rpr3gen_derive.rpr3.frames import u3
from rpr3gen_derive.rpr3.kinematics import LegKinematics, leg_kinematics, platform_rotation
from rpr3gen_derive.rpr3.symbols import LEGS, PARAM_NAMES

STEP_JACOBIAN = "actuator Jacobian, d qa / d q, from eq. (6)"
STEP_RATE = "actuator accelerations at zero platform acceleration, eq. (9)"
STEP_TANGENT = "loads differentiated with respect to the platform acceleration, eqs. (10)-(17)"
STEP_BIAS = "loads at zero platform acceleration, eqs. (10)-(17)"
STEP_TASK = "task-space dynamics, M q'' + c = J^T tau"
STEP_FORWARD = "forward dynamics, LDL^T solve of M q'' = J^T tau - c"
STEP_VELOCITY = "platform velocity from the actuator rates, J q' = qa'"

QA_NAMES: tuple[str, ...] = tuple(f"qa_{leg}" for leg in LEGS)
TAU_NAMES: tuple[str, ...] = tuple(f"tau_{leg}" for leg in LEGS)

#: Measured actuator coordinates (rad or m) and commanded actuator efforts (N m or N), inputs.
qa = sp.Matrix([sp.Symbol(name, real=True) for name in QA_NAMES])
tau = sp.Matrix([sp.Symbol(name, real=True) for name in TAU_NAMES])


@dataclass(frozen=True)
class Actuator:
    """Names of the actuated joint's coordinate, rate, acceleration and effort (conventions.md)."""

    coordinate: str
    rate: str
    acceleration: str
    effort: str


ACTUATORS: dict[str, Actuator] = {
    "revolute": Actuator("phi10", "omega10", "eps10", "m10"),
    "prismatic": Actuator("lambda21", "v21", "gamma21", "f21z"),
}

#: Upper triangle of the symmetric 3 x 3 mass matrix, row-major.
UPPER: tuple[tuple[int, int], ...] = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


_RESERVED = (
    frozenset(PARAM_NAMES)
    | frozenset(s.name for s in (*syms.q, *syms.qd, *syms.qdd, *qa, *tau))
    | frozenset(f"qa_dot_{leg}" for leg in LEGS)
)


class Builder:
    """Defines assignments in a program, reusing one that has the same right-hand side.

    An assignment of the same name and right-hand side is reused (so that the functions of this
    module can share a program in any order); with ``share``, so is one of another name (so that,
    e.g., the derivative of a velocity and of an acceleration by the same input is one symbol).
    """

    def __init__(self, prog: Program) -> None:
        self.prog = prog
        self.existing = prog.definitions()
        self.by_expr: dict[sp.Expr, sp.Symbol] = {}
        for symbol, expr in self.existing.items():
            self.by_expr.setdefault(expr, symbol)

    def define(self, name: str, expr: sp.Expr, step: str, share: bool = True) -> sp.Expr:
        expr = sp.sympify(expr)
        if name in _RESERVED:
            raise ValueError(f"{name!r} is an input or a parameter, not a name for an assignment")
        symbol = sp.Symbol(name, real=True)
        if symbol in self.existing:
            if self.existing[symbol] != expr:
                raise ValueError(f"{name} is already defined differently in the program")
            return symbol
        if share and expr in self.by_expr:
            return self.by_expr[expr]
        out = self.prog.define(name, expr, step)
        if out == symbol:
            self.existing[symbol] = expr
            self.by_expr.setdefault(expr, symbol)
        return out


# ----------------------------------------------------------------------------------------------
# The inverse-dynamics program, and differentiation of a program assignment by assignment.


@dataclass(frozen=True)
class Derivation:
    """The inverse-dynamics program of ``specs.derive`` with the structure the control model uses.

    ``kinematics`` and ``wrenches`` are the per-leg objects of eqs. (5)-(11); their symbols are
    assignments of ``program`` (same names, same expressions).
    """

    actuation: str
    program: Program
    outputs: dict[str, sp.Expr]
    kinematics: dict[str, LegKinematics]
    wrenches: dict[str, LegWrenches]


@cache
def inverse_dynamics(actuation: str) -> Derivation:
    """``specs.derive(actuation)`` (eqs. 5-17), with its leg kinematics and wrenches.

    The program is the one of ``specs.derive``; the leg objects are rebuilt by the same steps on
    a scratch program, which must reproduce the first assignments of it exactly (else the
    derivation changed under us, and this raises).
    """
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    program, outputs = derive(actuation)
    scratch = Program()
    cos_phi, sin_phi = platform_rotation(scratch)
    kinematics = {leg: leg_kinematics(scratch, leg, cos_phi, sin_phi) for leg in LEGS}
    wrenches = {
        leg: leg_wrenches(scratch, kinematics[leg], carries_platform=(leg == LEGS[0]))
        for leg in LEGS
    }
    prefix = program.assignments[: len(scratch.assignments)]
    if prefix != scratch.assignments:
        raise RuntimeError("specs.derive no longer starts with the leg kinematics and wrenches")
    return Derivation(actuation, program, outputs, kinematics, wrenches)


def include_inverse_dynamics(prog: Program, actuation: str) -> Derivation:
    """Append the inverse-dynamics program to ``prog`` (once) and return its structure.

    Assignments that ``prog`` already has with the same right-hand side are skipped, so the
    functions of this module can be called on one program in any order.
    """
    derivation = inverse_dynamics(actuation)
    bld = Builder(prog)
    for a in derivation.program.assignments:
        bld.define(a.symbol.name, a.expr, a.step, share=False)
    return derivation


def _needed(prog: Program, exprs: Sequence[sp.Expr]) -> set[sp.Symbol]:
    """The program symbols that ``exprs`` depend on, directly or through other assignments."""
    definitions = prog.definitions()
    needed: set[sp.Symbol] = set()
    stack = [s for e in exprs for s in sp.sympify(e).free_symbols]
    while stack:
        s = stack.pop()
        if s in needed or s not in definitions:
            continue
        needed.add(s)
        stack.extend(definitions[s].free_symbols)
    return needed


def _ordered(symbols: set[sp.Symbol]) -> list[sp.Symbol]:
    return sorted(symbols, key=lambda s: s.name)


#: A derivative in factored form: ``sum of coefficient * seed``, the seed a vector over ``wrt``.
Factored = list[tuple[sp.Expr, tuple[sp.Expr, ...]]]


def differentiate_factored(
    prog: Program, exprs: Sequence[sp.Expr], wrt: Sequence[sp.Symbol], step: str
) -> list[Factored]:
    """Forward-mode derivatives of ``exprs`` by ``wrt``, one assignment of ``prog`` at a time.

    The derivative of an assignment is kept as a sum over a few *seed* vectors with scalar
    coefficients: a seed is the vector of direct partial derivatives ``d_{name}_d_{var}`` of an
    assignment that uses ``wrt`` itself (e.g. the acceleration of A3 along a leg's normal, by
    ``q''``), and every later assignment only combines the coefficients of its arguments by the
    chain rule (``k_{name}__{seed}``, one scalar each, shared by all the variables). So a leg's
    whole chain of wrenches costs a few scalars, and its share of the mass matrix stays a rank-one
    product. Nothing is expanded down to the inputs.
    """
    wrt = list(wrt)
    needed = _needed(prog, exprs)
    bld = Builder(prog)
    seeds: list[tuple[str, tuple[sp.Expr, ...]]] = []
    seed_of: dict[tuple[sp.Expr, ...], int] = {}
    tangent: dict[sp.Symbol, dict[int, sp.Expr]] = {}

    def chain(expr: sp.Expr, name: str | None) -> dict[int, sp.Expr]:
        terms: dict[int, sp.Expr] = {}
        for a in _ordered(expr.free_symbols & tangent.keys()):
            partial = sp.diff(expr, a)
            for index, coeff in tangent[a].items():
                terms[index] = terms.get(index, sp.Integer(0)) + partial * coeff
        direct = [sp.diff(expr, var) for var in wrt]
        if any(d != 0 for d in direct):
            if name is None:
                vector = tuple(direct)
            else:
                vector = tuple(
                    bld.define(f"d_{name}_d_{var.name}", d, step)
                    for var, d in zip(wrt, direct, strict=True)
                )
            if vector not in seed_of:
                seed_of[vector] = len(seeds)
                seeds.append((name or f"seed{len(seeds)}", vector))
            index = seed_of[vector]
            terms[index] = terms.get(index, sp.Integer(0)) + 1
        return {i: c for i, c in terms.items() if c != 0}

    for a in list(prog.assignments):
        if a.symbol not in needed or not a.expr.free_symbols & (tangent.keys() | set(wrt)):
            continue
        terms = chain(a.expr, a.symbol.name)
        tangent[a.symbol] = {
            i: bld.define(f"k_{a.symbol.name}__{seeds[i][0]}", c, step) for i, c in terms.items()
        }
    out = []
    for expr in exprs:
        terms = chain(sp.sympify(expr), None)
        out.append([(c, seeds[i][1]) for i, c in sorted(terms.items())])
    return out


def expand_factored(factored: Factored, size: int) -> list[sp.Expr]:
    """The derivative vector ``sum_i coeff_i * seed_i`` of a factored derivative."""
    return [sum((c * seed[k] for c, seed in factored), sp.Integer(0)) for k in range(size)]


def differentiate(
    prog: Program, exprs: Sequence[sp.Expr], wrt: Sequence[sp.Symbol], step: str
) -> list[list[sp.Expr]]:
    """``d exprs[i] / d wrt[k]`` as a ``len(exprs) x len(wrt)`` table (see
    :func:`differentiate_factored`, which names the intermediate derivatives in ``prog``)."""
    factored = differentiate_factored(prog, exprs, wrt, step)
    return [expand_factored(f, len(wrt)) for f in factored]


def at_zero(
    prog: Program, exprs: Sequence[sp.Expr], variables: Sequence[sp.Symbol], suffix: str, step: str
) -> list[sp.Expr]:
    """``exprs`` with ``variables`` set to zero, as new assignments ``{name}{suffix}``.

    Only the assignments that depend on ``variables`` are copied; the rest are shared.
    """
    needed = _needed(prog, exprs)
    bld = Builder(prog)
    replace: dict[sp.Symbol, sp.Expr] = {v: sp.Integer(0) for v in variables}
    for a in list(prog.assignments):
        if a.symbol in needed and a.expr.free_symbols & replace.keys():
            replace[a.symbol] = bld.define(
                f"{a.symbol.name}{suffix}", a.expr.xreplace(replace), step
            )
    return [sp.sympify(e).xreplace(replace) for e in exprs]


def depends_on(prog: Program, expr: sp.Expr, variables: Sequence[sp.Symbol]) -> bool:
    """True when ``expr`` depends on ``variables``, directly or through assignments."""
    definitions = prog.definitions()
    targets = set(variables)
    seen: set[sp.Symbol] = set()
    stack = list(sp.sympify(expr).free_symbols)
    while stack:
        s = stack.pop()
        if s in targets:
            return True
        if s in seen or s not in definitions:
            continue
        seen.add(s)
        stack.extend(definitions[s].free_symbols)
    return False


# ----------------------------------------------------------------------------------------------
# Actuator Jacobian and its rate term.


def _leg_rates(prog: Program, actuation: str, family: str) -> list[sp.Expr]:
    derivation = include_inverse_dynamics(prog, actuation)
    return [getattr(derivation.kinematics[leg], family) for leg in LEGS]


def actuator_jacobian(prog: Program, actuation: str) -> sp.Matrix:
    """``J = d qa / d q`` (3 x 3, one row per leg A, B, C), so that ``qa' = J q'``.

    The rows are the connectivity conditions (6) differentiated with respect to the platform
    velocity: with ``e`` the leg axis, ``n`` its normal, ``L = |A1A3|`` and ``s = A3 - G``,
    ``omega10 = n . vA3 / L`` gives the row ``(n_x, n_y, e . s) / L`` (revolute actuation) and
    ``v21 = e . vA3`` the row ``(e_x, e_y, s_x e_y - s_y e_x)`` (prismatic). Units: 1/m, 1
    (revolute); 1, m (prismatic). ``det J = 0`` is the parallel singularity.
    """
    rates = _leg_rates(prog, actuation, ACTUATORS[actuation].rate)
    rows = differentiate(prog, rates, list(syms.qd), STEP_JACOBIAN)
    return sp.Matrix(rows)


def jacobian_rate_term(prog: Program, actuation: str) -> sp.Matrix:
    """``J' q'`` (3-vector): the actuator accelerations of eq. (9) at zero platform acceleration.

    ``qa'' = J q'' + J' q'``: ``eps10`` (revolute) or ``gamma21`` (prismatic) of eq. (9), whose
    part free of ``q''`` is ``J' q'``, e.g. ``eps10 = (n . aA3 - 2 v21 omega10) / L``.
    """
    accelerations = _leg_rates(prog, actuation, ACTUATORS[actuation].acceleration)
    return sp.Matrix(at_zero(prog, accelerations, list(syms.qdd), "_qdd0", STEP_RATE))


# ----------------------------------------------------------------------------------------------
# Task-space dynamics and forward dynamics.


def _symmetric(prog: Program, name: str, entries: dict[tuple[int, int], sp.Expr]) -> sp.Matrix:
    """A symmetric matrix from its upper triangle, each entry named once as ``{name}{i}{j}``."""
    bld = Builder(prog)
    upper = {
        (i, j): bld.define(f"{name}{i + 1}{j + 1}", entries[i, j], STEP_TASK) for i, j in UPPER
    }
    return sp.Matrix(3, 3, lambda i, j: upper[min(i, j), max(i, j)])


def _effort_affine(prog: Program, actuation: str) -> tuple[sp.Matrix, sp.Matrix]:
    """``tau = A q'' + b``: the actuator loads of eqs. (12)-(17) split by their affinity in q''."""
    derivation = include_inverse_dynamics(prog, actuation)
    efforts = [derivation.outputs[f"{ACTUATORS[actuation].effort}_{leg}"] for leg in LEGS]
    A = sp.Matrix(differentiate(prog, efforts, list(syms.qdd), STEP_TANGENT))
    for entry in A:
        if depends_on(prog, entry, list(syms.qdd)):
            raise RuntimeError("the actuator loads are not affine in the platform acceleration")
    b = sp.Matrix(at_zero(prog, efforts, list(syms.qdd), "_qdd0", STEP_BIAS))
    return A, b


def _leg_wrench_components(
    prog: Program, derivation: Derivation
) -> dict[str, tuple[sp.Expr, sp.Expr]]:
    """Per leg, the moment about A1 (z0) and the axial force (e) that the leg's own two bodies
    require: ``M1_z`` and ``F2_z`` of the recursion (10)-(11) run without the platform.

    They are built by ``dynamics.leg_wrenches(..., carries_platform=False)`` on a scratch
    program; its assignments that ``prog`` already has are reused, and the few that differ there
    (leg A's chain carries the platform in the inverse dynamics) are substituted in place.
    """
    bld = Builder(prog)
    out = {}
    for leg in LEGS:
        scratch = Program()
        own = leg_wrenches(scratch, derivation.kinematics[leg], carries_platform=False)
        inline: dict[sp.Symbol, sp.Expr] = {}
        for a in scratch.assignments:
            expr = a.expr.xreplace(inline)
            known = bld.existing.get(a.symbol)
            if known is None:
                bld.define(a.symbol.name, expr, a.step, share=False)
            elif known != expr:
                inline[a.symbol] = expr
        out[leg] = (own.M[0][2].xreplace(inline), own.F[1][2].xreplace(inline))
    return out


def _platform_wrench() -> sp.Matrix:
    """The wrench the platform requires, at G in the world frame: ``(F_x, F_y, M_z)``.

    ``dynamics.required_wrench`` (inertia, weight and payload, as for every body of eqs. 10-11)
    applied to the platform about its centre G, whose velocity and acceleration are the inputs.
    """
    motion = BodyMotion(
        omega=syms.dphi * u3,
        eps=syms.ddphi * u3,
        gamma=sp.Matrix([syms.ddx, syms.ddy, 0]),
    )
    force, moment = required_wrench(
        motion,
        syms.m3,
        sp.zeros(3, 1),
        sp.diag(0, 0, syms.J3),
        syms.gravity,
        external_force=syms.payload_force,
        external_moment=syms.payload_moment,
    )
    return sp.Matrix([force[0], force[1], moment[2]])


def _virtual_powers(prog: Program, actuation: str) -> list[tuple[tuple[sp.Expr, ...], sp.Expr]]:
    """``J^T tau = sum_m row_m * w_m``: the virtual power of the required wrenches per unit twist.

    Give the platform a virtual twist ``e_k`` (principle of virtual work, as for eqs. 12-17). Leg
    i then turns by ``omega10 = J10_i e_k`` and slides by ``v21 = J21_i e_k`` (eq. 6), and its
    cylinder and piston absorb the power ``omega10 M1z_i + v21 F2z_i`` of their required wrenches
    (:func:`_leg_wrench_components`); the platform absorbs ``e_k . (F_x, F_y, M_z)`` of its own
    (:func:`_platform_wrench`). The actuators supply ``tau . J e_k``, so the sum is
    ``(J^T tau)_k`` whatever joints are actuated. ``J10``, ``J21`` are kept in factored form
    (seed vector times scalar), so each term is a row vector times one named scalar ``w_m``.
    """
    derivation = include_inverse_dynamics(prog, actuation)
    kinematics = derivation.kinematics
    bld = Builder(prog)
    rates = [kinematics[leg].omega10 for leg in LEGS] + [kinematics[leg].v21 for leg in LEGS]
    rows = differentiate_factored(prog, rates, list(syms.qd), STEP_JACOBIAN)
    wrenches = _leg_wrench_components(prog, derivation)
    terms: list[tuple[tuple[sp.Expr, ...], sp.Expr]] = []
    for i, leg in enumerate(LEGS):
        moment, force = wrenches[leg]
        for family, factored, load in (("10", rows[i], moment), ("21", rows[3 + i], force)):
            for k, (coeff, seed) in enumerate(factored):
                w = bld.define(f"w{family}_{leg}_{k}", coeff * load, STEP_TASK)
                terms.append((seed, w))
    platform = _platform_wrench()
    for k in range(3):
        unit = tuple(sp.Integer(int(j == k)) for j in range(3))
        terms.append((unit, bld.define(f"w3_{k + 1}", platform[k], STEP_TASK)))
    return terms


def task_space_dynamics(
    prog: Program, actuation: str, method: str = "virtual_power"
) -> tuple[sp.Matrix, sp.Matrix]:
    """``M`` (3 x 3, symmetric positive definite) and ``c`` (3) with ``M q'' + c = J^T tau``.

    The loads of the virtual-work derivation (eqs. 10-17) are affine in the platform
    acceleration, ``tau = A(q) q'' + b(q, q')``, so ``M = J^T A`` and ``c = J^T b`` (units: kg,
    kg m, kg m^2; N, N m). Two routes, equal to round-off (tested):

    - ``method="efforts"``: exactly that. ``A`` by differentiating the program of
      ``specs.derive`` assignment by assignment (:func:`differentiate`), ``b`` by setting
      ``q'' = 0`` in it (:func:`at_zero`), then ``J^T A``, ``J^T b``. It carries the closure
      solve of eq. (7) (``W^-1``, which ``J^T`` then undoes: ``W = -diag(L) J`` with revolute
      actuation, ``diag(L) J`` with prismatic).
    - ``method="virtual_power"`` (the default, about half the operations): ``J^T tau`` is the
      virtual power of the same required wrenches (``dynamics.required_wrench`` and the
      recursion 10-11 of each leg) in the unit platform twists, :func:`_virtual_powers`, so no
      closure matrix is inverted; then the same differentiation and zeroing. ``M`` and ``c``
      are those of the mechanism, the same for both actuations, and each leg adds a rank-one
      term per joint: ``M = diag(m3, m3, J3) + sum_i (K_i J10_i^T J10_i + m2 J21_i^T J21_i)``
      with ``K_i`` the inertia of cylinder and piston about A1.

    ``M`` is positive definite wherever every leg has positive length, parallel singularities
    included. Only its upper triangle is named (``M11 M12 M13 M22 M23 M33``); ``c`` is named
    ``bias1..3``.
    """
    if method == "efforts":
        A, b = _effort_affine(prog, actuation)
        J = actuator_jacobian(prog, actuation)
        mass = J.T * A
        bias = J.T * b
    elif method == "virtual_power":
        terms = _virtual_powers(prog, actuation)
        powers = [w for _, w in terms]
        slopes = differentiate_factored(prog, powers, list(syms.qdd), STEP_TANGENT)
        mass = sp.zeros(3, 3)
        for (row, _), slope in zip(terms, slopes, strict=True):
            column = expand_factored(slope, 3)
            for i, j in UPPER:
                mass[i, j] += row[i] * column[j]
        for entry in mass:
            if depends_on(prog, entry, list(syms.qdd)):
                raise RuntimeError("the generalized forces are not affine in q''")
        at_rest = at_zero(prog, powers, list(syms.qdd), "_qdd0", STEP_BIAS)
        bias = sp.zeros(3, 1)
        for (row, _), w0 in zip(terms, at_rest, strict=True):
            bias += sp.Matrix(row) * w0
    else:
        raise ValueError(f"method must be 'virtual_power' or 'efforts', got {method!r}")
    M = _symmetric(prog, "M", {(i, j): mass[i, j] for i, j in UPPER})
    bld = Builder(prog)
    c = sp.Matrix([bld.define(f"bias{k + 1}", bias[k], STEP_TASK) for k in range(3)])
    return M, c


def ldlt_solve(prog: Program, M: sp.Matrix, rhs: sp.Matrix, name: str, step: str) -> sp.Matrix:
    """Solve ``M x = rhs`` for a symmetric positive definite 3 x 3 ``M`` by ``M = L D L^T``.

    No square root; three divisions (the pivots ``D``). Every factor is a named assignment
    ``{name}_...``; only the upper triangle of ``M`` is read.
    """
    bld = Builder(prog)
    d1 = bld.define(f"{name}_d1", M[0, 0], step)
    inv_d1 = bld.define(f"{name}_inv_d1", 1 / d1, step)
    l21 = bld.define(f"{name}_l21", M[0, 1] * inv_d1, step)
    l31 = bld.define(f"{name}_l31", M[0, 2] * inv_d1, step)
    d2 = bld.define(f"{name}_d2", M[1, 1] - l21 * M[0, 1], step)
    inv_d2 = bld.define(f"{name}_inv_d2", 1 / d2, step)
    l32 = bld.define(f"{name}_l32", (M[1, 2] - l21 * M[0, 2]) * inv_d2, step)
    d3 = bld.define(f"{name}_d3", M[2, 2] - l31 * M[0, 2] - l32**2 * d2, step)
    inv_d3 = bld.define(f"{name}_inv_d3", 1 / d3, step)
    z1 = rhs[0]
    z2 = bld.define(f"{name}_z2", rhs[1] - l21 * z1, step)
    z3 = bld.define(f"{name}_z3", rhs[2] - l31 * z1 - l32 * z2, step)
    x3 = bld.define(f"{name}_x3", z3 * inv_d3, step)
    x2 = bld.define(f"{name}_x2", z2 * inv_d2 - l32 * x3, step)
    x1 = bld.define(f"{name}_x1", z1 * inv_d1 - l21 * x2 - l31 * x3, step)
    return sp.Matrix([x1, x2, x3])


def cofactor_solve(prog: Program, A: sp.Matrix, rhs: sp.Matrix, name: str, step: str) -> sp.Matrix:
    """Solve ``A x = rhs`` for a general 3 x 3 ``A`` by cofactors: ``x = adj(A) rhs / det A``.

    The entries of ``A`` are named first (``{name}_A11`` ...), so the adjugate multiplies names,
    and ``1 / det A`` is one division.
    """
    bld = Builder(prog)
    a = sp.Matrix(3, 3, lambda i, j: bld.define(f"{name}_A{i + 1}{j + 1}", A[i, j], step))
    adj = a.adjugate()
    det = bld.define(f"{name}_det", sum(a[0, j] * adj[j, 0] for j in range(3)), step)
    inv_det = bld.define(f"{name}_inv_det", 1 / det, step)
    return sp.Matrix(
        [
            bld.define(
                f"{name}_x{i + 1}", sum(adj[i, j] * rhs[j] for j in range(3)) * inv_det, step
            )
            for i in range(3)
        ]
    )


#: The actuator rates ``qa'``, inputs of :func:`platform_velocity`.
qa_dot = sp.Matrix([sp.Symbol(f"qa_dot_{leg}", real=True) for leg in LEGS])


def platform_velocity(prog: Program, actuation: str) -> sp.Matrix:
    """``q' = J^-1 qa'`` (3-vector): the platform velocity that the actuator rates produce."""
    J = actuator_jacobian(prog, actuation)
    return cofactor_solve(prog, J, qa_dot, "pv", STEP_VELOCITY)


def forward_dynamics(prog: Program, actuation: str) -> sp.Matrix:
    """``q'' = M^-1 (J^T tau - c)`` (3-vector), for the efforts :data:`tau`, by LDL^T.

    ``M``, ``c`` of :func:`task_space_dynamics` (default route) and the 3 x 3 solve of
    :func:`ldlt_solve`. Nothing here divides by ``det J``: the forward dynamics is defined at a
    parallel singularity too (the efforts just cannot push the platform along the singular
    direction); only a leg of zero length is singular. Units: m/s^2, m/s^2, rad/s^2.
    """
    M, c = task_space_dynamics(prog, actuation)
    J = actuator_jacobian(prog, actuation)
    rhs = J.T * tau - c
    bld = Builder(prog)
    rhs = sp.Matrix([bld.define(f"fd_rhs{k + 1}", rhs[k], STEP_FORWARD) for k in range(3)])
    return ldlt_solve(prog, M, rhs, "fd", STEP_FORWARD)
