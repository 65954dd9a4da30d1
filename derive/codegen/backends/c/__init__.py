"""The C99 backend: a header and a source per variant, needing only ``<math.h>``, ``<stddef.h>``,
and the files that make them a CMake and pkg-config package (:mod:`.package`).

Per function ``f`` of a module with prefix ``p``: ``int p_f(params, inputs..., outputs...)`` for
one sample (outputs untouched unless it returns ``P_OK``) and ``size_t p_f_batch(params, n,
inputs..., outputs...)`` over n row-major samples, evaluated in three passes so that the
compiler vectorises them (:mod:`.batch`). Both run the same statements and the same math
kernels (:mod:`rpr3gen_derive.codegen.mathkernels`); a batch sample that fails a check, or
whose ``sin``/``cos`` argument is beyond the kernels' fast path, is evaluated again by the
single-sample kernel.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import jinja2
from rpr3gen_derive.codegen import mathkernels
from rpr3gen_derive.codegen.backends.c import package, sincos
from rpr3gen_derive.codegen.backends.c.batch import NotSplittableError, plan
from rpr3gen_derive.codegen.backends.c.lanes import lanes, plain
from rpr3gen_derive.codegen.backends.c.order import Line, schedule
from rpr3gen_derive.codegen.backends.c.printer import c_code, fast_trig_arguments
from rpr3gen_derive.codegen.compiled import name_tables, table_count
from rpr3gen_derive.codegen.spec import ModuleSpec

if TYPE_CHECKING:
    from rpr3gen_derive.codegen.compiled import Compiled, Stage


WIDTH = 100


def signature(head: str, params: list[str], tail: str = "") -> str:
    """A C declarator ``head(p1, p2, ...)tail`` wrapped at :data:`WIDTH`, aligned on ``(``."""
    indent = " " * (len(head) + 1)
    lines = [f"{head}("]
    for k, param in enumerate(params):
        text = param + ("," if k < len(params) - 1 else ")" + tail)
        if lines[-1].endswith("(") or len(lines[-1]) + 1 + len(text) <= WIDTH:
            lines[-1] += ("" if lines[-1].endswith("(") else " ") + text
        else:
            lines.append(indent + text)
    return "\n".join(lines)


def comment(text: str, first: str, rest: str, width: int = WIDTH - 4) -> str:
    """``text`` as lines of a C block comment: ``first`` before the first, ``rest`` the others."""
    words, lines = text.split(), [first]
    for word in words:
        if len(lines[-1]) + 1 + len(word) > width and lines[-1].strip(" *"):
            lines.append(rest)
        lines[-1] += ("" if lines[-1].endswith(" ") else " ") + word
    return "\n".join(lines)


def _lines(statements: Any, prefix: str, fast: bool = False) -> list[tuple[str, str]]:
    return [(str(lhs), c_code(rhs, prefix, fast)) for lhs, rhs in statements]


def _kernel_lines(
    c: Compiled, prefix: str, outputs: list[tuple[str, int, str]], public_only: bool = False
) -> list[Line]:
    """The single-sample kernel's loads, assignments and output stores, scheduled
    (:func:`.order.schedule`) so that few values are live at once; ``public_only``: the stores
    of the public outputs and what they need, nothing else (the values-only kernel)."""

    def names(expr: Any) -> frozenset[str]:
        return frozenset(str(s) for s in expr.free_symbols)

    none: frozenset[str] = frozenset()
    lines = [Line("load", name, none, (f"params[{k}]",)) for k, name in c.used_params]
    lines += [Line("load", name, none, (f"{arg}[{k}]",)) for arg, k, name in c.used_inputs]
    lines += [Line("assign", str(lhs), names(rhs), (c_code(rhs, prefix),))
              for lhs, rhs in c.code.assignments]  # fmt: skip
    stored = zip(outputs, c.code.outputs, strict=True)
    lines += [Line("store", "", names(e), (out, str(index), text))
              for (out, index, text), (_, e) in stored]  # fmt: skip
    if public_only:
        hidden = {o.name for o in c.spec.outputs if o not in c.spec.public_outputs}
        lines = _needed([x for x in lines if x.kind != "store" or x.payload[0] not in hidden])
    return schedule(lines)


def _code(lines: list[Line], param_count: int, prefix: str, legs: str) -> list[str]:
    """A kernel's statements as C lines: its legs (the module's letters) as lane loops
    (:mod:`.lanes`) when it has enough statements to share them, else one statement after the
    other; a sine and a cosine of one argument as one call (:mod:`.sincos`)."""
    return sincos.pair(lanes(lines, param_count, legs) or plain(lines), prefix)


def _needed(lines: list[Line]) -> list[Line]:
    """The stores of ``lines`` and the lines they read, transitively, in order."""
    defined = {x.name: x for x in lines if x.name}
    wanted = {x.name for x in lines if x.kind == "store"}
    pending = [r for x in lines if x.kind == "store" for r in x.reads]
    while pending:
        name = pending.pop()
        if name in defined and name not in wanted:
            wanted.add(name)
            pending.extend(defined[name].reads)
    return [x for x in lines if x.kind == "store" or x.name in wanted]


def _function(module: ModuleSpec, c: Compiled, values: bool = False) -> dict[str, Any]:
    """Template context of one function; ``values``: with its values-only kernel too."""

    prefix, spec = module.prefix, c.spec
    upper = prefix.upper()
    params = c.param_symbols(module.params)
    try:
        p = None if spec.c_body else plan(c.code, c.input_symbols, params)
    except NotSplittableError:  # the batch loops over the kernel instead
        p = None
    slot = dict(enumerate(c.slots))
    count = len(module.params.symbols)

    def outputs(indexed: Any, fast: bool = False) -> list[tuple[str, int, str]]:
        return [(*slot[k], c_code(e, prefix, fast)) for k, e in indexed]

    sizes = {
        o.name: f"{upper}_{table_count(o.table)}" if o.table else str(o.size) for o in spec.outputs
    }
    name = f"{prefix}_{spec.name}"
    single = ["const double *params"]
    single += [f"const double {a.name}[{a.size}]" for a in spec.inputs]
    single += [f"double {o.name}[{sizes[o.name]}]" for o in spec.public_outputs]
    batch = ["const double *params", "size_t n"]
    batch += [f"const double *{a.name}" for a in spec.inputs]
    batch += [f"double *{o.name}" for o in spec.public_outputs]
    kernel = ["const double *restrict params"]
    kernel += [f"const double *restrict {a.name}" for a in spec.inputs]
    kernel += [f"double *restrict r_{o.name}" for o in spec.outputs]
    values_params = kernel[: 1 + len(spec.inputs)]
    values_params += [f"double *restrict r_{o.name}" for o in spec.public_outputs]
    checks = []
    input_code = None
    custom_code = None
    for check in spec.checks:
        code = f"{upper}_{check.code}"
        if check.kind == "inputs_not_finite":
            input_code = code
        elif check.kind == "below":
            out = spec.output(str(check.output))
            index = [comp.name for comp in out.components].index(str(check.component))
            checks.append(
                {
                    "kind": "below",
                    "code": code,
                    "output": out.name,
                    "index": index,
                    "threshold": f"{upper}_{check.threshold}",
                }
            )
        elif check.kind == "outputs_not_finite":
            checks.append({"kind": check.kind, "code": code})
        else:
            custom_code = code
    return {
        "spec": spec,
        "name": name,
        "single": signature(f"int {name}", single),
        "batch_signature": signature(f"size_t {name}_batch", batch),
        "kernel": signature(f"static int {name}_kernel", kernel),
        "kernel_cold": signature(f"{upper}_COLD int {name}_kernel_cold", kernel),
        "sizes": sizes,
        "used_params": c.used_params,
        "used_inputs": c.used_inputs,
        "assignments": _lines(c.code.assignments, prefix),
        "kernel_lines": _code(
            _kernel_lines(c, prefix, outputs(enumerate(e for _, e in c.code.outputs))),
            count,
            prefix,
            module.legs,
        ),
        "values_lines": (
            _code(
                _kernel_lines(c, prefix, outputs(enumerate(e for _, e in c.code.outputs)), True),
                count,
                prefix,
                module.legs,
            )
            if values
            else None
        ),
        "values_signature": signature(f"static void {name}_values", values_params),
        "input_code": input_code,
        "custom_code": custom_code,
        "checks": checks,
        "body": spec.c_body,
        "context": dict(spec.c_context),
        "ops_before": c.code.ops_before,
        "ops_after": c.code.ops_after,
        "batch": None if p is None else _batch(prefix, p, outputs),
    }


def _batch(prefix: str, p: Any, outputs: Any) -> dict[str, Any]:
    """Template context of a function's three-pass batch (:mod:`.batch`)."""
    fast_exprs = [e for _, e in p.pass_b] + [e for _, e in p.outputs_b]
    return {
        "constants": _lines(p.constants, prefix),
        "pass_a": _lines(p.pass_a, prefix),
        "pass_b": _lines(p.pass_b, prefix, fast=True),
        "pass_c": _lines(p.pass_c, prefix),
        "a_arrays": sorted({str(s) for s in p.a_to_b + p.a_to_c}),
        "a_to_b": [str(s) for s in p.a_to_b],
        "a_to_c": [str(s) for s in p.a_to_c],
        "b_to_c": [str(s) for s in p.b_to_c],
        "outputs_b": outputs(p.outputs_b, fast=True),
        "outputs_c": outputs(p.outputs_c),
        # sin/cos arguments of pass B: beyond the fast path, the sample is evaluated again
        "fast_trig": [c_code(arg, prefix) for arg in fast_trig_arguments(fast_exprs)],
    }


def render(
    module: ModuleSpec,
    compiled: list[Compiled],
    digest: str,
    env: jinja2.Environment,
    stage: Stage,
) -> dict[str, tuple[str, str]]:
    """``{"c_header": (name, text), "c_source": (name, text), ...}`` of one module, with the
    package files of :func:`.package.render` (``c_cmake``, ``c_pkgconfig``). A translation unit
    of its own (:attr:`FunctionSpec.unit`) gets ``c_header_{unit}`` and ``c_source_{unit}``: the
    main header declares only the main unit's functions, so that a variant whose unit is
    deferred (:attr:`ModuleSpec.deferred`) has the same main files as the whole one."""

    with stage("print"):
        values = {name for c in compiled for name in c.spec.c_values}
        functions = {c.spec.name: _function(module, c, c.spec.name in values) for c in compiled}
    units = sorted({c.spec.unit for c in compiled if c.spec.unit})
    main = [c for c in compiled if not c.spec.unit]
    tables = name_tables(module, main)
    files: dict[str, tuple[str, str]] = {}
    with stage("render"):
        header = env.get_template("backends/c/templates/header.h.jinja")
        files["c_header"] = (
            f"{module.prefix}.h",
            header.render(_context(module, main, functions, digest, tables)),
        )
        source = env.get_template("backends/c/templates/source.c.jinja")
        files["c_source"] = (
            f"{module.prefix}.c",
            source.render(_context(module, main, functions, digest, tables)),
        )
        unit_header = env.get_template("backends/c/templates/unit_header.h.jinja")
        for unit in units:
            members = [c for c in compiled if c.spec.unit == unit]
            context = _context(module, members, functions, digest, [], unit)
            files[f"c_header_{unit}"] = (f"{module.prefix}_{unit}.h", unit_header.render(context))
            files[f"c_source_{unit}"] = (f"{module.prefix}_{unit}.c", source.render(context))
        names = {"header": files["c_header"][0], "source": files["c_source"][0]}
        extra = [files[f"c_source_{unit}"][0] for unit in units]
        headers = [files[f"c_header_{unit}"][0] for unit in units]
        files.update(
            package.render(module, digest, env, **names, extra_sources=extra, extra_headers=headers)
        )
    return files


def _context(
    module: ModuleSpec,
    compiled: list[Compiled],
    functions: dict[str, dict[str, Any]],
    digest: str,
    tables: list[Any] | None = None,
    unit: str = "",
) -> dict[str, Any]:
    """The templates' context for the functions ``compiled`` (one translation unit, or all
    of them for the header); ``tables``: the name tables the unit defines (the main one)."""
    chosen = [functions[c.spec.name] for c in compiled]
    kernels = mathkernels.used(
        e for c in compiled for e in [rhs for _, rhs in c.code.assignments + c.code.outputs]
    )
    kernels |= {k for c in compiled for k in c.spec.c_kernels}
    return {
        "module": module,
        "functions": chosen,
        "tables": name_tables(module, compiled) if tables is None else tables,
        "source_hash": digest,
        "upper": module.prefix.upper(),
        "prefix": module.prefix,
        "unit": unit,
        "uses_finite": any(f["input_code"] or f["checks"] for f in chosen),
        "ops_before": sum(f["ops_before"] for f in chosen),
        "ops_after": sum(f["ops_after"] for f in chosen),
        "assignments": sum(len(f["assignments"]) for f in chosen),
        "math": mathkernels.context(kernels),
    }


__all__ = ["render"]
