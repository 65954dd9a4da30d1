"""A sweep's plan: everything a worker needs to evaluate any chunk of designs (picklable)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rpr3gen.design.grid import Grid
from rpr3gen.model.general import is_general
from rpr3gen.model.spatial import is_spatial
from rpr3gen.trajectory import Trajectory

__all__ = ["SweepPlan"]


@dataclass(frozen=True)
class SweepPlan:
    """Everything a worker needs to evaluate any chunk of a sweep (picklable).

    Attributes:
        base: the base model's data (parsed TOML).
        base_source: its name, for messages.
        grid: the designs.
        names: the trajectories' names, for the reasons.
        trajectories: the trajectories, in the order given.
        min_conditioning: the least conditioning of a feasible pose.
        area_resolution: grid points per axis of a planar design's workspace area (0: no
            area, NaN).
        chunk_size: designs per chunk.
        volume_resolution: grid points per axis (x, y and z) of a spatial design's workspace
            volume (0: no volume, NaN).
        backend: ``"numpy"`` or ``"c"``, the generated code that evaluates a spatial design.
    """

    base: dict[str, Any]
    base_source: str
    grid: Grid
    names: tuple[str, ...]
    trajectories: tuple[Trajectory, ...]
    min_conditioning: float
    area_resolution: int
    chunk_size: int
    volume_resolution: int = 0
    backend: str = "numpy"

    @property
    def spatial(self) -> bool:
        """The base model is a spatial robot's (a hexapod or a Delta)."""
        return is_spatial(self.base)

    @property
    def general(self) -> bool:
        """The base model is of the general planar format."""
        return is_general(self.base) and not self.spatial

    @property
    def chunks(self) -> int:
        """Number of chunks."""
        return -(-len(self.grid) // self.chunk_size)

    def chunk(self, index: int) -> range:
        """The designs of chunk ``index``."""
        start = index * self.chunk_size
        return range(start, min(start + self.chunk_size, len(self.grid)))
