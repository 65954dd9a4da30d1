"""Benchmarks of rpr3gen: regeneration, NumPy and C backends, Python calls, peers, control model.

Run from anywhere with the project's interpreter (rpr3gen installed with the ``dev`` extra)::

    python benchmarks/run.py                # full run; writes benchmarks/results.md
    python benchmarks/run.py --quick        # fewer repeats, no 10^7 samples; results-quick.md
    python benchmarks/run.py --out FILE.md  # write the Markdown elsewhere
    python benchmarks/run.py --only control # one section (several: --only c --only python);
                                            # writes benchmarks/results-only-control.md
    python benchmarks/run.py --readme       # full run, and README.md's performance tables

It prints the report (Markdown) on stdout, progress on stderr, and writes the same Markdown to
``--out``. The measurements live in the package ``rpr3bench`` beside this file (``workers``:
what runs in a fresh interpreter, ``sections``: what each section runs and shows, ``report``:
tables, machine, targets; ``charness``: ``bench.c``). See ``benchmarks/README.md``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from rpr3bench import report, sections, workers
from rpr3bench.common import BENCH, log


def report_path(out: str | None, quick: bool, only: list[str] | None = None) -> Path:
    """Where the report goes: ``--out``, else ``results.md``, or ``results-quick.md`` with
    ``--quick``, or ``results-only-KEY[-quick].md`` with ``--only``, so that neither a quick
    nor a partial run replaces the committed full results."""
    if out:
        return Path(out)
    if only:
        keys = [key for key in sections.SECTIONS if key in only]
        return BENCH / f"results-only-{'-'.join(keys)}{'-quick' if quick else ''}.md"
    return BENCH / ("results-quick.md" if quick else "results.md")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, no 10^7 NumPy run")
    parser.add_argument(
        "--out",
        help="Markdown report file (default: benchmarks/results.md, with --quick "
        "benchmarks/results-quick.md)",
    )
    parser.add_argument(
        "--only",
        action="append",
        choices=list(sections.SECTIONS),
        help="run only this section (repeat for several): "
        + ", ".join(f"{key} ({title})" for key, title in sections.SECTIONS.items()),
    )
    parser.add_argument(
        "--readme",
        action="store_true",
        help="also write the run's targets and speed tables into README.md (between its "
        "performance markers)",
    )
    parser.add_argument("--worker", help=argparse.SUPPRESS)  # one measurement, in this process
    parser.add_argument("--args", default="{}", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.readme and args.only:
        parser.error("--readme takes a run of every section (no --only)")
    if args.worker:
        print(json.dumps(workers.work(args.worker, json.loads(args.args))))
        return 0

    started = time.perf_counter()
    info = report.machine()
    parts, results = sections.run_all(args.quick, args.only)
    info["load average (end)"] = report.loadavg()
    kind = "--quick" if args.quick else "full"
    if args.only:
        kind += ", only " + ", ".join(args.only)
    info["run"] = f"{kind}, {time.perf_counter() - started:.0f} s"
    command = "python benchmarks/run.py" + (" --quick" if args.quick else "")
    command += "".join(f" --only {key}" for key in args.only or [])
    text = report.document(command, info, results, parts)
    print(text)
    out = report_path(args.out, args.quick, args.only)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    log(f"wrote {out}")
    if args.readme:
        readme = BENCH.parent / "README.md"
        if not report.update_readme(readme, report.readme_block(command, info, results)):
            log(f"{readme} has no performance markers: not written")
            return 1
        log(f"wrote the performance tables of {readme}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
