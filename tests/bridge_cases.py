"""The robots the bridges' tests (test_casadi_bridge.py, test_jax_backend.py) evaluate, their
samples and their independent references.

Four committed variants: the paper's robot (``revolute``, judged by tests/newton_euler.py), a
random 3-RRR (``rrr_1``, by tests/planar_reference.py), a random 6-UPS (``ups_2``) and a random
Delta (``rss2_1``), by tests/spatial_reference.py. ``reference_outputs`` gives the reference's
value of every inverse dynamics output it has, by the generated code's names.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

import rpr3gen

try:
    from . import newton_euler as ne
    from . import planar_models as pm
    from . import planar_reference as pr
    from . import spatial_models as sm
    from . import spatial_reference as sr
except ImportError:
    import newton_euler as ne
    import planar_models as pm
    import planar_reference as pr
    import spatial_models as sm
    import spatial_reference as sr

CASES = ("revolute", "rrr_1", "ups_2", "rss2_1")
SAMPLES = 3


@dataclass(frozen=True)
class Case:
    """A robot, its reference's own description and a few samples of motion."""

    name: str
    model: rpr3gen.Model
    data: dict | None  # the model dict the reference parses (None: the paper's robot)
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def reference(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict[str, np.ndarray]:
        """Every output the reference computes, by name, (n,) each."""
        if self.name == "revolute":
            return ne.solve(dict(self.model.params), "revolute", q, qd, qdd)
        if self.name == "rrr_1":
            return pr.solve(pr.parse_model(self.data), q, qd, qdd)
        return sr.solve(self.data, q, qd, qdd)

    def reference_efforts(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """(n, k) actuator efforts by the reference, legs in order."""
        out = self.reference(q, qd, qdd)
        if self.name == "revolute":
            return np.stack([out[f"m10_{leg}"] for leg in "ABC"], axis=1)
        if self.name == "rrr_1":
            return pr.efforts(out)
        return sr.efforts(self.data, out)


@functools.cache
def case(name: str) -> Case:
    """The robot ``name`` of :data:`CASES` with :data:`SAMPLES` samples of a smooth motion."""
    rng = np.random.default_rng(5000 + CASES.index(name))
    if name == "revolute":
        model = rpr3gen.load_model()
        t = np.linspace(0.4, 2.6, SAMPLES)
        q, qd, qdd = ne.cosine_motion(t, (0.05, -0.04, 0.3))
        return Case(name, model, None, *(np.ascontiguousarray(a) for a in (q, qd, qdd)))
    if name == "rrr_1":
        data = pm.random_model(rng, "RRR", 1)
        q, qd, qdd = pm.random_motion(rng, pr.parse_model(data), np.linspace(0.1, 1.9, SAMPLES))
    else:
        data = sm.random_model("UPS" if name == "ups_2" else "RSS2", rng)
        q, qd, qdd = sm.random_motion(data, rng, SAMPLES)
    model = rpr3gen.model_from_dict(data, source=f"random-{name}")
    return Case(name, model, data, *(np.ascontiguousarray(a) for a in (q, qd, qdd)))


def inputs(c: Case, info: rpr3gen.manifest.FunctionInfo) -> list[np.ndarray]:
    """Samples of every input of a function: the motion's poses, rates, accelerations; the
    actuator coordinates of the poses and poses a little off them (forward kinematics); the
    efforts of the motion (forward dynamics); small values for the rest."""
    rng = np.random.default_rng(7)
    n = len(c.q)
    found = []
    for arg in info.inputs:
        if arg.name == "q":
            found.append(c.q)
        elif arg.name == "qd":
            found.append(c.qd)
        elif arg.name == "qdd":
            found.append(c.qdd)
        elif arg.name == "q_near":
            found.append(c.q + 1e-3)
        elif arg.name == "qa":
            (qa,), _ = rpr3gen.evaluate(c.model, "actuator_coordinates", [c.q])
            found.append(np.ascontiguousarray(qa))
        elif arg.name == "tau":
            (tau,), _ = rpr3gen.evaluate(c.model, "actuator_efforts", [c.q, c.qd, c.qdd])
            found.append(np.ascontiguousarray(tau))
        else:
            found.append(rng.normal(0.0, 0.1, (n, arg.size)))
    return found


def expected(c: Case, function: str, inputs: list[np.ndarray]) -> list[np.ndarray]:
    """The NumPy backend's outputs of ``function`` on ``inputs`` (every sample evaluated); a
    planar robot's forward kinematics, which NumPy does not offer: the motion's poses (its
    inputs are their actuator coordinates) and the actuator Jacobian there."""
    if function.startswith("forward_kinematics") and not c.model.structure.spatial:
        (J,), _ = rpr3gen.evaluate(c.model, "actuator_jacobian", [c.q])
        return [c.q, J] if function.endswith("jacobian") else [c.q]
    found, codes = rpr3gen.evaluate(c.model, function, inputs)
    assert not codes.any(), (function, codes)
    return found


def efforts_rows(model: rpr3gen.Model) -> list[int]:
    """The rows of the inverse dynamics' output that are the actuator efforts, legs in order."""
    info = rpr3gen.manifest.load(model.structure.variant).function("inverse_dynamics")
    names = info.outputs[0].names
    if model.structure.variant == "revolute":
        return [names.index(f"m10_{leg}") for leg in "ABC"]
    legs = [n.rpartition("_")[2] for n in names if n.startswith("tau_")]
    return [names.index(f"tau_{leg}") for leg in legs]


def central_differences(f, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """d f / d x (m, k) of ``f: (k,) -> (m,)`` by central differences."""
    columns = []
    for j in range(len(x)):
        e = np.zeros_like(x)
        e[j] = h
        columns.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(columns, axis=1)


def scale_close(got: np.ndarray, want: np.ndarray, rtol: float) -> None:
    """``got`` equals ``want`` within ``rtol`` of ``want``'s largest |value| (at least 1)."""
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    scale = max(1.0, float(np.nanmax(np.abs(want))) if want.size else 1.0)
    np.testing.assert_allclose(got, want, rtol=0.0, atol=rtol * scale)
