"""MuJoCo as the peer of the spatial robots: the model ``rpr3gen export --format mjcf`` writes,
driven by the efforts of the generated inverse dynamics, accelerates its platform as the
generated forward dynamics says.

The state is made consistent in MuJoCo's own terms: the legs' joint coordinates are the
generated inverse dynamics' (a Delta rod's ball the least turn taking its home direction to its
current one), and the legs' joint rates the least-squares solution of MuJoCo's loop constraints
for the platform's rates. MuJoCo's loops are soft (``solimp`` 0.9999): the acceleration it finds
leaves about 1e-4 of the unconstrained one, hence the tolerance.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

import rpr3gen
from rpr3gen import control
from rpr3gen.cli import main
from rpr3gen.export import mjcf

ROOT = Path(__file__).resolve().parent.parent


def _quat_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The least rotation taking the unit ``u`` to the unit ``v``, as MuJoCo's (w, x, y, z)."""
    axis = np.cross(u, v)
    w = 1.0 + float(u @ v)
    q = np.array([w, *axis])
    return q / np.linalg.norm(q)


def _state(model: rpr3gen.Model, mm, d, q: np.ndarray, qd: np.ndarray) -> None:
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
            quat = _quat_between(home, now / np.linalg.norm(now))  # in the world
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


@pytest.mark.parametrize("name", ["tsai-ups", "delta", "rus-hexapod", "linear-delta"])
def test_mujoco_accelerates_the_platform_as_the_generated_forward_dynamics(name: str) -> None:
    model = rpr3gen.load_model(ROOT / "models" / f"{name}.toml")
    traj = rpr3gen.read_trajectory_csv(ROOT / "models" / f"{name}.csv", pose=model.structure.pose)
    mm = mujoco.MjModel.from_xml_string(mjcf(model))
    d = mujoco.MjData(mm)
    s = model.structure
    order = [0, 1, 2, 5, 4, 3] if s.dof == 6 else [0, 1, 2]
    p = model.params
    force = np.array([p["fx"], p["fy"], p["fz"]])
    moment = np.array([p["mx"], p["my"], p["mz"]])
    platform = mm.body("platform").id
    for k in (30, 70, 120, 160):
        q, qd, qdd = traj.q[k], traj.qd[k], traj.qdd[k]
        tau = control.actuator_efforts(model, q, qd, qdd)[0]
        expected = control.forward_dynamics(model, q, qd, tau)[0]
        _state(model, mm, d, q, qd)
        d.ctrl[:] = tau
        com = np.array(d.xipos[platform])
        origin = np.array(d.xpos[platform])
        d.xfrc_applied[platform, :3] = force
        d.xfrc_applied[platform, 3:] = moment + np.cross(origin - com, force)
        mujoco.mj_forward(mm, d)
        found = np.array(d.qacc[: s.dof])[np.argsort(order)]
        scale = max(float(np.abs(expected).max()), 1.0)
        assert np.allclose(found, expected, rtol=0, atol=2e-3 * scale), (k, found, expected)
        assert np.allclose(expected, qdd, rtol=1e-8, atol=1e-8 * scale)


def test_export_writes_a_model_mujoco_loads(tmp_path: Path) -> None:
    out = tmp_path / "delta.xml"
    assert main(["export", "--model", str(ROOT / "models" / "delta.toml"), "--format", "mjcf",
                 "--out", str(out)]) == 0  # fmt: skip
    mm = mujoco.MjModel.from_xml_path(str(out))
    assert mm.nu == 3
    assert mm.neq == 6
    d = mujoco.MjData(mm)
    for _ in range(10):
        mujoco.mj_step(mm, d)
    assert np.isfinite(d.qpos).all()


def test_export_refuses_a_planar_model(capsys: pytest.CaptureFixture, tmp_path: Path) -> None:
    assert main(["export", "--format", "mjcf", "--out", str(tmp_path / "x.xml")]) != 0
    assert "spatial" in capsys.readouterr().err
    assert not (tmp_path / "x.xml").exists()
