"""Specs: the one source of each generated function, and of the module that holds them.

A :class:`FunctionSpec` names a function, its ordered per-sample inputs and outputs (each an
array of named, documented components), the program of assignments that computes the outputs,
its docstring and its failure conditions. Every generated artefact is drawn from it: the NumPy
function, the C declaration, definition and batch variant, the C name tables, the manifest the
runtime reads (and builds its C binding from), and the documentation of array layouts.

A :class:`ModuleSpec` gathers the functions of one generated module (one variant of a robot)
with what they share: the parameter vector, the return codes and the thresholds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import sympy as sp
from rpr3gen_derive.codegen.program import Program


@dataclass(frozen=True)
class Component:
    """One scalar of an argument: its name (an identifier), unit and meaning."""

    name: str
    unit: str = ""
    meaning: str = ""


@dataclass(frozen=True)
class Argument:
    """An input or the parameter vector: ordered symbols, one :class:`Component` each.

    ``table`` names the C name table (``{prefix}_{table}``) and its count macro
    (``{PREFIX}_NUM_{TABLE}``, the table's last word) when the argument has one.
    """

    name: str
    symbols: tuple[sp.Symbol, ...]
    components: tuple[Component, ...]
    doc: str
    table: str | None = None

    def __post_init__(self) -> None:
        if len(self.symbols) != len(self.components):
            raise ValueError(f"argument {self.name}: symbols and components differ in number")

    @property
    def size(self) -> int:
        return len(self.symbols)


@dataclass(frozen=True)
class Output:
    """An output array: one expression per component, in program symbols.

    A ``hidden`` output is not part of the C interface: the engine makes one, ``guards``, of the
    values that checks test when they are not outputs (see :class:`Check`).
    """

    name: str
    exprs: tuple[sp.Expr, ...]
    components: tuple[Component, ...]
    doc: str
    table: str | None = None
    hidden: bool = False

    def __post_init__(self) -> None:
        if len(self.exprs) != len(self.components):
            raise ValueError(f"output {self.name}: expressions and components differ in number")

    @property
    def size(self) -> int:
        return len(self.exprs)


@dataclass(frozen=True)
class ReturnCode:
    """A return code of every function of a module (``{PREFIX}_{name}``)."""

    name: str
    value: int
    meaning: str


@dataclass(frozen=True)
class Threshold:
    """A named constant of the failure conditions (``{PREFIX}_{name}``).

    ``literal`` is how it is written in C and Python (``"1e-9"``).
    """

    name: str
    literal: str
    meaning: str

    @property
    def value(self) -> float:
        return float(self.literal)


CheckKind = Literal["inputs_not_finite", "below", "outputs_not_finite", "custom"]


@dataclass(frozen=True)
class Check:
    """A failure condition; the first that holds gives the function's return code.

    ``inputs_not_finite``: an input component is NaN or infinite.
    ``below``: a value is below the threshold (or NaN): the output component
    ``output[component]``, or a ``guard`` value computed only for the check: its name and
    expression (``guard=("conditioning", expr)``), which the engine gathers into the hidden output
    ``guards`` of the function.
    ``outputs_not_finite``: an output component is NaN or infinite.
    ``custom``: a function with a hand-written C body (:attr:`FunctionSpec.c_body`) returns this
    code when it fails.

    The batch functions report a failed sample as a row of NaN, so after the input check all the
    checks of a function must give the same code (:class:`ModuleSpec` enforces it).
    """

    kind: CheckKind
    code: str
    output: str | None = None
    component: str | None = None
    threshold: str | None = None
    guard: tuple[str, sp.Expr] | None = None


@dataclass(frozen=True)
class FunctionSpec:
    """A generated function ``outputs = f(params, inputs)``, computed by ``program``.

    A function whose work is not a straight-line program (an iteration, a search) names instead
    a template of its C kernel's body, ``c_body``, found in the robot's template folders and
    rendered with ``c_context``; it may call the kernels of the functions before it. It has no
    NumPy version (the runtime composes those from the others) and its outputs' expressions are
    unused.
    """

    name: str
    doc: str
    inputs: tuple[Argument, ...]
    outputs: tuple[Output, ...]
    program: Program
    checks: tuple[Check, ...] = ()
    c_body: str | None = None
    c_context: tuple[tuple[str, object], ...] = ()
    #: Math kernels the hand-written body calls (names of ``mathkernels.used``: ``"trig"``,
    #: ``"atan2"``, ``"rint"``, ``"minmax"``), emitted whether or not another function needs them.
    c_kernels: tuple[str, ...] = ()
    #: Functions whose values-only kernel (``{prefix}_{name}_values``: the public outputs, no
    #: check, no hidden output) the hand-written body calls.
    c_values: tuple[str, ...] = ()
    #: The C translation unit of the function: "" the variant's source, else a source file of
    #: its own (``{prefix}_{unit}.c``) that the runtime compiles, into a library of its own
    #: linked to the main one, only when one of its functions is first called (the derivatives:
    #: large kernels that need not slow every first use). Its hand-written body may call the
    #: main unit's public functions, not its kernels.
    unit: str = ""
    #: The program is already free of common subexpressions (written so by
    #: :mod:`rpr3gen_derive.codegen.adjoint`): the engine keeps its statements as they are.
    straight: bool = False

    def __post_init__(self) -> None:
        guards = [c.guard for c in self.checks if c.guard is not None]
        if not guards:
            return
        hidden = Output(
            "guards",
            tuple(expr for _, expr in guards),
            tuple(Component(name, "1", "value a failure condition tests") for name, _ in guards),
            "values the failure conditions test (internal)",
            hidden=True,
        )
        checks = tuple(
            Check(c.kind, c.code, "guards", c.guard[0], c.threshold) if c.guard else c
            for c in self.checks
        )
        object.__setattr__(self, "outputs", (*self.outputs, hidden))
        object.__setattr__(self, "checks", checks)

    @property
    def public_outputs(self) -> tuple[Output, ...]:
        """The outputs of the C interface (all but the hidden ones)."""
        return tuple(o for o in self.outputs if not o.hidden)

    def output(self, name: str) -> Output:
        return next(o for o in self.outputs if o.name == name)

    def flat_outputs(self) -> list[tuple[str, int, sp.Expr]]:
        """``(output name, component index, expression)`` for every output component, in order."""
        return [(o.name, k, e) for o in self.outputs for k, e in enumerate(o.exprs)]


@dataclass(frozen=True)
class ModuleSpec:
    """The functions of one generated module and what they share.

    ``prefix`` starts every C name (``rpr3_inverse_dynamics``, ``RPR3_OK``) and the generated
    files' names (``rpr3.h``, ``rpr3.c``, ``rpr3_numpy.py``). ``defines`` are extra C macros,
    ``(name, C literal, comment)``. ``tables`` are extra name tables (each an :class:`Argument`
    with a ``table``), for indices that no function's input or output names one by one (e.g.
    the columns of a matrix output).

    ``legs`` are the letters of the robot's legs, in order (``"ABC"``, ``"ABCDEF"``): a leg's
    symbols are named alike but for its letter at one place (``bx_A`` ... ``bx_F``), and the
    engine names each leg's temporaries after the first leg's (:mod:`.legnames`) and runs the
    legs' alike statements side by side (the C lanes, the NumPy backend's leg blocks). Empty
    (the default) or one leg: nothing is shared between legs.

    ``deferred`` names functions of the variant that this module leaves out, for the runtime to
    derive when one is first called (its cache does so with the derivatives, which take most of
    a variant's derivation): the manifest lists them, so that the runtime knows to.
    """

    prefix: str
    variant: str
    doc: str
    params: Argument
    functions: tuple[FunctionSpec, ...]
    return_codes: tuple[ReturnCode, ...]
    thresholds: tuple[Threshold, ...] = ()
    defines: tuple[tuple[str, str, str], ...] = field(default_factory=tuple)
    tables: tuple[Argument, ...] = field(default_factory=tuple)
    legs: str = ""
    deferred: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if len(set(self.legs)) != len(self.legs) or not all(
            leg.isascii() and leg.isupper() for leg in self.legs
        ):
            raise ValueError(f"legs must be distinct capital letters, not {self.legs!r}")
        if any(t.table is None for t in self.tables):
            raise ValueError("an extra name table needs a table name")
        codes = {c.name for c in self.return_codes}
        thresholds = {t.name for t in self.thresholds}
        if "OK" not in codes or next(c for c in self.return_codes if c.name == "OK").value != 0:
            raise ValueError("a module needs the return code OK = 0")
        names = [f.name for f in self.functions]
        if len(set(names)) != len(names):
            raise ValueError(f"functions defined twice in {names}")
        if set(self.deferred) & set(names):
            raise ValueError(f"deferred functions defined here: {set(self.deferred) & set(names)}")
        for function in self.functions:
            later = {c.code for c in function.checks if c.kind != "inputs_not_finite"}
            if len(later) > 1:
                raise ValueError(f"{function.name}: checks after the input check differ in code")
            for check in function.checks:
                if check.code not in codes:
                    raise ValueError(f"{function.name}: unknown return code {check.code!r}")
                if check.kind == "below":
                    if check.threshold not in thresholds:
                        raise ValueError(f"{function.name}: unknown threshold {check.threshold!r}")
                    out = function.output(str(check.output))
                    if check.component not in [c.name for c in out.components]:
                        raise ValueError(f"{function.name}: no output {check.component!r}")

    def code(self, name: str) -> ReturnCode:
        return next(c for c in self.return_codes if c.name == name)
