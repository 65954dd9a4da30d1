"""`rpr3gen animate`: frames, size, the drawing against the pose, bounds, atomic writing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import rpr3gen
from rpr3gen import animation
from rpr3gen.cli import main
from rpr3gen.errors import InputError, TrajectoryError

ROOT = Path(__file__).resolve().parent.parent
SIZE = (480, 320)
FPS = 2  # 7 frames over the paper's 3 s


def _robot(name: str) -> tuple[rpr3gen.Model, rpr3gen.Trajectory]:
    """The paper's robot on its rotation, the gallery's 3-RRR on the rectilinear motion."""
    if name == "paper":
        return rpr3gen.load_model(), rpr3gen.paper_trajectory("rotation", samples=61)
    model = rpr3gen.load_model(ROOT / "models" / "rrr.toml")
    return model, rpr3gen.paper_trajectory("rectilinear", samples=61)


def _platform_points(model: rpr3gen.Model, q: np.ndarray) -> np.ndarray:
    """The platform joints at pose q, from the model's numbers alone: G + R(phi) p (3, 2)."""
    p = model.params
    if model.structure.paper:
        local = np.array([[p[f"x{leg}3"], p[f"y{leg}3"]] for leg in "ABC"])
    else:  # the general format gives joint 3 at home, where the platform frame is the world's
        local = np.array([[p[f"x3_{leg}"], p[f"y3_{leg}"]] for leg in "ABC"])
    c, s = np.cos(q[2]), np.sin(q[2])
    return q[:2] + local @ np.array([[c, s], [-s, c]])


def test_plan_places_frames_in_time() -> None:
    t = np.linspace(0.0, 3.0, 301)
    plan = animation.plan(t, "m.gif")
    assert plan.frames == 61  # 3 s at 20 frames/s, both ends
    np.testing.assert_array_equal(plan.samples, np.arange(0, 301, 5))
    fast = animation.plan(t, "m.gif", fps=10, speed=2.0)
    np.testing.assert_array_equal(fast.samples, np.arange(0, 301, 20))
    coarse = animation.plan(np.array([0.0, 1.0, 2.0]), "m.gif", fps=2)
    np.testing.assert_array_equal(coarse.samples, [0, 0, 1, 1, 2])  # nearest, ties to earlier
    single = animation.plan(np.array([0.5]), "m.gif")
    np.testing.assert_array_equal(single.samples, [0])  # one pose: one frame


@pytest.mark.parametrize(
    ("request_", "words"),
    [
        ({"out": "m.avi"}, "suffix"),
        ({"size": (100, 300)}, "width"),
        ({"size": (800, 5000)}, "height"),
        ({"fps": 0}, "fps"),
        ({"fps": 10_000}, "fps"),
        ({"fps": 12.5}, "fps"),
        ({"speed": -1.0}, "speed"),
        ({"t": np.linspace(0.0, 600.0, 11)}, "frames"),
        ({"t": np.linspace(0.0, 49.0, 11), "size": (1920, 1080)}, "pixels"),
    ],
)
def test_refuses_absurd_requests_up_front(request_: dict, words: str) -> None:
    args = {"t": np.linspace(0.0, 3.0, 31), "out": "m.gif", **request_}
    t, out = args.pop("t"), args.pop("out")
    with pytest.raises(InputError, match=words) as info:
        animation.plan(t, out, **args)
    assert "\n" not in str(info.value)


def test_mp4_needs_ffmpeg(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(animation.frames, "ffmpeg_path", lambda: None)
    with pytest.raises(InputError, match="ffmpeg"):
        animation.plan(np.linspace(0.0, 1.0, 3), "robot.mp4")


def test_cli_refuses_before_any_work(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "robot.gif"
    status = main(["animate", "--out", str(out), "--size", "99999x10"])
    err = capsys.readouterr().err
    assert status == 2
    assert err.startswith("rpr3gen: error: size:")
    assert err.count("\n") == 1
    assert not out.exists()
    assert main(["animate", "--out", str(out), "--fps", "2000"]) == 2
    assert "fps" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["paper", "rrr"])
def test_gif_frames_size_and_a_frame_against_the_pose(name: str, tmp_path: Path) -> None:
    model, traj = _robot(name)
    out = tmp_path / "robot.gif"
    plan = animation.write_animation(model, traj, out, fps=FPS, size=SIZE)
    assert plan.frames == 7
    with Image.open(out) as gif:
        assert gif.n_frames == plan.frames
        assert gif.size == SIZE
        assert gif.info["duration"] == 500  # ms per frame at 2 frames/s
        k = 4  # a frame where the platform has moved
        gif.seek(k)
        frame = np.asarray(gif.convert("RGB"))

    # the drawing posed at that frame's sample: its platform is the pose's, by the model's numbers
    sample = int(plan.samples[k])
    drawing = animation.Drawing(animation.scene(model, traj), SIZE, plan.samples)
    drawing.show(sample)
    vertices = drawing.platform.get_xy()[:3]
    np.testing.assert_allclose(vertices, _platform_points(model, traj.q[sample]), atol=1e-12)
    (points,), _ = rpr3gen.evaluate(model, "joint_points", (traj.q[sample],))
    np.testing.assert_allclose(vertices, points.reshape(3, 3, 2)[:, 2], atol=1e-15)

    # and the GIF shows it there: inside the triangle is the platform's grey
    robot = drawing.axes["robot"]
    drawing.figure.canvas.draw()
    probe = (vertices.mean(axis=0) + vertices[0] + vertices[1]) / 3  # centroid of G, v1, v2
    px, py = robot.transData.transform(probe)
    colour = frame[SIZE[1] - round(py), round(px)].astype(int)
    assert np.all(np.abs(colour - 0xD9) <= 6), colour


@pytest.mark.parametrize("name", ["paper", "rrr"])
def test_joint_forces_and_slides(name: str) -> None:
    """The forces drawn at the platform joints hold the platform (Newton), both formats; the
    paper's slide is along its leg."""
    model, traj = _robot(name)
    scn = animation.scene(model, traj, loads=True)
    assert scn.forces is not None
    p = model.params
    mass = p["m3"]
    gravity = np.array([p["gx"], p["gy"]])
    on_platform = scn.forces[:, :, 2].sum(axis=1)
    np.testing.assert_allclose(on_platform, mass * (traj.qdd[:, :2] - gravity), atol=1e-9)
    if model.structure.paper:
        axis = scn.points[:, 0, 2] - scn.points[:, 0, 0]
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        np.testing.assert_allclose(scn.slides[("A", 2)], axis, atol=1e-12)


def test_write_is_atomic(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model, traj = _robot("paper")
    out = tmp_path / "robot.gif"
    out.write_bytes(b"the previous movie")
    shown = []

    def fail_on_the_third(self: animation.Drawing, sample: int) -> None:
        shown.append(sample)
        if len(shown) == 3:
            raise RuntimeError("interrupted")

    monkeypatch.setattr(animation.Drawing, "show", fail_on_the_third)
    with pytest.raises(RuntimeError, match="interrupted"):
        animation.write_animation(model, traj, out, fps=FPS, size=SIZE)
    assert out.read_bytes() == b"the previous movie"
    assert [p.name for p in tmp_path.iterdir()] == ["robot.gif"]  # no temporary file left
    shown.clear()
    fresh = tmp_path / "sub" / "new.gif"
    with pytest.raises(RuntimeError):
        animation.write_animation(model, traj, fresh, fps=FPS, size=SIZE)
    assert list(fresh.parent.iterdir()) == []


def test_refuses_a_singular_pose(tmp_path: Path) -> None:
    model = rpr3gen.load_model(ROOT / "models" / "rrr.toml")
    traj = rpr3gen.paper_trajectory("rotation")  # through a parallel singularity at 1.49 s
    with pytest.raises(TrajectoryError, match="conditioning"):
        animation.write_animation(model, traj, tmp_path / "x.gif", fps=FPS, size=SIZE)
    assert list(tmp_path.iterdir()) == []


def test_cli_writes_the_movie(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "rrr.gif"
    args = ["--model", str(ROOT / "models" / "rrr.toml"), "--trajectory", "rectilinear"]
    args += ["--out", str(out), "--fps", "1", "--size", "320x240", "--loads"]
    assert main(["animate", *args]) == 0
    assert "4 frames of 320 x 240" in capsys.readouterr().out
    with Image.open(out) as gif:
        assert (gif.n_frames, gif.size) == (4, (320, 240))


def test_mp4_through_ffmpeg(tmp_path: Path) -> None:
    model, traj = _robot("rrr")
    out = tmp_path / "rrr.mp4"
    plan = animation.write_animation(model, traj, out, fps=FPS, size=(320, 240))
    assert plan.frames == 7
    assert out.read_bytes()[4:8] == b"ftyp"  # an MP4 container
    assert [p.name for p in tmp_path.iterdir()] == ["rrr.mp4"]


def test_mp4_without_a_system_ffmpeg_uses_the_video_extras(tmp_path: Path) -> None:
    """With matplotlib's ffmpeg missing, imageio-ffmpeg's build writes the movie, and the
    user's ``rcParams`` stay as they were."""
    import imageio_ffmpeg
    import matplotlib as mpl

    model, traj = _robot("rrr")
    out = tmp_path / "rrr.mp4"
    with mpl.rc_context({"animation.ffmpeg_path": str(tmp_path / "no-such-ffmpeg")}):
        assert animation.frames.ffmpeg_path() == imageio_ffmpeg.get_ffmpeg_exe()
        animation.write_animation(model, traj, out, fps=FPS, size=(320, 240))
        assert mpl.rcParams["animation.ffmpeg_path"] == str(tmp_path / "no-such-ffmpeg")
    assert out.read_bytes()[4:8] == b"ftyp"
