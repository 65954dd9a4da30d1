"""The control model of any structure: actuator Jacobian, task-space dynamics, forward dynamics.

Everything here appends named assignments to a :class:`~rpr3gen_derive.codegen.program.Program`,
as the inverse dynamics does, so that the code-generation engine can turn it into NumPy and C.

- Actuator coordinates ``qa`` (:data:`~.symbols.qa`): the actuated joint's coordinate of legs A,
  B, C; actuator efforts ``tau`` (:data:`~.symbols.tau`): its effort (the paper's variants:
  ``phi10``/``m10`` or ``lambda21``/``f21z``).
- :func:`actuator_jacobian` and :func:`jacobian_rate_term`: ``qa' = J q'``,
  ``qa'' = J q'' + J' q'``, by differentiating the leg kinematics of eqs. (6) and (9).
- :func:`task_space_dynamics`: ``M q'' + c = J^T tau``, from the virtual power of the required
  wrenches of eqs. (10)-(11), which is affine in ``q''``.
- :func:`forward_dynamics`: ``q'' = M^-1 (J^T tau - c)`` by an explicit LDL^T solve.
- The direct kinematics (every assembly mode) is in :mod:`.direct_kinematics`.

See ``docs/control-model.md`` for the mathematics and the operation counts.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import outputs
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.calculus import (
    Builder,
    at_zero,
    cofactor_solve,
    depends_on,
    differentiate,
    differentiate_factored,
    expand_factored,
    ldlt_solve,
)
from rpr3gen_derive.planar.derivation import Derivation, derive
from rpr3gen_derive.planar.dynamics import leg_wrenches, platform_inertia, platform_wrench
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.structures import Structure, param_names

STEP_JACOBIAN = "actuator Jacobian, d qa / d q, from eq. (6)"
STEP_RATE = "actuator accelerations at zero platform acceleration, eq. (9)"
STEP_HESSIAN = "second derivatives of qa by the pose, from eq. (9)"
STEP_TANGENT = "loads differentiated with respect to the platform acceleration, eqs. (10)-(17)"
STEP_BIAS = "loads at zero platform acceleration, eqs. (10)-(17)"
STEP_TASK = "task-space dynamics, M q'' + c = J^T tau"
STEP_FORWARD = "forward dynamics, LDL^T solve of M q'' = J^T tau - c"
STEP_VELOCITY = "platform velocity from the actuator rates, J q' = qa'"

#: Upper triangle of the symmetric 3 x 3 mass matrix, row-major.
UPPER: tuple[tuple[int, int], ...] = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def reserved(structure: Structure) -> frozenset[str]:
    """Names no assignment may take: the structure's parameters and every input."""
    return frozenset(param_names(structure)) | syms.INPUT_NAMES


def builder(prog: Program, structure: Structure) -> Builder:
    """A :class:`~.calculus.Builder` on ``prog`` that refuses the structure's reserved names."""
    return Builder(prog, reserved(structure))


@cache
def inverse_dynamics(structure: Structure) -> Derivation:
    """The inverse-dynamics derivation of ``structure`` (eqs. 5-17), derived once per process."""
    return derive(structure)


def include_inverse_dynamics(prog: Program, structure: Structure) -> Derivation:
    """Append the inverse-dynamics program to ``prog`` (once) and return its structure.

    Assignments that ``prog`` already has with the same right-hand side are skipped, so the
    functions of this module can be called on one program in any order.
    """
    derivation = inverse_dynamics(structure)
    bld = builder(prog, structure)
    for a in derivation.program.assignments:
        bld.define(a.symbol.name, a.expr, a.step, share=False)
    return derivation


# ----------------------------------------------------------------------------------------------
# Actuator coordinates, Jacobian and its rate term.


def actuator_values(prog: Program, structure: Structure, which: str) -> list[sp.Expr]:
    """The actuated joint's coordinate (``"q"``), rate (``"qd"``) or acceleration (``"qdd"``)
    of legs A, B, C, from the inverse-dynamics program appended to ``prog``."""
    derivation = include_inverse_dynamics(prog, structure)
    a = structure.actuated - 1
    return [getattr(derivation.kinematics[leg], which)[a] for leg in LEGS]


def actuator_efforts(prog: Program, structure: Structure) -> list[sp.Expr]:
    """The actuator efforts of legs A, B, C (the inverse dynamics' actuator loads)."""
    derivation = include_inverse_dynamics(prog, structure)
    family = outputs.effort_family(structure)
    return [derivation.outputs[f"{family}_{leg}"] for leg in LEGS]


def actuator_jacobian(prog: Program, structure: Structure) -> sp.Matrix:
    """``J = d qa / d q`` (3 x 3, one row per leg A, B, C), so that ``qa' = J q'``.

    The rows are the connectivity conditions (6) differentiated with respect to the platform
    velocity: the actuated joint's rate of each leg, ``qd_a = (S^-1 (v_X3, phi'))_a``, is linear
    in ``q'``. ``det J = 0`` is the parallel singularity.
    """
    rates = actuator_values(prog, structure, "qd")
    return sp.Matrix(differentiate(prog, rates, list(syms.qd), STEP_JACOBIAN))


def jacobian_rate_term(prog: Program, structure: Structure) -> sp.Matrix:
    """``J' q'`` (3-vector): the actuator accelerations of eq. (9) at zero platform acceleration,
    so that ``qa'' = J q'' + J' q'``."""
    accelerations = actuator_values(prog, structure, "qdd")
    return sp.Matrix(at_zero(prog, accelerations, list(syms.qdd), "_qdd0", STEP_RATE))


#: The index pairs (j, k), j <= k, of the second derivatives d2 qa_i / dq_j dq_k, in order.
HESSIAN_PAIRS: tuple[tuple[int, int], ...] = UPPER


def actuator_hessian(prog: Program, structure: Structure) -> list[list[sp.Expr]]:
    """``H[i][p] = d2 qa_i / dq_j dq_k`` for the pairs ``(j, k)`` of :data:`HESSIAN_PAIRS`: the
    actuator coordinates' second derivatives by the pose, one row per leg A, B, C.

    ``J' q' = H[q', q']`` (eq. 9 at zero platform acceleration is a quadratic form in ``q'``),
    so ``H`` is half the second derivative of :func:`jacobian_rate_term` by ``q'``, which
    depends on the pose alone: the tracked forward kinematics evaluates it with ``qa`` and ``J``
    and forms its Chebyshev correction ``H[dq, dq]`` without another kernel on its chain.
    """
    rate = jacobian_rate_term(prog, structure)
    first = differentiate(prog, list(rate), list(syms.qd), STEP_HESSIAN)
    flat = [first[i][j] for i in range(3) for j in range(3)]
    second = differentiate(prog, flat, list(syms.qd), STEP_HESSIAN)
    return [[second[3 * i + j][k] / 2 for j, k in HESSIAN_PAIRS] for i in range(3)]


def platform_velocity(prog: Program, structure: Structure) -> sp.Matrix:
    """``q' = J^-1 qa'`` (3-vector): the platform velocity that the actuator rates produce."""
    J = actuator_jacobian(prog, structure)
    return cofactor_solve(prog, J, syms.qa_dot, "pv", STEP_VELOCITY)


# ----------------------------------------------------------------------------------------------
# Task-space dynamics and forward dynamics.


def _symmetric(prog: Program, name: str, entries: dict[tuple[int, int], sp.Expr]) -> sp.Matrix:
    """A symmetric matrix from its upper triangle, each entry named once as ``{name}{i}{j}``."""
    bld = Builder(prog)
    upper = {
        (i, j): bld.define(f"{name}{i + 1}{j + 1}", entries[i, j], STEP_TASK) for i, j in UPPER
    }
    return sp.Matrix(3, 3, lambda i, j: upper[min(i, j), max(i, j)])


def _effort_affine(prog: Program, structure: Structure) -> tuple[sp.Matrix, sp.Matrix]:
    """``tau = A q'' + b``: the actuator loads of eqs. (12)-(17) split by their affinity in q''."""
    efforts = actuator_efforts(prog, structure)
    A = sp.Matrix(differentiate(prog, efforts, list(syms.qdd), STEP_TANGENT))
    for entry in A:
        if depends_on(prog, entry, list(syms.qdd)):
            raise RuntimeError("the actuator loads are not affine in the platform acceleration")
    b = sp.Matrix(at_zero(prog, efforts, list(syms.qdd), "_qdd0", STEP_BIAS))
    return A, b


def _reusing(bld: Builder) -> Callable[[str, sp.Expr, str], sp.Expr]:
    """``define`` that reuses an assignment of the same name and right-hand side."""
    return lambda name, expr, step: bld.define(name, expr, step, share=False)


def _own_joint_powers(prog: Program, derivation: Derivation) -> dict[str, list[sp.Expr]]:
    """Per leg, the power per unit rate of each joint's own motion of the chain wrench of the
    leg's own two bodies (without the platform): ``M_j`` of a revolute joint, ``F_j . w_j`` of
    a prismatic one (eqs. 10-11 run without the platform; leg A's differ from the inverse
    dynamics', which carries it there)."""
    out = {}
    for leg in LEGS:
        kin = derivation.kinematics[leg]
        wrenches = derivation.wrenches[leg]
        if leg == LEGS[0]:
            wrenches = leg_wrenches(
                prog, kin, None, derivation.robot, tag="own", define=_reusing(Builder(prog))
            )
        powers = []
        for j in (1, 2, 3):
            w = wrenches.joints[j - 1]
            if kin.kinds[j - 1] == "R":
                powers.append(w.moment)
            else:
                axis = kin.pose.axes[j]
                powers.append(w.force[0] * axis[0] + w.force[1] * axis[1])
        out[leg] = powers
    return out


def _virtual_powers(
    prog: Program, structure: Structure
) -> list[tuple[str | None, tuple[sp.Expr, ...], sp.Expr]]:
    """``J^T tau = sum_m row_m * w_m``: the virtual power of the required wrenches per unit twist.

    Give the platform a virtual twist ``e_k`` (principle of virtual work, as for eqs. 12-17).
    Each leg's joints then move at ``qd_j = (S^-1 e_k)_j`` (eq. 6), and its two bodies absorb
    ``sum_j qd_j P_j``, ``P_j`` the power per unit rate of joint j's motion of the chain wrench
    of the leg's own bodies (:func:`_own_joint_powers`); the platform absorbs ``e_k . (F_x,
    F_y, M_z)`` of its own. The actuators supply ``tau . J e_k``, so the sum is ``(J^T tau)_k``
    whatever joints are actuated (the passive ones do no work). The joint rates are kept in
    factored form (seed vector times scalar), so each term is a row vector times one named
    scalar ``w_m``; each term comes with its leg (``None``: the platform's).
    """
    derivation = include_inverse_dynamics(prog, structure)
    bld = builder(prog, structure)
    rates = [derivation.kinematics[leg].qd[j] for leg in LEGS for j in range(3)]
    rows = differentiate_factored(prog, rates, list(syms.qd), STEP_JACOBIAN)
    powers = _own_joint_powers(prog, derivation)
    terms: list[tuple[str | None, tuple[sp.Expr, ...], sp.Expr]] = []
    for i, leg in enumerate(LEGS):
        for j in range(3):
            if powers[leg][j] == 0:
                continue
            for k, (coeff, seed) in enumerate(rows[3 * i + j]):
                w = bld.define(f"w{j + 1}_{leg}_{k}", coeff * powers[leg][j], STEP_TASK)
                terms.append((leg, seed, w))
    cos_phi, sin_phi = (sp.Symbol(n, real=True) for n in ("cos_phi", "sin_phi"))
    robot = derivation.robot
    platform = platform_wrench(robot, platform_inertia(robot, cos_phi, sin_phi))
    for k, value in enumerate((*platform.force, platform.moment)):
        unit = tuple(sp.Integer(int(j == k)) for j in range(3))
        terms.append((None, unit, bld.define(f"w3_{k + 1}", value, STEP_TASK)))
    return terms


#: A share of the task-space dynamics: of ``M`` (3 x 3, its upper triangle) and of ``c`` (3).
Share = tuple[sp.Matrix, sp.Matrix]


def _shares(prog: Program, structure: Structure) -> dict[str | None, Share]:
    """Each leg's share of ``M`` and ``c``, and the platform's (key ``None``): the virtual
    powers of :func:`_virtual_powers` differentiated by ``q''`` and at ``q'' = 0``, summed leg by
    leg. A leg's entries are named ``M11_A`` ... ``bias1_A`` ...: one expression for the three
    legs, which the C backend runs side by side (its lanes), so that ``M`` and ``c`` are sums of
    four terms each instead of one long scalar sum over every joint of every leg."""
    terms = _virtual_powers(prog, structure)
    powers = [w for _, _, w in terms]
    slopes = differentiate_factored(prog, powers, list(syms.qdd), STEP_TANGENT)
    at_rest = at_zero(prog, powers, list(syms.qdd), "_qdd0", STEP_BIAS)
    sums: dict[str | None, Share] = {}
    for (leg, row, _), slope, w0 in zip(terms, slopes, at_rest, strict=True):
        mass, bias = sums.setdefault(leg, (sp.zeros(3, 3), sp.zeros(3, 1)))
        column = expand_factored(slope, 3)
        for i, j in UPPER:
            mass[i, j] += row[i] * column[j]
        for i in range(3):
            bias[i] += row[i] * w0
    for mass, _ in sums.values():
        if any(depends_on(prog, entry, list(syms.qdd)) for entry in mass):
            raise RuntimeError("the generalized forces are not affine in q''")
    bld = Builder(prog)

    def named(leg: str, mass: sp.Matrix, bias: sp.Matrix) -> Share:
        return (
            sp.Matrix(3, 3, lambda i, j: bld.define(f"M{i + 1}{j + 1}_{leg}", mass[i, j], STEP_TASK)
                      if i <= j else 0),
            sp.Matrix([bld.define(f"bias{k + 1}_{leg}", bias[k], STEP_TASK) for k in range(3)]),
        )  # fmt: skip

    return {leg: share if leg is None else named(leg, *share) for leg, share in sums.items()}


def _total(shares: dict[str | None, Share]) -> Share:
    """``M`` (upper triangle) and ``c``: the sums of the shares."""
    return (
        sum((mass for mass, _ in shares.values()), sp.zeros(3, 3)),
        sum((bias for _, bias in shares.values()), sp.zeros(3, 1)),
    )


def task_space_dynamics(
    prog: Program, structure: Structure, method: str = "virtual_power"
) -> tuple[sp.Matrix, sp.Matrix]:
    """``M`` (3 x 3, symmetric positive definite) and ``c`` (3) with ``M q'' + c = J^T tau``.

    The loads of the virtual-work derivation (eqs. 10-17) are affine in the platform
    acceleration, ``tau = A(q) q'' + b(q, q')``, so ``M = J^T A`` and ``c = J^T b`` (units: kg,
    kg m, kg m^2; N, N m). Two routes, equal to round-off (tested):

    - ``method="efforts"``: exactly that, ``A`` by differentiating the inverse-dynamics program
      assignment by assignment, ``b`` by setting ``q'' = 0`` in it, then ``J^T A``, ``J^T b``.
      It carries the closure solve of eq. (7) (``W^-1``), which ``J^T`` then undoes.
    - ``method="virtual_power"`` (the default, about half the operations): ``J^T tau`` is the
      virtual power of the same required wrenches in the unit platform twists
      (:func:`_virtual_powers`), so no closure matrix is inverted; then the same
      differentiation and zeroing, leg by leg (:func:`_shares`). ``M`` and ``c`` are those of
      the mechanism, the same for every choice of actuated joint.

    Only the upper triangle of ``M`` is named (``M11 M12 M13 M22 M23 M33``); ``c`` is named
    ``bias1..3``.
    """
    if method == "efforts":
        A, b = _effort_affine(prog, structure)
        J = actuator_jacobian(prog, structure)
        mass = J.T * A
        bias = J.T * b
    elif method == "virtual_power":
        mass, bias = _total(_shares(prog, structure))
    else:
        raise ValueError(f"method must be 'virtual_power' or 'efforts', got {method!r}")
    M = _symmetric(prog, "M", {(i, j): mass[i, j] for i, j in UPPER})
    bld = Builder(prog)
    c = sp.Matrix([bld.define(f"bias{k + 1}", bias[k], STEP_TASK) for k in range(3)])
    return M, c


def forward_dynamics(prog: Program, structure: Structure) -> sp.Matrix:
    """``q'' = M^-1 (J^T tau - c)`` (3-vector), for the efforts :data:`~.symbols.tau`, by LDL^T.

    ``M`` and ``c`` of :func:`task_space_dynamics` (default route: the legs' shares, and the
    right-hand side ``J^T tau - c`` summed from each leg's ``J_i^T tau_i - c_i`` too) and the
    3 x 3 solve of :func:`~.calculus.ldlt_solve`. Nothing here divides by ``det J``: the forward
    dynamics is defined at a parallel singularity too (the efforts just cannot push the platform
    along the singular direction); only a serial singularity is. Units: m/s^2, m/s^2, rad/s^2.
    """
    shares = _shares(prog, structure)
    mass, _ = _total(shares)
    M = _symmetric(prog, "M", {(i, j): mass[i, j] for i, j in UPPER})
    J = actuator_jacobian(prog, structure)
    bld = Builder(prog)
    rhs = -shares[None][1]
    for i, leg in enumerate(LEGS):  # J^T tau - c leg by leg (leg i drives actuator i), as lanes
        bias = shares[leg][1]
        rhs += sp.Matrix([
            bld.define(f"fd_rhs{k + 1}_{leg}", J[i, k] * syms.tau[i] - bias[k], STEP_FORWARD)
            for k in range(3)
        ])  # fmt: skip
    rhs = sp.Matrix([bld.define(f"fd_rhs{k + 1}", rhs[k], STEP_FORWARD) for k in range(3)])
    return ldlt_solve(prog, M, rhs, "fd", STEP_FORWARD)
