"""Hostile input to every command: one line on stderr naming what is at fault, exit status 2,
no traceback, nothing written and nothing lost (issue 23; docs/errors.md).

One row of :data:`COMMANDS` per command: its valid invocation, its numeric options (each with
the values it takes), its outputs and its input files. The cases are drawn from the rows:
numbers that are not numbers, not finite, negative in any notation (``-1e-3`` is a value, never
an option), sizes beyond the memory limit; outputs below a regular file, of the wrong kind,
where nothing can be created, and an existing output left byte-identical by a failing run;
input files missing, a folder, unreadable, empty, damaged; a damaged ``--generated`` folder.
A new command joins by adding its row. The commands run in this process (``rpr3gen.cli.main``).
"""

from __future__ import annotations

import json
import math
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import rpr3gen
from rpr3gen import manifest
from rpr3gen.cli import main
from rpr3gen.excitation import FourierMotion
from rpr3gen.parameters import inertial_parameters

ROOT = Path(__file__).resolve().parent.parent
DELTA = str(ROOT / "models" / "delta.toml")
RRR = str(ROOT / "models" / "rrr.toml")
LOOP_PATH = str(ROOT / "models" / "loop-path.csv")

# -- the options' values ------------------------------------------------------------------


@dataclass(frozen=True)
class Numeric:
    """A numeric option: ``whole`` numbers or reals, within ``[least, most]`` (``below``: open),
    ``finite``; ``size``: refused beyond the memory limit (10^12 always is)."""

    whole: bool = False
    least: float = -math.inf
    most: float = math.inf
    below: float = math.inf
    finite: bool = True
    size: bool = False

    def takes(self, text: str) -> bool:
        value = float(text)
        if math.isnan(value) or (self.finite and math.isinf(value)):
            return False
        if self.whole and not (math.isfinite(value) and value.is_integer()):
            return False
        return self.least <= value <= self.most and (value < self.below or self.below == math.inf)


NOT_NUMBERS = ("x", "", "1,5", "0x10", "--")
NON_FINITE = ("nan", "inf", "-inf", "1e999", "-nan")
NEGATIVE = ("-1e-3", "-.5", "-1E+2", "-1", "-0.001")
HUGE = ("1e12", "1000000000000")


@dataclass(frozen=True)
class Command:
    """A row: see the module docstring.

    Attributes:
        name: the command.
        argv: a valid invocation (``tmp`` a temporary folder); the cases add to it or change it.
        numbers: numeric options (a positional's metavar for ``fk``'s readings).
        outputs: output options, True for a folder.
        inputs: input-file options and their kind (``"model"``, ``"csv"``, ``"grid"``...).
        failing: arguments that make the command fail after parsing (to show a number taken).
    """

    name: str
    argv: Callable[[Path], list[str]]
    numbers: dict[str, Numeric] = field(default_factory=dict)
    outputs: dict[str, bool] = field(default_factory=dict)
    inputs: dict[str, str] = field(default_factory=dict)
    failing: tuple[str, ...] = ("--model", "missing-model.toml")

    def __repr__(self) -> str:
        return self.name


MODEL_ = rpr3gen.load_model()
_RNG = np.random.default_rng(5)
_MOTION = FourierMotion(  # smooth and exciting: identify takes it (condition number 686)
    4.0, np.zeros(3), *(_RNG.uniform(-1.0, 1.0, (3, 3)) * [[0.05], [0.05], [0.3]] for _ in "ab")
)
_T = np.linspace(0.0, 4.0, 120)
_Q, _QD, _QDD = _MOTION.at(_T)
_TAU = rpr3gen.regressor(MODEL_, _Q, _QD, _QDD) @ inertial_parameters(MODEL_)
_TAU = _TAU + rpr3gen.payload_efforts(MODEL_, _Q)
_COLUMNS = "t,x,y,phi,dx,dy,dphi,ddx,ddy,ddphi,m10_A,m10_B,m10_C"


def data_csv(tmp: Path, rows: slice = slice(None)) -> str:
    """A valid identification data file (a trajectory and its efforts), 120 rows."""
    table = np.column_stack([_T, _Q, _QD, _QDD, _TAU])[rows]
    path = tmp / "data.csv"
    path.write_text(
        _COLUMNS + "\n" + "".join(",".join(map(repr, r)) + "\n" for r in table.tolist())
    )
    return str(path)


def grid_toml(tmp: Path) -> str:
    path = tmp / "grid.toml"
    path.write_text('"mass.m3" = [3.0, 4.0]\n')
    return str(path)


CONDITIONING = Numeric(least=0.0, below=1.0)
THREADS = Numeric(whole=True, least=1, size=True)
DURATION = Numeric(least=1e-6, most=1e9)
SMOOTHING = Numeric(least=0.0, most=1e100)

COMMANDS: tuple[Command, ...] = (
    Command(
        "simulate",
        lambda tmp: ["simulate", "--samples", "11"],
        numbers={
            "--samples": Numeric(whole=True, least=2, size=True),
            "--duration": DURATION,
            "--smoothing": SMOOTHING,
            "--min-conditioning": CONDITIONING,
            "--threads": THREADS,
        },
        outputs={"--out": False, "--plots": True},
        inputs={"--model": "model", "--trajectory": "trajectory", "--generated": "generated"},
    ),
    Command(
        "paper",
        lambda tmp: ["paper", "--out", str(tmp / "paper")],
        numbers={"--threads": THREADS},
        outputs={"--out": True},
        failing=("--backend", "gpu"),
    ),
    Command("params", lambda tmp: ["params"], inputs={"--model": "model"}),
    Command(
        "animate",
        lambda tmp: ["animate", "--out", str(tmp / "a.gif"), "--fps", "1", "--size", "240x240"],
        numbers={
            "--duration": DURATION,
            "--fps": Numeric(whole=True, least=1, most=60),
            "--speed": Numeric(least=0.0),
        },
        outputs={"--out": False},
        inputs={"--model": "model", "--trajectory": "trajectory"},
    ),
    Command(
        "fk",
        lambda tmp: ["fk", "0.1", "0.0", "0.0"],
        numbers={"QA": Numeric()},
        inputs={"--model": "model", "--generated": "generated"},
    ),
    Command(
        "generate",
        lambda tmp: ["generate", "--out", str(tmp / "generated")],
        outputs={"--out": True},
        inputs={"--model": "model"},
    ),
    Command(
        "identify",
        lambda tmp: ["identify", "--data", data_csv(tmp)],
        numbers={
            "--smoothing": SMOOTHING,
            "--warn-condition": Numeric(least=1.0, finite=False),
            "--max-condition": Numeric(least=1.0, finite=False),
        },
        outputs={"--out": False},
        inputs={"--model": "model", "--data": "data"},
    ),
    Command(
        "excite",
        lambda tmp: ["excite", "--out", str(tmp / "excite.csv")],
        numbers={
            "--harmonics": Numeric(whole=True, least=1, size=True),
            "--period": Numeric(least=0.0),
            "--samples": Numeric(whole=True, least=10, size=True),
            "--min-conditioning": CONDITIONING,
            "--seed": Numeric(whole=True, least=0),
            "--max-iterations": Numeric(whole=True, least=1, most=2**31 - 1),
            "--max-translation": Numeric(least=0.0),
            "--max-angle": Numeric(least=0.0),
        },
        outputs={"--out": False},
        inputs={"--model": "model"},
    ),
    Command(
        "workspace",
        lambda tmp: ["workspace", "--out", str(tmp / "ws")],
        numbers={
            "--phi": Numeric(),
            "--resolution": Numeric(whole=True, least=2, size=True),
            "--heights": Numeric(whole=True, least=1),
            "--min-conditioning": CONDITIONING,
        },
        outputs={"--out": True},
        inputs={"--model": "model"},
    ),
    Command(
        "retime",
        lambda tmp: [
            "retime",
            "--model",
            RRR,
            "--path",
            LOOP_PATH,
            "--effort-limit",
            "8",
            "--out",
            str(tmp / "fast.csv"),
            "--grid-points",
            "41",
            "--samples",
            "11",
        ],
        numbers={
            "--effort-limit": Numeric(least=0.0),  # > 0: no case tries 0 itself
            "--velocity-limit": Numeric(least=0.0),
            "--samples": Numeric(whole=True, least=2, size=True),
            "--grid-points": Numeric(whole=True, least=3, size=True),
            "--min-conditioning": CONDITIONING,
        },
        outputs={"--out": False},
        inputs={"--model": "model", "--path": "path", "--generated": "generated"},
    ),
    Command(
        "export",
        lambda tmp: ["export", "--model", DELTA, "--out", str(tmp / "delta.xml")],
        outputs={"--out": False},
        inputs={"--model": "model"},
    ),
    Command(
        "sweep",
        lambda tmp: [
            "sweep",
            "--grid",
            grid_toml(tmp),
            "--workers",
            "0",
            "--out",
            str(tmp / "s.parquet"),
        ],
        numbers={
            "--samples": Numeric(whole=True, least=2, size=True),
            "--duration": DURATION,
            "--workers": Numeric(whole=True, least=0, size=True),
            "--chunk-size": Numeric(whole=True, least=1),
            "--area-resolution": Numeric(whole=True, least=0, size=True),
            "--volume-resolution": Numeric(whole=True, least=0, size=True),
            "--min-conditioning": CONDITIONING,
        },
        outputs={"--out": False},
        inputs={"--model": "model", "--grid": "grid", "--trajectory": "trajectory"},
    ),
)
"""Every command, its valid invocation and its options' kinds."""


def test_every_command_has_a_row() -> None:
    from rpr3gen.cli import build_parser as _parser
    from rpr3gen.commands.args import subparser

    parser = _parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    assert set(commands) == {c.name for c in COMMANDS}
    for command in COMMANDS:  # every numeric option of the parser is in the row
        sub = subparser(parser, command.name)
        assert sub is not None
        typed = {
            (a.option_strings[-1] if a.option_strings else a.metavar)
            for a in sub._actions
            if a.type is not None and getattr(a.type, "__qualname__", "").startswith("_argument")
        }
        assert typed == set(command.numbers), command.name


# -- running a case -------------------------------------------------------------------------


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def refused(argv: list[str], capsys: pytest.CaptureFixture[str], *named: str) -> str:
    """Run ``argv``; it must fail as one line on stderr naming one of ``named``, nothing on
    stdout; the line is returned."""
    code, out, err = run(argv, capsys)
    assert code == 2, (argv, code, out, err)
    assert out == "", out
    assert err.count("\n") == 1, err
    assert err.startswith("rpr3gen"), err
    assert "Traceback" not in err
    assert any(n in err for n in named), (named, err)
    return err


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() if p.is_file() else b"<dir>"
        for p in sorted(folder.rglob("*"))
    }


def with_option(argv: list[str], option: str, value: str) -> list[str]:
    """``argv`` with ``option`` set to ``value`` (replaced when there), as ``--opt=value``
    never: a value that looks like an option must be taken all the same."""
    argv = list(argv)
    if option in argv:
        del argv[argv.index(option) : argv.index(option) + 2]
    return [*argv, option, value]


def with_reading(argv: list[str], value: str) -> list[str]:
    """``fk``'s second reading set to ``value``."""
    return [argv[0], argv[1], value, *argv[3:]]


def _number_cases() -> list[object]:
    return [
        pytest.param(command, option, id=f"{command.name}-{option}")
        for command in COMMANDS
        for option in command.numbers
    ]


def _set(command: Command, option: str, value: str, tmp: Path) -> list[str]:
    argv = command.argv(tmp)
    if option == "QA":
        return with_reading(argv, value)
    return with_option(argv, option, value)


@pytest.mark.parametrize(("command", "option"), _number_cases())
def test_a_numeric_option_takes_numbers_of_any_notation_and_refuses_the_rest(
    command: Command, option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    kind = command.numbers[option]
    command.argv(tmp_path)  # writes its input files first
    before = snapshot(tmp_path)
    for text in NOT_NUMBERS:
        refused(_set(command, option, text, tmp_path), capsys, option)
    for text in NON_FINITE + NEGATIVE:
        argv = _set(command, option, text, tmp_path)
        if kind.takes(text):  # taken as a value: the failing model is what stops the run
            err = refused([*argv, *command.failing], capsys, command.failing[-1])
        else:
            err = refused(argv, capsys, option)
            assert "expected one argument" not in err, err
    if kind.size:
        for text in HUGE:
            err = refused(_set(command, option, text, tmp_path), capsys, option)
            assert "at most" in err, err
    assert snapshot(tmp_path) == before, "a failing run wrote something"


# -- outputs ----------------------------------------------------------------------------------


def _output_cases() -> list[object]:
    return [
        pytest.param(command, option, id=f"{command.name}-{option}")
        for command in COMMANDS
        for option in command.outputs
    ]


@pytest.mark.parametrize(("command", "option"), _output_cases())
def test_an_output_that_cannot_be_written_is_refused_before_any_work(
    command: Command, option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = command.outputs[option]
    blocker = tmp_path / "blocker"
    blocker.write_bytes(b"a regular file")
    subfolder = tmp_path / "a-folder"
    subfolder.mkdir()
    bad = [str(blocker / "out"), str(blocker / "deeper" / "out"), "/proc/rpr3gen-hostile/out"]
    bad += [str(blocker)] if folder else [str(subfolder), "/dev/null"]
    if os.geteuid() != 0:  # root writes anywhere: permissions then prove nothing
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o555)
        bad.append(str(locked / "out"))
    argv = command.argv(tmp_path)  # writes its input files first
    before = snapshot(tmp_path)
    for path in bad:
        err = refused(with_option(argv, option, path), capsys, path)
        assert "cannot write" in err, err
        assert "File exists" not in err, err
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(("command", "option"), _output_cases())
def test_a_failing_run_leaves_an_existing_output_byte_identical(
    command: Command, option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = command.argv(tmp_path)
    given = argv[argv.index(option) + 1] if option in argv else ""
    target = tmp_path / f"existing{Path(given).suffix}"  # the kind of file the option writes
    if command.outputs[option]:
        target.mkdir()
        (target / "earlier.txt").write_bytes(b"earlier results\n")
    else:
        target.write_bytes(b"earlier results\n")
    argv = with_option(argv, option, str(target))
    before = snapshot(tmp_path)
    refused([*argv, *command.failing], capsys, command.failing[-1])
    assert snapshot(tmp_path) == before


# -- input files ------------------------------------------------------------------------------


def _inputs(kind: str) -> list[tuple[str, Callable[[Path], str], str]]:
    """(label, path maker, what the message names) of the bad files of ``kind``."""

    def written(name: str, text: str) -> Callable[[Path], str]:
        def make(tmp: Path) -> str:
            (tmp / name).write_text(text)
            return str(tmp / name)

        return make

    suffix = {"model": ".toml", "grid": ".toml"}.get(kind, ".csv")
    cases = [
        ("missing", lambda tmp: str(tmp / f"missing{suffix}"), f"missing{suffix}"),
        ("a folder", lambda tmp: str(tmp), "directory"),
        ("unreadable", lambda tmp: "/proc/self/mem", "/proc/self/mem"),
        ("empty", written(f"empty{suffix}", ""), f"empty{suffix}"),
    ]
    if kind == "model":
        cases += [
            ("not TOML", written("bad.toml", "[mass\n"), "bad.toml"),
            ("not UTF-8", lambda tmp: _bytes(tmp / "latin.toml", b"name = '\xe9'\n"), "UTF-8"),
            ("a typo", written("typo.toml", 'name = "x"\nactuaton = "revolute"\n'), "typo.toml"),
        ]
    if kind == "grid":
        cases += [
            (
                "a huge range",
                written(
                    "huge.toml", '"mass.m3" = {start = 1.0, stop = 2.0, num = 1000000000000}\n'
                ),
                "at most",
            ),
            (
                "10^12 designs",
                written(
                    "many.toml",
                    "".join(
                        f'"mass.{k}" = [{", ".join(str(1.0 + i) for i in range(100))}]\n'
                        for k in ("m1", "m2", "m3", "J1", "J2", "J3")
                    ),
                ),
                "at most",
            ),
            ("an unknown key", written("key.toml", '"mass.m9" = [1.0]\n'), "mass.m9"),
        ]
    if kind in ("trajectory", "data"):
        header = "t,x,y,phi" if kind == "trajectory" else _COLUMNS
        width = header.count(",") + 1
        cases += [
            ("a NaN", written("nan.csv", f"{header}\n0{',0' * (width - 2)},nan\n"), "not finite"),
            ("one row of positions", written("one.csv", "t,x,y,phi\n0,0,0,0\n"), "one.csv"),
            (
                "time going back",
                written("back.csv", f"{header}\n1{',0' * (width - 1)}\n0{',0' * (width - 1)}\n"),
                "strictly increasing",
            ),
        ]
    if kind == "data":
        cases.append(("one row", lambda tmp: data_csv(tmp, slice(0, 1)), "more samples"))
    if kind == "path":  # waypoints of the 3-RRR: x,y,phi, no times
        cases += [
            ("a NaN", written("nan.csv", "x,y,phi\n0,0,0\n0,0,nan\n"), "not finite"),
            ("one waypoint", written("one.csv", "x,y,phi\n0,0,0\n"), "at least 2 waypoints"),
            ("no phi", written("xy.csv", "x,y\n0,0\n0.01,0\n"), "missing column 'phi'"),
            ("a repeat", written("rep.csv", "x,y,phi\n0,0,0\n0,0,0\n"), "line 3 (waypoint 2)"),
            (
                "a singular pose",  # the 3-RRR's parallel singularity at (0, 0, 0.51813)
                written("sing.csv", "x,y,phi\n0,0,0\n0,0,0.51813\n"),
                "sing.csv: line 3 (waypoint 2)",
            ),
        ]
    return cases


def _bytes(path: Path, data: bytes) -> str:
    path.write_bytes(data)
    return str(path)


def _input_cases() -> list[object]:
    return [
        pytest.param(command, option, id=f"{command.name}-{option}")
        for command in COMMANDS
        for option, kind in command.inputs.items()
        if kind != "generated"
    ]


@pytest.mark.parametrize(("command", "option"), _input_cases())
def test_a_bad_input_file_is_one_line_naming_it(
    command: Command, option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    work = tmp_path / "work"
    work.mkdir()
    for label, make, named in _inputs(command.inputs[option]):
        argv = with_option(command.argv(work), option, make(work))
        if command.name == "simulate" and option == "--trajectory":
            argv.remove("--samples"), argv.remove("11")  # a file has its own times
        assert refused(argv, capsys, named), label


# -- a damaged generated folder --------------------------------------------------------------


def _lines(path: Path, edit: Callable[[list[str]], list[str]]) -> None:
    path.write_text("\n".join(edit(path.read_text().split("\n"))))


def _manifest(folder: Path, edit: Callable[[dict], object], *, replace: bool = False) -> None:
    """Edit the revolute manifest in place (``edit``'s value written instead with ``replace``)."""
    path = folder / "revolute" / "manifest.json"
    data = json.loads(path.read_text())
    changed = edit(data)
    path.write_text(json.dumps(changed if replace else data))


DAMAGES: dict[str, tuple[Callable[[Path], None], str]] = {
    "a syntax error": (
        lambda g: _lines(g / "revolute" / "rpr3_numpy.py", lambda ls: [*ls[:2], "def (:", *ls[2:]]),
        "rpr3_numpy.py: line 3",
    ),
    "an import error": (
        lambda g: _lines(
            g / "revolute" / "rpr3_numpy.py",
            lambda ls: [*ls[:2], "import rpr3gen_nowhere", *ls[2:]],
        ),
        "cannot import it",
    ),
    "a missing module": (lambda g: (g / "revolute" / "rpr3_numpy.py").unlink(), "missing"),
    "another variant's module": (
        lambda g: shutil.copy(g / "prismatic" / "rpr3_numpy.py", g / "revolute"),
        "not the revolute variant",
    ),
    "mixed generations": (
        lambda g: _lines(
            g / "revolute" / "rpr3.h",
            lambda ls: [ls[0], " * Source hash: 0123456789abcdef", *ls[2:]],
        ),
        "different generations",
    ),
    "a manifest missing a key": (
        lambda g: _manifest(g, lambda d: d.pop("functions")),
        "no key 'functions'",
    ),
    "a manifest of another format": (
        lambda g: _manifest(g, lambda d: d.update(format=99)),
        "manifest format 99",
    ),
    "a manifest not JSON": (
        lambda g: (g / "revolute" / "manifest.json").write_text("{not json"),
        "not JSON",
    ),
    "a manifest not an object": (
        lambda g: _manifest(g, lambda d: [d], replace=True),
        "manifest format None",
    ),
    "a missing manifest": (
        lambda g: (g / "revolute" / "manifest.json").unlink(),
        "no generated variant",
    ),
    "other parameters (ABI)": (
        lambda g: _manifest(g, lambda d: d["params"].pop()),
        "other model parameters",
    ),
    "a damaged function entry": (
        lambda g: _manifest(g, lambda d: d["functions"][0].pop("inputs")),
        "no key 'inputs'",
    ),
}


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("generated") / "generated"
    shutil.copytree(manifest.default_folder(), folder, ignore=shutil.ignore_patterns("__pycache__"))
    return folder


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_a_damaged_generated_folder_is_one_line_naming_the_file_and_the_fix(
    damage: str, pristine: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "generated"
    shutil.copytree(pristine, folder)
    spoil, expected = DAMAGES[damage]
    spoil(folder)
    for argv in (["simulate", "--samples", "5"], ["fk", "0.1", "0", "0"]):
        err = refused([argv[0], "--generated", str(folder), *argv[1:]], capsys, expected)
        assert f"rpr3gen generate --out {folder}" in err, err
    with pytest.raises(rpr3gen.GeneratedCodeError, match="rpr3gen generate --out") as info:
        rpr3gen.load_model(generated=folder)
    assert "\n" not in str(info.value)


# -- the command line itself ------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["frobnicate"],
        ["simulate", "--frobnicate"],
        ["sweep"],
        ["fk", "0.1"],
        ["fk", "0.1", "0", "0", "0"],
        ["simulate", "--backend", "gpu"],
        ["--debug"],
    ],
    ids=str,
)
def test_a_usage_error_is_one_line(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(argv, capsys)
    assert code == 2
    assert "Traceback" not in err
    assert err.count("\n") == 1 or err.startswith("usage:"), err


def test_a_negative_reading_in_exponent_notation_is_a_reading(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, err = run(["fk", "0.1", "-1e-3", "0.0"], capsys)
    assert (code, err) == (0, "")
    assert run(["fk", "0.1", "-0.001", "0.0"], capsys)[1] == out
