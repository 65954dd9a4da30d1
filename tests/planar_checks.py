"""Physics checks shared by the tests of the planar derivation and of its generated code.

Everything here works on a model dict of the general format (``shared/spec/interfaces.md``, "Any
planar 3-leg robot") and on output dicts named as the spec names them (``q1_A`` ... ``tau_C``),
with NumPy alone: it imports nothing from ``rpr3gen`` or ``derive/``, so the tests that use it
judge the production code by laws it was not built from (the parameter vector of the general
format, the inertial parameters, balance of forces and moments, relative errors by unit).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

LEGS: tuple[str, ...] = ("A", "B", "C")
DEFAULT_GRAVITY: tuple[float, float] = (0.0, -9.81)


def _perp(v: np.ndarray) -> np.ndarray:
    """``v`` turned by +90 deg (last axis = x, y)."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _rotate(theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    v = np.broadcast_to(np.asarray(v, dtype=float), (*np.shape(theta), 2))
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def wrap(angle: Any) -> np.ndarray:
    """Angles wrapped into ``[-pi, pi]``."""
    a = np.asarray(angle, dtype=float)
    return a - 2 * np.pi * np.rint(a / (2 * np.pi))


def gravity(model: Mapping[str, Any]) -> np.ndarray:
    return np.asarray(model.get("environment", {}).get("gravity", DEFAULT_GRAVITY), dtype=float)


def payload(model: Mapping[str, Any]) -> tuple[np.ndarray, float]:
    p = model.get("payload", {})
    return np.asarray(p.get("force", (0.0, 0.0)), dtype=float), float(p.get("moment", 0.0))


def unit_axes(model: Mapping[str, Any], leg: str) -> np.ndarray:
    """(3, 2) unit axes of the leg's joints (rows of R joints zero)."""
    axes = np.zeros((3, 2))
    for j, kind in enumerate(model["leg"]):
        if kind == "P":
            u = np.asarray(model["legs"][leg]["axes"][j], dtype=float)
            axes[j] = u / np.hypot(*u)
    return axes


def param_values(model: Mapping[str, Any]) -> dict[str, float]:
    """The general format's parameter vector by name (``shared/spec``; the names of
    ``derive/planar/general.py``), computed from the model dict: joint points, unit P axes,
    ``sigma_L`` (sign at home of the leg's serial determinant, columns ``(perp(P3 - Pj), 1)``
    for R and ``(u_j, 0)`` for P), masses, centres of mass and inertias, platform, gravity and
    payload."""
    kinds = model["leg"]
    out: dict[str, float] = {}
    for leg in LEGS:
        L = model["legs"][leg]
        P = np.asarray(L["joints"], dtype=float)
        u = unit_axes(model, leg)
        columns = []
        for j in range(3):
            out[f"x{j + 1}_{leg}"], out[f"y{j + 1}_{leg}"] = (float(v) for v in P[j])
            if kinds[j] == "P":
                out[f"ux{j + 1}_{leg}"], out[f"uy{j + 1}_{leg}"] = (float(v) for v in u[j])
                columns.append([u[j][0], u[j][1], 0.0])
            else:
                arm = _perp(P[2] - P[j])
                columns.append([arm[0], arm[1], 1.0])
        out[f"sigma_{leg}"] = float(np.sign(np.linalg.det(np.array(columns).T)))
        for k in (1, 2):
            out[f"m{k}_{leg}"] = float(L["mass"][k - 1])
            out[f"J{k}_{leg}"] = float(L["inertia"][k - 1])
            out[f"cx{k}_{leg}"], out[f"cy{k}_{leg}"] = (float(v) for v in L["com"][k - 1])
    plat = model["platform"]
    out["m3"], out["J3"] = float(plat["mass"]), float(plat["inertia"])
    out["cx3"], out["cy3"] = (float(v) for v in plat["com"])
    out["gx"], out["gy"] = (float(v) for v in gravity(model))
    force, moment = payload(model)
    out["fx"], out["fy"] = (float(v) for v in force)
    out["mz"] = moment
    return out


def inertial_values(model: Mapping[str, Any]) -> dict[str, float]:
    """The inertial parameters by name (``m_1A``, ``mcx_1A``, ``mcy_1A``, ``Jzz_1A`` ... ``Jzz_3``):
    per body, its mass, first moment about its first joint point at home (world axes) and
    inertia about that point; the platform's about G."""
    out: dict[str, float] = {}

    def body(name: str, m: float, c: np.ndarray, J: float) -> None:
        out[f"m_{name}"] = m
        out[f"mcx_{name}"], out[f"mcy_{name}"] = m * c[0], m * c[1]
        out[f"Jzz_{name}"] = J + m * float(c @ c)

    for leg in LEGS:
        L = model["legs"][leg]
        for k in (1, 2):
            c = np.asarray(L["com"][k - 1], dtype=float) - np.asarray(L["joints"][k - 1])
            body(f"{k}{leg}", float(L["mass"][k - 1]), c, float(L["inertia"][k - 1]))
    plat = model["platform"]
    body("3", float(plat["mass"]), np.asarray(plat["com"], dtype=float), float(plat["inertia"]))
    return out


def rotated(model: Mapping[str, Any], degrees: float) -> dict[str, Any]:
    """The whole scene turned about the world origin: joints, axes, centres of mass (the
    platform's too), gravity and the payload force; the payload moment, masses and inertias
    unchanged. A pose ``(x, y, phi)`` of ``model`` is ``(R (x, y), phi)`` of the result."""
    th = math.radians(degrees)
    R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])

    def turn(v: Any) -> list:
        return (np.asarray(v, dtype=float) @ R.T).tolist()

    out = {k: v for k, v in model.items() if k not in ("legs", "platform", "symmetric")}
    out["legs"] = {}
    for leg in LEGS:
        L = model["legs"][leg]
        new = dict(L)
        for key in ("joints", "axes", "com"):
            if key in L:
                new[key] = turn(L[key])
        out["legs"][leg] = new
    plat = dict(model["platform"])
    plat["com"] = turn(plat["com"])
    out["platform"] = plat
    out["environment"] = {"gravity": turn(gravity(model))}
    force, moment = payload(model)
    out["payload"] = {"force": turn(force), "moment": moment}
    return out


# ------------------------------------------------------------------------------------------------
# Errors by unit.


def output_unit(name: str, leg_kinds: str, actuated: int) -> str:
    """A unit class of an output name ``family_L`` (angles and lengths apart, forces, moments)."""
    family = name.split("_")[0]
    if family == "tau":
        return "N m" if leg_kinds[actuated - 1] == "R" else "N"
    if family[0] == "q":  # q, qd, qdd
        j = int(family[-1])
        return f"{family[:-1]}:{'rad' if leg_kinds[j - 1] == 'R' else 'm'}"
    if family[0] == "f":
        return "N"
    if family[0] == "m":
        return "N m"
    return family


def difference(name: str, a: np.ndarray, b: np.ndarray, leg_kinds: str) -> np.ndarray:
    """``a - b``; a revolute joint's coordinate modulo 2 pi."""
    family = name.split("_")[0]
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    if family in ("q1", "q2", "q3") and leg_kinds[int(family[1]) - 1] == "R":
        d = wrap(d)
    return d


def worst_error(
    out: Mapping[str, np.ndarray],
    ref: Mapping[str, np.ndarray],
    leg_kinds: str,
    actuated: int,
    names: Sequence[str] | None = None,
) -> tuple[float, str]:
    """The largest ``|out - ref|`` over ``names`` (default: every name of ``ref``), relative to
    the largest ``|ref|`` of the same unit class (:func:`output_unit`), and its name."""
    names = list(ref) if names is None else list(names)
    scale: dict[str, float] = {}
    for name in names:
        unit = output_unit(name, leg_kinds, actuated)
        scale[unit] = max(scale.get(unit, 0.0), float(np.max(np.abs(ref[name]))))
    worst, where = 0.0, ""
    for name in names:
        d = difference(name, out[name], ref[name], leg_kinds)
        if not np.all(np.isfinite(d)):
            return math.inf, name
        err = float(np.max(np.abs(d))) / max(scale[output_unit(name, leg_kinds, actuated)], 1e-300)
        if err > worst:
            worst, where = err, name
    return worst, where


# ------------------------------------------------------------------------------------------------
# Balance of forces and moments.


def _compose(g: tuple[np.ndarray, np.ndarray], h: tuple[np.ndarray, np.ndarray]):
    """Planar rigid motions ``(theta, t)``, ``x -> R(theta) x + t``: ``g o h``."""
    return g[0] + h[0], _rotate(g[0], h[1]) + g[1]


def leg_bodies(
    model: Mapping[str, Any], leg: str, out: Mapping[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Where the leg's bodies are, from its joint coordinates in ``out`` (``q1_L .. q3_L``): a
    revolute joint turns the later body about the joint's (current) point, a prismatic one moves
    it along its axis, fixed in the earlier body. Returns the current points of joints 1, 2, 3
    (``p1 p2 p3``), the centres of mass of bodies 1 and 2 (``c1 c2``) and the platform pose that
    the chain reaches (``pose``), each (n, 2) (the pose (n, 3))."""
    kinds = model["leg"]
    L = model["legs"][leg]
    P = np.asarray(L["joints"], dtype=float)
    u = unit_axes(model, leg)
    qj = [np.asarray(out[f"q{j}_{leg}"], dtype=float) for j in (1, 2, 3)]
    n = qj[0].shape[0]
    g = (np.zeros(n), np.zeros((n, 2)))
    res: dict[str, np.ndarray] = {}
    for j in range(3):
        if kinds[j] == "R":
            h = (qj[j], P[j] - _rotate(qj[j], P[j]))
        else:
            h = (np.zeros(n), qj[j][:, None] * u[j])
        g = _compose(g, h)
        res[f"p{j + 1}"] = _rotate(g[0], P[j]) + g[1]
        if j < 2:
            res[f"c{j + 1}"] = _rotate(g[0], np.asarray(L["com"][j], dtype=float)) + g[1]
    res["pose"] = np.column_stack([g[1], g[0]])
    return res


def rest_residual(
    model: Mapping[str, Any], out: Mapping[str, np.ndarray], q: np.ndarray
) -> tuple[float, float]:
    """At rest, the base's loads on the three legs (joint 1) balance the weight of every body
    and the payload: the force and the moment about the world origin that remain, relative to
    the total weight and to the total weight times the robot's size."""
    g = gravity(model)
    force_p, moment_p = payload(model)
    q = np.asarray(q, dtype=float)
    plat = model["platform"]
    G = q[:, :2]
    c3 = G + _rotate(q[:, 2], np.asarray(plat["com"], dtype=float))
    m3 = float(plat["mass"])
    force = m3 * g + force_p
    moment = _cross(c3, m3 * g) + _cross(G, force_p) + moment_p
    total = m3
    size = 0.0
    for leg in LEGS:
        b = leg_bodies(model, leg, out)
        f1 = np.column_stack([out[f"fx1_{leg}"], out[f"fy1_{leg}"]])
        force = force + f1
        moment = moment + out[f"m1_{leg}"] + _cross(b["p1"], f1)
        for k in (1, 2):
            m = float(model["legs"][leg]["mass"][k - 1])
            force = force + m * g
            moment = moment + _cross(b[f"c{k}"], m * g)
            total += m
        size = max(size, float(np.max(np.abs(b["p1"]))))
    weight = total * float(np.hypot(*g))
    return (
        float(np.max(np.abs(force))) / weight,
        float(np.max(np.abs(moment))) / (weight * size),
    )


def platform_residual(
    model: Mapping[str, Any],
    out: Mapping[str, np.ndarray],
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
) -> tuple[float, float]:
    """Newton-Euler of the platform alone from the joint-3 loads of ``out`` (exerted by each
    leg's body 2 on the platform at joint 3's point, moment about it), gravity and the payload:
    the force and moment (about the centre of mass) residuals relative to the largest joint-3
    force and that times the platform's radius."""
    g = gravity(model)
    force_p, moment_p = payload(model)
    q, qd, qdd = (np.asarray(a, dtype=float) for a in (q, qd, qdd))
    plat = model["platform"]
    m3, J3 = float(plat["mass"]), float(plat["inertia"])
    r = _rotate(q[:, 2], np.asarray(plat["com"], dtype=float))
    c3 = q[:, :2] + r
    a3 = qdd[:, :2] + qdd[:, 2:3] * _perp(r) - qd[:, 2:3] ** 2 * r
    force = m3 * g + force_p - m3 * a3
    moment = _cross(q[:, :2] - c3, np.broadcast_to(force_p, c3.shape)) + moment_p - J3 * qdd[:, 2]
    biggest, radius = 0.0, 0.0
    for leg in LEGS:
        home = np.asarray(model["legs"][leg]["joints"][2], dtype=float)
        p3 = q[:, :2] + _rotate(q[:, 2], home)
        f3 = np.column_stack([out[f"fx3_{leg}"], out[f"fy3_{leg}"]])
        force = force + f3
        moment = moment + out[f"m3_{leg}"] + _cross(p3 - c3, f3)
        biggest = max(biggest, float(np.max(np.hypot(f3[:, 0], f3[:, 1]))))
        radius = max(radius, float(np.hypot(*home)))
    return (
        float(np.max(np.abs(force))) / biggest,
        float(np.max(np.abs(moment))) / (biggest * radius),
    )
