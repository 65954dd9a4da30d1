"""The constant-orientation workspace of spatial robots (``rpr3gen workspace`` with a spatial
model): its points against the independent reference, its volume, its files."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.design.spatial_workspace import spatial_workspace

try:
    from . import spatial_reference as sr
except ImportError:
    import spatial_reference as sr


def conditioning(data: dict, q: np.ndarray) -> np.ndarray:
    """docs/spatial-robots.md's conditioning, from the reference's geometry: ``|det A|`` over
    its columns' lengths, the columns ``(w, (r x w) / rho)`` of the legs' (rods') free force
    directions ``w`` at their platform points ``r`` (from the platform's origin), ``rho`` those
    points' RMS distance at home; NaN where a leg cannot reach."""
    robot = sr.as_robot(data)
    out = np.full(len(q), np.nan)
    zero = np.zeros(robot.dof)
    home = []
    for lg in robot.legs:
        offsets = (
            [lg.platform]
            if robot.dof == 6
            else [lg.platform + s * lg.width / 2 * lg.bar for s in (1.0, -1.0)]
        )
        home += offsets
    rho = np.sqrt(np.mean([float(p @ p) for p in home]))
    for i, qi in enumerate(q):
        plat = sr._platform_state(robot, qi, zero, zero)
        columns = []
        for lg in robot.legs:
            S = plat.point(lg.platform)[0]
            if robot.leg == "UPS":
                start = lg.base
            else:
                start = sr._joint1(lg, robot.leg[0], S, lg.home_sign)[1]
            w = (S - start) / np.linalg.norm(S - start)
            points = [S] if robot.dof == 6 else [S + s * lg.width / 2 * lg.bar for s in (1.0, -1.0)]
            for point in points:
                r = point - qi[:3]
                columns.append(np.concatenate([w, np.cross(r, w) / rho]))
        A = np.array(columns).T
        if np.isfinite(A).all():
            out[i] = abs(np.linalg.det(A)) / np.prod(np.linalg.norm(A, axis=0))
    return out


ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize(("name", "floor"), [("delta", 0.05), ("tsai-ups", 0.25)])
def test_reachable_points_are_the_references(name: str, floor: float) -> None:
    """A point is reachable where the reference's legs reach it and its conditioning (the
    reference's own, the same definition) is at least the floor; the static efforts are the
    reference's at rest."""
    path = ROOT / "models" / f"{name}.toml"
    model = rpr3gen.load_model(path)
    data = tomllib.loads(path.read_text())
    ws = spatial_workspace(model, resolution=9, heights=3, min_conditioning=floor)
    Z, Y, X = np.meshgrid(ws.z, ws.y, ws.x, indexing="ij")
    q = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    if model.structure.dof == 6:
        q = np.column_stack([q, np.zeros((len(q), 3))])
    theirs = conditioning(data, q)
    mine = ws.conditioning.ravel()
    assert np.array_equal(np.isnan(mine), np.isnan(theirs))
    both = ~np.isnan(theirs)
    assert np.allclose(mine[both], theirs[both], rtol=1e-9, atol=1e-12)
    with np.errstate(invalid="ignore"):
        assert np.array_equal(ws.reachable.ravel(), theirs >= floor)
    ours = ws.reachable.ravel()
    assert ours.any()
    assert not ours.all()
    rest = np.zeros((int(ours.sum()), model.structure.dof))
    ref = sr.solve(data, q[ours], rest, rest)
    for k, leg in enumerate(model.structure.legs):
        tau = ws.tau[..., k].ravel()[ours]
        assert np.allclose(tau, ref[f"tau_{leg}"], rtol=1e-9, atol=1e-9)


def test_volume_converges_and_files_are_written(tmp_path: Path) -> None:
    model = rpr3gen.load_model(ROOT / "models" / "delta.toml")
    coarse = spatial_workspace(model, resolution=21, heights=11).volume
    fine = spatial_workspace(model, resolution=41, heights=21).volume
    assert fine == pytest.approx(coarse, rel=0.15)
    assert main(["workspace", "--model", str(ROOT / "models" / "delta.toml"), "--resolution",
                 "11", "--heights", "3", "--out", str(tmp_path / "ws")]) == 0  # fmt: skip
    table = pq.read_table(tmp_path / "ws" / "workspace.parquet")
    assert table.column_names[:5] == ["x", "y", "z", "reachable", "conditioning"]
    assert table.num_rows == 11 * 11 * 3
    assert (tmp_path / "ws" / "slices.png").is_file()


def test_a_delta_takes_no_orientation(capsys: pytest.CaptureFixture, tmp_path: Path) -> None:
    args = ["workspace", "--model", str(ROOT / "models" / "delta.toml"), "--orientation",
            "1,0,0", "--out", str(tmp_path / "ws")]  # fmt: skip
    assert main(args) != 0
    assert "home orientation" in capsys.readouterr().err
