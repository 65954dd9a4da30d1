"""The package's errors are also the standard exceptions: ValueError for bad values, TypeError
for wrong types, so code that catches those catches them too (errors.py, docs/errors.md)."""

from __future__ import annotations

import numpy as np
import pytest

import rpr3gen
from rpr3gen.atomic import write_results_csv
from rpr3gen.errors import InputError, InputTypeError, ModelError, Rpr3genError, TrajectoryError
from rpr3gen.model import model_from_dict
from rpr3gen.plots import plotted_families


@pytest.mark.parametrize(
    ("error", "standard"),
    [
        (ModelError, ValueError),
        (TrajectoryError, ValueError),
        (InputError, ValueError),
        (InputTypeError, TypeError),
    ],
)
def test_hierarchy(error: type[Exception], standard: type[Exception]) -> None:
    assert issubclass(error, Rpr3genError)
    assert issubclass(error, standard)
    assert getattr(rpr3gen, error.__name__) is error


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
