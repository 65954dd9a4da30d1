"""MuJoCo as the peer of the spatial robots: the model ``rpr3gen export --format mjcf`` writes,
driven by the efforts of the generated inverse dynamics, accelerates its platform as the
generated forward dynamics says.

The state is made consistent in MuJoCo's own terms (``mujoco_spatial.state``, which the
benchmark's ``mj_forward`` shares). MuJoCo's loops are soft (``solimp`` 0.9999): the
acceleration it finds leaves about 1e-4 of the unconstrained one, hence the tolerance.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from mujoco_spatial import state

import rpr3gen
from rpr3gen import control
from rpr3gen.cli import main
from rpr3gen.export import mjcf

ROOT = Path(__file__).resolve().parent.parent


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
        state(model, mm, d, q, qd)
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
