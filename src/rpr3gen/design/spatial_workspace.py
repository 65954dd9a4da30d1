"""The constant-orientation workspace of a spatial robot (docs/spatial-robots.md): horizontal
slices of a box about home, at a fixed platform orientation, with each point's reach,
conditioning and the static efforts that hold the robot there; the reachable volume.

A point is reachable where the generated code evaluates the pose (every leg reaches it in its
working mode, ``reach`` above ``MIN_REACH``) and its ``conditioning`` is at least
``min_conditioning``. The volume is the reachable points' count times a cell's volume (the grid
is regular): it converges as the resolution grows.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rpr3gen.backends import evaluate, inverse_dynamics
from rpr3gen.errors import InputError
from rpr3gen.model import Model
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING
from rpr3gen.spatial_modes import point
from rpr3gen.validation import Instance, Integer, Number, checked

__all__ = ["SpatialWorkspace", "spatial_workspace", "write_spatial_workspace"]

DEFAULT_RESOLUTION = 41
DEFAULT_HEIGHTS = 9
#: A leg's ``reach`` at or below this: it cannot hold the pose (the generated code's floor).
MIN_REACH = 1e-9


@dataclass(frozen=True)
class SpatialWorkspace:
    """A spatial robot's workspace at one orientation.

    Attributes:
        model: the robot.
        orientation: ``(a, b, c)`` (rad) of a hexapod, ``()`` for a Delta.
        x, y, z: the grid's coordinates of the platform frame's origin (m), (nx,), (ny,), (nz,).
        conditioning: (nz, ny, nx), NaN where a leg cannot reach the pose.
        reachable: (nz, ny, nx) bool.
        tau: (nz, ny, nx, legs): the actuator efforts holding the robot at rest there (NaN
            where not reachable).
        volume: the reachable volume, m^3.
        min_conditioning: the floor used.
    """

    model: Model
    orientation: tuple[float, ...]
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    conditioning: np.ndarray
    reachable: np.ndarray
    tau: np.ndarray
    volume: float
    min_conditioning: float


def _size(model: Model) -> float:
    """The longest leg at home (base or elbow to the platform point): the box's half size."""
    start = "b" if model.structure.leg == "UPS" else "e"
    return max(
        float(np.linalg.norm(point(model, "p", leg) - point(model, start, leg)))
        for leg in model.structure.legs
    )


def workspace_box(
    model: Model, resolution: int, heights: int, orientation: tuple[float, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The grid of :func:`spatial_workspace`: its axes ``x``, ``y``, ``z`` and every pose
    ``q`` on it, (heights * resolution^2, dof), ``z`` slowest and ``x`` fastest; a hexapod's at
    the ``orientation`` ``(a, b, c)`` (rad)."""
    half = _size(model)
    x = np.linspace(-half, half, resolution)
    y = np.linspace(-half, half, resolution)
    z = np.linspace(-half, half, heights) if heights > 1 else np.zeros(1)
    Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
    q = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    if model.structure.dof == 6:
        q = np.column_stack([q, np.tile(orientation, (len(q), 1))])
    return x, y, z, q


def reachable_poses(
    diagnostics: np.ndarray, min_conditioning: float
) -> tuple[np.ndarray, np.ndarray]:
    """From ``pose_diagnostics``' output (n, legs + 1): which poses are reachable (every leg
    reaches the pose, its reach above ``MIN_REACH``, and the conditioning is at least
    ``min_conditioning``), and the conditioning (NaN where a leg does not reach the pose)."""
    reach = diagnostics[:, :-1]
    conditioning = diagnostics[:, -1].copy()
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(reach).all(axis=1) & (reach.min(axis=1) > MIN_REACH)
    conditioning[~ok] = np.nan
    with np.errstate(invalid="ignore"):
        reachable = ok & (conditioning >= min_conditioning)
    return reachable, conditioning


def cell_volume(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> float:
    """The volume of one cell of the grid ``x, y, z`` (m^3; one slice: its area, m^2)."""
    return float((x[1] - x[0]) * (y[1] - y[0]) * ((z[1] - z[0]) if len(z) > 1 else 1.0))


@checked(
    resolution=Integer(2, cost=lambda n: n * n * 64 * 8, what="the workspace's points"),
    heights=Integer(1, cost=lambda n: n * 64 * 8, what="the workspace's slices"),
    min_conditioning=Number(least=0.0, most=1.0),
    orientation=Instance(tuple, "a tuple of three angles (rad)"),
)
def spatial_workspace(
    model: Model,
    resolution: int = DEFAULT_RESOLUTION,
    heights: int = DEFAULT_HEIGHTS,
    orientation: tuple[float, float, float] = (0.0, 0.0, 0.0),
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
) -> SpatialWorkspace:
    """The workspace of a spatial ``model`` at a fixed ``orientation`` (hexapods: ``(a, b,
    c)`` in rad; a Delta's platform keeps its home orientation).

    The box is centred on home, as wide in x and y as twice the longest leg at home and as
    high as that too, sampled by ``resolution`` x ``resolution`` points in each of ``heights``
    slices.

    Raises:
        InputError: a planar model, or an orientation that is not three finite numbers.
    """
    s = model.structure
    if not s.spatial:
        raise InputError("model: spatial_workspace is for spatial robots; see rpr3gen.workspace")
    angles = tuple(float(v) for v in orientation)
    if len(angles) != 3 or not all(math.isfinite(v) for v in angles):
        raise InputError(f"orientation: must be three finite angles (rad), got {orientation!r}")
    x, y, z, q = workspace_box(model, resolution, heights, angles)
    (diagnostics,), _ = evaluate(model, "pose_diagnostics", (q,))
    reachable, conditioning = reachable_poses(diagnostics, min_conditioning)
    tau = np.full((len(q), len(s.legs)), np.nan)
    if reachable.any():
        rest = np.zeros((int(reachable.sum()), s.dof))
        out = inverse_dynamics(model, q[reachable], rest, rest)
        tau[reachable] = np.column_stack([out[f"tau_{leg}"] for leg in s.legs])
    cell = cell_volume(x, y, z)
    shape = (len(z), len(y), len(x))
    return SpatialWorkspace(
        model=model,
        orientation=angles if s.dof == 6 else (),
        x=x,
        y=y,
        z=z,
        conditioning=conditioning.reshape(shape),
        reachable=reachable.reshape(shape),
        tau=tau.reshape(*shape, len(s.legs)),
        volume=float(np.count_nonzero(reachable) * cell),
        min_conditioning=float(min_conditioning),
    )


def write_spatial_workspace(ws: SpatialWorkspace, out: str | os.PathLike[str]) -> list[Path]:
    """Write ``workspace.parquet`` (columns ``x, y, z, reachable, conditioning, tau_L``) and
    ``slices.png`` (the conditioning of every slice) into the folder ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pyarrow as pa
    import pyarrow.parquet as pq

    from rpr3gen.atomic import atomic_write

    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    Z, Y, X = np.meshgrid(ws.z, ws.y, ws.x, indexing="ij")
    columns = {
        "x": X.ravel(),
        "y": Y.ravel(),
        "z": Z.ravel(),
        "reachable": ws.reachable.ravel(),
        "conditioning": ws.conditioning.ravel(),
    }
    for k, leg in enumerate(ws.model.structure.legs):
        columns[f"tau_{leg}"] = ws.tau[..., k].ravel()
    table = pa.table(columns)
    parquet = folder / "workspace.parquet"
    with atomic_write(parquet, "wb") as f:
        pq.write_table(table, f)
    n = len(ws.z)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(
        rows, cols, figsize=(4.0 * cols, 3.6 * rows), squeeze=False, layout="constrained"
    )
    for k in range(rows * cols):
        ax = axes[k // cols][k % cols]
        if k >= n:
            ax.axis("off")
            continue
        shown = np.where(ws.reachable[k], ws.conditioning[k], np.nan)
        image = ax.imshow(shown, origin="lower", vmin=0.0, vmax=1.0, cmap="viridis",
                          extent=(ws.x[0], ws.x[-1], ws.y[0], ws.y[-1]))  # fmt: skip
        ax.set_title(f"z = {ws.z[k]:.3g} m")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.colorbar(image, ax=axes, shrink=0.8, label="conditioning")
    orientation = (
        " at (a, b, c) = (" + ", ".join(f"{math.degrees(v):g}" for v in ws.orientation) + ") deg"
        if ws.orientation
        else ""
    )
    fig.suptitle(f"{ws.model.name}: reachable volume {ws.volume:.4g} m^3{orientation}")
    png = folder / "slices.png"
    with atomic_write(png, "wb") as f:
        fig.savefig(f, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return [parquet, png]
