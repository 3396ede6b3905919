"""`gauss6 reference-speed [--set NAME ...] [--steps N] [--both] [--json]`: the exact first contact's
CPU time per CCD step set (gauss6.reference_speed), filtered and (--both) exact-only, checked
equal; exit 1 when the two paths disagree."""
from __future__ import annotations

import argparse
import json
import sys

from ..cli_args import EXIT_FAILED, EXIT_OK, positive_int


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("reference-speed", help="the exact first contact's CPU time per CCD step set, "
                                                      "filtered and (--both) exact-only, checked equal")
    p.add_argument("--set", action="append", help="a set of datasets_generated/ccd/ (repeatable; default: all)")
    p.add_argument("--steps", type=positive_int, help="only the first N steps of each set")
    p.add_argument("--both", action="store_true", help="also the exact-only path (slow: minutes on the large "
                                                       "rotations), and check the answers are the same")
    p.add_argument("--json", action="store_true")
    return p


def run(args: argparse.Namespace) -> int:
    from ..reference_speed import format_table, measure

    def progress(name, done, total):
        if not args.json:
            print(f"\r{name}: {done}/{total}", end="", file=sys.stderr, flush=True)

    result = measure(args.set, args.steps, args.both, progress)
    if not args.json:
        print(file=sys.stderr)
    print(json.dumps(result, indent=2) if args.json else format_table(result))
    return EXIT_FAILED if any(r["mismatches"] for r in result.values()) else EXIT_OK
