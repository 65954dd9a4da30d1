"""A spatial robot as a MuJoCo model (MJCF): ``rpr3gen export --format mjcf``.

So that a user can simulate contact and the environment in MuJoCo with the model's own numbers.
Every body's frame is the world frame at home, so the model file's home points are the bodies'
local coordinates and every ``qpos`` of a joint is the joint coordinate of docs/spatial-robots.md
(zero at home):

- the platform, a child of the world with the joints ``x, y, z`` (slides along the world axes)
  and, for a hexapod, ``c, b, a`` (hinges about z, then the turned y, then x, through the
  platform frame's origin): ``R = Rz(c) Ry(b) Rx(a)``, its ``qpos`` the pose;
- per leg, the bodies of the model file in chain order: a U is two hinges at its centre, about
  its first axis then its second (``Rot(u1, a) Rot(u2, b)``), an R a hinge, a P a slide along
  its home axis (in the earlier body, so it turns with it); a Delta's rod a body with a ball
  joint at its upper S, inertia ``rod_inertia`` across it and a small one about it (MuJoCo needs
  a positive tensor; nothing turns a rod about its own axis);
- the S joints at the platform are ``connect`` equalities (the loops closed, soft as MuJoCo's
  constraints are: ``solref`` and ``solimp`` below);
- one ``motor`` per leg on the actuated joint, ``gear = 1``: ``ctrl`` is ``tau_L``.

The payload is not part of the model: apply it with ``xfrc_applied`` on the platform (MuJoCo
applies a force there at the body's centre of mass; the model's payload force acts at the
platform frame's origin). Contacts are off: there is no geometry but markers without mass.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from rpr3gen.atomic import atomic_write
from rpr3gen.errors import ModelError
from rpr3gen.model import Model
from rpr3gen.spatial_modes import point
from rpr3gen.structure import INERTIA_ENTRIES

__all__ = ["SOLIMP", "SOLREF", "TIMESTEP", "mjcf", "write_mjcf"]

TIMESTEP = 1e-3
#: The loops' softness: a time constant of two steps, critically damped, and an impedance that
#: leaves 1e-4 of an acceleration unconstrained.
SOLREF: tuple[float, float] = (2 * TIMESTEP, 1.0)
SOLIMP: tuple[float, float, float, float, float] = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: A rod's inertia about its own axis, as a fraction of its inertia across it.
ROD_SPIN = 1e-3


def _num(x: float) -> str:
    return repr(float(x))


def _vec(v: Sequence[float] | np.ndarray) -> str:
    return " ".join(_num(x) for x in v)


def _inertia(model: Model, k: int | str, leg: str | None) -> str:
    suffix = f"_{leg}" if leg else ""
    xx, yy, zz, xy, xz, yz = (model.params[f"I{k}{e}{suffix}"] for e in INERTIA_ENTRIES)
    return _vec((xx, yy, zz, xy, xz, yz))


def _inertial(mass: float, com: np.ndarray, full: str) -> str:
    return f'<inertial pos="{_vec(com)}" mass="{_num(mass)}" fullinertia="{full}"/>'


def mjcf(model: Model) -> str:
    """The MJCF text of a spatial ``model`` (module docstring)."""
    s = model.structure
    if not s.spatial:
        raise ModelError(
            f"export: the MJCF export serves spatial robots (hexapods and Deltas); "
            f"{model.name} is a {s.title}"
        )
    p = model.params
    lines = [
        f'<mujoco model="{model.name}">',
        '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
        f'  <option timestep="{_num(TIMESTEP)}" gravity="{_vec((p["gx"], p["gy"], p["gz"]))}" '
        'integrator="RK4" solver="Newton" tolerance="1e-12" iterations="200">',
        '    <flag contact="disable"/>',
        "  </option>",
        "  <default>",
        f'    <equality solref="{_vec(SOLREF)}" solimp="{_vec(SOLIMP)}"/>',
        '    <geom contype="0" conaffinity="0" mass="0" size="0.005"/>',
        "  </default>",
        "  <worldbody>",
        '    <body name="platform">',
    ]
    for axis, name in zip(("1 0 0", "0 1 0", "0 0 1"), ("x", "y", "z"), strict=True):
        lines.append(f'      <joint name="{name}" type="slide" axis="{axis}"/>')
    if s.dof == 6:
        for axis, name in zip(("0 0 1", "0 1 0", "1 0 0"), ("c", "b", "a"), strict=True):
            lines.append(f'      <joint name="{name}" type="hinge" axis="{axis}"/>')
    com3 = np.array([p["c3x"], p["c3y"], p["c3z"]])
    lines.append("      " + _inertial(p["m3"], com3, _inertia(model, 3, None)))
    lines.append('      <geom type="sphere" pos="0 0 0"/>')
    lines.append("    </body>")
    equalities: list[str] = []
    for leg in s.legs:
        lines += _leg(model, leg, equalities)
    lines.append("  </worldbody>")
    lines.append("  <equality>")
    lines += equalities
    lines.append("  </equality>")
    lines.append("  <actuator>")
    joint = {"UPS": "q2", "RUS": "q1", "PUS": "q1", "RSS2": "q1", "PSS2": "q1"}[s.leg]
    for leg in s.legs:
        lines.append(f'    <motor name="tau_{leg}" joint="{joint}_{leg}" gear="1"/>')
    lines.append("  </actuator>")
    lines.append("</mujoco>")
    return "\n".join(lines) + "\n"


def _u(model: Model, leg: str, centre: np.ndarray, indent: str, name: str) -> list[str]:
    at = _vec(centre)
    return [
        f'{indent}<joint name="{name}{k}_{leg}" type="hinge" pos="{at}" axis="{_vec(axis)}"/>'
        for k, axis in (("a", point(model, "u1", leg)), ("b", point(model, "u2", leg)))
    ]


def _connect(name: str, body: str, anchor: np.ndarray) -> str:
    """An S joint between ``body`` and the platform at the home point ``anchor``."""
    return f'    <connect name="{name}" body1="{body}" body2="platform" anchor="{_vec(anchor)}"/>'


def _leg(model: Model, leg: str, equalities: list[str]) -> list[str]:
    s = model.structure
    p = model.params
    B, P = point(model, "b", leg), point(model, "p", leg)
    c1 = point(model, "c1", leg)
    out: list[str] = []
    if s.leg == "UPS":
        u = (P - B) / np.linalg.norm(P - B)
        out += [f'    <body name="cylinder_{leg}">', *_u(model, leg, B, "      ", "q1")]
        out.append("      " + _inertial(p[f"m1_{leg}"], c1, _inertia(model, 1, leg)))
        out += [f'      <body name="piston_{leg}">',
                f'        <joint name="q2_{leg}" type="slide" pos="{_vec(B)}" axis="{_vec(u)}"/>',
                "        " + _inertial(p[f"m2_{leg}"], point(model, "c2", leg),
                                       _inertia(model, 2, leg)),
                f'        <geom type="sphere" pos="{_vec(P)}"/>',
                "      </body>", "    </body>"]  # fmt: skip
        equalities.append(_connect(f"S_{leg}", f"piston_{leg}", P))
        return out
    a = point(model, "a", leg)
    E = point(model, "e", leg)
    kind = "hinge" if s.leg[0] == "R" else "slide"
    first = "crank" if s.leg == "RUS" else "carriage" if s.leg[0] == "P" else "arm"
    out += [f'    <body name="{first}_{leg}">',
            f'      <joint name="q1_{leg}" type="{kind}" pos="{_vec(B)}" axis="{_vec(a)}"/>',
            "      " + _inertial(p[f"m1_{leg}"], c1, _inertia(model, 1, leg))]  # fmt: skip
    if s.leg in ("RUS", "PUS"):
        out += [f'      <body name="rod_{leg}">', *_u(model, leg, E, "        ", "q2")]
        out.append("        " + _inertial(p[f"m2_{leg}"], point(model, "c2", leg),
                                          _inertia(model, 2, leg)))  # fmt: skip
        out += [f'        <geom type="sphere" pos="{_vec(P)}"/>', "      </body>", "    </body>"]
        equalities.append(_connect(f"S_{leg}", f"rod_{leg}", P))
        return out
    bar = a if s.leg == "RSS2" else point(model, "bar", leg)
    half = p[f"w_{leg}"] / 2
    length = float(np.linalg.norm(P - E))
    u = (P - E) / length
    rod_i = p[f"Ir_{leg}"]
    tensor = rod_i * (np.eye(3) - np.outer(u, u)) + ROD_SPIN * rod_i * np.outer(u, u)
    full = _vec([tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2],
                 tensor[1, 2]])  # fmt: skip
    for k, sign in ((1, 1.0), (2, -1.0)):
        upper = E + sign * half * bar
        lower = P + sign * half * bar
        com = upper + p[f"fr_{leg}"] * (lower - upper)
        out += [f'      <body name="rod{k}_{leg}">',
                f'        <joint name="s{k}_{leg}" type="ball" pos="{_vec(upper)}"/>',
                "        " + _inertial(p[f"mr_{leg}"], com, full),
                f'        <geom type="sphere" pos="{_vec(lower)}"/>',
                "      </body>"]  # fmt: skip
        equalities.append(_connect(f"S{k}_{leg}", f"rod{k}_{leg}", lower))
    out.append("    </body>")
    return out


def write_mjcf(model: Model, path: str | os.PathLike[str]) -> None:
    """Write :func:`mjcf` of ``model`` to ``path``, atomically."""
    text = mjcf(model)
    with atomic_write(path, "w") as f:
        f.write(text)
