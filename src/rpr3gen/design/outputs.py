"""The files of ``rpr3gen workspace``: the grid as Parquet and the four figures."""

from __future__ import annotations

import os
from pathlib import Path

from rpr3gen.design.maps import WorkspaceMap
from rpr3gen.paths import check_output
from rpr3gen.validation import Instance, PathArg, checked

__all__ = ["PARQUET_NAME", "write_workspace"]

PARQUET_NAME = "workspace.parquet"
"""The grid's file in the output folder."""


@checked(wmap=Instance(WorkspaceMap, "a WorkspaceMap (rpr3gen.workspace(...))"), outdir=PathArg())
def write_workspace(wmap: WorkspaceMap, outdir: str | os.PathLike[str]) -> list[Path]:
    """Write ``outdir/workspace.parquet`` (:data:`rpr3gen.design.maps.COLUMNS`) and the
    figures of :func:`rpr3gen.design.figures.write_figures`, each atomically.

    Returns:
        The paths written: the Parquet file, then the figures.

    Raises:
        InputTypeError, InputError: a bad argument, or a folder that cannot be written
            (:func:`rpr3gen.paths.check_output`), before anything is written.
    """
    check_output(outdir, "the workspace maps", folder=True, argument="outdir")
    # pyarrow and matplotlib load here, not with `import rpr3gen`.
    from rpr3gen.design.figures import write_figures
    from rpr3gen.design.parquet import to_table, write_table

    folder = Path(outdir)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / PARQUET_NAME
    write_table(path, to_table(wmap.columns()))
    return [path, *write_figures(wmap, folder)]
