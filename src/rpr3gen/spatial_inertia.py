"""A spatial robot's inertial parameters ``pi`` and the model numbers whose ``pi`` is a unit
vector (docs/spatial-robots.md, "Identification").

Per body ``m``, ``mcx, mcy, mcz`` and the inertia tensor's entries ``Ixx, Iyy, Izz, Ixy, Ixz,
Iyz`` about its first joint point (world axes at home, moving with the body); the platform's
about its frame's origin in its own axes; per rod pair of a Delta's leg ``m``, ``mc`` (along
the rod, from its upper S) and ``I`` (across the rod, about its upper S). The generated C
regressor (``derive/spatial/identification.py``) and :func:`rpr3gen.composed.run` evaluate the
inverse dynamics at the model numbers :func:`unit_columns` gives, one per column of ``Y``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "Body",
    "bodies",
    "inertial_parameters",
    "parameter_names",
    "unit_columns",
    "unit_edits",
]

_ENTRIES = ("xx", "yy", "zz", "xy", "xz", "yz")
BODY_QUANTITIES: tuple[str, ...] = ("m", "mcx", "mcy", "mcz", *(f"I{e}" for e in _ENTRIES))
ROD_QUANTITIES: tuple[str, ...] = ("m", "mc", "I")
#: The payload's parameters: apart from ``pi`` (``tau_payload``).
PAYLOAD: tuple[str, ...] = ("fx", "fy", "fz", "mx", "my", "mz")


@dataclass(frozen=True)
class Body:
    """One body's model numbers (parameter names) and its reference point's.

    ``name``: ``1A``, ``2A``, ``rA`` (a Delta leg's rods) or ``3`` (the platform). A rod's
    ``com`` is ``(fr,)``, its ``inertia`` ``(Ir,)``, its ``reference`` the upper S midpoint
    ``e`` and ``tip`` the lower ``p``; ``reference`` None is the origin (the platform).
    """

    name: str
    rod: bool
    mass: str
    com: tuple[str, ...]
    inertia: tuple[str, ...]
    reference: tuple[str, ...] | None
    tip: tuple[str, ...] | None = None

    @property
    def quantities(self) -> tuple[str, ...]:
        return ROD_QUANTITIES if self.rod else BODY_QUANTITIES


def bodies(kinds: str, legs: str) -> tuple[Body, ...]:
    """The bodies in ``pi``'s order: per leg bodies 1 and 2 (hexapods) or 1 and its rods
    (Deltas, ``kinds`` ending in ``SS2``), then the platform."""
    delta = kinds.endswith("SS2")
    out = []
    for leg in legs:
        b = tuple(f"b{a}_{leg}" for a in "xyz")
        e = tuple(f"e{a}_{leg}" for a in "xyz") if kinds != "UPS" else b
        for k in (1,) if delta else (1, 2):
            out.append(
                Body(
                    name=f"{k}{leg}",
                    rod=False,
                    mass=f"m{k}_{leg}",
                    com=tuple(f"c{k}{a}_{leg}" for a in "xyz"),
                    inertia=tuple(f"I{k}{x}_{leg}" for x in _ENTRIES),
                    reference=b if k == 1 else e,
                )
            )
        if delta:
            out.append(
                Body(
                    name=f"r{leg}",
                    rod=True,
                    mass=f"mr_{leg}",
                    com=(f"fr_{leg}",),
                    inertia=(f"Ir_{leg}",),
                    reference=e,
                    tip=tuple(f"p{a}_{leg}" for a in "xyz"),
                )
            )
    out.append(
        Body(
            name="3",
            rod=False,
            mass="m3",
            com=tuple(f"c3{a}" for a in "xyz"),
            inertia=tuple(f"I3{x}" for x in _ENTRIES),
            reference=None,
        )
    )
    return tuple(out)


def parameter_names(kinds: str, legs: str) -> tuple[str, ...]:
    """``pi``'s names, e.g. ``m_1A, mcx_1A, ..., Iyz_1A, ..., m_rA, mc_rA, I_rA, ..., Iyz_3``."""
    return tuple(f"{q}_{b.name}" for b in bodies(kinds, legs) for q in b.quantities)


def _rod_length(body: Body, p: Mapping[str, float]) -> float:
    assert body.reference is not None
    assert body.tip is not None
    return float(
        np.linalg.norm([p[t] - p[r] for t, r in zip(body.tip, body.reference, strict=True)])
    )


def inertial_parameters(kinds: str, legs: str, p: Mapping[str, float]) -> np.ndarray:
    """``pi`` (P,) of the model numbers ``p`` (parameter name -> value): the parallel axis
    theorem, ``I_O = I_C + m (|d|^2 E - d d^T)`` with ``d`` the centre of mass from the
    reference point; a rod's ``mc = m fr L`` and ``I = Ir + m (fr L)^2``."""
    out: list[float] = []
    for b in bodies(kinds, legs):
        m = p[b.mass]
        if b.rod:
            arm = p[b.com[0]] * _rod_length(b, p)
            out += [m, m * arm, p[b.inertia[0]] + m * arm**2]
            continue
        ref = [p[r] for r in b.reference] if b.reference else [0.0, 0.0, 0.0]
        d = np.array([p[c] for c in b.com]) - ref
        xx, yy, zz, xy, xz, yz = (p[i] for i in b.inertia)
        dx, dy, dz = d
        out += [m, *(m * d)]
        out += [xx + m * (dy * dy + dz * dz), yy + m * (dx * dx + dz * dz)]
        out += [zz + m * (dx * dx + dy * dy), xy - m * dx * dy, xz - m * dx * dz, yz - m * dy * dz]
    return np.array(out, dtype=float)


def zeroed(kinds: str, legs: str) -> tuple[str, ...]:
    """The numbers zeroed in every column's evaluation: masses, inertias and the payload."""
    out = list(PAYLOAD)
    for b in bodies(kinds, legs):
        out += [b.mass, *b.inertia]
    return tuple(out)


def unit_edits(
    kinds: str,
    legs: str,
    names: Sequence[str],
    params: Any,
    sqrt: Callable[[Any], Any] = math.sqrt,
) -> list[tuple[str, dict[int, Any]]]:
    """For each column ``j`` of ``Y`` in order: its role and the components of the parameter
    vector (``names``' order; ``params`` numeric or symbolic, ``sqrt`` of its kind) to replace
    so that ``pi`` is ``e_j``. Roles: ``"mass"`` (a body's mass column), ``"moment"`` (a first
    moment: ``pi`` is ``e_j`` plus the body's mass, so the column is the efforts less the mass
    column) or ``"plain"``. Gravity is the model's; every other body is massless."""
    index = {n: i for i, n in enumerate(names)}
    base = {index[n]: 0.0 for n in zeroed(kinds, legs)}
    out: list[tuple[str, dict[int, Any]]] = []
    for b in bodies(kinds, legs):
        p = dict(base)
        p[index[b.mass]] = 1.0
        if b.rod:
            assert b.reference is not None
            assert b.tip is not None
            fr, ir = index[b.com[0]], index[b.inertia[0]]
            squares = [
                (params[index[t]] - params[index[r]]) * (params[index[t]] - params[index[r]])
                for t, r in zip(b.tip, b.reference, strict=True)
            ]
            length = sqrt(squares[0] + squares[1] + squares[2])
            p[fr] = 0.0
            out.append(("mass", dict(p)))
            p[fr], p[ir] = 1.0 / length, -1.0
            out.append(("moment", dict(p)))
            p[index[b.mass]], p[fr], p[ir] = 0.0, 0.0, 1.0
            out.append(("plain", dict(p)))
            continue
        ref = [params[index[r]] for r in b.reference] if b.reference else [0.0, 0.0, 0.0]
        com = [index[c] for c in b.com]
        inertia = [index[i] for i in b.inertia]
        for a in range(3):
            p[com[a]] = ref[a]
        out.append(("mass", dict(p)))
        for a in range(3):
            q = dict(p)
            q[com[a]] = ref[a] + 1.0
            for d in range(3):
                if d != a:
                    q[inertia[d]] = -1.0
            out.append(("moment", q))
        p[index[b.mass]] = 0.0
        for e in range(6):
            q = dict(p)
            q[inertia[e]] = 1.0
            out.append(("plain", q))
    return out


def unit_columns(
    kinds: str, legs: str, names: Sequence[str], params: np.ndarray
) -> Iterator[tuple[np.ndarray, str]]:
    """:func:`unit_edits` applied to a copy of the numeric ``params``: each column's parameter
    vector and its role."""
    for role, edits in unit_edits(kinds, legs, names, params):
        p = np.array(params, dtype=float)
        for k, v in edits.items():
            p[k] = v
        yield p, role
