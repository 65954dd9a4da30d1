"""The spatial model files (docs/spatial-robots.md): the gallery, the parameter vector, the
symmetric sugar, the working mode ``sigma``, and one clear error per kind of bad input.

Every error case is a gallery file with one thing wrong, written to a temporary TOML file:
``load_model`` raises one ``ModelError`` (a ``ValueError``) whose message is one line, starts
with the file's path and names the dotted key.
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import rpr3gen
from rpr3gen.errors import ModelError
from rpr3gen.model import model_from_dict
from rpr3gen.model.spatial_home import home_conditioning

MODELS = Path(__file__).resolve().parent.parent / "models"
GALLERY = {
    "tsai-ups": "UPS",
    "rus-hexapod": "RUS",
    "pus-hexapod": "PUS",
    "delta": "RSS2",
    "linear-delta": "PSS2",
}


def _data(name: str) -> dict[str, Any]:
    with open(MODELS / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return repr(float(v) if isinstance(v, np.floating) else v)


def _toml(data: dict, prefix: str = "") -> str:
    """A small TOML writer for these models: values first, then sub-tables."""
    lines = [f"{k} = {_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            name = f"{prefix}{k}"
            if any(not isinstance(x, dict) for x in v.values()) or not v:
                lines.append(f"\n[{name}]")
            lines.append(_toml(v, f"{name}."))
    return "\n".join(lines)


def _edit(base: str | dict, **changes: Any) -> dict:
    """A deep copy of a gallery file's data (or of ``base``) with ``__``-separated keys set
    (``legs__A__axis``); None removes a key."""
    data = _data(base) if isinstance(base, str) else copy.deepcopy(base)
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


def _load(tmp_path: Path, data: dict) -> rpr3gen.Model:
    path = tmp_path / "x.toml"
    path.write_text(_toml(data) + "\n", encoding="utf-8")
    return rpr3gen.load_model(path)


# -- the gallery ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", GALLERY)
def test_gallery_loads_well_conditioned(name: str) -> None:
    model = rpr3gen.load_model(MODELS / f"{name}.toml")
    structure = model.structure
    assert structure.spatial
    assert structure.leg == GALLERY[name]
    assert model.actuation == structure.actuation
    assert tuple(model.params) == structure.param_names()
    assert model.param_names == structure.param_names()
    assert np.all(np.isfinite(model.vector()))
    assert model.stroke is None
    assert model.limits is None
    assert home_conditioning(structure, model.params) > 0.1


@pytest.mark.parametrize("name", GALLERY)
def test_gallery_directions_are_unit(name: str) -> None:
    model = rpr3gen.load_model(MODELS / f"{name}.toml")
    p = model.params
    for leg in model.structure.legs:
        names = [n for n in ("a", "u1", "u2", "bar") if f"{n}x_{leg}" in p]
        vectors = {n: np.array([p[f"{n}{a}_{leg}"] for a in "xyz"]) for n in names}
        for v in vectors.values():
            assert np.linalg.norm(v) == pytest.approx(1.0, abs=1e-14)
        if "u1" in vectors:
            assert abs(vectors["u1"] @ vectors["u2"]) < 1e-14


def _expanded(data: dict) -> dict:
    """``data`` with ``symmetric = true`` replaced by every leg, turned here independently of
    the reader."""
    out = copy.deepcopy(data)
    out.pop("symmetric")
    letters = "ABCDEF" if data["leg"] in ("UPS", "RUS", "PUS") else "ABC"
    given = letters[:2] if len(letters) == 6 else letters[:1]
    legs = {}
    for k, letter in enumerate(letters):
        source = data["legs"][given[k % len(given)]]
        t = math.radians(120.0 * (k // len(given)))
        R = np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]])
        leg: dict[str, Any] = {}
        for key, value in source.items():
            if key in ("base", "axis", "elbow", "platform", "bar"):
                leg[key] = (R @ np.array(value)).tolist()
            elif key in ("u_axes", "com"):
                leg[key] = [(R @ np.array(v)).tolist() for v in value]
            elif key == "inertia":
                tensors = []
                for xx, yy, zz, xy, xz, yz in value:
                    m = R @ np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) @ R.T
                    tensors.append(
                        [
                            float(m[i, j])
                            for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
                        ]
                    )
                leg[key] = tensors
            else:
                leg[key] = copy.deepcopy(value)
        legs[letter] = leg
    out["legs"] = legs
    return out


@pytest.mark.parametrize("name", GALLERY)
def test_symmetric_equals_explicit_legs(name: str) -> None:
    data = _data(name)
    assert data["symmetric"] is True
    sugar = model_from_dict(data, source=f"{name}.toml")
    explicit = model_from_dict(_expanded(data), source=f"{name}-explicit.toml")
    assert tuple(explicit.params) == tuple(sugar.params)
    np.testing.assert_allclose(explicit.vector(), sugar.vector(), rtol=1e-12, atol=1e-14)


def _D(model: rpr3gen.Model, leg: str) -> float:
    """``(S - E) . dE/dq1`` at home, computed from the parameters."""
    p = model.params

    def v(n: str) -> np.ndarray:
        return np.array([p[f"{n}{a}_{leg}"] for a in "xyz"])

    de = v("a") if model.structure.leg[0] == "P" else np.cross(v("a"), v("e") - v("b"))
    return float((v("p") - v("e")) @ de)


@pytest.mark.parametrize("name", [n for n, k in GALLERY.items() if k != "UPS"])
def test_sigma_is_the_sign_of_D_at_home(name: str) -> None:
    model = rpr3gen.load_model(MODELS / f"{name}.toml")
    for leg in model.structure.legs:
        assert model.params[f"sigma_{leg}"] == math.copysign(1.0, _D(model, leg))
    # Reversing joint 1's axis reverses dE/dq1, hence every sigma.
    data = _data(name)
    for leg in data["legs"].values():
        leg["axis"] = [-x for x in leg["axis"]]
    flipped = model_from_dict(data)
    for leg in model.structure.legs:
        assert flipped.params[f"sigma_{leg}"] == -model.params[f"sigma_{leg}"]


def test_defaults_and_normalisation(tmp_path: Path) -> None:
    data = _edit("pus-hexapod", environment=None, payload=None)
    u1, u2 = data["legs"]["A"]["u_axes"]
    data["legs"]["A"]["u_axes"] = [
        [3 * x for x in u1],
        [x + 4e-7 * y for x, y in zip(u2, u1, strict=True)],
    ]
    data["legs"]["A"]["axis"] = [0.0, 0.0, 2.5]
    model = _load(tmp_path, data)
    p = model.params
    assert (p["gx"], p["gy"], p["gz"]) == (0.0, 0.0, -9.81)
    assert all(p[n] == 0.0 for n in ("fx", "fy", "fz", "mx", "my", "mz"))
    assert (p["ax_A"], p["ay_A"], p["az_A"]) == (0.0, 0.0, 1.0)
    v1 = np.array([p[f"u1{a}_A"] for a in "xyz"])
    v2 = np.array([p[f"u2{a}_A"] for a in "xyz"])
    assert np.linalg.norm(v1) == pytest.approx(1.0, abs=1e-15)
    assert abs(v1 @ v2) < 1e-15
    np.testing.assert_allclose(v2, u2, atol=1e-6)


def test_massless_rods_are_allowed(tmp_path: Path) -> None:
    model = _load(tmp_path, _edit("delta", legs__A__rod_mass=0.0, legs__A__rod_inertia=0.0))
    assert model.params["mr_C"] == 0.0


def test_every_leg_given_without_symmetric(tmp_path: Path) -> None:
    data = _expanded(_data("linear-delta"))
    assert _load(tmp_path, data).params["sigma_C"] == -1.0


@pytest.mark.parametrize("factor", [1e-150, 1e150])
def test_home_checks_do_not_overflow(factor: float) -> None:
    """The home checks are dimensionless: a robot scaled to any finite size reads alike."""
    data = _data("delta")
    leg = data["legs"]["A"]
    for key in ("base", "elbow", "platform"):
        leg[key] = [factor * x for x in leg[key]]
    leg["com"] = [[factor * x for x in c] for c in leg["com"]]
    leg["width"] *= factor
    scaled = model_from_dict(data)
    model = rpr3gen.load_model(MODELS / "delta.toml")
    for letter in "ABC":
        assert scaled.params[f"sigma_{letter}"] == model.params[f"sigma_{letter}"]


# -- errors -----------------------------------------------------------------------------------

_UPS_LEG = _data("tsai-ups")["legs"]["A"]


def _vertical_ups() -> dict:
    """Six vertical legs: every leg's force is vertical, so the platform slides sideways."""
    data = _edit("tsai-ups", symmetric=False)
    legs = {}
    for k, letter in enumerate("ABCDEF"):
        t = math.radians(60 * k + 10)
        legs[letter] = {
            "base": [math.cos(t), math.sin(t), -1.0],
            "u_axes": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            "platform": [math.cos(t), math.sin(t), 0.0],
            "mass": [0.1, 0.1],
            "com": [[0.0, 0.0, -0.75], [0.0, 0.0, -0.25]],
            "inertia": [[0.01, 0.01, 0.001, 0.0, 0.0, 0.0]] * 2,
        }
    data["legs"] = legs
    return data


def _straight_delta() -> dict:
    """A Delta whose rods continue its arms: the rods cannot turn the arms (serial)."""
    leg = _data("delta")["legs"]["A"]
    b, e = np.array(leg["base"]), np.array(leg["elbow"])
    return _edit("delta", legs__A__platform=(e + 2.0 * (e - b)).tolist())


#: id -> (model data, dotted key the message names, words it must contain)
CASES: dict[str, tuple[dict, str, tuple[str, ...]]] = {
    "unknown top-level key": (
        _edit("tsai-ups", symetric=True),
        "symetric",
        ("unknown key", "did you mean 'symmetric'?"),
    ),
    "unknown leg key": (
        _edit("tsai-ups", legs__A__u_axis=[[1.0, 0.0, 0.0]]),
        "legs.A.u_axis",
        ("unknown key", "did you mean 'u_axes'?"),
    ),
    "unknown platform key": (
        _edit("delta", platform__inertial=[1.0] * 6),
        "platform.inertial",
        ("unknown key", "did you mean 'inertia'?"),
    ),
    "key of another leg type": (
        _edit("tsai-ups", legs__B__width=0.1),
        "legs.B.width",
        ("not a key of UPS legs", "RSS2, PSS2"),
    ),
    "bar in an RSS2": (
        _edit("delta", legs__A__bar=[1.0, 0.0, 0.0]),
        "legs.A.bar",
        ("not a key of RSS2 legs", "PSS2"),
    ),
    "unknown leg": (
        _edit("delta", legs__D=dict(_data("delta")["legs"]["A"])),
        "legs.D",
        ("unknown leg", "legs A to C"),
    ),
    "missing leg key": (
        _edit("rus-hexapod", legs__B__elbow=None),
        "legs.B.elbow",
        ("missing required key",),
    ),
    "missing platform": (_edit("delta", platform=None), "platform", ("missing required table",)),
    "missing platform key": (
        _edit("delta", platform__com=None),
        "platform.com",
        ("missing required key",),
    ),
    "missing name": (_edit("delta", name=None), "name", ("missing required key",)),
    "empty name": (_edit("delta", name=" "), "name", ("non-empty string",)),
    "missing leg B of a symmetric hexapod": (
        _edit("pus-hexapod", legs__B=None),
        "legs.B",
        ("missing required table [legs.B]", "legs A and B"),
    ),
    "missing leg without symmetric": (
        _edit("delta", symmetric=None),
        "legs.B",
        ("missing required table [legs.B]", "symmetric = true"),
    ),
    "extra leg with symmetric": (
        _edit("tsai-ups", legs__C=dict(_UPS_LEG)),
        "legs.C",
        ("not allowed with symmetric = true",),
    ),
    "symmetric not a boolean": (_edit("delta", symmetric=1), "symmetric", ("true or false",)),
    "leg not a table": (_edit("delta", legs__A=3), "legs.A", ("must be a table",)),
    "wrong actuated joint": (
        _edit("tsai-ups", actuated=1),
        "actuated",
        ("UPS legs carry their motor on joint 2", "got 1"),
    ),
    "actuated a boolean": (_edit("delta", actuated=True), "actuated", ("joint 1", "got true")),
    "limit of a joint without a coordinate": (
        _edit("delta", limits={"q2": [-1.0, 1.0]}),
        "limits.q2",
        ("unknown key", "'q1'"),
    ),
    "limit of a hexapod's S joint": (
        _edit("tsai-ups", limits={"q3": [-1.0, 1.0]}),
        "limits.q3",
        ("unknown key", "'q1a', 'q1b', 'q2'"),
    ),
    "limit upside down": (
        _edit("tsai-ups", limits={"q2": [0.1, -0.1]}),
        "limits.q2",
        ("lower bound must be below the upper",),
    ),
    "limit not a pair": (
        _edit("delta", limits={"q1": [0.1]}),
        "limits.q1",
        ("must be a list of 2 numbers",),
    ),
    "wrong type": (
        _edit("tsai-ups", legs__A__base="origin"),
        "legs.A.base",
        ("must be a list of 3 numbers", 'got "origin"'),
    ),
    "wrong number type": (
        _edit("tsai-ups", legs__A__base=[0.0, "1", 0.0]),
        "legs.A.base[1]",
        ("must be a number",),
    ),
    "wrong shape of com": (
        _edit("tsai-ups", legs__A__com=[[0.0, 0.0, 0.0]]),
        "legs.A.com",
        ("must be a list of 2 points", "a list of 1 item"),
    ),
    "wrong shape of a Delta's mass": (
        _edit("delta", legs__A__mass=1.6),
        "legs.A.mass",
        ("must be a list of 1 number (the arm, kg)",),
    ),
    "wrong length of an inertia": (
        _edit("delta", legs__A__inertia=[[0.02, 0.002, 0.02, 0.0, 0.0]]),
        "legs.A.inertia[0]",
        ("must be a list of 6 numbers",),
    ),
    "non-finite point": (
        _edit("rus-hexapod", legs__A__elbow=[math.nan, 0.0, 0.0]),
        "legs.A.elbow[0]",
        ("finite",),
    ),
    "non-finite gravity": (
        _edit("delta", environment__gravity=[0.0, 0.0, -math.inf]),
        "environment.gravity[2]",
        ("finite",),
    ),
    "wrong length of gravity": (
        _edit("delta", environment__gravity=[0.0, -9.81]),
        "environment.gravity",
        ("must be a list of 3 numbers",),
    ),
    "zero body mass": (
        _edit("tsai-ups", legs__B__mass=[0.1, 0.0]),
        "legs.B.mass[1]",
        ("must be a positive number", "got 0.0"),
    ),
    "negative platform mass": (
        _edit("delta", platform__mass=-0.5),
        "platform.mass",
        ("must be a positive number",),
    ),
    "negative rod mass": (
        _edit("delta", legs__A__rod_mass=-0.2),
        "legs.A.rod_mass",
        ("at least 0", "kg"),
    ),
    "rod_com outside [0, 1]": (
        _edit("linear-delta", legs__A__rod_com=1.5),
        "legs.A.rod_com",
        ("in [0, 1]",),
    ),
    "negative rod inertia": (
        _edit("linear-delta", legs__A__rod_inertia=-1e-4),
        "legs.A.rod_inertia",
        ("at least 0",),
    ),
    "zero width": (_edit("delta", legs__A__width=0.0), "legs.A.width", ("positive number",)),
    "zero axis": (
        _edit("rus-hexapod", legs__A__axis=[0.0, 0.0, 0.0]),
        "legs.A.axis",
        ("non-zero direction",),
    ),
    "zero bar": (
        _edit("linear-delta", legs__A__bar=[0, 0, 0]),
        "legs.A.bar",
        ("non-zero direction",),
    ),
    "zero U axis": (
        _edit("tsai-ups", legs__A__u_axes=[_UPS_LEG["u_axes"][0], [0.0, 0.0, 0.0]]),
        "legs.A.u_axes[1]",
        ("non-zero direction",),
    ),
    "U axes not perpendicular": (
        _edit("tsai-ups", legs__A__u_axes=[[1.0, 0.0, 0.0], [0.01, 1.0, 0.0]]),
        "legs.A.u_axes",
        ("perpendicular", "degrees"),
    ),
    "leg inertia not positive definite": (
        _edit("delta", legs__A__inertia=[[0.02, 0.002, 0.02, 0.0, 0.0, 0.01]]),
        "legs.A.inertia[0]",
        ("not positive definite",),
    ),
    "leg inertia zero": (
        _edit("tsai-ups", legs__A__inertia=[[0.0] * 6, _UPS_LEG["inertia"][1]]),
        "legs.A.inertia[0]",
        ("it is zero",),
    ),
    "inertia breaks the triangle inequality": (
        _edit("delta", platform__inertia=[0.001, 0.001, 0.003, 0.0, 0.0, 0.0]),
        "platform.inertia",
        ("triangle inequality",),
    ),
    "leg not perpendicular to u_axes[1]": (
        _edit("tsai-ups", legs__B__u_axes=[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
        "legs.B.u_axes",
        ("perpendicular to u_axes[1]", "assumption"),
    ),
    "leg along u_axes[0]": (
        _edit(_vertical_ups(), legs__A__u_axes=[[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]),
        "legs.A.u_axes",
        ("along u_axes[0]", "singularity"),
    ),
    "UPS leg of zero length": (
        _edit("tsai-ups", legs__A__platform=_UPS_LEG["base"]),
        "legs.A.platform",
        ("zero length",),
    ),
    "serial singularity of a PUS": (
        _edit("pus-hexapod", legs__A__axis=_data("pus-hexapod")["legs"]["A"]["u_axes"][0]),
        "legs.A",
        ("serial singularity", "D = (S - E) . dE/dq1"),
    ),
    "serial singularity of a Delta": (
        _straight_delta(),
        "legs.A",
        ("serial singularity",),
    ),
    "parallel singularity": (
        _vertical_ups(),
        "legs",
        ("parallel singularity", "conditioning"),
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_error_names_file_and_key(tmp_path: Path, case: str) -> None:
    data, key, words = CASES[case]
    path = tmp_path / "x.toml"
    path.write_text(_toml(data) + "\n", encoding="utf-8")
    with pytest.raises(ModelError) as info:
        rpr3gen.load_model(path)
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert "\n" not in message
    assert message.startswith(f"{path}: {key}: "), message
    for word in words:
        assert word in message, message


def test_dict_source_is_named() -> None:
    with pytest.raises(ModelError, match=r"^<dict>: legs\.A\.width: "):
        model_from_dict(_edit("delta", legs__A__width=-1.0))


def test_a_misspelt_spatial_leg_type_is_named_with_the_spatial_types() -> None:
    from rpr3gen.errors import ModelError
    from rpr3gen.model import model_from_dict

    with pytest.raises(ModelError, match="did you mean 'RSS2'") as caught:
        model_from_dict({"name": "x", "leg": "RSS", "actuated": 1})
    assert "UPS, RUS, PUS, RSS2, PSS2" in str(caught.value)
    assert "\n" not in str(caught.value)
