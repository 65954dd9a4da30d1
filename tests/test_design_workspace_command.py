"""`rpr3gen workspace` end to end: the Parquet grid, the four figures, and its errors."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.colors
import numpy as np
import pyarrow.parquet as pq
import pytest

import rpr3gen
from rpr3gen.cli import main

FIGURES = ["conditioning.png", "orientation_range.png", "peak_effort.png", "reachable.png"]


def test_writes_the_grid_and_four_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ws"
    assert main(["workspace", "--phi", "10", "--resolution", "24", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted([*FIGURES, "workspace.parquet"])
    table = pq.read_table(out / "workspace.parquet")
    assert table.column_names == [
        "x", "y", "phi", "reachable", "conditioning",
        "tau_A", "tau_B", "tau_C", "phi_min", "phi_max",
    ]  # fmt: skip
    assert table.num_rows == 24 * 24
    expected = rpr3gen.workspace(rpr3gen.load_model(), math.radians(10), 24).columns()
    for name, values in expected.items():
        np.testing.assert_array_equal(table.column(name).to_numpy(), values, err_msg=name)
    stdout = capsys.readouterr().out
    assert stdout.startswith("workspace of paper at phi = 10 deg: 24 x 24 points")
    assert f"wrote {out / 'workspace.parquet'} and 4 figures in {out}" in stdout
    for name in FIGURES:
        assert (out / name).read_bytes().startswith(b"\x89PNG")
    first = {name: (out / name).read_bytes() for name in [*FIGURES, "workspace.parquet"]}
    assert main(["workspace", "--phi", "10", "--resolution", "24", "--out", str(out)]) == 0
    assert {name: (out / name).read_bytes() for name in first} == first  # same bytes again


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--resolution", "1"], "--resolution: must be an integer >= 2, got 1"),
        (["--phi", "nan"], "--phi: must be a finite number (deg)"),
        (["--model", "nope.toml"], "nope.toml: model file not found"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(
    tmp_path: Path, args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ws"
    assert main(["workspace", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert message in err
    assert not out.exists()


def test_a_file_in_the_way_of_the_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "ws"
    blocker.write_text("not a folder")
    assert main(["workspace", "--resolution", "8", "--out", str(blocker)]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err
    assert blocker.read_text() == "not a folder"


def test_the_peak_effort_scale_ends_at_the_95th_percentile() -> None:
    """Points just above the conditioning floor would take the whole colour scale: it ends at
    the 95th percentile of the reachable points' efforts, and the figure says what is above."""
    from rpr3gen.design import figures

    wmap = rpr3gen.workspace(rpr3gen.load_model(), 0.0, 60)
    peak = np.max(np.abs(wmap.tau), axis=2)
    efforts = peak[np.isfinite(peak)]
    top = np.percentile(efforts, 95)
    assert efforts.max() > 10 * top  # the paper robot's map needs it
    fig = figures.effort_figure(wmap)
    (image,) = fig.axes[0].get_images()
    assert image.norm.vmin == efforts.min()
    assert image.norm.vmax == pytest.approx(top, rel=1e-12)
    assert image.cmap.get_over() == pytest.approx(matplotlib.colors.to_rgba(figures.OVER_COLOR))
    assert fig.axes[1].get_ylabel().endswith("(log scale, to the 95th percentile)")
    (legend,) = fig.legends
    share = np.count_nonzero(efforts > top) / efforts.size
    label = f"above the scale: {top:,.0f} to {efforts.max():,.0f} N·m ({share:.1%} of the points)"
    assert label in [t.get_text() for t in legend.get_texts()]


def test_a_map_without_a_long_tail_keeps_its_whole_scale(repo_root: Path) -> None:
    """The 3-RRR of the gallery has no parallel singularity at phi = 0: its largest effort is
    about twice the 95th percentile, and the scale spans every point, nothing drawn over."""
    from rpr3gen.design import figures

    wmap = rpr3gen.workspace(rpr3gen.load_model(repo_root / "models" / "rrr.toml"), 0.0, 40)
    peak = np.max(np.abs(wmap.tau), axis=2)
    efforts = peak[np.isfinite(peak) & (peak > 0)]
    assert efforts.max() < figures.CLIP_RATIO * np.percentile(efforts, 95)
    fig = figures.effort_figure(wmap)
    (image,) = fig.axes[0].get_images()
    assert (image.norm.vmin, image.norm.vmax) == (efforts.min(), efforts.max())
    assert fig.axes[1].get_ylabel().endswith("(log scale)")
    (legend,) = fig.legends
    assert not any("above the scale" in t.get_text() for t in legend.get_texts())
