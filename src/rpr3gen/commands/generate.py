"""``rpr3gen generate``: derive and write the generated sources, the committed variants into
the source tree's ``generated/`` or one structure's variant; ``--check`` only compares."""

from __future__ import annotations

import argparse
from pathlib import Path

from rpr3gen import variants
from rpr3gen.errors import GeneratedCodeError, InputError, SetupError, did_you_mean
from rpr3gen.model import load_model
from rpr3gen.paths import check_output
from rpr3gen.structure import LEG_TYPES, SPATIAL_LEG_TYPES, Structure

NAME = "generate"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """The ``generate`` subcommand's parser."""
    parser = sub.add_parser(
        NAME,
        help="derive and write the generated sources",
        description="Derive and write generated code. Without --leg or --model: the committed "
        "variants (the paper's revolute and prismatic, rrr_1, ups_2 and rss2_1) into the source "
        "tree's "
        "generated/. With --leg and --actuated (or --model): that one structure's variant, into "
        "--out DIR, or by default into the cache where the runtime finds it (see "
        "RPR3GEN_CACHE_DIR).",
    )
    parser.add_argument(
        "--model",
        metavar="FILE",
        help="generate only this model's variant (default: the committed variants)",
    )
    parser.add_argument(
        "--leg",
        metavar="TYPE",
        help="generate the variant of this leg type (planar: RRR RPR RRP PRR PPR PRP RPP; "
        "spatial: UPS RUS PUS RSS2 PSS2); needs the actuated joint too (default: the committed "
        "variants)",
    )
    parser.add_argument(
        "--actuated",
        type=int,
        metavar="J",
        help="the joint (1, 2 or 3) of every leg that carries its motor (UPS: 2; the other "
        "spatial types: 1); needs the leg type "
        "too (default: none)",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: the source tree's generated/, or the cache for one "
        "structure)",
    )
    parser.add_argument(
        "--check",
        action="store_true",
        help="write nothing; fail if the sources are stale (default: write them). The "
        "committed tree is checked against its checksums.json when that was written by a "
        "render of the same generator, SymPy, Jinja2 and Python, else rendered again",
    )
    parser.add_argument(
        "--render",
        action="store_true",
        help="when checking, render the sources again and compare, even where checksums.json "
        "would tell (default: off)",
    )


def run(args: argparse.Namespace) -> int:
    """Render the sources (needs the ``derive`` extra) and write them, or check them."""
    if args.out and not args.check:  # before sympy loads: a second, not an hour of work
        check_output(args.out, "the generated sources", folder=True, argument="out")
    try:
        from rpr3gen_derive.codegen import files as codegen_files
        from rpr3gen_derive.planar import generate
    except ImportError as exc:
        raise SetupError(
            f"regeneration needs sympy and jinja2 ({exc.name} is missing): "
            "pip install 'rpr3gen[derive]'"
        ) from exc
    one = _structure(args)
    if one is not None:
        if one.singular:
            raise InputError(
                f"--actuated: a {one.title} cannot move: both its passive joints are prismatic "
                "(architecturally singular); nothing to generate"
            )
        target = generate.structure_of(one.leg, one.actuated, one.paper)
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
            raise SetupError("no source tree's generated/ folder here; name one with --out DIR")
        key = codegen_files.render_key(generate.source_hash())
        if args.check and not args.render:
            known = codegen_files.quick_stale(out_dir, key)
            if known is not None:
                return _report(out_dir, known, "checksums.json")
        if not args.check:
            check_output(out_dir, "the generated sources", folder=True, argument="out")
        files = generate.render(generate.COMMITTED)
        if not args.check:
            changed = codegen_files.write_files(
                out_dir, {**files, codegen_files.CHECKSUMS: codegen_files.checksums(files, key)}
            )
            print(f"{out_dir}: {len(changed)} of {len(files) + 1} files changed")
            return 0
    if args.check:
        return _report(out_dir, codegen_files.stale_files(out_dir, files), "a render", len(files))
    changed = codegen_files.write_files(out_dir, files)
    print(f"{out_dir}: {len(changed)} of {len(files)} files changed")
    return 0


def _report(out_dir: Path, stale: list[str], how: str, count: int | None = None) -> int:
    """``--check``'s outcome: a line of success, or the stale files as an error."""
    if stale:
        raise GeneratedCodeError(
            f"{out_dir}: stale or edited generated files: {', '.join(stale)}; "
            "run `rpr3gen generate`"
        )
    files = "" if count is None else f"{count} "
    print(f"{out_dir}: {files}generated files up to date (checked by {how})")
    return 0


def _structure(args: argparse.Namespace) -> Structure | None:
    """The one structure ``rpr3gen generate`` was asked for, or None for the committed ones."""
    if args.leg is not None or args.actuated is not None:
        if args.model:
            raise InputError("--model: not together with --leg and --actuated")
        if args.leg is None or args.actuated is None:
            raise InputError("--leg and --actuated go together")
        leg = str(args.leg).upper()
        every = (*LEG_TYPES, *SPATIAL_LEG_TYPES)
        if leg not in every:
            hint = did_you_mean(leg, every)
            raise InputError(f"--leg: must be one of {', '.join(every)}, got {args.leg!r}{hint}")
        if leg in SPATIAL_LEG_TYPES:
            joint = SPATIAL_LEG_TYPES[leg][1]
            if args.actuated != joint:
                raise InputError(
                    f"--actuated: a {leg} leg carries its motor on joint {joint}, got "
                    f"{args.actuated}"
                )
            return Structure(leg, args.actuated)
        if args.actuated not in (1, 2, 3):
            raise InputError(f"--actuated: must be 1, 2 or 3, got {args.actuated}")
        return Structure(leg, args.actuated)
    if args.model:
        return load_model(args.model).structure
    return None
