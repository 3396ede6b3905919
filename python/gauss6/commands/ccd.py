"""`gauss6 ccd queries FILE.csv|DIR [--kind vf|ee] [--impl optimized|reference] [--json]`: a CCD
query file (or a folder of them) through one implementation; exit 1 on a false negative."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..cli_args import EXIT_FAILED, EXIT_OK, error


def add_parser(subparsers) -> argparse.ArgumentParser:
    from .. import defaults  # the C++ settings' default time tolerance

    p = subparsers.add_parser("ccd", help="continuous collision detection")
    cq = p.add_subparsers(dest="action", required=True).add_parser(
        "queries", help="run a CCD query file (or a folder of them) through one implementation")
    cq.add_argument("target", help="query CSV file, or a directory (every CSV under vertex-face/ or edge-edge/)")
    cq.add_argument("--kind", choices=["vf", "ee"], help="vertex/face or edge/edge (default: from the folder name)")
    cq.add_argument("--impl", choices=["optimized", "reference"], default="optimized", help="default: optimized")
    time_tolerance = defaults()["ccd"]["time_tolerance"]
    cq.add_argument("--time-tolerance", type=float, default=time_tolerance,
                    help=f"optimized CCD time tolerance (default {time_tolerance:g})")
    cq.add_argument("--json", action="store_true", help="machine-readable output")
    return p


def run(args: argparse.Namespace) -> int:
    from ..ccd import format_stats, run_queries

    try:
        stats = run_queries(Path(args.target), args.kind, args.impl, time_tolerance=args.time_tolerance)
    except (ValueError, RuntimeError) as e:
        return error(str(e))
    print(json.dumps(stats.as_json()) if args.json else format_stats(stats, args.impl))
    for m in stats.missed[:50]:
        print(f"FALSE NEGATIVE {m}", file=sys.stderr)
    return EXIT_FAILED if stats.false_negatives else EXIT_OK
