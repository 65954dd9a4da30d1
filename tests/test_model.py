"""Model files: the paper robot's derived parameters, the two geometry forms, and validation."""

from __future__ import annotations

import dataclasses
import math
import os
import pickle
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rpr3gen.model
from rpr3gen.errors import InputTypeError, ModelError, Rpr3genError
from rpr3gen.model import ACTUATIONS, PARAM_NAMES, Model, load_model, model_from_dict

REPO = Path(__file__).resolve().parents[1]

PAPER = """\
name = "paper"
actuation = "revolute"

[geometry]
l0 = 0.1
l1 = 0.2
l2 = 0.2
r = 0.3
alpha_deg = [90.0, -150.0, -30.0]
beta_deg = 30.0

[mass]
m1 = 3.0
m2 = 1.5
m3 = 5.0

[environment]
gravity = [0.0, -9.81]

[payload]
force = [0.0, 0.0]
moment = 0.0
"""

# The paper robot with explicit points (values of the conventions table, rounded to 1e-4).
EXPLICIT = """\
name = "explicit"
actuation = "revolute"

[geometry]
l0 = 0.1
l1 = 0.2
l2 = 0.2
alpha_deg = [90.0, -150.0, -30.0]
base = [[0.2598, -0.15], [0.0, 0.3], [-0.2598, -0.15]]
platform = [[0.2598, 0.15], [-0.2598, 0.15], [0.0, -0.3]]

[mass]
m1 = 3.0
m2 = 1.5
m3 = 5.0
J3 = 0.1125

[environment]
gravity = [0.0, -9.81]
"""


def write(tmp_path: Path, text: str, name: str = "robot.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# -- the paper robot ---------------------------------------------------------------------------


def test_paper_model_derived_numbers() -> None:
    model = load_model()
    p = model.params
    assert model.name == "paper"
    assert model.actuation == "revolute"
    # Base pivots and platform joints as printed in conventions.md.
    expected_points = {
        "A1": (0.2598, -0.15),
        "B1": (0.0, 0.3),
        "C1": (-0.2598, -0.15),
        "A3": (0.2598, 0.15),
        "B3": (-0.2598, 0.15),
        "C3": (0.0, -0.3),
    }
    for point, (x, y) in expected_points.items():
        leg, index = point
        assert p[f"x{leg}{index}"] == pytest.approx(x, abs=1e-4), point
        assert p[f"y{leg}{index}"] == pytest.approx(y, abs=1e-4), point
    assert (p["alpha_A"], p["alpha_B"], p["alpha_C"]) == pytest.approx(
        (math.pi / 2, -5 * math.pi / 6, -math.pi / 6), rel=1e-15
    )
    expected = {
        "l0": 0.1,
        "l2": 0.2,
        "c1": 0.2 / 2,
        "c2": 0.2 / 2,
        "m1": 3.0,
        "m2": 1.5,
        "m3": 5.0,
        "J1": 3.0 * 0.2**2 / 12,
        "J2": 1.5 * 0.2**2 / 12,
        "J3": 5 * (0.3 * math.sqrt(3)) ** 2 / 12,
        "gx": 0.0,
        "gy": -9.81,
        "fx": 0.0,
        "fy": 0.0,
        "mz": 0.0,
    }
    for name, value in expected.items():
        assert p[name] == pytest.approx(value, rel=1e-12, abs=1e-15), name


def test_paper_legs_are_symmetrically_extended() -> None:
    """At the central pose every leg has length l0 + l2 and points along alpha_i."""
    p = load_model().params
    for leg in "ABC":
        dx = p[f"x{leg}3"] - p[f"x{leg}1"]
        dy = p[f"y{leg}3"] - p[f"y{leg}1"]
        assert math.hypot(dx, dy) == pytest.approx(0.3, rel=1e-12)
        assert math.atan2(dy, dx) == pytest.approx(p[f"alpha_{leg}"], abs=1e-12)
        # Platform joints lie at distance r from G.
        assert math.hypot(p[f"x{leg}3"], p[f"y{leg}3"]) == pytest.approx(0.3, rel=1e-12)


def test_params_order_vector_and_immutability() -> None:
    model = load_model()
    assert tuple(model.params) == PARAM_NAMES
    assert len(PARAM_NAMES) == 32
    v = model.vector()
    assert v.dtype == np.float64
    assert v.shape == (len(PARAM_NAMES),)
    assert v.tolist() == [model.params[n] for n in PARAM_NAMES]
    assert model.vector(["m3", "gy"]).tolist() == [5.0, -9.81]
    with pytest.raises(TypeError):
        model.params["m1"] = 1.0  # type: ignore[index]
    with pytest.raises(KeyError):
        model.vector(["nope"])
    assert pickle.loads(pickle.dumps(model)) == model
    assert hash(model) == hash(load_model())


def test_repo_model_file_is_the_packaged_one() -> None:
    assert load_model(REPO / "models" / "paper.toml").params == load_model().params
    assert load_model(str(REPO / "models" / "paper.toml")).name == "paper"


def test_same_text_gives_same_model(tmp_path: Path) -> None:
    assert load_model(write(tmp_path, PAPER)).params == load_model().params


def test_explicit_form_matches_symmetric(tmp_path: Path) -> None:
    explicit = load_model(write(tmp_path, EXPLICIT))
    paper = load_model()
    assert explicit.name == "explicit"
    assert explicit.vector() == pytest.approx(paper.vector(), abs=1e-4)
    assert explicit.params["J3"] == 0.1125
    assert explicit.params["xA1"] == 0.2598


def test_optional_values_override_defaults(tmp_path: Path) -> None:
    text = PAPER.replace(
        "m3 = 5.0",
        "m3 = 5.0\nc1 = 0.05\nc2 = 0.15\nc1_perp = 0.01\nc2_perp = -0.02\nJ1 = 0.02\nJ2 = 0.03\n"
        "J3 = 0.2",
    )
    text = text.replace("gravity = [0.0, -9.81]", "gravity = [1, -9]")
    text = text.replace("force = [0.0, 0.0]\nmoment = 0.0", "force = [2.0, -3.0]\nmoment = 0.5")
    text = text.replace('actuation = "revolute"', 'actuation = "prismatic"')
    model = load_model(write(tmp_path, text))
    keys = ("c1", "c2", "c1_perp", "c2_perp", "J1", "J2", "J3", "gx", "gy", "fx", "fy", "mz")
    got = {k: model.params[k] for k in keys}
    assert got == {
        "c1": 0.05, "c2": 0.15, "c1_perp": 0.01, "c2_perp": -0.02, "J1": 0.02, "J2": 0.03,
        "J3": 0.2,
        "gx": 1.0, "gy": -9.0, "fx": 2.0, "fy": -3.0, "mz": 0.5,
    }  # fmt: skip
    assert model.actuation == "prismatic"
    assert all(type(v) is float for v in model.params.values())


def test_optional_tables_may_be_absent(tmp_path: Path) -> None:
    text = PAPER.split("[environment]")[0]
    p = load_model(write(tmp_path, text)).params
    assert (p["gx"], p["gy"], p["fx"], p["fy"], p["mz"]) == (0.0, -9.81, 0.0, 0.0, 0.0)


def test_integers_are_numbers(tmp_path: Path) -> None:
    text = PAPER.replace("m1 = 3.0", "m1 = 3").replace("beta_deg = 30.0", "beta_deg = 30")
    p = load_model(write(tmp_path, text)).params
    assert p["m1"] == 3.0
    assert p["J1"] == pytest.approx(3 * 0.04 / 12)


def test_model_from_dict_accepts_tuples_and_arrays() -> None:
    data = {
        "name": "d",
        "actuation": "prismatic",
        "geometry": {
            "l0": 0.1,
            "l1": 0.2,
            "l2": np.float64(0.2),
            "r": 0.3,
            "alpha_deg": np.array([90.0, -150.0, -30.0]),
            "beta_deg": np.int64(30),
        },
        "mass": {"m1": 3.0, "m2": 1.5, "m3": 5},
        "environment": {"gravity": (0.0, -9.81)},
    }
    model = model_from_dict(data)
    assert model.source == "<dict>"
    assert model.vector() == pytest.approx(load_model().vector(), rel=1e-15, abs=1e-15)
    with pytest.raises(ModelError, match=r"^nb: geometry\.l0: must be a positive number"):
        model_from_dict({**data, "geometry": {**data["geometry"], "l0": 0}}, source="nb")
    with pytest.raises(InputTypeError, match="data: must be a mapping"):
        model_from_dict([1, 2])  # type: ignore[arg-type]


def test_model_constructor_checks_its_fields() -> None:
    params = dict(load_model().params)
    with pytest.raises(ModelError, match="actuation"):
        Model(name="x", actuation="hydraulic", params=params, source="s")
    with pytest.raises(ModelError, match="J3"):
        Model(name="x", actuation="revolute", params={**params, "J3x": 1.0}, source="s")
    with pytest.raises(ModelError, match=r"params\['m3'\]: must be a finite number"):
        Model(name="x", actuation="revolute", params={**params, "m3": 10**400}, source="s")
    with pytest.raises(ModelError, match=r"stroke\[1\]: must be a finite number"):
        Model(name="x", actuation="revolute", params=params, source="s",
              stroke=((0.0, 0.1), (0.0, 10**400), (0.0, 0.1)))  # fmt: skip
    reordered = Model(
        name="x", actuation="revolute", params=dict(reversed(params.items())), source="s"
    )
    assert tuple(reordered.params) == PARAM_NAMES
    assert ACTUATIONS == ("revolute", "prismatic")


def test_model_constructor_checks_a_general_models_limits() -> None:
    """``limits`` (the general format's ``[limits]``) is checked like every field: a wrong type
    is an InputTypeError, a bad key or pair a ModelError naming it; never a traceback later."""
    model = load_model(REPO / "models" / "prr.toml")
    assert dict(model.limits) == {f"{leg}.q1": (-0.25, 0.25) for leg in "ABC"}
    again = dataclasses.replace(model, limits={"B.q2": [-1, 1]})
    assert dict(again.limits) == {"B.q2": (-1.0, 1.0)}
    with pytest.raises(ModelError, match=r"params: missing \['xA1', .* and 19 more, .*"
                       "structure=None means the paper's format"):  # fmt: skip
        dataclasses.replace(model, structure=None)
    with pytest.raises(InputTypeError, match="limits: must be a mapping"):
        dataclasses.replace(model, limits=[("A.q1", (0.0, 1.0))])
    for key, words in (("A.q4", "unknown joint coordinate; did you mean 'A.q3'?"),
                       ("q1", "unknown joint coordinate")):  # fmt: skip
        with pytest.raises(ModelError, match=re.escape(f"limits[{key!r}]: {words}")):
            dataclasses.replace(model, limits={key: (0.0, 1.0)})
    for pair, words in (
        ((1.0, 0.0), "the lower bound must be below the upper"),
        ((0.0, math.nan), "must be a finite number"),
        ((0.0, 10**400), "must be a finite number"),
        ((0.0,), "must be a pair (lo, hi)"),
        ("01", "must be a pair (lo, hi)"),
    ):
        with pytest.raises(ModelError, match=re.escape(f"limits['A.q1']: {words}")):
            dataclasses.replace(model, limits={"A.q1": pair})
    with pytest.raises(InputTypeError, match=re.escape("limits['A.q1']: must be a number")):
        dataclasses.replace(model, limits={"A.q1": ("lo", 1.0)})
    with pytest.raises(ModelError, match="bounds its pistons with stroke"):
        dataclasses.replace(load_model(), limits={"A.q1": (0.0, 1.0)})


def test_errors_are_rpr3gen_errors() -> None:
    assert issubclass(ModelError, Rpr3genError)


# -- validation --------------------------------------------------------------------------------

J_SET = "m3 = 5.0\nJ1 = 0.01\nJ2 = 0.005\nJ3 = 0.1125"

# (id, text, substrings the message must contain)
BAD_FILES: list[tuple[str, str, tuple[str, ...]]] = [
    ("l0-negative", PAPER.replace("l0 = 0.1", "l0 = -0.1"),
     ("geometry.l0: must be a positive number, got -0.1",)),
    ("l1-zero", PAPER.replace("l1 = 0.2", "l1 = 0"), ("geometry.l1", "positive")),
    ("l2-string", PAPER.replace("l2 = 0.2", 'l2 = "0.2"'), ("geometry.l2", "number", '"0.2"')),
    ("r-negative", PAPER.replace("r = 0.3", "r = -0.3"), ("geometry.r", "positive")),
    ("m1-zero", PAPER.replace("m1 = 3.0", "m1 = 0.0"), ("mass.m1", "positive")),
    ("m2-negative", PAPER.replace("m2 = 1.5", "m2 = -1.5"), ("mass.m2", "positive")),
    ("m3-bool", PAPER.replace("m3 = 5.0", "m3 = true"), ("mass.m3", "number", "true")),
    ("J1-zero", PAPER.replace("m3 = 5.0", "m3 = 5.0\nJ1 = 0.0"), ("mass.J1", "positive")),
    ("J2-negative", PAPER.replace("m3 = 5.0", "m3 = 5.0\nJ2 = -1"), ("mass.J2", "positive")),
    ("J3-zero", PAPER.replace("m3 = 5.0", "m3 = 5.0\nJ3 = 0"), ("mass.J3", "positive")),
    ("c1-string", PAPER.replace("m3 = 5.0", "m3 = 5.0\nc1 = 'half'"), ("mass.c1", "number")),
    ("c2-nan", PAPER.replace("m3 = 5.0", "m3 = 5.0\nc2 = nan"), ("mass.c2", "finite")),
    ("l0-nan", PAPER.replace("l0 = 0.1", "l0 = nan"), ("geometry.l0", "finite", "nan")),
    ("m1-inf", PAPER.replace("m1 = 3.0", "m1 = inf"), ("mass.m1", "finite", "inf")),
    ("m1-beyond-float64", PAPER.replace("m1 = 3.0", "m1 = 1" + "0" * 400),
     ("mass.m1", "finite", "an integer of 401 digits")),
    ("l0-beyond-float64", PAPER.replace("l0 = 0.1", "l0 = -1" + "0" * 310),
     ("geometry.l0", "finite", "an integer of 311 digits")),
    ("beta-inf", PAPER.replace("beta_deg = 30.0", "beta_deg = -inf"), ("geometry.beta_deg",)),
    ("alpha-short", PAPER.replace("[90.0, -150.0, -30.0]", "[90.0, -150.0]"),
     ("geometry.alpha_deg", "list of 3 numbers", "list of 2 items")),
    ("alpha-scalar", PAPER.replace("[90.0, -150.0, -30.0]", "90.0"), ("geometry.alpha_deg",)),
    ("alpha-item", PAPER.replace("[90.0, -150.0, -30.0]", '[90.0, "x", -30.0]'),
     ("geometry.alpha_deg[1]", "number")),
    ("alpha-nan", PAPER.replace("[90.0, -150.0, -30.0]", "[90.0, -150.0, nan]"),
     ("geometry.alpha_deg[2]", "finite")),
    ("gravity-long", PAPER.replace("[0.0, -9.81]", "[0.0, -9.81, 0.0]"), ("environment.gravity",)),
    ("gravity-scalar", PAPER.replace("[0.0, -9.81]", "-9.81"), ("environment.gravity",)),
    ("gravity-bool", PAPER.replace("[0.0, -9.81]", "[false, -9.81]"),
     ("environment.gravity[0]",)),
    ("force-short", PAPER.replace("force = [0.0, 0.0]", "force = [1.0]"), ("payload.force",)),
    ("moment-string", PAPER.replace("moment = 0.0", 'moment = "0"'), ("payload.moment",)),
    ("moment-inf", PAPER.replace("moment = 0.0", "moment = inf"), ("payload.moment", "finite")),
    ("unknown-typo", PAPER.replace("beta_deg", "beta_dg"),
     ("geometry.beta_dg", "unknown key", "did you mean 'beta_deg'?")),
    ("unknown-mass", PAPER.replace("m2 = 1.5", "m2 = 1.5\nJ4 = 1.0"), ("mass.J4", "unknown key")),
    ("unknown-top", "colour = 1\n" + PAPER, ("colour", "unknown key")),
    ("unknown-table", PAPER + "\n[extra]\nx = 1\n", ("extra", "unknown key")),
    ("unknown-subtable", PAPER + "\n[geometry.sub]\nx = 1\n", ("geometry.sub", "unknown key")),
    ("unknown-payload", PAPER.replace("moment = 0.0", "moments = 0.0"),
     ("payload.moments", "did you mean 'moment'?")),
    ("wrong-table", "l0 = 0.1\n" + PAPER, ("l0", "unknown key", "[geometry]")),
    ("missing-l1", PAPER.replace("l1 = 0.2\n", ""), ("geometry.l1", "missing")),
    ("missing-alpha", PAPER.replace("alpha_deg = [90.0, -150.0, -30.0]\n", ""),
     ("geometry.alpha_deg", "missing")),
    ("missing-m2", PAPER.replace("m2 = 1.5\n", ""), ("mass.m2", "missing")),
    ("missing-name", PAPER.replace('name = "paper"\n', ""), ("name", "missing")),
    ("missing-actuation", PAPER.replace('actuation = "revolute"\n', ""), ("actuation", "missing")),
    ("missing-mass", PAPER.replace("[mass]\nm1 = 3.0\nm2 = 1.5\nm3 = 5.0\n", ""),
     ("mass", "missing")),
    ("missing-geometry", PAPER.split("[geometry]")[0] + "[mass]" + PAPER.split("[mass]")[1],
     ("geometry", "missing")),
    ("environment-not-table", PAPER.replace('actuation = "revolute"\n',
                                         'actuation = "revolute"\nenvironment = 3\n').replace(
        "[environment]\ngravity = [0.0, -9.81]\n", ""), ("environment", "must be a table")),
    ("actuation-bad", PAPER.replace('"revolute"', '"hydraulic"'),
     ("actuation", '"revolute" or "prismatic"', '"hydraulic"')),
    ("actuation-typo", PAPER.replace('"revolute"', '"revolut"'), ("did you mean 'revolute'?",)),
    ("actuation-number", PAPER.replace('"revolute"', "1"), ("actuation",)),
    ("name-empty", PAPER.replace('"paper"', '""'), ("name", "non-empty string")),
    ("name-blank", PAPER.replace('"paper"', '"   "'), ("name", "non-empty string", "got \"   \"")),
    ("name-number", PAPER.replace('"paper"', "3"), ("name", "non-empty string", "got 3")),
    ("mixed-forms", PAPER.replace("beta_deg = 30.0",
                                  "beta_deg = 30.0\nbase = [[0, 0], [1, 0], [0, 1]]"),
     ("geometry.base", "geometry.r", "either")),
    ("mixed-platform", EXPLICIT.replace("J3 = 0.1125", "").replace("l2 = 0.2", "l2 = 0.2\nr = 1"),
     ("geometry.base", "geometry.r")),
    ("no-form", PAPER.replace("r = 0.3\n", "").replace("beta_deg = 30.0\n", ""),
     ("geometry", "r and beta_deg", "base and platform")),
    ("r-without-beta", PAPER.replace("beta_deg = 30.0\n", ""), ("geometry.beta_deg", "missing")),
    ("beta-without-r", PAPER.replace("r = 0.3\n", ""), ("geometry.r", "missing")),
    ("base-without-platform", EXPLICIT.replace("platform = [[0.2598, 0.15], [-0.2598, 0.15], "
                                               "[0.0, -0.3]]\n", ""),
     ("geometry.platform", "missing")),
    ("explicit-no-J3", EXPLICIT.replace("J3 = 0.1125\n", ""), ("mass.J3", "missing")),
    ("base-two-points", EXPLICIT.replace("[[0.2598, -0.15], [0.0, 0.3], [-0.2598, -0.15]]",
                                         "[[0.2598, -0.15], [0.0, 0.3]]"),
     ("geometry.base", "3 points")),
    ("platform-3d-point", EXPLICIT.replace("[-0.2598, 0.15], [0.0, -0.3]]",
                                           "[-0.2598, 0.15, 0.0], [0.0, -0.3]]"),
     ("geometry.platform[1]", "list of 2 numbers")),
    ("base-point-string", EXPLICIT.replace("[0.0, 0.3]", '"B1"'), ("geometry.base[1]",)),
    ("base-coordinate-nan", EXPLICIT.replace("[0.0, 0.3]", "[0.0, nan]"),
     ("geometry.base[1][1]", "finite")),
    ("base-coincide", EXPLICIT.replace("[0.0, 0.3]", "[0.2598, -0.15]"),
     ("geometry.base", "A1 and B1 coincide")),
    ("platform-coincide", EXPLICIT.replace("[0.0, -0.3]]", "[-0.2598, 0.15]]"),
     ("geometry.platform", "B3 and C3 coincide")),
    ("leg-zero-length", EXPLICIT.replace("[[0.2598, -0.15], [0.0, 0.3]",
                                         "[[0.2598, 0.15], [0.0, 0.3]"),
     ("geometry.base", "leg A", "zero length")),
    ("symmetric-coincide", PAPER.replace("[90.0, -150.0, -30.0]", "[90.0, 90.0, -30.0]"),
     ("geometry.alpha_deg", "A1 and B1 coincide")),
    ("toml-syntax", PAPER.replace("l1 = 0.2", "l1 = = 0.2"), ("invalid TOML", "line 6, column 6")),
    ("toml-duplicate", PAPER.replace("l1 = 0.2", "l1 = 0.2\nl1 = 0.3"), ("invalid TOML", "line")),
    ("toml-unclosed", PAPER.replace("[90.0, -150.0, -30.0]", "[90.0, -150.0"), ("invalid TOML",)),
]  # fmt: skip


@pytest.mark.parametrize(
    ("text", "needles"), [c[1:] for c in BAD_FILES], ids=[c[0] for c in BAD_FILES]
)
def test_bad_model_file(tmp_path: Path, text: str, needles: tuple[str, ...]) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ModelError) as info:
        load_model(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    for needle in needles:
        assert needle in message, (needle, message)


def test_bad_files_are_really_different_from_good_ones() -> None:
    """Guard against a replace() that did not match and so tested the good file."""
    for case_id, text, _ in BAD_FILES:
        assert text not in (PAPER, EXPLICIT), case_id


def test_relative_path_is_reported_as_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "models").mkdir()
    write(tmp_path / "models", PAPER.replace("l0 = 0.1", "l0 = -0.1"), "x.toml")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ModelError) as info:
        load_model("models/x.toml")
    assert str(info.value) == "models/x.toml: geometry.l0: must be a positive number, got -0.1"


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.toml"
    with pytest.raises(ModelError, match="not found") as info:
        load_model(path)
    assert str(path) in str(info.value)


def test_directory_and_binary_file(tmp_path: Path) -> None:
    with pytest.raises(ModelError, match="directory"):
        load_model(tmp_path)
    path = tmp_path / "bin.toml"
    path.write_bytes(b'name = "\xff\xfe"\n')
    with pytest.raises(ModelError, match="UTF-8"):
        load_model(path)


def test_runtime_modules_do_not_need_sympy() -> None:
    src = str(Path(rpr3gen.__file__).resolve().parents[1])
    code = (
        "import sys; sys.modules['sympy'] = None\n"
        "import rpr3gen.model, rpr3gen.trajectory, rpr3gen.atomic, rpr3gen.plots\n"
        "rpr3gen.model.load_model()\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
    )
    env = {**os.environ, "PYTHONPATH": src}
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
