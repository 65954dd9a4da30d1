"""Design studies: workspace and singularity maps of one design, and sweeps over many.

- :func:`workspace` maps one design at a fixed platform angle (:mod:`.maps`), and
  :func:`write_workspace` writes the map as Parquet and four figures (:mod:`.outputs`).
- :func:`sweep` evaluates every design of a grid (:mod:`.grid`) over trajectories
  (:mod:`.metrics`), in chunks (:mod:`.sweeps`) on Dask (:mod:`.cluster`), as Parquet
  (:mod:`.parquet`).

Both take a model of either format (the paper's 3-RPR, or the general one of any leg type),
evaluate the generated NumPy code with one parameter vector per sample (:mod:`.stacked`), and
count a pose reachable as :mod:`.reach` says (with its default limits for design studies).

A spatial robot (a hexapod or a Delta) has its own workspace (:func:`spatial_workspace`), and
its sweeps its own grid keys (:mod:`.spatial_grid`) and measures (:mod:`.spatial_metrics`: the
workspace volume in place of the area), in NumPy or C.
"""

from rpr3gen.design.maps import WorkspaceMap, workspace
from rpr3gen.design.outputs import write_workspace
from rpr3gen.design.spatial_workspace import (
    SpatialWorkspace,
    spatial_workspace,
    write_spatial_workspace,
)
from rpr3gen.design.sweeps import sweep

__all__ = [
    "SpatialWorkspace",
    "WorkspaceMap",
    "spatial_workspace",
    "sweep",
    "workspace",
    "write_spatial_workspace",
    "write_workspace",
]
