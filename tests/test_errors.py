"""The package's errors are also the standard exceptions: ValueError for bad values, TypeError
for wrong types, OSError for the environment, so code that catches those catches them too
(errors.py, docs/errors.md); the bare base class is never raised (issue 51)."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen import errors
from rpr3gen.atomic import write_results_csv
from rpr3gen.errors import (
    GeneratedCodeError,
    GridError,
    IdentificationError,
    InputError,
    InputTypeError,
    ModelError,
    Rpr3genError,
    SetupError,
    TrajectoryError,
)
from rpr3gen.model import model_from_dict
from rpr3gen.plots import plotted_families


@pytest.mark.parametrize(
    ("error", "standard"),
    [
        (ModelError, ValueError),
        (TrajectoryError, ValueError),
        (GridError, ValueError),
        (InputError, ValueError),
        (IdentificationError, ValueError),
        (InputTypeError, TypeError),
        (SetupError, OSError),
        (GeneratedCodeError, OSError),
    ],
)
def test_hierarchy(error: type[Exception], standard: type[Exception]) -> None:
    assert issubclass(error, Rpr3genError)
    assert issubclass(error, standard)
    assert getattr(rpr3gen, error.__name__) is error


FAMILIES = (ValueError, TypeError, OSError)


def test_every_error_class_is_of_exactly_one_family() -> None:
    """Every subclass of Rpr3genError that errors.py defines is a ValueError, a TypeError or an
    OSError, and only one: ``except`` of one family never catches another's."""
    classes = [
        c
        for _, c in inspect.getmembers(errors, inspect.isclass)
        if issubclass(c, Rpr3genError) and c is not Rpr3genError
    ]
    assert {c.__name__ for c in classes} >= {"InputError", "SetupError", "GeneratedCodeError"}
    for c in classes:
        families = [f.__name__ for f in FAMILIES if issubclass(c, f)]
        assert len(families) == 1, (c.__name__, families)
        assert c.__name__ in errors.__doc__, f"{c.__name__}: add it to errors.py's tree"


def _constructions(tree: ast.AST) -> list[int]:
    """Lines that call ``Rpr3genError(...)`` (the bare base class), raised or returned."""
    return [
        node.lineno
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and (
            (isinstance(node.func, ast.Name) and node.func.id == "Rpr3genError")
            or (isinstance(node.func, ast.Attribute) and node.func.attr == "Rpr3genError")
        )
    ]


def test_no_code_makes_a_bare_rpr3gen_error() -> None:
    """Nothing in the runtime (``src/``) constructs the base class: each error names its family.
    (``type(exc)(...)`` re-raises an error's own class, so it stays of the family.)"""
    src = Path(rpr3gen.__file__).parent
    found = [
        f"{path.relative_to(src.parent)}:{line}"
        for path in sorted(src.rglob("*.py"))
        for line in _constructions(ast.parse(path.read_text(encoding="utf-8")))
    ]
    assert not found, f"raise a family's class (errors.py), not Rpr3genError: {found}"


def test_an_os_error_of_the_package_keeps_its_message() -> None:
    """A SetupError is an OSError whose message is the one line given, no errno or filename,
    and it keeps the argument at fault."""
    error = GeneratedCodeError("x/manifest.json: damaged; regenerate it", argument="generated")
    assert str(error) == "x/manifest.json: damaged; regenerate it"
    assert error.argument == "generated"
    assert (error.errno, error.filename) == (None, None)


def test_a_bad_array_shape_is_a_value_error() -> None:
    model = rpr3gen.load_model()
    with pytest.raises(ValueError, match=r"q: must have shape \(n, 3\)") as info:
        rpr3gen.inverse_dynamics(model, np.zeros((2, 2)), np.zeros((2, 3)), np.zeros((2, 3)))
    assert isinstance(info.value, InputError)
    with pytest.raises(ValueError, match="must have the same number of samples"):
        rpr3gen.inverse_dynamics(model, np.zeros((2, 3)), np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="unknown backend"):
        rpr3gen.inverse_dynamics(model, np.zeros(3), np.zeros(3), np.zeros(3), backend="gpu")


def test_a_bad_model_value_is_a_value_error() -> None:
    with pytest.raises(TypeError, match="data: must be a mapping"):  # InputTypeError
        model_from_dict([])  # type: ignore[arg-type]
    data = {
        "name": "x",
        "actuation": "revolute",
        "geometry": {"l0": 0.1, "l1": 0.2, "l2": 0.2, "r": 0.3, "beta_deg": 30.0,
                     "alpha_deg": [90.0, -150.0, -30.0]},
        "mass": {"m1": 3.0, "m2": 1.5, "m3": -5.0},
    }  # fmt: skip
    with pytest.raises(ValueError, match=r"^x\.toml: mass\.m3: must be a positive number"):
        model_from_dict(data, source="x.toml")


def test_trajectory_values_and_types() -> None:
    with pytest.raises(ValueError, match="samples"):
        rpr3gen.paper_trajectory("rotation", samples=1)
    with pytest.raises(ValueError, match="did you mean 'rotation'"):
        rpr3gen.paper_trajectory("rotaton")
    with pytest.raises(TypeError, match="samples") as info:
        rpr3gen.paper_trajectory("rotation", samples="301")  # type: ignore[arg-type]
    assert isinstance(info.value, Rpr3genError)


def test_helpers_raise_the_package_errors(tmp_path) -> None:
    with pytest.raises(InputError, match="actuation"):
        plotted_families("hydraulic")
    with pytest.raises(InputError, match="q must"):
        write_results_csv(tmp_path / "r.csv", np.zeros(2), np.zeros((2, 2)), {}, [])
