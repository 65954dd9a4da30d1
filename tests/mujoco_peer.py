"""The 3-RPR robot built in MuJoCo, as an independent peer of rpr3gen's dynamics (issue 12).

Written from ``shared/spec/conventions.md`` and the model's parameter mapping
(:attr:`rpr3gen.Model.params`); it imports nothing from rpr3gen, so agreement between the two is
evidence about both. MuJoCo is imported only by the functions that need it, so this module can
be imported (and :func:`build_mjcf` called) without MuJoCo installed.

The MJCF (world frame x0 horizontal, y0 up, every hinge axis z0, gravity ``(gx, gy, 0)``):

- per leg L, a body ``cylinder_L`` at the base pivot ``L1``, turned by ``alpha_L``, with the
  hinge ``phi10_L`` (axis z, at ``L1``); its local x axis is the leg axis ``e``, so the hinge's
  position *is* ``phi10`` of conventions.md. COM at ``c1`` along x, mass ``m1``, inertia ``J1``
  about the COM, axis z.
- its child ``piston_L`` at ``l0`` along x, with the slide ``lambda21_L`` along x: the slide's
  position is ``lambda21`` and the body's origin is ``A2``. COM at ``A2 + c2 e``, mass ``m2``,
  inertia ``J2``. The site ``tip_L`` at ``l2`` along x is the piston's end ``A3``.
- the platform, a child of the world with the planar joints ``x``, ``y`` (slides along x0, y0)
  and ``phi`` (hinge about z0 through G): its ``qpos`` is the pose ``(x, y, phi)`` of
  conventions.md. COM at G, mass ``m3``, inertia ``J3``. The site ``joint_L`` is the platform
  joint ``L3`` (``xL3, yL3`` in the platform frame).
- three ``connect`` equality constraints pull ``tip_L`` onto ``joint_L``: they close the loops.
- one motor per leg on the actuated joint, ``gear = 1``, no control range, so ``ctrl`` is the
  effort of conventions.md: ``m10_L`` (N m about +z0 on the cylinder, "revolute") or ``f21z_L``
  (N along e on the piston, "prismatic").

Out-of-plane rotations and translations have no joint, so the inertia about x and y never enters
the dynamics; it is set to a valid (triangle-inequality) value: a rod ``(J/1e6, J, J)`` for the
legs, a plate ``(J/2, J/2, J)`` for the platform. Contacts are disabled and bodies carry only
visual geoms (no mass: ``inertiafromgeom="false"``).

The payload wrench ``fx, fy, mz`` at G is not part of the MJCF (MuJoCo has no constant applied
wrench in a model); :func:`apply_payload` writes it into ``data.xfrc_applied``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

LEGS: tuple[str, ...] = ("A", "B", "C")
ACTUATIONS: tuple[str, ...] = ("revolute", "prismatic")

TIMESTEP = 1e-3
"""Default step, s: with RK4 and the constraint settings below, 1 s of the paper's rectilinear
motion driven open-loop by rpr3gen's efforts stays within 5e-6 m of the reference."""

SOLREF: tuple[float, float] = (2 * TIMESTEP, 1.0)
"""Default ``(timeconst, dampratio)`` of the loop closures: the stiffest MuJoCo allows at
:data:`TIMESTEP` (with ``refsafe`` on it clamps ``timeconst`` to ``2 * timestep``)."""

SOLIMP: tuple[float, float, float, float, float] = (0.9999, 0.9999, 0.001, 0.5, 2.0)
"""Default impedance of the loop closures: ``d = 0.9999`` (``mjMAXIMP``), the hardest
constraint MuJoCo allows; the regularisation ``R = (1 - d)/d A_ii`` then bends the constrained
accelerations by ~1e-4 relative."""

# Inertia about the leg axis of a slender rod, relative to J (MuJoCo needs a positive value).
_ROD_AXIAL = 1e-6
# Radius of the visual geoms, m (no mass, no contact).
_GEOM_RADIUS = 0.01


def _num(value: float) -> str:
    # repr round-trips a float exactly, so the MJCF carries the model's numbers bit for bit.
    return repr(float(value))


def _vec(values: Sequence[float]) -> str:
    return " ".join(_num(v) for v in values)


def build_mjcf(
    params: Mapping[str, float],
    actuation: str,
    *,
    timestep: float = TIMESTEP,
    integrator: str = "RK4",
    solref: Sequence[float] = SOLREF,
    solimp: Sequence[float] = SOLIMP,
) -> str:
    """MJCF text of the robot with the given parameters (layout in the module docstring).

    Args:
        params: ``rpr3gen.Model.params`` (or the same keys): base pivots ``xA1..yC1`` (m, world),
            platform joints ``xA3..yC3`` (m, platform frame), ``alpha_A..alpha_C`` (rad),
            ``l0, l2, c1, c2`` (m), ``m1, m2, m3`` (kg), ``J1, J2, J3`` (kg m², about the COM,
            axis z), ``gx, gy`` (m/s²). The payload ``fx, fy, mz`` is ignored here (see
            :func:`apply_payload`).
        actuation: ``"revolute"`` (motors on the hinges ``phi10_*``) or ``"prismatic"``
            (motors on the slides ``lambda21_*``).
        timestep: ``option/timestep``, s.
        integrator: ``option/integrator`` (``"RK4"``, ``"Euler"``, ``"implicitfast"``, ...).
        solref: ``(timeconst, dampratio)`` of the three ``connect`` constraints.
        solimp: ``(dmin, dmax, width, midpoint, power)`` of the three ``connect`` constraints.

    Returns:
        The MJCF XML. The keyframe ``central`` is the central configuration (G = 0, phi = 0).
    """
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    p = {k: float(v) for k, v in params.items()}
    l0, l2, c1, c2 = p["l0"], p["l2"], p["c1"], p["c2"]
    c1p, c2p = p.get("c1_perp", 0.0), p.get("c2_perp", 0.0)  # along the body's y = n

    legs = []
    for leg in LEGS:
        a1 = (p[f"x{leg}1"], p[f"y{leg}1"], 0.0)
        legs.append(
            f"""
    <body name="cylinder_{leg}" pos="{_vec(a1)}" euler="0 0 {_num(p[f"alpha_{leg}"])}">
      <joint name="phi10_{leg}" type="hinge" axis="0 0 1"/>
      <inertial pos="{_num(c1)} {_num(c1p)} 0" mass="{_num(p["m1"])}"
                diaginertia="{_vec((_ROD_AXIAL * p["J1"], p["J1"], p["J1"]))}"/>
      <geom type="capsule" fromto="0 0 0 {_num(2 * c1)} 0 0" size="{_GEOM_RADIUS}"
            rgba="0.3 0.4 0.8 1"/>
      <body name="piston_{leg}" pos="{_num(l0)} 0 0">
        <joint name="lambda21_{leg}" type="slide" axis="1 0 0"/>
        <inertial pos="{_num(c2)} {_num(c2p)} 0" mass="{_num(p["m2"])}"
                  diaginertia="{_vec((_ROD_AXIAL * p["J2"], p["J2"], p["J2"]))}"/>
        <geom type="capsule" fromto="0 0 0 {_num(l2)} 0 0" size="{_GEOM_RADIUS / 2}"
              rgba="0.8 0.8 0.8 1"/>
        <site name="tip_{leg}" pos="{_num(l2)} 0 0"/>
      </body>
    </body>"""
        )
    sites = "".join(
        f'\n      <site name="joint_{leg}" pos="{_vec((p[f"x{leg}3"], p[f"y{leg}3"], 0.0))}"/>'
        for leg in LEGS
    )
    spokes = "".join(
        f'\n      <geom type="capsule" fromto="0 0 0 {_vec((p[f"x{leg}3"], p[f"y{leg}3"], 0.0))}"'
        f' size="{_GEOM_RADIUS}" rgba="0.8 0.5 0.2 1"/>'
        for leg in LEGS
    )
    connects = "".join(f'\n    <connect site1="tip_{leg}" site2="joint_{leg}"/>' for leg in LEGS)
    joint = "phi10" if actuation == "revolute" else "lambda21"
    motors = "".join(
        f'\n    <motor name="{joint}_{leg}" joint="{joint}_{leg}" gear="1"/>' for leg in LEGS
    )
    central = _vec(central_qpos(p))

    return f"""<mujoco model="rpr3 {actuation}">
  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>
  <option timestep="{_num(timestep)}" integrator="{integrator}" gravity="{_num(p["gx"])} \
{_num(p["gy"])} 0"
          solver="Newton" jacobian="dense" iterations="100" tolerance="1e-12">
    <flag contact="disable"/>
  </option>
  <default>
    <equality solref="{_vec(solref)}" solimp="{_vec(solimp)}"/>
    <geom contype="0" conaffinity="0"/>
  </default>
  <worldbody>{"".join(legs)}
    <body name="platform">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="y" type="slide" axis="0 1 0"/>
      <joint name="phi" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{_num(p["m3"])}"
                diaginertia="{_vec((p["J3"] / 2, p["J3"] / 2, p["J3"]))}"/>{spokes}{sites}
    </body>
  </worldbody>
  <equality>{connects}
  </equality>
  <actuator>{motors}
  </actuator>
  <keyframe>
    <key name="central" qpos="{central}"/>
  </keyframe>
</mujoco>
"""


# -- kinematics, from the parameters alone --------------------------------------------------------


@dataclass(frozen=True)
class Geometry:
    """What the inverse kinematics needs, per leg in :data:`LEGS` order (SI units)."""

    base: np.ndarray  # (3, 2) base pivots L1, world frame
    platform: np.ndarray  # (3, 2) platform joints L3, platform frame
    alpha: np.ndarray  # (3,) leg angles at phi10 = 0
    l0: float
    l2: float

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Geometry:
        return cls(
            base=np.array([[params[f"x{L}1"], params[f"y{L}1"]] for L in LEGS], dtype=float),
            platform=np.array([[params[f"x{L}3"], params[f"y{L}3"]] for L in LEGS], dtype=float),
            alpha=np.array([params[f"alpha_{L}"] for L in LEGS], dtype=float),
            l0=float(params["l0"]),
            l2=float(params["l2"]),
        )

    @classmethod
    def from_mujoco(cls, model: Any) -> Geometry:
        """Read the geometry back from a model compiled from :func:`build_mjcf`."""
        import mujoco

        def body(name: str) -> int:
            return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)

        def site(name: str) -> int:
            return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)

        cylinders = [body(f"cylinder_{L}") for L in LEGS]
        quats = model.body_quat[cylinders]
        return cls(
            base=model.body_pos[cylinders, :2].copy(),
            platform=model.site_pos[[site(f"joint_{L}") for L in LEGS], :2].copy(),
            alpha=2.0 * np.arctan2(quats[:, 3], quats[:, 0]),
            l0=float(model.body_pos[body("piston_A"), 0]),
            l2=float(model.site_pos[site("tip_A"), 0]),
        )


@dataclass(frozen=True)
class LegState:
    """Joint values of the three legs (each ``(3,)``, legs A, B, C), conventions.md's names."""

    phi10: np.ndarray  # cylinder angle from its central direction alpha, rad, in (-pi, pi]
    lambda21: np.ndarray  # piston displacement |L1 L3| - l0 - l2, m
    omega10: np.ndarray
    v21: np.ndarray
    eps10: np.ndarray
    gamma21: np.ndarray
    axis: np.ndarray  # (3, 2) unit leg axes e, world frame


def leg_state(
    geometry: Geometry,
    q: Sequence[float],
    qd: Sequence[float],
    qdd: Sequence[float] = (0.0, 0.0, 0.0),
) -> LegState:
    """Inverse kinematics of the legs for one platform pose, velocity and acceleration.

    With ``L3 - L1 = s e`` (``s`` the leg length, ``n`` = ``e`` turned by +90°), the platform
    joint's velocity is ``s' e + s omega n`` and its acceleration
    ``(s'' - s omega²) e + (s eps + 2 s' omega) n``.

    Args:
        geometry: The robot.
        q: Platform pose ``(x, y, phi)`` (m, m, rad).
        qd: Its rate ``(dx, dy, dphi)``.
        qdd: Its second derivative ``(ddx, ddy, ddphi)``.
    """
    x, y, phi = (float(v) for v in q)
    dx, dy, dphi = (float(v) for v in qd)
    ddx, ddy, ddphi = (float(v) for v in qdd)
    c, s = math.cos(phi), math.sin(phi)
    arm = geometry.platform @ np.array([[c, s], [-s, c]])  # R(phi) p, one row per leg
    turned = np.stack([-arm[:, 1], arm[:, 0]], axis=1)  # z0 x arm
    leg = np.array([x, y]) + arm - geometry.base
    length = np.hypot(leg[:, 0], leg[:, 1])
    e = leg / length[:, None]
    n = np.stack([-e[:, 1], e[:, 0]], axis=1)
    e0 = np.stack([np.cos(geometry.alpha), np.sin(geometry.alpha)], axis=1)
    v3 = np.array([dx, dy]) + dphi * turned
    a3 = np.array([ddx, ddy]) + ddphi * turned - dphi**2 * arm
    v21 = np.sum(v3 * e, axis=1)
    omega10 = np.sum(v3 * n, axis=1) / length
    return LegState(
        phi10=np.arctan2(e0[:, 0] * e[:, 1] - e0[:, 1] * e[:, 0], np.sum(e0 * e, axis=1)),
        lambda21=length - geometry.l0 - geometry.l2,
        omega10=omega10,
        v21=v21,
        eps10=(np.sum(a3 * n, axis=1) - 2.0 * v21 * omega10) / length,
        gamma21=np.sum(a3 * e, axis=1) + length * omega10**2,
        axis=e,
    )


def central_qpos(params: Mapping[str, float]) -> np.ndarray:
    """``qpos`` of the central configuration (G = 0, phi = 0), in the MJCF's joint order."""
    legs = leg_state(Geometry.from_params(params), (0, 0, 0), (0, 0, 0))
    return _pack(legs.phi10, legs.lambda21, (0.0, 0.0, 0.0))


def _pack(
    per_leg_1: Sequence[float], per_leg_2: Sequence[float], platform: Sequence[float]
) -> np.ndarray:
    # Joint order of build_mjcf: phi10_A, lambda21_A, phi10_B, ..., lambda21_C, x, y, phi.
    rows = [v for pair in zip(per_leg_1, per_leg_2, strict=True) for v in pair]
    return np.array([*rows, *platform], dtype=float)


# -- MuJoCo helpers ---------------------------------------------------------------------------


def compile_model(params: Mapping[str, float], actuation: str, **options: Any) -> Any:
    """``mujoco.MjModel`` of :func:`build_mjcf` (``options`` are passed on to it)."""
    import mujoco

    return mujoco.MjModel.from_xml_string(build_mjcf(params, actuation, **options))


def set_state(model: Any, data: Any, q: Sequence[float], qd: Sequence[float]) -> None:
    """Put the whole mechanism at a consistent platform pose and velocity, then ``mj_forward``.

    The legs' joints are set by the inverse kinematics (:func:`leg_state`) of the geometry read
    back from ``model``, so every loop is closed exactly and every constraint velocity is zero.
    ``data.time``, ``ctrl`` and ``xfrc_applied`` are left as they are.

    Args:
        model: ``mujoco.MjModel`` from :func:`build_mjcf`.
        data: Its ``mujoco.MjData``.
        q: Platform pose ``(x, y, phi)`` (m, m, rad).
        qd: Platform velocity ``(dx, dy, dphi)``.
    """
    import mujoco

    legs = leg_state(Geometry.from_mujoco(model), q, qd)
    data.qpos[:] = _pack(legs.phi10, legs.lambda21, q)
    data.qvel[:] = _pack(legs.omega10, legs.v21, qd)
    data.qacc_warmstart[:] = 0.0
    mujoco.mj_forward(model, data)


def apply_payload(model: Any, data: Any, params: Mapping[str, float]) -> None:
    """Write the payload wrench ``(fx, fy, mz)`` at G into ``data.xfrc_applied`` (persists)."""
    import mujoco

    platform = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "platform")
    data.xfrc_applied[platform] = (params["fx"], params["fy"], 0.0, 0.0, 0.0, params["mz"])


def platform_state(data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Platform pose ``(x, y, phi)`` and velocity: the last three ``qpos``/``qvel``."""
    return data.qpos[-3:].copy(), data.qvel[-3:].copy()


def closure_error(model: Any, data: Any) -> float:
    """max over legs of ``|A3 (piston end) - A3 (platform joint)|``, m, at the current ``qpos``."""
    import mujoco

    mujoco.mj_kinematics(model, data)
    xyz = data.site_xpos[np.array(_site_ids(model))]  # (3 legs, tip/joint, xyz)
    return float(np.max(np.linalg.norm(xyz[:, 0] - xyz[:, 1], axis=1)))


def _site_ids(model: Any) -> list[tuple[int, int]]:
    import mujoco

    def site(name: str) -> int:
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)

    return [(site(f"tip_{L}"), site(f"joint_{L}")) for L in LEGS]


def rigid_inverse_dynamics(
    model: Any,
    data: Any,
    q: Sequence[float],
    qd: Sequence[float],
    qdd: Sequence[float],
) -> tuple[np.ndarray, np.ndarray]:
    """Actuator efforts and loop-closure forces from MuJoCo's tree dynamics, with rigid loops.

    MuJoCo's own constraint model is soft, so ``mj_inverse`` cannot resolve the loop forces
    of a closed chain; instead this takes MuJoCo's open-tree inverse dynamics ``M qacc + c``
    (``mj_rne``, gravity included) at the consistent state of :func:`set_state` with the leg
    accelerations of :func:`leg_state`, and solves the 9 x 9 system

        M qacc + c - qfrc(payload) = S tau + J^T lambda,

    with ``S`` the actuated joints' columns and ``J`` the in-plane Jacobian of
    ``tip_L - joint_L`` (``mj_jacSite``). ``lambda_L`` is the force of the platform on piston
    L at A3, so the piston exerts ``-lambda_L`` on the platform.

    Args:
        model: ``mujoco.MjModel`` from :func:`build_mjcf`; ``data.xfrc_applied`` holds the
            payload, if any (:func:`apply_payload`).
        data: Its ``mujoco.MjData`` (its state is overwritten).
        q, qd, qdd: Platform pose, velocity and acceleration.

    Returns:
        ``tau`` ``(3,)``: ``m10_L`` (revolute) or ``f21z_L`` (prismatic) for legs A, B, C; and
        ``force`` ``(3, 2)``: the force of piston L on the platform at A3, world x0, y0.
    """
    import mujoco

    legs = leg_state(Geometry.from_mujoco(model), q, qd, qdd)
    set_state(model, data, q, qd)
    data.qacc[:] = _pack(legs.eps10, legs.gamma21, qdd)
    tree = np.zeros(model.nv)
    mujoco.mj_rne(model, data, 1, tree)
    payload = np.zeros(model.nv)
    platform = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "platform")
    wrench = data.xfrc_applied[platform]
    mujoco.mj_applyFT(
        model,
        data,
        wrench[:3].copy(),
        wrench[3:].copy(),
        data.xipos[platform].copy(),
        platform,
        payload,
    )

    columns = np.zeros((model.nv, 9))
    for k in range(model.nu):
        columns[model.jnt_dofadr[model.actuator_trnid[k, 0]], k] = model.actuator_gear[k, 0]
    jacp = np.zeros((3, model.nv))
    jacp_other = np.zeros((3, model.nv))
    for k, (tip, joint) in enumerate(_site_ids(model)):
        mujoco.mj_jacSite(model, data, jacp, None, tip)
        mujoco.mj_jacSite(model, data, jacp_other, None, joint)
        columns[:, 3 + 2 * k : 5 + 2 * k] = (jacp - jacp_other)[:2].T
    solution = np.linalg.solve(columns, tree - payload)
    return solution[:3], -solution[3:].reshape(3, 2)
