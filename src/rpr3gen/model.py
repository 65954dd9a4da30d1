"""Robot model files: read, validate and turn into the numeric parameter vector.

A model file (TOML, see ``docs/interfaces.md``) describes one 3-RPR robot. :func:`load_model` reads
it, checks every key and value, applies the defaults of ``docs/conventions.md`` and returns a
:class:`Model` whose ``params`` hold exactly :data:`PARAM_NAMES` in SI units (angles in rad),
the inputs of the generated inverse-dynamics functions.

Every problem is reported as a :class:`~rpr3gen.errors.ModelError` with a one-line message that
names the file and the dotted key, e.g. ``my.toml: geometry.l0: must be a positive number, got
-0.1``.
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import json
import math
import os
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from numbers import Real
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from rpr3gen.errors import ModelError, did_you_mean
from rpr3gen.model_checks import check_fields
from rpr3gen.structure import PAPER_PARAM_NAMES, Structure
from rpr3gen.validation import Instance, Optional, PathArg, checked

__all__ = [
    "ACTUATIONS",
    "LEGS",
    "MODEL_KEYS",
    "PARAM_NAMES",
    "Model",
    "load_model",
    "model_from_dict",
    "read_model_data",
]

ACTUATIONS: tuple[str, ...] = ("revolute", "prismatic")
"""Which joint of each leg is driven: the base revolute (the paper) or the prismatic joint."""

PARAM_NAMES: tuple[str, ...] = PAPER_PARAM_NAMES
"""Names of the paper format's model parameters, in the order of the generated code's
``params`` array (a general model's are its structure's, :meth:`Structure.param_names`)."""

LEGS: tuple[str, ...] = ("A", "B", "C")

DEFAULT_GRAVITY: tuple[float, float] = (0.0, -9.81)
"""Gravity in the world frame (y0 up) when the model file has no ``environment.gravity``, m/s²."""

# Two points closer than this (m) are taken to coincide.
_COINCIDE_TOL = 1e-9

_SYMMETRIC_KEYS = ("r", "beta_deg")
_EXPLICIT_KEYS = ("base", "platform")

# Allowed keys per table; None marks a leaf value, a dict a sub-table.
_SCHEMA: dict[str, Any] = {
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
    for table, sub in _SCHEMA.items()
    for key in (sub if isinstance(sub, dict) else (None,))
)
"""Every key a model file may hold, dotted (``"geometry.r"``, ``"mass.m3"``, ``"name"``...)."""


class _ReadOnlyParams(Mapping[str, float]):
    """An immutable, hashable, picklable ``str -> float`` mapping that keeps its key order."""

    def __init__(self, items: Mapping[str, float]) -> None:
        self._data = dict(items)

    def __getitem__(self, key: str) -> float:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __hash__(self) -> int:
        return hash(tuple(self._data.items()))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Mapping) and dict(self.items()) == dict(other.items())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._data!r})"


@dataclass(frozen=True)
class Model:
    """A validated robot, of the paper's format or the general one.

    Attributes:
        name: The model's name (``name`` in the file).
        actuation: ``"revolute"`` (motors on revolute joints: the paper's base motors) or
            ``"prismatic"``: the kind of the actuated joint.
        params: Read-only mapping with exactly the structure's parameter names
            (:meth:`Structure.param_names`), in that order, as floats in SI units. The paper's
            format: base pivots ``xA1..yC1`` (m, world frame), platform joints ``xA3..yC3``
            (m, platform frame), ``alpha_A..alpha_C`` (rad), lengths (m), masses (kg),
            inertias (kg m², about the COM, axis z), gravity ``gx, gy`` (m/s²) and the payload
            wrench at G ``fx, fy`` (N), ``mz`` (N m). The general format: docs/interfaces.md.
        source: Where the model came from (a file path or ``"<dict>"``), for messages.
        stroke: The paper's format: optional piston displacement bounds ``((lo, hi), ...)``
            for legs A, B, C (m, bounds on lambda21), from ``[limits] stroke``; else None.
        generated: The folder of generated code that evaluates this model (written by
            ``rpr3gen generate --out DIR``), or None for the installed package (and the cache
            of variants generated on first use).
        structure: The leg type and actuated joint (and the format); None (only when built by
            hand) means the paper's of ``actuation``.
        limits: The general format: joint coordinate bounds ``{"A.q2": (lo, hi), ...}`` (m or
            rad) from ``[limits]``; None when the file sets none.
    """

    name: str
    actuation: str
    params: Mapping[str, float]
    source: str
    stroke: tuple[tuple[float, float], ...] | None = None
    generated: str | None = None
    # Always a Structure after construction (None at construction means the paper's).
    structure: Structure = None  # type: ignore[assignment]
    limits: Mapping[str, tuple[float, float]] | None = None

    def __post_init__(self) -> None:
        fields = check_fields(self, ACTUATIONS)  # rpr3gen.model_checks
        object.__setattr__(self, "structure", fields["structure"])
        object.__setattr__(self, "params", _ReadOnlyParams(fields["params"]))
        object.__setattr__(self, "stroke", fields["stroke"])
        object.__setattr__(self, "generated", fields["generated"])
        if fields["limits"] is not None:
            object.__setattr__(self, "limits", _ReadOnlyLimits(fields["limits"]))

    @property
    def variant(self) -> str:
        """The generated variant that evaluates this model (a folder name: ``revolute``,
        ``rrr_1``, ...)."""
        return self.structure.variant

    @property
    def param_names(self) -> tuple[str, ...]:
        """The model's parameter names, in the generated code's order."""
        return tuple(self.params)

    def vector(self, names: Sequence[str] | None = None) -> np.ndarray:
        """Return the parameters ``names`` (default: all, in order) as a new float64 array.

        Raises:
            KeyError: If a name is not one of the model's parameters.
        """
        names = tuple(self.params) if names is None else names
        return np.array([self.params[n] for n in names], dtype=np.float64)


class _ReadOnlyLimits(Mapping[str, tuple[float, float]]):
    """An immutable, hashable ``"A.q2" -> (lo, hi)`` mapping in sorted key order."""

    def __init__(self, items: Mapping[str, tuple[float, float]]) -> None:
        self._data = {k: (float(v[0]), float(v[1])) for k, v in sorted(items.items())}

    def __getitem__(self, key: str) -> tuple[float, float]:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __hash__(self) -> int:
        return hash(tuple(self._data.items()))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Mapping) and dict(self.items()) == dict(other.items())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._data!r})"


@checked(path=Optional(PathArg()), generated=Optional(PathArg()))
def load_model(
    path: str | os.PathLike[str] | None = None,
    generated: str | os.PathLike[str] | None = None,
) -> Model:
    """Read and validate a model file.

    Args:
        path: A TOML model file; ``None`` loads the packaged paper robot (``models/paper.toml``).
        generated: A folder written by ``rpr3gen generate --out DIR`` whose code evaluates the
            model; ``None`` uses the installed generated package.

    Returns:
        The validated model, with the defaults of ``docs/conventions.md`` filled in.

    Raises:
        ModelError: If the file cannot be read, is not valid TOML, or any key or value is wrong;
            the one-line message names the file and the dotted key.
    """
    source, data = read_model_data(path)
    model = model_from_dict(data, source=source)
    if generated is None:
        return model
    return dataclasses.replace(model, generated=os.fspath(generated))


def read_model_data(path: str | os.PathLike[str] | None = None) -> tuple[str, dict[str, Any]]:
    """Read a model file as parsed TOML, not yet validated (see :func:`model_from_dict`).

    Args:
        path: A TOML model file; ``None`` reads the packaged paper robot.

    Returns:
        The file's name for messages and its tables as nested dictionaries.

    Raises:
        ModelError: If the file cannot be read or is not valid UTF-8 TOML.
    """
    if path is None:
        resource = importlib.resources.files("rpr3gen") / "models" / "paper.toml"
        source, read_bytes = str(resource), resource.read_bytes
    else:
        source = os.fspath(path)
        read_bytes = Path(source).read_bytes
    try:
        raw = read_bytes()
    except FileNotFoundError:
        raise ModelError(f"{source}: model file not found") from None
    except IsADirectoryError:
        raise ModelError(f"{source}: is a directory, not a model file") from None
    except OSError as exc:
        raise ModelError(f"{source}: cannot read model file: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError(f"{source}: not UTF-8 text (bad byte at offset {exc.start})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{source}: invalid TOML: {_one_line(str(exc))}") from None
    return source, data


@checked(data=Instance(Mapping, "a mapping (the parsed TOML)"), source=Instance(str, "a str"))
def model_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Model:
    """Validate a model given as nested mappings (the parsed TOML) and build the :class:`Model`.

    Args:
        data: Same structure as a model file: ``name``, ``actuation`` and the tables
            ``geometry``, ``mass``, optional ``environment`` and ``payload``. Lists may be
            lists, tuples or numpy arrays.
        source: Name used in error messages.

    Raises:
        ModelError: On the first problem found, naming ``source`` and the dotted key.
    """
    if isinstance(data, Mapping) and "leg" in data:
        from rpr3gen.general_model import read_general

        return read_general(data, source)
    return _Reader(source).read(data)


class _Reader:
    """Validates one model description; every failure names ``source`` and a dotted key."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, key: str, message: str) -> NoReturn:
        raise ModelError(_one_line(f"{self.source}: {key}: {message}"))

    # -- structure -------------------------------------------------------------------------

    def read(self, data: Any) -> Model:
        if not isinstance(data, Mapping):
            raise ModelError(f"{self.source}: a model must be a table, got {_describe(data)}")
        self.check_keys(data, _SCHEMA, "")

        name = self.required(data, "name", "name")
        if not isinstance(name, str) or not name.strip():
            self.fail("name", f"must be a non-empty string, got {_describe(name)}")
        actuation = self.required(data, "actuation", "actuation")
        if actuation not in ACTUATIONS:
            hint = did_you_mean(actuation, ACTUATIONS) if isinstance(actuation, str) else ""
            self.fail(
                "actuation",
                f"must be one of {_quoted(ACTUATIONS)}, got {_describe(actuation)}{hint}",
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

    def check_keys(self, table: Mapping[Any, Any], schema: Mapping[str, Any], prefix: str) -> None:
        for key in table:
            dotted = f"{prefix}{key}"
            if key not in schema:
                hint = did_you_mean(str(key), schema) or self.elsewhere(str(key), prefix)
                self.fail(dotted, f"unknown key{hint}")
            sub = schema[key]
            if isinstance(sub, dict):
                value = table[key]
                if not isinstance(value, Mapping):
                    self.fail(dotted, f"must be a table [{dotted}], got {_describe(value)}")
                self.check_keys(value, sub, f"{dotted}.")

    def elsewhere(self, key: str, prefix: str) -> str:
        """Hint for a key that belongs in another table (e.g. ``l0`` at the top level)."""
        for section, sub in _SCHEMA.items():
            if isinstance(sub, dict) and key in sub and prefix != f"{section}.":
                return f"; it belongs in [{section}]"
        return ""

    def required(self, table: Mapping[str, Any], dotted: str, key: str) -> Any:
        if key not in table:
            self.fail(dotted, "missing required key")
        return table[key]

    def table(self, data: Mapping[str, Any], key: str, *, required: bool) -> Mapping[str, Any]:
        if key not in data:
            if required:
                self.fail(key, f"missing required table [{key}]")
            return {}
        return data[key]  # type checked by check_keys

    # -- values ----------------------------------------------------------------------------

    def number(
        self,
        table: Mapping[str, Any],
        dotted: str,
        key: str,
        *,
        default: float | None = None,
        positive: bool = False,
        why_required: str = "",
    ) -> float:
        if key not in table:
            if default is None:
                self.fail(dotted, f"missing required key{why_required}")
            return float(default)
        return self.scalar(table[key], dotted, positive=positive)

    def scalar(self, value: Any, dotted: str, *, positive: bool = False) -> float:
        kind = "a positive number" if positive else "a number"
        if isinstance(value, bool | np.bool_) or not isinstance(value, Real):
            self.fail(dotted, f"must be {kind}, got {_describe(value)}")
        try:
            x = float(value)
        except OverflowError:  # an integer beyond float64 (TOML integers have no bound)
            self.fail(dotted, f"must be a finite number, got {_describe(value)}")
        if not math.isfinite(x):
            self.fail(dotted, f"must be a finite number, got {_describe(value)}")
        if positive and x <= 0.0:
            self.fail(dotted, f"must be {kind}, got {_describe(value)}")
        return x

    def vector(
        self,
        table: Mapping[str, Any],
        dotted: str,
        key: str,
        length: int,
        default: Sequence[float] | None = None,
    ) -> tuple[float, ...]:
        if key not in table:
            if default is None:
                self.fail(dotted, "missing required key")
            return tuple(float(v) for v in default)
        value = _as_list(table[key])
        if not isinstance(value, list) or len(value) != length:
            self.fail(dotted, f"must be a list of {length} numbers, got {_describe(table[key])}")
        return tuple(self.scalar(v, f"{dotted}[{i}]") for i, v in enumerate(value))

    def points(
        self,
        table: Mapping[str, Any],
        dotted: str,
        key: str,
        shape: str = "a list of 3 points [[x, y], [x, y], [x, y]]",
        count: int = 3,
    ) -> list[tuple[float, ...]]:
        value = _as_list(table[key])
        if not isinstance(value, list) or len(value) != count:
            self.fail(dotted, f"must be {shape}, got {_describe(table[key])}")
        return [self.vector({"p": p}, f"{dotted}[{i}]", "p", 2) for i, p in enumerate(value)]

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
                    f"platform joint {leg}3 both at {_point(b)})",
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
                        f"{_point(points[i])}",
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


def _as_list(value: Any) -> Any:
    """Lists, tuples and numpy arrays become lists; anything else is returned unchanged."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return list(value)
    return value


def _describe(value: Any) -> str:
    """Short, one-line description of a value as the user wrote it (TOML spelling)."""
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, str):
        text = json.dumps(value, ensure_ascii=False)
        return text if len(text) <= 40 else text[:36] + '..."'
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, list | tuple | np.ndarray):
        n = len(value)
        return f"a list of {n} item{'s' if n != 1 else ''}"
    if isinstance(value, int | np.integer):
        return _integer(int(value))
    if isinstance(value, Real):
        return repr(float(value))
    return f"a value of type {type(value).__name__}"


def _integer(value: int) -> str:
    """An integer as written, or its first digits and its size when it is too long to show
    (TOML integers have no bound: ``10**400`` is a valid one)."""
    text = repr(value)
    if len(text) <= 24:
        return text
    return f"{text[:12]}... (an integer of {len(text.lstrip('-'))} digits)"


def _quoted(words: Sequence[str]) -> str:
    return " or ".join(f'"{w}"' for w in words)


def _point(p: Sequence[float]) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _one_line(text: str) -> str:
    return " ".join(text.splitlines())
