"""Render generated sources from the specs through Jinja2 templates, and write or check them.

Output is byte-identical for identical sources: no dates, versions, paths or hash-seed order.
The header carries a SHA-256 of the derivation's own files (``derive/*.py`` and templates).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

import jinja2
from rpr3gen_derive.batch import plan
from rpr3gen_derive.cse import straight_line
from rpr3gen_derive.lowering import lower_numpy
from rpr3gen_derive.printers import c_code, numpy_code
from rpr3gen_derive.specs import ACTUATIONS, OUTPUT_DOCS, PARAM_DOCS, build_spec

PACKAGE_DIR = Path(__file__).resolve().parent
TEMPLATE_DIR = PACKAGE_DIR / "templates"


def source_hash() -> str:
    """SHA-256 of every file the generated code is derived from, by relative path and content."""
    digest = hashlib.sha256()
    files = sorted(PACKAGE_DIR.glob("*.py")) + sorted(TEMPLATE_DIR.glob("*.jinja"))
    for path in files:
        digest.update(path.relative_to(PACKAGE_DIR).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes().replace(b"\r\n", b"\n"))
        digest.update(b"\0")
    return digest.hexdigest()


def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(TEMPLATE_DIR),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )


def render_variant(actuation: str, digest: str | None = None) -> dict[str, str]:
    """Sources of one actuation scheme, ``{relative path: text}``, under ``{actuation}/``."""
    spec = build_spec(actuation)
    code = straight_line(spec)
    used = set().union(*(rhs.free_symbols for _, rhs in code.assignments + code.outputs))
    used_names = {str(sym) for sym in used}
    inputs = {sym: str(sym) for _, symbols in spec.inputs for sym in symbols}
    params = {sym for sym in used if str(sym) in spec.param_names}
    rows = {name: f"out[{k}]" for k, name in enumerate(spec.output_names)}
    lowered = lower_numpy(code, inputs, params, rows)
    env = _environment()
    context = {
        "lowered": lowered,
        "spec": spec,
        "source_hash": digest or source_hash(),
        "ops_before": code.ops_before,
        "ops_after": code.ops_after,
        "used_params": [(k, n) for k, n in enumerate(spec.param_names) if n in used_names],
        "used_inputs": [
            (group, k, str(sym))
            for group, symbols in spec.inputs
            for k, sym in enumerate(symbols)
            if str(sym) in used_names
        ],
        "assignments": [(str(lhs), numpy_code(rhs)) for lhs, rhs in code.assignments],
        "outputs": [(k, numpy_code(rhs)) for k, (_, rhs) in enumerate(code.outputs)],
        "c_assignments": [(str(lhs), c_code(rhs)) for lhs, rhs in code.assignments],
        "batch": _c_batch(code, set(inputs), params),
        "c_outputs": [(k, c_code(rhs)) for k, (_, rhs) in enumerate(code.outputs)],
        "conditioning_index": spec.output_names.index("conditioning"),
        "params_doc": PARAM_DOCS,
        "outputs_doc": OUTPUT_DOCS,
    }
    templates = {
        "__init__.py": "variant_init.py.jinja",
        "rpr3_numpy.py": "numpy_module.py.jinja",
        "rpr3.h": "c_header.h.jinja",
        "rpr3.c": "c_source.c.jinja",
    }
    return {
        f"{actuation}/{name}": env.get_template(template).render(context)
        for name, template in templates.items()
    }


def _c_batch(code, inputs: set, params: set) -> dict[str, object]:
    """The three passes of the C batch loop (see :mod:`rpr3gen_derive.batch`), printed."""
    p = plan(code, inputs, params)

    def lines(statements):
        return [(str(lhs), c_code(rhs)) for lhs, rhs in statements]

    return {
        "constants": lines(p.constants),
        "pass_a": lines(p.pass_a),
        "pass_b": lines(p.pass_b),
        "pass_c": lines(p.pass_c),
        "a_arrays": sorted({str(s) for s in p.a_to_b + p.a_to_c}),
        "a_to_b": [str(s) for s in p.a_to_b],
        "a_to_c": [str(s) for s in p.a_to_c],
        "b_to_c": [str(s) for s in p.b_to_c],
        "outputs_b": [(k, c_code(e)) for k, e in p.outputs_b],
        "outputs_c": [(k, c_code(e)) for k, e in p.outputs_c],
    }


def render(actuations: Iterable[str] = ACTUATIONS) -> dict[str, str]:
    """Every generated file for the given actuation schemes, ``{relative path: text}``."""
    digest = source_hash()
    files: dict[str, str] = {}
    for actuation in actuations:
        files.update(render_variant(actuation, digest))
    # The package's name tables hold for every variant (the specs are cached by now).
    specs = [build_spec(actuation) for actuation in ACTUATIONS]
    if len({(spec.param_names, spec.output_names) for spec in specs}) != 1:
        raise ValueError("the actuation variants disagree on their parameter or output names")
    context = {
        "source_hash": digest,
        "actuations": ACTUATIONS,
        "param_names": specs[0].param_names,
        "output_names": specs[0].output_names,
    }
    files["__init__.py"] = _environment().get_template("package_init.py.jinja").render(context)
    return dict(sorted(files.items()))


def stale_files(out_dir: Path, files: dict[str, str]) -> list[str]:
    """Relative paths whose content on disk differs from ``files`` (or that are missing)."""
    stale = []
    for rel, text in files.items():
        path = out_dir / rel
        if not path.is_file() or path.read_bytes() != text.encode():
            stale.append(rel)
    return stale


def write_files(out_dir: Path, files: dict[str, str]) -> list[str]:
    """Write ``files`` under ``out_dir``; return the paths that changed.

    Every file is first written to a temporary file beside its target; only when all are written
    are they renamed into place, so an error leaves the previous sources as they were.
    """
    changed = stale_files(out_dir, files)
    staged: list[tuple[str, Path]] = []
    try:
        for rel in changed:
            target = out_dir / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, name = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as handle:
                handle.write(files[rel])
            staged.append((rel, Path(name)))
        for rel, temporary in staged:
            os.replace(temporary, out_dir / rel)
    except BaseException:
        for _, temporary in staged:
            temporary.unlink(missing_ok=True)
        raise
    return changed


def default_out_dir() -> Path | None:
    """``generated/`` beside ``derive/`` in a source checkout, or None when there is none."""
    out = PACKAGE_DIR.parent / "generated"
    return out if (out / "__init__.py").is_file() else None
