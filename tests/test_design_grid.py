"""Grids of designs: what a grid file enumerates, and every way it can be wrong.

A wrong grid is one line naming the file and the key, before any work: the command exits with
status 2, writes no output file and no parts folder, and shows no traceback.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from rpr3gen.cli import main
from rpr3gen.design.grid import read_grid
from rpr3gen.errors import GridError
from rpr3gen.model import model_from_dict, read_model_data

SOURCE, BASE = read_model_data()  # the paper's robot, as parsed TOML


def _grid_file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "grid.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_designs_in_grid_order_last_key_fastest() -> None:
    grid = read_grid(
        {"geometry.r": [0.25, 0.3, 0.35], "mass.m3": {"start": 2.0, "stop": 8.0, "num": 4}}, BASE
    )
    assert grid.keys == ("geometry.r", "mass.m3")
    assert grid.values[1] == (2.0, 4.0, 6.0, 8.0)  # both ends included
    assert len(grid) == 12
    expected = list(itertools.product(*grid.values))
    assert [grid.design(i) for i in range(12)] == expected
    columns = grid.columns(5, 9)
    np.testing.assert_array_equal(columns["geometry.r"], [e[0] for e in expected[5:9]])
    np.testing.assert_array_equal(columns["mass.m3"], [e[1] for e in expected[5:9]])


def test_tables_indexed_elements_and_text_keys(tmp_path: Path) -> None:
    text = (
        '"geometry.alpha_deg[0]" = [80, 90.0]\n'
        'actuation = ["revolute", "prismatic"]\n'
        "[payload]\n"
        "force = { start = -5.0, stop = 5.0, num = 3 }\n"
    )
    with pytest.raises(GridError, match=r"payload\.force holds a list"):
        read_grid(_grid_file(tmp_path, text), BASE)
    grid = read_grid(_grid_file(tmp_path, text.replace("force =", '"force[1]" =')), BASE)
    assert grid.keys == ("geometry.alpha_deg[0]", "actuation", "payload.force[1]")
    assert grid.values[0] == (80.0, 90.0)
    assert isinstance(grid.values[0][0], float)
    last = grid.apply(BASE, grid.design(len(grid) - 1))
    assert last["geometry"]["alpha_deg"] == [90.0, -150.0, -30.0]
    assert last["actuation"] == "prismatic"
    assert last["payload"]["force"] == [0.0, 5.0]
    assert BASE["payload"]["force"] == [0.0, 0.0]  # the base is not changed
    assert model_from_dict(last).actuation == "prismatic"
    assert grid.columns(0, 6)["actuation"].tolist() == ["revolute"] * 3 + ["prismatic"] * 3


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('"geometry.radius" = [0.2]', "radius: unknown model key; did you mean 'geometry.r'"),
        ("[mas]\nm3 = [2.0]", "mas.m3: unknown model key; did you mean 'mass.m3'?"),
        (
            '"mass.m3" = { start = 2.0, stop = 8.0, nm = 4 }',
            "mass.m3: unknown range key 'nm'; did you mean 'num'?",
        ),
        ('"mass.m3" = { start = 2.0, stop = 8.0 }', "needs start, stop and num; missing num"),
        ('"mass.m3" = { start = 2, stop = 8, num = 0 }', "num: must be an integer >= 1, got 0"),
        ('"mass.m3" = { start = 2, stop = "8", num = 2 }', 'stop: must be a number, got "8"'),
        ('"mass.m3" = 5.0', "mass.m3: must be a list of values or a range"),
        ('"mass.m3" = []', "mass.m3: an empty list; give at least one value"),
        ('"mass.m3" = [2.0, "heavy"]', 'mass.m3[1]: must be a number, got "heavy"'),
        ('"mass.m3" = [2.0, true]', "mass.m3[1]: must be a number, got true"),
        ('"mass.m3" = [2.0, nan]', "mass.m3[1]: must be a finite number, got nan"),
        (f'"mass.m3" = [2.0, 1{"0" * 400}]', "mass.m3[1]: must be a finite number, got 10000"),
        (f'"mass.m3" = {{ start = -1{"0" * 400}, stop = 8, num = 2 }}',
         "mass.m3.start: must be a finite number, got -10000"),
        ('"mass.m3" = [2.0, -1.0]', "mass.m3 = -1.0: mass.m3: must be a positive number, got -1.0"),
        ('"geometry.alpha_deg" = [90.0]', 'vary one element, e.g. "geometry.alpha_deg[0]"'),
        ('"geometry.alpha_deg[3]" = [90.0]', "alpha_deg[3]: index 3 out of range (0 to 2)"),
        ('"mass.m3[0]" = [1.0]', "mass.m3[0]: mass.m3 holds one value, not a list"),
        ('name = ["a"]', "name: not a design parameter"),
        ('"limits.stroke[0][1]" = [0.2]', "the base model has no limits.stroke to vary"),
        ('"geometry.base[0][0]" = [0.2]', "the base model has no geometry.base to vary"),
        ("actuation = { start = 1, stop = 2, num = 2 }", "actuation: a range needs numbers"),
        ('actuation = ["revolute", "prismatc"]', "did you mean 'prismatic'?"),
        ('"mass.m3" = [2.0]\n[mass]\nm3 = [3.0]', "mass.m3: given twice"),
        ("[mass]", "mass: an empty table"),
        ('"mass.m3" = [2.0', "invalid TOML"),
        ("", "no keys; set model keys to values"),
    ],
)  # fmt: skip
def test_bad_grid_is_one_line_naming_the_key(tmp_path: Path, text: str, message: str) -> None:
    path = _grid_file(tmp_path, text)
    with pytest.raises(GridError) as caught:
        read_grid(path, BASE)
    assert str(caught.value).startswith(f"{path}: ")
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_missing_grid_file(tmp_path: Path) -> None:
    with pytest.raises(GridError, match="grid file not found"):
        read_grid(tmp_path / "nope.toml", BASE)


@pytest.mark.parametrize(
    "text",
    ['"geometry.radius" = [0.2, 0.3]', '"mass.m3" = [2.0, 0.0]', '"mass.m3" = { start = 1 }'],
)
def test_the_command_stops_before_any_work(
    tmp_path: Path, text: str, capsys: pytest.CaptureFixture[str]
) -> None:
    grid = _grid_file(tmp_path, text)
    out = tmp_path / "results" / "sweep.parquet"
    status = main(["sweep", "--grid", str(grid), "--out", str(out), "--workers", "0"])
    captured = capsys.readouterr()
    assert status == 2
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f"rpr3gen: error: {grid}: ")
    assert "Traceback" not in captured.err
    assert not out.exists()
    assert not (tmp_path / "results").exists()
    assert not Path(f"{out}.parts").exists()
