"""``python -m rpr3gen_derive [--check] [--out DIR]``: regenerate without the runtime.

The same as ``rpr3gen generate`` for every variant, for when the runtime cannot start (its
generated package missing or broken).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rpr3gen_derive.codegen.files import stale_files, write_files
from rpr3gen_derive.planar import generate


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rpr3gen_derive", description=__doc__)
    parser.add_argument("--out", metavar="DIR", help="default: the source tree's generated/")
    parser.add_argument("--check", action="store_true", help="fail if the sources are stale")
    args = parser.parse_args(argv)
    out = Path(args.out) if args.out else generate.default_out_dir()
    if out is None:
        print("no source tree's generated/ folder here; name one with --out DIR", file=sys.stderr)
        return 2
    files = generate.render()
    if args.check:
        stale = stale_files(out, files)
        print(
            f"{out}: {len(stale)} stale of {len(files)} files", file=sys.stderr if stale else None
        )
        return 1 if stale else 0
    changed = write_files(out, files)
    print(f"{out}: {len(changed)} of {len(files)} files changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
