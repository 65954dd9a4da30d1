"""The legs side by side: a single-sample kernel's leg statements as loops over 4 lanes.

The three legs are independent until the platform's equations: leg B's kinematics are leg A's
statements with B's parameters. Written one leg after the other, the inverse dynamics' single
call was ~1,650 instructions; written as ``for (i = 0; i < 4; ++i)`` over the legs, gcc's loop
vectoriser runs the three legs as lanes of one 4-wide vector (lane 3 is padding), and the call
is ~1,170 (issue 20, full benchmark runs: revolute 123 -> 107 ns, forward dynamics 96 -> 75 ns;
with the per-leg names of :mod:`rpr3gen_derive.codegen.legnames`, 97 ns).

:func:`lanes` finds the lane groups: three statements, one per leg, that are the same
expression once each operand that is itself a lane group's member is read as the group's
(a leg's parameters: three loads ``params[k0]``, ``params[k0 + d]``, ``params[k0 + 2 d]`` whose
names differ only by the leg's letter). "The same expression" is exact: the expressions' trees
are equal up to swapping the two operands of an addition or a multiplication, which IEEE 754
computes to the same bits; a lane therefore gives its leg the same bits as the scalar statement
would, and the batch (which runs the scalar statements) still agrees with the single call bit
for bit. The kernel is then cut into phases, scalar statements and lane loops alternately, each
taking every statement whose operands an earlier phase computed, in the scheduler's order
(:mod:`.order`). A lane value read after its loop is kept in an array of 4 and read back just
before its first reader as the leg's scalar (``const double rx_B = rx_legs[1];``).

Lane 3 loads ``params[k0 + 3 d]``: an unrelated parameter, so its values mean nothing and are
never read. That holds for strides ``d`` of 1 and 2 inside the vector (the paper's formats). A
leg's parameters at a larger stride (the general format: 17 per leg) are one interleaved group
of 17 loads to gcc's loop vectoriser, which it does not vectorise: the general structures' lane
loops ran as scalar loops of four turns (the general 3-RPR's inverse dynamics: 206 ns in the
single call, against ~100 for the paper's variant of the same robot). So the kernel first copies
those parameters leg by leg, :data:`BY_LEG`: ``by_leg[4 k + leg]`` is leg ``leg``'s parameter
``k`` of its block (lane 3 holds 0.0, and never reads past the vector), a copy that gcc
vectorises as a 4x4 transposition, and the lanes load ``by_leg[4 k + i]``, contiguous (133 ns).
Lane 3's arithmetic can raise floating-point exception flags the three legs would not raise;
the library is built with ``-fno-trapping-math`` and does not support running with
floating-point traps enabled.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rpr3gen_derive.codegen.backends.c.order import Line
from rpr3gen_derive.codegen.legnames import LEGS, leg_family

#: Lanes per loop: the legs, padded to a 4-wide vector of doubles.
WIDTH = 4
#: How every lane loop opens (readers of the generated C, e.g. the benchmark's floor, find the
#: loops by it); the loop closes at the first ``}`` back at this line's indent.
LOOP = f"for (i = 0; i < {WIDTH}; ++i) {{ /* legs A, B, C; lane 3 unused */"
#: Fewest lane groups that make a function's loops worth their overhead.
MIN_GROUPS = 4
#: The legs' parameters copied leg by leg, for strides the vectoriser does not take (the module).
BY_LEG = "params_by_leg"
#: The largest stride of a leg's parameters that the lanes read from ``params`` itself.
MAX_STRIDE = 2

_INDEX = re.compile(r"params\[(\d+)\]$")
_NAME = re.compile(r"\b[A-Za-z_]\w*\b")


@dataclass(frozen=True)
class _Group:
    """Three statements, one per leg (``members[k]`` for ``LEGS[k]``), run as one lane loop."""

    members: tuple[Line, Line, Line]
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


def _groups(lines: Sequence[Line], param_count: int) -> dict[str, tuple[int, int]]:
    """Lane groups: each member's name -> (group, leg), found to a fixed point."""
    by_name = {x.name: x for x in lines if x.name}
    member: dict[str, tuple[int, int]] = {}
    count = 0
    families: list[tuple[list[str], int, int]] = []
    for line in lines:  # a leg's parameters: an arithmetic progression inside params
        family = leg_family(line.name, by_name.keys()) if line.kind == "load" else None
        if family is None:
            continue
        head, tail = family
        loads = [head + leg + tail for leg in LEGS]
        index = [_INDEX.match(by_name[n].payload[0]) for n in loads]
        if all(index):
            k0, k1, k2 = (int(m.group(1)) for m in index if m)
            if k2 - k1 == k1 - k0 != 0 and k0 + 3 * (k1 - k0) >= 0:
                families.append((loads, k0, k1 - k0))
    copied = _copied_stride([(k0, d) for _, k0, d in families], param_count)
    for loads, k0, d in families:  # read from params, or from the copy by leg (the module)
        if d == copied or (abs(d) <= MAX_STRIDE and k0 + 3 * d < param_count):
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
            legs = {member[r][1] for r in line.reads if r in member}
            if len(legs) != 1:
                continue
            rename = {r: f"@{member[r][0]}" for r in line.reads if r in member}
            key = _canonical(tree, rename)
            found.setdefault(key, {}).setdefault(legs.pop(), line.name)
        new = [three for three in found.values() if len(three) == len(LEGS)]
        if not new:
            return member
        for three in new:
            for leg, n in three.items():
                member[n] = (count, leg)
            count += 1


def lanes(lines: Sequence[Line], param_count: int, indent: str = "    ") -> list[str] | None:
    """The kernel's statements (in the scheduler's order) as C lines, the leg statements as lane
    loops; None when the kernel has fewer than :data:`MIN_GROUPS` lane groups."""
    member = _groups(lines, param_count)
    found: dict[int, list[Line]] = {}
    for line in lines:
        if line.name in member:
            found.setdefault(member[line.name][0], []).append(line)
    if len(found) < MIN_GROUPS:
        return None
    groups = _named(found, member, {x.name for x in lines if x.name} | {"i", BY_LEG})
    by_leg = _by_leg(groups.values(), param_count)
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
        f"{indent}double {groups[g].name}_legs[{WIDTH}];"
        for g in sorted(kept, key=lambda g: groups[g].name)
    ]
    if by_leg is not None:
        start, d, rows = by_leg
        out += [
            f"{indent}double {BY_LEG}[{WIDTH * rows}]; /* params[{start} + {d}*leg + k] at "
            f"[{WIDTH}*k + leg]; lane 3: 0.0 */",
            f"{indent}for (i = 0; i < {rows}; ++i) {{",
            *(
                f"{indent}    {BY_LEG}[{WIDTH}*i + {leg}] = params[{start + d * leg} + i];"
                for leg in range(len(LEGS))
            ),
            f"{indent}    {BY_LEG}[{WIDTH}*i + {len(LEGS)}] = 0.0;",
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
        out.append(indent + LOOP)
        for unit in here:
            assert isinstance(unit, _Group)
            text = _lane_text(unit, member, groups, where, p, by_leg)
            out.append(f"{indent}    const double {unit.name} = {text};")
            if member[unit.members[0].name][0] in kept:
                out.append(f"{indent}    {unit.name}_legs[i] = {unit.name};")
        out.append(indent + "}")
    return out


def _named(
    found: dict[int, list[Line]], member: dict[str, tuple[int, int]], taken: set[str]
) -> dict[int, _Group]:
    """Each group with its loop's name for the value: the members' with the leg as ``i``
    (``rx_A`` -> ``rx_i``, ``xA1`` -> ``xi1``), else leg A's with ``_i`` (``x0`` -> ``x0_i``)."""
    groups = {}
    for g, three in found.items():
        a, b, c = sorted(three, key=lambda x: member[x.name][1])
        family = leg_family(a.name, {a.name, b.name, c.name})
        name = family[0] + "i" + family[1] if family else f"{a.name}_i"
        while name in taken:  # e.g. x2_A's family and the temporary x2 both make x2_i
            name += "_"
        taken.add(name)
        groups[g] = _Group((a, b, c), name)
    return groups


def _progression(group: _Group) -> tuple[int, int] | None:
    """``(k0, d)`` when ``group`` is a leg parameter's loads ``params[k0 + d*leg]``."""
    a, b, _ = group.members
    first, second = _INDEX.match(a.payload[0]), _INDEX.match(b.payload[0])
    if a.kind != "load" or not first or not second:
        return None
    k0 = int(first.group(1))
    return k0, int(second.group(1)) - k0


def _needs_copy(k0: int, d: int, param_count: int) -> bool:
    return d > MAX_STRIDE or k0 + 3 * d >= param_count


def _copied_stride(families: Sequence[tuple[int, int]], param_count: int) -> int | None:
    """The stride of the leg parameters read from :data:`BY_LEG` (the most common of those
    that need it; the others stay scalar), or None."""
    strides = [d for k0, d in families if d > 0 and _needs_copy(k0, d, param_count)]
    return max(sorted(set(strides)), key=strides.count) if strides else None


def _by_leg(groups: Iterable[_Group], param_count: int) -> tuple[int, int, int] | None:
    """``(start, d, rows)`` of :data:`BY_LEG`: rows ``k`` hold the legs'
    ``params[start + d*leg + k]``, a whole number of vectors where the vector allows it;
    None when every lane reads ``params`` itself."""
    found = list(filter(None, map(_progression, groups)))
    d = _copied_stride(found, param_count)
    if d is None:
        return None
    start = min(k0 for k0, stride in found if stride == d)
    rows = max(k0 for k0, stride in found if stride == d) + 1 - start
    whole = -(-rows // WIDTH) * WIDTH
    return start, d, whole if start + 2 * d + whole <= param_count else rows


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
) -> str:
    """Leg A's statement for lane ``i``: a parameter as ``params[k0 + d*i]`` (or its row of
    :data:`BY_LEG`), a group's value as the loop's local (same loop) or its array's lane (an
    earlier loop)."""
    a = group.members[0]
    progression = _progression(group)
    if progression is not None:
        k0, d = progression
        if by_leg is not None and d == by_leg[1]:
            return f"{BY_LEG}[{WIDTH * (k0 - by_leg[0])} + i]"
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
