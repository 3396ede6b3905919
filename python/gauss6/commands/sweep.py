"""`gauss6 sweep [--build DIR] [--out DIR] [--knob NAME ...] [--quick]`: speed against error per
accuracy knob (gauss6.sweeps: Pareto plots, table); exit 1 when a swept value violates a property."""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import paths
from ..cli_args import EXIT_FAILED, EXIT_OK, error


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..sweeps import KNOBS

    p = subparsers.add_parser("sweep", help="speed against error per accuracy knob (Pareto plots, table)")
    p.add_argument("--out", type=Path, default=paths.REPO_ROOT / "out" / "bench" / "sweeps")
    p.add_argument("--build", type=Path, default=None,
                   help="build tree with the benchmarks (default: GAUSS6_BUILD_DIR or build/)")
    p.add_argument("--knob", action="append", choices=KNOBS, help="one knob (repeatable; default: all)")
    p.add_argument("--quick", action="store_true", help="fewer values and data (a smoke run)")
    return p


def run(args: argparse.Namespace) -> int:
    from ..sweeps import KNOBS, format_table, run as run_sweeps

    try:
        results = run_sweeps(args.out, args.build, args.knob or KNOBS, args.quick)
    except (FileNotFoundError, RuntimeError, ValueError) as e:
        return error(str(e))
    print(format_table(results))
    print(f"written to {args.out}")
    bad = sum(r.get("violations", 0) for res in results.values() for r in res["rows"])
    return EXIT_FAILED if bad else EXIT_OK
