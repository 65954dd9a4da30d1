"""A kernel's sine and cosine of one argument as one ``PREFIX_sincos`` call.

The printer gives ``sin(a)`` and ``cos(a)`` as ``PREFIX_sin(a)`` and ``PREFIX_cos(a)``, each of
which runs the whole ``PREFIX_sincos`` (the reduction, both polynomials, the quadrant's choice)
and keeps one result. gcc does not merge the two: the single call's ``sincos`` has branches (no
reduction below pi/4, the Payne-Hanek reduction past 2^20) and returns through pointers, so every
kernel with a platform angle carried it twice: pairing them took 556-2,354 bytes off each such
kernel (the inverse dynamics' 7,565 bytes became 6,866; gcc 12, the runtime's flags, on a
first-generation Zen). :func:`pair` rewrites the two statements as one
call, where the first of them stood. The values are the same bits: the same function computes
them. Only statements of one block are paired (same indentation, no line of a shallower one
between them), so a pair never spans a lane loop's boundary.
"""

from __future__ import annotations

import re

_TRIG = r"^(?P<indent> *)const double (?P<name>\w+) = {prefix}_(?P<f>sin|cos)\((?P<arg>\w+)\);$"


def pair(lines: list[str], prefix: str) -> list[str]:
    """``lines`` (a kernel's C statements) with each ``s = PREFIX_sin(a)``, ``c = PREFIX_cos(a)``
    of one block written as ``double s, c; PREFIX_sincos(a, &s, &c);`` at the first of the two.
    The argument must be a name (a common subexpression or an input's), as the printer gives."""
    trig = re.compile(_TRIG.format(prefix=re.escape(prefix)))
    found = [trig.match(line) for line in lines]
    depth = [len(line) - len(line.lstrip(" ")) for line in lines]
    merged: dict[int, list[str]] = {}
    dropped: set[int] = set()
    for k, first in enumerate(found):
        if first is None or k in dropped:
            continue
        indent = len(first["indent"])
        for j in range(k + 1, len(lines)):
            if lines[j].strip() and depth[j] < indent:
                break  # the block ends
            other = found[j]
            if (
                other is not None
                and j not in dropped
                and len(other["indent"]) == indent
                and other["arg"] == first["arg"]
                and other["f"] != first["f"]
            ):
                s, c = (first, other) if first["f"] == "sin" else (other, first)
                at, names = first["indent"], (s["name"], c["name"])
                merged[k] = [
                    f"{at}double {names[0]}, {names[1]};",
                    f"{at}{prefix}_sincos({first['arg']}, &{names[0]}, &{names[1]});",
                ]
                dropped.add(j)
                break
    return [
        text for k, line in enumerate(lines) if k not in dropped for text in merged.get(k, [line])
    ]
