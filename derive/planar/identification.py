"""Dynamic identification: the actuator efforts as a linear regression on inertia, any structure.

The required wrenches of eqs. (10)-(11) are linear in each body's mass ``m``, first moment
``m c`` and inertia ``J`` about its first joint point, and the loads of eqs. (12)-(17) are
linear in the required wrenches (virtual work: the virtual velocities of eqs. (7)-(8) depend on
the geometry alone). So the actuator efforts are

    tau = Y(q, q', q'') @ pi + tau_payload(q),

with, per moving body (bodies 1 and 2 of legs A, B, C, then the platform 3), the four inertial
parameters of :data:`INERTIAL_PARAMETER_NAMES`: ``m``; ``mcx``, ``mcy``, the first moment about
the body's first joint point (the platform: G) in the body's frame of inertial parameters (the
general format: the world's axes at home; the paper's legs: x along the leg axis e, y along
its normal n; the platform: the platform frame); ``Jzz``, the moment of inertia about that
point, axis z.

:func:`regressor` runs the algorithm of eqs. (5)-(17) with these parameters as fresh symbols and
differentiates the efforts with respect to them, assignment by assignment
(:func:`~.calculus.differentiate`); :func:`payload_efforts` is the same program at ``pi = 0``,
the efforts that hold the payload wrench at rest, a function of the pose only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
import scipy.linalg
import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import outputs, paper, structures
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.calculus import at_zero, depends_on, differentiate
from rpr3gen_derive.planar.derivation import algorithm
from rpr3gen_derive.planar.dynamics import Inertia
from rpr3gen_derive.planar.geometry import LEGS, Robot
from rpr3gen_derive.planar.kinematics import LegKinematics
from rpr3gen_derive.planar.structures import Structure
from rpr3gen_derive.planar.vectors import along, rotate

STEP_REGRESSOR = "regressor: efforts differentiated by the inertial parameters, eqs. (10)-(17)"
STEP_PAYLOAD = "efforts holding the payload at rest (inertial parameters zero), eqs. (12)-(17)"

#: The four inertial parameters of a body, in order.
QUANTITIES: tuple[str, ...] = ("m", "mcx", "mcy", "Jzz")
#: Moving bodies: bodies 1 and 2 of each leg, leg by leg, then the platform (3).
BODIES: tuple[str, ...] = (*(f"{k}{leg}" for leg in LEGS for k in "12"), "3")

INERTIAL_PARAMETER_NAMES: tuple[str, ...] = tuple(f"{q}_{b}" for b in BODIES for q in QUANTITIES)

#: Bodies when the three legs share one set of parameters (``identical_legs``).
SHARED_BODIES: tuple[str, ...] = ("1", "2", "3")
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


def symbolic_leg_inertias(kin: LegKinematics) -> tuple[Inertia, Inertia]:
    """Bodies 1 and 2 of a leg about their first joint points, with symbolic inertial
    parameters: the first moment ``mcx f + mcy perp(f)``, ``f`` the current x axis of the body's
    frame of inertial parameters (leg frame)."""
    out = []
    for body in (1, 2):
        m, mcx, mcy, jzz = _body(f"{body}{kin.leg}")
        axis = kin.body_vector(body, kin.geometry.inertial_x[body - 1])
        out.append(Inertia(m, along((mcx, mcy), axis), jzz))
    return out[0], out[1]


def symbolic_platform_inertia(robot: Robot, cos_phi: sp.Expr, sin_phi: sp.Expr) -> Inertia:
    """The platform about G with symbolic inertial parameters (first moment in the platform
    frame, turned by ``phi``)."""
    m, mcx, mcy, jzz = _body("3")
    return Inertia(m, rotate(cos_phi, sin_phi, (mcx, mcy)), jzz)


@cache
def _efforts_program(structure: Structure) -> tuple[Program, tuple[sp.Expr, ...]]:
    """The algorithm (eqs. 5-17) with symbolic inertial parameters: the efforts."""
    prog = Program()
    robot = structures.robot(structure)
    _, _, loads = algorithm(
        prog,
        robot,
        structure.actuated,
        inertias=symbolic_leg_inertias,
        platform_body=symbolic_platform_inertia,
    )
    values = {}
    for leg in LEGS:
        joint = loads.joints[(leg, structure.actuated)]
        values[leg] = joint.moment if structure.actuated_kind == "R" else joint.force[0]
    return prog, tuple(values[leg] for leg in LEGS)


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


def efforts(prog: Program, structure: Structure) -> list[sp.Expr]:
    """The actuator efforts with symbolic inertial parameters, appended to ``prog``.

    Assignments already in ``prog`` with the same right-hand side are shared (the leg
    kinematics of eqs. 5-9); those defined differently there (the loads of eqs. 12-17 of the
    model's own derivation) get the suffix ``__pi``.
    """
    source, values = _efforts_program(structure)
    rename = _merge(prog, source, "__pi")
    return [sp.sympify(e).xreplace(rename) for e in values]


def regressor(prog: Program, structure: Structure) -> sp.Matrix:
    """``Y`` (3 x 28): ``tau = Y @ pi + tau_payload``, tau the efforts of legs A, B, C.

    Column j is ``d tau / d pi_j`` (:data:`INERTIAL_PARAMETER_NAMES`), differentiated through
    the program of eqs. (5)-(17) (:func:`efforts`); the efforts being linear in pi (checked), Y
    depends on the pose, velocity and acceleration and on the geometry and gravity only.
    """
    taus = efforts(prog, structure)
    symbols = [pi_symbols[n] for n in INERTIAL_PARAMETER_NAMES]
    Y = sp.Matrix(differentiate(prog, taus, symbols, STEP_REGRESSOR))
    for entry in Y:
        if depends_on(prog, entry, symbols):
            raise RuntimeError("the actuator efforts are not linear in the inertial parameters")
    return Y


def payload_efforts(prog: Program, structure: Structure) -> sp.Matrix:
    """``tau_payload`` (3): the efforts at ``pi = 0``, which hold the payload wrench (at G) at
    rest: without mass nothing depends on the velocity or the acceleration (the payload wrench
    is given, the virtual velocities are geometric), so the result is a function of the pose
    (and the geometry and payload) alone."""
    taus = efforts(prog, structure)
    symbols = [pi_symbols[n] for n in INERTIAL_PARAMETER_NAMES] + [*syms.qd, *syms.qdd]
    return sp.Matrix(at_zero(prog, taus, symbols, "_pi0", STEP_PAYLOAD))


def effort_family(structure: Structure) -> str:
    """The name of the actuator efforts' family (``tau``; the paper's ``m10``, ``f21z``)."""
    return outputs.effort_family(structure)


# ----------------------------------------------------------------------------------------------
# The paper's robot: numeric values, identical legs, base parameters in closed form.


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
        l2 = paper.params["l2"]
        out[f"Jzz_1{leg}"] = s[f"Jzz_1{leg}"] + s[f"Jzz_2{leg}"] - l2**2 * s[f"m_2{leg}"]
        out[f"mcx_2{leg}"] = s[f"mcx_2{leg}"] - paper.params["l2"] * s[f"m_2{leg}"]
        out[f"mcy_2{leg}"] = s[f"mcy_2{leg}"]
    joints = [paper.platform_joint(leg) for leg in LEGS]
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
    values = {paper.params[k]: float(v) for k, v in params.items() if k in paper.params}
    rows = []
    for expr in regroupings(identical_legs).values():
        expr = sp.expand(expr.xreplace(values))
        rows.append([float(expr.coeff(sp.Symbol(n, real=True))) for n in names])
    return np.array(rows)
