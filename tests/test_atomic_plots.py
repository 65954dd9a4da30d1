"""Atomic output files, the results CSV, and the paper's figures as PNG."""

from __future__ import annotations

import errno
import os
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
import rpr3gen.plots
from rpr3gen.atomic import atomic_write, write_csv_table, write_results_csv
from rpr3gen.plots import (
    DPI,
    FIGSIZE,
    coinciding_legs,
    family_figure,
    plot_families,
    plotted_families,
)
from rpr3gen.trajectory import paper_trajectory

OLD = b"old contents\x00\xff\n"


class BoomError(Exception):
    pass


def write_then_fail(path: Path, error: type[BaseException], mode: str = "wb") -> None:
    """Write part of a file through atomic_write, then raise ``error`` inside the block."""
    with atomic_write(path, mode) as f:
        f.write(b"new, half written" if "b" in mode else "new, half written")
        f.flush()
        raise error()


def leftovers(folder: Path, keep: set[str]) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name not in keep)


# -- atomic_write ------------------------------------------------------------------------------


def test_atomic_write_creates_and_replaces(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    with atomic_write(path) as f:
        f.write("first ü\n")
    assert path.read_bytes() == "first ü\n".encode()
    with atomic_write(str(path), "wb") as f:
        f.write(b"second")
    assert path.read_bytes() == b"second"
    assert leftovers(tmp_path, {"out.txt"}) == []


def test_target_does_not_exist_until_success(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    with atomic_write(path) as f:
        f.write("partial")
        f.flush()
        assert not path.exists()
    assert path.read_text(encoding="utf-8") == "partial"


@pytest.mark.parametrize("error", [BoomError, KeyboardInterrupt, SystemExit])
def test_failure_leaves_existing_file_unchanged(tmp_path: Path, error: type[BaseException]) -> None:
    path = tmp_path / "out.bin"
    path.write_bytes(OLD)
    with pytest.raises(error):
        write_then_fail(path, error)
    assert path.read_bytes() == OLD
    assert leftovers(tmp_path, {"out.bin"}) == []


def test_the_package_s_os_error_in_the_block_is_kept(tmp_path: Path) -> None:
    """A SetupError (an OSError with no file: no C compiler...) raised while the file is written
    reaches the caller as it is, not reworded as a failure to write the file."""
    path = tmp_path / "out.bin"
    with pytest.raises(rpr3gen.SetupError) as info, atomic_write(path, "wb"):
        raise rpr3gen.SetupError("the c backend needs a C compiler")
    assert str(info.value) == "the c backend needs a C compiler"
    assert list(tmp_path.iterdir()) == []


def test_failure_creates_no_file(tmp_path: Path) -> None:
    path = tmp_path / "new.txt"
    with pytest.raises(BoomError):
        write_then_fail(path, BoomError, "w")
    assert list(tmp_path.iterdir()) == []


def test_permissions(tmp_path: Path) -> None:
    path = tmp_path / "p.txt"
    path.write_text("x", encoding="utf-8")
    path.chmod(0o640)
    with atomic_write(path) as f:
        f.write("y")
    assert path.stat().st_mode & 0o777 == 0o640
    fresh = tmp_path / "fresh.txt"
    with atomic_write(fresh) as f:
        f.write("z")
    umask = os.umask(0o022)
    os.umask(umask)
    assert fresh.stat().st_mode & 0o777 == 0o666 & ~umask


def test_bad_mode_and_bad_encoding(tmp_path: Path) -> None:
    for mode in ("r", "a", "w+", "x"):
        with pytest.raises(ValueError, match="mode"), atomic_write(tmp_path / "m.txt", mode):
            pass
    with pytest.raises(LookupError), atomic_write(tmp_path / "e.txt", encoding="no-such-codec"):
        pass
    assert list(tmp_path.iterdir()) == []


def test_missing_folder_raises_oserror(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError), atomic_write(tmp_path / "no" / "such.txt") as f:
        f.write("x")


def test_errors_name_the_file_asked_for_never_the_temporary_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A folder in the target's place: the rename fails.
    folder = tmp_path / "taken"
    folder.mkdir()
    with pytest.raises(IsADirectoryError) as info, atomic_write(folder) as f:
        f.write("x")
    assert info.value.filename == str(folder)
    assert ".tmp" not in str(info.value)
    # The disk fills up while writing (such errors carry no file name).
    target = tmp_path / "full.csv"
    with pytest.raises(OSError, match="No space left") as info, atomic_write(target) as f:
        raise OSError(errno.ENOSPC, "No space left on device")
    assert info.value.errno == errno.ENOSPC
    assert info.value.filename == str(target)

    # The temporary file cannot be created (e.g. /proc, a read-only folder).
    def refuse(*, prefix: str, suffix: str, dir: str) -> tuple[int, str]:
        raise PermissionError(errno.EACCES, "Permission denied", f"{dir}/{prefix}abc{suffix}")

    monkeypatch.setattr("tempfile.mkstemp", refuse)
    with pytest.raises(PermissionError) as info, atomic_write("some/file.csv"):
        pass
    assert info.value.filename == "some/file.csv"
    assert ".tmp" not in str(info.value)
    assert leftovers(tmp_path, {"taken"}) == []


# -- results CSV -------------------------------------------------------------------------------


def test_results_csv_columns_and_exact_values(tmp_path: Path) -> None:
    t = np.array([0.0, 0.1, 0.2])
    q = np.array([[0.1, 0.2, 1 / 3], [1e-300, -2.5e300, 0.0], [np.pi, -np.e, 7.0]])
    outputs = {
        "m10_A": np.array([1 / 7, np.nan, -0.0]),
        "f32z_C": np.array([1.0, 2.0, 3.0]),
        "unused": np.zeros(3),
        "const": np.float64(4.25),
    }
    path = tmp_path / "res.csv"
    write_results_csv(path, t, q, outputs, ["f32z_C", "m10_A", "const"])
    lines = path.read_text(encoding="utf-8").splitlines()
    assert lines[0] == "t,x,y,phi,f32z_C,m10_A,const"
    assert len(lines) == 4
    back = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    expected = np.column_stack([t, q, outputs["f32z_C"], outputs["m10_A"], np.full(3, 4.25)])
    assert np.array_equal(back, expected, equal_nan=True)
    assert lines[1].split(",")[5] == f"{1 / 7:.17g}"


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"names": ["nope"]}, "nope"),
        ({"names": ["a", "a"]}, "repeat"),
        ({"outputs": {"a": np.zeros(4)}}, "'a'"),
        ({"q": np.zeros((3, 2))}, "q must"),
        ({"t": np.zeros((3, 1))}, "t must"),
    ],
)
def test_results_csv_rejects_bad_input_and_keeps_old_file(
    tmp_path: Path, kwargs: dict[str, object], needle: str
) -> None:
    path = tmp_path / "res.csv"
    path.write_bytes(OLD)
    args: dict[str, object] = {
        "t": np.zeros(3),
        "q": np.zeros((3, 3)),
        "outputs": {"a": np.zeros(3)},
        "names": ["a"],
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=needle):
        write_results_csv(path, **args)  # type: ignore[arg-type]
    assert path.read_bytes() == OLD
    assert leftovers(tmp_path, {"res.csv"}) == []


def test_csv_table_shape_is_checked(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="shape"):
        write_csv_table(tmp_path / "x.csv", ["a", "b"], np.zeros((2, 3)))
    write_csv_table(tmp_path / "x.csv", ["a", "b"], np.zeros((0, 2)))
    assert (tmp_path / "x.csv").read_text(encoding="utf-8") == "a,b\n"


# -- plots -------------------------------------------------------------------------------------


def fake_outputs(t: np.ndarray, actuation: str) -> dict[str, np.ndarray]:
    return {
        f"{spec.family}_{leg}": np.sin((k + 1) * t + i)
        for k, spec in enumerate(plotted_families(actuation))
        for i, leg in enumerate("ABC")
    }


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


REVOLUTE = ["f10x", "f10y", "f21y", "m21", "f32y", "f32z", "m10", "phi10", "lambda21"]
PRISMATIC = ["f10x", "f10y", "f21y", "m21", "f32y", "f32z", "f21z", "phi10", "lambda21"]


@pytest.mark.parametrize(
    ("actuation", "families"), [("revolute", REVOLUTE), ("prismatic", PRISMATIC)]
)
def test_plots_written(tmp_path: Path, actuation: str, families: list[str]) -> None:
    t = paper_trajectory("rotation", samples=31).t
    outdir = tmp_path / "figs" / "nested"
    paths = plot_families(
        t, fake_outputs(t, actuation), outdir, prefix="rot", title="rotation", actuation=actuation
    )
    assert paths == [outdir / f"rot_{family}.png" for family in families]
    assert sorted(p.name for p in outdir.iterdir()) == sorted(p.name for p in paths)
    width, height = round(FIGSIZE[0] * DPI), round(FIGSIZE[1] * DPI)
    for path in paths:
        assert png_size(path) == (width, height)
        data = path.read_bytes()
        assert b"Software" not in data
        assert b"atplotlib" not in data


def test_plots_are_reproducible(tmp_path: Path) -> None:
    t = np.linspace(0.0, 3.0, 31)
    outputs = fake_outputs(t, "revolute")
    first = plot_families(t, outputs, tmp_path / "a", prefix="p", title="x", actuation="revolute")
    second = plot_families(t, outputs, tmp_path / "b", prefix="p", title="x", actuation="revolute")
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes()
    # Different data give a different picture.
    outputs["f10x_A"] = outputs["f10x_A"] + 1.0
    third = plot_families(t, outputs, tmp_path / "c", prefix="p", title="x", actuation="revolute")
    assert third[0].read_bytes() != first[0].read_bytes()


def test_titles_and_labels() -> None:
    revolute = plotted_families("revolute")
    assert revolute[0].title("rotation") == "Joint forces f10x (paper fig. 3) — rotation"
    assert revolute[3].title("rectilinear (paper)") == (
        "Joint torques m21 (paper fig. 12) — rectilinear (paper)"
    )
    assert revolute[5].title("motion") == "Joint forces f32z (cf. paper figs 8, 14) — motion"
    assert [(s.family, s.unit) for s in revolute[6:]] == [
        ("m10", "N·m"),
        ("phi10", "rad"),
        ("lambda21", "m"),
    ]
    assert plotted_families("prismatic")[6].unit == "N"


def test_plot_errors_write_nothing(tmp_path: Path) -> None:
    t = np.linspace(0.0, 1.0, 5)
    outputs = fake_outputs(t, "revolute")
    with pytest.raises(ValueError, match="actuation"):
        plot_families(t, outputs, tmp_path / "o", prefix="p", title="", actuation="hydraulic")
    with pytest.raises(ValueError, match="f21z_A"):
        plot_families(t, outputs, tmp_path / "o", prefix="p", title="", actuation="prismatic")
    outputs["m21_B"] = np.zeros(4)
    with pytest.raises(ValueError, match="m21_B"):
        plot_families(t, outputs, tmp_path / "o", prefix="p", title="", actuation="revolute")
    assert not (tmp_path / "o").exists()


def test_plotting_does_not_use_pyplot(tmp_path: Path) -> None:
    src = str(Path(rpr3gen.plots.__file__).resolve().parents[1])
    code = (
        "import sys, numpy as np\n"
        "from rpr3gen.plots import plot_families, plotted_families\n"
        "t = np.linspace(0, 1, 5)\n"
        "out = {f'{s.family}_{l}': t for s in plotted_families('revolute') for l in 'ABC'}\n"
        f"plot_families(t, out, {str(tmp_path)!r}, prefix='p', title='', actuation='revolute')\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
    )
    env = {**os.environ, "PYTHONPATH": src}
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert len(list(tmp_path.glob("p_*.png"))) == 9


def test_coinciding_legs() -> None:
    t = np.linspace(0.0, 1.0, 11)
    a, b = np.sin(t), np.cos(t)
    assert coinciding_legs([a, b, t]) == ()
    assert coinciding_legs([a, b, a * (1 + 1e-12)]) == (("A", "C"),)
    assert coinciding_legs([a, a, a]) == (("A", "B", "C"),)
    assert coinciding_legs([0 * t, 0 * t, 0 * t]) == (("A", "B", "C"),)
    nan_a = np.where(t > 0.5, np.nan, a)
    assert coinciding_legs([nan_a, b, nan_a]) == (("A", "C"),)
    assert coinciding_legs([a, a + 1e-6, b]) == ()


def test_rotation_figures_keep_coinciding_legs_visible() -> None:
    # In the paper's rotation the three legs move alike: phi10 and lambda21 coincide.
    model = rpr3gen.load_model()
    traj = paper_trajectory("rotation")
    out = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
    for spec in plotted_families("revolute"):
        legs = [out[f"{spec.family}_{leg}"] for leg in "ABC"]
        fig = family_figure(traj.t, legs, spec, "rotation (paper)")
        (ax,) = fig.axes
        title = ax.get_title()
        if spec.family in ("phi10", "lambda21"):
            assert title.endswith("\n(legs A, B and C coincide)"), title
        else:
            assert "coincide" not in title, title
        lines = ax.get_lines()
        assert [line.get_label() for line in lines] == ["leg A", "leg B", "leg C"]
        assert len({line.get_linestyle() for line in lines}) == 3
        assert len({line.get_marker() for line in lines}) == 3
        widths = [line.get_linewidth() for line in lines]
        assert widths == sorted(widths, reverse=True)  # the later drawn, the narrower
        assert all(line.get_markerfacecolor() == "none" for line in lines)  # hollow
        starts_steps = [line.get_markevery() for line in lines]
        marked = [set(range(start, len(traj.t), step)) for start, step in starts_steps]
        assert len(set.union(*marked)) == sum(len(m) for m in marked)  # no two at one sample
