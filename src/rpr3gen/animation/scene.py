"""What an animation draws, evaluated for every sample of the trajectory (:func:`scene`): the
joint points (the generated ``joint_points``), the actuator efforts, the axes of the prismatic
joints and, optionally, every joint's force."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from rpr3gen import variants
from rpr3gen.backends import evaluate, inverse_dynamics
from rpr3gen.errors import TrajectoryError
from rpr3gen.model import Model
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING, invalid_samples
from rpr3gen.structure import LEGS
from rpr3gen.trajectory import Trajectory


@dataclass(frozen=True)
class Scene:
    """Everything an animation draws, for every sample of the trajectory.

    Attributes:
        model: The robot.
        title: The figure's title.
        t: Sample times, s, shape ``(n,)``.
        q: Platform poses ``(x, y, phi)``, shape ``(n, 3)``.
        points: Joint points, world frame (m), shape ``(n, 3, 3, 2)``: sample, leg (A, B, C),
            joint (1, 2, 3), ``(x, y)``: the generated ``joint_points``.
        efforts: Actuator efforts of legs A, B, C, shape ``(n, 3)``.
        effort_name: Their output family (``tau``; the paper's ``m10`` or ``f21z``).
        effort_unit: ``"N m"`` or ``"N"``.
        slides: The current unit axis (world) of each prismatic joint, shape ``(n, 2)``, by
            ``(leg, joint)``.
        forces: With joint loads, the force of the earlier body on the later one at each joint
            (world, N), shape ``(n, 3, 3, 2)`` like ``points``; else None.
    """

    model: Model
    title: str
    t: np.ndarray
    q: np.ndarray
    points: np.ndarray
    efforts: np.ndarray
    effort_name: str
    effort_unit: str
    slides: Mapping[tuple[str, int], np.ndarray]
    forces: np.ndarray | None = None


def scene(
    model: Model,
    traj: Trajectory,
    *,
    title: str | None = None,
    loads: bool = False,
    backend: str = "numpy",
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
) -> Scene:
    """Evaluate what an animation of ``model`` along ``traj`` draws.

    Args:
        model: The robot, of any structure or format.
        traj: The platform's motion.
        title: The figure's title (default: the model's name and structure).
        loads: Also compute every joint's force (drawn as arrows).
        backend: ``"numpy"`` or ``"c"``, for the generated functions.
        min_conditioning: Refuse poses whose ``conditioning`` is below this, as ``rpr3gen
            simulate`` does.

    Raises:
        TrajectoryError: If a sample is singular, too close to a singularity or outside a joint
            limit (the message names the first one and why).
    """
    out = inverse_dynamics(model, traj.q, traj.qd, traj.qdd, backend=backend)
    thresholds = variants.load(model.structure, model.generated).thresholds
    invalid = invalid_samples(model, traj.q, out, min_conditioning, thresholds)
    if invalid is not None:
        k = invalid.first
        raise TrajectoryError(
            f"t = {traj.t[k]:.6g} s (sample {k + 1} of {len(traj.t)}): {invalid.reason}; "
            "the animation draws valid poses only"
        )
    (flat,), _ = evaluate(model, "joint_points", (traj.q,), backend=backend)
    points = flat.reshape(-1, 3, 3, 2).copy()
    structure = model.structure
    family = structure.effort
    efforts = np.column_stack([out[f"{family}_{leg}"] for leg in LEGS])
    unit = "N m" if structure.actuated_kind == "R" else "N"
    if title is None:
        title = f"{model.name}: {structure.title}"
    forces = _joint_forces(model, out, points) if loads else None
    return Scene(
        model, title, traj.t, traj.q, points, efforts, family, unit, _slides(model, out), forces
    )


def _home_axis(model: Model, leg: str, joint: int) -> np.ndarray:
    """Prismatic joint ``joint``'s unit axis when every joint coordinate is zero (world)."""
    p = model.params
    if model.structure.paper:  # the slide along the leg, at alpha from x0
        angle = p[f"alpha_{leg}"]
        return np.array([math.cos(angle), math.sin(angle)])
    return np.array([p[f"ux{joint}_{leg}"], p[f"uy{joint}_{leg}"]])


def _slides(model: Model, out: Mapping[str, np.ndarray]) -> dict[tuple[str, int], np.ndarray]:
    """The current axis of every prismatic joint: its home axis turned with the body that
    carries it, by the revolute coordinates before it in the chain."""
    structure = model.structure
    slides = {}
    for leg in LEGS:
        turn = np.zeros_like(out["conditioning"])
        for joint, kind in enumerate(structure.leg, start=1):
            if kind == "P":
                u = _home_axis(model, leg, joint)
                c, s = np.cos(turn), np.sin(turn)
                slides[(leg, joint)] = np.column_stack([c * u[0] - s * u[1], s * u[0] + c * u[1]])
            else:
                turn = turn + out[f"{structure.coordinate(joint)}_{leg}"]
    return slides


def _joint_forces(model: Model, out: Mapping[str, np.ndarray], points: np.ndarray) -> np.ndarray:
    """The force at every joint (world, N), ``(n, 3, 3, 2)``.

    The general format gives them in world components (``fxj``, ``fyj``); the paper's gives the
    slide's and the platform joint's along the leg axis ``e`` (``f21z``, ``f32z``) and its normal
    ``n`` (``f21y``, ``f32y``), with ``e`` from A1 to A3.
    """
    forces = np.zeros_like(points)
    for i, leg in enumerate(LEGS):
        if not model.structure.paper:
            for j in (1, 2, 3):
                forces[:, i, j - 1] = np.column_stack([out[f"fx{j}_{leg}"], out[f"fy{j}_{leg}"]])
            continue
        axis = points[:, i, 2] - points[:, i, 0]
        e = axis / np.linalg.norm(axis, axis=1, keepdims=True)
        n = np.column_stack([-e[:, 1], e[:, 0]])
        forces[:, i, 0] = np.column_stack([out[f"f10x_{leg}"], out[f"f10y_{leg}"]])
        forces[:, i, 1] = out[f"f21z_{leg}"][:, None] * e + out[f"f21y_{leg}"][:, None] * n
        forces[:, i, 2] = out[f"f32z_{leg}"][:, None] * e + out[f"f32y_{leg}"][:, None] * n
    return forces
