"""The paper's robot in the general format (``models/paper-general.toml``) equals the paper's model.

The same robot, two formats: ``models/paper.toml`` (the paper's parameters, its variants
``revolute``/``prismatic`` and output names) and ``models/paper-general.toml`` (a symmetric 3-RPR
of the general format, ``rpr_1``; ``rpr_2`` with ``actuated = 2``, the prismatic actuation).
Through ``inverse_dynamics`` and ``rpr3gen simulate``, the general outputs under the paper's
names and frames (``tests/planar_models.py``: ``paper_outputs``: ``f21y = f2 . n``,
``m21 = -m2``, ...) equal the paper model's to round-off, on the paper's two motions, both
actuations. Measured: loads within 8e-14 N of the paper model's (up to 99 N; its f21z, zero with
base motors, is 4e-14 N here), angles within 4e-16 rad.
"""

from __future__ import annotations

import csv
import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen.cli import main
from rpr3gen.model import model_from_dict

try:
    from . import planar_models as pm
    from . import planar_reference as pr
except ImportError:
    import planar_models as pm
    import planar_reference as pr


ROOT = Path(__file__).resolve().parent.parent
GENERAL = ROOT / "models" / "paper-general.toml"
PAPER = ROOT / "models" / "paper.toml"
ACTUATIONS = {"revolute": 1, "prismatic": 2}


def _general_data(actuation: str) -> dict:
    with GENERAL.open("rb") as handle:
        data = tomllib.load(handle)
    data["actuated"] = ACTUATIONS[actuation]
    return data


def _paper(actuation: str) -> rpr3gen.Model:
    return dataclasses.replace(rpr3gen.load_model(PAPER), actuation=actuation)


def _explicit(data: dict) -> dict:
    """The general model with legs B and C written out, for the reference's kinematics."""
    out = {k: v for k, v in data.items() if k != "symmetric"}
    out["legs"] = pr.expand_symmetric(data["legs"]["A"])
    return out


def _compare(paper_out, general_out, data: dict, q: np.ndarray) -> float:
    """The largest difference between the paper model's outputs and the general model's under
    the paper's names, relative to the largest value of each family."""
    mapped = pm.paper_outputs(general_out, _explicit(data), q)
    loads = max(float(np.max(np.abs(paper_out[n]))) for n in mapped if n.startswith(("f", "m")))
    worst = 0.0
    for name, value in mapped.items():
        expected = np.asarray(paper_out[name], dtype=float)
        d = np.asarray(value) - expected
        if name.startswith(("phi10", "phi32")):
            d = pr.wrap_to_pi(d)
        family = name.split("_")[0]
        scale = max(float(np.max(np.abs(paper_out[f"{family}_{L}"]))) for L in pr.LEGS)
        if family[0] in "fm":  # a load that vanishes (f21z, revolute) is round-off of the others
            scale = max(scale, 1e-3 * loads)
        worst = max(worst, float(np.max(np.abs(d))) / max(scale, 1e-300))
    return worst


def test_the_file_is_the_paper_twin() -> None:
    """Its parameters are those of ``paper_twin`` of the paper model's parameters: the same
    robot, home the central configuration."""
    general = rpr3gen.load_model(GENERAL)
    assert general.variant == "rpr_1"
    twin = model_from_dict(pm.paper_twin(dict(_paper("revolute").params), "revolute"))
    assert set(general.params) == set(twin.params)
    for key, value in twin.params.items():
        assert general.params[key] == pytest.approx(value, abs=1e-15), key


@pytest.mark.parametrize("motion", ["rotation", "rectilinear"])
@pytest.mark.parametrize("actuation", list(ACTUATIONS))
def test_inverse_dynamics_equals_the_paper_model(actuation: str, motion: str) -> None:
    data = _general_data(actuation)
    general = model_from_dict(data, source=str(GENERAL))
    assert general.structure.actuated == ACTUATIONS[actuation]
    paper = _paper(actuation)
    traj = rpr3gen.paper_trajectory(motion, samples=61)
    out = rpr3gen.inverse_dynamics(general, traj.q, traj.qd, traj.qdd)
    expected = rpr3gen.inverse_dynamics(paper, traj.q, traj.qd, traj.qdd)
    assert _compare(expected, out, data, traj.q) < 1e-12
    # The efforts: the paper's m10 (base motors) or f21z (slides) is tau.
    family = "m10" if actuation == "revolute" else "f21z"
    tau = np.stack([out[f"tau_{leg}"] for leg in pr.LEGS])
    paper_tau = np.stack([expected[f"{family}_{leg}"] for leg in pr.LEGS])
    assert np.max(np.abs(tau - paper_tau)) < 1e-12 * np.max(np.abs(paper_tau))
    # The same closeness to a parallel singularity.
    np.testing.assert_allclose(out["conditioning"], expected["conditioning"], rtol=1e-12)


def _read(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize("actuation", list(ACTUATIONS))
def test_simulate_gives_the_paper_model_s_outputs(actuation: str, tmp_path: Path) -> None:
    """``rpr3gen simulate`` on the general file (``actuated = 2`` written into a copy for the
    prismatic actuation) and on the paper's: the same table after the mapping."""
    general_file, paper_file = GENERAL, PAPER
    if actuation == "prismatic":
        general_file = tmp_path / "general.toml"
        text = GENERAL.read_text()
        assert text.count("\nactuated = 1 ") == 1
        general_file.write_text(text.replace("\nactuated = 1 ", "\nactuated = 2 "))
        paper_file = tmp_path / "paper.toml"
        text = PAPER.read_text()
        assert text.count('\nactuation = "revolute"') == 1
        paper_file.write_text(text.replace('\nactuation = "revolute"', '\nactuation = "prismatic"'))
    a, b = tmp_path / "general.csv", tmp_path / "paper.csv"
    common = ["--trajectory", "rectilinear", "--samples", "41"]
    assert main(["simulate", "--model", str(general_file), *common, "--out", str(a)]) == 0
    assert main(["simulate", "--model", str(paper_file), *common, "--out", str(b)]) == 0
    header, table = _read(a)
    paper_header, paper_table = _read(b)
    assert header[:4] == paper_header[:4] == ["t", "x", "y", "phi"]
    np.testing.assert_array_equal(table[:, :4], paper_table[:, :4])
    general_out = dict(zip(header, table.T, strict=True))
    paper_out = dict(zip(paper_header, paper_table.T, strict=True))
    assert {f"tau_{L}" for L in pr.LEGS} <= set(general_out)
    q = table[:, 1:4]
    assert _compare(paper_out, general_out, _general_data(actuation), q) < 1e-12
