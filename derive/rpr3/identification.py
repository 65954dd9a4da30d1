"""Dynamic identification (issue 13): the actuator efforts as a linear regression on inertia.

The required wrenches of eqs. (10)-(11) are linear in each body's mass ``m``, first moment
``m c`` and inertia ``J`` about its joint point, and the loads of eqs. (12)-(17) are linear in
the required wrenches (virtual work: the virtual velocities of eqs. (7)-(8) depend on the
geometry alone). So the actuator efforts (``m10_*`` or ``f21z_*``) are

    tau = Y(q, q', q'') @ pi + tau_payload(q),

with, per moving body (cylinder 1 and piston 2 of legs A, B, C, then the platform 3), the four
inertial parameters of :data:`INERTIAL_PARAMETER_NAMES`:

- ``m``: mass;
- ``mcx``, ``mcy``: first moment about the body's joint point, in the body's frame: x along the
  leg axis e and y along its normal n for the cylinder (about A1) and the piston (about A2); the
  platform frame's xG, yG for the platform (about G);
- ``Jzz``: moment of inertia about the joint point (A1, A2, G), axis z0.

:func:`regressor` rebuilds the required wrenches of eqs. (10)-(11) with these parameters as
fresh symbols (``dynamics.required_wrench``, the body motions of ``dynamics.body_motions``),
runs the same virtual-work solution (``virtual_work.joint_loads``, eqs. 7-8 and 12-17), and
differentiates the efforts with respect to the parameters, assignment by assignment
(``control.differentiate``). :func:`payload_efforts` is the same program at ``pi = 0``: the
efforts that hold the payload wrench at rest, which depend on the pose only.

:func:`base_parameters` is Gautier's numerical method on a stacked regressor (QR of the
observation matrix); :func:`regroupings` and :func:`regrouping_matrix` state the regroupings
found with it in closed form (docs/identification.md).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
import scipy.linalg
import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.control import ACTUATORS, at_zero, depends_on, differentiate
from rpr3gen_derive.rpr3.derivation import algorithm
from rpr3gen_derive.rpr3.dynamics import (
    STEP_INERTIA,
    STEP_RECURSION,
    BodyMotion,
    LegWrenches,
    body_motions,
    required_wrench,
)
from rpr3gen_derive.rpr3.frames import skew, u1, u3
from rpr3gen_derive.rpr3.kinematics import LegKinematics
from rpr3gen_derive.rpr3.symbols import LEGS

STEP_REGRESSOR = "regressor: efforts differentiated by the inertial parameters, eqs. (10)-(17)"
STEP_PAYLOAD = "efforts holding the payload at rest (inertial parameters zero), eqs. (12)-(17)"

#: The four inertial parameters of a body, in order.
QUANTITIES: tuple[str, ...] = ("m", "mcx", "mcy", "Jzz")
#: Moving bodies: cylinder (1) and piston (2) of each leg, leg by leg, then the platform (3).
BODIES: tuple[str, ...] = (*(f"{k}{leg}" for leg in LEGS for k in "12"), "3")
#: Bodies when the three legs share one set of parameters (``identical_legs``).
SHARED_BODIES: tuple[str, ...] = ("1", "2", "3")

INERTIAL_PARAMETER_NAMES: tuple[str, ...] = tuple(f"{q}_{b}" for b in BODIES for q in QUANTITIES)
SHARED_PARAMETER_NAMES: tuple[str, ...] = tuple(
    f"{q}_{b}" for b in SHARED_BODIES for q in QUANTITIES
)

#: The inertial parameters as symbols (inputs of the identification program, like ``q``).
pi_symbols: dict[str, sp.Symbol] = {
    name: sp.Symbol(name, real=True) for name in INERTIAL_PARAMETER_NAMES
}


def parameter_names(identical_legs: bool = False) -> tuple[str, ...]:
    """The P names: 28 (per leg), or 12 with ``identical_legs`` (leg letter dropped)."""
    return SHARED_PARAMETER_NAMES if identical_legs else INERTIAL_PARAMETER_NAMES


def _body(name: str) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol, sp.Symbol]:
    m, mcx, mcy, jzz = (pi_symbols[f"{q}_{name}"] for q in QUANTITIES)
    return m, mcx, mcy, jzz


# ----------------------------------------------------------------------------------------------
# The required wrenches (10)-(11) with symbolic inertial parameters.


def _linear(vector: sp.Matrix) -> sp.Matrix:
    """Expand a wrench whose centre of mass was given as ``m c / m``; check it is linear."""
    out = vector.applyfunc(sp.expand)
    names = set(pi_symbols.values())
    for term in (t for entry in out for t in sp.Add.make_args(entry)):
        numerator, denominator = sp.fraction(term)
        if denominator.free_symbols & names:
            raise RuntimeError("a required wrench divides by an inertial parameter")
        if len([f for f in sp.Mul.make_args(numerator) if f.free_symbols & names]) > 1:
            raise RuntimeError("a required wrench is not linear in the inertial parameters")
    return out


def body_wrench(
    motion: BodyMotion,
    mass: sp.Expr,
    first_moment: sp.Matrix,
    inertia_zz: sp.Expr,
    axis: int,
    gravity: sp.Matrix,
) -> tuple[sp.Matrix, sp.Matrix]:
    """``F_k0``, ``M_k0`` of ``dynamics.required_wrench`` (eqs. 10-11, no external load) as
    linear forms in ``(m, m c, J)``, all about the joint point and in the body frame.

    ``required_wrench`` takes the centre of mass ``c``; it is given ``m c / m`` and the result is
    expanded, which cancels ``m`` exactly (the wrench contains ``c`` only as ``m c``). ``axis``
    is the body-frame axis normal to the plane (2 = z for frames 1 and 3, 0 = x2 = -z0).
    """
    inertia = sp.zeros(3, 3)
    inertia[axis, axis] = inertia_zz
    F, M = required_wrench(motion, mass, first_moment / mass, inertia, gravity)
    return _linear(F), _linear(M)


def identification_wrenches(
    prog: Program, kin: LegKinematics, carries_platform: bool
) -> tuple[LegWrenches, tuple[sp.Matrix, sp.Matrix]]:
    """``F_k``, ``M_k`` of eqs. (10)-(11) of one leg with the inertial parameters as symbols.

    As ``dynamics.leg_wrenches``, with, in the body frames: the cylinder's first moment about
    A1 ``(mcx, mcy, 0)`` in frame 1 (x1 = e, y1 = n); the piston's about A2 ``(0, mcy, mcx)``
    in frame 2 (y2 = n, z2 = e); the platform's about A3 ``m rho + (mcx, mcy, 0)`` in frame 3
    (parallel to the platform frame; ``rho = G - A3``), with ``J_A3 = Jzz + m |rho|^2 +
    2 rho . (mcx, mcy)``. The payload acts at G, separately (it does not scale with pi); its
    part of ``F_3``, ``M_3`` is returned too (zero unless ``carries_platform``).
    """
    leg = kin.leg
    cyl, piston, platform = body_motions(kin)
    g1 = kin.a10 * syms.gravity
    g2 = kin.a21 * g1
    g3 = kin.a30 * syms.gravity
    m, mcx, mcy, jzz = _body(f"1{leg}")
    F10, M10 = body_wrench(cyl, m, sp.Matrix([mcx, mcy, 0]), jzz, 2, g1)
    m, mcx, mcy, jzz = _body(f"2{leg}")
    F20, M20 = body_wrench(piston, m, sp.Matrix([0, mcy, mcx]), jzz, 0, g2)
    step = STEP_INERTIA
    F10 = prog.define_vector(f"F10pi_{leg}", F10, step)
    M10 = prog.define_vector(f"M10pi_{leg}", M10, step)
    F20 = prog.define_vector(f"F20pi_{leg}", F20, step)
    M20 = prog.define_vector(f"M20pi_{leg}", M20, step)
    payload = (sp.zeros(3, 1), sp.zeros(3, 1))
    if carries_platform:
        m, mcx, mcy, jzz = _body("3")
        rho = kin.rho
        first = m * rho + sp.Matrix([mcx, mcy, 0])
        about_a3 = jzz + m * (rho.T * rho)[0] + 2 * (rho[0] * mcx + rho[1] * mcy)
        F30, M30 = body_wrench(platform, m, first, about_a3, 2, g3)
        # The payload wrench at G (body "mass" zero, its point of application rho from A3).
        Fp, Mp = required_wrench(
            platform,
            sp.Integer(0),
            rho,
            sp.zeros(3, 3),
            g3,
            external_force=kin.a30 * syms.payload_force,
            external_moment=syms.payload_moment,
        )
        payload = (Fp, Mp)
        F3 = prog.define_vector(f"F3pi_{leg}", F30 + Fp, step)
        M3 = prog.define_vector(f"M3pi_{leg}", M30 + Mp, step)
    else:
        F3, M3 = sp.zeros(3, 1), sp.zeros(3, 1)
    step = STEP_RECURSION
    r21 = (syms.l0 + kin.lambda21) * u1
    r32 = syms.l2 * u3
    F2 = prog.define_vector(f"F2pi_{leg}", F20 + kin.a32.T * F3, step)
    M2 = prog.define_vector(f"M2pi_{leg}", M20 + kin.a32.T * M3 + skew(r32) * kin.a32.T * F3, step)
    F1 = prog.define_vector(f"F1pi_{leg}", F10 + kin.a21.T * F2, step)
    M1 = prog.define_vector(f"M1pi_{leg}", M10 + kin.a21.T * M2 + skew(r21) * kin.a21.T * F2, step)
    return LegWrenches(F=(F1, F2, F3), M=(M1, M2, M3)), payload


@cache
def _efforts_program(actuation: str) -> tuple[Program, tuple[sp.Expr, ...]]:
    """The paper's algorithm (eqs. 5-17) with symbolic inertial parameters: the efforts."""
    prog = Program()
    _, loads = algorithm(
        prog, actuation, lambda p, kin, platform: identification_wrenches(p, kin, platform)[0]
    )
    effort = ACTUATORS[actuation].effort
    return prog, tuple(loads[f"{effort}_{leg}"] for leg in LEGS)


def _merge(prog: Program, source: Program, suffix: str) -> dict[sp.Symbol, sp.Expr]:
    """Append ``source``'s assignments to ``prog``; a name that ``prog`` already defines
    differently is renamed with ``suffix``. Returns the renaming to apply to ``source``'s
    expressions."""
    existing = prog.definitions()
    rename: dict[sp.Symbol, sp.Expr] = {}
    for a in source.assignments:
        expr = a.expr.xreplace(rename)
        known = existing.get(a.symbol)
        if known == expr:
            continue
        if known is None:
            existing[a.symbol] = expr
            prog.define(a.symbol.name, expr, a.step)
            continue
        other = sp.Symbol(f"{a.symbol.name}{suffix}", real=True)
        if existing.get(other) != expr:
            existing[other] = expr
            prog.define(other.name, expr, a.step)
        rename[a.symbol] = other
    return rename


def efforts(prog: Program, actuation: str) -> list[sp.Expr]:
    """The actuator efforts with symbolic inertial parameters, appended to ``prog``.

    Assignments already in ``prog`` with the same right-hand side are shared (the leg
    kinematics of eqs. 5-9); those defined differently there (the loads of eqs. 12-17 of the
    model's own derivation) get the suffix ``__pi``.
    """
    source, outputs = _efforts_program(actuation)
    rename = _merge(prog, source, "__pi")
    return [sp.sympify(e).xreplace(rename) for e in outputs]


def regressor(prog: Program, actuation: str) -> sp.Matrix:
    """``Y`` (3 x 28): ``tau = Y @ pi + tau_payload``, tau the efforts of legs A, B, C.

    Column j is ``d tau / d pi_j`` (:data:`INERTIAL_PARAMETER_NAMES`), differentiated through
    the program of eqs. (5)-(17) (:func:`efforts`); the efforts being linear in pi (checked), Y
    depends on the pose, velocity and acceleration and on the geometry and gravity only.
    """
    taus = efforts(prog, actuation)
    symbols = [pi_symbols[n] for n in INERTIAL_PARAMETER_NAMES]
    table = differentiate(prog, taus, symbols, STEP_REGRESSOR)
    Y = sp.Matrix(table)
    for entry in Y:
        if depends_on(prog, entry, symbols):
            raise RuntimeError("the actuator efforts are not linear in the inertial parameters")
    return Y


def payload_efforts(prog: Program, actuation: str) -> sp.Matrix:
    """``tau_payload`` (3): the efforts at ``pi = 0``, which hold the payload wrench (fx, fy,
    mz at G) at rest, eqs. (12)-(17) with only the payload in ``F_3``, ``M_3``.

    Without mass nothing depends on the velocity or the acceleration (the payload wrench is
    given, the virtual velocities are geometric), so they are set to zero too: the result is a
    function of the pose (and the geometry and payload) alone.
    """
    taus = efforts(prog, actuation)
    symbols = [pi_symbols[n] for n in INERTIAL_PARAMETER_NAMES] + [*syms.qd, *syms.qdd]
    return sp.Matrix(at_zero(prog, taus, symbols, "_pi0", STEP_PAYLOAD))


# ----------------------------------------------------------------------------------------------
# Numeric values and identical legs.


def inertial_parameters(params: Mapping[str, float], identical_legs: bool = False) -> np.ndarray:
    """The model's ``pi`` (P,), in the order of :func:`parameter_names`.

    Cylinder: ``m1, m1 c1, m1 c1_perp, J1 + m1 (c1^2 + c1_perp^2)`` (about A1); piston:
    ``m2, m2 c2, m2 c2_perp, J2 + m2 (c2^2 + c2_perp^2)`` (about A2); platform: ``m3, 0, 0, J3``
    (COM at G). The model's legs are identical, so with ``identical_legs`` the leg values appear
    once (P = 12).
    """
    p = params

    def body(m: float, c: float, c_perp: float, j: float) -> tuple[float, ...]:
        return (m, m * c, m * c_perp, j + m * (c**2 + c_perp**2))

    leg = {
        "1": body(p["m1"], p["c1"], p.get("c1_perp", 0.0), p["J1"]),
        "2": body(p["m2"], p["c2"], p.get("c2_perp", 0.0), p["J2"]),
    }
    platform = (p["m3"], 0.0, 0.0, p["J3"])
    if identical_legs:
        values = [*leg["1"], *leg["2"], *platform]
    else:
        values = [v for _ in LEGS for k in "12" for v in leg[k]] + list(platform)
    return np.array(values, dtype=float)


def identical_legs_matrix() -> np.ndarray:
    """``S`` (28 x 12) with ``Y_shared = Y @ S``: each leg parameter's three columns summed."""
    S = np.zeros((len(INERTIAL_PARAMETER_NAMES), len(SHARED_PARAMETER_NAMES)))
    for i, name in enumerate(INERTIAL_PARAMETER_NAMES):
        quantity, body = name.split("_")
        S[i, SHARED_PARAMETER_NAMES.index(f"{quantity}_{body[0]}")] = 1.0
    return S


# ----------------------------------------------------------------------------------------------
# Base parameters: Gautier's numerical QR method, and the regroupings in closed form.


@dataclass(frozen=True)
class BaseParameters:
    """The identifiable combinations of pi found from a stacked regressor W (n x P).

    ``names`` (B): the parameters kept as base, each standing for the combination
    ``matrix[k] @ pi``; ``matrix`` (B x P); ``rank`` = B; ``unidentifiable``: parameters whose
    column of W is zero; ``regrouped``: parameters that enter base combinations only;
    ``alone``: base parameters no other parameter regroups into.
    """

    names: tuple[str, ...]
    matrix: np.ndarray
    rank: int
    unidentifiable: tuple[str, ...]
    regrouped: tuple[str, ...]
    alone: tuple[str, ...]


def numerical_rank(W: np.ndarray, rtol: float | None = None) -> int:
    """Rank of W by QR with column pivoting: ``|R_kk| > rtol |R_00|``, with the usual
    ``rtol = max(n, P) eps`` when not given."""
    R = scipy.linalg.qr(W, mode="r", pivoting=True)[0]
    diag = np.abs(np.diag(R))
    if rtol is None:
        rtol = max(W.shape) * np.finfo(float).eps
    return int(np.sum(diag > rtol * diag[0])) if diag.size and diag[0] > 0 else 0


def base_parameters(
    W: np.ndarray,
    names: Sequence[str],
    preference: Sequence[str] | None = None,
    rtol: float = 1e-8,
) -> BaseParameters:
    """Gautier's numerical method: which combinations of pi a stacked regressor W determines.

    The rank B comes from QR with column pivoting (:func:`numerical_rank`). The base columns are
    chosen in the deterministic order ``preference`` (default: ``names``): QR without pivoting
    of the reordered W, a column being dependent when ``|R_kk|`` is below ``rtol`` times the
    norm of its column (zero columns: unidentifiable). With ``W_b`` the base and ``W_d`` the
    dependent columns, ``W_d = W_b beta`` exactly, so ``W pi = W_b (pi_b + beta pi_d)``:
    ``matrix = [I beta]`` in the original column order (entries below 1e-9 set to zero).
    """
    names = tuple(names)
    order = [names.index(n) for n in (preference or names)]
    if sorted(order) != list(range(len(names))):
        raise ValueError("preference must be a permutation of names")
    scale = np.linalg.norm(W, axis=0)
    top = scale.max()
    unidentifiable = tuple(names[j] for j in range(len(names)) if scale[j] <= rtol * top)
    R = scipy.linalg.qr(W[:, order], mode="r")[0]
    base = [
        order[k] for k in range(len(order)) if abs(R[k, k]) > rtol * max(scale[order[k]], 1e-300)
    ]
    base = [j for j in base if names[j] not in unidentifiable]
    rank = numerical_rank(W)
    if len(base) != rank:
        raise RuntimeError(f"base selection found {len(base)} columns, the rank is {rank}")
    dependent = [j for j in range(len(names)) if j not in base]
    beta = np.linalg.lstsq(W[:, base], W[:, dependent], rcond=None)[0]
    beta[np.abs(beta) < 1e-9] = 0.0
    matrix = np.zeros((len(base), len(names)))
    for k, j in enumerate(base):
        matrix[k, j] = 1.0
    matrix[:, dependent] = beta
    base_sorted = sorted(range(len(base)), key=lambda k: base[k])
    matrix = matrix[base_sorted]
    base = [base[k] for k in base_sorted]
    regrouped = tuple(
        names[j] for j in dependent if names[j] not in unidentifiable and np.any(matrix[:, j])
    )
    alone = tuple(names[j] for k, j in enumerate(base) if np.count_nonzero(matrix[k]) == 1)
    return BaseParameters(
        names=tuple(names[j] for j in base),
        matrix=matrix,
        rank=rank,
        unidentifiable=unidentifiable,
        regrouped=regrouped,
        alone=alone,
    )


def preference(identical_legs: bool = False) -> tuple[str, ...]:
    """The order in which base columns are chosen: the platform's parameters first, then per
    leg the cylinder's first moments and inertia, the piston's first moments, its inertia and
    mass, and the cylinder's mass last. This keeps the regroupings of :func:`regroupings`:
    the piston's mass and inertia are the parameters eliminated."""
    legs = ("",) if identical_legs else LEGS
    order = ["m_3", "mcx_3", "mcy_3", "Jzz_3"]
    for leg in legs:
        order += [f"mcx_1{leg}", f"mcy_1{leg}", f"Jzz_1{leg}", f"mcx_2{leg}", f"mcy_2{leg}"]
        order += [f"Jzz_2{leg}", f"m_2{leg}", f"m_1{leg}"]
    return tuple(order)


def regroupings(identical_legs: bool = False) -> dict[str, sp.Expr]:
    """The base parameters in closed form: base name -> linear combination of pi.

    Derived from the energy of the piston written about the platform joint A3 (which is a point
    of the platform): the piston's mass is a point mass at A3 plus its first moment and inertia
    moved from A2 to A3 (``|A2A3| = l2``), so, with ``p_i`` the platform joint of leg i in the
    platform frame,

    - ``m_3 + sum_i m_2i``, ``mcx_3 + sum_i xi3 m_2i``, ``mcy_3 + sum_i yi3 m_2i``,
      ``Jzz_3 + sum_i |p_i|^2 m_2i`` (the platform's);
    - ``mcx_2i - l2 m_2i`` and ``Jzz_1i + Jzz_2i - l2^2 m_2i`` (the leg's: the cylinder and the
      piston turn together, so only the sum of their inertias counts);
    - ``mcx_1i``, ``mcy_1i``, ``mcy_2i`` alone; ``m_1i`` not at all (A1 is fixed).

    With ``identical_legs`` the sums run over the same leg parameters (``3 m_2`` and so on).
    """
    legs = ("",) if identical_legs else LEGS
    s = {name: sp.Symbol(name, real=True) for name in parameter_names(identical_legs)}
    out: dict[str, sp.Expr] = {}
    for leg in legs:
        out[f"mcx_1{leg}"] = s[f"mcx_1{leg}"]
        out[f"mcy_1{leg}"] = s[f"mcy_1{leg}"]
        out[f"Jzz_1{leg}"] = s[f"Jzz_1{leg}"] + s[f"Jzz_2{leg}"] - syms.l2**2 * s[f"m_2{leg}"]
        out[f"mcx_2{leg}"] = s[f"mcx_2{leg}"] - syms.l2 * s[f"m_2{leg}"]
        out[f"mcy_2{leg}"] = s[f"mcy_2{leg}"]
    joints = [syms.platform_joint(leg) for leg in LEGS]
    masses = [s["m_2"]] * 3 if identical_legs else [s[f"m_2{leg}"] for leg in LEGS]
    out["m_3"] = s["m_3"] + sum(masses)
    out["mcx_3"] = s["mcx_3"] + sum(p[0] * m for p, m in zip(joints, masses, strict=True))
    out["mcy_3"] = s["mcy_3"] + sum(p[1] * m for p, m in zip(joints, masses, strict=True))
    out["Jzz_3"] = s["Jzz_3"] + sum(
        (p[0] ** 2 + p[1] ** 2) * m for p, m in zip(joints, masses, strict=True)
    )
    names = parameter_names(identical_legs)
    return {n: out[n] for n in names if n in out}


def regrouping_matrix(params: Mapping[str, float], identical_legs: bool = False) -> np.ndarray:
    """:func:`regroupings` as a numeric (B x P) matrix for a model's geometry."""
    names = parameter_names(identical_legs)
    values = {syms.params[k]: float(v) for k, v in params.items() if k in syms.params}
    rows = []
    for expr in regroupings(identical_legs).values():
        expr = sp.expand(expr.xreplace(values))
        rows.append([float(expr.coeff(sp.Symbol(n, real=True))) for n in names])
    return np.array(rows)
