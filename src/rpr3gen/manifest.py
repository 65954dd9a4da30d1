"""The generated code's manifest: every function's signature, name tables, thresholds and codes.

``rpr3gen generate`` writes one ``manifest.json`` per variant beside the generated NumPy and C
sources. The runtime reads nothing else about the generated functions: it calls them by name,
builds the C binding and applies the failure policy (:mod:`rpr3gen.failures`) from it.

A generated folder is either the installed package ``rpr3gen_generated`` (the default) or any
folder written by ``rpr3gen generate --out DIR`` (``load_model(..., generated=DIR)``).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from functools import cache
from importlib import resources
from pathlib import Path

from rpr3gen.errors import GeneratedCodeError

#: The manifest format this runtime reads.
FORMAT = 1


@dataclass(frozen=True)
class ArgInfo:
    """An input or output array of a generated function: its component names and units."""

    name: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    doc: str
    table: str | None = None
    hidden: bool = False  # an output the failure checks read, not part of the C interface

    @property
    def size(self) -> int:
        return len(self.names)


@dataclass(frozen=True)
class CheckInfo:
    """A failure condition (see ``derive/codegen/spec.py``), resolved to numbers."""

    kind: str  # "inputs_not_finite", "below" or "outputs_not_finite"
    code: int
    output: int | None = None  # index of the output array ("below")
    component: int | None = None  # index of the component in it ("below")
    threshold: float | None = None  # ("below")


@dataclass(frozen=True)
class FunctionInfo:
    """One generated function, as the manifest describes it."""

    name: str
    c_symbol: str
    c_batch_symbol: str
    numpy_function: str | None  # None: C only (a hand-written kernel body)
    doc: str
    inputs: tuple[ArgInfo, ...]
    outputs: tuple[ArgInfo, ...]  # the public ones first, then any hidden one
    checks: tuple[CheckInfo, ...]
    #: Its C translation unit: "" the variant's source, else ``c_source_{unit}`` (a library of
    #: its own, built when one of its functions is first called).
    unit: str = ""

    @property
    def public_outputs(self) -> tuple[ArgInfo, ...]:
        """The outputs of the C interface and of the Python API."""
        return tuple(o for o in self.outputs if not o.hidden)


@dataclass(frozen=True)
class Variant:
    """One generated variant (a folder with ``manifest.json``, NumPy and C sources)."""

    folder: Path
    prefix: str
    variant: str
    source_hash: str
    files: dict[str, str]
    param_names: tuple[str, ...]
    return_codes: dict[str, int]
    code_meanings: dict[int, str]
    thresholds: dict[str, float]
    functions: dict[str, FunctionInfo]
    tables: dict[str, tuple[str, ...]] = field(default_factory=dict)  # extra name tables
    #: The C header's extra macros by name, as C literals (``LEG``: ``"\"UPS\""``, ``DOF``).
    defines: dict[str, str] = field(default_factory=dict)
    #: Functions of the variant that this folder leaves out: the runtime's cache derives a
    #: variant without its derivatives, and them when one is first called (:mod:`.variants`).
    deferred: tuple[str, ...] = ()

    def function(self, name: str) -> FunctionInfo:
        """The function called ``name`` (without the prefix), or a clear error."""
        try:
            return self.functions[name]
        except KeyError:
            known = ", ".join(self.functions)
            raise GeneratedCodeError(
                f"{self.folder}: no generated function {name!r} (it has: {known}); "
                "run `rpr3gen generate`"
            ) from None

    def path(self, role: str) -> Path:
        """Path of a generated file by role: ``numpy``, ``c_header``, ``c_source``, ``c_cmake``
        or ``c_pkgconfig``."""
        return self.folder / self.files[role]


def regenerate_hint(folder: Path) -> str:
    """How to make a generated folder anew: ``rpr3gen generate --out FOLDER``, or for the
    installed package, reinstalling (or ``rpr3gen generate`` in a source tree)."""
    if folder.resolve() == default_folder().resolve():
        return "reinstall rpr3gen, or run `rpr3gen generate` in its source tree"
    return f"regenerate it: rpr3gen generate --out {folder}"


@cache
def default_folder() -> Path:
    """Folder of the installed generated package ``rpr3gen_generated`` (looked up once: every
    array call asks for it, and ``importlib.resources`` takes ~30 µs to answer)."""
    return Path(str(resources.files("rpr3gen_generated")))


def _folder(generated: str | os.PathLike[str] | None) -> Path:
    return default_folder() if generated is None else Path(generated).resolve()


def _arg(data: dict) -> ArgInfo:
    comps = data["components"]
    return ArgInfo(
        name=data["name"],
        names=tuple(c["name"] for c in comps),
        units=tuple(c["unit"] for c in comps),
        doc=data["doc"],
        table=data.get("table"),
        hidden=bool(data.get("hidden", False)),
    )


def _function(data: dict, codes: dict[str, int], thresholds: dict[str, float]) -> FunctionInfo:
    outputs = tuple(_arg(o) for o in data["outputs"])
    checks = []
    for c in data["checks"]:
        if c["kind"] == "below":
            index = next(k for k, o in enumerate(outputs) if o.name == c["output"])
            checks.append(
                CheckInfo(
                    kind="below",
                    code=codes[c["code"]],
                    output=index,
                    component=outputs[index].names.index(c["component"]),
                    threshold=thresholds[c["threshold"]],
                )
            )
        else:
            checks.append(CheckInfo(kind=c["kind"], code=codes[c["code"]]))
    return FunctionInfo(
        name=data["name"],
        c_symbol=data["c_symbol"],
        c_batch_symbol=data["c_batch_symbol"],
        numpy_function=data["numpy_function"],
        doc=data["doc"],
        inputs=tuple(_arg(a) for a in data["inputs"]),
        outputs=outputs,
        checks=tuple(checks),
        unit=str(data.get("unit", "")),
    )


@cache
def _load(folder: Path, variant: str) -> Variant:
    path = folder / variant / "manifest.json"
    hint = regenerate_hint(folder)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        found = ", ".join(available(folder)) or "none"
        raise GeneratedCodeError(
            f"{path}: no generated variant {variant!r} here (variants found: {found}); {hint}"
        ) from None
    except UnicodeDecodeError as exc:
        raise GeneratedCodeError(f"{path}: not UTF-8 text (byte {exc.start}); {hint}") from None
    except ValueError as exc:
        raise GeneratedCodeError(f"{path}: not JSON ({exc}); {hint}") from None
    except OSError as exc:
        raise GeneratedCodeError(f"{path}: cannot read it: {exc.strerror or exc}; {hint}") from None
    found_format = data.get("format") if isinstance(data, dict) else None
    if found_format != FORMAT:
        raise GeneratedCodeError(
            f"{path}: manifest format {found_format!r}, this runtime reads {FORMAT}; {hint}"
        )
    try:
        return _variant(folder, variant, data)
    except KeyError as exc:
        raise GeneratedCodeError(
            f"{path}: damaged: no key {exc.args[0]!r} where one is needed; {hint}"
        ) from None
    except (TypeError, ValueError, AttributeError, StopIteration) as exc:
        raise GeneratedCodeError(
            f"{path}: damaged: {type(exc).__name__}: {exc or 'a value of the wrong kind'}; {hint}"
        ) from None


def _variant(folder: Path, variant: str, data: dict) -> Variant:
    """The :class:`Variant` of a parsed manifest (KeyError, TypeError... when damaged)."""
    codes = {c["name"]: int(c["value"]) for c in data["return_codes"]}
    thresholds = {t["name"]: float(t["value"]) for t in data["thresholds"]}
    found = Variant(
        folder=folder / variant,
        prefix=str(data["prefix"]),
        variant=str(data["variant"]),
        source_hash=str(data["source_hash"]),
        files={str(k): str(v) for k, v in dict(data["files"]).items()},
        param_names=tuple(str(p["name"]) for p in data["params"]),
        return_codes=codes,
        code_meanings={int(c["value"]): str(c["meaning"]) for c in data["return_codes"]},
        thresholds=thresholds,
        functions={f["name"]: _function(f, codes, thresholds) for f in data["functions"]},
        tables={
            name: tuple(c["name"] for c in comps) for name, comps in data.get("tables", {}).items()
        },
        defines={str(k): str(v) for k, v in dict(data.get("defines", {})).items()},
        deferred=tuple(str(name) for name in data.get("deferred", ())),
    )
    missing = [role for role in ("numpy", "c_header", "c_source") if role not in found.files]
    if missing:
        raise KeyError(f"files.{missing[0]}")
    return found


def load(variant: str, generated: str | os.PathLike[str] | None = None) -> Variant:
    """The manifest of ``variant`` in the generated folder ``generated`` (default: installed)."""
    return _load(_folder(generated), variant)


def available(generated: str | os.PathLike[str] | Path | None = None) -> tuple[str, ...]:
    """Variants present in a generated folder (sub-folders with a manifest), sorted."""
    folder = _folder(generated)
    if not folder.is_dir():
        return ()
    return tuple(sorted(p.parent.name for p in folder.glob("*/manifest.json")))
