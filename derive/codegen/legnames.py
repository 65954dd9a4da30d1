"""Per-leg names for the CSE temporaries, so that every leg prints its statements alike.

``sympy.cse`` numbers its temporaries in the order it meets them: leg A's ``x38`` is leg B's
``x50``. The printers order a sum's terms by the names in them, so the same sum of two legs can
print as ``(a + x38) + b*x6`` and ``(a + b*x20) + x50``. Those round differently, so the C
backend cannot run them as lanes of one vector (:mod:`.backends.c.lanes`). :func:`leg_names`
renames the temporaries that are one expression for every leg to ``x38_A``, ``x38_B``, ...
(the first leg's number and each leg's letter; ``x1__A`` ... where ``x1_A`` is taken, as by the
general format's parameters). Then every name of leg B compares to the expression's other names
as leg A's does, and the legs print their sums in one order.

The legs are the module's (:attr:`~rpr3gen_derive.codegen.spec.ModuleSpec.legs`): ``ABC`` for a
planar robot or a Delta, ``ABCDEF`` for a hexapod. A leg's symbols are the program's: names that
differ only by the leg's letter at one place (``xA1``, ``xB1``, ``xC1``; ``rx_A`` ... ``rx_F``).
A temporary belongs to one leg when the leg's symbols are the only leg symbols it reads,
directly or through temporaries renamed before it; the renaming runs to a fixed point, and a
group is renamed only when every leg has its member. Names change, not values: the expressions
are the same.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from collections.abc import Set as AbstractSet

import sympy as sp


def leg_family(name: str, known: AbstractSet[str], legs: str) -> tuple[str, str] | None:
    """``(head, tail)`` when ``name`` is the first leg's of names in ``known``, one per leg of
    ``legs``, that differ only by the leg's letter at one place: ``head + leg + tail`` (``xA1``,
    ``xB1``, ``xC1``; ``rx_A`` ... ``rx_F``). None for fewer than two legs. The backends' leg
    groups (the C lanes, :mod:`.backends.c.lanes`; NumPy's leg blocks) use it too."""
    if len(legs) < 2:
        return None
    for k, ch in enumerate(name):
        if ch == legs[0] and all(name[:k] + leg + name[k + 1 :] in known for leg in legs[1:]):
            return name[:k], name[k + 1 :]
    return None


def shape(expr: sp.Expr, family: Mapping[sp.Symbol, object]) -> object:
    """``expr`` as a hashable tree, each symbol of ``family`` replaced by its family (its
    pattern, or a group's number): equal for two expressions exactly when they are one tree once
    those symbols are read as their families: the same operations on the same operands, a sum's
    or a product's terms as a multiset (SymPy orders them by the symbols' names), the operands
    of anything else in order. No two symbols of one expression share a family. SymPy's
    equality after substituting a symbol per family says the same, at ten times the cost, but
    for pairs its own rules make one once substituted: ``cos(u)`` and ``cos(-u)``, whose signs
    SymPy chose by the names, are one expression there and two trees here."""
    if expr in family:
        return ("@", family[expr])
    if not expr.args:
        return expr
    args = [shape(a, family) for a in expr.args]
    if isinstance(expr, (sp.Add, sp.Mul)):
        return (expr.func, frozenset(Counter(args).items()))
    return (expr.func, tuple(args))


def _families(names: Iterable[str], legs: str) -> dict[str, tuple[str, int]]:
    """Each leg symbol's name -> (its family's pattern, its leg)."""
    known = set(names)
    found: dict[str, tuple[str, int]] = {}
    for name in sorted(known):
        family = leg_family(name, known, legs)
        if family is not None:
            head, tail = family
            for leg, letter in enumerate(legs):
                found.setdefault(head + letter + tail, (head + "@" + tail, leg))
    return found


def leg_names(
    lines: Sequence[tuple[sp.Symbol, sp.Expr]],
    outputs: Sequence[tuple[str, sp.Expr]],
    temporaries: set[sp.Symbol],
    reserved: frozenset[str] = frozenset(),
    *,
    legs: str,
) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[tuple[str, sp.Expr]]]:
    """``lines`` and ``outputs`` with the leg temporaries renamed (see the module); ``legs``:
    the module's legs' letters. A new name is never one of ``reserved`` (every parameter's and
    input's, used here or not) or of a symbol here."""
    if len(legs) < 2:
        return list(lines), list(outputs)
    symbols: set[sp.Symbol] = set()
    for sym, expr in lines:
        symbols |= {sym} | expr.free_symbols
    for _, expr in outputs:
        symbols |= expr.free_symbols
    names = {str(s) for s in symbols} | set(reserved)
    temp_names = {str(t) for t in temporaries}
    family = _families((n for n in names if n not in temp_names), legs)
    leg_of: dict[sp.Symbol, tuple[str, int]] = {
        s: family[str(s)] for s in symbols if str(s) in family
    }
    rename: dict[sp.Symbol, sp.Symbol] = {}
    pending = {sym: expr for sym, expr in lines if sym in temporaries}
    readers: dict[sp.Symbol, list[sp.Symbol]] = {}
    reads = {sym: expr.free_symbols for sym, expr in pending.items()}
    for sym, free in reads.items():
        for s in free:
            readers.setdefault(s, []).append(sym)
    keyed: dict[sp.Symbol, object] = {}  # a temporary's current key (one leg only)
    index: dict[object, dict[int, sp.Symbol]] = {}  # key -> leg -> temporary
    dirty = list(pending)
    while dirty:  # each pass looks again only at the readers of what the last one renamed
        touched: list[object] = []
        for sym in dirty:
            old = keyed.pop(sym, None)
            if old is not None:
                index[old] = {g: t for g, t in index[old].items() if t != sym}
            read = {leg_of[s][1] for s in reads[sym] if s in leg_of}
            if len(read) != 1:
                continue
            key = shape(pending[sym], {s: leg_of[s][0] for s in reads[sym] if s in leg_of})
            keyed[sym] = key
            index.setdefault(key, {}).setdefault(read.pop(), sym)
            touched.append(key)
        grouped: list[sp.Symbol] = []
        for key in dict.fromkeys(touched):
            each = index.get(key, {})  # leg -> its member
            if len(each) != len(legs) or any(t in rename for t in each.values()):
                continue
            base = str(each[0])
            for glue in ("_", "__", "___"):  # x1_A may be a parameter's (the general format's)
                targets = [f"{base}{glue}{leg}" for leg in legs]
                if not any(t in names for t in targets):
                    break
            else:
                continue
            for leg, sym in each.items():
                leg_of[sym] = (f"{base}{glue}@", leg)
                rename[sym] = sp.Symbol(targets[leg], real=True)
                names.add(targets[leg])
                grouped.append(sym)
        done = set(rename)
        dirty = list(dict.fromkeys(r for g in grouped for r in readers.get(g, []) if r not in done))
    if not rename:
        return list(lines), list(outputs)
    return (
        [(rename.get(s, s), e.xreplace(rename)) for s, e in lines],
        [(n, e.xreplace(rename)) for n, e in outputs],
    )
