"""Hostile input to every public Python function: the README's classes, the argument named,
never a crash, never a silent wrong answer (issue 23).

One row of :data:`APIS` per function of ``rpr3gen.__all__`` (and the public methods); the cases
are drawn from each argument's :class:`~hostile_kinds.Kind`: values of the wrong type
(``InputTypeError``), bad values and shapes (``InputError``, or the function's own class),
good values (the same answer as the plain float64 array), arrays of different lengths, NaN
rows, empty and one-row inputs; then Hypothesis draws any value for any argument and checks
the outcome against the kind's oracle. A new function joins by adding its row.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hostile_kinds import (
    HUGE,
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
from rpr3gen.errors import (
    GridError,
    IdentificationError,
    InputError,
    InputTypeError,
    ModelError,
    Rpr3genError,
    TrajectoryError,
)
from rpr3gen.identification import Fit, inertial_parameters
from rpr3gen.structure import Structure

SETTINGS = settings(
    max_examples=20,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)

# -- data: small, valid, fast ---------------------------------------------------------------

MODEL = rpr3gen.load_model()
_RNG = np.random.default_rng(23)
N_FIT = 40  # identify: enough equations, well conditioned (condition number about 40)
Q_FIT = _RNG.uniform(-1.0, 1.0, (N_FIT, 3)) * [0.03, 0.03, 0.2]
QD_FIT = _RNG.normal(0.0, 1.0, (N_FIT, 3)) * [0.3, 0.3, 1.0]
QDD_FIT = _RNG.normal(0.0, 1.0, (N_FIT, 3)) * [1.5, 1.5, 5.0]
TAU_FIT = rpr3gen.regressor(MODEL, Q_FIT, QD_FIT, QDD_FIT) @ inertial_parameters(MODEL)
TAU_FIT = TAU_FIT + rpr3gen.payload_efforts(MODEL, Q_FIT)
Q, QD, QDD, TAU = Q_FIT[:4], QD_FIT[:4], QDD_FIT[:4], TAU_FIT[:4]
QA = rpr3gen.actuator_coordinates(MODEL, Q[:2])
FIT = rpr3gen.identify(MODEL, Q_FIT, QD_FIT, QDD_FIT, TAU_FIT)
WMAP = rpr3gen.workspace(MODEL, 0.0, 2)
EVALUATOR = rpr3gen.SampleEvaluator(MODEL, backend="numpy")
T6 = np.linspace(0.0, 0.5, 6)
Q6 = np.column_stack([0.01 * T6, -0.01 * T6, 0.1 * T6])
PAPER_TOML = Path(rpr3gen.__file__).parent / "models" / "paper.toml"


def _paper_copy(tmp: Path) -> str:
    return str(shutil.copy(PAPER_TOML, tmp / "paper.toml"))


def _paper_data() -> dict:
    import tomllib

    return tomllib.loads(Path(PAPER_TOML).read_text())


def _positions_csv(tmp: Path) -> str:
    path = tmp / "positions.csv"
    table = np.column_stack([T6, Q6]).tolist()
    lines = ["t,x,y,phi", *(",".join(repr(v) for v in row) for row in table)]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


# -- kinds particular to a few functions ----------------------------------------------------

MODEL_KIND = instance(rpr3gen.Model, MODEL)
MOTION = rows(3)


def _backend(value: Any) -> str | None:
    if not isinstance(value, str):
        return "type"
    return {"numpy": "ok", "c": None}.get(value, "value")  # "c" compiles: other tests do


BACKEND = dataclasses.replace(choice("numpy"), classify=_backend)
THREADS = optional(count(1, 4))
CONDITIONING = number(least=0.0, below=1.0, good=(0.0, 0.5))
FUNCTIONS = tuple(sorted(rpr3gen.manifest.load("revolute").functions))
MOTION_FUNCTIONS = ("actuator_efforts", "inverse_dynamics", "regressor")  # inputs q, qd, qdd


def _motion_function(value: Any) -> str | None:
    if not isinstance(value, str):
        return "type"
    return "ok" if value in MOTION_FUNCTIONS else None if value in FUNCTIONS else "value"


FUNCTION = Kind(
    "function",
    _motion_function,
    wrong_types=(None, 5, ["inverse_dynamics"]),
    bad_values=("nothing", "", "inverse-dynamics"),
    good_values=MOTION_FUNCTIONS,
)


def _inputs(value: Any) -> str | None:
    if not isinstance(value, list | tuple):
        return "type"
    if len(value) != 3:
        return "value"
    verdicts = [MOTION.classify(v) for v in value]
    if verdicts != ["ok"] * 3:
        return None  # the first bad one decides
    lengths = {len(np.atleast_2d(np.asarray(v, dtype=float))) for v in value}
    return "ok" if len(lengths) == 1 else "value"


INPUTS = Kind(
    "inputs",
    _inputs,
    wrong_types=(Q, "q", None, {"q": Q}),
    bad_values=((Q,), (Q, Q, Q, Q), (Q, QD[:3], QDD)),
    good_values=((Q, QD, QDD), [Q, QD, QDD]),
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
    bad_values=([0.0, 0.0, 1.0, 2.0], [0.0, math.nan, 1.0, 2.0], np.zeros((4, 1)), []),
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


GRID = Kind(
    "grid",
    _grid,
    wrong_types=(None, 5, ["mass.m3"]),
    bad_values=(
        {},
        {"mass.m9": [1.0]},
        {"mass.m3": "heavy"},
        {"mass.m3": [-1.0]},
        {"mass.m3": {"start": 1.0, "stop": 2.0, "num": HUGE}},
        {
            f"mass.{key}": [1.0 + k for k in range(100)]  # 10^12 designs
            for key in ("m1", "m2", "m3", "J1", "J2", "J3")
        },
    ),
    value_error=GridError,
)
BASE_MODEL = Kind(
    "base model",
    lambda v: None if v is None or isinstance(v, str | Path | dict) else "type",
    wrong_types=(5, ["paper.toml"], MODEL),
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
PARAMS = Kind(
    "params",
    lambda v: None if isinstance(v, dict) else "type",
    wrong_types=("params", 5, None, [1.0]),
    bad_values=(
        {},
        {**MODEL.params, "m1": math.nan},
        {**MODEL.params, "extra": 1.0},
    ),
    value_error=ModelError,
)
GENERATED = Kind(
    "generated folder",
    lambda v: None if isinstance(v, str | Path) else "type",
    wrong_types=(5, b"gen", ["gen"]),
    bad_values=(Where("missing", lambda tmp: str(tmp / "nothing")), ""),
    value_error=Rpr3genError,  # the environment: a plain Rpr3genError (README)
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

# -- the table ------------------------------------------------------------------------------

MOTION3 = (("q", "qd", "qdd"),)


def _motion(n: int = 4) -> dict[str, Any]:
    return {"model": MODEL, "q": Q[:n], "qd": QD[:n], "qdd": QDD[:n]}


def _api(name: str, **fields: Any) -> Api:
    call = fields.pop("call", None) or getattr(rpr3gen, name)
    return Api(name=name, call=call, **fields)


APIS: tuple[Api, ...] = (
    _api(
        "inverse_dynamics",
        good=lambda tmp: _motion(),
        kinds={
            "model": MODEL_KIND,
            "q": MOTION,
            "qd": MOTION,
            "qdd": MOTION,
            "backend": BACKEND,
            "progress": flag(),
            "threads": THREADS,
        },
        same_length=MOTION3,
    ),
    _api(
        "evaluate",
        good=lambda tmp: {"model": MODEL, "function": "inverse_dynamics", "inputs": (Q, QD, QDD)},
        kinds={
            "model": MODEL_KIND,
            "function": FUNCTION,
            "inputs": INPUTS,
            "backend": BACKEND,
            "progress": flag(),
            "threads": THREADS,
        },
    ),
    _api(
        "actuator_coordinates",
        good=lambda tmp: {"model": MODEL, "q": Q},
        kinds={"model": MODEL_KIND, "q": MOTION, "backend": BACKEND},
    ),
    _api(
        "actuator_jacobian",
        good=lambda tmp: {"model": MODEL, "q": Q},
        kinds={"model": MODEL_KIND, "q": MOTION, "backend": BACKEND},
    ),
    _api(
        "payload_efforts",
        good=lambda tmp: {"model": MODEL, "q": Q},
        kinds={"model": MODEL_KIND, "q": MOTION, "backend": BACKEND},
    ),
    _api(
        "actuator_efforts",
        good=lambda tmp: _motion(),
        kinds={"model": MODEL_KIND, "q": MOTION, "qd": MOTION, "qdd": MOTION, "backend": BACKEND},
        same_length=MOTION3,
    ),
    _api(
        "regressor",
        good=lambda tmp: _motion(),
        kinds={
            "model": MODEL_KIND,
            "q": MOTION,
            "qd": MOTION,
            "qdd": MOTION,
            "identical_legs": flag(),
            "backend": BACKEND,
        },
        same_length=MOTION3,
    ),
    _api(
        "base_regressor",
        good=lambda tmp: _motion(),
        kinds={
            "model": MODEL_KIND,
            "q": MOTION,
            "qd": MOTION,
            "qdd": MOTION,
            "identical_legs": flag(),
            "backend": BACKEND,
        },
        same_length=MOTION3,
    ),
    _api(
        "jacobian_rate",
        good=lambda tmp: {"model": MODEL, "q": Q, "qd": QD},
        kinds={"model": MODEL_KIND, "q": MOTION, "qd": MOTION, "backend": BACKEND},
        same_length=(("q", "qd"),),
    ),
    _api(
        "task_space_dynamics",
        good=lambda tmp: {"model": MODEL, "q": Q, "qd": QD},
        kinds={"model": MODEL_KIND, "q": MOTION, "qd": MOTION, "backend": BACKEND},
        same_length=(("q", "qd"),),
    ),
    _api(
        "platform_velocity",
        good=lambda tmp: {"model": MODEL, "q": Q, "qa_dot": QD},
        kinds={"model": MODEL_KIND, "q": MOTION, "qa_dot": MOTION, "backend": BACKEND},
        same_length=(("q", "qa_dot"),),
    ),
    _api(
        "forward_dynamics",
        good=lambda tmp: {"model": MODEL, "q": Q, "qd": QD, "tau": TAU},
        kinds={"model": MODEL_KIND, "q": MOTION, "qd": MOTION, "tau": MOTION, "backend": BACKEND},
        same_length=(("q", "qd", "tau"),),
    ),
    _api(
        "assembly_modes",
        good=lambda tmp: {"model": MODEL, "qa": QA[0]},
        kinds={"model": MODEL_KIND, "qa": reading(3), "backend": BACKEND},
    ),
    _api(
        "forward_kinematics",
        good=lambda tmp: {"model": MODEL, "qa": QA, "near": Q[:2]},
        kinds={"model": MODEL_KIND, "qa": MOTION, "near": MOTION, "backend": BACKEND},
        same_length=(("qa", "near"),),
    ),
    _api(
        "platform_radius",
        good=lambda tmp: {"model": MODEL},
        kinds={"model": MODEL_KIND},
    ),
    _api(
        "base_parameters",
        good=lambda tmp: {"model": MODEL},
        kinds={"model": MODEL_KIND, "identical_legs": flag()},
    ),
    _api(
        "inertial_parameters",
        good=lambda tmp: {"model": MODEL},
        kinds={"model": MODEL_KIND, "identical_legs": flag()},
    ),
    _api(
        "identify",
        good=lambda tmp: {"model": MODEL, "q": Q_FIT, "qd": QD_FIT, "qdd": QDD_FIT, "tau": TAU_FIT},
        kinds={
            "model": MODEL_KIND,
            "q": MOTION,
            "qd": MOTION,
            "qdd": MOTION,
            "tau": MOTION,
            "friction": flag(),
            "identical_legs": flag(),
            "weights": optional(reading(3, positive=True)),
            "max_condition": number(greater=1.0, finite=False, good=(1e3, math.inf)),
            "t": optional(TIMES),
            "backend": BACKEND,
        },
        same_length=(("q", "qd", "qdd", "tau", "t"),),
        nan_rows=False,
    ),
    _api(
        "excite",
        good=lambda tmp: {"model": MODEL, "harmonics": 1, "samples": 10, "max_iterations": 1},
        kinds={
            "model": MODEL_KIND,
            "harmonics": count(1, 1),
            "period": number(greater=0.0),
            "samples": count(10, 12),
            "min_conditioning": CONDITIONING,
            "max_acceleration": reading(2, positive=True),
            "identical_legs": flag(),
            "friction": flag(),
            "seed": count(0, 2, huge_refused=False),
            "max_iterations": count(1, 1, most=2**31 - 1),
        },
        costly=True,
    ),
    _api(
        "workspace",
        good=lambda tmp: {"model": MODEL, "resolution": 2},
        kinds={
            "model": MODEL_KIND,
            "phi": number(good=(0.0, -1e-3)),
            "resolution": count(2, 3),
            "min_conditioning": CONDITIONING,
        },
    ),
    _api(
        "write_workspace",
        good=lambda tmp: {"wmap": WMAP, "outdir": str(tmp / "ws")},
        kinds={"wmap": instance(rpr3gen.WorkspaceMap), "outdir": output_path(folder=True)},
        costly=True,
    ),
    _api(
        "sweep",
        good=lambda tmp: {
            "model": None,
            "grid": {"mass.m3": [3.0]},
            "trajectories": ["rotation"],
            "workers": 0,
            "samples": 3,
            "area_resolution": 0,
        },
        kinds={
            "model": BASE_MODEL,
            "grid": GRID,
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
        good=lambda tmp: {},
        kinds={
            "path": optional(
                input_file(".toml", value_error=ModelError, good=Where("paper", _paper_copy))
            ),
            "generated": optional(GENERATED),
        },
    ),
    _api(
        "model_from_dict",
        good=lambda tmp: {"data": _paper_data(), "source": "paper"},
        kinds={
            "data": Kind(
                "model data (a mapping)",
                lambda v: (
                    "ok"
                    if isinstance(v, dict) and v == _paper_data()
                    else ("value" if isinstance(v, dict) else "type")
                ),
                # Bad contents are ModelErrors naming the key (tests/test_model.py).
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
    ),
    _api(
        "Model",
        good=lambda tmp: (
            {f.name: getattr(MODEL, f.name) for f in dataclasses.fields(MODEL)}
            | {"params": dict(MODEL.params)}
        ),
        kinds={
            "name": Kind(
                "name",
                lambda v: "ok" if isinstance(v, str) else "type",
                wrong_types=(3, None, ["paper"]),
            ),
            "actuation": dataclasses.replace(
                choice("revolute", "prismatic"), value_error=ModelError
            ),
            "params": PARAMS,
            "stroke": Kind(
                "stroke",
                lambda v: None,
                wrong_types=("wide", 5),
                bad_values=([[0.1, -0.1]] * 3, [[0.0, 1.0]], [[0.0, math.nan]] * 3),
                value_error=ModelError,
            ),
            "generated": optional(GENERATED),
            "structure": optional(
                Kind(
                    "Structure",
                    lambda v: "ok" if isinstance(v, Structure) else "type",
                    wrong_types=("RPR", 1, {"leg": "RPR"}),
                    good_values=(MODEL.structure,),
                )
            ),
            "limits": Kind(
                "limits",
                lambda v: "ok" if v is None else None,
                good_values=(None,),
            ),
        },
    ),
    _api(
        "SampleEvaluator",
        good=lambda tmp: {"model": MODEL, "backend": "numpy"},
        kinds={"model": MODEL_KIND, "backend": BACKEND, "function": choice(*FUNCTIONS)},
    ),
    _api(
        "SampleEvaluator.evaluate",
        call=lambda q, qd, qdd: EVALUATOR.evaluate(q, qd, qdd),
        good=lambda tmp: {"q": Q[0], "qd": QD[0], "qdd": QDD[0]},
        kinds={"q": reading(3), "qd": reading(3), "qdd": reading(3)},
    ),
    _api(
        "Trajectory",
        good=lambda tmp: {"t": T6[:4], "q": Q, "qd": QD, "qdd": QDD},
        kinds={"t": T_KIND, "q": EXACT_ROWS, "qd": EXACT_ROWS, "qdd": EXACT_ROWS},
    ),
    _api(
        "Trajectory.from_positions",
        call=rpr3gen.Trajectory.from_positions,
        good=lambda tmp: {"t": T6, "q": Q6},
        kinds={
            "t": dataclasses.replace(
                T_KIND,
                classify=lambda v: None,
                bad_values=([0.0, 0.0, 1.0, 2.0, 3.0, 4.0], [0.0, math.nan, 1.0, 2.0, 3.0, 4.0]),
            ),
            "q": dataclasses.replace(EXACT_ROWS, bad_values=(np.zeros((6, 2)), np.zeros(3))),
            "smoothing": number(least=0.0, most=1e100, good=(0.0,)),
            "source": Kind("source", lambda v: "ok" if isinstance(v, str) else "type"),
        },
    ),
    _api(
        "Fit.predict",
        call=FIT.predict,
        good=lambda tmp: {"q": Q, "qd": QD, "qdd": QDD},
        kinds={"q": MOTION, "qd": MOTION, "qdd": MOTION},
        same_length=MOTION3,
    ),
)
"""Every public function, its valid call and its arguments' kinds."""

#: What may be refused although every argument is valid alone: a pose out of reach, data that
#: do not identify, a reading the generated code refuses (documented refusals, not crashes).
REFUSALS: dict[str, tuple[type[Exception], ...]] = {
    "identify": (InputError, IdentificationError),
    "excite": (IdentificationError,),
    "SampleEvaluator.evaluate": (Rpr3genError,),
    "Trajectory.from_positions": (TrajectoryError,),
    "Trajectory": (TrajectoryError,),
}

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


# -- the cases ------------------------------------------------------------------------------


def _arguments(attribute: str) -> list[Any]:
    """(api, argument) pairs whose kind has values of ``attribute``; one test case each, which
    tries every value (a case per value would cost pytest's overhead a thousand times). Good
    values of a costly function are left to its own tests."""
    return [
        pytest.param(api, name, id=f"{api.name}-{name}")
        for api in APIS
        for name, kind in api.kinds.items()
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


@pytest.mark.parametrize(("api", "name"), _arguments("wrong_types"))
def test_a_wrong_type_is_an_input_type_error_naming_it(api: Api, name: str, tmp_path: Path) -> None:
    def check(value: Any) -> None:
        with pytest.raises(InputTypeError) as info:
            _call(api, tmp_path, **{name: value})
        _assert_names(info.value, name)

    _every(api.kinds[name].wrong_types, check)


@pytest.mark.parametrize(("api", "name"), _arguments("bad_values"))
def test_a_bad_value_is_the_promised_error_naming_it(api: Api, name: str, tmp_path: Path) -> None:
    def check(value: Any) -> None:
        with pytest.raises(Rpr3genError) as info:
            _call(api, tmp_path, **{name: value})
        assert isinstance(info.value, api.kinds[name].value_error), repr(info.value)
        assert not isinstance(info.value, InputTypeError), repr(info.value)
        assert isinstance(info.value, ValueError) or type(info.value) is Rpr3genError
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


@pytest.mark.parametrize(("api", "name"), _arguments("good_values"))
def test_a_good_value_is_taken_as_its_float64_array(api: Api, name: str, tmp_path: Path) -> None:
    def check(value: Any) -> None:
        result = _call(api, tmp_path, **{name: value})
        if api.kinds[name].rows and value is not None:
            _same(result, _call(api, tmp_path, **{name: np.array(value, dtype=float)}))

    _every(api.kinds[name].good_values, check)


def _row_groups(api: Api) -> list[tuple[str, ...]]:
    arrays = [n for n, k in api.kinds.items() if k.rows and not k.one_reading and n != "t"]
    return [tuple(arrays)] if arrays else []


ROWED = [api for api in APIS if _row_groups(api) and api.name != "Trajectory"]


@pytest.mark.parametrize("api", ROWED)
@pytest.mark.parametrize(
    "like",
    [
        np.ndarray.tolist,
        lambda a: tuple(map(tuple, a)),
        lambda a: a.astype(np.float32).astype(object),
    ],
)
def test_an_array_like_is_taken_as_its_float64_array(api: Api, like: Any, tmp_path: Path) -> None:
    (names,) = _row_groups(api)
    good = api.good(tmp_path)
    given_ = {n: like(np.asarray(good[n])) for n in names}
    floats = {n: np.array(given_[n], dtype=float) for n in names}
    _same(_call(api, tmp_path, **given_), _call(api, tmp_path, **floats))


@pytest.mark.parametrize("api", [a for a in APIS if a.same_length])
def test_arrays_of_different_lengths_are_refused_naming_them(api: Api, tmp_path: Path) -> None:
    for group in api.same_length:
        present = [n for n in group if n != "t"]
        good = api.good(tmp_path)
        longer = np.vstack([good[present[0]], good[present[0]][:1]])
        with pytest.raises(InputError) as info:
            _call(api, tmp_path, **{present[0]: longer})
        for name in present:
            assert name in str(info.value), str(info.value)


@pytest.mark.parametrize("api", ROWED)
def test_one_row_and_one_sample_are_the_same_answer(api: Api, tmp_path: Path) -> None:
    (names,) = _row_groups(api)
    good = api.good(tmp_path)
    if not api.nan_rows:  # a function that needs many samples refuses one
        with pytest.raises(IdentificationError, match="give more samples"):
            _call(api, tmp_path, **{n: np.asarray(good[n])[0] for n in names})
        return
    one = _call(api, tmp_path, **{n: np.asarray(good[n])[0] for n in names})
    _same(one, _call(api, tmp_path, **{n: np.asarray(good[n])[:1] for n in names}))


@pytest.mark.parametrize("api", ROWED)
def test_empty_input_is_an_empty_answer_or_refused(api: Api, tmp_path: Path) -> None:
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


@pytest.mark.parametrize("api", ROWED)
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_non_finite_row_is_a_nan_row_and_the_others_are_kept(
    api: Api, bad: float, tmp_path: Path
) -> None:
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


def test_one_reading_refuses_two_rather_than_use_the_first() -> None:
    with pytest.raises(InputError, match=r"qa: must have shape \(3,\), got \(2, 3\)"):
        rpr3gen.assembly_modes(MODEL, QA)


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


@pytest.mark.parametrize("api", [a for a in APIS if a.kinds], ids=lambda a: a.name)
@SETTINGS
@given(data=st.data())
def test_any_value_is_taken_or_refused_as_promised(
    api: Api, fuzz_tmp: Path, data: st.DataObject
) -> None:
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
    if verdict == "type":
        assert isinstance(refused, InputTypeError), repr(refused)
        _assert_names(refused, name)
    elif verdict == "value":
        assert isinstance(refused, api.kinds[name].value_error), repr(refused)
        assert not isinstance(refused, InputTypeError), repr(refused)
        _assert_names(refused, name)
    else:
        assert isinstance(refused, REFUSALS.get(api.name, ())), repr(refused)
