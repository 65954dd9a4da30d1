"""Hostile input to every public Python function: docs/errors.md's classes, the argument named,
never a crash, never a silent wrong answer (issue 23).

One row of :func:`apis` per function of ``rpr3gen.__all__`` (and the public methods); the cases
are drawn from each argument's :class:`~hostile_kinds.Kind`: values of the wrong type
(``InputTypeError``), bad values and shapes (``InputError``, or the function's own class),
good values (the same answer as the plain float64 array), arrays of different lengths, NaN
rows, empty and one-row inputs; then Hypothesis draws any value for any argument and checks
the outcome against the kind's oracle. A new function joins by adding its row. Every refusal is
of the families docs/errors.md promises (issue 51): a ``TypeError`` for a wrong type, a
``ValueError`` (or, for the environment, such as a folder without generated code, an
``OSError``) for a bad value; never the bare ``Rpr3genError``.

The rows are a function of a :class:`Scene`: a robot, a motion it follows and every other input
derived from the runtime. Every row that takes a model runs on each scene: the paper's robot,
and general model files of several structures, ``models/rrr.toml`` (the committed ``rrr_1``,
NumPy and C), ``models/prr.toml`` and ``models/ppr.toml`` (generated on first use into the
session's cache; a 3-PPR has prismatic base joints and a ``reach`` that depends on its
parameters only), on samples of ``models/loop.csv``. What a general model's legs do not share
is refused there: ``identical_legs=True`` (an ``InputError`` naming it).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
import os
import re
import shutil
import tomllib
from collections.abc import Callable
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hostile_kinds import (
    HUGE,
    WRONG_ARRAYS,
    Api,
    Kind,
    Where,
    choice,
    count,
    flag,
    input_file,
    instance,
    number,
    numeric_array,
    optional,
    output_path,
    reading,
    resolve,
    rows,
)
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import rpr3gen
import rpr3gen.casadi
import rpr3gen.jax
from rpr3gen.errors import (
    GeneratedCodeError,
    GridError,
    IdentificationError,
    InputError,
    InputTypeError,
    ModelError,
    Rpr3genError,
    TrajectoryError,
)
from rpr3gen.identification import MAX_WEIGHT_RATIO, Fit
from rpr3gen.model import ACTUATIONS, Model
from rpr3gen.parameters import inertial_parameters
from rpr3gen.structure import Structure

#: The same examples on every run, so that the suite's outcome is the commit's alone (a new
#: find must not fail someone else's submission); RPR3GEN_FUZZ=random explores new ones (with
#: RPR3GEN_FUZZ_EXAMPLES=N, more of them): run it after changing a checked function. 100 a
#: function (Hypothesis' default; 250 until 2026-11-28, ~35 s more of the suite's CPU time on
#: 2 cores, when the suite came near CI's 10 minutes on a slower machine).
SETTINGS = settings(
    max_examples=int(os.environ.get("RPR3GEN_FUZZ_EXAMPLES", "100")),
    deadline=None,
    derandomize=os.environ.get("RPR3GEN_FUZZ") != "random",
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)


# -- scenes: a robot, a motion it follows, every other input from the runtime --------------

ROOT = Path(__file__).resolve().parent.parent
PAPER_TOML = Path(rpr3gen.__file__).parent / "models" / "paper.toml"
N_FIT = 40  # identify: enough equations, well conditioned (condition number about 40)
T6 = np.linspace(0.0, 0.5, 6)
Q6 = np.column_stack([0.01 * T6, -0.01 * T6, 0.1 * T6])


@dataclasses.dataclass(frozen=True, eq=False)
class Scene:
    """What the rows evaluate: a model, ``N_FIT`` samples that identify it (poses, rates and
    accelerations) and a motion of four samples; the efforts, actuator coordinates, fit,
    workspace map and single-sample evaluator are derived from the runtime when first asked
    for (inside a test: a general model's variant may have to be generated first).

    Attributes:
        backend: the backend of every call of the rows that take one.
        shared_legs: ``identical_legs=True`` is meaningful (the paper's format describes one
            leg for all three); a general model's legs, turned by 120 degrees, refuse it.
    """

    name: str
    model: Model
    file: Path
    q_fit: np.ndarray
    qd_fit: np.ndarray
    qdd_fit: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    backend: str = "numpy"
    shared_legs: bool = True

    def __repr__(self) -> str:
        return self.name

    @property
    def paper(self) -> bool:
        return self.model.structure.paper

    @property
    def backend_arg(self) -> dict[str, str]:
        """``{"backend": ...}`` for a row whose function takes one (nothing for NumPy: the
        default, so that the paper's calls stay as they were)."""
        return {} if self.backend == "numpy" else {"backend": self.backend}

    @cached_property
    def tau_fit(self) -> np.ndarray:
        """The efforts of the identification samples: ``Y @ pi + tau_payload``."""
        Y = rpr3gen.regressor(self.model, self.q_fit, self.qd_fit, self.qdd_fit)
        return Y @ inertial_parameters(self.model) + rpr3gen.payload_efforts(self.model, self.q_fit)

    @cached_property
    def tau(self) -> np.ndarray:
        """The motion's actuator efforts (the inverse dynamics)."""
        return rpr3gen.actuator_efforts(self.model, self.q, self.qd, self.qdd)

    @cached_property
    def qa(self) -> np.ndarray:
        """(2, 3) the actuator coordinates of the motion's first two poses."""
        return rpr3gen.actuator_coordinates(self.model, self.q[:2])

    @cached_property
    def fit(self) -> Fit:
        return rpr3gen.identify(
            self.model, self.q_fit, self.qd_fit, self.qdd_fit, self.tau_fit, **self.backend_arg
        )

    @cached_property
    def wmap(self) -> rpr3gen.WorkspaceMap:
        return rpr3gen.workspace(self.model, 0.0, 2)

    @cached_property
    def evaluator(self) -> rpr3gen.SampleEvaluator:
        return rpr3gen.SampleEvaluator(self.model, backend=self.backend)

    @cached_property
    def functions(self) -> tuple[str, ...]:
        """The generated functions of the model's variant."""
        from rpr3gen import variants

        return tuple(variants.load(self.model.structure, self.model.generated).functions)

    @cached_property
    def data(self) -> dict:
        """The model file's tables (what :func:`rpr3gen.model_from_dict` takes)."""
        with self.file.open("rb") as handle:
            return tomllib.load(handle)


def _paper() -> Scene:
    """The paper's robot: random poses near the central configuration, random rates."""
    rng = np.random.default_rng(23)
    q = rng.uniform(-1.0, 1.0, (N_FIT, 3)) * [0.03, 0.03, 0.2]
    qd = rng.normal(0.0, 1.0, (N_FIT, 3)) * [0.3, 0.3, 1.0]
    qdd = rng.normal(0.0, 1.0, (N_FIT, 3)) * [1.5, 1.5, 5.0]
    return Scene("paper", rpr3gen.load_model(), PAPER_TOML, q, qd, qdd, q[:4], qd[:4], qdd[:4])


@functools.cache
def _loop() -> rpr3gen.Trajectory:
    """``models/loop.csv``: a closed loop inside the workspace of every gallery robot."""
    return rpr3gen.read_trajectory_csv(ROOT / "models" / "loop.csv")


def _general(file: str, backend: str = "numpy") -> Scene:
    """A gallery model: every tenth pose of the loop with random rates (they identify), and
    four samples of the loop itself (its rates and accelerations)."""
    loop = _loop()
    rng = np.random.default_rng(23)
    fit = np.arange(N_FIT) * 10  # distinct poses (the loop is closed: t = 0 and 4 s coincide)
    qd = rng.normal(0.0, 1.0, (N_FIT, 3)) * [0.3, 0.3, 1.0]
    qdd = rng.normal(0.0, 1.0, (N_FIT, 3)) * [1.5, 1.5, 5.0]
    motion = [25, 125, 225, 325]
    name = Path(file).stem + ("" if backend == "numpy" else f"-{backend}")
    return Scene(
        name,
        rpr3gen.load_model(ROOT / "models" / file),
        ROOT / "models" / file,
        loop.q[fit],
        qd,
        qdd,
        loop.q[motion],
        loop.qd[motion],
        loop.qdd[motion],
        backend=backend,
        shared_legs=False,
    )


SCENES: dict[str, Callable[[], Scene]] = {
    "paper": _paper,
    "rrr": functools.partial(_general, "rrr.toml"),
    "rrr-c": functools.partial(_general, "rrr.toml", backend="c"),
    "prr": functools.partial(_general, "prr.toml"),
    "ppr": functools.partial(_general, "ppr.toml"),
}
"""Every scene the rows that take a model run on (``rrr-c``: the C backend)."""
FUZZED = ("rrr", "prr", "ppr")
"""The general scenes Hypothesis draws from (the paper's is fuzzed on its own, as before)."""


@functools.cache
def scene(name: str) -> Scene:
    return SCENES[name]()


def _copy(s: Scene) -> Where:
    """The scene's model file, copied into the test's folder."""
    return Where(s.file.stem, lambda tmp: str(shutil.copy(s.file, tmp / s.file.name)))


def _positions_csv(tmp: Path) -> str:
    path = tmp / "positions.csv"
    table = np.column_stack([T6, Q6]).tolist()
    lines = ["t,x,y,phi", *(",".join(repr(v) for v in row) for row in table)]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


# -- kinds particular to a few functions ----------------------------------------------------

MOTION = rows(3)


def _backend(value: Any) -> str | None:
    if not isinstance(value, str):
        return "type"
    # "c" compiles, "jax" compiles each function (the extra "jax"): other tests do
    return {"numpy": "ok", "c": None, "jax": None}.get(value, "value")


def _c_backend(value: Any) -> str | None:
    return "ok" if value == "c" else _backend(value)


BACKEND = dataclasses.replace(choice("numpy"), classify=_backend)
# a scene of the C backend: its library is built already
C_BACKEND = dataclasses.replace(choice("numpy", "c"), classify=_c_backend)
THREADS = optional(count(1, 4))
CONDITIONING = number(least=0.0, below=1.0, good=(0.0, 0.5))
FUNCTIONS = tuple(sorted(rpr3gen.manifest.load("revolute").functions))  # every variant's
MOTION_FUNCTIONS = ("actuator_efforts", "inverse_dynamics", "regressor")  # inputs q, qd, qdd


def _function(s: Scene) -> Kind:
    """``evaluate``'s function: one of the scene's variant (those of q, qd, qdd run)."""

    def classify(value: Any) -> str | None:
        if not isinstance(value, str):
            return "type"
        return "ok" if value in MOTION_FUNCTIONS else None if value in s.functions else "value"

    return Kind(
        "function",
        classify,
        wrong_types=(None, 5, ["inverse_dynamics"]),
        bad_values=("nothing", "", "inverse-dynamics"),
        good_values=MOTION_FUNCTIONS,
    )


def _bridge_name(s: Scene) -> Kind:
    """The bridges' ``name``: a function of the scene's variant (a planar robot's are all
    offered; the inverse dynamics is the one built here)."""

    def classify(value: Any) -> str | None:
        if not isinstance(value, str):
            return "type"
        return "ok" if value == "inverse_dynamics" else None if value in s.functions else "value"

    return Kind(
        "name",
        classify,
        wrong_types=(None, 5, ["inverse_dynamics"]),
        bad_values=("nothing", "", "inverse-dynamics"),
        good_values=("inverse_dynamics",),
    )


def _bound_function(s: Scene) -> Kind:
    """``SampleEvaluator``'s function: any of the scene's variant."""
    kind = choice(*FUNCTIONS)

    def classify(value: Any) -> str | None:
        if not isinstance(value, str):
            return "type"
        return "ok" if value in s.functions else "value"

    return dataclasses.replace(kind, classify=classify)


def _inputs_kind(s: Scene) -> Kind:
    def classify(value: Any) -> str | None:
        if not isinstance(value, list | tuple):
            return "type"
        if len(value) != 3:
            return "value"
        verdicts = [MOTION.classify(v) for v in value]
        if verdicts != ["ok"] * 3:
            return None  # the first bad one decides
        lengths = {len(np.atleast_2d(np.asarray(v, dtype=float))) for v in value}
        return "ok" if len(lengths) == 1 else "value"

    q, qd, qdd = s.q, s.qd, s.qdd
    return Kind(
        "inputs",
        classify,
        wrong_types=(q, "q", None, {"q": q}),
        bad_values=((q,), (q, q, q, q), (q, qd[:3], qdd)),
        good_values=((q, qd, qdd), [q, qd, qdd]),
    )


def _identical_legs(s: Scene) -> Kind:
    """A flag; where the legs' parameters differ (a general model), True is refused."""
    if s.shared_legs:
        return flag()
    return dataclasses.replace(
        flag(),
        classify=lambda v: ("value" if v else "ok") if isinstance(v, bool | np.bool_) else "type",
        bad_values=(True, np.True_),
        good_values=(False, np.False_),
    )


def _times(value: Any) -> str | None:
    verdict, array = numeric_array(value)
    if array is None:
        return verdict
    return "ok" if array.ndim == 1 and np.isfinite(array).all() else "value"


def _increasing(value: Any) -> str | None:
    verdict = _times(value)
    if verdict != "ok":
        return verdict
    array = np.asarray(value, dtype=float)
    return "ok" if array.size and (np.diff(array) > 0).all() else "value"


TIMES = Kind("times", _times, wrong_types=("t", {}, [["a"]]), bad_values=([0.0, math.nan],))
T_KIND = Kind(
    "t",
    _increasing,
    wrong_types=("t", None, [["a"]]),
    # [0, 0, inf, inf]: Hypothesis's find (inf - inf warned before t was refused)
    bad_values=(
        [0.0, 0.0, 1.0, 2.0],
        [0.0, math.nan, 1.0, 2.0],
        [0.0, 0.0, math.inf, math.inf],
        np.zeros((4, 1)),
        [],
    ),
    value_error=TrajectoryError,
)
EXACT_ROWS = Kind(  # Trajectory's arrays: (n, 3), n the length of t
    "exact rows",
    lambda v: MOTION.classify(v) if MOTION.classify(v) != "ok" else None,
    wrong_types=rows(3).wrong_types,
    bad_values=(np.zeros(3), np.zeros((4, 2)), np.zeros((5, 3))),
    value_error=TrajectoryError,
)


def _grid(value: Any) -> str | None:
    if isinstance(value, dict):
        return None
    return None if isinstance(value, str | Path) else "type"


#: A grid key of each format, a key it does not have, and six keys for 10^12 designs.
GRID_KEYS = {
    True: ("mass.m3", "mass.m9", tuple(f"mass.{k}" for k in ("m1", "m2", "m3", "J1", "J2", "J3"))),
    False: (
        "platform.mass",
        "platform.mass9",
        ("platform.mass", "platform.inertia", "legs.A.mass[0]", "legs.A.mass[1]",
         "legs.A.inertia[0]", "legs.A.inertia[1]"),
    ),
}  # fmt: skip


def _grid_kind(s: Scene) -> Kind:
    key, unknown, six = GRID_KEYS[s.paper]
    return Kind(
        "grid",
        _grid,
        wrong_types=(None, 5, [key]),
        bad_values=(
            {},
            {unknown: [1.0]},
            {key: "heavy"},
            {key: [-1.0]},
            {key: {"start": 1.0, "stop": 2.0, "num": HUGE}},
            {k: [1.0 + n for n in range(100)] for k in six},  # 10^12 designs
        ),
        value_error=GridError,
    )


def _base_model(s: Scene) -> Kind:
    return Kind(
        "base model",
        lambda v: None if v is None or isinstance(v, str | Path | dict) else "type",
        wrong_types=(5, ["paper.toml"], s.model),
        bad_values=({"name": "x"},),
        value_error=ModelError,
    )


TRAJECTORIES = Kind(
    "trajectories",
    lambda v: None if isinstance(v, list | tuple) else "type",
    wrong_types=("rotation", None, 5, ["rotation", 5]),
    bad_values=([], ["rotaton"]),
    value_error=(InputError, TrajectoryError),
)
AREA = dataclasses.replace(  # 0 (no area) or at least 2
    count(0, 2),
    classify=lambda v: "value" if type(v) is int and v == 1 else count(0, 2).classify(v),
)
WORKERS = dataclasses.replace(  # only 0 runs: any other starts a Dask cluster
    optional(count(0, 0)),
    classify=lambda v: None if v is None else count(0, 0).classify(v),
    good_values=(0,),
)
RESUME = dataclasses.replace(  # True needs the out of an interrupted sweep
    flag(), classify=lambda v: None if v is True else flag().classify(v), good_values=(False,)
)


def _params_kind(s: Scene) -> Kind:
    mass = "m1" if s.paper else "m1_A"
    return Kind(
        "params",
        lambda v: None if isinstance(v, dict) else "type",
        wrong_types=("params", 5, None, [1.0]),
        bad_values=(
            {},
            {**s.model.params, mass: math.nan},
            {**s.model.params, "extra": 1.0},
        ),
        value_error=ModelError,
    )


def _actuation(s: Scene) -> Kind:
    """The paper's format: either (it picks the variant); a general model: its structure's."""
    if s.paper:
        return dataclasses.replace(choice(*ACTUATIONS), value_error=ModelError)
    own = s.model.actuation
    (other,) = (a for a in ACTUATIONS if a != own)
    kind = choice(own)
    return dataclasses.replace(
        kind, bad_values=(*kind.bad_values, other), good_values=(own,), value_error=ModelError
    )


def _structure(s: Scene) -> Kind:
    """The model's own; None means the paper's format (of the actuation): a general model's
    parameters are not its."""
    kind = Kind(
        "Structure",
        lambda v: (
            ("ok" if v == s.model.structure else None) if isinstance(v, Structure) else "type"
        ),
        wrong_types=("RPR", 1, {"leg": "RPR"}),
        good_values=(s.model.structure,),
        value_error=ModelError,
    )
    if s.paper:
        return optional(kind)
    return dataclasses.replace(
        kind,
        classify=lambda v: "value" if v is None else kind.classify(v),
        bad_values=(None,),
    )


def _limits(s: Scene) -> Kind:
    """A general model's joint bounds ``{"A.q2": (lo, hi)}`` (the paper's format has none)."""
    bad: tuple[Any, ...] = (
        ({"A.q1": (0.0, 1.0)},)  # the paper's format bounds its pistons with stroke
        if s.paper
        else (
            {"A.q9": (0.0, 1.0)},
            {"q1": (0.0, 1.0)},
            {"A.q1": (1.0, 0.0)},
            {"A.q1": (0.0, math.nan)},
            {"A.q1": (0.0, 10**400)},
            {"A.q1": (0.0,)},
        )
    )
    return Kind(
        "limits",
        lambda v: "ok" if v is None else None if isinstance(v, dict) else "type",
        wrong_types=(5, "A.q1", [("A.q1", (0.0, 1.0))]),
        bad_values=bad,
        good_values=(None, *((dict(s.model.limits),) if s.model.limits else ())),
        value_error=ModelError,
    )


GENERATED = Kind(
    "generated folder",
    lambda v: None if isinstance(v, str | Path) else "type",
    wrong_types=(5, b"gen", ["gen"]),
    bad_values=(Where("missing", lambda tmp: str(tmp / "nothing")), ""),
    # An empty name is a bad value; a folder without the generated code is the environment's
    # (an OSError, docs/errors.md).
    value_error=(InputError, GeneratedCodeError),
)
NAME = Kind(
    "trajectory name",
    lambda v: (
        ("ok" if v in ("rotation", "rectilinear") else "value") if isinstance(v, str) else "type"
    ),
    wrong_types=(None, 5, ["rotation"]),
    bad_values=("rotaton", ""),
    good_values=("rotation", "rectilinear"),
    value_error=TrajectoryError,
)

# -- retime's arguments: a path (waypoints or a path file) and the actuators' limits ---------

#: An effort limit (N m or N) above every scene's load at rest along its path, and low enough
#: for TOPP-RA to resolve the motion it allows.
EFFORT = 200.0


def _retime_path(s: Scene) -> np.ndarray:
    """A path the scene's robot follows: a short turn of the paper's, nine poses of the loop
    (the loop is closed: its first and last poses are equal, not consecutive)."""
    if s.paper:
        return np.array([[0.0, 0.0, 0.0], [0.01, -0.01, 0.1], [0.02, 0.0, 0.2]])
    return np.ascontiguousarray(_loop().q[::50])


def _waypoints(s: Scene) -> Kind:
    """retime's ``path``: (m, 3) waypoints, m >= 2, finite, no two consecutive equal, or a path
    file (unknown to the oracle: what it holds decides); other waypoints may leave the
    workspace (a documented refusal)."""
    good = _retime_path(s)

    def classify(value: Any) -> str | None:
        if isinstance(value, str | os.PathLike):
            return None
        verdict, array = numeric_array(value)
        if array is None:
            return verdict
        if array.ndim != 2 or array.shape[1] != 3 or len(array) < 2:
            return "value"
        if not np.isfinite(array).all() or (np.diff(array, axis=0) == 0).all(axis=1).any():
            return "value"
        return "ok" if np.array_equal(array, good) else None

    return Kind(
        "waypoints",
        classify,
        wrong_types=tuple(v for v in WRONG_ARRAYS if not isinstance(v, str)),
        bad_values=(
            good[:1],
            np.zeros((2, 3)),
            np.zeros((3, 2)),
            np.zeros(3),
            np.float64(0.0),
            [[0.0, 0.0, 0.0], [math.nan, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],  # out of reach
            Where("missing", lambda tmp: str(tmp / "missing.csv")),
        ),
        good_values=(good, good.tolist()),
        value_error=(InputError, TrajectoryError),
    )


def _limit_verdict(value: Any) -> str | None:
    """A limit: a number > 0, or one (finite, > 0) per actuator, (1,) or (3,); a positive
    limit may still be refused (too low to hold the robot, too high to resolve)."""
    if isinstance(value, bool | np.bool_):
        return "type"
    if isinstance(value, numbers.Real):
        try:
            x = float(value)
        except OverflowError:
            return "value"
        return "ok" if math.isfinite(x) and x > 0 else "value"
    verdict, array = numeric_array(value)
    if array is None:
        return verdict
    if array.shape not in ((), (1,), (3,)):
        return "value"
    return "ok" if (np.isfinite(array) & (array > 0)).all() else "value"


def _limit_kind(good: tuple[Any, ...]) -> Kind:
    return Kind(
        "limit",
        _limit_verdict,
        wrong_types=("10", None, True, [["a"]], {"x": 1.0}, 1j, object()),
        bad_values=(
            0.0,
            -1.0,
            math.nan,
            math.inf,
            10**400,
            [1.0, 2.0],
            [10.0, 0.0, 10.0],
            np.ones((1, 3)),
            [],
        ),
        good_values=good,
    )


EFFORT_LIMIT = dataclasses.replace(
    _limit_kind((EFFORT, [EFFORT] * 3, np.float64(EFFORT))),
    bad_values=(*_limit_kind(()).bad_values, 1e-9),  # 1e-9: cannot hold the robot at rest
)
#: 1.7e153: a find of the random fuzz (its square overflowed in retime's scaling, a
#: RuntimeWarning); a rate limit that limits nothing.
VELOCITY_LIMIT = optional(_limit_kind((1.0, [1.0, 2.0, 3.0], 1.7e153)))


# -- the table ------------------------------------------------------------------------------

MOTION3 = (("q", "qd", "qdd"),)


def _weights() -> Kind:
    """identify's weights: a positive reading whose largest is at most MAX_WEIGHT_RATIO times
    its smallest (Hypothesis found (1, 1, 1e154): the standard deviations overflowed)."""
    base = reading(3, positive=True)

    def classify(value: Any) -> str | None:
        verdict = base.classify(value)
        if verdict == "ok":
            a = np.asarray(value, dtype=float)
            return "value" if a.max() > MAX_WEIGHT_RATIO * a.min() else "ok"
        return verdict

    return dataclasses.replace(
        base, classify=classify, bad_values=(*base.bad_values, [1.0, 1.0, 1e154])
    )


def _api(name: str, **fields: Any) -> Api:
    call = fields.pop("call", None) or getattr(rpr3gen, name)
    return Api(name=name, call=call, **fields)


def apis(s: Scene) -> tuple[Api, ...]:
    """Every public function, its valid call on the scene ``s`` and its arguments' kinds (a
    row of ``scene_free`` takes no model: it runs on the paper's scene only)."""
    model, q, qd, qdd = s.model, s.q, s.qd, s.qdd
    on = s.backend_arg  # the scene's backend, for a function that takes one

    def motion() -> dict[str, Any]:
        return {"model": model, "q": q, "qd": qd, "qdd": qdd, **on}

    model_kind = instance(rpr3gen.Model, model)
    backend = C_BACKEND if s.backend == "c" else BACKEND
    identical_legs = _identical_legs(s)
    grid_key = GRID_KEYS[s.paper][0]
    return (
        _api(
            "inverse_dynamics",
            good=lambda tmp: motion(),
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "qdd": MOTION,
                "backend": backend,
                "progress": flag(),
                "threads": THREADS,
            },
            same_length=MOTION3,
        ),
        _api(
            "evaluate",
            good=lambda tmp: {
                "model": model,
                "function": "inverse_dynamics",
                "inputs": (q, qd, qdd),
                **on,
            },
            kinds={
                "model": model_kind,
                "function": _function(s),
                "inputs": _inputs_kind(s),
                "backend": backend,
                "progress": flag(),
                "threads": THREADS,
            },
        ),
        _api(
            "actuator_coordinates",
            good=lambda tmp: {"model": model, "q": q, **on},
            kinds={"model": model_kind, "q": MOTION, "backend": backend},
        ),
        _api(
            "actuator_jacobian",
            good=lambda tmp: {"model": model, "q": q, **on},
            kinds={"model": model_kind, "q": MOTION, "backend": backend},
        ),
        _api(
            "actuator_coordinates_jacobian",
            good=lambda tmp: {"model": model, "q": q, **on},
            kinds={"model": model_kind, "q": MOTION, "backend": backend},
        ),
        _api(
            "actuator_coordinates_hessian",
            good=lambda tmp: {"model": model, "q": q, **on},
            kinds={"model": model_kind, "q": MOTION, "backend": backend},
        ),
        _api(
            "payload_efforts",
            good=lambda tmp: {"model": model, "q": q, **on},
            kinds={"model": model_kind, "q": MOTION, "backend": backend},
        ),
        _api(
            "actuator_efforts",
            good=lambda tmp: motion(),
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "qdd": MOTION,
                "backend": backend,
            },
            same_length=MOTION3,
        ),
        _api(
            "regressor",
            good=lambda tmp: motion(),
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "qdd": MOTION,
                "identical_legs": identical_legs,
                "backend": backend,
            },
            same_length=MOTION3,
        ),
        _api(
            "base_regressor",
            good=lambda tmp: motion(),
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "qdd": MOTION,
                "identical_legs": identical_legs,
                "backend": backend,
            },
            same_length=MOTION3,
        ),
        _api(
            "jacobian_rate",
            good=lambda tmp: {"model": model, "q": q, "qd": qd, **on},
            kinds={"model": model_kind, "q": MOTION, "qd": MOTION, "backend": backend},
            same_length=(("q", "qd"),),
        ),
        _api(
            "task_space_dynamics",
            good=lambda tmp: {"model": model, "q": q, "qd": qd, **on},
            kinds={"model": model_kind, "q": MOTION, "qd": MOTION, "backend": backend},
            same_length=(("q", "qd"),),
        ),
        _api(
            "platform_velocity",
            good=lambda tmp: {"model": model, "q": q, "qa_dot": qd, **on},
            kinds={"model": model_kind, "q": MOTION, "qa_dot": MOTION, "backend": backend},
            same_length=(("q", "qa_dot"),),
        ),
        _api(
            "forward_dynamics",
            good=lambda tmp: {"model": model, "q": q, "qd": qd, "tau": s.tau, **on},
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "tau": MOTION,
                "backend": backend,
            },
            same_length=(("q", "qd", "tau"),),
        ),
        _api(
            "inverse_dynamics_derivatives",
            good=lambda tmp: {"model": model, "q": q, "qd": qd, "qdd": qdd, **on},
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "qdd": MOTION,
                "backend": backend,
            },
            same_length=(("q", "qd", "qdd"),),
        ),
        _api(
            "forward_dynamics_derivatives",
            good=lambda tmp: {"model": model, "q": q, "qd": qd, "tau": s.tau, **on},
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "tau": MOTION,
                "backend": backend,
            },
            same_length=(("q", "qd", "tau"),),
        ),
        _api(
            "assembly_modes",
            good=lambda tmp: {"model": model, "qa": s.qa[0], **on},
            kinds={"model": model_kind, "qa": reading(3), "backend": backend},
        ),
        _api(
            "forward_kinematics",
            good=lambda tmp: {"model": model, "qa": s.qa, "near": q[:2], **on},
            kinds={"model": model_kind, "qa": MOTION, "near": MOTION, "backend": backend},
            same_length=(("qa", "near"),),
        ),
        _api(
            "platform_radius",
            good=lambda tmp: {"model": model},
            kinds={"model": model_kind},
        ),
        _api(
            "base_parameters",
            good=lambda tmp: {"model": model},
            kinds={"model": model_kind, "identical_legs": identical_legs},
        ),
        _api(
            "inertial_parameters",
            good=lambda tmp: {"model": model},
            kinds={"model": model_kind, "identical_legs": identical_legs},
        ),
        _api(
            "inertial_parameter_names",
            good=lambda tmp: {"model": model},
            kinds={"model": model_kind, "identical_legs": flag()},
        ),
        _api(
            "identify",
            good=lambda tmp: {
                "model": model,
                "q": s.q_fit,
                "qd": s.qd_fit,
                "qdd": s.qdd_fit,
                "tau": s.tau_fit,
                **on,
            },
            kinds={
                "model": model_kind,
                "q": MOTION,
                "qd": MOTION,
                "qdd": MOTION,
                "tau": MOTION,
                "friction": flag(),
                "identical_legs": identical_legs,
                "weights": optional(_weights()),
                "max_condition": number(greater=1.0, finite=False, good=(1e3, math.inf)),
                "t": optional(TIMES),
                "backend": backend,
            },
            same_length=(("q", "qd", "qdd", "tau", "t"),),
            nan_rows=False,
        ),
        _api(
            "excite",
            good=lambda tmp: {"model": model, "harmonics": 1, "samples": 10, "max_iterations": 1},
            kinds={
                "model": model_kind,
                "harmonics": count(1, 1),
                "period": number(greater=0.0),
                "samples": count(10, 12),
                "min_conditioning": CONDITIONING,
                "max_acceleration": reading(2, positive=True),
                "identical_legs": identical_legs,
                "friction": flag(),
                "seed": count(0, 2, huge_refused=False),
                "max_iterations": count(1, 1, most=2**31 - 1),
            },
            costly=True,
        ),
        _api(
            "workspace",
            good=lambda tmp: {"model": model, "resolution": 2},
            kinds={
                "model": model_kind,
                "phi": number(good=(0.0, -1e-3)),
                "resolution": count(2, 3),
                "min_conditioning": CONDITIONING,
            },
        ),
        _api(
            "write_workspace",
            good=lambda tmp: {"wmap": s.wmap, "outdir": str(tmp / "ws")},
            kinds={"wmap": instance(rpr3gen.WorkspaceMap), "outdir": output_path(folder=True)},
            costly=True,
        ),
        _api(
            "sweep",
            good=lambda tmp: {
                "model": None if s.paper else str(s.file),
                "grid": {grid_key: [3.0]},
                "trajectories": ["rotation"],
                "workers": 0,
                "samples": 3,
                "area_resolution": 0,
            },
            kinds={
                "model": _base_model(s),
                "grid": _grid_kind(s),
                "trajectories": TRAJECTORIES,
                "out": optional(output_path(folder=False)),
                "scheduler": Kind(
                    "scheduler",
                    lambda v: None if isinstance(v, str) or v is None else "type",
                    wrong_types=(5, ["tcp://x:1"]),
                ),
                "workers": WORKERS,
                "resume": RESUME,
                "chunk_size": count(1, 2, huge_refused=False),
                "min_conditioning": CONDITIONING,
                "area_resolution": AREA,
                "samples": count(2, 5),
                "duration": number(least=1e-6, most=1e9),
                "progress": flag(),
            },
        ),
        _api(
            "load_model",
            good=lambda tmp: {} if s.paper else {"path": str(s.file)},
            kinds={
                "path": optional(input_file(".toml", value_error=ModelError, good=_copy(s))),
                "generated": optional(GENERATED),
            },
        ),
        _api(
            "model_from_dict",
            good=lambda tmp: {"data": s.data, "source": s.name},
            kinds={
                "data": Kind(
                    "model data (a mapping)",
                    lambda v: (
                        "ok"
                        if isinstance(v, dict) and v == s.data
                        else (None if isinstance(v, dict) else "type")
                    ),
                    # Bad contents are ModelErrors naming the key, not the argument: judged
                    # in tests/test_model.py and tests/test_planar_model_errors.py.
                    wrong_types=("paper.toml", None, 5, [("name", "x")]),
                    good_values=(),
                    value_error=ModelError,
                ),
                "source": Kind(
                    "a str",
                    lambda v: "ok" if isinstance(v, str) else "type",
                    wrong_types=(None, 5, b"paper", ["paper"]),
                    good_values=("paper", "my robot"),
                ),
            },
        ),
        _api(
            "paper_trajectory",
            good=lambda tmp: {"name": "rotation", "samples": 5},
            kinds={
                "name": NAME,
                "samples": count(2, 20, value_error=TrajectoryError),
                "duration": number(least=1e-6, most=1e9, value_error=TrajectoryError),
            },
            scene_free=True,
        ),
        _api(
            "read_trajectory_csv",
            good=lambda tmp: {"path": _positions_csv(tmp)},
            kinds={
                "path": input_file(
                    ".csv", value_error=TrajectoryError, good=Where("positions", _positions_csv)
                ),
                "smoothing": optional(number(least=0.0, most=1e100, good=(0.0, 1e-6))),
            },
            scene_free=True,
        ),
        _api(
            "Model",
            good=lambda tmp: (
                {f.name: getattr(model, f.name) for f in dataclasses.fields(model)}
                | {"params": dict(model.params)}
            ),
            kinds={
                "name": Kind(
                    "name",
                    lambda v: "ok" if isinstance(v, str) else "type",
                    wrong_types=(3, None, ["paper"]),
                ),
                "actuation": _actuation(s),
                "params": _params_kind(s),
                "stroke": Kind(
                    "stroke",
                    lambda v: None,
                    wrong_types=("wide", 5),
                    bad_values=([[0.1, -0.1]] * 3, [[0.0, 1.0]], [[0.0, math.nan]] * 3),
                    value_error=ModelError,
                ),
                "generated": optional(GENERATED),
                "structure": _structure(s),
                "limits": _limits(s),
            },
        ),
        _api(
            "SampleEvaluator",
            good=lambda tmp: {"model": model, "backend": s.backend},
            kinds={"model": model_kind, "backend": backend, "function": _bound_function(s)},
        ),
        _api(
            "SampleEvaluator.evaluate",
            call=lambda q, qd, qdd: s.evaluator.evaluate(q, qd, qdd),
            good=lambda tmp: {"q": q[0], "qd": qd[0], "qdd": qdd[0]},
            kinds={"q": reading(3), "qd": reading(3), "qdd": reading(3)},
        ),
        _api(
            "Trajectory",
            good=lambda tmp: {"t": T6[:4], "q": q, "qd": qd, "qdd": qdd},
            kinds={"t": T_KIND, "q": EXACT_ROWS, "qd": EXACT_ROWS, "qdd": EXACT_ROWS},
            scene_free=True,
        ),
        _api(
            "Trajectory.from_positions",
            call=rpr3gen.Trajectory.from_positions,
            good=lambda tmp: {"t": T6, "q": Q6},
            kinds={
                "t": dataclasses.replace(
                    T_KIND,
                    classify=lambda v: None,
                    bad_values=(
                        [0.0, 0.0, 1.0, 2.0, 3.0, 4.0],
                        [0.0, math.nan, 1.0, 2.0, 3.0, 4.0],
                    ),
                ),
                "q": dataclasses.replace(EXACT_ROWS, bad_values=(np.zeros((6, 2)), np.zeros(3))),
                "smoothing": number(least=0.0, most=1e100, good=(0.0,)),
                "source": Kind("source", lambda v: "ok" if isinstance(v, str) else "type"),
            },
            scene_free=True,
        ),
        _api(
            "retime",
            good=lambda tmp: {
                "model": model,
                "path": _retime_path(s),
                "effort_limit": EFFORT,
                "samples": 5,
                "grid_points": 21,
                **on,
            },
            kinds={
                "model": model_kind,
                "path": _waypoints(s),
                "effort_limit": EFFORT_LIMIT,
                "velocity_limit": VELOCITY_LIMIT,
                "samples": count(2, 20),
                "grid_points": count(3, 40),
                "min_conditioning": number(least=0.0, below=1.0, good=(0.0, 1e-3)),
                "backend": backend,
            },
        ),
        *(
            _api(
                f"{bridge}.{what}",
                call=getattr(module, what),
                good=(lambda tmp: {"model": model, "name": "inverse_dynamics"})
                if what == "function"
                else (lambda tmp: {"model": model}),
                kinds={"model": model_kind, "name": _bridge_name(s)}
                if what == "function"
                else {"model": model_kind},
            )
            for bridge, module in (("casadi", rpr3gen.casadi), ("jax", rpr3gen.jax))
            for what in ("function", "parameters")
        ),
        _api(
            "Fit.predict",
            call=lambda q, qd, qdd: s.fit.predict(q, qd, qdd),
            good=lambda tmp: {"q": q, "qd": qd, "qdd": qdd},
            kinds={"q": MOTION, "qd": MOTION, "qdd": MOTION},
            same_length=MOTION3,
        ),
    )


@functools.cache
def table(name: str) -> dict[str, Api]:
    """The rows on the scene ``name``, by function (built without evaluating anything)."""
    return {api.name: api for api in apis(scene(name))}


APIS: tuple[Api, ...] = tuple(table("paper").values())
"""Every public function's row, on the paper's scene."""

#: What may be refused although every argument is valid alone: a pose out of reach, data that
#: do not identify, a reading the generated code refuses (documented refusals, not crashes).
REFUSALS: dict[str, tuple[type[Exception], ...]] = {
    "identify": (InputError, IdentificationError),
    "excite": (IdentificationError,),
    "SampleEvaluator.evaluate": (InputError,),
    "Trajectory.from_positions": (TrajectoryError,),
    "Trajectory": (TrajectoryError,),
    "retime": (InputError, TrajectoryError),
}

#: The standard families every error of the package belongs to (docs/errors.md): a bad value,
#: a wrong type, the environment. A bare Rpr3genError is none of them.
FAMILIES = (ValueError, TypeError, OSError)

EXEMPT = {
    "BACKENDS": "a constant",
    "INERTIAL_PARAMETER_NAMES": "a constant",
    "OUTPUT_NAMES": "a constant",
    "PARAM_NAMES": "a constant",
    "__version__": "a constant",
    "WorkspaceMap": "a result, made by workspace()",
}


def test_every_public_name_has_a_row() -> None:
    rowed = {api.name.split(".")[0] for api in APIS}
    errors = {
        n
        for n in rpr3gen.__all__
        if isinstance(getattr(rpr3gen, n), type)
        and issubclass(getattr(rpr3gen, n), Exception | Warning)
    }
    missing = set(rpr3gen.__all__) - rowed - set(EXEMPT) - errors
    assert not missing, f"add a row to APIS for {sorted(missing)}"


def _classes(promised: type[Exception] | tuple[type[Exception], ...]) -> tuple[type, ...]:
    return promised if isinstance(promised, tuple) else (promised,)


@pytest.mark.parametrize("where", SCENES)
def test_every_promised_error_is_of_a_family(where: str) -> None:
    """What the rows promise for a bad value, and REFUSALS, name classes of the families
    (a ValueError or an OSError, never the bare base class)."""
    promised = {
        f"{api.name}({name})": _classes(kind.value_error)
        for api in table(where).values()
        for name, kind in api.kinds.items()
    } | {f"{name} (a refusal)": classes for name, classes in REFUSALS.items()}
    bare = {
        k: [c.__name__ for c in classes if not issubclass(c, ValueError | OSError)]
        for k, classes in promised.items()
    }
    assert not {k: v for k, v in bare.items() if v}


# -- the cases ------------------------------------------------------------------------------


def _scenes(api: Api) -> tuple[str, ...]:
    """The scenes a row runs on: every one, or the paper's for a row that takes no model."""
    return ("paper",) if api.scene_free else tuple(SCENES)


def _rows(keep: Callable[[Api], bool] = lambda api: True) -> list[Any]:
    """(scene, function) of every row ``keep`` keeps, on each of its scenes."""
    return [
        pytest.param(where, api.name, id=f"{where}-{api.name}")
        for api in APIS
        for where in _scenes(api)
        if keep(table(where)[api.name])
    ]


def _arguments(attribute: str) -> list[Any]:
    """(scene, function, argument) whose kind has values of ``attribute``; one test case each,
    which tries every value (a case per value would cost pytest's overhead a thousand times).
    Good values of a costly function are left to its own tests."""
    return [
        pytest.param(where, api.name, name, id=f"{where}-{api.name}-{name}")
        for api in APIS
        for where in _scenes(api)
        for name, kind in table(where)[api.name].kinds.items()
        if getattr(kind, attribute) and not (attribute == "good_values" and api.costly)
    ]


def _every(values: Any, check: Any) -> None:
    """``check(value)`` for each value; every failure reported, not only the first."""
    failures = []
    for value in values:
        try:
            check(value)
        except AssertionError as exc:  # pragma: no cover - shown when the battery fails
            failures.append(f"{value!r:.60}: {exc}")
    assert not failures, "\n".join(failures)


def _call(api: Api, tmp: Path, **changed: Any) -> Any:
    kwargs = api.good(tmp) | {k: resolve(v, tmp) for k, v in changed.items()}
    return api.call(**kwargs)


def _assert_names(exc: BaseException, name: str, *paths: str) -> None:
    """One line that names the argument (as a word), or one of ``paths``."""
    message = str(exc)
    assert "\n" not in message, message
    named = re.search(rf"(?<![\w-]){re.escape(name)}(?!\w)", message)
    assert named or any(p in message for p in paths), (name, paths, message)


@pytest.mark.parametrize(("where", "function", "name"), _arguments("wrong_types"))
def test_a_wrong_type_is_an_input_type_error_naming_it(
    where: str, function: str, name: str, tmp_path: Path
) -> None:
    api = table(where)[function]

    def check(value: Any) -> None:
        with pytest.raises(InputTypeError) as info:
            _call(api, tmp_path, **{name: value})
        assert isinstance(info.value, TypeError), repr(info.value)
        _assert_names(info.value, name)

    _every(api.kinds[name].wrong_types, check)


@pytest.mark.parametrize(("where", "function", "name"), _arguments("bad_values"))
def test_a_bad_value_is_the_promised_error_naming_it(
    where: str, function: str, name: str, tmp_path: Path
) -> None:
    api = table(where)[function]

    def check(value: Any) -> None:
        with pytest.raises(Rpr3genError) as info:
            _call(api, tmp_path, **{name: value})
        assert isinstance(info.value, api.kinds[name].value_error), repr(info.value)
        assert not isinstance(info.value, InputTypeError), repr(info.value)
        assert isinstance(info.value, ValueError | OSError), repr(info.value)
        shown = resolve(value, tmp_path)
        _assert_names(info.value, name, *([shown] if isinstance(shown, str) and shown else []))

    _every(api.kinds[name].bad_values, check)


def _leaves(result: Any) -> list[np.ndarray]:
    """The arrays of a result, in a fixed order."""
    if isinstance(result, dict):
        return [np.asarray(result[k]) for k in sorted(result)]
    if isinstance(result, list | tuple):
        return [leaf for item in result for leaf in _leaves(item)]
    if isinstance(result, np.ndarray):
        return [result]
    if isinstance(result, Fit):
        return [result.values, result.std]
    return []


def _same(a: Any, b: Any) -> None:
    left, right = _leaves(a), _leaves(b)
    assert len(left) == len(right)
    for x, y in zip(left, right, strict=True):
        assert x.shape == y.shape
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), (x, y)


@pytest.mark.parametrize(("where", "function", "name"), _arguments("good_values"))
def test_a_good_value_is_taken_as_its_float64_array(
    where: str, function: str, name: str, tmp_path: Path
) -> None:
    api = table(where)[function]

    def check(value: Any) -> None:
        result = _call(api, tmp_path, **{name: value})
        if api.kinds[name].rows and value is not None:
            _same(result, _call(api, tmp_path, **{name: np.array(value, dtype=float)}))

    _every(api.kinds[name].good_values, check)


def _row_groups(api: Api) -> list[tuple[str, ...]]:
    arrays = [n for n, k in api.kinds.items() if k.rows and not k.one_reading and n != "t"]
    return [tuple(arrays)] if arrays else []


ROWED = _rows(lambda api: bool(_row_groups(api)) and api.name != "Trajectory")


@pytest.mark.parametrize(("where", "function"), ROWED)
@pytest.mark.parametrize(
    "like",
    [
        np.ndarray.tolist,
        lambda a: tuple(map(tuple, a)),
        lambda a: a.astype(np.float32).astype(object),
    ],
)
def test_an_array_like_is_taken_as_its_float64_array(
    where: str, function: str, like: Any, tmp_path: Path
) -> None:
    api = table(where)[function]
    (names,) = _row_groups(api)
    good = api.good(tmp_path)
    given_ = {n: like(np.asarray(good[n])) for n in names}
    floats = {n: np.array(given_[n], dtype=float) for n in names}
    _same(_call(api, tmp_path, **given_), _call(api, tmp_path, **floats))


@pytest.mark.parametrize(("where", "function"), _rows(lambda api: bool(api.same_length)))
def test_arrays_of_different_lengths_are_refused_naming_them(
    where: str, function: str, tmp_path: Path
) -> None:
    api = table(where)[function]
    for group in api.same_length:
        present = [n for n in group if n != "t"]
        good = api.good(tmp_path)
        longer = np.vstack([good[present[0]], good[present[0]][:1]])
        with pytest.raises(InputError) as info:
            _call(api, tmp_path, **{present[0]: longer})
        for name in present:
            assert name in str(info.value), str(info.value)


@pytest.mark.parametrize(("where", "function"), ROWED)
def test_one_row_and_one_sample_are_the_same_answer(
    where: str, function: str, tmp_path: Path
) -> None:
    api = table(where)[function]
    (names,) = _row_groups(api)
    good = api.good(tmp_path)
    if not api.nan_rows:  # a function that needs many samples refuses one
        with pytest.raises(IdentificationError, match="give more samples"):
            _call(api, tmp_path, **{n: np.asarray(good[n])[0] for n in names})
        return
    one = _call(api, tmp_path, **{n: np.asarray(good[n])[0] for n in names})
    _same(one, _call(api, tmp_path, **{n: np.asarray(good[n])[:1] for n in names}))


@pytest.mark.parametrize(("where", "function"), ROWED)
def test_empty_input_is_an_empty_answer_or_refused(
    where: str, function: str, tmp_path: Path
) -> None:
    api = table(where)[function]
    (names,) = _row_groups(api)
    empty = {n: np.zeros((0, 3)) for n in names}
    if not api.nan_rows:
        with pytest.raises((InputError, IdentificationError)) as info:
            _call(api, tmp_path, **empty)
        assert "\n" not in str(info.value)
        return
    for leaf in _leaves(_call(api, tmp_path, **empty)):
        if leaf.ndim:
            assert leaf.shape[0] == 0, leaf.shape


@pytest.mark.parametrize(("where", "function"), ROWED)
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_non_finite_row_is_a_nan_row_and_the_others_are_kept(
    where: str, function: str, bad: float, tmp_path: Path
) -> None:
    api = table(where)[function]
    (names,) = _row_groups(api)
    good = api.good(tmp_path)
    spoiled = np.array(good[names[0]], dtype=float)
    spoiled[1, 0] = bad
    if not api.nan_rows:
        with pytest.raises(InputError, match="sample 2"):
            _call(api, tmp_path, **{names[0]: spoiled})
        return
    result = _call(api, tmp_path, **{names[0]: spoiled})
    baseline = _call(api, tmp_path)
    n = len(spoiled)
    for got, want in zip(_leaves(result), _leaves(baseline), strict=True):
        if got.ndim and got.shape[0] == n and got.dtype.kind == "f":
            assert np.isnan(got[1]).all(), (api.name, got[1])
            keep = np.arange(n) != 1
            assert np.array_equal(got[keep], want[keep], equal_nan=True)


@pytest.mark.parametrize("where", list(SCENES))
def test_one_reading_refuses_two_rather_than_use_the_first(where: str) -> None:
    s = scene(where)
    with pytest.raises(InputError, match=r"qa: must have shape \(3,\), got \(2, 3\)"):
        rpr3gen.assembly_modes(s.model, s.qa, **s.backend_arg)


@pytest.mark.parametrize("where", list(SCENES))
def test_a_scene_is_a_motion_the_robot_follows(where: str) -> None:
    """The good calls are not vacuous: every sample of the scene is inside the workspace (no
    NaN row), its inputs agree (the efforts of the regressor are the inverse dynamics', the
    poses come back from the actuator coordinates) and its data identify the robot."""
    s = scene(where)
    for q, qd, qdd in ((s.q, s.qd, s.qdd), (s.q_fit, s.qd_fit, s.qdd_fit)):
        out = rpr3gen.inverse_dynamics(s.model, q, qd, qdd, **s.backend_arg)
        assert all(np.isfinite(v).all() for v in out.values()), where
        assert (out["conditioning"] > 0.02).all()
        assert (out["reach"] > 0.02).all()
    efforts = rpr3gen.actuator_efforts(s.model, s.q_fit, s.qd_fit, s.qdd_fit)
    assert np.allclose(s.tau_fit, efforts, rtol=1e-9, atol=1e-9 * np.abs(efforts).max())
    near = rpr3gen.forward_kinematics(s.model, s.qa, s.q[:2], **s.backend_arg)
    assert np.allclose(near, s.q[:2], rtol=0.0, atol=1e-12)
    assert s.fit.condition_number < 1e3
    assert np.allclose(s.fit.predict(s.q, s.qd, s.qdd), s.tau, rtol=1e-7, atol=1e-7)


@pytest.mark.parametrize("where", [w for w in SCENES if not scene(w).shared_legs])
def test_identical_legs_is_refused_where_the_legs_differ(where: str, tmp_path: Path) -> None:
    """A general model's legs turned by 120 degrees do not share their inertial parameters:
    every function that would share them refuses, naming the leg, rather than fit a robot
    that is not this one."""
    checked = []
    for api in table(where).values():
        # The names alone are those of the shared parameters whatever the legs' values.
        if "identical_legs" in api.kinds and api.name != "inertial_parameter_names":
            with pytest.raises(InputError, match=r"^identical_legs: leg B's .* differ"):
                _call(api, tmp_path, identical_legs=True)
            checked.append(api.name)
    assert len(checked) == 6, checked


# -- Hypothesis: any value for any argument ---------------------------------------------------

_shapes = hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=4)
_dtypes = st.sampled_from([np.float64, np.float32, np.int64, np.uint8, np.bool_, np.complex128])
ANYTHING = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.sampled_from([HUGE, 10**30, -1, 0, 1, 2, 3, 2**63]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.complex_numbers(allow_nan=True),
    st.text(max_size=6),
    st.binary(max_size=4),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
    st.lists(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), max_size=3),
    st.lists(st.lists(st.one_of(st.floats(-1, 1), st.text(max_size=1)), max_size=3), max_size=3),
    hnp.arrays(_dtypes, _shapes),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.builds(object),
    st.fractions(),
    st.decimals(allow_nan=True),
    st.lists(st.integers(-(2**80), 2**80), min_size=3, max_size=3),
    st.builds(np.float16, st.floats(width=16)),
    st.builds(np.longdouble, st.floats()),
    st.tuples(st.floats(), st.floats(), st.floats()),
)


def _value_for(api: Api, name: str, data: st.DataObject) -> Any:
    kind = api.kinds[name]
    known = [
        v
        for v in (*kind.wrong_types, *kind.bad_values, *kind.good_values)
        if not isinstance(v, Where)
    ]
    pools = [ANYTHING] + ([st.sampled_from(known)] if known else [])
    return data.draw(st.one_of(pools), label=name)


def _verdict(api: Api, name: str, value: Any, tmp: Path) -> str | None:
    verdict = api.kinds[name].classify(value)
    if verdict != "ok":
        return verdict
    for group in api.same_length:  # an array alone fine, but of another length than the rest
        if name in group and value is not None:
            n = len(np.atleast_2d(np.asarray(value, dtype=float)))
            others = api.good(tmp)
            if any(len(others[o]) != n for o in group if o != name and o in others):
                return "value"
    return verdict


@pytest.fixture(scope="module")
def fuzz_tmp(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


def _fuzzed() -> list[Any]:
    """(function, scenes): each row on the paper's scene, and each that takes a model on a
    general scene Hypothesis draws (as many examples each: the paper's stay as many)."""
    cases = []
    for api in APIS:
        if api.kinds:
            cases.append(pytest.param(api.name, ("paper",), id=f"{api.name}-paper"))
            if not api.scene_free:
                cases.append(pytest.param(api.name, FUZZED, id=f"{api.name}-general"))
    return cases


@pytest.mark.parametrize(("function", "scenes"), _fuzzed())
@SETTINGS
@given(data=st.data())
def test_any_value_is_taken_or_refused_as_promised(
    function: str, scenes: tuple[str, ...], fuzz_tmp: Path, data: st.DataObject
) -> None:
    where = data.draw(st.sampled_from(scenes), label="scene") if len(scenes) > 1 else scenes[0]
    api = table(where)[function]
    tmp = fuzz_tmp
    name = data.draw(st.sampled_from(sorted(api.kinds)), label="argument")
    value = _value_for(api, name, data)
    verdict = _verdict(api, name, value, tmp)
    assume(verdict is not None and not (verdict == "ok" and api.costly))
    refused: Rpr3genError | None = None
    try:
        result = _call(api, tmp, **{name: value})
    except Rpr3genError as exc:
        refused = exc
    if refused is None:
        assert verdict == "ok", f"{api.name}({name}={value!r}) answered instead of refusing"
        if api.kinds[name].rows and value is not None:  # the answer of the float64 array
            _same(result, _call(api, tmp, **{name: np.array(value, dtype=float)}))
        return
    assert "\n" not in str(refused), str(refused)
    assert isinstance(refused, FAMILIES), repr(refused)
    if verdict == "type":
        assert isinstance(refused, InputTypeError), repr(refused)
        _assert_names(refused, name)
    elif verdict == "value":
        assert isinstance(refused, api.kinds[name].value_error), repr(refused)
        assert isinstance(refused, ValueError | OSError), repr(refused)
        assert not isinstance(refused, InputTypeError), repr(refused)
        _assert_names(refused, name)
    else:
        assert isinstance(refused, REFUSALS.get(api.name, ())), repr(refused)
