"""The planar derivation (``derive/planar``) against physics, for every derivable structure.

The SymPy programs of the derivation are evaluated directly (``tests/program_eval.py``), with no
code generation, on random models and motions of the general format (``tests/planar_models.py``)
and judged by the independent Newton-Euler reference (``tests/planar_reference.py``) and by laws
the derivation was not built from (``tests/planar_checks.py``): every inverse-dynamics output,
power balance, balance of the whole robot at rest and of the platform in motion, the actuator
Jacobian by finite differences and its rate term, the mass matrix against the kinetic energy's,
``M qdd + c = J^T tau``, forward dynamics inverting inverse dynamics, the platform velocity from
the actuator rates, the direct kinematics' candidates, and the identification regressor.

Each structure is derived once per process (``functools.cache``): the inverse dynamics and the
control model of all 18 in about 8 s of CPU; the direct kinematics and the regressor, about 7 s
more, on 7 structures that cover every leg type, every kind of locked-leg hold (circle, line,
platform line) with both kinds of actuated joint (``DK_STRUCTURES``), and every leg type with both
kinds of actuated joint (``REGRESSOR_STRUCTURES``). Measured worst relative errors over the
structures (seeds below): inverse dynamics 5.2e-15, balances 2.3e-15, power 2.9e-15, J against
central differences 2.3e-10 (truncation and round-off of the differences), actuator rates and
accelerations 1.1e-15, mass matrix 6.4e-16, ``M qdd + c - J^T tau`` 1.5e-15, forward dynamics
1.7e-13, direct kinematics 1.4e-14 (of the platform radius), regressor 4.5e-15.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import pytest
import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import control, direct_kinematics, general, identification, registry
from rpr3gen_derive.planar import structures as st
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.registry.direct_kinematics import ANGLE

try:
    from . import planar_checks as chk
    from . import planar_models as pm
    from . import planar_reference as pr
    from .program_eval import compile_program
except ImportError:
    import planar_checks as chk
    import planar_models as pm
    import planar_reference as pr
    from program_eval import compile_program

STRUCTURES = [(s.kinds, s.actuated) for s in st.DERIVABLE]
IDS = [f"{leg}{a}" for leg, a in STRUCTURES]
LEGS = chk.LEGS
T = np.linspace(0.0, 1.5, 7)
MODELS = 2  # random models per structure

#: Inputs of every evaluated program (unused ones are ignored by the evaluator).
MOTION_INPUTS = (*syms.q, *syms.qd, *syms.qdd, *syms.tau, *syms.qa, *syms.qa_dot)


def _inputs(kinds: str) -> list:
    return [*MOTION_INPUTS, *(general.param_symbol(n) for n in general.param_names(kinds))]


def _values(model: dict, **arrays: np.ndarray) -> dict[str, object]:
    """Keyword arguments of a compiled program: the model's parameters and the named inputs
    (``q``, ``qd``, ``qdd``, ``tau``, ``qa``, ``qa_dot``: (n, 3) arrays; missing ones zero)."""
    n = max(np.atleast_2d(a).shape[0] for a in arrays.values())
    values: dict[str, object] = dict(chk.param_values(model))
    groups = {
        "q": syms.q,
        "qd": syms.qd,
        "qdd": syms.qdd,
        "tau": syms.tau,
        "qa": syms.qa,
        "qa_dot": syms.qa_dot,
    }
    for key, symbols in groups.items():
        a = np.atleast_2d(arrays[key]) if key in arrays else np.zeros((n, 3))
        for k, s in enumerate(symbols):
            values[s.name] = np.broadcast_to(a[:, k], (n,))
    return values


@functools.cache
def _control(kinds: str, actuated: int):
    """One program with the inverse dynamics and the control model of a structure, compiled:
    ``f(model, **arrays) -> {name: (n,) or (n, 3, 3) array}``."""
    s = st.Structure(kinds, actuated)
    prog = Program()
    derivation = control.include_inverse_dynamics(prog, s)
    J = control.actuator_jacobian(prog, s)
    rate = control.jacobian_rate_term(prog, s)
    M, c = control.task_space_dynamics(prog, s)
    fd = control.forward_dynamics(prog, s)
    pv = control.platform_velocity(prog, s)
    groups = {name: [expr] for name, expr in derivation.outputs.items()}
    groups.update(J=list(J), Jdqd=list(rate), M=list(M), c=list(c), fd=list(fd), pv=list(pv))
    flat = [e for exprs in groups.values() for e in exprs]
    function = compile_program(prog, _inputs(kinds), flat)

    def evaluate(model: dict, **arrays: np.ndarray) -> dict[str, np.ndarray]:
        results = iter(function(**_values(model, **arrays)))
        out = {}
        for name, exprs in groups.items():
            cols = [next(results) for _ in exprs]
            out[name] = cols[0] if len(cols) == 1 else np.stack(cols, axis=-1)
        for name in ("J", "M"):
            out[name] = out[name].reshape(-1, 3, 3)
        return out

    return evaluate


@functools.cache
def _case(kinds: str, actuated: int, k: int = 0):
    """Random model ``k`` of a structure and a random motion of it at times T."""
    seed = 4000 + 100 * pr.LEG_TYPES.index(kinds) + 10 * actuated + k
    rng = np.random.default_rng(seed)
    model = pm.random_model(rng, kinds, actuated)
    robot = pr.parse_model(model)
    q, qd, qdd = pm.random_motion(rng, robot, T)
    return model, robot, q, qd, qdd


@dataclass(frozen=True)
class Solved:
    """A random case, the derivation's outputs (and control model) and the reference's."""

    model: dict
    robot: pr.Robot
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    out: dict[str, np.ndarray]
    ref: dict[str, np.ndarray]


@functools.cache
def _solved(kinds: str, actuated: int, k: int = 0) -> Solved:
    model, robot, q, qd, qdd = _case(kinds, actuated, k)
    out = _control(kinds, actuated)(model, q=q, qd=qd, qdd=qdd)
    return Solved(model, robot, q, qd, qdd, out, pr.solve(robot, q, qd, qdd))


def _efforts(out) -> np.ndarray:
    return np.stack([out[f"tau_{leg}"] for leg in LEGS], axis=1)


def _actuated(out, family: str, actuated: int) -> np.ndarray:
    return np.stack([out[f"{family}{actuated}_{leg}"] for leg in LEGS], axis=1)


def test_the_derivable_structures_are_the_nonsingular_ones() -> None:
    assert pm.nonsingular_structures() == STRUCTURES
    singular = [(s.kinds, s.actuated) for s in st.ALL if s.singular]
    assert sorted(singular) == sorted(pr.SINGULAR_STRUCTURES)
    for kinds, actuated in singular:
        with pytest.raises(ValueError, match="architecturally singular"):
            registry.module(st.Structure(kinds, actuated))


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    """``max |a - b| / max |b|``."""
    return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))


#: The worst error of each check and structure seen in this process (for reports).
MEASURED: dict[tuple[str, str], float] = {}


def _bound(check: str, kinds: str, actuated: int, err: float, tol: float, at: str = "") -> None:
    key = (check, f"{kinds.lower()}_{actuated}")
    MEASURED[key] = max(MEASURED.get(key, 0.0), err)
    assert err < tol, f"{check}: {err:.2e} (bound {tol:.0e}) {at}"


def _inverse_dynamics_matches_the_reference(kinds: str, actuated: int) -> None:
    """Every output (joint coordinates modulo 2 pi, rates, accelerations, every joint load,
    efforts) on two random models, each along a random motion, relative to the largest value
    of its unit; reach 1 at home and positive along the motion; conditioning in (0, 1]."""
    for k in range(MODELS):
        s = _solved(kinds, actuated, k)
        assert set(s.ref) < set(s.out)
        err, where = chk.worst_error(s.out, s.ref, kinds, actuated)
        _bound("inverse dynamics", kinds, actuated, err, 1e-11, f"at {where}, model {k}")
        home = _control(kinds, actuated)(s.model, q=np.zeros((1, 3)))
        assert home["reach"][0] == pytest.approx(1.0, abs=1e-12)
        assert np.all(s.out["reach"] > 0.05)
        assert np.all((s.out["conditioning"] > 0) & (s.out["conditioning"] <= 1 + 1e-12))


def _power_balance(kinds: str, actuated: int) -> None:
    """The actuators' and the payload's power equals the rate of the robot's energy (the
    reference's analytic dE/dt), with the derivation's efforts and joint rates."""
    s = _solved(kinds, actuated)
    supplied = pr.input_power(s.robot, s.out, s.qd)
    stored = pr.energy_rate(s.robot, s.q, s.qd, s.qdd)
    _bound("power", kinds, actuated, _rel(supplied, stored), 1e-11)


def _balance_at_rest_and_of_the_platform(kinds: str, actuated: int) -> None:
    """At rest (poses of the motion), the base's loads on the legs balance the weight of every
    body and the payload (forces and moments about the origin, bodies placed by the
    derivation's own joint coordinates); in motion, the joint-3 loads, gravity and the payload
    move the platform by Newton-Euler; the joint coordinates close every leg on the pose."""
    s = _solved(kinds, actuated)
    zero = np.zeros_like(s.q)
    rest = _control(kinds, actuated)(s.model, q=s.q, qd=zero, qdd=zero)
    _bound("balance", kinds, actuated, max(chk.rest_residual(s.model, rest, s.q)), 1e-12)
    platform = chk.platform_residual(s.model, s.out, s.q, s.qd, s.qdd)
    _bound("balance", kinds, actuated, max(platform), 1e-12)
    for leg in LEGS:
        pose = chk.leg_bodies(s.model, leg, s.out)["pose"]
        assert np.max(np.abs(pose[:, :2] - s.q[:, :2])) < 1e-13
        assert np.max(np.abs(chk.wrap(pose[:, 2] - s.q[:, 2]))) < 1e-13


def _actuator_jacobian_and_its_rate(kinds: str, actuated: int) -> None:
    """J against central differences of the actuator coordinates; ``J qd`` the actuator rates,
    ``J qdd + J' qd`` their accelerations; the platform velocity from the rates is qd."""
    s = _solved(kinds, actuated)
    f = _control(kinds, actuated)
    h = 1e-6
    angle = kinds[actuated - 1] == "R"
    J = s.out["J"]
    for k in range(3):
        dq = np.zeros(3)
        dq[k] = h
        after = _actuated(f(s.model, q=s.q + dq), "q", actuated)
        before = _actuated(f(s.model, q=s.q - dq), "q", actuated)
        diff = chk.wrap(after - before) if angle else after - before
        err = float(np.max(np.abs(diff / (2 * h) - J[:, :, k])) / np.max(np.abs(J)))
        _bound("J finite differences", kinds, actuated, err, 1e-7)
    qa_dot = np.einsum("nij,nj->ni", J, s.qd)
    qa_ddot = np.einsum("nij,nj->ni", J, s.qdd) + s.out["Jdqd"]
    _bound("J rates", kinds, actuated, _rel(qa_dot, _actuated(s.out, "qd", actuated)), 1e-12)
    _bound("J rates", kinds, actuated, _rel(qa_ddot, _actuated(s.out, "qdd", actuated)), 1e-12)
    pv = f(s.model, q=s.q, qa_dot=qa_dot)["pv"]
    _bound("J rates", kinds, actuated, _rel(pv, s.qd), 1e-12)


def _task_space_dynamics(kinds: str, actuated: int) -> None:
    """M symmetric positive definite and equal to the kinetic energy's mass matrix (the
    reference's, independent of any Newton-Euler solve); ``M qdd + c = J^T tau``."""
    s = _solved(kinds, actuated)
    M, c, J = s.out["M"], s.out["c"], s.out["J"]
    assert np.array_equal(M, np.swapaxes(M, 1, 2))
    assert np.all(np.linalg.eigvalsh(M) > 0)
    _bound("M", kinds, actuated, _rel(M, pr.mass_matrix_from_energy(s.robot, s.q)), 1e-12)
    lhs = np.einsum("nij,nj->ni", M, s.qdd) + c
    rhs = np.einsum("nji,nj->ni", J, _efforts(s.out))
    _bound("M qdd + c = J^T tau", kinds, actuated, _rel(lhs, rhs), 1e-12)


def _forward_dynamics_inverts_inverse_dynamics(kinds: str, actuated: int) -> None:
    """``fd(q, qd, tau(q, qd, qdd)) = qdd``; with random efforts, the reference's."""
    s = _solved(kinds, actuated)
    f = _control(kinds, actuated)
    back = f(s.model, q=s.q, qd=s.qd, tau=_efforts(s.out))["fd"]
    _bound("forward dynamics", kinds, actuated, _rel(back, s.qdd), 1e-11)
    tau = np.random.default_rng(3).normal(size=s.q.shape) * np.max(np.abs(_efforts(s.out)))
    ours = f(s.model, q=s.q, qd=s.qd, tau=tau)["fd"]
    ref = pr.forward_dynamics(s.robot, s.q, s.qd, tau)
    _bound("forward dynamics", kinds, actuated, _rel(ours, ref), 1e-11)


#: The checks of the inverse dynamics and the control model, run by one test per structure.
CHECKS = (
    _inverse_dynamics_matches_the_reference,
    _power_balance,
    _balance_at_rest_and_of_the_platform,
    _actuator_jacobian_and_its_rate,
    _task_space_dynamics,
    _forward_dynamics_inverts_inverse_dynamics,
)


@pytest.mark.parametrize(("kinds", "actuated"), STRUCTURES, ids=IDS)
def test_inverse_dynamics_and_control_model(kinds: str, actuated: int) -> None:
    """Every check of ``CHECKS`` on the structure. One test per structure, so that each is
    derived once per session on pytest-xdist workers too (separate tests of one structure
    would land on several workers, each deriving it); every check runs, and the failures are
    reported together."""
    failures = []
    for check in CHECKS:
        try:
            check(kinds, actuated)
        except AssertionError as exc:
            failures.append(f"{check.__name__[1:]}: {exc}")
    assert not failures, "\n".join(failures)


# -- direct kinematics -----------------------------------------------------------------------


@functools.cache
def _direct_kinematics(kinds: str, actuated: int):
    """``f(model, qa) -> (k, 3)`` candidate poses of one qa (3,): the real roots of the sextic
    back substituted (circles), or both closed-form candidates with a margin >= 0 (lines)."""
    s = st.Structure(kinds, actuated)
    robot = st.robot(s)
    holds = direct_kinematics.locked_legs(robot, s)
    kind = direct_kinematics.locked_kind(kinds, actuated)
    inputs = _inputs(kinds)
    if kind == "circle":
        prog = Program()
        sextic = compile_program(prog, inputs, direct_kinematics.sextic_coefficients(prog, holds))
        cs = list(ANGLE.symbols)
        prog2 = Program()
        xy = direct_kinematics.pose_from_angle(prog2, holds, *cs)
        back = compile_program(prog2, [*inputs, *cs], list(xy))

        def circles(model: dict, qa: np.ndarray) -> np.ndarray:
            values = _values(model, qa=qa[None])
            a = np.array([float(v[0]) for v in sextic(**values)])
            roots = np.roots(a[::-1] / np.max(np.abs(a)))
            phi = np.array([2 * math.atan(t.real) for t in roots if abs(t.imag) < 1e-7])
            values = _values(model, qa=np.tile(qa, (phi.size, 1)))
            values.update({cs[0].name: np.cos(phi), cs[1].name: np.sin(phi)})
            x, y = back(**values)
            return np.column_stack([x, y, phi])

        return kind, circles
    prog = Program()
    modes = direct_kinematics.line_modes(prog, robot, holds)
    function = compile_program(prog, inputs, [e for m in modes for e in m])

    def lines(model: dict, qa: np.ndarray) -> np.ndarray:
        m = np.array([float(v[0]) for v in function(**_values(model, qa=qa[None]))]).reshape(2, 4)
        return m[m[:, 3] >= 0, :3]

    return kind, lines


#: Every leg type, every kind of hold with both kinds of actuated joint.
DK_STRUCTURES = [
    ("RRR", 1),  # circle, revolute motors
    ("RPR", 2),  # circle, prismatic
    ("PRR", 2),  # line, revolute
    ("PPR", 1),  # line, prismatic
    ("RRP", 1),  # platform line, revolute
    ("PRP", 1),  # platform line, prismatic
    ("RPP", 2),  # platform line, prismatic
]


def test_the_direct_kinematics_sample_covers_every_hold() -> None:
    kinds = {leg for leg, _ in DK_STRUCTURES}
    assert kinds == set(pr.LEG_TYPES)
    holds = {(direct_kinematics.locked_kind(leg, a), leg[a - 1] == "R") for leg, a in DK_STRUCTURES}
    assert holds == {(h, r) for h in ("circle", "line", "platform_line") for r in (True, False)}


@pytest.mark.parametrize(
    ("kinds", "actuated"), DK_STRUCTURES, ids=[f"{k}{a}" for k, a in DK_STRUCTURES]
)
def test_direct_kinematics_candidates_contain_the_true_pose(kinds: str, actuated: int) -> None:
    """For poses of the motion, the actuator coordinates (the reference's inverse kinematics)
    give at most the bound of candidates (6 on circles, 2 on lines), and the pose is one of
    them."""
    model, robot, q, _, _ = _case(kinds, actuated)
    kind, candidates = _direct_kinematics(kinds, actuated)
    rho = robot.platform_radius
    qa = np.stack([x[:, actuated - 1] for x in pr.inverse_kinematics(robot, q)], axis=1)
    for i in (0, 3, 6):
        found = candidates(model, qa[i])
        assert 1 <= len(found) <= direct_kinematics.MAX_MODES[kind]
        d = np.hypot(
            np.hypot(found[:, 0] - q[i, 0], found[:, 1] - q[i, 1]),
            rho * chk.wrap(found[:, 2] - q[i, 2]),
        )
        _bound("direct kinematics", kinds, actuated, float(np.min(d)) / rho, 1e-10)


# -- identification ----------------------------------------------------------------------------


@functools.cache
def _regressor(kinds: str, actuated: int):
    s = st.Structure(kinds, actuated)
    prog = Program()
    Y = identification.regressor(prog, s)
    tau0 = identification.payload_efforts(prog, s)
    function = compile_program(prog, _inputs(kinds), [*Y, *tau0])
    names = identification.INERTIAL_PARAMETER_NAMES

    def evaluate(model: dict, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        res = function(**_values(model, q=q, qd=qd, qdd=qdd))
        Yn = np.stack(res[: 3 * len(names)], axis=1).reshape(-1, 3, len(names))
        return Yn, np.stack(res[3 * len(names) :], axis=1)

    return names, evaluate


#: Every leg type and both kinds of actuated joint.
REGRESSOR_STRUCTURES = [
    ("RRR", 3),
    ("RPR", 2),
    ("RRP", 1),
    ("PRR", 1),
    ("PPR", 2),
    ("PRP", 3),
    ("RPP", 2),
]


@pytest.mark.parametrize(
    ("kinds", "actuated"), REGRESSOR_STRUCTURES, ids=[f"{k}{a}" for k, a in REGRESSOR_STRUCTURES]
)
def test_regressor_reproduces_the_efforts(kinds: str, actuated: int) -> None:
    """``Y pi + tau_payload`` equals the reference's efforts, pi from the model's bodies (mass,
    first moment and inertia about the body's first joint point, world axes at home)."""
    model, robot, q, qd, qdd = _case(kinds, actuated)
    names, evaluate = _regressor(kinds, actuated)
    values = chk.inertial_values(model)
    assert set(values) == set(names)
    pi = np.array([values[n] for n in names])
    Y, tau0 = evaluate(model, q, qd, qdd)
    expected = pr.efforts(pr.solve(robot, q, qd, qdd))
    _bound("regressor", kinds, actuated, _rel(Y @ pi + tau0, expected), 1e-11)
    # tau_payload holds the payload alone: the efforts at rest without gravity.
    zero = np.zeros_like(q)
    weightless = pr.parse_model({**model, "environment": {"gravity": [0.0, 0.0]}})
    at_rest = pr.efforts(pr.solve(weightless, q, zero, zero))
    _bound("regressor", kinds, actuated, _rel(tau0, at_rest), 1e-11)


def test_a_legs_constraint_data_simplify_as_leg_as() -> None:
    """direct_kinematics._simple simplifies leg B's and C's data as leg A's, renamed: the result
    must be what trigsimp gives for the leg's own expression, and an expression of two legs
    (no one-to-one renaming) must be simplified as it is."""

    def leg(letter: str) -> sp.Expr:
        q, a = sp.Symbol(f"qa_{letter}", real=True), sp.Symbol(f"alpha_{letter}", real=True)
        x1 = sp.Symbol(f"x{letter}1", real=True)
        return (
            (x1 + sp.cos(a)) * sp.cos(q) - sp.sin(a) * sp.sin(q) + sp.sin(q) ** 2 + sp.cos(q) ** 2
        )

    for letter in "BC":
        expr = leg(letter)
        simple = direct_kinematics._simple(expr)
        assert simple == sp.trigsimp(sp.expand(expr))
        assert {s.name for s in simple.free_symbols} == {s.name for s in expr.free_symbols}
    mixed = leg("A") + leg("B")
    assert direct_kinematics._simple(mixed) == sp.trigsimp(sp.expand(mixed))
