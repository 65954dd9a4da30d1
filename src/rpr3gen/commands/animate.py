"""``rpr3gen animate``: a movie (GIF or MP4) of the robot moving along a trajectory, with its
actuator efforts (and with ``--loads`` every joint's force)."""

from __future__ import annotations

import argparse

from rpr3gen import animation
from rpr3gen.commands import options
from rpr3gen.commands.args import integer, number
from rpr3gen.model import load_model
from rpr3gen.paths import check_output

NAME = "animate"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``animate`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="draw the robot moving along a trajectory, with its actuator efforts (GIF or MP4)",
        description="Draw the base, the legs and the platform along the motion, the actuator "
        "efforts as bars and as curves with a time cursor (and with --loads every joint's "
        "force as an arrow); GIF through Pillow, MP4 through ffmpeg (the system's, or the "
        "video extra's: pip install 'rpr3gen[video]'). Frames are "
        f"bounded: at most {animation.MAX_FRAMES}, sides {animation.MIN_SIDE} to "
        f"{animation.MAX_SIDE} pixels.",
    )
    options.add_model(parser)
    options.add_trajectory(parser, samples=False, smoothing=False)
    parser.add_argument("--out", required=True, metavar="FILE.gif|FILE.mp4", help="the movie")
    parser.add_argument(
        "--fps",
        type=integer(1, animation.MAX_FPS),
        default=animation.DEFAULT_FPS,
        metavar="N",
        help=f"frames per second, 1 to {animation.MAX_FPS} (default: {animation.DEFAULT_FPS})",
    )
    parser.add_argument(
        "--speed",
        type=number(greater=0),
        default=1.0,
        metavar="S",
        help="trajectory seconds per movie second (default: 1, real time)",
    )
    parser.add_argument(
        "--size",
        default="{}x{}".format(*animation.DEFAULT_SIZE),
        metavar="WxH",
        help="frame size in pixels (default: {}x{})".format(*animation.DEFAULT_SIZE),
    )
    parser.add_argument("--loads", action="store_true", help="draw every joint's force as an arrow")
    options.add_backend(parser)


def run(args: argparse.Namespace) -> int:
    """Check the movie's plan before any work, then draw and write it."""
    check_output(args.out, "the movie", argument="out")
    size = animation.parse_size(args.size)
    model = load_model(args.model)
    name, traj = options.trajectory(args, model.structure.pose)
    animation.plan(traj.t, args.out, fps=args.fps, speed=args.speed, size=size)  # before work
    done = animation.write_animation(
        model, traj, args.out, fps=args.fps, speed=args.speed, size=size, loads=args.loads,
        title=f"{model.name}: {model.structure.title}, {name}", backend=args.backend,
    )  # fmt: skip
    print(f"wrote {done.path}: {done.frames} frames of {size[0]} x {size[1]} at {args.fps}/s")
    return 0
