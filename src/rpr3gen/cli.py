"""The ``rpr3gen`` command: ``simulate``, ``paper`` (the paper's two examples), ``params``,
``fk``, ``generate``, the identification's ``identify`` and ``excite``
(:mod:`rpr3gen.cli_identification`), and the design studies ``workspace`` and ``sweep``
(:mod:`rpr3gen.design`).

Every failure is one line on stderr (``rpr3gen: error: ...``) and exit status 2; ``--debug``
shows the traceback instead. The package's warnings are one line each (``rpr3gen: warning:
...``). Output files are written atomically, and a reader of stdout that goes away ends the
command quietly.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TextIO

import numpy as np

from rpr3gen import __version__, animation, cli_identification, sizes, variants
from rpr3gen.backends import BACKENDS, inverse_dynamics, output_names
from rpr3gen.cli_args import EXIT_ERROR, Parser, as_option, integer, number, subparser
from rpr3gen.derivatives import MAX_SMOOTHING
from rpr3gen.design.maps import DEFAULT_RESOLUTION, WorkspaceMap
from rpr3gen.design.sweeps import (
    DEFAULT_AREA_RESOLUTION,
    DEFAULT_CHUNK_SIZE,
    DEFAULT_TRAJECTORIES,
)
from rpr3gen.errors import (
    InputError,
    Rpr3genError,
    Rpr3genWarning,
    TrajectoryError,
    did_you_mean,
)
from rpr3gen.model import Model, load_model
from rpr3gen.paths import check_output
from rpr3gen.policy import DEFAULT_MIN_CONDITIONING, Invalid, invalid_samples
from rpr3gen.structure import LEG_TYPES, Structure
from rpr3gen.trajectory import (
    DEFAULT_DURATION,
    DEFAULT_SAMPLES,
    DURATIONS,
    PAPER_TRAJECTORIES,
    Trajectory,
    paper_trajectory,
    read_trajectory_csv,
)

#: ``type=`` of every ``--min-conditioning``: conditioning is 1 at best, so 1 would refuse all.
_CONDITIONING = number(least=0.0, below=1.0)


def _add_threads(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--threads",
        type=integer(1),
        metavar="N",
        help="threads of the c backend (default: every core this process may use); the "
        "results do not depend on it",
    )


def _parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="rpr3gen",
        description="Inverse dynamics of the 3-RPR planar parallel robot (Staicu), "
        "from generated code. SI units throughout (m, rad, s, N, N·m).",
        epilog="Run 'rpr3gen COMMAND --help' for the options of a command.",
    )
    parser.add_argument("--version", action="version", version=f"rpr3gen {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    paper_model = "default: the paper's robot, models/paper.toml"

    sim = sub.add_parser("simulate", help="evaluate the inverse dynamics over a trajectory")
    sim.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")
    sim.add_argument(
        "--trajectory",
        default="rotation",
        metavar="NAME|FILE.csv",
        help="'rotation' or 'rectilinear' (the paper's motions, eq. 3), or a trajectory CSV "
        "file (default: rotation)",
    )
    sim.add_argument(
        "--samples",
        type=integer(2),
        metavar="N",
        help="number of samples of a paper trajectory, both ends included "
        f"(default: {DEFAULT_SAMPLES})",
    )
    sim.add_argument(
        "--duration",
        type=number(least=DURATIONS[0], most=DURATIONS[1], unit="s"),
        metavar="T",
        help=f"duration of a paper trajectory, s (default: {DEFAULT_DURATION:g})",
    )
    sim.add_argument(
        "--smoothing",
        type=number(least=0.0, most=MAX_SMOOTHING),
        metavar="S",
        help="for a CSV file of positions only (t,x,y,phi): RMS deviation allowed between the "
        "quintic spline whose derivatives give the velocities and accelerations and the "
        "positions, m for x, y and rad for phi; give the noise level of measured positions "
        "(default: 0, through every sample)",
    )
    sim.add_argument(
        "--backend",
        choices=BACKENDS,
        default="numpy",
        help="evaluate the generated NumPy or C code (default: numpy)",
    )
    _add_threads(sim)
    sim.add_argument(
        "--out",
        metavar="FILE.csv",
        help="write t,x,y,phi and every output as CSV, SI units (default: no file)",
    )
    sim.add_argument(
        "--plots",
        metavar="DIR",
        help="write the paper's figures into DIR as PNG (default: no figures)",
    )
    sim.add_argument(
        "--min-conditioning",
        type=_CONDITIONING,
        default=DEFAULT_MIN_CONDITIONING,
        metavar="C",
        help="refuse poses whose output 'conditioning' (dimensionless, 0 = singular, 1 = best) "
        f"is below C, 0 <= C < 1 (default: {DEFAULT_MIN_CONDITIONING:g})",
    )
    sim.add_argument(
        "--allow-invalid",
        action="store_true",
        help="write rows at poses too close to a singularity or outside a stroke limit as NaN "
        "instead of refusing the trajectory (default: refuse)",
    )
    sim.add_argument(
        "--generated",
        metavar="DIR",
        help="evaluate with the generated code that `rpr3gen generate` wrote into DIR "
        "(default: the installed generated package)",
    )

    paper = sub.add_parser("paper", help="run the paper's two examples: CSV and figures")
    paper.add_argument(
        "--out", default="results", metavar="DIR", help="output folder (default: ./results)"
    )
    paper.add_argument(
        "--backend",
        choices=BACKENDS,
        default="numpy",
        help="evaluate the generated NumPy or C code (default: numpy)",
    )
    _add_threads(paper)

    par = sub.add_parser(
        "params", help="print a model's parameter vector as 'name value' lines (for C users)"
    )
    par.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")

    fk = sub.add_parser(
        "fk",
        help="forward kinematics: every assembly mode of three actuator readings",
        description="Print every assembly mode of the actuator coordinates QA1 QA2 QA3 (legs A, "
        "B, C: phi10 in rad with revolute actuation, lambda21 in m with prismatic), one per "
        "line: x y (m) phi (rad, in (-pi, pi]) and the pose's conditioning (0 = singular, 1 = "
        "best).",
    )
    fk.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")
    fk.add_argument(
        "--generated",
        metavar="DIR",
        help="use the generated code that `rpr3gen generate` wrote into DIR "
        "(default: the installed generated package)",
    )
    fk.add_argument("qa", nargs=3, type=number(), metavar="QA", help="actuator coordinate")

    cli_identification.add_parsers(sub, paper_model)
    _animate_parser(sub, paper_model)
    ws = sub.add_parser(
        "workspace",
        help="workspace and singularity maps of a design at a fixed platform angle",
        description="Map the positions of G reachable at the platform angle PHI (joint limits, "
        "conditioning), the conditioning with the singularity curves, the static actuator "
        "efforts holding the robot at rest and the reachable orientation range; write "
        "DIR/workspace.parquet and four PNG figures.",
    )
    ws.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")
    ws.add_argument(
        "--phi",
        type=number(unit="deg"),
        default=0.0,
        metavar="DEG",
        help="platform angle, degrees (default: 0)",
    )
    ws.add_argument(
        "--resolution",
        type=integer(2),
        default=DEFAULT_RESOLUTION,
        metavar="N",
        help=f"grid points along x and along y (default: {DEFAULT_RESOLUTION})",
    )
    ws.add_argument(
        "--out", default="workspace", metavar="DIR", help="output folder (default: ./workspace)"
    )
    ws.add_argument(
        "--min-conditioning",
        type=_CONDITIONING,
        default=DEFAULT_MIN_CONDITIONING,
        metavar="C",
        help=f"poses below this conditioning are not reachable (default: "
        f"{DEFAULT_MIN_CONDITIONING:g})",
    )

    sw = sub.add_parser(
        "sweep",
        help="evaluate every design of a grid of model keys over trajectories (Dask), as Parquet",
        description="For every design of GRID.toml (dotted model keys set to lists or "
        "{start, stop, num} ranges, applied to BASE.toml): feasible or not and why, peak and "
        "RMS actuator efforts, peak joint loads, least conditioning and the workspace area at "
        "phi = 0; one row per design, in the grid's order.",
    )
    sw.add_argument("--model", metavar="BASE.toml", help=f"base model ({paper_model})")
    sw.add_argument("--grid", required=True, metavar="GRID.toml", help="the designs (required)")
    sw.add_argument(
        "--trajectory",
        action="append",
        dest="trajectories",
        metavar="NAME|FILE.csv",
        help="'rotation', 'rectilinear' or a trajectory CSV file; repeat for several "
        "(default: rotation and rectilinear)",
    )
    sw.add_argument(
        "--samples",
        type=integer(2),
        default=DEFAULT_SAMPLES,
        metavar="N",
        help=f"samples of each paper trajectory (default: {DEFAULT_SAMPLES})",
    )
    sw.add_argument(
        "--duration",
        type=number(least=DURATIONS[0], most=DURATIONS[1], unit="s"),
        default=DEFAULT_DURATION,
        metavar="T",
        help=f"duration of each paper trajectory, s (default: {DEFAULT_DURATION:g})",
    )
    sw.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on the Dask scheduler at ADDRESS, e.g. tcp://host:8786 (default: a local "
        "cluster on this machine's cores)",
    )
    sw.add_argument(
        "--workers",
        type=integer(0),
        metavar="N",
        help="processes of the local cluster (default: one per core); 0 runs in this process "
        "without Dask",
    )
    sw.add_argument(
        "--resume",
        action="store_true",
        help="continue an interrupted sweep from the chunks in FILE.parquet.parts",
    )
    sw.add_argument(
        "--out",
        default="sweep.parquet",
        metavar="FILE.parquet",
        help="output file (default: ./sweep.parquet)",
    )
    sw.add_argument(
        "--chunk-size",
        type=integer(1),
        default=DEFAULT_CHUNK_SIZE,
        metavar="N",
        help=f"designs per task and per part file (default: {DEFAULT_CHUNK_SIZE})",
    )
    sw.add_argument(
        "--area-resolution",
        type=integer(0),
        default=DEFAULT_AREA_RESOLUTION,
        metavar="N",
        help="grid points per axis of each design's workspace area; 0: no area "
        f"(default: {DEFAULT_AREA_RESOLUTION})",
    )
    sw.add_argument(
        "--min-conditioning",
        type=_CONDITIONING,
        default=DEFAULT_MIN_CONDITIONING,
        metavar="C",
        help=f"a pose below this conditioning makes a design infeasible (default: "
        f"{DEFAULT_MIN_CONDITIONING:g})",
    )

    gen = sub.add_parser(
        "generate",
        help="derive and write the generated sources",
        description="Derive and write generated code. Without --leg or --model: the committed "
        "variants (the paper's revolute and prismatic, and rrr_1) into the source tree's "
        "generated/. With --leg and --actuated (or --model): that one structure's variant, into "
        "--out DIR, or by default into the cache where the runtime finds it (see "
        "RPR3GEN_CACHE_DIR).",
    )
    gen.add_argument(
        "--model",
        metavar="FILE",
        help="generate only this model's variant (default: the committed variants)",
    )
    gen.add_argument(
        "--leg",
        metavar="TYPE",
        help="generate the variant of this leg type (RRR RPR RRP PRR PPR PRP RPP); needs the "
        "actuated joint too (default: the committed variants)",
    )
    gen.add_argument(
        "--actuated",
        type=int,
        metavar="J",
        help="the joint (1, 2 or 3) of every leg that carries its motor; needs the leg type "
        "too (default: none)",
    )
    gen.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: the source tree's generated/, or the cache for one "
        "structure)",
    )
    gen.add_argument(
        "--check",
        action="store_true",
        help="write nothing; fail if the sources are stale (default: write them)",
    )
    return parser


def _trajectory(args: argparse.Namespace) -> tuple[str, Trajectory]:
    given = {"samples": args.samples, "duration": args.duration}
    timing = {key: value for key, value in given.items() if value is not None}
    if args.trajectory in PAPER_TRAJECTORIES:
        if args.smoothing is not None:
            raise TrajectoryError(
                "--smoothing: only for a trajectory CSV file of positions; "
                f"{args.trajectory!r} has analytic derivatives"
            )
        sizes.check("samples", timing.get("samples", DEFAULT_SAMPLES),
                    lambda n: n * sizes.SIMULATED_SAMPLE, "the simulation, its CSV and figures",
                    least=2, argument="samples")  # fmt: skip
        return args.trajectory, paper_trajectory(args.trajectory, **timing)
    path = Path(args.trajectory)
    if path.suffix.lower() != ".csv" and not path.exists():
        names = ", ".join(PAPER_TRAJECTORIES)
        hint = did_you_mean(args.trajectory, PAPER_TRAJECTORIES)
        raise TrajectoryError(
            f"--trajectory: {args.trajectory!r} is neither {names} nor a CSV file{hint}"
        )
    if timing:
        options = " and ".join(f"--{key}" for key in timing)
        raise TrajectoryError(f"{options}: only for a paper trajectory; {path} has its own times")
    return path.stem, read_trajectory_csv(path, smoothing=args.smoothing)


def _screen(
    model: Model,
    traj: Trajectory,
    out: dict[str, np.ndarray],
    min_conditioning: float,
    allow_invalid: bool,
) -> Invalid | None:
    """Refuse a trajectory through an invalid pose, or blank those rows when allowed.

    Returns:
        The samples blanked (written as NaN), or None when every sample is valid.
    """
    thresholds = variants.load(model.structure, model.generated).thresholds
    invalid = invalid_samples(model, traj.q, out, min_conditioning, thresholds)
    if invalid is None:
        return None
    if not allow_invalid:
        k = invalid.first
        raise Rpr3genError(
            f"t = {traj.t[k]:.6g} s (sample {k + 1} of {len(traj.t)}): {invalid.reason}; "
            "pass --allow-invalid to write such rows as NaN"
        )
    for name in output_names(model):
        if name != "conditioning":
            out[name] = np.where(invalid.mask, np.nan, out[name])
    return invalid


def _spans(t: np.ndarray, mask: np.ndarray, most: int = 3) -> str:
    """When ``mask`` holds, e.g. ``"t = 0.2 s, 1.17 to 3 s"``: its runs, the first ``most``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    runs = list(zip(edges[::2], edges[1::2] - 1, strict=True))  # first and last sample of each
    parts = [f"{t[a]:.6g} s" if a == b else f"{t[a]:.6g} to {t[b]:.6g} s" for a, b in runs[:most]]
    more = f" and {len(runs) - most} more spans" if len(runs) > most else ""
    return "t = " + ", ".join(parts) + more


def _refused(traj: Trajectory, invalid: Invalid) -> str:
    """One line: how many samples were refused, when, and why the first one was."""
    count = int(np.count_nonzero(invalid.mask))
    return (
        f"{count} of {len(traj.t)} samples refused and written as NaN, "
        f"{_spans(traj.t, invalid.mask)} (first: {invalid.reason})"
    )


def _warn(message: str) -> None:
    print(f"rpr3gen: warning: {message}", file=sys.stderr)


@contextlib.contextmanager
def _warnings_as_lines() -> Iterator[None]:
    """Show the package's warnings as one line each, ``rpr3gen: warning: <msg>``, every time."""
    with warnings.catch_warnings():
        warnings.simplefilter("always", Rpr3genWarning)
        show = warnings.showwarning

        def show_ours(
            message: Warning | str,
            category: type[Warning],
            filename: str,
            lineno: int,
            file: TextIO | None = None,
            line: str | None = None,
        ) -> None:
            if issubclass(category, Rpr3genWarning):
                _warn(str(message))
            else:
                show(message, category, filename, lineno, file, line)

        warnings.showwarning = show_ours
        yield


def simulate(
    model: Model,
    name: str,
    traj: Trajectory,
    backend: str,
    out_csv: str | None,
    plots_dir: str | None,
    min_conditioning: float = DEFAULT_MIN_CONDITIONING,
    allow_invalid: bool = False,
    threads: int | None = None,
) -> tuple[dict[str, np.ndarray], Invalid | None]:
    """Evaluate, screen, and write the CSV and figures of one trajectory.

    Nothing is written unless the whole trajectory is valid (or ``allow_invalid``).

    Returns:
        Every output by name, shape ``(n,)``, and the samples refused (their outputs, but
        ``conditioning``, are NaN; None when there are none, always unless ``allow_invalid``).
    """
    from rpr3gen.atomic import write_results_csv

    if not 0.0 <= min_conditioning < 1.0:
        raise InputError(f"min_conditioning: must be in [0, 1), got {min_conditioning!r}")
    if out_csv:
        check_output(out_csv, "the CSV", argument="out")
    if plots_dir:
        check_output(plots_dir, "the figures", folder=True, argument="plots")
    out = inverse_dynamics(
        model, traj.q, traj.qd, traj.qdd, backend=backend, progress=True, threads=threads
    )
    invalid = _screen(model, traj, out, min_conditioning, allow_invalid)
    if out_csv:
        Path(out_csv).parent.mkdir(parents=True, exist_ok=True)
        write_results_csv(out_csv, traj.t, traj.q, out, output_names(model))
    if plots_dir:
        from rpr3gen.plots import plot_families

        plot_families(
            traj.t,
            out,
            plots_dir,
            prefix=name,
            title=f"{name} ({model.name})",
            actuation=model.structure,
        )
    return out, invalid


def _summary(
    name: str,
    model: Model,
    traj: Trajectory,
    out: dict[str, np.ndarray],
    invalid: Invalid | None = None,
) -> str:
    n = len(traj.t)
    lines = [f"{name}: {n} samples over {traj.t[-1] - traj.t[0]:g} s, model {model.name}"]
    if invalid is not None:
        valid = n - int(np.count_nonzero(invalid.mask))
        lines.append(f"  {_refused(traj, invalid)}; the peaks are of the {valid} others")
    lines.append(f"  {'peak |value|':<12} {'leg A':>12} {'leg B':>12} {'leg C':>12}")
    families = (
        ("m10", "f21z", "f10x", "f10y", "f21y", "m21", "f32y", "f32z")
        if model.structure.paper
        else ("tau", *(f"{f}{j}" for j in (1, 2, 3) for f in ("fx", "fy", "m")))
    )
    for family in families:
        peaks = [float(np.nanmax(np.abs(out[f"{family}_{leg}"]), initial=0.0)) for leg in "ABC"]
        lines.append(f"  {family:<12} " + " ".join(f"{p:12.5g}" for p in peaks))
    return "\n".join(lines)


def _cmd_simulate(args: argparse.Namespace) -> int:
    model = load_model(args.model, generated=args.generated)
    name, traj = _trajectory(args)
    out, invalid = simulate(
        model,
        name,
        traj,
        args.backend,
        args.out,
        args.plots,
        min_conditioning=args.min_conditioning,
        allow_invalid=args.allow_invalid,
        threads=args.threads,
    )
    if invalid is not None:
        _warn(f"{name}: {_refused(traj, invalid)}")
    print(_summary(name, model, traj, out, invalid))
    return 0


def _cmd_paper(args: argparse.Namespace) -> int:
    model = load_model()
    root = Path(args.out)
    summaries = []  # printed once every file is written, so a closed stdout stops nothing
    for name in PAPER_TRAJECTORIES:
        traj = paper_trajectory(name)
        out, _ = simulate(
            model,
            name,
            traj,
            args.backend,
            str(root / f"{name}.csv"),
            str(root / "figures"),
            threads=args.threads,
        )
        summaries.append(_summary(name, model, traj, out))
    print("\n".join(summaries))
    print(f"wrote {root / '*.csv'} and {root / 'figures'}/*.png")
    return 0


def _cmd_params(args: argparse.Namespace) -> int:
    model = load_model(args.model)
    lines = [f"{name} {value:.17g}" for name, value in model.params.items()]
    print("\n".join(lines))
    return 0


def _cmd_fk(args: argparse.Namespace) -> int:
    from rpr3gen.control import assembly_modes

    model = load_model(args.model, generated=args.generated)
    qa = np.array(args.qa)  # three finite numbers (cli_args.number)
    modes = assembly_modes(model, qa)
    zero = np.zeros_like(modes)
    conditioning = (
        inverse_dynamics(model, modes, zero, zero)["conditioning"] if len(modes) else zero
    )
    family = model.structure.actuator
    what = f"{model.actuation} actuation" if model.structure.paper else model.structure.title
    print(
        f"# {len(modes)} assembly mode(s) of {family} = {' '.join(f'{v:g}' for v in qa)} "
        f"({model.name}, {what}): x y phi conditioning"
    )
    for mode, c in zip(modes, conditioning, strict=True):
        print(f"{mode[0]:.12g} {mode[1]:.12g} {mode[2]:.12g} {c:.6g}")
    return 0


def _animate_parser(sub: argparse._SubParsersAction, paper_model: str) -> None:
    anim = sub.add_parser(
        "animate",
        help="draw the robot moving along a trajectory, with its actuator efforts (GIF or MP4)",
        description="Draw the base, the legs and the platform along the motion, the actuator "
        "efforts as bars and as curves with a time cursor (and with --loads every joint's "
        "force as an arrow); GIF through Pillow, MP4 through ffmpeg when installed. Frames are "
        f"bounded: at most {animation.MAX_FRAMES}, sides {animation.MIN_SIDE} to "
        f"{animation.MAX_SIDE} pixels.",
    )
    anim.add_argument("--model", metavar="FILE", help=f"model TOML file ({paper_model})")
    anim.add_argument(
        "--trajectory",
        default="rotation",
        metavar="NAME|FILE.csv",
        help="'rotation', 'rectilinear' or a trajectory CSV file (default: rotation)",
    )
    anim.add_argument(
        "--duration",
        type=number(least=DURATIONS[0], most=DURATIONS[1], unit="s"),
        metavar="T",
        help=f"duration of a paper trajectory, s (default: {DEFAULT_DURATION:g})",
    )
    anim.add_argument("--out", required=True, metavar="FILE.gif|FILE.mp4", help="the movie")
    anim.add_argument(
        "--fps",
        type=integer(1, animation.MAX_FPS),
        default=animation.DEFAULT_FPS,
        metavar="N",
        help=f"frames per second, 1 to {animation.MAX_FPS} (default: {animation.DEFAULT_FPS})",
    )
    anim.add_argument(
        "--speed",
        type=number(greater=0),
        default=1.0,
        metavar="S",
        help="trajectory seconds per movie second (default: 1, real time)",
    )
    anim.add_argument(
        "--size",
        default="{}x{}".format(*animation.DEFAULT_SIZE),
        metavar="WxH",
        help="frame size in pixels (default: {}x{})".format(*animation.DEFAULT_SIZE),
    )
    anim.add_argument("--loads", action="store_true", help="draw every joint's force as an arrow")
    anim.add_argument(
        "--backend", choices=BACKENDS, default="numpy", help="generated code (default: numpy)"
    )
    anim.set_defaults(samples=None, smoothing=None)


def _cmd_animate(args: argparse.Namespace) -> int:
    check_output(args.out, "the movie", argument="out")
    size = animation.parse_size(args.size)
    name, traj = _trajectory(args)
    animation.plan(traj.t, args.out, fps=args.fps, speed=args.speed, size=size)  # before work
    model = load_model(args.model)
    done = animation.write_animation(
        model, traj, args.out, fps=args.fps, speed=args.speed, size=size, loads=args.loads,
        title=f"{model.name}: {model.structure.title}, {name}", backend=args.backend,
    )  # fmt: skip
    print(f"wrote {done.path}: {done.frames} frames of {size[0]} x {size[1]} at {args.fps}/s")
    return 0


def _cmd_workspace(args: argparse.Namespace) -> int:
    from rpr3gen.design import workspace, write_workspace

    model = load_model(args.model)
    out = check_output(args.out, "the workspace maps", folder=True, argument="out")
    wmap = workspace(model, np.radians(args.phi), args.resolution,
                     min_conditioning=args.min_conditioning)  # fmt: skip
    written = write_workspace(wmap, out)
    print(_workspace_summary(wmap))
    print(f"wrote {written[0]} and {len(written) - 1} figures in {out}")
    return 0


def _workspace_summary(wmap: WorkspaceMap) -> str:
    reachable = int(np.count_nonzero(wmap.reachable))
    if wmap.stroke is not None:
        strokes = ", ".join(f"[{lo:.4g}, {hi:.4g}]" for lo, hi in wmap.stroke)
        limits = f"strokes lambda21 {strokes} m"
    else:
        limits = wmap.limits_text(unicode=False)
    lines = [
        f"workspace of {wmap.model.name} at phi = {np.degrees(wmap.phi):g} deg: "
        f"{wmap.x.size} x {wmap.y.size} points, x {wmap.x[0]:.4g} to {wmap.x[-1]:.4g} m, "
        f"y {wmap.y[0]:.4g} to {wmap.y[-1]:.4g} m",
        f"  reachable: {reachable} points, area {wmap.area:.5g} m^2 ({limits}; "
        f"conditioning >= {wmap.min_conditioning:g})",
    ]
    if reachable:
        peak = float(np.nanmax(np.abs(wmap.tau)))
        width = np.degrees(np.nanmax(wmap.phi_max - wmap.phi_min))
        unit = wmap.effort_unit.replace("·", " ")
        lines.append(f"  peak static |{wmap.effort}|: {peak:.5g} {unit}; widest orientation "
                     f"range: {width:.4g} deg")  # fmt: skip
    return "\n".join(lines)


def _cmd_sweep(args: argparse.Namespace) -> int:
    from rpr3gen.design import sweep
    from rpr3gen.design.sweeps import SweepInterrupted

    try:
        table = sweep(
            args.model,
            args.grid,
            args.trajectories or DEFAULT_TRAJECTORIES,
            out=args.out,
            scheduler=args.scheduler,
            workers=args.workers,
            resume=args.resume,
            chunk_size=args.chunk_size,
            min_conditioning=args.min_conditioning,
            area_resolution=args.area_resolution,
            samples=args.samples,
            duration=args.duration,
            progress=True,
        )
    except SweepInterrupted as exc:  # main prints it as one line: what is kept, how to go on
        raise KeyboardInterrupt(
            f"{exc.kept} of {exc.chunks} chunks done, kept in {exc.folder}: rerun with --resume "
            "to compute only the others"
        ) from None
    feasible = table.column("feasible").to_numpy(zero_copy_only=False)
    print(f"{table.num_rows} designs, {int(feasible.sum())} feasible; wrote {args.out}")
    return 0


def _cmd_generate(args: argparse.Namespace) -> int:
    if args.out and not args.check:  # before sympy loads: a second, not an hour of work
        check_output(args.out, "the generated sources", folder=True, argument="out")
    try:
        from rpr3gen_derive.codegen import files as codegen_files
        from rpr3gen_derive.planar import generate, structures
    except ImportError as exc:
        raise Rpr3genError(
            f"regeneration needs sympy and jinja2 ({exc.name} is missing): "
            "pip install 'rpr3gen[derive]'"
        ) from exc
    one = _generated_structure(args)
    if one is not None:
        if one.singular:
            raise Rpr3genError(
                f"--actuated: a {one.title} cannot move: both its passive joints are prismatic "
                "(architecturally singular); nothing to generate"
            )
        target = structures.Structure(one.leg, one.actuated, one.paper)
        committed = target in generate.COMMITTED
        if args.out:
            out_dir = Path(args.out)
        elif committed and generate.default_out_dir() is not None:
            out_dir = generate.default_out_dir()
        else:
            out_dir = variants.folder(one)
        package = generate.COMMITTED if committed and not args.out else (target,)
        files = generate.render((target,), package=package)
    else:
        out_dir = Path(args.out) if args.out else generate.default_out_dir()
        if out_dir is None:
            raise Rpr3genError("no source tree's generated/ folder here; name one with --out DIR")
        if not args.check:
            check_output(out_dir, "the generated sources", folder=True, argument="out")
        files = generate.render(generate.COMMITTED)
    if args.check:
        stale = codegen_files.stale_files(out_dir, files)
        if stale:
            raise Rpr3genError(
                f"{out_dir}: stale or edited generated files: {', '.join(stale)}; "
                "run `rpr3gen generate`"
            )
        print(f"{out_dir}: {len(files)} generated files up to date")
        return 0
    changed = codegen_files.write_files(out_dir, files)
    print(f"{out_dir}: {len(changed)} of {len(files)} files changed")
    return 0


def _generated_structure(args: argparse.Namespace) -> Structure | None:
    """The one structure ``rpr3gen generate`` was asked for, or None for the committed ones."""
    if args.leg is not None or args.actuated is not None:
        if args.model:
            raise InputError("--model: not together with --leg and --actuated")
        if args.leg is None or args.actuated is None:
            raise InputError("--leg and --actuated go together")
        leg = str(args.leg).upper()
        if leg not in LEG_TYPES:
            hint = did_you_mean(leg, LEG_TYPES)
            raise InputError(
                f"--leg: must be one of {', '.join(LEG_TYPES)}, got {args.leg!r}{hint}"
            )
        if args.actuated not in (1, 2, 3):
            raise InputError(f"--actuated: must be 1, 2 or 3, got {args.actuated}")
        return Structure(leg, args.actuated)
    if args.model:
        return load_model(args.model).structure
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rpr3gen`` command; returns the exit status."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # a usage error, its line printed: the status (--help exits 0)
        if exc.code in (0, None):
            raise
        return exc.code if isinstance(exc.code, int) else EXIT_ERROR
    if args.command is None:  # a bare `rpr3gen`: show what it can do
        parser.print_help(sys.stderr)
        return EXIT_ERROR
    commands = {
        "simulate": _cmd_simulate,
        "paper": _cmd_paper,
        "params": _cmd_params,
        "fk": _cmd_fk,
        "animate": _cmd_animate,
        "workspace": _cmd_workspace,
        "sweep": _cmd_sweep,
        "generate": _cmd_generate,
        "identify": cli_identification.cmd_identify,
        "excite": cli_identification.cmd_excite,
    }
    try:
        with _warnings_as_lines():
            status = commands[args.command](args)
        sys.stdout.flush()  # a reader that went away shows here, not at the interpreter's exit
        return status
    except BrokenPipeError:
        return _reader_went_away()
    except (Rpr3genError, OSError) as exc:
        if args.debug:
            raise
        if isinstance(exc, Rpr3genError):  # "samples: ..." of the Python API is "--samples: ..."
            message = as_option(exc, subparser(parser, args.command))
        else:
            message = _os_message(exc)
        print(f"rpr3gen: error: {message}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt as exc:
        detail = f"; {exc}" if str(exc) else ""
        print(f"rpr3gen: interrupted{detail}", file=sys.stderr)
        return 130


def _reader_went_away() -> int:
    """``rpr3gen ... | head -1``: the reader of stdout closed the pipe; stop quietly, status 0.

    Every output file is complete by then (stdout gets only the summary, printed last); what
    is lost is the text that the reader chose not to read.
    """
    # Python flushes stdout once more at exit and would report the pipe again: send the rest
    # of the buffer to /dev/null instead.
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    return 0


def _os_message(exc: OSError) -> str:
    where = f"{exc.filename}: " if exc.filename else ""
    return f"{where}{exc.strerror or exc}"


if __name__ == "__main__":
    sys.exit(main())
