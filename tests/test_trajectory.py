"""Trajectories: the paper's motions (eq. 3) and trajectory CSV files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rpr3gen.errors import InputTypeError, Rpr3genError, TrajectoryError, TrajectoryWarning
from rpr3gen.trajectory import (
    CSV_COLUMNS,
    PAPER_TRAJECTORIES,
    Trajectory,
    paper_trajectory,
    read_trajectory_csv,
    write_trajectory_csv,
)

HEADER = "t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi"


# -- the paper's motions -----------------------------------------------------------------------


def test_amplitudes_are_the_papers() -> None:
    assert PAPER_TRAJECTORIES["rotation"] == (0.0, 0.0, math.pi / 6)
    assert PAPER_TRAJECTORIES["rectilinear"] == (0.05, -0.05, 0.0)
    with pytest.raises(TypeError):
        PAPER_TRAJECTORIES["other"] = (0.0, 0.0, 0.0)  # type: ignore[index]


def test_rotation_defaults() -> None:
    traj = paper_trajectory("rotation")
    assert len(traj) == 301
    assert traj.t.shape == (301,)
    assert traj.q.shape == traj.qd.shape == traj.qdd.shape == (301, 3)
    assert traj.t[0] == 0.0
    assert traj.t[-1] == 3.0
    assert np.all(np.diff(traj.t) > 0)
    # Starts at rest in the central configuration; x and y never move.
    assert traj.q[0].tolist() == [0.0, 0.0, 0.0]
    assert traj.qd[0].tolist() == [0.0, 0.0, 0.0]
    assert np.all(traj.q[:, :2] == 0.0)
    # 1 - cos(pi) = 2: ends at phi = 2 phi* = pi/3, again at rest.
    assert traj.q[-1, 2] == pytest.approx(math.pi / 3, rel=1e-15)
    assert traj.qd[-1, 2] == pytest.approx(0.0, abs=1e-15)
    # Initial angular acceleration phi* (pi/3)^2.
    assert traj.qdd[0, 2] == pytest.approx(math.pi / 6 * (math.pi / 3) ** 2, rel=1e-15)


def test_rectilinear_values_at_mid_time() -> None:
    traj = paper_trajectory("rectilinear", samples=5, duration=2.0)
    assert traj.t.tolist() == [0.0, 0.5, 1.0, 1.5, 2.0]
    w = math.pi / 2.0
    # At t = 1 (half the duration): s = 1, s' = w, s'' = 0.
    np.testing.assert_allclose(traj.q[2], [0.05, -0.05, 0.0], rtol=1e-15)
    np.testing.assert_allclose(traj.qd[2], [0.05 * w, -0.05 * w, 0.0], rtol=1e-15)
    np.testing.assert_allclose(traj.qdd[2], [0.0, 0.0, 0.0], atol=1e-16)
    assert np.all(traj.q[:, 2] == 0.0)


@pytest.mark.parametrize("name", sorted(PAPER_TRAJECTORIES))
def test_derivatives_match_finite_differences(name: str) -> None:
    traj = paper_trajectory(name, samples=4001, duration=3.0)
    dt = traj.t[1] - traj.t[0]
    for value, derivative in ((traj.q, traj.qd), (traj.qd, traj.qdd)):
        numeric = np.gradient(value, dt, axis=0, edge_order=2)
        scale = max(np.abs(derivative).max(), 1e-300)
        np.testing.assert_allclose(numeric, derivative, atol=1e-6 * scale, rtol=0)


def test_samples_and_duration_are_used() -> None:
    traj = paper_trajectory("rotation", samples=2, duration=0.5)
    assert traj.t.tolist() == [0.0, 0.5]
    assert traj.q[-1, 2] == pytest.approx(math.pi / 3)
    assert traj.qdd[0, 2] == pytest.approx(math.pi / 6 * (math.pi / 0.5) ** 2)
    assert len(paper_trajectory("rotation", samples=np.int64(3), duration=1)) == 3


@pytest.mark.parametrize("samples", [1, 0, -5])
def test_bad_samples(samples: object) -> None:
    with pytest.raises(TrajectoryError, match="samples"):
        paper_trajectory("rotation", samples=samples)  # type: ignore[arg-type]


@pytest.mark.parametrize("samples", [2.5, True, "10", None])
def test_samples_of_the_wrong_type(samples: object) -> None:
    with pytest.raises(InputTypeError, match="samples"):
        paper_trajectory("rotation", samples=samples)  # type: ignore[arg-type]


@pytest.mark.parametrize("duration", [0.0, -1.0, math.nan, math.inf])
def test_bad_duration(duration: object) -> None:
    with pytest.raises(TrajectoryError, match="duration"):
        paper_trajectory("rotation", duration=duration)  # type: ignore[arg-type]


@pytest.mark.parametrize("duration", [True, "3", None])
def test_duration_of_the_wrong_type(duration: object) -> None:
    with pytest.raises(InputTypeError, match="duration"):
        paper_trajectory("rotation", duration=duration)  # type: ignore[arg-type]


def test_unknown_name() -> None:
    with pytest.raises(TrajectoryError, match="rotatoin") as info:
        paper_trajectory("rotatoin")
    assert "did you mean 'rotation'?" in str(info.value)
    assert isinstance(info.value, Rpr3genError)
    with pytest.raises(TrajectoryError, match="spiral"):
        paper_trajectory("spiral")


def test_trajectory_arrays_are_read_only_copies() -> None:
    q = np.zeros((2, 3))
    traj = Trajectory(t=[0.0, 1.0], q=q, qd=q, qdd=q)  # type: ignore[arg-type]
    q[0, 0] = 1.0
    assert traj.q[0, 0] == 0.0
    assert traj.t.dtype == np.float64
    with pytest.raises(ValueError, match="read-only"):
        traj.q[0, 0] = 2.0


@pytest.mark.parametrize(
    ("t", "q"),
    [(np.zeros((2, 1)), np.zeros((2, 3))), (np.zeros(2), np.zeros((3, 3))), (np.zeros(0), None)],
)
def test_trajectory_shapes_are_checked(t: np.ndarray, q: np.ndarray | None) -> None:
    q = np.zeros((len(t), 3)) if q is None else q
    with pytest.raises(TrajectoryError, match="shape"):
        Trajectory(t=t, q=q, qd=q, qdd=q)


# -- CSV files ---------------------------------------------------------------------------------


def test_csv_round_trip_is_exact(tmp_path: Path) -> None:
    rng = np.random.default_rng(1)
    n = 50
    t = np.cumsum(rng.uniform(1e-9, 1.0, n)) - 3.0
    values = rng.normal(size=(n, 9)) * 10.0 ** rng.integers(-300, 300, size=(n, 9))
    traj = Trajectory(t=t, q=values[:, :3], qd=values[:, 3:6], qdd=values[:, 6:])
    path = tmp_path / "traj.csv"
    write_trajectory_csv(path, traj)
    with pytest.warns(TrajectoryWarning, match="disagree"):  # random values: no motion
        back = read_trajectory_csv(path)
    for name in ("t", "q", "qd", "qdd"):
        assert np.array_equal(getattr(back, name), getattr(traj, name)), name
    assert path.read_text(encoding="utf-8").splitlines()[0] == HEADER


def test_csv_round_trip_of_paper_trajectory(tmp_path: Path) -> None:
    traj = paper_trajectory("rectilinear")
    path = tmp_path / "r.csv"
    write_trajectory_csv(str(path), traj)
    back = read_trajectory_csv(str(path))
    assert np.array_equal(back.q, traj.q)
    assert np.array_equal(back.qdd, traj.qdd)
    assert len(path.read_text(encoding="utf-8").splitlines()) == 302
    assert HEADER.split(",") == list(CSV_COLUMNS)


def test_csv_any_column_order_extra_columns_blank_lines_bom(tmp_path: Path) -> None:
    path = tmp_path / "t.csv"
    path.write_text(
        "\ufeffnote, ddphi,ddy,ddx,dphi,dy,dx,phi,y,x,t\r\n"
        "a,10,9,8,7,6,5,4,3,2,1\r\n"
        "\r\n"
        "b, 20 ,19,18,17,16,15,14,13,12,1.5\r\n",
        encoding="utf-8",
    )
    with pytest.warns(TrajectoryWarning, match="disagree"):  # arbitrary values
        traj = read_trajectory_csv(path)
    assert traj.t.tolist() == [1.0, 1.5]
    assert traj.q.tolist() == [[2, 3, 4], [12, 13, 14]]
    assert traj.qd.tolist() == [[5, 6, 7], [15, 16, 17]]
    assert traj.qdd.tolist() == [[8, 9, 10], [18, 19, 20]]


ROW1 = "0,0,0,0,0,0,0,0,0,0"
ROW2 = "0.1,1,2,3,4,5,6,7,8,9"

# (id, file text, substrings the message must contain)
BAD_CSV: list[tuple[str, str, tuple[str, ...]]] = [
    ("empty", "", ("empty file",)),
    ("only-blank-lines", "\n\n  \n", ("empty file",)),
    ("header-only", HEADER + "\n", ("no data rows",)),
    ("header-and-blank", HEADER + "\n\n\n", ("no data rows",)),
    ("missing-column", HEADER.replace(",ddphi", "") + "\n" + ROW1[:-2] + "\n",
     ("line 1 (header)", "missing column 'ddphi'")),
    ("misspelt-column", HEADER.replace("dphi,", "dph,") + "\n" + ROW1 + "\n",
     ("missing column 'dphi'", "found 'dph'")),
    ("duplicate-column", HEADER + ",x\n" + ROW1 + ",0\n", ("column 'x' appears twice",)),
    ("not-a-number", f"{HEADER}\n{ROW1}\n0.1,1,2,3,abc,5,6,7,8,9\n",
     ("line 3 (data row 2)", "column 'dx'", "not a number", "'abc'")),
    ("empty-cell", f"{HEADER}\n0,0,0,,0,0,0,0,0,0\n",
     ("line 2 (data row 1)", "column 'phi'", "not a number")),
    ("nan", f"{HEADER}\n{ROW1}\n0.1,1,2,3,4,5,6,7,nan,9\n",
     ("line 3 (data row 2)", "column 'ddy'", "not finite")),
    ("inf", f"{HEADER}\n-inf,0,0,0,0,0,0,0,0,0\n", ("line 2 (data row 1)", "column 't'", "finite")),
    ("time-equal", f"{HEADER}\n{ROW1}\n{ROW2}\n{ROW2}\n",
     ("line 4 (data row 3)", "column 't'", "strictly increasing")),
    ("time-decreasing", f"{HEADER}\n{ROW2}\n\n{ROW1}\n",
     ("line 4 (data row 2)", "column 't'", "not greater")),
    ("short-row", f"{HEADER}\n{ROW1}\n0.1,1,2\n", ("line 3 (data row 2)", "3 fields", "10")),
    ("long-row", f"{HEADER}\n{ROW1},7\n", ("line 2 (data row 1)", "11 fields")),
]  # fmt: skip


@pytest.mark.parametrize(("text", "needles"), [c[1:] for c in BAD_CSV], ids=[c[0] for c in BAD_CSV])
def test_bad_csv(tmp_path: Path, text: str, needles: tuple[str, ...]) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(TrajectoryError) as info:
        read_trajectory_csv(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    for needle in needles:
        assert needle in message, (needle, message)


def test_missing_directory_and_binary_csv(tmp_path: Path) -> None:
    with pytest.raises(TrajectoryError, match="not found"):
        read_trajectory_csv(tmp_path / "nope.csv")
    with pytest.raises(TrajectoryError, match="directory"):
        read_trajectory_csv(tmp_path)
    path = tmp_path / "bin.csv"
    path.write_bytes(HEADER.encode() + b"\n\xff\xfe,0\n")
    with pytest.raises(TrajectoryError, match="UTF-8"):
        read_trajectory_csv(path)
