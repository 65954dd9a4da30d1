"""MuJoCo's state for a pose of a spatial robot that ``rpr3gen export --format mjcf`` exported:
shared by the peer's test (``test_spatial_mujoco.py``) and the benchmark's ``mj_forward``
(``benchmarks/harness/mujoco.py``).

The state is made consistent in MuJoCo's own terms: the legs' joint coordinates are the
generated inverse dynamics' (a Delta rod's ball the least turn taking its home direction to its
current one), and the legs' joint rates the least-squares solution of MuJoCo's loop constraints
for the platform's rates.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

import rpr3gen


def quat_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The least rotation taking the unit ``u`` to the unit ``v``, as MuJoCo's (w, x, y, z)."""
    axis = np.cross(u, v)
    w = 1.0 + float(u @ v)
    q = np.array([w, *axis])
    return q / np.linalg.norm(q)


def state(model: Any, mm: Any, d: Any, q: np.ndarray, qd: np.ndarray) -> None:
    """Set ``d``'s qpos and qvel to the pose ``q`` and rates ``qd``, the legs consistent."""
    s = model.structure
    out = rpr3gen.inverse_dynamics(model, q, qd, np.zeros_like(q))
    qpos = np.zeros(mm.nq)
    order = [0, 1, 2, 5, 4, 3] if s.dof == 6 else [0, 1, 2]
    qpos[: s.dof] = q[order]
    p = model.params
    for leg in s.legs:
        if s.leg == "UPS":
            names = {"q1a": f"q1a_{leg}", "q1b": f"q1b_{leg}", "q2": f"q2_{leg}"}
        elif s.leg in ("RUS", "PUS"):
            names = {"q1": f"q1_{leg}", "q2a": f"q2a_{leg}", "q2b": f"q2b_{leg}"}
        else:
            names = {"q1": f"q1_{leg}"}
        for family, joint in names.items():
            qpos[mm.jnt_qposadr[mm.joint(joint).id]] = out[f"{family}_{leg}"][0]
        if s.leg.endswith("SS2"):
            e = np.array([p[f"e{a}_{leg}"] for a in "xyz"])
            pp = np.array([p[f"p{a}_{leg}"] for a in "xyz"])
            B = np.array([p[f"b{a}_{leg}"] for a in "xyz"])
            axis = np.array([p[f"a{a}_{leg}"] for a in "xyz"])
            q1 = out[f"q1_{leg}"][0]
            if s.leg == "RSS2":
                c0 = B + (axis @ (e - B)) * axis
                r0 = e - c0
                E = c0 + np.cos(q1) * r0 + np.sin(q1) * np.cross(axis, r0)
            else:
                E = e + q1 * axis
            home = (pp - e) / np.linalg.norm(pp - e)
            now = q[:3] + pp - E
            quat = quat_between(home, now / np.linalg.norm(now))  # in the world
            if s.leg == "RSS2":  # the ball turns the rod relative to the arm, turned by q1
                arm = np.zeros(4)
                mujoco.mju_axisAngle2Quat(arm, axis, -q1)
                relative = np.zeros(4)
                mujoco.mju_mulQuat(relative, arm, quat)
                quat = relative
            for k in (1, 2):
                adr = mm.jnt_qposadr[mm.joint(f"s{k}_{leg}").id]
                qpos[adr : adr + 4] = quat
    d.qpos[:] = qpos
    d.qvel[:] = 0.0
    mujoco.mj_forward(mm, d)
    # the legs' rates: the loops' velocity constraints for the platform's rates
    J = np.array(d.efc_J).reshape(d.nefc, mm.nv)
    vel = np.zeros(mm.nv)
    vel[: s.dof] = qd[order]
    legs = slice(s.dof, mm.nv)
    rhs = -J[:, : s.dof] @ vel[: s.dof]
    vel[legs] = np.linalg.lstsq(J[:, legs], rhs, rcond=None)[0]
    d.qvel[:] = vel
    assert np.abs(np.array(d.efc_pos)).max() < 1e-9  # the loops closed at this pose
