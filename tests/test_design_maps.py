"""Workspace maps against brute-force inverse kinematics and an independent Newton-Euler solve.

The paper robot and random robots (explicit points, tilted gravity, payload, stroke limits, both
actuations): the reachable set, the conditioning, the piston displacements, the static efforts
and the orientation intervals of :func:`rpr3gen.workspace` are checked against
``workspace_reference`` (legs and closure matrix from the geometry alone) and ``newton_euler``.
"""

from __future__ import annotations

import math
import re
from typing import Any

import newton_euler as ne
import numpy as np
import pytest
import workspace_reference as ref

import rpr3gen
from rpr3gen.design.metrics import workspace_areas
from rpr3gen.design.reach import design_stroke
from rpr3gen.model import model_from_dict

THRESHOLD = 1e-3
#: Poses this close to a reachability boundary (m, or conditioning) may go either way.
NEAR = 1e-9


def _random_model(seed: int, actuation: str) -> rpr3gen.Model:
    rng = np.random.default_rng(seed)
    robot = ne.random_robot(rng)
    p = robot["params"]
    stroke = [[-rng.uniform(0.3, 0.9) * p["l0"], rng.uniform(0.05, 0.25)] for _ in range(3)]
    data: dict[str, Any] = {
        "name": f"random {seed}",
        "actuation": actuation,
        "geometry": {
            "l0": p["l0"],
            "l1": robot["l1"],
            "l2": p["l2"],
            "alpha_deg": robot["alpha_deg"].tolist(),
            "base": robot["base"].tolist(),
            "platform": robot["platform"].tolist(),
        },
        "mass": {k: p[k] for k in ("m1", "m2", "m3", "c1", "c2", "J1", "J2", "J3")},
        "environment": {"gravity": [p["gx"], p["gy"]]},
        "payload": {"force": [p["fx"], p["fy"]], "moment": p["mz"]},
        "limits": {"stroke": stroke},
    }
    return model_from_dict(data)


MODELS = {
    "paper": lambda: rpr3gen.load_model(),
    "random-revolute": lambda: _random_model(4, "revolute"),
    "random-prismatic": lambda: _random_model(14, "prismatic"),
}
PHI = {"paper": 0.2, "random-revolute": -0.1, "random-prismatic": 0.05}


@pytest.fixture(scope="module", params=sorted(MODELS))
def case(request: pytest.FixtureRequest) -> tuple[rpr3gen.Model, rpr3gen.WorkspaceMap]:
    model = MODELS[request.param]()
    return model, rpr3gen.workspace(model, phi=PHI[request.param], resolution=41)


def _poses(wmap: rpr3gen.WorkspaceMap) -> np.ndarray:
    xx, yy = np.meshgrid(wmap.x, wmap.y)
    return np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, wmap.phi)])


def test_reachable_set_is_the_brute_force_one(case: Any) -> None:
    model, wmap = case
    q = _poses(wmap)
    stroke = design_stroke(model)
    expected = ref.reachable(model.params, model.actuation, q, stroke, THRESHOLD)
    got = wmap.reachable.ravel()
    differ = got != expected
    assert np.all(ref.margin(model.params, model.actuation, q[differ], stroke, THRESHOLD) < NEAR)
    assert 0 < np.count_nonzero(got) < got.size  # the box holds the whole region, and more
    assert wmap.area == pytest.approx(np.count_nonzero(expected) * wmap.cell_area, rel=0.01)


def test_conditioning_and_displacements_are_the_geometric_ones(case: Any) -> None:
    model, wmap = case
    q = _poses(wmap)
    np.testing.assert_allclose(
        wmap.lambda21.reshape(-1, 3), ref.lambda21(model.params, q), rtol=0, atol=1e-12
    )
    expected = ref.conditioning(model.params, model.actuation, q)
    got = wmap.conditioning.ravel()
    defined = np.isfinite(got)
    assert defined.mean() > 0.99  # NaN only where a leg has no length
    np.testing.assert_allclose(got[defined], expected[defined], rtol=0, atol=1e-9)


def test_the_grid_holds_every_reachable_position(case: Any) -> None:
    """Positions just outside the box are not reachable (the box is not too small)."""
    model, wmap = case
    dx, dy = wmap.x[1] - wmap.x[0], wmap.y[1] - wmap.y[0]
    x = np.linspace(wmap.x[0] - dx / 2, wmap.x[-1] + dx / 2, 200)
    y = np.linspace(wmap.y[0] - dy / 2, wmap.y[-1] + dy / 2, 200)
    rim = np.concatenate(
        [
            np.column_stack([x, np.full_like(x, y[0] - 1e-9)]),
            np.column_stack([x, np.full_like(x, y[-1] + 1e-9)]),
            np.column_stack([np.full_like(y, x[0] - 1e-9), y]),
            np.column_stack([np.full_like(y, x[-1] + 1e-9), y]),
        ]
    )
    q = np.column_stack([rim, np.full(len(rim), wmap.phi)])
    assert not ref.reachable(model.params, model.actuation, q, design_stroke(model), 0.0).any()


def test_static_efforts_are_newton_eulers_at_rest(case: Any) -> None:
    model, wmap = case
    q = _poses(wmap)
    inside = np.flatnonzero(wmap.reachable.ravel())
    pick = inside[np.linspace(0, inside.size - 1, 40).astype(int)]
    zero = np.zeros((pick.size, 3))
    solved = ne.solve(dict(model.params), model.actuation, q[pick], zero, zero)
    family = "m10" if model.actuation == "revolute" else "f21z"
    expected = np.stack([solved[f"{family}_{leg}"] for leg in ref.LEGS], axis=1)
    got = wmap.tau.reshape(-1, 3)[pick]
    np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-9 * np.abs(expected).max())
    assert np.isnan(wmap.tau.reshape(-1, 3)[~wmap.reachable.ravel()]).all()


def test_orientation_intervals_against_brute_force(case: Any) -> None:
    model, wmap = case
    q = _poses(wmap)
    stroke = design_stroke(model)
    inside = np.flatnonzero(wmap.reachable.ravel())
    pick = inside[np.linspace(0, inside.size - 1, 25).astype(int)]
    lo, hi = wmap.phi_min.ravel()[pick], wmap.phi_max.ravel()[pick]
    assert np.all(lo <= wmap.phi)
    assert np.all(wmap.phi <= hi)
    for (x, y, _), a, b in zip(q[pick], lo, hi, strict=True):
        inner = np.linspace(a, b, 400)[1:-1]
        poses = np.column_stack([np.full(inner.size, x), np.full(inner.size, y), inner])
        assert ref.reachable(model.params, model.actuation, poses, stroke, THRESHOLD).all()
        for edge, outward in ((a, -1.0), (b, 1.0)):
            if abs(edge - wmap.phi) >= math.pi - 1e-12:  # half a turn: no edge
                continue
            near = np.array([[x, y, edge - outward * 1e-8], [x, y, edge + outward * 1e-8]])
            found = ref.reachable(model.params, model.actuation, near, stroke, THRESHOLD)
            assert found.tolist() == [True, False]  # just inside, just outside
    assert np.isnan(wmap.phi_min.ravel()[~wmap.reachable.ravel()]).all()


def test_sweep_area_is_the_maps(case: Any) -> None:
    model, _ = case
    wmap = rpr3gen.workspace(model, 0.0, 30)
    (area,) = workspace_areas([model], 30, THRESHOLD)
    assert area == pytest.approx(wmap.area, rel=1e-12)
    assert area > 0


def test_columns_are_the_interfaces() -> None:
    wmap = rpr3gen.workspace(rpr3gen.load_model(), 0.1, 12)
    columns = wmap.columns()
    assert list(columns) == [
        "x", "y", "phi", "reachable", "conditioning",
        "tau_A", "tau_B", "tau_C", "phi_min", "phi_max",
    ]  # fmt: skip
    assert all(v.shape == (144,) for v in columns.values())
    # one row per point, x fastest
    np.testing.assert_array_equal(columns["x"][:12], wmap.x)
    np.testing.assert_array_equal(columns["y"][::12], wmap.y)
    assert columns["reachable"].dtype == bool


def test_default_stroke_without_limits_and_the_models_with() -> None:
    paper = rpr3gen.load_model()
    assert design_stroke(paper) == ((-0.1, 0.30000000000000004),) * 3
    limited = _random_model(7, "revolute")
    assert design_stroke(limited) == limited.stroke


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"resolution": 1}, "resolution: must be an integer >= 2"),
        ({"resolution": 10.0}, "resolution: must be an integer >= 2"),
        ({"phi": math.nan}, "phi: must be a finite number (rad)"),
        ({"min_conditioning": 1.0}, "min_conditioning: must be a number in [0, 1)"),
    ],
)
def test_bad_arguments(kwargs: dict[str, Any], message: str) -> None:
    with pytest.raises(rpr3gen.Rpr3genError, match=re.escape(message)):
        rpr3gen.workspace(rpr3gen.load_model(), **kwargs)
