"""The legs side by side: a single-sample kernel's leg statements as loops over the lanes.

The legs are independent until the platform's equations: leg B's kinematics are leg A's
statements with B's parameters. Written one leg after the other, the 3-RPR's inverse dynamics'
single call was ~1,650 instructions; written as ``for (i = 0; i < 4; ++i)`` over the legs, gcc's
loop vectoriser runs the three legs as lanes of one 4-wide vector (lane 3 is padding), and the
call is ~1,170 (issue 20, full benchmark runs: revolute 123 -> 107 ns, forward dynamics 96 -> 75
ns; with the per-leg names of :mod:`rpr3gen_derive.codegen.legnames`, 97 ns).

The legs are the module's (:attr:`~rpr3gen_derive.codegen.spec.ModuleSpec.legs`), any number of
them: a loop has :func:`width` lanes, the legs' count rounded up to a power of two (three legs:
4, lane 3 unused; a hexapod's six: 8, lanes 6 and 7 unused), so that the loop is whole vectors.

:func:`lanes` finds the lane groups: one statement per leg, that are the same expression once
each operand that is itself a lane group's member is read as the group's (a leg's parameters:
loads ``params[k0]``, ``params[k0 + d]``, ``params[k0 + 2 d]`` ... whose names differ only by
the leg's letter). "The same expression" is exact: the expressions' trees
are equal up to swapping the two operands of an addition or a multiplication, which IEEE 754
computes to the same bits; a lane therefore gives its leg the same bits as the scalar statement
would, and the batch (which runs the scalar statements) still agrees with the single call bit
for bit. The kernel is then cut into phases, scalar statements and lane loops alternately, each
taking every statement whose operands an earlier phase computed, in the scheduler's order
(:mod:`.order`). A lane value read after its loop is kept in an array of the loop's width and
read back just before its first reader as the leg's scalar (``const double rx_B =
rx_legs[1];``).

A padding lane (lane 3 of three legs) loads ``params[k0 + 3 d]``: an unrelated parameter, so its
values mean nothing and are never read. That holds for strides ``d`` of 1 and 2 inside the vector
(the paper's formats). A leg's parameters at a larger stride (the general format: 17 per leg; a
spatial leg's: 32) are one interleaved group of 17 (or 32) loads to gcc's loop vectoriser, which it
does not vectorise: the general structures' lane loops ran as scalar loops of four turns (the
general 3-RPR's inverse dynamics: 206 ns in the single call, against ~100 for the paper's variant of
the same robot). So the kernel first copies those parameters leg by leg, :data:`BY_LEG`:
``by_leg[W k + leg]`` is leg ``leg``'s parameter ``k`` of its block, ``W`` the loop's width (the
padding lanes hold 0.0, and never read past the vector), a copy that gcc vectorises as a
transposition, and the lanes load ``by_leg[W k + i]``, contiguous (133 ns). A padding lane's
arithmetic can raise floating-point exception flags the legs would not raise; the library is built
with ``-fno-trapping-math`` and does not support running with floating-point traps enabled.
"""

from __future__ import annotations

import ast
import itertools
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rpr3gen_derive.codegen.backends.c.order import Line
from rpr3gen_derive.codegen.legnames import leg_family

#: How every lane loop opens, :func:`loop`'s line (readers of the generated C, e.g. the
#: benchmark's floor, find the loops by it, and the legs in it); the loop closes at the first
#: ``}`` back at its indent.
LOOP = re.compile(
    r"for \(i = 0; i < (?P<width>\d+); \+\+i\) \{ /\* legs (?P<legs>[A-Z](?:, [A-Z])*)"
    r"(?:; lanes? [\d, ]+ unused)? \*/"
)
#: Fewest lane groups that make a function's loops worth their overhead.
MIN_GROUPS = 4
#: The legs' parameters copied leg by leg, for strides the vectoriser does not take (the module).
BY_LEG = "params_by_leg"
#: The largest stride of a leg's parameters that the lanes read from ``params`` itself.
MAX_STRIDE = 2

_INDEX = re.compile(r"params\[(\d+)\]$")
_NAME = re.compile(r"\b[A-Za-z_]\w*\b")


def width(legs: str) -> int:
    """The lanes of a loop over ``legs``: their count rounded up to a power of two."""
    return 1 << max(len(legs) - 1, 0).bit_length()


def loop(legs: str) -> str:
    """The line that opens a lane loop over ``legs`` (matched by :data:`LOOP`)."""
    wide = width(legs)
    spare = [str(k) for k in range(len(legs), wide)]
    unused = f"; lane{'s' if len(spare) > 1 else ''} {', '.join(spare)} unused" if spare else ""
    return f"for (i = 0; i < {wide}; ++i) {{ /* legs {', '.join(legs)}{unused} */"


@dataclass(frozen=True)
class _Group:
    """One statement per leg (``members[k]`` for the ``k``-th leg), run as one lane loop."""

    members: tuple[Line, ...]
    name: str  # the loop's name for the value (the members' name with the leg as ``i``)


def _canonical(node: ast.AST, rename: dict[str, str]) -> str:
    """``node`` as text with names renamed and the operands of every addition and
    multiplication sorted (the forms IEEE 754 computes to the same bits)."""
    if isinstance(node, ast.BinOp):
        left, right = _canonical(node.left, rename), _canonical(node.right, rename)
        op = type(node.op).__name__
        if op in ("Add", "Mult") and right < left:
            left, right = right, left
        return f"({left} {op} {right})"
    if isinstance(node, ast.UnaryOp):
        return f"({type(node.op).__name__} {_canonical(node.operand, rename)})"
    if isinstance(node, ast.Call):
        args = ", ".join(_canonical(a, rename) for a in node.args)
        return f"{_canonical(node.func, rename)}({args})"
    if isinstance(node, ast.Name):
        return rename.get(node.id, node.id)
    if isinstance(node, ast.Constant):
        return repr(node.value)
    raise ValueError(f"not a kernel expression: {ast.dump(node)}")


def _parse(text: str) -> ast.AST | None:
    try:
        return ast.parse(text, mode="eval").body
    except SyntaxError:  # C only (a ternary, a cast): stays scalar
        return None


def _groups(lines: Sequence[Line], param_count: int, legs: str) -> dict[str, tuple[int, int]]:
    """Lane groups: each member's name -> (group, leg), found to a fixed point."""
    by_name = {x.name: x for x in lines if x.name}
    member: dict[str, tuple[int, int]] = {}
    count = 0
    spare = width(legs) - 1  # the last lane's offset, in strides
    families: list[tuple[list[str], int, int]] = []
    for line in lines:  # a leg's parameters: an arithmetic progression inside params
        family = leg_family(line.name, by_name.keys(), legs) if line.kind == "load" else None
        if family is None:
            continue
        head, tail = family
        loads = [head + leg + tail for leg in legs]
        index = [_INDEX.match(by_name[n].payload[0]) for n in loads]
        if all(index):
            ks = [int(m.group(1)) for m in index if m]
            d = ks[1] - ks[0]
            steps = {b - a for a, b in itertools.pairwise(ks)}
            if steps == {d} and d != 0 and ks[0] + spare * d >= 0:
                families.append((loads, ks[0], d))
    copied = _copied_stride([(k0, d) for _, k0, d in families], param_count, legs)
    for loads, k0, d in families:  # read from params, or from the copy by leg (the module)
        if d == copied or (abs(d) <= MAX_STRIDE and k0 + spare * d < param_count):
            for leg, n in enumerate(loads):
                member[n] = (count, leg)
            count += 1
    trees = {x.name: _parse(x.payload[0]) for x in lines if x.kind == "assign"}
    while True:  # a group can make the statements that read it groups: repeat until none new
        found: dict[str, dict[int, str]] = {}
        for line in lines:
            tree = trees.get(line.name)
            if line.kind != "assign" or line.name in member or tree is None:
                continue
            read = {member[r][1] for r in line.reads if r in member}
            if len(read) != 1:
                continue
            rename = {r: f"@{member[r][0]}" for r in line.reads if r in member}
            key = _canonical(tree, rename)
            found.setdefault(key, {}).setdefault(read.pop(), line.name)
        new = [each for each in found.values() if len(each) == len(legs)]
        if not new:
            return member
        for each in new:
            for leg, n in each.items():
                member[n] = (count, leg)
            count += 1


def lanes(
    lines: Sequence[Line], param_count: int, legs: str, indent: str = "    "
) -> list[str] | None:
    """The kernel's statements (in the scheduler's order) as C lines, the leg statements as lane
    loops over ``legs`` (the module's legs' letters); None when the kernel has fewer than
    :data:`MIN_GROUPS` lane groups, or the module fewer than two legs."""
    if len(legs) < 2:
        return None
    member = _groups(lines, param_count, legs)
    found: dict[int, list[Line]] = {}
    for line in lines:
        if line.name in member:
            found.setdefault(member[line.name][0], []).append(line)
    if len(found) < MIN_GROUPS:
        return None
    wide = width(legs)
    groups = _named(found, member, {x.name for x in lines if x.name} | {"i", BY_LEG}, legs)
    by_leg = _by_leg(groups.values(), param_count, legs)
    # units in the scheduler's order: a group stands where its first member stood
    units: list[Line | _Group] = []
    placed: set[int] = set()
    for line in lines:
        if line.name not in member:
            units.append(line)
        elif member[line.name][0] not in placed:
            placed.add(member[line.name][0])
            units.append(groups[member[line.name][0]])
    phase = _phases(units)
    where = {x.name: phase[u] for u, unit in enumerate(units) for x in _lines_of(unit) if x.name}
    kept = {  # groups whose values a later phase reads: kept in arrays
        member[r][0]
        for u, unit in enumerate(units)
        for x in _lines_of(unit)
        for r in x.reads
        if r in member and where[r] != phase[u]
    }
    out = [indent + "int i;"]
    out += [
        f"{indent}double {groups[g].name}_legs[{wide}];"
        for g in sorted(kept, key=lambda g: groups[g].name)
    ]
    if by_leg is not None:
        start, d, rows = by_leg
        spare = range(len(legs), wide)
        zeros = f"lane{'s' if len(spare) > 1 else ''} {', '.join(map(str, spare))}: 0.0"
        out += [
            f"{indent}double {BY_LEG}[{wide * rows}]; /* params[{start} + {d}*leg + k] at "
            f"[{wide}*k + leg]{'; ' + zeros if spare else ''} */",
            f"{indent}for (i = 0; i < {rows}; ++i) {{",
            *(
                f"{indent}    {BY_LEG}[{wide}*i + {leg}] = params[{start + d * leg} + i];"
                for leg in range(len(legs))
            ),
            *(f"{indent}    {BY_LEG}[{wide}*i + {lane}] = 0.0;" for lane in spare),
            f"{indent}}}",
        ]
    unpacked: set[str] = set()
    for p in range(max(phase) + 1):
        here = [unit for u, unit in enumerate(units) if phase[u] == p]
        if p % 2 == 0:  # scalar statements, reading kept lane values as their legs' scalars
            for unit in here:
                assert isinstance(unit, Line)
                for r in sorted(unit.reads & member.keys() - unpacked):
                    g, leg = member[r]
                    out.append(f"{indent}const double {r} = {groups[g].name}_legs[{leg}];")
                    unpacked.add(r)
                out.extend(plain([unit], indent))
            continue
        if not here:
            continue
        out.append(indent + loop(legs))
        for unit in here:
            assert isinstance(unit, _Group)
            text = _lane_text(unit, member, groups, where, p, by_leg, wide)
            out.append(f"{indent}    const double {unit.name} = {text};")
            if member[unit.members[0].name][0] in kept:
                out.append(f"{indent}    {unit.name}_legs[i] = {unit.name};")
        out.append(indent + "}")
    return out


def _named(
    found: dict[int, list[Line]], member: dict[str, tuple[int, int]], taken: set[str], legs: str
) -> dict[int, _Group]:
    """Each group with its loop's name for the value: the members' with the leg as ``i``
    (``rx_A`` -> ``rx_i``, ``xA1`` -> ``xi1``), else the first leg's with ``_i`` (``x0`` ->
    ``x0_i``)."""
    groups = {}
    for g, each in found.items():
        ordered = tuple(sorted(each, key=lambda x: member[x.name][1]))
        family = leg_family(ordered[0].name, {x.name for x in ordered}, legs)
        name = family[0] + "i" + family[1] if family else f"{ordered[0].name}_i"
        while name in taken:  # e.g. x2_A's family and the temporary x2 both make x2_i
            name += "_"
        taken.add(name)
        groups[g] = _Group(ordered, name)
    return groups


def _progression(group: _Group) -> tuple[int, int] | None:
    """``(k0, d)`` when ``group`` is a leg parameter's loads ``params[k0 + d*leg]``."""
    a, b = group.members[:2]
    first, second = _INDEX.match(a.payload[0]), _INDEX.match(b.payload[0])
    if a.kind != "load" or not first or not second:
        return None
    k0 = int(first.group(1))
    return k0, int(second.group(1)) - k0


def _needs_copy(k0: int, d: int, param_count: int, legs: str) -> bool:
    return d > MAX_STRIDE or k0 + (width(legs) - 1) * d >= param_count


def _copied_stride(families: Sequence[tuple[int, int]], param_count: int, legs: str) -> int | None:
    """The stride of the leg parameters read from :data:`BY_LEG` (the most common of those
    that need it; the others stay scalar), or None."""
    strides = [d for k0, d in families if d > 0 and _needs_copy(k0, d, param_count, legs)]
    return max(sorted(set(strides)), key=strides.count) if strides else None


def _by_leg(groups: Iterable[_Group], param_count: int, legs: str) -> tuple[int, int, int] | None:
    """``(start, d, rows)`` of :data:`BY_LEG`: rows ``k`` hold the legs'
    ``params[start + d*leg + k]``, a whole number of vectors where the vector allows it;
    None when every lane reads ``params`` itself."""
    found = list(filter(None, map(_progression, groups)))
    d = _copied_stride(found, param_count, legs)
    if d is None:
        return None
    start = min(k0 for k0, stride in found if stride == d)
    rows = max(k0 for k0, stride in found if stride == d) + 1 - start
    whole = -(-rows // width(legs)) * width(legs)
    return start, d, whole if start + (len(legs) - 1) * d + whole <= param_count else rows


def _lines_of(unit: Line | _Group) -> tuple[Line, ...]:
    return unit.members if isinstance(unit, _Group) else (unit,)


def _phases(units: Sequence[Line | _Group]) -> list[int]:
    """Per unit, its phase: even phases are scalar statements, odd ones lane loops; each phase
    takes every unit of its kind whose operands earlier units computed (to a fixed point)."""
    defined_by = {x.name: u for u, unit in enumerate(units) for x in _lines_of(unit) if x.name}
    deps = [
        {defined_by[r] for x in _lines_of(unit) for r in x.reads if r in defined_by} - {u}
        for u, unit in enumerate(units)
    ]
    phase = [-1] * len(units)
    p = 0
    while min(phase, default=0) < 0:
        assert p <= 2 * len(units), "the kernel's statements have a cycle"
        grew = True
        while grew:
            grew = False
            for u, unit in enumerate(units):
                ready = all(phase[d] >= 0 for d in deps[u])
                if phase[u] < 0 and isinstance(unit, _Group) == (p % 2 == 1) and ready:
                    phase[u] = p
                    grew = True
        p += 1
    return phase


def _lane_text(
    group: _Group,
    member: dict[str, tuple[int, int]],
    groups: dict[int, _Group],
    where: dict[str, int],
    p: int,
    by_leg: tuple[int, int, int] | None,
    wide: int,
) -> str:
    """The first leg's statement for lane ``i``: a parameter as ``params[k0 + d*i]`` (or its row
    of :data:`BY_LEG`, ``wide`` wide), a group's value as the loop's local (same loop) or its
    array's lane (an earlier loop)."""
    a = group.members[0]
    progression = _progression(group)
    if progression is not None:
        k0, d = progression
        if by_leg is not None and d == by_leg[1]:
            return f"{BY_LEG}[{wide * (k0 - by_leg[0])} + i]"
        return f"params[{k0} + {d}*i]"

    def local(m: re.Match[str]) -> str:
        n = m.group(0)
        if n not in member or member[n][1] != 0:
            return n
        other = groups[member[n][0]]
        return other.name if where[n] == p else f"{other.name}_legs[i]"

    return _NAME.sub(local, a.payload[0])


def plain(lines: Sequence[Line], indent: str = "    ") -> list[str]:
    """The kernel's statements as C lines, one after the other."""
    return [
        f"{indent}r_{x.payload[0]}[{x.payload[1]}] = {x.payload[2]};"
        if x.kind == "store"
        else f"{indent}const double {x.name} = {x.payload[0]};"
        for x in lines
    ]
