"""The generated C of the tracked forward kinematics (``rpr3_forward_kinematics``), both variants.

Through the runtime (``rpr3gen.evaluate`` and ``SampleEvaluator``, ``backend="c"``), against
the true poses and against the NumPy prototype ``fk_reference.tracked_forward_kinematics``, which
the C ports. A test-only build (:func:`_traced`) renders the same body with ``trace=True`` and
other numbers in its ``c_context``: it then reports, per call, the Newton steps and whether the
pose came from Newton, the fallback or nothing, which the generated code cannot say.
"""

from __future__ import annotations

import ctypes
import dataclasses
import math
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import fk_reference as fk
import newton_euler as ne
import numpy as np
import pytest
from rpr3gen_derive.codegen.spec import FunctionSpec
from rpr3gen_derive.planar import generate, paper, registry, structures
from rpr3gen_derive.planar.registry import direct_kinematics as dk_specs

import rpr3gen
from rpr3gen.model import Model

ACTUATIONS = ("revolute", "prismatic")
COORDINATE = {"revolute": "phi10", "prismatic": "lambda21"}
HOW = {0: "newton", 1: "fallback", 2: "none"}


def _model(params: dict, actuation: str) -> Model:
    return Model(name="test", actuation=actuation, params=params, source="<test>")


def _qa(params: dict, actuation: str, q) -> np.ndarray:
    """Actuator coordinates of the poses ``q`` by the independent inverse kinematics."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    kin = ne.kinematics(params, q, np.zeros_like(q))
    return np.stack([kin[leg][COORDINATE[actuation]] for leg in ne.LEGS], axis=1)


def _fk(model: Model, qa, near) -> tuple[np.ndarray, np.ndarray]:
    (q,), codes = rpr3gen.evaluate(model, "forward_kinematics", (qa, near), backend="c")
    return q, codes


def _same_pose(geom: fk.Geometry, a, b, tol: float) -> bool:
    return fk.distance(geom, a, b) < tol


# ----------------------------------------------------------------------------------------------
# A test-only build: the body rendered with trace=True (and other numbers), compiled with a
# harness that keeps the last call's trace.

HARNESS = """\
static int trace_steps = -1, trace_how = -1;
static void rpr3_fk_trace(int steps, int how);
#include "rpr3.c"
static void rpr3_fk_trace(int steps, int how)
{
    trace_steps = steps;
    trace_how = how;
}
void last_trace(int out[2]);
void last_trace(int out[2])
{
    out[0] = trace_steps;
    out[1] = trace_how;
}
"""
FK_KERNELS = (
    "actuator_coordinates",
    "actuator_coordinates_jacobian",
    "actuator_coordinates_hessian",
    "jacobian_rate",
    "assembly_modes",
    "pose_from_angle",
    "locked_circles",
)

Traced = Callable[[dict, np.ndarray, np.ndarray], tuple[int, np.ndarray, int, str]]


def _build(folder: Path, actuation: str, **context: object) -> ctypes.CDLL:
    def builder(structure: structures.Structure) -> FunctionSpec:
        spec = dk_specs.forward_kinematics(structure)
        values = {**dict(spec.c_context), "trace": True, **context}
        return dataclasses.replace(spec, c_context=tuple(values.items()))

    functions = {name: registry.FUNCTIONS[name] for name in FK_KERNELS}
    fkj = {"forward_kinematics_jacobian": registry.FUNCTIONS["forward_kinematics_jacobian"]}
    files = generate.render(
        (structures.from_variant(actuation),), {**functions, "forward_kinematics": builder, **fkj}
    )
    folder.mkdir(parents=True)
    for name in ("rpr3.c", "rpr3.h"):
        (folder / name).write_text(files[f"{actuation}/{name}"])
    (folder / "harness.c").write_text(HARNESS)
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler is required by the test suite"
    subprocess.run(
        [cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", "-fPIC", "-shared",
         "harness.c", "-o", "libfk.so", "-lm"],
        cwd=folder, check=True, capture_output=True, text=True,
    )  # fmt: skip
    return ctypes.CDLL(str(folder / "libfk.so"))


@pytest.fixture(scope="module")
def traced(tmp_path_factory) -> Callable[..., Traced]:
    """``traced(actuation, **context)``: a function ``(params, qa, q_near) -> (code, q, steps,
    how)`` of a test-only build, built once per actuation and context; its ``library`` holds
    the build's other functions (``rpr3_forward_kinematics_jacobian`` calls the traced body)."""
    libraries: dict[tuple, ctypes.CDLL] = {}

    def get(actuation: str, **context: object) -> Traced:
        key = (actuation, *sorted(context.items()))
        if key not in libraries:
            folder = tmp_path_factory.mktemp("fk") / "build"
            libraries[key] = _build(folder, actuation, **context)
        lib = libraries[key]

        def call(
            params: dict, qa: np.ndarray, near: np.ndarray
        ) -> tuple[int, np.ndarray, int, str]:
            p = np.array([params[name] for name in paper.PARAM_NAMES], dtype=np.float64)
            qa = np.ascontiguousarray(qa, dtype=np.float64)
            near = np.ascontiguousarray(near, dtype=np.float64)
            q = np.full(3, np.nan)
            trace = (ctypes.c_int * 2)(-1, -1)
            ptr = ctypes.c_void_p
            code = lib.rpr3_forward_kinematics(
                ptr(p.ctypes.data), ptr(qa.ctypes.data), ptr(near.ctypes.data), ptr(q.ctypes.data)
            )
            lib.last_trace(trace)
            return code, q, trace[0], HOW.get(trace[1], "not traced")

        call.library = lib  # type: ignore[attr-defined]  # its other functions, for a test
        return call

    return get


# ----------------------------------------------------------------------------------------------
# A nearby reference: Newton, to round-off.


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_recovers_the_pose_from_a_nearby_reference(actuation: str) -> None:
    rng = np.random.default_rng(31)
    checked = 0
    for params in fk.robots(rng, 10):
        geom = fk.Geometry.from_params(params)
        poses = np.array(
            [p for p in fk.random_poses(rng, 12) if ne.well_conditioned(params, p, 0.05, 1e3)]
        )
        if len(poses) == 0:
            continue
        near = poses + rng.normal(0, [0.003, 0.003, 0.02], poses.shape)
        # Only the poses the generated code evaluates (reach above its floor) are modes.
        keep = np.array([fk.reach(geom, p) > fk.MIN_REACH for p in poses])
        poses, near = poses[keep], near[keep]
        if len(poses) == 0:
            continue
        qa = _qa(params, actuation, poses)
        q, codes = _fk(_model(params, actuation), qa, near)
        assert (codes == 0).all()
        assert np.abs(q - poses).max() < 1e-10
        for row, qa_n, near_n in zip(q, qa, near, strict=True):
            ref = fk.tracked_forward_kinematics(geom, actuation, qa_n, near_n)
            assert ref.status == "newton"
            assert _same_pose(geom, row, ref.q, 1e-12)
        checked += len(poses)
    assert checked > 50


def _track(evaluator: rpr3gen.SampleEvaluator, qa: np.ndarray, q0, predict: bool):
    """Track ``qa`` sample by sample through the single call: the reference is the previous
    solution or the prediction ``2 q[k-1] - q[k-2]``. Returns the solutions, references, codes."""
    prev = prev2 = np.array(q0, dtype=float)
    found, nears, codes = [], [], []
    for row in qa:
        near = 2 * prev - prev2 if predict else prev
        evaluator.qa[:] = row
        evaluator.q_near[:] = near
        codes.append(evaluator())
        found.append(evaluator.q.copy())
        nears.append(near)
        prev2, prev = prev, evaluator.q.copy()
    return np.array(found), np.array(nears), np.array(codes)


@pytest.mark.parametrize("actuation", ACTUATIONS)
@pytest.mark.parametrize("predict", [False, True], ids=["previous", "predicted"])
def test_tracks_the_paper_trajectories(actuation: str, predict: bool) -> None:
    """Encoders every 1 ms; the single call and the batch (same references) agree bit for bit."""
    model = rpr3gen.load_model()
    model = dataclasses.replace(model, actuation=actuation)
    params = dict(model.params)
    evaluator = rpr3gen.SampleEvaluator(model, backend="c", function="forward_kinematics")
    for kind in ("rotation", "rectilinear"):
        _, q, _, _ = ne.paper_motion(kind, samples=3001)
        qa = _qa(params, actuation, q)
        found, nears, codes = _track(evaluator, qa, q[0], predict)
        assert (codes == 0).all()
        assert np.abs(found - q).max() < 1e-10
        batch, batch_codes = _fk(model, qa, nears)
        assert (batch_codes == 0).all()
        assert np.array_equal(batch, found)  # bit for bit


def test_tracks_through_a_parallel_singularity() -> None:
    """A random motion that crosses det J = 0 (revolute actuation): with the predicted reference
    the C follows the robot into the other aspect, as the prototype does."""
    t = np.arange(0.0, 2.0, 1e-3)
    robot, q, _, _ = ne.random_case(8, t)
    params = robot["params"]
    geom = fk.Geometry.from_params(params)
    dets = [fk.det3(fk.actuator_jacobian(geom, "revolute", row)) for row in q]
    assert min(dets) < 0 < max(dets)
    evaluator = rpr3gen.SampleEvaluator(_model(params, "revolute"), function="forward_kinematics")
    found, _, codes = _track(evaluator, _qa(params, "revolute", q), q[0], predict=True)
    assert (codes == 0).all()
    assert np.abs(found - q).max() < 1e-7


# ----------------------------------------------------------------------------------------------
# Any reference: the same mode as the prototype; far references; the fallback.


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_agrees_with_the_prototype(actuation: str) -> None:
    """References near and far (up to the other modes' basins): the same status (no mode or a
    mode) and the same mode as ``fk_reference.tracked_forward_kinematics``."""
    rng = np.random.default_rng(32)
    statuses = []
    for params in fk.robots(rng, 12):
        geom = fk.Geometry.from_params(params)
        poses = fk.random_poses(rng, 10)
        qa = _qa(params, actuation, poses)
        for spread in (0.003, 0.03, 0.3):
            near = poses + rng.normal(0, 1, poses.shape) * spread * np.array([1.0, 1.0, 10.0])
            q, codes = _fk(_model(params, actuation), qa, near)
            for row, code, qa_n, near_n in zip(q, codes, qa, near, strict=True):
                ref = fk.tracked_forward_kinematics(geom, actuation, qa_n, near_n)
                statuses.append(ref.status)
                if ref.status == "none":
                    assert code == 3
                    assert np.isnan(row).all()
                else:
                    assert code == 0
                    assert _same_pose(geom, row, ref.q, 1e-9), (ref, row)
    assert statuses.count("fallback") > 40
    assert statuses.count("newton") > 50


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_a_reference_in_another_modes_basin_gives_that_mode(actuation: str, traced) -> None:
    """Every mode of ``qa`` (the prototype's ``assembly_modes``), and a reference near it but not
    on it (2 cm and 0.1 rad off, phi 2 pi away): that mode comes back, phi next to the
    reference's. Newton converges there or the fallback picks it; both happen."""
    rng = np.random.default_rng(33)
    call = traced(actuation)
    hows, nearest_found, several = [], [], 0
    for params in fk.robots(rng, 10):
        geom = fk.Geometry.from_params(params)
        for pose in fk.random_poses(rng, 6):
            qa = _qa(params, actuation, pose)[0]
            modes = fk.assembly_modes(geom, actuation, qa)
            several += len(modes) > 1
            for mode in modes:
                near = np.array(mode) + rng.choice([-1.0, 1.0], 3) * [0.02, 0.02, 0.1]
                near[2] += 2 * math.pi
                code, q, _, how = call(params, qa, near)
                ref = fk.tracked_forward_kinematics(geom, actuation, qa, near)
                assert code == 0
                assert how == ref.status
                assert _same_pose(geom, q, ref.q, 1e-9)
                assert abs(q[2] - near[2]) <= math.pi
                unwrapped = [(m[0], m[1], fk.unwrap_near(m[2], near[2])) for m in modes]
                nearest = min(unwrapped, key=lambda m: fk.distance(geom, m, near))
                if how == "fallback":
                    assert _same_pose(geom, q, nearest, 1e-9)
                hows.append(how)
                nearest_found.append(_same_pose(geom, q, nearest, 1e-9))
    assert several > 20
    print(
        f"{actuation}: {len(hows)} references, {hows.count('fallback')} fallbacks, "
        f"nearest mode {np.mean(nearest_found):.3f}"
    )
    assert np.mean(nearest_found) > 0.9


@pytest.mark.parametrize("actuation", ACTUATIONS)
@pytest.mark.parametrize("max_iter", [0, 1])
def test_fallback_when_newton_is_cut_short(actuation: str, max_iter: int, traced) -> None:
    """A build whose Newton may take no step (or one): the fallback finds the mode nearest the
    reference, as the prototype with the same ``max_iter`` does, and reports none when there is
    none."""
    rng = np.random.default_rng(34)
    call = traced(actuation, max_iter=max_iter)
    hows = []
    for params in fk.robots(rng, 8):
        geom = fk.Geometry.from_params(params)
        for pose in fk.random_poses(rng, 6):
            qa = _qa(params, actuation, pose)[0]
            near = pose + rng.normal(0, [0.02, 0.02, 0.3])
            code, q, steps, how = call(params, qa, near)
            ref = fk.tracked_forward_kinematics(geom, actuation, qa, near, max_iter=max_iter)
            assert how == ref.status
            assert steps == ref.iterations <= max_iter
            hows.append(how)
            if how == "none":
                assert code == 3
                continue
            assert code == 0
            assert _same_pose(geom, q, ref.q, 1e-9)
            assert abs(q[2] - near[2]) <= math.pi
    assert hows.count("fallback") > 20


@pytest.mark.parametrize("seed", [8, 57])
def test_fallback_across_a_parallel_singularity(seed: int, traced) -> None:
    """Revolute actuation, random motions that cross det J = 0 (``ne.random_case``; seeds 8
    and 57 have crossings), the reference 1 to 300 ms on one side of a crossing and the pose on
    the other: Newton lands in the reference's aspect, or in the other and is rejected, and the
    fallback returns the mode nearest the reference. The C does what the prototype does, both
    ways. (Newton's Chebyshev step lands in the reference's aspect more often than plain
    Newton's did: the references reach 300 ms, not 100, so that the rejection is exercised.)"""
    t = np.arange(0.0, 2.0, 1e-3)
    robot, q, _, _ = ne.random_case(seed, t)
    params = robot["params"]
    geom = fk.Geometry.from_params(params)
    call = traced("revolute")
    dets = np.array([fk.det3(fk.actuator_jacobian(geom, "revolute", row)) for row in q])
    crossings = np.flatnonzero(np.sign(dets[1:]) != np.sign(dets[:-1]))
    assert len(crossings) > 0
    hows = []
    for k in crossings:
        for d1 in (1, 5, 20, 40, 100, 200, 300):
            for d2 in (1, 5, 20, 40, 100, 200, 300):
                for before, after in ((k - d1, k + d2), (k + d2, k - d1)):
                    if not (0 <= before < len(q) and 0 <= after < len(q)):
                        continue
                    qa = _qa(params, "revolute", q[after])[0]
                    code, found, _, how = call(params, qa, q[before])
                    ref = fk.tracked_forward_kinematics(geom, "revolute", qa, q[before])
                    hows.append(how)
                    assert code == 0
                    assert how == ref.status
                    assert _same_pose(geom, found, ref.q, 1e-9)
                    if how == "fallback":
                        modes = fk.revolute_modes(geom, qa)
                        near = q[before]
                        unwrapped = [(m[0], m[1], fk.unwrap_near(m[2], near[2])) for m in modes]
                        nearest = min(unwrapped, key=lambda m: fk.distance(geom, m, near))
                        assert _same_pose(geom, found, nearest, 1e-9)
    assert hows.count("fallback") >= 4


def test_prismatic_special_angles(traced) -> None:
    """The prismatic fallback at phi = pi (the sextic's degree drops) and where the back
    substitution's equations are parallel (two modes of one orientation: line and circle)."""
    rng = np.random.default_rng(14)
    for _ in range(50):  # as in test_control_math: a robot whose D(phi) has real zeros
        params = ne.random_robot(rng)["params"]
        params.update({f"y{leg}3": -params[f"y{leg}3"] for leg in ne.LEGS})
        geom = fk.Geometry.from_params(params)
        d0, dc, ds = fk._harmonics(geom, [0.0, 0.0, 0.0])["det"][0]
        if abs(d0) < 0.9 * math.hypot(dc, ds):
            break
    else:
        pytest.fail("no robot with a real zero of D")
    call = traced("prismatic", max_iter=0)  # always the fallback
    phase = math.atan2(ds, dc)
    parallel = fk.wrap(phase + math.acos(-d0 / math.hypot(dc, ds)))
    for pose in ((0.02, -0.01, math.pi), (0.01, 0.015, parallel)):
        qa = _qa(params, "prismatic", pose)[0]
        near = np.add(pose, [0.001, -0.001, 0.002])
        code, q, _, how = call(params, qa, near)
        assert code == 0
        assert how == "fallback"
        assert _same_pose(geom, q, pose, 1e-9)


# ----------------------------------------------------------------------------------------------
# No mode, non-finite inputs, single call and batch.


def _no_mode_inputs(actuation: str) -> np.ndarray:
    geom = fk.Geometry.from_params(ne.paper_params())
    if actuation == "revolute":
        alpha = np.array(geom.alpha)
        return np.stack(
            [
                0.3 - alpha,  # every leg along 0.3 rad: parallel, G is not fixed
                np.array([0.7, 0.7, 0.7]) - alpha,
                np.array([2.0, -2.0, 0.5]),  # lines that meet no platform
            ]
        )
    return np.array(
        [
            [-geom.offset, 0.0, 0.0],  # a leg of zero length
            [0.0, -geom.offset - 0.01, 0.0],  # below zero
            [0.5, -0.25, -0.25],  # unreachable
            [0.0, 0.0, 5.0],
        ]
    )


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_no_mode_returns_3_and_leaves_the_output(actuation: str) -> None:
    model = dataclasses.replace(rpr3gen.load_model(), actuation=actuation)
    geom = fk.Geometry.from_params(dict(model.params))
    qa = _no_mode_inputs(actuation)
    near = np.zeros_like(qa)
    q, codes = _fk(model, qa, near)
    assert (codes == 3).all()
    assert np.isnan(q).all()
    evaluator = rpr3gen.SampleEvaluator(model, backend="c", function="forward_kinematics")
    for row in qa:
        assert fk.tracked_forward_kinematics(geom, actuation, row, (0, 0, 0)).status == "none"
        evaluator.q[:] = (1.0, 2.0, 3.0)
        evaluator.qa[:] = row
        evaluator.q_near[:] = 0.0
        assert evaluator() == 3
        assert list(evaluator.q) == [1.0, 2.0, 3.0]


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_not_finite_input_returns_1(actuation: str) -> None:
    model = dataclasses.replace(rpr3gen.load_model(), actuation=actuation)
    qa = np.zeros((4, 3))
    near = np.zeros((4, 3))
    qa[0, 1] = np.nan
    near[1, 2] = np.inf
    qa[2, 0] = -np.inf
    q, codes = _fk(model, qa, near)
    assert list(codes) == [1, 1, 1, 0]
    assert np.isnan(q[:3]).all()
    assert np.abs(q[3]).max() < 1e-12
    evaluator = rpr3gen.SampleEvaluator(model, backend="c", function="forward_kinematics")
    evaluator.q[:] = 7.0
    evaluator.qa[:] = (0.0, np.nan, 0.0)
    assert evaluator() == 1
    assert list(evaluator.q) == [7.0, 7.0, 7.0]


@pytest.mark.usefixtures("optimised_c_builds")
@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_single_and_batch_are_bit_identical(actuation: str) -> None:
    """References near and far (Newton and the fallback), and samples with no mode."""
    rng = np.random.default_rng(35)
    counts = np.zeros(4, dtype=int)
    evaluated = 0
    for params in fk.robots(rng, 4):
        model = _model(params, actuation)
        poses = fk.evaluable(fk.Geometry.from_params(params), fk.random_poses(rng, 40))
        evaluated += len(poses)
        qa = np.concatenate([_qa(params, actuation, poses), _no_mode_inputs(actuation)])
        near = np.concatenate(
            [
                poses + rng.normal(0, [0.05, 0.05, 0.5], poses.shape),
                np.zeros((len(qa) - len(poses), 3)),
            ]
        )
        batch, codes = _fk(model, qa, near)
        evaluator = rpr3gen.SampleEvaluator(model, backend="c", function="forward_kinematics")
        for row, code, qa_n, near_n in zip(batch, codes, qa, near, strict=True):
            evaluator.q[:] = np.nan
            evaluator.qa[:] = qa_n
            evaluator.q_near[:] = near_n
            assert evaluator() == code
            assert np.array_equal(evaluator.q, row, equal_nan=True)
        counts += np.bincount(codes, minlength=4)
    assert counts[0] >= evaluated
    assert counts[3] >= 6


def _fk_jacobian(model: Model, qa, near) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    (q, J), codes = rpr3gen.evaluate(model, "forward_kinematics_jacobian", (qa, near), backend="c")
    return q, J, codes


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_forward_kinematics_jacobian_is_fk_then_the_jacobian(actuation: str) -> None:
    """``rpr3_forward_kinematics_jacobian``: the pose and the return code of
    ``rpr3_forward_kinematics``, and the Jacobian of ``rpr3_actuator_coordinates_jacobian`` at
    that pose, bit for bit (``rpr3_actuator_jacobian``'s to round-off); references a few cm and
    half a radian off, inputs with no mode or not finite; the single call the batch's, and a
    failed call leaves both outputs. (The fallback's path, forced, is the next test's.)"""
    rng = np.random.default_rng(36)
    codes_seen = np.zeros(4, dtype=int)
    for params in fk.robots(rng, 3):
        model = _model(params, actuation)
        poses = fk.evaluable(fk.Geometry.from_params(params), fk.random_poses(rng, 40))
        qa = np.concatenate([_qa(params, actuation, poses), _no_mode_inputs(actuation)])
        near = np.concatenate(
            [
                poses + rng.normal(0, [0.05, 0.05, 0.5], poses.shape),
                np.zeros((len(qa) - len(poses), 3)),
            ]
        )
        qa[1, 0] = np.nan
        q, codes = _fk(model, qa, near)
        q2, J2, codes2 = _fk_jacobian(model, qa, near)
        assert np.array_equal(codes2, codes)
        assert np.array_equal(q2, q, equal_nan=True)
        ok = codes == 0
        (_, J), jacobian_codes = rpr3gen.evaluate(
            model, "actuator_coordinates_jacobian", (q[ok],), backend="c"
        )
        assert (jacobian_codes == 0).all()
        assert np.array_equal(J2[ok], J)
        alone = rpr3gen.actuator_jacobian(model, q[ok], backend="c").reshape(-1, 9)
        assert np.max(np.abs(J - alone) / np.max(np.abs(alone), axis=1, keepdims=True)) < 1e-14
        assert np.isnan(J2[~ok]).all()
        evaluator = rpr3gen.SampleEvaluator(
            model, backend="c", function="forward_kinematics_jacobian"
        )
        for k in range(len(qa)):
            evaluator.q[:] = 7.0
            evaluator.J[:] = 7.0
            evaluator.qa[:] = qa[k]
            evaluator.q_near[:] = near[k]
            assert evaluator() == codes[k]
            if codes[k] == 0:
                assert np.array_equal(evaluator.q, q2[k])
                assert np.array_equal(evaluator.J, J2[k])
            else:
                assert (evaluator.q == 7.0).all()
                assert (evaluator.J == 7.0).all()
        codes_seen += np.bincount(codes, minlength=4)
    assert codes_seen[0] >= 100
    assert codes_seen[1] == 3
    assert codes_seen[3] >= 6


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_forward_kinematics_jacobian_after_the_fallback(actuation: str, traced) -> None:
    """With Newton cut to no step (a test-only build, ``max_iter=0``), every pose comes from the
    fallback, whose mode's phi is unwrapped next to the reference: the Jacobian returned is still
    ``rpr3_actuator_coordinates_jacobian``'s at the pose returned, bit for bit."""
    lib = traced(actuation, max_iter=0).library
    rng = np.random.default_rng(37)
    params = dict(rpr3gen.load_model().params)
    geom = fk.Geometry.from_params(params)
    poses = fk.evaluable(geom, fk.random_poses(rng, 40))
    qa = _qa(params, actuation, poses)
    near = poses + rng.normal(0, [0.01, 0.01, 0.1], poses.shape)
    near[:, 2] += 2.0 * np.pi * rng.integers(-2, 3, len(near))  # phi unwrapped by whole turns
    p = np.array([params[name] for name in paper.PARAM_NAMES], dtype=np.float64)
    fallbacks = 0
    for k in range(len(qa)):
        q = np.full(3, np.nan)
        J = np.full(9, np.nan)
        trace = (ctypes.c_int * 2)(-1, -1)
        ptr = ctypes.c_void_p
        args = [ptr(a.ctypes.data) for a in (p, np.ascontiguousarray(qa[k]), near[k].copy())]
        code = lib.rpr3_forward_kinematics_jacobian(*args, ptr(q.ctypes.data), ptr(J.ctypes.data))
        lib.last_trace(trace)
        assert code == 0
        fallbacks += trace[1] == 1
        assert abs(q[2] - near[k, 2]) < np.pi + 1e-9  # unwrapped next to the reference
        expected, qa_back = np.full(9, np.nan), np.full(3, np.nan)
        assert lib.rpr3_actuator_coordinates_jacobian(
            ptr(p.ctypes.data), ptr(q.ctypes.data), ptr(qa_back.ctypes.data),
            ptr(expected.ctypes.data)
        ) == 0  # fmt: skip
        assert np.array_equal(J, expected)
    assert fallbacks == len(qa) >= 15


# ----------------------------------------------------------------------------------------------
# Newton steps, measured in the test-only build.


@pytest.mark.parametrize("actuation", ACTUATIONS)
def test_newton_steps_on_the_paper_trajectories(actuation: str, traced) -> None:
    """Per sample at 1 ms: at most 2 Newton steps from the previous pose, 1 from the prediction,
    never the fallback; the same counts as the prototype's (docs/control-model.md)."""
    params = ne.paper_params()
    geom = fk.Geometry.from_params(params)
    call = traced(actuation)
    for kind in ("rotation", "rectilinear"):
        _, q, _, _ = ne.paper_motion(kind, samples=3001)
        qa = _qa(params, actuation, q)
        for predict, most in ((False, 2), (True, 1)):
            prev = prev2 = q[0]
            steps = []
            for k, row in enumerate(qa):
                near = 2 * prev - prev2 if predict else prev
                code, found, n, how = call(params, row, near)
                assert code == 0
                assert how == "newton"
                steps.append(n)
                if k % 100 == 0:
                    ref = fk.tracked_forward_kinematics(geom, actuation, row, near)
                    assert n == ref.iterations
                prev2, prev = prev, found
            assert max(steps) <= most
            print(f"{kind} {actuation} predict={predict}: mean {np.mean(steps):.3f} steps")
