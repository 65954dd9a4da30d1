"""The NumPy lowering's leg groups: the legs' statements that are one expression, run as one
call on a (legs, n) block (:func:`leg_groups`), and the units they are placed by
(:func:`_units`)."""

from __future__ import annotations

import heapq

import sympy as sp
from rpr3gen_derive.codegen.backends.python.sums import ROW_PATTERN
from rpr3gen_derive.codegen.legnames import leg_family, shape

#: Fewest leg groups that make a function's statements worth lowering on (legs, n) blocks.
MIN_GROUPS = 4


def _fits(each: dict[int, sp.Symbol], alias: dict[sp.Symbol, str]) -> bool:
    """A group's members are no outputs, or outputs in consecutive rows of one array in the
    legs' order (written at once: ``out[3:6]``)."""
    rows = [alias.get(each[leg]) for leg in range(len(each))]
    if all(r is None for r in rows):
        return True
    found = [ROW_PATTERN.match(r) if r else None for r in rows]
    if not all(found):
        return False
    names = {m[1] for m in found if m}
    starts = [int(m[2]) for m in found if m]
    return len(names) == 1 and starts == list(range(starts[0], starts[0] + len(each)))


def leg_groups(
    statements: list[tuple[sp.Symbol, sp.Expr]],
    scalars: set[sp.Symbol],
    alias: dict[sp.Symbol, str],
    legs: str,
) -> dict[sp.Symbol, tuple[int, int, bool]]:
    """The legs' statements that one call can evaluate for every leg of ``legs`` (the module's
    letters) at once: each member's symbol -> (its group, its leg, whether the group is
    per-sample).

    A group is one symbol per leg, named alike but for the leg's letter
    (:func:`~rpr3gen_derive.codegen.legnames.leg_family`): the legs' parameters, parameter-only
    statements, then, to a fixed point, per-sample statements whose right-hand sides are one
    expression once each member they read is read as its group (the same tree, as SymPy keeps
    it: the same operations on the same operands; compared by
    :func:`~rpr3gen_derive.codegen.legnames.shape`). Such statements give each leg the same bits
    as one statement each. None when there are fewer than :data:`MIN_GROUPS` per-sample
    groups, or fewer than two legs."""
    if len(legs) < 2:
        return {}
    names = {str(x): x for x in scalars} | {str(lhs): lhs for lhs, _ in statements}
    scalar = set(scalars)
    for lhs, rhs in statements:
        if rhs.free_symbols <= scalar:
            scalar.add(lhs)
    member: dict[sp.Symbol, tuple[int, int, bool]] = {}
    count = 0
    for name in sorted(names):
        family = leg_family(name, names.keys(), legs)
        if family is None:
            continue
        per_leg = [names[family[0] + leg + family[1]] for leg in legs]
        if all(x in scalar for x in per_leg):
            for leg, x in enumerate(per_leg):
                member[x] = (count, leg, False)
            count += 1
    # A candidate's key changes only when a symbol it reads joins a group: each pass computes
    # again the keys of those statements alone (the rest are kept), then collects the keys in
    # the statements' order, as one pass over them all would.
    candidates = [
        (lhs, rhs, rhs.free_symbols)
        for lhs, rhs in statements
        if lhs not in member and lhs not in scalar and not isinstance(rhs, (sp.sin, sp.cos))
    ]
    keys: dict[sp.Symbol, tuple[object, int] | None] = {}
    joined: set[sp.Symbol] | None = None  # None: every key is to compute
    groups = 0
    while True:
        found: dict[object, dict[int, sp.Symbol]] = {}
        for lhs, rhs, free in candidates:
            if lhs in member:
                continue
            if joined is None or not joined.isdisjoint(free):
                read = [x for x in free if x in member]
                of = {member[x][1] for x in read}
                keys[lhs] = (
                    (shape(rhs, {x: member[x][0] for x in read}), of.pop())
                    if len(of) == 1
                    else None
                )
            entry = keys[lhs]
            if entry is not None:
                found.setdefault(entry[0], {}).setdefault(entry[1], lhs)
        complete = [t for t in found.values() if len(t) == len(legs) and _fits(t, alias)]
        if not complete:
            break
        joined = set()
        for each in complete:
            for leg, x in each.items():
                member[x] = (count, leg, True)
                joined.add(x)
            count += 1
            groups += 1
    return member if groups >= MIN_GROUPS else {}


def _units(
    statements: list[tuple[sp.Symbol, sp.Expr]], member: dict[sp.Symbol, tuple[int, int, bool]]
) -> list[list[tuple[sp.Symbol, sp.Expr]]]:
    """The statements as units: a per-sample group's (in the legs' order) or one alone,
    each unit after those it reads, otherwise in the order of its first statement."""
    unit_of: dict[int, object] = {}
    members: dict[object, list[int]] = {}
    for index, (lhs, _) in enumerate(statements):
        key: object = ("g", member[lhs][0]) if lhs in member and member[lhs][2] else index
        unit_of[index] = key
        members.setdefault(key, []).append(index)
    defined = {lhs: unit_of[k] for k, (lhs, _) in enumerate(statements)}
    deps = {
        key: {defined[x] for k in ks for x in statements[k][1].free_symbols if x in defined} - {key}
        for key, ks in members.items()
    }
    readers: dict[object, list[object]] = {}
    for key, ds in deps.items():
        for d in ds:
            readers.setdefault(d, []).append(key)
    waiting = {key: len(ds) for key, ds in deps.items()}
    ready = [(min(ks), str(key), key) for key, ks in members.items() if not waiting[key]]
    heapq.heapify(ready)
    order: list[list[tuple[sp.Symbol, sp.Expr]]] = []
    while ready:
        _, _, key = heapq.heappop(ready)
        ks = sorted(members[key], key=lambda k: member.get(statements[k][0], (0, 0))[1])
        order.append([statements[k] for k in ks])
        for r in readers.get(key, []):
            waiting[r] -= 1
            if not waiting[r]:
                heapq.heappush(ready, (min(members[r]), str(r), r))
    assert len(order) == len(members), "the statements have a cycle"
    return order
