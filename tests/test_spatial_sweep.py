"""Sweeps of spatial robots (hexapods and Deltas): each row against the independent Newton-Euler
reference (``tests/spatial_reference.py``) and ``spatial_workspace``, infeasible designs and
their reasons, the C backend against NumPy, the command writing Parquet (in this process and on
a real Dask cluster, resumed after an interruption), and every bad grid key or option as one
line naming it, nothing written.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.design import sweeps
from rpr3gen.design.grid import read_grid
from rpr3gen.design.metrics import evaluate_chunk
from rpr3gen.design.spatial_metrics import spatial_result_columns
from rpr3gen.design.spatial_workspace import spatial_workspace
from rpr3gen.design.sweeps import DEFAULT_VOLUME_RESOLUTION
from rpr3gen.errors import GridError
from rpr3gen.model import model_from_dict, read_model_data

try:
    from . import spatial_reference as sr
    from .test_spatial_workspace import conditioning as reference_conditioning
except ImportError:
    import spatial_reference as sr
    from test_spatial_workspace import conditioning as reference_conditioning

ROOT = Path(__file__).resolve().parent.parent
DELTA = ROOT / "models" / "delta.toml"
UPS = ROOT / "models" / "tsai-ups.toml"
_, DELTA_DATA = read_model_data(DELTA)
_, UPS_DATA = read_model_data(UPS)
RESOLUTION = 6  # of the volume: 216 poses a design, quick
RTOL = 1e-9  # the generated code against the reference (measured agreement about 1e-13)


def _gallery(name: str, every: int) -> rpr3gen.Trajectory:
    """Every ``every``-th sample of the gallery's trajectory of ``name``."""
    model = rpr3gen.load_model(ROOT / "models" / f"{name}.toml")
    whole = rpr3gen.read_trajectory_csv(ROOT / "models" / f"{name}.csv", pose=model.structure.pose)
    rows = slice(None, None, every)
    return rpr3gen.Trajectory(t=whole.t[rows], q=whole.q[rows], qd=whole.qd[rows],
                              qdd=whole.qdd[rows])  # fmt: skip


def _rest_to_rest(amplitude: list[float], samples: int = 21) -> rpr3gen.Trajectory:
    """``q = A (1 - cos(2 pi t)) / 2`` over one second, and its derivatives."""
    t = np.linspace(0.0, 1.0, samples)
    a = np.asarray(amplitude)
    s = (1 - np.cos(2 * np.pi * t)) / 2
    ds, dds = np.pi * np.sin(2 * np.pi * t), 2 * np.pi**2 * np.cos(2 * np.pi * t)
    return rpr3gen.Trajectory(t=t, q=np.outer(s, a), qd=np.outer(ds, a), qdd=np.outer(dds, a))


DELTA_MOTION = _gallery("delta", 20)  # 11 samples
UPS_MOTION = _gallery("tsai-ups", 40)  # 6 samples
DEEP = _rest_to_rest([0.05, 0.0, -0.4])  # 0.4 m down: the gallery Delta's legs reach it


def _weights(t: np.ndarray) -> np.ndarray:
    dt = np.diff(t)
    return np.concatenate([[dt[0]], dt[1:] + dt[:-1], [dt[-1]]]) / 2


def _expected(base: dict, grid: dict, designs: list[int], motion: rpr3gen.Trajectory) -> dict:
    """Design ``i``'s row of a sweep of ``grid`` on ``base`` over ``motion``, by the Newton-
    Euler reference (efforts, joint loads), the reference's conditioning and
    ``spatial_workspace`` (the volume): ``{i: {column: value}}``."""
    checked = read_grid(grid, base)
    rows = {}
    for i in designs:
        data = checked.apply(base, checked.design(i))
        robot = sr.parse_model(data)
        out = sr.solve(robot, motion.q, motion.qd, motion.qdd)
        w = _weights(motion.t)
        row: dict[str, Any] = dict(zip(checked.keys, checked.design(i), strict=True))
        for leg in robot.leg_names:
            tau = out[f"tau_{leg}"]
            row[f"peak_tau_{leg}"] = np.abs(tau).max()
            row[f"rms_tau_{leg}"] = np.sqrt((w * tau**2).sum() / w.sum())
        joints = 3 if robot.dof == 6 else 5
        for j in range(1, joints + 1):
            for load in ("f", "m") if j < joints and (robot.dof == 6 or j == 1) else ("f",):
                row[f"peak_{load}{j}"] = max(
                    np.sqrt(sum(out[f"{load}{axis}{j}_{leg}"] ** 2 for axis in "xyz")).max()
                    for leg in robot.leg_names
                )
        row["min_conditioning"] = np.nanmin(reference_conditioning(data, motion.q))
        model = model_from_dict(data)
        row["workspace_volume"] = spatial_workspace(model, RESOLUTION, RESOLUTION).volume
        rows[i] = row
    return rows


def _compare(row: dict, want: dict) -> None:
    for key, value in want.items():
        if key == "workspace_volume":
            assert row[key] == value, key  # the same poses, the same count
        else:
            assert row[key] == pytest.approx(value, rel=RTOL, abs=1e-12), key


# -- rows against the reference ------------------------------------------------------------------


def test_delta_rows_are_newton_euler_and_spatial_workspace() -> None:
    grid = {"platform.mass": [0.5, 1.0], "legs.A.rod_mass": [0.1, 0.2]}
    table = rpr3gen.sweep(DELTA, grid, [DELTA_MOTION], workers=0, chunk_size=3,
                          volume_resolution=RESOLUTION)  # fmt: skip
    structure = rpr3gen.load_model(DELTA).structure
    assert table.column_names == [*grid, *spatial_result_columns(structure)]
    assert table.column_names[-6:] == [*(f"peak_f{j}" for j in range(1, 6)), "peak_m1"]
    rows = table.to_pylist()
    assert [r["feasible"] for r in rows] == [True] * 4
    assert [r["reason"] for r in rows] == [""] * 4
    for i, want in _expected(DELTA_DATA, grid, [0, 1, 2, 3], DELTA_MOTION).items():
        _compare(rows[i], want)


def test_a_hexapod_whose_legs_move_turns_its_u_joints_with_them() -> None:
    grid = {"legs.A.platform[2]": [0.0, 0.1], "platform.mass": [1.5, 3.0]}
    table = rpr3gen.sweep(UPS, grid, [UPS_MOTION], workers=0, volume_resolution=RESOLUTION)
    assert table.column_names[-7:] == [
        "min_conditioning", "workspace_volume", "peak_f1", "peak_f2", "peak_f3", "peak_m1",
        "peak_m2",
    ]  # fmt: skip
    assert [f"peak_tau_{leg}" for leg in "ABCDEF"] == table.column_names[4:10]
    rows = table.to_pylist()
    assert all(r["feasible"] for r in rows)
    for i, want in _expected(UPS_DATA, grid, [0, 3], UPS_MOTION).items():
        _compare(rows[i], want)
    checked = read_grid(grid, UPS_DATA)
    moved = checked.apply(UPS_DATA, checked.design(3))["legs"]["A"]
    given = UPS_DATA["legs"]["A"]
    assert moved["u_axes"][0] == given["u_axes"][0]  # the U's first axis stays
    u2, line = np.array(moved["u_axes"][1]), np.subtract(moved["platform"], moved["base"])
    assert abs(u2 @ line) < 1e-15 * np.linalg.norm(line)  # the second turns with the leg
    assert np.linalg.norm(u2) == pytest.approx(1.0, abs=1e-15)
    assert u2 @ given["u_axes"][1] > 0.99
    unmoved = checked.apply(UPS_DATA, checked.design(0))["legs"]["A"]
    assert unmoved["u_axes"] == given["u_axes"]  # the base's values: the base's U


def test_the_default_volume_is_spatial_workspaces() -> None:
    table = rpr3gen.sweep(DELTA, {"platform.mass": [0.5]}, [DELTA_MOTION], workers=0,
                          min_conditioning=0.05)  # fmt: skip
    model = rpr3gen.load_model(DELTA)
    expected = spatial_workspace(model, DEFAULT_VOLUME_RESOLUTION, DEFAULT_VOLUME_RESOLUTION,
                                 min_conditioning=0.05)  # fmt: skip
    assert table.column("workspace_volume").to_pylist() == [expected.volume]
    assert expected.volume > 0.0


# -- infeasible and invalid designs --------------------------------------------------------------


def test_a_design_out_of_reach_says_where_and_why() -> None:
    grid = {"legs.A.elbow[2]": [0.843982, 0.7]}  # the arms lowered: the legs reach less far
    table = rpr3gen.sweep(DELTA, grid, [DEEP], workers=0, volume_resolution=0)
    rows = table.to_pylist()
    assert rows[0]["feasible"]
    assert rows[0]["reason"] == ""
    assert not rows[1]["feasible"]
    data = read_grid(grid, DELTA_DATA).apply(DELTA_DATA, (0.7,))
    angles = sr.inverse_kinematics(data, DEEP.q)
    missing = np.array([np.isnan(angles[f"q1_{leg}"]) for leg in "ABC"])  # (legs, samples)
    first = int(np.flatnonzero(missing.any(axis=0))[0])
    leg = "ABC"[int(np.flatnonzero(missing[:, first])[0])]
    assert rows[1]["reason"] == (
        f"trajectory 1: t = {DEEP.t[first]:.6g} s: leg {leg} cannot reach this pose in its "
        "working mode"
    )
    assert np.isfinite(rows[1]["peak_tau_A"])  # over the samples evaluated
    least = np.nanmin(reference_conditioning(data, DEEP.q))  # where every leg reaches
    assert rows[1]["min_conditioning"] == pytest.approx(least, rel=RTOL)
    assert np.isnan(rows[1]["workspace_volume"])  # not asked for


def test_a_design_too_close_to_a_singularity_says_when() -> None:
    motions = [DELTA_MOTION, ROOT / "models" / "delta.csv"]
    table = rpr3gen.sweep(DELTA, {"platform.mass": [0.5]}, motions, workers=0,
                          volume_resolution=0, min_conditioning=0.3)  # fmt: skip
    (row,) = table.to_pylist()
    assert not row["feasible"]
    below = reference_conditioning(DELTA_DATA, DELTA_MOTION.q) < 0.3
    first = int(np.flatnonzero(below)[0])
    assert row["reason"].startswith(f"trajectory 1: t = {DELTA_MOTION.t[first]:.6g} s: ")
    assert row["reason"].endswith("under the threshold 0.3 (too close to a singularity)")
    assert row["min_conditioning"] < 0.3


def test_a_design_whose_motion_leaves_a_joint_limit_says_which() -> None:
    base = {**UPS_DATA, "limits": {"q2": [-0.2, 0.2]}}  # every piston's stroke
    grid = {"limits.q2[1]": [0.01, 0.2]}
    rows = rpr3gen.sweep(base, grid, [UPS_MOTION], workers=0, volume_resolution=0).to_pylist()
    assert [r["feasible"] for r in rows] == [False, True]
    strokes = sr.inverse_kinematics(base, UPS_MOTION.q)
    over = np.array([strokes[f"q2_{leg}"] > 0.01 for leg in "ABCDEF"])  # (legs, samples)
    first = int(np.flatnonzero(over.any(axis=0))[0])
    k = int(np.flatnonzero(over[:, first])[0])
    leg, value = "ABCDEF"[k], strokes[f"q2_{'ABCDEF'[k]}"][first]
    assert rows[0]["reason"] == (
        f"trajectory 1: t = {UPS_MOTION.t[first]:.6g} s: joint coordinate q2_{leg} = "
        f"{value:.6g} m outside its limits [-0.2, 0.01] (limits.{leg}.q2)"
    )


def test_an_invalid_combination_is_an_infeasible_row() -> None:
    """Each value is a platform inertia alone; together, not positive definite."""
    grid = {"platform.inertia[0]": [0.0008, 0.0007], "platform.inertia[3]": [0.0, 0.00075]}
    table = rpr3gen.sweep(DELTA, grid, [DELTA_MOTION], workers=0, volume_resolution=RESOLUTION)
    rows = table.to_pylist()
    assert [r["feasible"] for r in rows] == [True, True, True, False]
    assert rows[3]["reason"].startswith("invalid model: ")
    assert "platform.inertia: not a body's inertia tensor" in rows[3]["reason"]
    assert all(np.isnan(rows[3][c]) for c in table.column_names[len(grid) + 2 :])


# -- both backends -------------------------------------------------------------------------------


def test_the_c_backend_gives_numpys_rows(quick_c_builds: None) -> None:
    grid = {"legs.A.elbow[2]": [0.843982, 0.7], "platform.mass": [0.5, 2.0]}
    options = {"workers": 0, "volume_resolution": RESOLUTION}
    numpy = rpr3gen.sweep(DELTA, grid, [DEEP], **options).to_pylist()
    c = rpr3gen.sweep(DELTA, grid, [DEEP], backend="c", **options).to_pylist()
    assert [r["feasible"] for r in c] == [True, True, False, False]
    for a, b in zip(numpy, c, strict=True):
        for key, value in a.items():
            if isinstance(value, float):
                assert b[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
            else:
                assert b[key] == value, key


# -- the command ---------------------------------------------------------------------------------

GRID_TOML = '"platform.mass" = [0.5, 1.0]\n[legs.A]\nrod_mass = [0.1, 0.2]\n'


def _command(tmp_path: Path, *extra: str) -> list[str]:
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID_TOML)
    return ["sweep", "--model", str(DELTA), "--grid", str(grid), "--trajectory",
            str(ROOT / "models" / "delta.csv"), "--volume-resolution", str(RESOLUTION),
            "--chunk-size", "3", *extra]  # fmt: skip


def test_the_command_writes_the_rows_as_parquet(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "designs.parquet"
    assert main([*_command(tmp_path), "--workers", "0", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert (captured.out, captured.err) == (f"4 designs, 4 feasible; wrote {out}\n", "")
    table = pq.read_table(out)
    same = rpr3gen.sweep(DELTA, {"platform.mass": [0.5, 1.0], "legs.A.rod_mass": [0.1, 0.2]},
                         [ROOT / "models" / "delta.csv"], workers=0, chunk_size=3,
                         volume_resolution=RESOLUTION)  # fmt: skip
    assert table.column_names[:2] == ["platform.mass", "legs.A.rod_mass"]
    assert table.to_pylist() == same.to_pylist()
    assert not Path(f"{out}.parts").exists()


@pytest.mark.slow
def test_the_scheduler_run_is_the_in_process_run(
    scheduler: str, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    here, there = tmp_path / "here.parquet", tmp_path / "there.parquet"
    assert main([*_command(tmp_path), "--workers", "0", "--out", str(here)]) == 0
    assert main([*_command(tmp_path), "--scheduler", scheduler, "--out", str(there)]) == 0
    assert capfd.readouterr().err == ""
    assert here.read_bytes() == there.read_bytes()
    assert pq.read_table(there).num_rows == 4


def test_an_interrupted_sweep_resumes_and_loses_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    straight, out = tmp_path / "straight.parquet", tmp_path / "resumed.parquet"
    grid = {"platform.mass": [0.5, 1.0, 1.5], "legs.A.rod_mass": [0.1, 0.2]}  # 3 chunks of 2
    options = {"workers": 0, "chunk_size": 2, "volume_resolution": RESOLUTION}
    rpr3gen.sweep(DELTA, grid, [DELTA_MOTION], out=straight, **options)
    evaluated: list[int] = []

    def interrupted(plan: Any, index: int) -> Any:
        if index == 1:
            raise KeyboardInterrupt
        evaluated.append(index)
        return evaluate_chunk(plan, index)

    monkeypatch.setattr(sweeps, "evaluate_chunk", interrupted)
    with pytest.raises(KeyboardInterrupt):
        rpr3gen.sweep(DELTA, grid, [DELTA_MOTION], out=out, **options)
    assert not out.exists()
    evaluated.clear()

    def counted(plan: Any, index: int) -> Any:
        evaluated.append(index)
        return evaluate_chunk(plan, index)

    monkeypatch.setattr(sweeps, "evaluate_chunk", counted)
    with pytest.raises(rpr3gen.SetupError, match="holds the chunks of another sweep"):
        rpr3gen.sweep(DELTA, grid, [DELTA_MOTION], out=out, resume=True, backend="c", **options)
    rpr3gen.sweep(DELTA, grid, [DELTA_MOTION], out=out, resume=True, **options)
    assert evaluated == [1, 2]
    assert out.read_bytes() == straight.read_bytes()


# -- bad grids and options: one line naming them -------------------------------------------------


@pytest.mark.parametrize(
    ("base", "grid", "message"),
    [
        (DELTA_DATA, {"platform.mas": [1.0]},
         "platform.mas: unknown model key; did you mean 'platform.mass'?"),
        (DELTA_DATA, {"legs.B.base[0]": [0.1]},
         "legs.B.base[0]: with symmetric = true only leg A's keys exist (leg B is leg A turned "
         "by 120 degrees about z); vary legs.A.base[0]"),
        (UPS_DATA, {"legs.E.mass[1]": [0.2]},
         "legs.E.mass[1]: with symmetric = true only legs A and B's keys exist (leg E is leg A "
         "turned by 240 degrees about z); vary legs.A.mass[1]"),
        (DELTA_DATA, {"legs.A.base": [0.1]},
         'legs.A.base: legs.A.base holds a list; vary one element, e.g. "legs.A.base[0]"'),
        (DELTA_DATA, {"legs.A.base[3]": [0.1]}, "legs.A.base[3]: index 3 out of range (0 to 2)"),
        (UPS_DATA, {"legs.B.inertia[1]": [0.1]},
         'vary one element, e.g. "legs.B.inertia[0][0]"'),
        (UPS_DATA, {"legs.A.com[2][0]": [0.1]}, "legs.A.com[2][0]: index 2 out of range (0 to 1)"),
        (DELTA_DATA, {"platform.mass[0]": [1.0]}, "platform.mass holds one value, not a list"),
        (DELTA_DATA, {"legs.A.u_axes[0][0]": [1.0]},
         "legs.A.u_axes[0][0]: not a key of RSS2 legs (only of UPS, RUS, PUS legs)"),
        (UPS_DATA, {"legs.A.rod_mass": [0.1]},
         "legs.A.rod_mass: not a key of UPS legs (only of RSS2, PSS2 legs)"),
        (DELTA_DATA, {"legs.D.mass[0]": [1.0]},
         "legs.D.mass[0]: unknown leg (a 3-RSS2 has legs A to C)"),
        (DELTA_DATA, {"actuated": [1]},
         "actuated: not a design parameter (a RSS2 leg carries its motor on joint 1)"),
        (UPS_DATA, {"symmetric": [1.0]}, "symmetric: not a design parameter"),
        (DELTA_DATA, {"leg": ["PSS2"]}, "leg: not a design parameter"),
        (DELTA_DATA, {"limits.q1[0]": [-1.0]}, "the base model has no limits.q1 to vary"),
        (DELTA_DATA, {"geometry.r": [0.3]}, "geometry.r: unknown model key"),
        (DELTA_DATA, {"platform.mass": [0.5, -1.0]},
         "platform.mass = -1.0: platform.mass: must be a positive number, got -1.0"),
        (DELTA_DATA, {"legs.A.rod_com": [1.5]}, "legs.A.rod_com: must be in [0, 1]"),
        (DELTA_DATA, {"legs.A.width": {"start": 0.0, "stop": 0.1, "num": 2}},
         "legs.A.width = 0.0: legs.A.width: must be a positive number"),
        (DELTA_DATA, {"legs.A.elbow[2]": [0.0]}, "the legs do not hold the platform at home"),
        (UPS_DATA, {"legs.A.u_axes[1][0]": [0.5]}, "the U's two axes must be perpendicular"),
        (DELTA_DATA, {"environment.gravity[2]": ["down"]},
         'environment.gravity[2][0]: must be a number, got "down"'),
        (DELTA_DATA, {"payload.moment[0]": 1.0}, "payload.moment[0]: must be a list of values"),
    ],
)  # fmt: skip
def test_a_bad_grid_is_one_line_naming_the_key(base: dict, grid: dict, message: str) -> None:
    with pytest.raises(GridError) as caught:
        read_grid(grid, base)
    text = str(caught.value)
    assert text.startswith("<grid>: "), text
    assert message in text, text
    assert "\n" not in text


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"--trajectory": None}, "--trajectory: 'rotation' is one of the paper's planar motions"),
        ({"--trajectory": "rectilinear"}, "needs its own: give a trajectory CSV file"),
        ({"--trajectory": str(ROOT / "models" / "loop.csv")}, "loop.csv"),
        ({"--area-resolution": "24"}, "--area-resolution: for a planar robot's workspace area"),
        ({"--model": None, "--volume-resolution": None, "--backend": "c"},
         "--backend: 'c' is for a spatial robot's sweep"),
        ({"--model": None, "--volume-resolution": "8"},
         "--volume-resolution: for a spatial robot's workspace volume"),
        ({"--volume-resolution": "1"}, "--volume-resolution: must be 0 (no volume) or"),
        ({"grid": '[legs.B]\nmass = [[1.0]]\n'}, "grid.toml: legs.B.mass: with symmetric = true"),
    ],
    ids=str,
)  # fmt: skip
def test_a_bad_spatial_sweep_is_one_line_and_writes_nothing(
    change: dict[str, Any], named: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "results" / "s.parquet"
    argv = [*_command(tmp_path), "--workers", "0", "--out", str(out)]
    if "grid" in change:
        (tmp_path / "grid.toml").write_text(change.pop("grid"))
    for option, value in change.items():
        at = argv.index(option) if option in argv else None
        if at is not None:
            del argv[at : at + 2]
        if value is not None:
            argv += [option, value]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1, captured.err
    assert captured.err.startswith("rpr3gen: error: "), captured.err
    assert named in captured.err, captured.err
    assert not (tmp_path / "results").exists()
