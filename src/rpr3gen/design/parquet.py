"""Parquet tables of design studies: fixed writer options, atomic files, same data same bytes.

Every table is written with the options of :data:`WRITE_OPTIONS` (compression, format version,
row-group size, statistics), from columns in a fixed order and with no metadata but the Arrow
schema, so the bytes depend on the values alone: no time, host or path is stored.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from rpr3gen.atomic import atomic_write

__all__ = ["WRITE_OPTIONS", "read_table", "to_table", "write_table", "write_tables"]

WRITE_OPTIONS: Mapping[str, Any] = {
    "compression": "zstd",
    "compression_level": 3,
    "version": "2.6",
    "data_page_version": "1.0",
    "use_dictionary": True,
    "write_statistics": True,
    "row_group_size": 1 << 16,
}
"""Options of :func:`pyarrow.parquet.write_table` for every file."""


def to_table(columns: Mapping[str, np.ndarray | Sequence[str]]) -> pa.Table:
    """An Arrow table of ``columns`` in their order: float64, bool or string columns."""
    arrays = []
    for values in columns.values():
        if isinstance(values, np.ndarray) and values.dtype != object:
            arrays.append(pa.array(values))
        else:
            arrays.append(pa.array(list(values), type=pa.string()))
    return pa.Table.from_arrays(arrays, names=list(columns))


def write_table(path: str | os.PathLike[str], table: pa.Table) -> None:
    """Write ``table`` as Parquet at ``path``, atomically, with :data:`WRITE_OPTIONS`."""
    with atomic_write(path, "wb") as f:
        pq.write_table(table.replace_schema_metadata(None), f, **WRITE_OPTIONS)


def write_tables(path: str | os.PathLike[str], parts: Iterable[str | os.PathLike[str]]) -> None:
    """Write the Parquet files ``parts``, one after the other, as one file at ``path``,
    atomically, with :data:`WRITE_OPTIONS`, holding at most one row group in memory.

    The row groups have ``row_group_size`` rows whatever the parts' sizes, so the bytes depend
    on the rows alone.
    """
    options = dict(WRITE_OPTIONS)
    rows = options.pop("row_group_size")
    with atomic_write(path, "wb") as f:
        writer: pq.ParquetWriter | None = None
        pending: list[pa.Table] = []
        count = 0
        for part in parts:
            table = read_table(part)
            if writer is None:
                writer = pq.ParquetWriter(f, table.schema, **options)
            pending.append(table.cast(writer.schema))
            count += table.num_rows
            while count >= rows:
                whole = pa.concat_tables(pending)
                writer.write_table(whole.slice(0, rows).combine_chunks(), row_group_size=rows)
                pending, count = [whole.slice(rows)], count - rows
        if writer is None:
            raise ValueError("write_tables: no parts")
        if count:
            writer.write_table(pa.concat_tables(pending).combine_chunks(), row_group_size=rows)
        writer.close()


def read_table(path: str | os.PathLike[str]) -> pa.Table:
    """Read a Parquet file written by :func:`write_table`."""
    return pq.read_table(path)
