"""The paper's model file format: the 3-RPR of S. Staicu, read into a :class:`Model`.

A file without a top-level ``leg`` key is of this format (docs/interfaces.md): ``name``,
``actuation`` and the tables ``geometry``, ``mass``, optional ``environment``, ``payload`` and
``limits``. :func:`read_paper` checks every key and value, applies the defaults of
``docs/conventions.md`` and returns the model whose ``params`` hold exactly
:data:`~rpr3gen.model.PARAM_NAMES` in SI units (angles in rad).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from rpr3gen.errors import ModelError, did_you_mean
from rpr3gen.model.reading import Reader, describe, point, quoted
from rpr3gen.model.types import ACTUATIONS, DEFAULT_GRAVITY, LEGS, Model

__all__ = ["MODEL_KEYS", "SCHEMA", "PaperReader", "read_paper"]

# Two points closer than this (m) are taken to coincide.
_COINCIDE_TOL = 1e-9

_SYMMETRIC_KEYS = ("r", "beta_deg")
_EXPLICIT_KEYS = ("base", "platform")

# Allowed keys per table; None marks a leaf value, a dict a sub-table.
SCHEMA: dict[str, Any] = {
    "name": None,
    "actuation": None,
    "geometry": dict.fromkeys(("l0", "l1", "l2", "alpha_deg", *_SYMMETRIC_KEYS, *_EXPLICIT_KEYS)),
    "mass": dict.fromkeys(("m1", "m2", "m3", "c1", "c2", "c1_perp", "c2_perp", "J1", "J2", "J3")),
    "environment": {"gravity": None},
    "payload": {"force": None, "moment": None},
    "limits": {"stroke": None},
}

MODEL_KEYS: tuple[str, ...] = tuple(
    f"{table}.{key}" if isinstance(sub, dict) else table
    for table, sub in SCHEMA.items()
    for key in (sub if isinstance(sub, dict) else (None,))
)
"""Every key a model file may hold, dotted (``"geometry.r"``, ``"mass.m3"``, ``"name"``...)."""


class PaperReader(Reader):
    """Validates one model of the paper's format; every failure names ``source`` and a dotted
    key."""

    schema = SCHEMA

    def read(self, data: Any) -> Model:
        """The model of the parsed TOML ``data``."""
        if not isinstance(data, Mapping):
            raise ModelError(f"{self.source}: a model must be a table, got {describe(data)}")
        self.check_keys(data, SCHEMA, "")

        name = self.required(data, "name", "name")
        if not isinstance(name, str) or not name.strip():
            self.fail("name", f"must be a non-empty string, got {describe(name)}")
        actuation = self.required(data, "actuation", "actuation")
        if actuation not in ACTUATIONS:
            hint = did_you_mean(actuation, ACTUATIONS) if isinstance(actuation, str) else ""
            self.fail(
                "actuation",
                f"must be one of {quoted(ACTUATIONS)}, got {describe(actuation)}{hint}",
            )

        geometry = self.table(data, "geometry", required=True)
        mass = self.table(data, "mass", required=True)
        environment = self.table(data, "environment", required=False)
        payload = self.table(data, "payload", required=False)

        params: dict[str, float] = {}
        l1, r = self.geometry(geometry, params)
        self.mass(mass, params, l1=l1, r=r)
        gravity = self.vector(environment, "environment.gravity", "gravity", 2, DEFAULT_GRAVITY)
        params["gx"], params["gy"] = gravity
        force = self.vector(payload, "payload.force", "force", 2, (0.0, 0.0))
        params["fx"], params["fy"] = force
        params["mz"] = self.number(payload, "payload.moment", "moment", default=0.0)
        stroke = self.stroke(self.table(data, "limits", required=False))
        return Model(
            name=name, actuation=actuation, params=params, source=self.source, stroke=stroke
        )

    def stroke(self, limits: Mapping[str, Any]) -> tuple[tuple[float, float], ...] | None:
        """``[limits] stroke = [[lo, hi], [lo, hi], [lo, hi]]``: lambda21 bounds per leg (m)."""
        if "stroke" not in limits:
            return None
        shape = "a list of 3 bounds [[lo, hi], [lo, hi], [lo, hi]] (m), for legs A, B, C"
        bounds = self.points(limits, "limits.stroke", "stroke", shape)
        for leg, (lo, hi) in zip(LEGS, bounds, strict=True):
            if not lo < hi:
                self.fail(
                    f"limits.stroke[{LEGS.index(leg)}]",
                    f"leg {leg}: the lower bound must be below the upper, got [{lo:g}, {hi:g}]",
                )
        return tuple((lo, hi) for lo, hi in bounds)

    # -- sections --------------------------------------------------------------------------

    def geometry(
        self, g: Mapping[str, Any], params: dict[str, float]
    ) -> tuple[float, float | None]:
        """Fill pivots, joints, angles, l0 and l2 into ``params``.

        Returns:
            ``(l1, r)`` in m; ``r`` is None for the explicit form.
        """
        l0 = self.number(g, "geometry.l0", "l0", positive=True)
        l1 = self.number(g, "geometry.l1", "l1", positive=True)
        l2 = self.number(g, "geometry.l2", "l2", positive=True)
        alpha_deg = self.vector(g, "geometry.alpha_deg", "alpha_deg", 3)
        alpha = [math.radians(a) for a in alpha_deg]

        symmetric = [k for k in _SYMMETRIC_KEYS if k in g]
        explicit = [k for k in _EXPLICIT_KEYS if k in g]
        forms = "use either r and beta_deg (symmetric form) or base and platform (explicit form)"
        if symmetric and explicit:
            self.fail(
                f"geometry.{explicit[0]}",
                f"not allowed together with geometry.{symmetric[0]}; {forms}",
            )
        if not symmetric and not explicit:
            self.fail("geometry", f"no platform geometry given; {forms}")
        if symmetric:
            why = " (the symmetric form needs r and beta_deg)"
            r = self.number(g, "geometry.r", "r", positive=True, why_required=why)
            beta = math.radians(self.number(g, "geometry.beta_deg", "beta_deg", why_required=why))
            platform: list[tuple[float, ...]] = [
                (r * math.sin(a + beta), -r * math.cos(a + beta)) for a in alpha
            ]
            base: list[tuple[float, ...]] = [
                (px - (l0 + l2) * math.cos(a), py - (l0 + l2) * math.sin(a))
                for (px, py), a in zip(platform, alpha, strict=True)
            ]
            base_key = platform_key = "geometry.alpha_deg"
        else:
            for k in _EXPLICIT_KEYS:
                if k not in g:
                    why = "(the explicit form needs base and platform)"
                    self.fail(f"geometry.{k}", f"missing required key {why}")
            base = self.points(g, "geometry.base", "base")
            platform = self.points(g, "geometry.platform", "platform")
            base_key, platform_key = "geometry.base", "geometry.platform"

        self.check_distinct(base, base_key, "base pivots", "1")
        self.check_distinct(platform, platform_key, "platform joints", "3")
        for leg, b, p in zip(LEGS, base, platform, strict=True):
            # At the central pose (G at the origin, phi = 0) the platform frame is the world frame.
            if math.dist(b, p) <= _COINCIDE_TOL:
                self.fail(
                    base_key,
                    f"leg {leg} has zero length at the central pose (base pivot {leg}1 and "
                    f"platform joint {leg}3 both at {point(b)})",
                )

        for leg, (x, y) in zip(LEGS, base, strict=True):
            params[f"x{leg}1"], params[f"y{leg}1"] = x, y
        for leg, (x, y) in zip(LEGS, platform, strict=True):
            params[f"x{leg}3"], params[f"y{leg}3"] = x, y
        for leg, a in zip(LEGS, alpha, strict=True):
            params[f"alpha_{leg}"] = a
        params["l0"], params["l2"] = l0, l2
        return l1, (r if symmetric else None)

    def check_distinct(
        self, points: Sequence[Sequence[float]], key: str, what: str, suffix: str
    ) -> None:
        for i in range(3):
            for j in range(i + 1, 3):
                if math.dist(points[i], points[j]) <= _COINCIDE_TOL:
                    self.fail(
                        key,
                        f"{what} {LEGS[i]}{suffix} and {LEGS[j]}{suffix} coincide at "
                        f"{point(points[i])}",
                    )

    def mass(
        self, m: Mapping[str, Any], params: dict[str, float], *, l1: float, r: float | None
    ) -> None:
        """Fill c1, c2, c1_perp, c2_perp, m1..m3 and J1..J3 into ``params`` (defaults:
        docs/conventions.md; the centres of mass are on the leg axis unless c1_perp, c2_perp,
        along the leg's normal n, say otherwise)."""
        l2 = params["l2"]
        m1 = self.number(m, "mass.m1", "m1", positive=True)
        m2 = self.number(m, "mass.m2", "m2", positive=True)
        m3 = self.number(m, "mass.m3", "m3", positive=True)
        params["c1"] = self.number(m, "mass.c1", "c1", default=l1 / 2)
        params["c2"] = self.number(m, "mass.c2", "c2", default=l2 / 2)
        params["c1_perp"] = self.number(m, "mass.c1_perp", "c1_perp", default=0.0)
        params["c2_perp"] = self.number(m, "mass.c2_perp", "c2_perp", default=0.0)
        params["J1"] = self.number(m, "mass.J1", "J1", default=m1 * l1**2 / 12, positive=True)
        params["J2"] = self.number(m, "mass.J2", "J2", default=m2 * l2**2 / 12, positive=True)
        if r is None:
            why = " (no default with explicit base and platform points)"
            params["J3"] = self.number(m, "mass.J3", "J3", positive=True, why_required=why)
        else:
            # Uniform equilateral triangular plate of edge l = r sqrt(3), about G.
            edge = r * math.sqrt(3.0)
            params["J3"] = self.number(m, "mass.J3", "J3", default=m3 * edge**2 / 12, positive=True)
        params["m1"], params["m2"], params["m3"] = m1, m2, m3


def read_paper(data: Any, source: str) -> Model:
    """Validate a model of the paper's format (the parsed TOML) and build the :class:`Model`."""
    return PaperReader(source).read(data)
