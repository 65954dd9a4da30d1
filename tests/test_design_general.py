"""Design studies of a general model (any leg type): maps and sweeps against a reference.

The maps of :func:`rpr3gen.workspace` for the gallery's 3-RRR (``models/rrr.toml``), a random
3-RRR with joint limits and a 3-PRR without limits (the prismatic default of the design
studies), checked against ``planar_reference`` (inverse kinematics, serial determinants and the
Newton-Euler statics, written apart from the derivation) and against a brute-force rule written
here from docs/design-studies.md: reachable where every leg reaches the pose in its
working mode with ``reach = min D_i / D_i(home)`` at least 1e-9, the closure's conditioning at
least the threshold and every bounded joint coordinate within its limits. The conditioning is
rebuilt here from its definition (docs/conventions.md): the Hadamard ratio of the rows that
annihilate each leg's passive joint columns, in platform twist coordinates, rotation scaled by
the platform's RMS joint radius.

Then sweeps over a general model's keys against a plain loop over the public API, and the
grid's errors. Every model but the 3-PRR (one on-demand variant) uses the committed ``rrr_1``.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import planar_models as pm
import planar_reference as pr
import pyarrow.parquet as pq
import pytest

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.design.grid import read_grid
from rpr3gen.design.metrics import GENERAL_RESULT_COLUMNS, workspace_areas
from rpr3gen.design.reach import design_limits
from rpr3gen.errors import GridError
from rpr3gen.model import model_from_dict

ROOT = Path(__file__).resolve().parent.parent
RRR = tomllib.loads((ROOT / "models" / "rrr.toml").read_text(encoding="utf-8"))
THRESHOLD = 1e-3
MIN_REACH = 1e-9  # the generated floor of reach
STEP = 1e-7  # m: a pose whose class changes within this distance is on a boundary


def _random_rrr() -> dict[str, Any]:
    data = pm.random_model(np.random.default_rng(1), "RRR", 1)
    data["limits"] = {"q2": [-0.5, 0.6], "B.q1": [-0.25, 0.3]}
    return data


def _prr() -> dict[str, Any]:
    """A symmetric 3-PRR, base slides actuated, without [limits], gravity tilted."""
    return {
        "name": "3-PRR",
        "leg": "PRR",
        "actuated": 1,
        "symmetric": True,
        "legs": {
            "A": {
                "joints": [[0.3, -0.45], [0.3, -0.45], [0.0, -0.15]],
                "axes": [[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]],
                "mass": [1.5, 0.8],
                "com": [[0.3, -0.45], [0.15, -0.3]],
                "inertia": [0.002, 0.012],
            }
        },
        "platform": {"mass": 2.0, "com": [0.01, 0.0], "inertia": 0.0225},
        "environment": {"gravity": [1.0, -9.76]},
        "payload": {"moment": 0.4},
    }


MODELS = {"rrr": lambda: RRR, "rrr-limits": _random_rrr, "prr": _prr}
PHI = {"rrr": 0.3, "rrr-limits": -0.1, "prr": 0.15}


def _robot(data: dict[str, Any]) -> pr.Robot:
    data = dict(data)
    if data.pop("symmetric", False):
        data["legs"] = pr.expand_symmetric(data["legs"]["A"])
    return pr.parse_model(data)


def _limits(data: dict[str, Any], robot: pr.Robot) -> list[tuple[int, int, float, float]]:
    """``(leg index, joint, lo, hi)``: the file's limits, and every other prismatic coordinate
    within plus or minus its leg's length at home |P2 - P1| + |P3 - P2|
    (docs/design-studies.md)."""
    given = data.get("limits", {})
    out = []
    for i, name in enumerate(pr.LEGS):
        for j in (1, 2, 3):
            bound = given.get(f"{name}.q{j}", given.get(f"q{j}"))
            if bound is None and robot.leg[j - 1] == "P":
                P = robot.legs[i].joints
                length = np.linalg.norm(P[1] - P[0]) + np.linalg.norm(P[2] - P[1])
                bound = (-length, length)
            if bound is not None:
                out.append((i, j, float(bound[0]), float(bound[1])))
    return out


def _conditioning(robot: pr.Robot, q: np.ndarray, qlegs: list[np.ndarray]) -> np.ndarray:
    """The closure's Hadamard ratio (NaN where a leg does not reach)."""
    rows = []
    for i in range(3):
        ok = np.all(np.isfinite(qlegs[i]), axis=1)
        S = pr.serial_jacobian(robot, i, np.where(ok[:, None], qlegs[i], 0.0))
        c1, c2 = (S[:, :, j] for j in range(3) if j != robot.actuated - 1)
        n = np.cross(c1, c2)  # annihilates the leg's passive motions of joint 3's point
        r = pr._rotate(q[:, 2], robot.legs[i].joints[2])  # G to joint 3's point
        moment = (n[:, 1] * r[:, 0] - n[:, 0] * r[:, 1] + n[:, 2]) / robot.platform_radius
        row = np.stack([n[:, 0], n[:, 1], moment], axis=1)
        row[~ok] = np.nan
        rows.append(row)
    W = np.stack(rows, axis=1)
    with np.errstate(invalid="ignore"):
        return np.abs(np.linalg.det(W)) / np.prod(np.linalg.norm(W, axis=2), axis=1)


def _reference(data: dict[str, Any], q: np.ndarray, threshold: float) -> dict[str, np.ndarray]:
    robot = _robot(data)
    qlegs = pr.inverse_kinematics(robot, q)
    home = pr.serial_determinant(robot, np.zeros((1, 3)))
    with np.errstate(invalid="ignore"):
        reach = (pr.serial_determinant_at(robot, qlegs) / home).min(axis=1)
        conditioning = _conditioning(robot, q, qlegs)
        ok = (reach >= MIN_REACH) & (conditioning >= threshold)
        for i, j, lo, hi in _limits(data, robot):
            ok &= (qlegs[i][:, j - 1] >= lo) & (qlegs[i][:, j - 1] <= hi)
    return {"reachable": ok, "conditioning": conditioning, "qlegs": np.stack(qlegs, axis=1)}


def _reachable(data: dict[str, Any], q: np.ndarray, threshold: float = THRESHOLD) -> np.ndarray:
    return _reference(data, q, threshold)["reachable"]


def _on_boundary(data: dict[str, Any], q: np.ndarray) -> np.ndarray:
    """Poses whose reachability changes within :data:`STEP` of them."""
    found = [_reachable(data, q + np.array([dx, dy, 0.0])) for dx, dy in
             ((0, 0), (STEP, 0), (-STEP, 0), (0, STEP), (0, -STEP))]  # fmt: skip
    return ~np.all(found == found[0], axis=0)


@pytest.fixture(scope="module", params=sorted(MODELS))
def case(request: pytest.FixtureRequest) -> tuple[dict[str, Any], rpr3gen.WorkspaceMap]:
    data = MODELS[request.param]()
    wmap = rpr3gen.workspace(model_from_dict(data), phi=PHI[request.param], resolution=41)
    return data, wmap


def _poses(wmap: rpr3gen.WorkspaceMap) -> np.ndarray:
    xx, yy = np.meshgrid(wmap.x, wmap.y)
    return np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, wmap.phi)])


def test_reachable_set_is_the_brute_force_one(case: Any) -> None:
    data, wmap = case
    q = _poses(wmap)
    expected = _reachable(data, q)
    got = wmap.reachable.ravel()
    differ = got != expected
    assert np.all(_on_boundary(data, q[differ]))
    assert 0.05 * got.size < np.count_nonzero(got) < got.size
    assert wmap.area == pytest.approx(np.count_nonzero(expected) * wmap.cell_area, rel=0.01)


def test_conditioning_and_joint_coordinates_are_the_references(case: Any) -> None:
    data, wmap = case
    q = _poses(wmap)
    ref = _reference(data, q, THRESHOLD)
    got = wmap.conditioning.ravel()
    defined = np.isfinite(got)
    assert np.array_equal(defined, np.isfinite(ref["conditioning"]))  # NaN: a leg cannot reach
    np.testing.assert_allclose(got[defined], ref["conditioning"][defined], rtol=0, atol=1e-9)
    limits = design_limits(model_from_dict(data))
    assert len(limits) == wmap.coordinates.shape[2] > 0 or not limits
    for k, (leg, family, _, _) in enumerate(limits):
        expected = ref["qlegs"][:, "ABC".index(leg), int(family[1]) - 1]
        value = wmap.coordinates[..., k].ravel()
        np.testing.assert_allclose(value[defined], expected[defined], rtol=0, atol=1e-9)


def test_the_grid_holds_every_reachable_position(case: Any) -> None:
    """Positions just outside the box are not reachable, whatever the conditioning."""
    data, wmap = case
    dx, dy = wmap.x[1] - wmap.x[0], wmap.y[1] - wmap.y[0]
    x = np.linspace(wmap.x[0] - dx / 2, wmap.x[-1] + dx / 2, 300)
    y = np.linspace(wmap.y[0] - dy / 2, wmap.y[-1] + dy / 2, 300)
    rim = np.concatenate(
        [
            np.column_stack([x, np.full_like(x, y[0] - 1e-9)]),
            np.column_stack([x, np.full_like(x, y[-1] + 1e-9)]),
            np.column_stack([np.full_like(y, x[0] - 1e-9), y]),
            np.column_stack([np.full_like(y, x[-1] + 1e-9), y]),
        ]
    )
    q = np.column_stack([rim, np.full(len(rim), wmap.phi)])
    assert not _reachable(data, q, threshold=0.0).any()


def test_static_efforts_are_newton_eulers_at_rest(case: Any) -> None:
    data, wmap = case
    q = _poses(wmap)
    inside = np.flatnonzero(wmap.reachable.ravel())
    pick = inside[np.linspace(0, inside.size - 1, 40).astype(int)]
    zero = np.zeros((pick.size, 3))
    expected = pr.efforts(pr.solve(_robot(data), q[pick], zero, zero))
    got = wmap.tau.reshape(-1, 3)[pick]
    np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-9 * np.abs(expected).max())
    assert np.isnan(wmap.tau.reshape(-1, 3)[~wmap.reachable.ravel()]).all()
    assert wmap.effort == "tau"


def test_orientation_intervals_against_brute_force(case: Any) -> None:
    data, wmap = case
    q = _poses(wmap)
    inside = np.flatnonzero(wmap.reachable.ravel())
    pick = inside[np.linspace(0, inside.size - 1, 15).astype(int)]
    lo, hi = wmap.phi_min.ravel()[pick], wmap.phi_max.ravel()[pick]
    assert np.all(lo <= wmap.phi)
    assert np.all(wmap.phi <= hi)
    for (x, y, _), a, b in zip(q[pick], lo, hi, strict=True):
        inner = np.linspace(a, b, 300)[1:-1]
        poses = np.column_stack([np.full(inner.size, x), np.full(inner.size, y), inner])
        assert _reachable(data, poses).all()
        for edge, outward in ((a, -1.0), (b, 1.0)):
            if abs(edge - wmap.phi) >= math.pi - 1e-12:  # half a turn: no edge
                continue
            near = np.array([[x, y, edge - outward * 1e-8], [x, y, edge + outward * 1e-8]])
            assert _reachable(data, near).tolist() == [True, False]  # just inside, outside
    assert np.isnan(wmap.phi_min.ravel()[~wmap.reachable.ravel()]).all()


def test_sweep_area_is_the_maps(case: Any) -> None:
    data, _ = case
    model = model_from_dict(data)
    (area,) = workspace_areas([model], 24, THRESHOLD)
    assert area == pytest.approx(rpr3gen.workspace(model, 0.0, 24).area, rel=1e-12)
    assert area > 0


def test_design_limits_default_and_given() -> None:
    prr = model_from_dict(_prr())
    length = math.hypot(0.3, 0.3)  # |P2 - P1| + |P3 - P2| = 0 + the link
    assert [limit[:2] for limit in design_limits(prr)] == [("A", "q1"), ("B", "q1"), ("C", "q1")]
    for _, _, lo, hi in design_limits(prr):
        assert (lo, hi) == pytest.approx((-length, length), rel=1e-15)
    given = design_limits(model_from_dict({**_prr(), "limits": {"A.q1": [-0.1, 0.2]}}))
    assert given[0] == ("A", "q1", -0.1, 0.2)
    assert given[1][2:] == pytest.approx((-length, length), rel=1e-15)
    assert design_limits(model_from_dict(RRR)) == ()  # revolute joints: bounded by the links
    limited = design_limits(model_from_dict(_random_rrr()))
    assert [(leg, f) for leg, f, _, _ in limited] == [("A", "q2"), ("B", "q1"), ("B", "q2"),
                                                      ("C", "q2")]  # fmt: skip


PRR_TOML = """
name = "3-PRR"
leg = "PRR"
actuated = 1
symmetric = true
[legs.A]
joints = [[0.3, -0.45], [0.3, -0.45], [0.0, -0.15]]
axes = [[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
mass = [1.5, 0.8]
com = [[0.3, -0.45], [0.15, -0.3]]
inertia = [0.002, 0.012]
[platform]
mass = 2.0
com = [0.01, 0.0]
inertia = 0.0225
[environment]
gravity = [1.0, -9.76]
[payload]
moment = 0.4
[limits]
"B.q1" = [-0.3, 0.2]
"""


def test_workspace_command_with_a_general_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "prr.toml"
    path.write_text(PRR_TOML, encoding="utf-8")
    assert tomllib.loads(PRR_TOML) == {**_prr(), "limits": {"B.q1": [-0.3, 0.2]}}
    out = tmp_path / "ws"
    args = ["workspace", "--model", str(path), "--phi", "10", "--resolution", "24",
            "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    table = pq.read_table(out / "workspace.parquet")
    assert table.column_names == [
        "x", "y", "phi", "reachable", "conditioning",
        "tau_A", "tau_B", "tau_C", "phi_min", "phi_max",
    ]  # fmt: skip
    model = rpr3gen.load_model(path)
    expected = rpr3gen.workspace(model, math.radians(10), 24).columns()
    for name, values in expected.items():
        np.testing.assert_array_equal(table.column(name).to_numpy(), values, err_msg=name)
    stdout = capsys.readouterr().out
    assert stdout.startswith("workspace of 3-PRR at phi = 10 deg: 24 x 24 points")
    length = f"{math.hypot(0.3, 0.3):.3g}"
    assert (f"(limits q1_A [-{length}, {length}] m, q1_B [-0.3, 0.2] m, q1_C [-{length}, "
            f"{length}] m; conditioning >= 0.001)") in stdout  # fmt: skip
    assert "peak static |tau|: " in stdout
    assert " N; widest orientation range" in stdout
    assert sorted(p.name for p in out.iterdir()) == [
        "conditioning.png", "orientation_range.png", "peak_effort.png", "reachable.png",
        "workspace.parquet",
    ]  # fmt: skip


# -- sweeps --------------------------------------------------------------------------------------

SAMPLES = 31
BASE = {**RRR, "limits": {"q2": [-2.5, 2.5]}}
GRID = {
    "platform.mass": [2.0, 3.0],
    "legs.A.mass[1]": [1.0, 1.5],
    "legs.A.joints[1][0]": [0.17854, 0.2],
    "environment.gravity[1]": [-9.81],
    "limits.q2[1]": [2.5, 0.3],
}


def _weights(t: np.ndarray) -> np.ndarray:
    dt = np.diff(t)
    return np.concatenate([[dt[0]], dt[1:] + dt[:-1], [dt[-1]]]) / 2


def _plain_loop(base: dict[str, Any], grid: dict[str, Any]) -> list[dict[str, Any]]:
    """What a sweep reports, one design at a time through ``rpr3gen.inverse_dynamics``."""
    checked = read_grid(grid, base)
    trajs = [rpr3gen.paper_trajectory(n, samples=SAMPLES) for n in ("rotation", "rectilinear")]
    rows = []
    for i in range(len(checked)):
        model = model_from_dict(checked.apply(base, checked.design(i)))
        outs = [rpr3gen.inverse_dynamics(model, tr.q, tr.qd, tr.qdd) for tr in trajs]
        w = np.concatenate([_weights(tr.t) for tr in trajs])
        row: dict[str, Any] = dict(zip(checked.keys, checked.design(i), strict=True))
        lo, hi = model.limits["A.q2"]
        row["feasible"] = all(
            (o["conditioning"] >= THRESHOLD).all()
            and all(((o[f"q2_{leg}"] >= lo) & (o[f"q2_{leg}"] <= hi)).all() for leg in "ABC")
            for o in outs
        )
        for leg in "ABC":
            tau = np.concatenate([o[f"tau_{leg}"] for o in outs])
            row[f"peak_tau_{leg}"] = np.abs(tau).max()
            row[f"rms_tau_{leg}"] = np.sqrt((w * tau**2).sum() / w.sum())
        row["min_conditioning"] = min(o["conditioning"].min() for o in outs)
        row["workspace_area"] = rpr3gen.workspace(model, 0.0, 16).area
        for j in (1, 2, 3):
            row[f"peak_f{j}"] = max(
                np.hypot(o[f"fx{j}_{leg}"], o[f"fy{j}_{leg}"]).max() for o in outs for leg in "ABC"
            )
            row[f"peak_m{j}"] = max(np.abs(o[f"m{j}_{leg}"]).max() for o in outs for leg in "ABC")
        rows.append(row)
    return rows


def test_general_sweep_rows_are_the_plain_loops() -> None:
    table = rpr3gen.sweep(BASE, GRID, workers=0, samples=SAMPLES, chunk_size=3, area_resolution=16)
    assert table.column_names == [*GRID, *GENERAL_RESULT_COLUMNS]
    expected = _plain_loop(BASE, GRID)
    rows = table.to_pylist()
    assert len(rows) == len(expected) == 16
    for row, want in zip(rows, expected, strict=True):
        for key, value in want.items():
            if isinstance(value, bool):
                assert row[key] is value, key
            else:
                assert row[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
    assert [r["feasible"] for r in rows] == [r["limits.q2[1]"] == 2.5 for r in rows]
    for row in rows:
        if row["feasible"]:
            assert row["reason"] == ""
            continue
        assert row["reason"].startswith("rectilinear: t = ")
        assert re.search(
            r"joint coordinate q2_A = \S+ rad outside its limits \[-2\.5, 0\.3\] \(limits\.A\.q2\)",
            row["reason"],
        )
    assert {r["peak_m2"] for r in rows} == {0.0}  # passive revolute joints: no moment


def test_general_grid_keys_reach_into_the_model() -> None:
    grid = read_grid(GRID, BASE)
    data = grid.apply(BASE, grid.design(len(grid) - 1))
    assert data["legs"]["A"]["joints"][1] == [0.2, -0.325]
    assert data["legs"]["A"]["mass"] == [1.0, 1.5]
    assert data["limits"] == {"q2": [-2.5, 0.3]}
    assert data["environment"]["gravity"] == [0.0, -9.81]
    assert BASE["legs"]["A"]["joints"][1] == [0.17854, -0.325]  # the base is not changed
    assert BASE["limits"] == {"q2": [-2.5, 2.5]}
    model = model_from_dict(data)
    assert model.params["x2_B"] == pytest.approx(0.2 * math.cos(2 * math.pi / 3) + 0.325 *
                                                 math.sin(2 * math.pi / 3))  # fmt: skip
    explicit = pm.random_model(np.random.default_rng(1), "RRR", 1)
    grid = read_grid({"legs.C.com[0][1]": [0.0, 0.01], "actuated": [1, 2]}, explicit)
    assert grid.values[1] == (1, 2)
    assert grid.columns(0, 4)["actuated"].dtype == np.int64
    assert grid.apply(explicit, grid.design(3))["legs"]["C"]["com"][0][1] == 0.01


@pytest.mark.parametrize(
    ("grid", "message"),
    [
        ({"legs.B.mass[0]": [1.0]}, "legs.B.mass[0]: with symmetric = true only leg A's keys"),
        ({"platform.mas": [1.0]}, "platform.mas: unknown model key; did you mean 'platform.mass'?"),
        ({"mass.m3": [1.0]}, "mass.m3: unknown model key"),
        ({"legs.A.joints[1]": [0.1]}, 'vary one element, e.g. "legs.A.joints[0][0]"'),
        ({"legs.A.joints[3][0]": [0.1]}, "legs.A.joints[3][0]: index 3 out of range (0 to 2)"),
        ({"platform.mass[0]": [1.0]}, "platform.mass holds one value, not a list"),
        ({"legs.A.mass[0]": [1.0, -1.0]}, "legs.A.mass[0]: must not be negative, got -1.0"),
        ({"legs.A.axes[0][0]": [1.0]}, "joint 1 of a 3-RRR is revolute; its axis is ignored"),
        ({"limits.q2[0]": [0.1]}, "the base model has no limits.q2 to vary"),
        ({"leg": ["RPR"]}, "leg: not a design parameter"),
        ({"actuated": [1, 4]}, "actuated[1]: must be the joint 1, 2 or 3, got 4"),
        ({"actuation": ["revolute"]}, "actuation: unknown model key; did you mean 'actuated'?"),
        ({"legs.A.joints[1][0]": [0.0]}, "leg A is in a serial singularity at home"),
    ],
)  # fmt: skip
def test_bad_general_grid_is_one_line_naming_the_key(grid: dict[str, Any], message: str) -> None:
    with pytest.raises(GridError) as caught:
        read_grid(grid, RRR)
    assert str(caught.value).startswith("<grid>: ")
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_sweep_command_with_a_general_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    grid = tmp_path / "grid.toml"
    grid.write_text('[legs.A]\n"inertia[0]" = [0.005, 0.01]\n', encoding="utf-8")
    out = tmp_path / "designs.parquet"
    args = ["sweep", "--model", str(ROOT / "models" / "rrr.toml"), "--grid", str(grid),
            "--samples", "11", "--area-resolution", "0", "--workers", "0",
            "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    assert capsys.readouterr().out == f"2 designs, 2 feasible; wrote {out}\n"
    table = pq.read_table(out)
    assert table.column_names == ["legs.A.inertia[0]", *GENERAL_RESULT_COLUMNS]
    assert np.isnan(table.column("workspace_area").to_numpy()).all()


def test_a_default_travel_is_named_as_such_in_the_reason() -> None:
    """Leg C's rail would pass its default travel (the 3-PRR has no [limits])."""
    t = np.linspace(0.0, 1.0, 21)
    s = 3 * t**2 - 2 * t**3  # rest to rest
    q = np.column_stack([0.2 * s, np.full_like(t, 0.1), np.zeros_like(t)])
    qd = np.column_stack([0.2 * (6 * t - 6 * t**2), np.zeros_like(t), np.zeros_like(t)])
    qdd = np.column_stack([0.2 * (6 - 12 * t), np.zeros_like(t), np.zeros_like(t)])
    line = rpr3gen.Trajectory(t=t, q=q, qd=qd, qdd=qdd)
    table = rpr3gen.sweep(_prr(), {"platform.mass": [2.0]}, [line], workers=0, area_resolution=0)
    (row,) = table.to_pylist()
    assert not row["feasible"]
    assert re.fullmatch(
        r"trajectory 1: t = \S+ s: joint coordinate q1_C = -0\.4\d+ m outside its limits "
        r"\[-0\.424264, 0\.424264\] \(the design studies' default travel; set \[limits\] in the "
        r"model file\)",
        row["reason"],
    ), row["reason"]


def test_stacked_designs_fall_back_to_one_call_per_design(monkeypatch: pytest.MonkeyPatch) -> None:
    """Generated code that takes one parameter vector only (a parameter-only output written by
    ``fill``, the 3-PPR's reach) raises ValueError on stacked columns: each design's run of
    columns is then evaluated alone, with the same values."""
    from rpr3gen.design.stacked import evaluate_stacked, param_rows
    from rpr3gen.evaluators import NumpyEvaluator

    grid = read_grid({"legs.A.joints[1][0]": [0.17, 0.18, 0.19]}, RRR)
    models = [model_from_dict(grid.apply(RRR, grid.design(i))) for i in range(len(grid))]
    traj = rpr3gen.paper_trajectory("rectilinear", samples=11)
    params = np.repeat(param_rows(models), 11, axis=1)
    inputs = [np.tile(a, (3, 1)) for a in (traj.q, traj.qd, traj.qdd)]
    stacked = evaluate_stacked(models[0], "inverse_dynamics", params, inputs)
    run = NumpyEvaluator.run
    calls = []

    def one_vector_only(self: Any, info: Any, p: np.ndarray, *args: Any, **kw: Any) -> Any:
        calls.append(p.shape)
        if p.ndim == 2 and np.any(p != p[:, :1]):
            raise ValueError("setting an array element with a sequence.")
        return run(self, info, p, *args, **kw)

    monkeypatch.setattr(NumpyEvaluator, "run", one_vector_only)
    alone = evaluate_stacked(models[0], "inverse_dynamics", params, inputs)
    assert calls == [params.shape, (params.shape[0],), (params.shape[0],), (params.shape[0],)]
    np.testing.assert_array_equal(alone.codes, stacked.codes)
    for name, values in stacked.values.items():
        np.testing.assert_allclose(alone[name], values, rtol=1e-13, atol=1e-12, err_msg=name)
