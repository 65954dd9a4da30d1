"""The NumPy lowering's output sums: each output row summed right after the line that last
names it (:func:`add_sums`), for the runtime's failure checks."""

from __future__ import annotations

import re


def add_sums(lines: list[str], rows: list[str], legs: int) -> list[str]:
    """``lines`` with ``sums[k] = _add.reduce(row)`` after the last line that names output row
    ``rows[k]`` (at the end for a row no line names); ``legs`` rows of one array at once where
    they come in a run (``legs``: the module's count of legs).

    The runtime's failure checks must know whether every output is finite. Read again after the
    kernel, a block's outputs come from the outer caches or memory: ~50 ns a sample of the
    inverse dynamics. Each row summed right after its last write is still in cache, and one
    non-finite value makes its sum non-finite (an overflowing sum only sends the block to the
    per-sample checks): about half of that (``benchmarks/harness/numpy_parts.py``).
    """
    last: dict[str, int] = {}
    wanted = set(rows)
    assert all(ROW_PATTERN.match(row) for row in wanted), rows
    for index, line in enumerate(lines):
        for row in _ROW.findall(line):  # each name[k] of the line, once
            if row in wanted:
                last[row] = index
        for name, start, stop in _SLICE.findall(line):  # the legs' rows at once: out[3:6]
            for k in range(int(start), int(stop)):
                if f"{name}[{k}]" in wanted:
                    last[f"{name}[{k}]"] = index
    after: dict[int, list[int]] = {}
    for k, row in enumerate(rows):
        after.setdefault(last.get(row, len(lines) - 1), []).append(k)
    found = []
    for index, line in enumerate(lines):
        found.append(line)
        found += _sum_lines(after.get(index, []), rows, legs)
    if not lines:
        found += _sum_lines(list(range(len(rows))), rows, legs)
    return found


_SLICE = re.compile(r"(?<![\w.])(\w+)\[(\d+):(\d+)\]")
#: An array's row, ``name[k]``, not part of a longer name or an attribute (what a row of
#: :func:`add_sums` is; one search of each line finds them all).
_ROW = re.compile(r"(?<![\w.])(\w+\[\d+\])")
ROW_PATTERN = re.compile(r"^(\w+)\[(\d+)\]$")


def _sum_lines(ks: list[int], rows: list[str], legs: int) -> list[str]:
    """``sums[k] = _add.reduce(row)`` for each k; ``legs`` consecutive rows of one array with
    consecutive ``k`` (a leg group's, for two legs or more) in one call along their rows."""
    lines, k = [], 0
    ks = sorted(ks)
    while k < len(ks):
        first = ROW_PATTERN.match(rows[ks[k]])
        run = 1
        while first and k + run < len(ks) and ks[k + run] == ks[k] + run:
            nxt = ROW_PATTERN.match(rows[ks[k + run]])
            if not nxt or nxt[1] != first[1] or int(nxt[2]) != int(first[2]) + run:
                break
            run += 1
        if legs > 1 and run >= legs and first:
            run = legs
            rows_text = f"{first[1]}[{first[2]}:{int(first[2]) + run}]"
            lines.append(f"_add.reduce({rows_text}, 1, None, sums[{ks[k]}:{ks[k] + run}])")
        else:
            run = 1
            lines.append(f"sums[{ks[k]}] = _add.reduce({rows[ks[k]]})")
        k += run
    return lines
