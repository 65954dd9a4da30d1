"""``rpr3gen workspace``: a design's workspace and singularity maps at a fixed platform angle
(reachable positions, conditioning, static efforts, orientation range), as Parquet and PNG."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rpr3gen.commands import options
from rpr3gen.commands.args import integer, number
from rpr3gen.design.maps import DEFAULT_RESOLUTION, WorkspaceMap
from rpr3gen.errors import InputError
from rpr3gen.model import Model, load_model
from rpr3gen.paths import check_output

NAME = "workspace"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``workspace`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="workspace and singularity maps of a design at a fixed platform angle",
        description="Map the positions of G reachable at the platform angle PHI (joint limits, "
        "conditioning), the conditioning with the singularity curves, the static actuator "
        "efforts holding the robot at rest and the reachable orientation range; write "
        "DIR/workspace.parquet and four PNG figures.",
    )
    options.add_model(parser)
    parser.add_argument(
        "--phi",
        type=number(unit="deg"),
        default=0.0,
        metavar="DEG",
        help="platform angle, degrees (default: 0)",
    )
    parser.add_argument(
        "--resolution",
        type=integer(2),
        default=DEFAULT_RESOLUTION,
        metavar="N",
        help=f"grid points along x and along y (default: {DEFAULT_RESOLUTION})",
    )
    parser.add_argument(
        "--heights",
        type=integer(1),
        default=9,
        metavar="K",
        help="spatial robots: horizontal slices of the box (default: 9)",
    )
    parser.add_argument(
        "--orientation",
        type=_three_angles,
        default=(0.0, 0.0, 0.0),
        metavar="A,B,C",
        help="hexapods: the platform's fixed orientation (a, b, c), degrees, comma-separated "
        "(default: 0,0,0)",
    )
    options.add_out_folder(parser, "workspace")
    options.add_min_conditioning(parser, "poses below this conditioning are not reachable")


def _three_angles(text: str) -> tuple[float, float, float]:
    """``A,B,C``: three finite numbers (degrees)."""
    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not three numbers: {text!r}") from None
    if len(values) != 3 or not all(np.isfinite(values)):
        raise argparse.ArgumentTypeError(f"must be three finite angles A,B,C, got {text!r}")
    return values[0], values[1], values[2]


def run(args: argparse.Namespace) -> int:
    """Map the workspace, write the table and figures, print a summary."""
    from rpr3gen.design import workspace, write_workspace

    model = load_model(args.model)
    out = check_output(args.out, "the workspace maps", folder=True, argument="out")
    if model.structure.spatial:
        return _spatial(args, model, out)
    wmap = workspace(model, np.radians(args.phi), args.resolution,
                     min_conditioning=args.min_conditioning)  # fmt: skip
    written = write_workspace(wmap, out)
    print(_summary(wmap))
    print(f"wrote {written[0]} and {len(written) - 1} figures in {out}")
    return 0


def _spatial(args: argparse.Namespace, model: Model, out: Path) -> int:
    """The constant-orientation workspace of a spatial robot: slices, volume, Parquet, PNG."""
    from rpr3gen.design.spatial_workspace import spatial_workspace, write_spatial_workspace

    if model.structure.dof == 3 and any(args.orientation):
        raise InputError("--orientation: a Delta's platform keeps its home orientation")
    if args.phi:
        raise InputError("--phi: for planar robots; a hexapod takes --orientation A,B,C")
    a, b, c = (float(v) for v in np.radians(args.orientation))
    angles = (a, b, c)
    ws = spatial_workspace(
        model, args.resolution, args.heights, angles, min_conditioning=args.min_conditioning
    )
    written = write_spatial_workspace(ws, out)
    reachable = int(np.count_nonzero(ws.reachable))
    peak = float(np.nanmax(np.abs(ws.tau), initial=0.0))
    print(
        f"workspace of {model.name} ({model.structure.title}): {ws.x.size} x {ws.y.size} x "
        f"{ws.z.size} points over x, y, z in [{ws.x[0]:.4g}, {ws.x[-1]:.4g}] m"
    )
    print(
        f"  reachable: {reachable} points, volume {ws.volume:.5g} m^3 (conditioning >= "
        f"{ws.min_conditioning:g}); peak static effort {peak:.5g}"
    )
    print(f"wrote {written[0]} and {written[1]}")
    return 0


def _summary(wmap: WorkspaceMap) -> str:
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
