"""The mathematics of dynamic identification (issue 13): regressor, payload efforts, base
parameters (derive/planar/identification.py, docs/identification.md).

The regressor ``Y`` (tau = Y pi + tau_payload) is checked against the independent Newton-Euler
reference (tests/newton_euler.py) for the model's parameters, against it again with the
platform's centre of mass moved off G (by moving G in the reference), against the power
balance ``tau . qa' = dE/dt`` column by column (every column, including the first moments
normal to the legs), and against the efforts of the same program with pi left symbolic.
"""

from __future__ import annotations

from functools import cache

import newton_euler as ne
import numpy as np
import pytest
import sympy as sp
from program_eval import compile_program, values_of
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.planar import identification as idn
from rpr3gen_derive.planar import paper, structures
from rpr3gen_derive.planar import symbols as syms

ACTUATIONS = ("revolute", "prismatic")
#: The paper's two variants, by actuation.
S = {a: structures.from_variant(a) for a in ACTUATIONS}
EFFORT = {"revolute": "m10", "prismatic": "f21z"}
RATE = {"revolute": "omega10", "prismatic": "v21"}
P = len(idn.INERTIAL_PARAMETER_NAMES)
INPUTS = [*paper.params.values(), *syms.q, *syms.qd, *syms.qdd]
PI = [idn.pi_symbols[n] for n in idn.INERTIAL_PARAMETER_NAMES]
T = np.linspace(0.0, 4.0, 41)

#: The minimal parameters of the P3RPR1 robot (3-RPR, identical legs) in Schappler's HybrDyn /
#: robsynth-parroblib toolbox (``P3RPR1A0_minimal_parameter_para.m``), in our names: the
#: cylinder's and piston's inertia summed, the cylinder's and the piston's two first moments,
#: the piston's mass, and the platform's four parameters.
LITERATURE_10 = (
    "Jzz_1", "mcx_1", "mcy_1", "mcx_2", "mcy_2", "m_2", "Jzz_3", "mcx_3", "mcy_3", "m_3",
)  # fmt: skip


@cache
def _functions(actuation: str):
    """(Y and tau_payload, efforts with symbolic pi), compiled from one program."""
    prog = Program()
    Y = idn.regressor(prog, S[actuation])
    payload = idn.payload_efforts(prog, S[actuation])
    efforts = idn.efforts(prog, S[actuation])
    regression = compile_program(prog, INPUTS, [*Y, *payload])
    symbolic = compile_program(prog, INPUTS + PI, efforts)
    return regression, symbolic


def _motion(q, qd, qdd) -> dict[str, np.ndarray]:
    names = (*syms.POSE_NAMES, *syms.VELOCITY_NAMES, *syms.ACCELERATION_NAMES)
    return {n: np.concatenate([q, qd, qdd], axis=1)[:, k] for k, n in enumerate(names)}


def regression(actuation: str, params, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
    """``Y`` (n, 3, 28) and ``tau_payload`` (n, 3) at the samples."""
    out = _functions(actuation)[0](**values_of(params, **_motion(q, qd, qdd)))
    Y = np.stack(out[: 3 * P], axis=-1).reshape(-1, 3, P)
    return Y, np.stack(out[3 * P :], axis=-1)


def reference_efforts(params, actuation: str, q, qd, qdd) -> np.ndarray:
    out = ne.solve(params, actuation, q, qd, qdd)
    effort = EFFORT[actuation]
    return np.stack([out[f"{effort}_{leg}"] for leg in ne.LEGS], axis=-1)


def _cases():
    yield "paper", ne.paper_params(), *ne.sinusoid_motion(np.random.default_rng(7), T)
    for seed in range(4):
        robot, q, qd, qdd = ne.random_case(seed, T)
        yield f"random{seed}", robot["params"], q, qd, qdd


def _close(a: np.ndarray, b: np.ndarray, rtol: float = 1e-9) -> None:
    scale = max(float(np.abs(b).max()), 1e-300)
    assert np.abs(a - b).max() <= rtol * scale, np.abs(a - b).max() / scale


# ----------------------------------------------------------------------------------------------
# Names and the model's pi.


def test_names_and_sizes() -> None:
    names = idn.INERTIAL_PARAMETER_NAMES
    assert len(names) == 28 == len(set(names))
    assert names[:4] == ("m_1A", "mcx_1A", "mcy_1A", "Jzz_1A")
    assert names[4:8] == ("m_2A", "mcx_2A", "mcy_2A", "Jzz_2A")
    assert names[-4:] == ("m_3", "mcx_3", "mcy_3", "Jzz_3")
    assert idn.SHARED_PARAMETER_NAMES == (
        "m_1", "mcx_1", "mcy_1", "Jzz_1", "m_2", "mcx_2", "mcy_2", "Jzz_2",
        "m_3", "mcx_3", "mcy_3", "Jzz_3",
    )  # fmt: skip
    S = idn.identical_legs_matrix()
    assert S.shape == (28, 12)
    assert np.array_equal(S.sum(axis=0), [3] * 8 + [1] * 4)


def test_inertial_parameters_of_the_paper_robot() -> None:
    p = ne.paper_params()
    pi = idn.inertial_parameters(p)
    by_name = dict(zip(idn.INERTIAL_PARAMETER_NAMES, pi, strict=True))
    for leg in ne.LEGS:
        assert by_name[f"m_1{leg}"] == 3.0
        assert by_name[f"mcx_1{leg}"] == pytest.approx(0.3)
        assert by_name[f"Jzz_1{leg}"] == pytest.approx(3.0 * 0.2**2 / 3)  # rod about its end
        assert by_name[f"mcx_2{leg}"] == pytest.approx(0.15)
        assert by_name[f"Jzz_2{leg}"] == pytest.approx(1.5 * 0.2**2 / 3)
        assert by_name[f"mcy_1{leg}"] == by_name[f"mcy_2{leg}"] == 0.0
    assert (by_name["m_3"], by_name["mcx_3"], by_name["mcy_3"]) == (5.0, 0.0, 0.0)
    assert by_name["Jzz_3"] == pytest.approx(5.0 * 0.27 / 12)
    shared = idn.inertial_parameters(p, identical_legs=True)
    assert np.array_equal(shared, pi[[0, 1, 2, 3, 4, 5, 6, 7, 24, 25, 26, 27]])


# ----------------------------------------------------------------------------------------------
# The regressor against Newton-Euler, the power balance and the symbolic efforts.


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_regressor_reproduces_newton_euler(actuation: str) -> None:
    for _label, params, q, qd, qdd in _cases():
        Y, payload = regression(actuation, params, q, qd, qdd)
        tau = Y @ idn.inertial_parameters(params) + payload
        _close(tau, reference_efforts(params, actuation, q, qd, qdd))
        S = idn.identical_legs_matrix()
        shared = (Y @ S) @ idn.inertial_parameters(params, identical_legs=True) + payload
        _close(shared, tau)


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_payload_efforts_hold_the_payload_of_a_massless_robot(actuation: str) -> None:
    for _label, params, q, qd, qdd in list(_cases())[1:3]:
        massless = dict(params, m1=0.0, m2=0.0, m3=0.0, J1=0.0, J2=0.0, J3=0.0)
        _, payload = regression(actuation, params, q, qd, qdd)
        _close(payload, reference_efforts(massless, actuation, q, qd, qdd))
        _, at_rest = regression(actuation, params, q, 0 * qd, 0 * qdd)
        _close(at_rest, payload, rtol=1e-14)


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_platform_centre_of_mass_off_g(actuation: str) -> None:
    """mcx_3, mcy_3 matter: the reference robot whose G is the platform's true centre of mass
    G' = G + R c (platform joints p - c) gives the efforts of pi with m_3 c, J_G = J' + m |c|^2.
    """
    for _label, params, q, qd, qdd in list(_cases())[:3]:
        params = dict(params, fx=0.0, fy=0.0, mz=0.0)
        c = np.array([0.03, -0.02])
        shifted = dict(params)
        for leg in ne.LEGS:
            shifted[f"x{leg}3"] -= c[0]
            shifted[f"y{leg}3"] -= c[1]
        phi, w, eps = q[:, 2], qd[:, 2], qdd[:, 2]
        rc = np.stack(
            [np.cos(phi) * c[0] - np.sin(phi) * c[1], np.sin(phi) * c[0] + np.cos(phi) * c[1]],
            axis=-1,
        )
        perp = np.stack([-rc[:, 1], rc[:, 0]], axis=-1)
        q2, qd2, qdd2 = q.copy(), qd.copy(), qdd.copy()
        q2[:, :2] += rc
        qd2[:, :2] += w[:, None] * perp
        qdd2[:, :2] += eps[:, None] * perp - (w**2)[:, None] * rc
        pi = idn.inertial_parameters(params)
        m3 = params["m3"]
        pi[-3:] = [m3 * c[0], m3 * c[1], params["J3"] + m3 * c @ c]
        Y, payload = regression(actuation, params, q, qd, qdd)
        assert np.abs(payload).max() < 1e-12
        _close(Y @ pi, reference_efforts(shifted, actuation, q2, qd2, qdd2))


def _perp(v: np.ndarray) -> np.ndarray:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def energy_rates(params, q, qd, qdd) -> np.ndarray:
    """d/dt of the energy (kinetic + potential) per unit of each inertial parameter (n, 28).

    A body with joint point O (velocity v, acceleration a), rate w, w' and axes u_x, u_y:
    ``E = m (v^2/2 - g . O) + w v . (z x mc) - g . mc + J w^2 / 2`` (mc in the world frame), so
    the rates are ``v . a - g . v`` (m), ``w' v . (z x u) + w a . (z x u) - w^2 v . u
    - w g . (z x u)`` (m c along u), and ``w w'`` (J).
    """
    kin = ne.kinematics(params, q, qd, qdd)
    g = np.array([params["gx"], params["gy"]])
    n = q.shape[0]

    def body(v, a, w, eps, ux):
        columns = [_dot(v, a) - v @ g]
        for u in (ux, _perp(ux)):
            zu = _perp(u)
            columns.append(eps * _dot(v, zu) + w * _dot(a, zu) - w**2 * _dot(v, u) - w * (zu @ g))
        columns.append(w * eps)
        return columns

    out = []
    zero = np.zeros((n, 2))
    for leg in ne.LEGS:
        k = kin[leg]
        e, nn, w, eps = k["e"], k["n"], k["omega10"], k["eps10"]
        s = params["l0"] + k["lambda21"]
        v2 = k["v21"][:, None] * e + (s * w)[:, None] * nn
        a2 = (k["gamma21"] - s * w**2)[:, None] * e + (s * eps + 2 * k["v21"] * w)[:, None] * nn
        out += body(zero, zero, w, eps, e)
        out += body(v2, a2, w, eps, e)
    ux = np.stack([np.cos(q[:, 2]), np.sin(q[:, 2])], axis=-1)
    out += body(qd[:, :2], qdd[:, :2], qd[:, 2], qdd[:, 2], ux)
    return np.stack(out, axis=-1)


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_every_column_satisfies_the_power_balance(actuation: str) -> None:
    """``sum_legs Y[leg, j] qa'_leg = dE_j/dt`` for each of the 28 columns separately (the
    first moments normal to the legs, mcy_1*, mcy_2*, which the model's pi leaves at zero,
    included); and the payload efforts do the payload's work."""
    rate = RATE[actuation]
    for _label, params, q, qd, qdd in _cases():
        Y, payload = regression(actuation, params, q, qd, qdd)
        kin = ne.kinematics(params, q, qd, qdd)
        qa_rate = np.stack([kin[leg][rate] for leg in ne.LEGS], axis=-1)
        power = np.einsum("nlj,nl->nj", Y, qa_rate)
        expected = energy_rates(params, q, qd, qdd)
        for j in range(P):
            scale = np.abs(Y[:, :, j]).max() * np.abs(qa_rate).max()
            assert np.abs(power[:, j] - expected[:, j]).max() <= 1e-9 * max(scale, 1e-12), (
                idn.INERTIAL_PARAMETER_NAMES[j]
            )
        payload_power = np.einsum("nl,nl->n", payload, qa_rate)
        work = -(qd[:, 0] * params["fx"] + qd[:, 1] * params["fy"] + qd[:, 2] * params["mz"])
        _close(payload_power, work)


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_efforts_are_linear_in_pi(actuation: str) -> None:
    """The program with pi symbolic, evaluated at random pi (sideways first moments
    included), equals Y @ pi + tau_payload: Y holds every term, none is bilinear."""
    rng = np.random.default_rng(11)
    symbolic = _functions(actuation)[1]
    for _label, params, q, qd, qdd in list(_cases())[:3]:
        Y, payload = regression(actuation, params, q, qd, qdd)
        for _ in range(3):
            pi = rng.uniform(-1.0, 1.0, P)
            values = values_of(params, **_motion(q, qd, qdd))
            values.update(zip(idn.INERTIAL_PARAMETER_NAMES, pi, strict=True))
            tau = np.stack(symbolic(**values), axis=-1)
            _close(tau, Y @ pi + payload)


def test_regressor_shares_a_program_with_the_inverse_dynamics() -> None:
    """Appended to a program that already holds the model's derivation, the kinematics are
    shared and the differently defined loads renamed; the values do not change."""
    from rpr3gen_derive.planar.derivation import derive

    derivation = derive(S["revolute"])
    prog, outputs = derivation.program, derivation.outputs
    before = len(prog.assignments)
    Y = idn.regressor(prog, S["revolute"])
    assert len(prog.assignments) > before
    names = [a.symbol.name for a in prog.assignments]
    assert len(names) == len(set(names))
    assert "load1r_A__pi" in names  # the motor torque of leg A, with pi symbolic
    _label, params, q, qd, qdd = next(iter(_cases()))
    f = compile_program(prog, INPUTS, [*Y, outputs["m10_A"]])
    out = f(**values_of(params, **_motion(q, qd, qdd)))
    Y_here = np.stack(out[: 3 * P], axis=-1).reshape(-1, 3, P)
    Y_alone, payload = regression("revolute", params, q, qd, qdd)
    _close(Y_here, Y_alone, rtol=1e-13)
    _close(out[-1], Y_alone[:, 0] @ idn.inertial_parameters(params) + payload[:, 0])


# ----------------------------------------------------------------------------------------------
# Base parameters.


@cache
def stacked(actuation: str, identical_legs: bool, robot: str) -> tuple[np.ndarray, dict]:
    """The observation matrix W of many random samples of one robot (paper or random)."""
    rng = np.random.default_rng(2024)
    if robot == "paper":
        params = ne.paper_params()
        q, qd, qdd = ne.sinusoid_motion(rng, np.linspace(0.0, 20.0, 150))
    else:
        case, q, qd, qdd = ne.random_case(5, np.linspace(0.0, 20.0, 150))
        params = case["params"]
    # Independent random velocities and accelerations at the poses: more exciting than one path.
    qd = rng.normal(0.0, [0.1, 0.1, 0.5], qd.shape)
    qdd = rng.normal(0.0, [1.0, 1.0, 5.0], qdd.shape)
    Y, _ = regression(actuation, params, q, qd, qdd)
    W = Y.reshape(-1, P)
    if identical_legs:
        W = W @ idn.identical_legs_matrix()
    return W, params


@pytest.mark.parametrize("actuation", ACTUATIONS)
@pytest.mark.parametrize("robot", ["paper", "random"])
@pytest.mark.parametrize(("identical_legs", "B"), [(False, 19), (True, 9)])
def test_base_parameters(actuation: str, robot: str, identical_legs: bool, B: int) -> None:
    W, params = stacked(actuation, identical_legs, robot)
    names = idn.parameter_names(identical_legs)
    base = idn.base_parameters(W, names, idn.preference(identical_legs))
    assert base.rank == B == len(base.names) == base.matrix.shape[0]
    legs = ("",) if identical_legs else ne.LEGS
    assert base.unidentifiable == tuple(f"m_1{leg}" for leg in legs)
    assert base.regrouped == tuple(f"{q}_2{leg}" for leg in legs for q in ("m", "Jzz"))
    assert set(base.names) == set(idn.regroupings(identical_legs))
    # The closed-form regroupings are the numerical ones.
    K = idn.regrouping_matrix(params, identical_legs)
    order = [list(idn.regroupings(identical_legs)).index(n) for n in base.names]
    np.testing.assert_allclose(K[order], base.matrix, atol=1e-9)
    # W pi = W_b (K pi) for any pi: the base parameters carry everything W sees.
    rng = np.random.default_rng(3)
    pi = rng.normal(size=(len(names), 4))
    Wb = W[:, [names.index(n) for n in base.names]]
    np.testing.assert_allclose(Wb @ (base.matrix @ pi), W @ pi, atol=1e-9 * np.abs(W).max())
    # The rank gap is clear: the B-th pivot is far above round-off.
    assert idn.numerical_rank(W, rtol=1e-6) == B


def test_regroupings_in_closed_form() -> None:
    r = idn.regroupings(identical_legs=True)
    s = {n: sp.Symbol(n, real=True) for n in idn.SHARED_PARAMETER_NAMES}
    l2 = paper.params["l2"]
    assert sp.expand(r["Jzz_1"] - (s["Jzz_1"] + s["Jzz_2"] - l2**2 * s["m_2"])) == 0
    assert sp.expand(r["mcx_2"] - (s["mcx_2"] - l2 * s["m_2"])) == 0
    assert sp.expand(r["m_3"] - (s["m_3"] + 3 * s["m_2"])) == 0
    # The paper's platform joints sum to zero: no first moment from the pistons' masses.
    K = idn.regrouping_matrix(ne.paper_params(), identical_legs=True)
    names = list(idn.regroupings(identical_legs=True))
    m2 = idn.SHARED_PARAMETER_NAMES.index("m_2")
    assert K[names.index("mcx_3"), m2] == pytest.approx(0.0, abs=1e-15)
    assert K[names.index("Jzz_3"), m2] == pytest.approx(3 * 0.3**2)


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_the_literature_ten_are_not_all_identifiable(actuation: str) -> None:
    """The toolbox's 10 minimal parameters have rank 9 here: the piston's mass is a point
    mass at the platform joint A3 (plus a first moment and inertia about A2), which the
    platform's m, mcx, mcy, Jzz already describe; a serial-chain regrouping of each leg
    cannot see that the leg's last point belongs to the platform."""
    for robot in ("paper", "random"):
        W, params = stacked(actuation, True, robot)
        names = idn.SHARED_PARAMETER_NAMES
        # Jzz_1 + Jzz_2 enter as one parameter: the Jzz_1 column (equal to the Jzz_2 column).
        np.testing.assert_allclose(
            W[:, names.index("Jzz_1")], W[:, names.index("Jzz_2")], atol=1e-12
        )
        columns = W[:, [names.index(n) for n in LITERATURE_10]]
        assert idn.numerical_rank(columns) == 9
        without_m2 = [n for n in LITERATURE_10 if n != "m_2"]
        assert idn.numerical_rank(W[:, [names.index(n) for n in without_m2]]) == 9
        # The dependency, explicitly: Y_m2 = 3 Y_m3 + sum(p) Y_mc3 + sum |p|^2 Y_J3
        # - l2 Y_mcx2 - l2^2 Y_J.
        p = [(params[f"x{leg}3"], params[f"y{leg}3"]) for leg in ne.LEGS]
        col = {n: W[:, names.index(n)] for n in names}
        l2 = params["l2"]
        rebuilt = (
            3 * col["m_3"]
            + sum(x for x, _ in p) * col["mcx_3"]
            + sum(y for _, y in p) * col["mcy_3"]
            + sum(x * x + y * y for x, y in p) * col["Jzz_3"]
            - l2 * col["mcx_2"]
            - l2**2 * col["Jzz_2"]
        )
        np.testing.assert_allclose(rebuilt, col["m_2"], atol=1e-9 * np.abs(W).max())
