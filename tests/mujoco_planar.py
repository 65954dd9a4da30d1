"""A planar 3-leg robot of the general format built in MuJoCo: a peer of the planar reference.

Written from the specification (``shared/spec/interfaces.md``, "Any planar 3-leg robot"); it
imports nothing from rpr3gen, and the reference (:mod:`planar_reference`) only for the parsed
model and the inverse kinematics that puts the mechanism in a consistent state. MuJoCo is
imported only by the functions that need it, so :func:`build_mjcf` works without it.

The MJCF (world frame x0 horizontal, y0 up; gravity ``(gx, gy, 0)``). Every body frame is the
world frame at home, so the model's home points are the bodies' local coordinates and every
``qpos`` is the spec's joint coordinate (zero at home):

- per leg L, ``body1_L`` (child of the world) and ``body2_L`` (child of ``body1_L``), each with the
  joint ``q1_L`` / ``q2_L``: a hinge about z at the joint's home point (R) or a slide along the
  joint's home axis (P; in the earlier body's frame, so it turns with it). COM, mass and inertia
  about the COM (axis z) of the model. The site ``tip_L`` of ``body2_L`` is joint 3's home point.
- the platform, a child of the world with the joints ``x``, ``y`` (slides along x0, y0) and
  ``phi`` (hinge about z0 through the origin of its frame, G): its ``qpos`` is the pose. The site
  ``joint_L`` is joint 3's home point on the platform.
- joint 3 of every leg is a ``connect`` equality between ``tip_L`` and ``joint_L``: a revolute
  joint. So only leg types whose joint 3 is R are built: RRR, RPR, PRR, PPR.
- one motor per leg on the actuated joint, ``gear = 1``: ``ctrl`` is ``tau_L`` (torque about +z0
  on the later body, or force along the current axis). Joint 3 has no MuJoCo joint, so its motor
  drives the fixed tendon ``q3_L = phi - (R coordinates of joints 1, 2)`` (joint 3's coordinate):
  the torque acts on the platform and its reaction on body 2.
- the payload wrench (force at G, moment) enters as the generalized force ``(fx, fy, mz)`` on the
  platform's joints ``x, y, phi`` (``qfrc_applied``): its virtual power is exactly
  ``F . v_G + mz dphi/dt``.

Out-of-plane inertia never enters (no out-of-plane joint): ``(J/2, J/2, J)``. Contacts are
disabled; visual geoms have no mass (``inertiafromgeom="false"``).

Simulation settings (those of ``tests/mujoco_peer.py``): RK4, ``dt = 1 ms``, closures with
``solref = (2 dt, 1)`` and ``solimp`` ``d = 0.9999``, Newton solver, tolerance 1e-12.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

try:
    from . import planar_reference as pr
except ImportError:
    import planar_reference as pr

LEGS = pr.LEGS
SUPPORTED_LEGS: tuple[str, ...] = ("RRR", "RPR", "PRR", "PPR")
"""Leg types whose joint 3 is revolute (closed by a ``connect``)."""

TIMESTEP = 1e-3
SOLREF: tuple[float, float] = (2 * TIMESTEP, 1.0)
SOLIMP: tuple[float, float, float, float, float] = (0.9999, 0.9999, 0.001, 0.5, 2.0)


def _num(value: float) -> str:
    return repr(float(value))


def _vec(values: Sequence[float]) -> str:
    return " ".join(_num(v) for v in values)


def check_supported(robot: pr.Robot) -> None:
    """Raise ValueError unless the robot can be built (joint 3 revolute)."""
    if robot.leg not in SUPPORTED_LEGS:
        raise ValueError(f"leg {robot.leg}: joint 3 must be revolute (one of {SUPPORTED_LEGS})")


def _joint_xml(name: str, kind: str, point: np.ndarray, axis: np.ndarray) -> str:
    if kind == "R":
        return f'<joint name="{name}" type="hinge" axis="0 0 1" pos="{_vec((*point, 0.0))}"/>'
    return (
        f'<joint name="{name}" type="slide" axis="{_vec((*axis, 0.0))}" '
        f'pos="{_vec((*point, 0.0))}"/>'
    )


def _inertial_xml(com: np.ndarray, mass: float, inertia: float) -> str:
    return (
        f'<inertial pos="{_vec((*com, 0.0))}" mass="{_num(mass)}" '
        f'diaginertia="{_vec((inertia / 2, inertia / 2, inertia))}"/>'
    )


def build_mjcf(
    robot: pr.RobotLike,
    *,
    timestep: float = TIMESTEP,
    integrator: str = "RK4",
    solref: Sequence[float] = SOLREF,
    solimp: Sequence[float] = SOLIMP,
) -> str:
    """MJCF text of the robot (layout in the module docstring).

    Args:
        robot: a parsed model (:func:`planar_reference.parse_model`) of a supported structure.
        timestep: ``option/timestep``, s.
        integrator: ``option/integrator``.
        solref: ``(timeconst, dampratio)`` of the three ``connect`` constraints.
        solimp: ``(dmin, dmax, width, midpoint, power)`` of the three ``connect`` constraints.

    Returns:
        The MJCF XML; ``qpos0`` (all zeros) is home, every loop closed.
    """
    robot = pr.as_robot(robot)
    check_supported(robot)
    legs = []
    for name, leg in zip(LEGS, robot.legs, strict=True):
        j1 = _joint_xml(f"q1_{name}", robot.leg[0], leg.joints[0], leg.axes[0])
        j2 = _joint_xml(f"q2_{name}", robot.leg[1], leg.joints[1], leg.axes[1])
        legs.append(
            f"""
    <body name="body1_{name}">
      {j1}
      {_inertial_xml(leg.com[0], leg.mass[0], leg.inertia[0])}
      <geom type="capsule" fromto="{_vec((*leg.joints[0], 0))} {_vec((*leg.joints[1], 0))}"
            size="0.01"/>
      <body name="body2_{name}">
        {j2}
        {_inertial_xml(leg.com[1], leg.mass[1], leg.inertia[1])}
        <geom type="capsule" fromto="{_vec((*leg.joints[1], 0))} {_vec((*leg.joints[2], 0))}"
              size="0.005"/>
        <site name="tip_{name}" pos="{_vec((*leg.joints[2], 0.0))}"/>
      </body>
    </body>"""
        )
    sites = "".join(
        f'\n      <site name="joint_{name}" pos="{_vec((*leg.joints[2], 0.0))}"/>'
        for name, leg in zip(LEGS, robot.legs, strict=True)
    )
    connects = "".join(f'\n    <connect site1="tip_{L}" site2="joint_{L}"/>' for L in LEGS)
    a = robot.actuated
    tendons = ""
    if a == 3:
        motors = "".join(f'\n    <motor name="tau_{L}" tendon="q3_{L}" gear="1"/>' for L in LEGS)
        for L in LEGS:
            coefs = '<joint joint="phi" coef="1"/>' + "".join(
                f'<joint joint="q{j}_{L}" coef="-1"/>' for j in (1, 2) if robot.leg[j - 1] == "R"
            )
            tendons += f'\n    <fixed name="q3_{L}">{coefs}</fixed>'
        tendons = f"\n  <tendon>{tendons}\n  </tendon>"
    else:
        motors = "".join(f'\n    <motor name="tau_{L}" joint="q{a}_{L}" gear="1"/>' for L in LEGS)
    gx, gy = robot.gravity
    return f"""<mujoco model="{robot.name or "planar"}">
  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>
  <option timestep="{_num(timestep)}" integrator="{integrator}" gravity="{_num(gx)} {_num(gy)} 0"
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
      {_inertial_xml(robot.platform_com, robot.platform_mass, robot.platform_inertia)}{sites}
    </body>
  </worldbody>
  <equality>{connects}
  </equality>{tendons}
  <actuator>{motors}
  </actuator>
</mujoco>
"""


def compile_model(robot: pr.RobotLike, **options: Any) -> tuple[Any, Any]:
    """``(mujoco.MjModel, mujoco.MjData)`` of :func:`build_mjcf`, the payload in
    ``qfrc_applied`` (``options`` go to :func:`build_mjcf`)."""
    robot = pr.as_robot(robot)
    import mujoco

    model = mujoco.MjModel.from_xml_string(build_mjcf(robot, **options))
    data = mujoco.MjData(model)
    apply_payload(robot, model, data)
    return model, data


def _platform_dofs(model: Any) -> np.ndarray:
    import mujoco

    return np.array(
        [
            model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)]
            for n in ("x", "y", "phi")
        ]
    )


def apply_payload(robot: pr.Robot, model: Any, data: Any) -> None:
    """Write the payload ``(fx, fy, mz)`` into ``data.qfrc_applied`` on the platform's dofs."""
    data.qfrc_applied[:] = 0.0
    data.qfrc_applied[_platform_dofs(model)] = (*robot.payload_force, robot.payload_moment)


def _pack(robot: pr.Robot, per_leg: Sequence[np.ndarray], platform: Sequence[float]) -> np.ndarray:
    # Joint order of build_mjcf: q1_A, q2_A, q1_B, q2_B, q1_C, q2_C, x, y, phi.
    return np.array([v for leg in per_leg for v in leg[:2]] + list(platform), dtype=float)


def set_state(
    robot: pr.Robot, model: Any, data: Any, q: Sequence[float], qd: Sequence[float]
) -> None:
    """Put the mechanism at a platform pose and velocity (legs by the reference's working-mode
    inverse kinematics, so every loop is closed), then ``mj_forward``.

    Args:
        robot: the robot the model was built from.
        model, data: from :func:`compile_model`.
        q: platform pose ``(x, y, phi)``.
        qd: its rate.
    """
    import mujoco

    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    motion = pr.leg_motion(robot, q[None], qd[None])
    if not all(np.all(np.isfinite(x)) for x in motion.q):
        raise ValueError(f"pose {q} is not reachable in the working mode")
    data.qpos[:] = _pack(robot, [x[0] for x in motion.q], q)
    data.qvel[:] = _pack(robot, [x[0] for x in motion.qd], qd)
    data.qacc_warmstart[:] = 0.0
    mujoco.mj_forward(model, data)


def platform_state(model: Any, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Platform pose ``(x, y, phi)`` and rate from ``qpos``/``qvel``."""
    dofs = _platform_dofs(model)
    return data.qpos[dofs].copy(), data.qvel[dofs].copy()


def _site_pairs(model: Any) -> list[tuple[int, int]]:
    import mujoco

    def site(name: str) -> int:
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)

    return [(site(f"tip_{L}"), site(f"joint_{L}")) for L in LEGS]


def closure_error(model: Any, data: Any) -> float:
    """max over legs of the distance between ``tip_L`` and ``joint_L``, m (current ``qpos``)."""
    import mujoco

    mujoco.mj_kinematics(model, data)
    xyz = data.site_xpos[np.array(_site_pairs(model))]
    return float(np.max(np.linalg.norm(xyz[:, 0] - xyz[:, 1], axis=1)))


def rigid_inverse_dynamics(
    robot: pr.Robot,
    model: Any,
    data: Any,
    q: Sequence[float],
    qd: Sequence[float],
    qdd: Sequence[float],
) -> tuple[np.ndarray, np.ndarray]:
    """Actuator efforts and joint-3 forces from MuJoCo's tree dynamics with rigid loops.

    MuJoCo's open-tree inverse dynamics ``M qacc + c`` (``mj_rne``, gravity included) at the
    consistent state, with the legs' joint accelerations of the reference's inverse kinematics,
    then the 9 x 9 system ``M qacc + c - qfrc_payload = S tau + Jc^T lambda`` (``S``: the motors'
    columns; ``Jc``: the in-plane Jacobian of ``tip_L - joint_L``). ``lambda_L`` is the force of
    the platform on body 2 at joint 3, so body 2 exerts ``-lambda_L`` on the platform.

    Returns:
        ``tau`` (3,) and the force of body 2 on the platform at joint 3, (3, 2) world.
    """
    import mujoco

    q, qd, qdd = (np.asarray(a, dtype=float) for a in (q, qd, qdd))
    set_state(robot, model, data, q, qd)
    motion = pr.leg_motion(robot, q[None], qd[None], qdd[None])
    data.qacc[:] = _pack(robot, [x[0] for x in motion.qdd], qdd)
    tree = np.zeros(model.nv)
    mujoco.mj_rne(model, data, 1, tree)
    columns = np.zeros((model.nv, 9))
    ctrl = data.ctrl.copy()
    for k in range(model.nu):  # generalized force of a unit effort of motor k
        data.ctrl[:] = 0.0
        data.ctrl[k] = 1.0
        mujoco.mj_fwdActuation(model, data)
        columns[:, k] = data.qfrc_actuator
    data.ctrl[:] = ctrl
    jac_tip = np.zeros((3, model.nv))
    jac_joint = np.zeros((3, model.nv))
    for k, (tip, joint) in enumerate(_site_pairs(model)):
        mujoco.mj_jacSite(model, data, jac_tip, None, tip)
        mujoco.mj_jacSite(model, data, jac_joint, None, joint)
        columns[:, 3 + 2 * k : 5 + 2 * k] = (jac_tip - jac_joint)[:2].T
    solution = np.linalg.solve(columns, tree - data.qfrc_applied)
    return solution[:3], -solution[3:].reshape(3, 2)
