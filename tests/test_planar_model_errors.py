"""Errors of the general model format: one clear line each, naming the file and the key.

Each case is a valid model file (a symmetric 3-RRR, or the paper's robot as a 3-RPR) with one
thing wrong: an unknown key (with a "did you mean"), a prismatic joint with a zero axis, a leg in
a serial singularity at home, the three architecturally singular structures, three legs that do
not hold the platform at home (a parallel singularity), ``symmetric = true`` with legs B or C
given, bad ``[limits]`` keys and bounds. ``load_model`` raises one ``ModelError`` whose message
is one line, starts with the file's path and names the dotted key; ``rpr3gen params`` exits with
status 2 and that line on stderr, nothing on stdout.
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path
from typing import Any

import pytest

import rpr3gen
from rpr3gen.cli import main

RRR: dict[str, Any] = {
    "name": "rrr",
    "leg": "RRR",
    "actuated": 1,
    "symmetric": True,
    "legs": {
        "A": {
            "joints": [[0.0, -0.5], [0.17854, -0.325], [0.0, -0.15]],
            "mass": [1.0, 1.0],
            "com": [[0.08927, -0.4125], [0.08927, -0.2375]],
            "inertia": [0.0052083, 0.0052083],
        }
    },
    "platform": {"mass": 2.0, "com": [0.0, 0.0], "inertia": 0.0225},
    "environment": {"gravity": [0.0, -9.81]},
}
_S3 = math.sqrt(3) / 2
RPR: dict[str, Any] = {
    "name": "rpr",
    "leg": "RPR",
    "actuated": 1,
    "symmetric": True,
    "legs": {
        "A": {
            "joints": [[0.3 * _S3, -0.15], [0.3 * _S3, -0.05], [0.3 * _S3, 0.15]],
            "axes": [[0.0, 0.0], [0.0, 1.0], [0.0, 0.0]],
            "mass": [3.0, 1.5],
            "com": [[0.3 * _S3, -0.05], [0.3 * _S3, 0.05]],
            "inertia": [0.01, 0.005],
        }
    },
    "platform": {"mass": 5.0, "com": [0.0, 0.0], "inertia": 0.1125},
}


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return repr(v)


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else f'"{k}"'


def _toml(data: dict, prefix: str = "") -> str:
    """A small TOML writer for these models: values first, then sub-tables."""
    lines = [f"{_key(k)} = {_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            name = f"{prefix}{k}"
            if any(not isinstance(x, dict) for x in v.values()) or not v:
                lines.append(f"\n[{name}]")
            lines.append(_toml(v, f"{name}."))
    return "\n".join(lines)


def _edit(base: dict, **changes: Any) -> dict:
    """A deep copy of ``base`` with dotted keys set (``legs.A.axes``); None removes a key."""
    data = copy.deepcopy(base)
    for dotted, value in changes.items():
        *path, last = dotted.split("__")
        table = data
        for part in path:
            table = table.setdefault(part, {})
        if value is None:
            table.pop(last, None)
        else:
            table[last] = value
    return data


RADIAL_LEG = {  # every leg's line through G: with sliding motors, the platform turns freely
    "joints": [[0.0, -0.5], [0.0, -0.35], [0.0, -0.15]],
    "axes": [[0.0, 0.0], [0.0, 1.0], [0.0, 0.0]],
    "mass": [3.0, 1.5],
    "com": [[0.0, -0.45], [0.0, -0.3]],
    "inertia": [0.01, 0.005],
}

#: id -> (model data, dotted key the message names, words it must contain)
CASES: dict[str, tuple[dict, str, tuple[str, ...]]] = {
    "unknown top-level key": (
        {**RRR, "actuatd": 1},
        "actuatd",
        ("unknown key", "did you mean 'actuated'?"),
    ),
    "unknown leg key": (
        _edit(RRR, legs__A__inertias=[0.1, 0.1]),
        "legs.A.inertias",
        ("unknown key", "did you mean 'inertia'?"),
    ),
    "unknown leg type": (
        {**RRR, "leg": "RPRR"},
        "leg",
        ("must be one of RRR, RPR", "did you mean"),
    ),
    "zero prismatic axis": (
        _edit(RPR, legs__A__axes=[[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]),
        "legs.A.axes[1]",
        ("joint 2 is prismatic", "non-zero"),
    ),
    "axes missing": (
        _edit(RPR, legs__A__axes=None),
        "legs.A.axes",
        ("missing", "prismatic"),
    ),
    "serial singularity at home": (
        _edit(RRR, legs__A__joints=[[0.0, -0.5], [0.0, -0.325], [0.0, -0.15]]),
        "legs.A",
        ("serial singularity at home",),
    ),
    "PPR motors on joint 3": (
        {
            **_edit(RPR, legs__A__axes=[[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]),
            "leg": "PPR",
            "actuated": 3,
        },
        "actuated",
        ("3-PPR", "cannot move", "architecturally singular"),
    ),
    "PRP motors on joint 2": (
        {
            **_edit(RPR, legs__A__axes=[[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]]),
            "leg": "PRP",
            "actuated": 2,
        },
        "actuated",
        ("3-PRP", "cannot move"),
    ),
    "RPP motors on joint 1": (
        {
            **_edit(RPR, legs__A__axes=[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]),
            "leg": "RPP",
            "actuated": 1,
        },
        "actuated",
        ("3-RPP", "cannot move"),
    ),
    "parallel singularity at home": (
        {**_edit(RPR, legs__A=RADIAL_LEG), "actuated": 2},
        "legs",
        ("parallel singularity", "do not hold the platform"),
    ),
    "legs B and C with symmetric": (
        _edit(RRR, legs__B=RRR["legs"]["A"]),
        "legs.B",
        ("not allowed with symmetric = true",),
    ),
    "limits: unknown joint": (
        _edit(RRR, limits={"A.q4": [-1.0, 1.0]}),
        "limits.A.q4",
        ("unknown key", "did you mean 'A.q"),
    ),
    "limits: unknown leg": (
        _edit(RRR, limits={"D.q1": [-1.0, 1.0]}),
        "limits.D.q1",
        ("unknown key",),
    ),
    "a number beyond float64": (
        _edit(RRR, platform__mass=10**400),
        "platform.mass",
        ("must be a finite number", "an integer of 401 digits"),
    ),
    "a bound beyond float64": (
        _edit(RRR, limits={"q2": [-(10**309), 0.5]}),
        "limits.q2[0]",
        ("must be a finite number",),
    ),
    "limits: bounds the wrong way": (
        _edit(RRR, limits={"q2": [0.5, -0.5]}),
        "limits.q2",
        ("lower bound must be below the upper",),
    ),
}


def test_the_base_models_are_valid(tmp_path: Path) -> None:
    for name, data in (("rrr", RRR), ("rpr", RPR), ("limits", _edit(RRR, limits={"q2": [-1, 1]}))):
        path = tmp_path / f"{name}.toml"
        path.write_text(_toml(data))
        model = rpr3gen.load_model(path)
        assert model.structure.leg == data["leg"]
    assert model.limits == {f"{leg}.q2": (-1.0, 1.0) for leg in "ABC"}


@pytest.mark.parametrize("case", list(CASES))
def test_one_line_naming_the_file_and_the_key(case: str, tmp_path: Path) -> None:
    data, key, words = CASES[case]
    path = tmp_path / "model.toml"
    path.write_text(_toml(data))
    with pytest.raises(rpr3gen.ModelError) as caught:
        rpr3gen.load_model(path)
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: {key}: "), message
    for word in words:
        assert word in message, message


def _in_unit(unit: float) -> dict:
    """The 3-RRR with every length times ``unit``."""
    scaled = copy.deepcopy(RRR)
    leg = scaled["legs"]["A"]
    leg["joints"] = [[v * unit for v in p] for p in leg["joints"]]
    leg["com"] = [[v * unit for v in p] for p in leg["com"]]
    return scaled


def test_a_model_in_a_huge_unit_reads_as_the_same_robot(tmp_path: Path) -> None:
    """The home checks are dimensionless: the 3-RRR with every length times 2^500 is read
    without overflow (a warning is an error here) and keeps its working modes."""
    paths = []
    for name, data in (("plain", RRR), ("huge", _in_unit(2.0**500))):
        paths.append(tmp_path / f"{name}.toml")
        paths[-1].write_text(_toml(data))
    plain, huge = (rpr3gen.load_model(p) for p in paths)
    for leg in "ABC":
        assert huge.params[f"sigma_{leg}"] == plain.params[f"sigma_{leg}"]
        assert huge.params[f"x3_{leg}"] == plain.params[f"x3_{leg}"] * 2.0**500


def test_a_model_in_a_tiny_unit_is_refused_for_what_it_is(tmp_path: Path) -> None:
    """Times 2^-500 the legs are no serial singularity (no underflow to 0 / 0): their platform
    joints are closer than the 1e-9 m in which points coincide, and the message says so."""
    path = tmp_path / "tiny.toml"
    path.write_text(_toml(_in_unit(2.0**-500)))
    with pytest.raises(rpr3gen.ModelError, match=r"legs\.B\.joints: legs A and B meet the"):
        rpr3gen.load_model(path)


@pytest.mark.parametrize(
    "case", ["unknown leg key", "PPR motors on joint 3", "limits: unknown joint"]
)
def test_the_command_exits_2_with_that_line(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data, key, _ = CASES[case]
    path = tmp_path / "model.toml"
    path.write_text(_toml(data))
    assert main(["params", "--model", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1
    assert captured.err.startswith(f"rpr3gen: error: {path}: {key}: ")
