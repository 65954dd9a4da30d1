"""Time-optimal retiming (``rpr3gen.retime``, ``rpr3gen retime``; TOPP-RA, docs/retime.md),
judged by the independent references: Newton-Euler for the paper's 3-RPR
(``tests/newton_euler.py``), for any planar 3-leg robot (``tests/planar_reference.py``, the
gallery's 3-RRR) and for spatial robots (``tests/spatial_reference.py``, the Delta of
``models/delta.toml`` and the 6-UPS hexapod of ``models/tsai-ups.toml``), which import nothing
of the code under test.

What is checked: every actuator effort and rate of the retimed trajectory within its limit, as
the references compute them; some limit active at nearly every sample (a time-optimal motion
has no slack); rest at both ends; every pose on the spline through the waypoints, rebuilt here
from its definition (scipy's not-a-knot cubic at equally spaced parameters) and travelled
forwards; no slower than the original timing of the same path scaled uniformly to the same
limits; the duration scaling as 1/sqrt(limit) without gravity; the excess between grid points
falling as the square of the grid step. Then the refusals, each one line naming where.

Tolerance: TOPP-RA holds the limits at its grid points (``s'' `` constant between them, each
step's efforts within the limits at both its ends); between them the efforts and rates exceed
the limits by at most ``h^2 / 8`` times their second derivative along the path, ``h`` the grid
step. At the default 1001 grid points that is below 1e-4 of the limits on these paths
(measured: the 3-RRR loop's efforts 1.5e-5 and rates 5e-5 over 20001 samples; at the samples
used here at most 1.5e-6 and 4.7e-5; the 3-RPR, the Delta and the hexapod below 1.3e-6);
:data:`TOL` = 1e-3 leaves a factor of twenty, and
:func:`test_the_excess_between_grid_points_falls_as_the_square_of_the_step`
checks the law itself. The references agree with the generated code to 1e-12.
"""

from __future__ import annotations

import math
import sys
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.errors import InputError, Rpr3genError, SetupError, TrajectoryError

try:
    from . import newton_euler as ne
    from . import planar_reference as pr
    from . import spatial_reference as sr
except ImportError:
    import newton_euler as ne
    import planar_reference as pr
    import spatial_reference as sr

ROOT = Path(__file__).resolve().parent.parent
MODELS = ROOT / "models"
LOOP_PATH = MODELS / "loop-path.csv"
TOL = 1e-3  # relative excess over a limit between grid points (module docstring)
ACTIVE = 0.99  # "at its limit": within 1% of it (TOPP-RA is within O(h) of the optimum)

#: A Delta's pick-and-place: up from the pick, across, down to the place (m).
DELTA_PATH = np.array(
    [[-0.1, 0.0, -0.05], [-0.1, 0.0, 0.0], [0.0, 0.02, 0.03], [0.1, 0.0, 0.0], [0.1, 0.0, -0.05]]
)
#: The paper's rotation (eq. 3, figs. 3-8) as a path: the platform turns by pi/3 about G.
PAPER_PATH = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, math.pi / 3]])


def _rrr_data() -> dict:
    """``models/rrr.toml`` with legs B and C written out (the reference has no sugar)."""
    with (MODELS / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    assert data.pop("symmetric") is True
    data["legs"] = pr.expand_symmetric(data["legs"]["A"])
    return data


def _spatial_data(name: str) -> dict:
    with (MODELS / f"{name}.toml").open("rb") as handle:
        return tomllib.load(handle)


def _hexapod_path() -> np.ndarray:
    """The first half of ``models/tsai-ups.csv`` (1 s, rest to rest), every tenth pose."""
    model = rpr3gen.load_model(MODELS / "tsai-ups.toml")
    traj = rpr3gen.read_trajectory_csv(MODELS / "tsai-ups.csv", pose=model.structure.pose)
    return traj.q[0:101:10]


@dataclass(frozen=True)
class Case:
    """A retimed path and what the reference says of it: efforts and actuator rates (n, legs)."""

    name: str
    waypoints: np.ndarray
    traj: rpr3gen.Trajectory
    effort_limit: np.ndarray
    velocity_limit: np.ndarray | None
    tau: np.ndarray
    rate: np.ndarray


def _reference(name: str, traj: rpr3gen.Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """The reference's efforts and actuator rates along ``traj``."""
    q, qd, qdd = traj.q, traj.qd, traj.qdd
    if name.startswith("paper"):
        out = ne.solve(ne.paper_params(), "revolute", q, qd, qdd)
        tau = np.stack([out[f"m10_{leg}"] for leg in "ABC"], axis=1)
        return tau, np.stack([out[f"omega10_{leg}"] for leg in "ABC"], axis=1)
    if name.startswith("rrr"):
        robot = pr.parse_model(_rrr_data())
        out = pr.solve(robot, q, qd, qdd)
        return pr.efforts(out), pr.actuated_rates(robot, out)
    data = _spatial_data("tsai-ups" if name.startswith("hexapod") else "delta")
    out = sr.solve(data, q, qd, qdd)
    return sr.efforts(data, out), sr.actuator_rates(data, q, qd)


def _waypoints(path: np.ndarray | Path) -> np.ndarray:
    if isinstance(path, Path):
        return np.loadtxt(path, delimiter=",", skiprows=1)
    return path


#: name -> (model file (None: the paper's), path, effort limit, velocity limit, samples); the
#: paper's 3-RPR, the gallery's 3-RRR, a Delta and a hexapod (the 6-UPS of models/tsai-ups.toml)
CASES = {
    "rrr": ("rrr.toml", LOOP_PATH, [8.0], None, 1001),
    "rrr-rates": ("rrr.toml", LOOP_PATH, [8.0], [2.0], 1001),
    "paper": (None, PAPER_PATH, [30.0, 30.0, 40.0], None, 1001),
    "paper-rates": (None, PAPER_PATH, [40.0], [1.5, 1.5, 3.0], 1001),
    "delta": ("delta.toml", DELTA_PATH, [16.0], None, 301),
    "hexapod": ("tsai-ups.toml", None, [10.0], None, 301),  # None: _hexapod_path()
}


@cache
def case(name: str) -> Case:
    file, path, effort, velocity, samples = CASES[name]
    model = rpr3gen.load_model(MODELS / file if file else None)
    path = _hexapod_path() if path is None else path
    given = str(path) if isinstance(path, Path) else path
    traj = rpr3gen.retime(model, given, effort, velocity, samples=samples)
    tau, rate = _reference(name, traj)
    legs = len(model.structure.legs)
    e = np.broadcast_to(np.array(effort), (legs,))
    v = None if velocity is None else np.broadcast_to(np.array(velocity), (legs,))
    return Case(name, _waypoints(path), traj, e, v, tau, rate)


@pytest.mark.parametrize("name", list(CASES))
def test_every_effort_is_within_its_limit_as_the_reference_computes_it(name: str) -> None:
    c = case(name)
    assert np.isfinite(c.tau).all()
    excess = np.abs(c.tau) / c.effort_limit - 1.0
    assert excess.max() <= TOL, (name, excess.max())


@pytest.mark.parametrize("name", [n for n in CASES if CASES[n][3] is not None])
def test_every_actuator_rate_is_within_its_limit(name: str) -> None:
    c = case(name)
    assert c.velocity_limit is not None
    ratio = np.abs(c.rate) / c.velocity_limit
    assert ratio.max() <= 1.0 + TOL, (name, ratio.max())
    assert ratio.max() >= ACTIVE  # the rate limit binds somewhere: it is not vacuous here


@pytest.mark.parametrize("name", list(CASES))
def test_some_limit_is_active_at_nearly_every_sample(name: str) -> None:
    """Time-optimal: no moment where every actuator has effort (and rate) to spare."""
    c = case(name)
    ratio = np.abs(c.tau) / c.effort_limit
    if c.velocity_limit is not None:
        ratio = np.maximum(ratio, np.abs(c.rate) / c.velocity_limit)
    active = ratio.max(axis=1) >= ACTIVE
    assert active.mean() >= 0.95, (name, active.mean())


@pytest.mark.parametrize("name", list(CASES))
def test_the_motion_starts_and_ends_at_rest(name: str) -> None:
    c = case(name)
    t, qd = c.traj.t, c.traj.qd
    assert t[0] == 0.0
    assert (np.diff(t) > 0).all()
    assert np.array_equal(qd[0], np.zeros_like(qd[0]))
    assert np.array_equal(qd[-1], np.zeros_like(qd[-1]))
    np.testing.assert_allclose(c.traj.q[[0, -1]], c.waypoints[[0, -1]], rtol=0, atol=1e-12)
    assert np.abs(c.rate[[0, -1]]).max() <= 1e-12  # the reference's actuator rates too


def _path_parameters(spline: CubicSpline, q: np.ndarray) -> np.ndarray:
    """The parameter of the point of ``spline`` nearest each pose, followed along the samples
    (a closed path passes its start twice): the nearest of a dense sampling just behind to well
    ahead of the previous sample's, polished by Newton steps on ``(p(s) - q) . p'(s) = 0``."""
    dense = np.linspace(0.0, 1.0, 200001)
    points = spline(dense)
    d1, d2 = spline.derivative(), spline.derivative(2)
    s = np.empty(len(q))
    k = 0
    for i, pose in enumerate(q):
        window = slice(max(k - 100, 0), k + 20000)
        k = window.start + int(np.argmin(((points[window] - pose) ** 2).sum(axis=1)))
        guess = dense[k]
        for _ in range(3):
            r = spline(guess) - pose
            df = d1(guess) @ d1(guess) + r @ d2(guess)
            guess = float(np.clip(guess - (r @ d1(guess)) / df, 0.0, 1.0)) if df > 0 else guess
        s[i] = guess
    return s


@pytest.mark.parametrize("name", ["rrr", "paper", "delta", "hexapod"])
def test_every_pose_is_on_the_spline_through_the_waypoints_travelled_forwards(name: str) -> None:
    c = case(name)
    spline = CubicSpline(np.linspace(0.0, 1.0, len(c.waypoints)), c.waypoints)
    s = _path_parameters(spline, c.traj.q)
    assert np.abs(spline(s) - c.traj.q).max() <= 1e-10
    assert s[0] == 0.0
    assert s[-1] == pytest.approx(1.0, abs=1e-12)
    assert (np.diff(s) >= -1e-12).all()  # forwards, never back
    tangent = spline(s, 1)
    speed = (c.traj.qd * tangent).sum(axis=1) / (tangent**2).sum(axis=1)  # qd = q_s s'
    assert (speed >= -1e-12).all()
    np.testing.assert_allclose(c.traj.qd, speed[:, None] * tangent, rtol=0, atol=1e-9)


def test_no_slower_than_the_original_timing_scaled_to_the_same_limit() -> None:
    """The gallery's loop takes 4 s; the same path, its timing scaled uniformly (``q(t/k)``)
    until its largest effort (the reference's) reaches the limit, is a feasible motion: the
    time-optimal one along the same path is no slower."""
    model = rpr3gen.load_model(MODELS / "rrr.toml")
    loop = rpr3gen.read_trajectory_csv(MODELS / "loop.csv")
    robot = pr.parse_model(_rrr_data())
    limit = 8.0

    def peak(k: float) -> float:
        out = pr.solve(robot, loop.q, loop.qd / k, loop.qdd / k**2)
        return float(np.abs(pr.efforts(out)).max())

    lo, hi = 0.05, 1.0  # peak(hi) <= limit < peak(lo)
    assert peak(hi) <= limit < peak(lo)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if peak(mid) <= limit else (mid, hi)
    uniform = loop.t[-1] * hi
    traj = rpr3gen.retime(model, str(MODELS / "loop.csv"), limit, samples=11)
    assert traj.t[-1] <= uniform, (traj.t[-1], uniform)
    assert traj.t[-1] < 0.6 * loop.t[-1]  # and much faster than the gallery's own 4 s


def test_without_gravity_four_times_the_limit_halves_the_duration() -> None:
    """``tau = a s'' + b s'^2`` without gravity or payload: limits k times higher allow
    ``s'(t) -> sqrt(k) s'(sqrt(k) t)``, so the optimum lasts 1/sqrt(k) as long; the units of the
    limits must not change TOPP-RA's answer (the path parameter is scaled to them)."""
    with (MODELS / "rrr.toml").open("rb") as handle:
        data = tomllib.load(handle)
    data["environment"]["gravity"] = [0.0, 0.0]
    model = rpr3gen.model_from_dict(data, source="rrr without gravity")
    slow = rpr3gen.retime(model, str(LOOP_PATH), 2.0, samples=11)
    fast = rpr3gen.retime(model, str(LOOP_PATH), 8.0, samples=11)
    assert fast.t[-1] == pytest.approx(slow.t[-1] / 2, rel=1e-9)


def test_the_excess_between_grid_points_falls_as_the_square_of_the_step() -> None:
    model = rpr3gen.load_model(MODELS / "rrr.toml")
    robot = pr.parse_model(_rrr_data())
    excess = []
    for points in (401, 801):
        traj = rpr3gen.retime(model, str(LOOP_PATH), 8.0, grid_points=points, samples=20001)
        tau = pr.efforts(pr.solve(robot, traj.q, traj.qd, traj.qdd))
        excess.append(np.abs(tau).max() / 8.0 - 1.0)
    assert 0 < excess[1] < excess[0] / 3, excess  # h halved: about a quarter (measured 4.8)
    assert excess[0] < 1e-3


def test_a_trajectory_sampled_anew_keeps_the_duration() -> None:
    model = rpr3gen.load_model()
    few = rpr3gen.retime(model, PAPER_PATH, 40.0, samples=2)
    many = rpr3gen.retime(model, PAPER_PATH, 40.0, samples=3001)
    assert few.t[-1] == many.t[-1]
    assert len(few) == 2
    assert len(many) == 3001


# -- bad input: one line, naming where ------------------------------------------------------

SINGULAR_PHI = 0.51813  # the 3-RRR at (0, 0, phi): a parallel singularity (conditioning 1e-5)


@pytest.fixture(scope="module")
def rrr() -> rpr3gen.Model:
    return rpr3gen.load_model(MODELS / "rrr.toml")


def test_a_waypoint_at_a_singular_pose_is_refused_naming_its_row(rrr: rpr3gen.Model) -> None:
    path = [[0.0, 0.0, 0.0], [0.0, 0.0, SINGULAR_PHI], [0.0, 0.0, 0.7]]
    with pytest.raises(InputError, match=r"^path: row 2: .*conditioning [0-9.e-]+, under") as info:
        rpr3gen.retime(rrr, path, 20.0)
    assert info.value.argument == "path"
    assert "\n" not in str(info.value)


def test_a_path_through_a_singular_pose_is_refused_naming_the_rows_around_it(
    rrr: rpr3gen.Model,
) -> None:
    path = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.3], [0.0, 0.0, 0.7]]
    with pytest.raises(InputError, match=r"^path: between rows 2 and 3: .*phi = 0\.51"):
        rpr3gen.retime(rrr, path, 20.0)


def test_a_path_out_of_reach_is_refused_naming_the_leg(rrr: rpr3gen.Model) -> None:
    with pytest.raises(InputError, match=r"^path: between rows 1 and 2: .*leg C cannot reach"):
        rpr3gen.retime(rrr, [[0.0, 0.0, 0.0], [0.5, 0.0, 0.3]], 20.0)


def test_a_limit_that_cannot_hold_the_robot_at_rest_says_where_and_how_much(
    rrr: rpr3gen.Model,
) -> None:
    with pytest.raises(InputError) as info:
        rpr3gen.retime(rrr, str(LOOP_PATH), [1.0, 20.0, 20.0])
    message = str(info.value)
    assert info.value.argument == "effort_limit"
    assert message.startswith("effort_limit: 1 N m cannot hold the robot at rest at ")
    assert "loop-path.csv line 2 (waypoint 1) (x = 0, y = 0, phi = 0): tau_A is 5.75" in message
    need = float(message.rsplit("|tau_A| reaches ", 1)[1].split()[0])
    c = rpr3gen.actuator_efforts(rrr, *(np.zeros((1, 3)),) * 3)  # at home, at rest
    assert need >= abs(c[0, 0])
    rpr3gen.retime(rrr, str(LOOP_PATH), [need * 1.01, 20.0, 20.0], samples=3)  # enough


@pytest.mark.parametrize(
    ("kwargs", "error", "pattern"),
    [
        ({"path": [[0.0, 0.0, 0.0]]}, InputError, r"^path: a path needs at least 2 waypoints"),
        ({"path": np.zeros((2, 3))}, InputError, r"^path: row 2: the same pose"),
        ({"path": np.zeros((2, 6))}, InputError, r"^path: the 3-RRR.* \(m, 3\)"),
        ({"path": [[0, 0, 0], [0, 0, math.nan]]}, InputError, r"^path: row 2: .*not finite"),
        ({"path": np.zeros(3)}, InputError, r"^path: must be waypoints of shape"),
        ({"path": "nowhere.csv"}, TrajectoryError, r"^nowhere\.csv: path file not found"),
        ({"effort_limit": 0.0}, InputError, r"^effort_limit: must be a finite number > 0"),
        ({"effort_limit": [10.0, -1.0, 10.0]}, InputError, r"^effort_limit: every limit .*2\)"),
        ({"effort_limit": [10.0, 10.0]}, InputError, r"^effort_limit: give one limit .* 3, legs"),
        ({"velocity_limit": math.inf}, InputError, r"^velocity_limit: must be a finite number"),
        ({"velocity_limit": np.ones((1, 3))}, InputError, r"^velocity_limit: must be a number"),
        ({"effort_limit": "10"}, TypeError, r"^effort_limit: must be"),
        ({"effort_limit": True}, TypeError, r"^effort_limit: must be"),
        ({"samples": 1}, InputError, r"^samples: must be an integer >= 2"),
        ({"grid_points": 10**12}, InputError, r"^grid_points: .* at most"),
        ({"effort_limit": 1e12}, InputError, r"^effort_limit: the time-optimal motion .*1e-06"),
        ({"velocity_limit": 1e-12}, InputError, r"^velocity_limit: .* would last"),
    ],
    ids=str,
)
def test_bad_input_is_one_line_of_the_error_family(
    rrr: rpr3gen.Model, kwargs: dict, error: type[Exception], pattern: str
) -> None:
    given = {"path": [[0.0, 0.0, 0.0], [0.01, 0.0, 0.1]], "effort_limit": 20.0} | kwargs
    with pytest.raises(error, match=pattern) as info:
        rpr3gen.retime(rrr, **given)
    assert isinstance(info.value, Rpr3genError)
    assert "\n" not in str(info.value)


def test_a_path_file_names_its_line(rrr: rpr3gen.Model, tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text(f"t,phi,x,y\n0,0,0,0\n\n1,0.3,0,0\n2,{SINGULAR_PHI},0,0\n")
    with pytest.raises(TrajectoryError, match=r"p\.csv: line 5 \(waypoint 3\): the path reaches"):
        rpr3gen.retime(rrr, str(path), 20.0)
    path.write_text("x,y\n0,0\n1,0\n")
    with pytest.raises(TrajectoryError, match=r"line 1 \(header\): missing column 'phi'"):
        rpr3gen.retime(rrr, path, 20.0)


def test_without_toppra_the_error_names_the_extra(
    rrr: rpr3gen.Model,
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setitem(sys.modules, "toppra", None)  # import toppra: ModuleNotFoundError
    monkeypatch.delitem(sys.modules, "rpr3gen.retiming.topp", raising=False)
    with pytest.raises(SetupError, match=r"pip install 'rpr3gen\[toppra\]'") as info:
        rpr3gen.retime(rrr, [[0.0, 0.0, 0.0], [0.01, 0.0, 0.1]], 20.0)
    assert isinstance(info.value, OSError)  # the environment's, as a missing C compiler
    assert "\n" not in str(info.value)
    out = tmp_path / "t.csv"
    argv = ["retime", "--model", str(MODELS / "rrr.toml"), "--path", str(LOOP_PATH)]
    assert main([*argv, "--effort-limit", "8", "--out", str(out)]) == 2
    printed, err = capsys.readouterr()
    assert printed == ""
    assert err.count("\n") == 1
    assert "install the extra 'toppra'" in err
    assert not out.exists()


# -- the command ----------------------------------------------------------------------------


def test_the_command_writes_a_trajectory_that_simulate_reads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The issue's "done when": ``rpr3gen retime --model models/rrr.toml --path ...``."""
    out = tmp_path / "fast.csv"
    model = ["--model", str(MODELS / "rrr.toml")]
    argv = ["retime", *model, "--path", str(LOOP_PATH), "--effort-limit", "8", "--out", str(out)]
    assert main(argv) == 0
    printed, err = capsys.readouterr()
    assert err == ""
    assert printed.startswith(f"wrote {out}: ")
    assert "peak |effort| / limit: leg A 1.0000, leg B 1.0000, leg C 1.0000" in printed
    traj = rpr3gen.read_trajectory_csv(out)  # no warning: derivatives agree with positions
    assert np.array_equal(traj.t, case("rrr").traj.t)
    assert (
        main(["simulate", *model, "--trajectory", str(out), "--out", str(tmp_path / "s.csv")]) == 0
    )
    assert capsys.readouterr().err == ""


def test_the_command_refuses_in_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "p.csv"
    path.write_text(f"x,y,phi\n0,0,0\n0,0,{SINGULAR_PHI}\n")
    out = tmp_path / "out.csv"
    out.write_text("earlier\n")
    model = ["--model", str(MODELS / "rrr.toml")]
    for argv, named in [
        (["--path", str(path), "--effort-limit", "20"], f"{path}: line 3 (waypoint 2)"),
        (["--path", str(LOOP_PATH), "--effort-limit", "1", "20", "20"], "--effort-limit: 1 N m"),
        (["--path", str(LOOP_PATH), "--effort-limit", "8", "8"], "--effort-limit: give one"),
        (["--path", str(LOOP_PATH), "--effort-limit", "0"], "--effort-limit: must be"),
    ]:
        assert main(["retime", *model, *argv, "--out", str(out)]) == 2
        printed, err = capsys.readouterr()
        assert printed == ""
        assert err.count("\n") == 1, err
        assert named in err, err
    assert out.read_text() == "earlier\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "p.csv"]
