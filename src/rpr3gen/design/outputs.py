"""The files of ``rpr3gen workspace``: the grid as Parquet and the four figures."""

from __future__ import annotations

import os
from pathlib import Path

from rpr3gen.design.maps import WorkspaceMap

__all__ = ["PARQUET_NAME", "write_workspace"]

PARQUET_NAME = "workspace.parquet"
"""The grid's file in the output folder."""


def write_workspace(wmap: WorkspaceMap, outdir: str | os.PathLike[str]) -> list[Path]:
    """Write ``outdir/workspace.parquet`` (:data:`rpr3gen.design.maps.COLUMNS`) and the
    figures of :func:`rpr3gen.design.figures.write_figures`, each atomically.

    Returns:
        The paths written: the Parquet file, then the figures.
    """
    # pyarrow and matplotlib load here, not with `import rpr3gen`.
    from rpr3gen.design.figures import write_figures
    from rpr3gen.design.parquet import to_table, write_table

    folder = Path(outdir)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / PARQUET_NAME
    write_table(path, to_table(wmap.columns()))
    return [path, *write_figures(wmap, folder)]
