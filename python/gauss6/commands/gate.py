"""`gauss6 gate --base REV [--json] [--config benchmarks/gate.toml]`: fail when the working tree is
slower, less accurate or violates a property compared with a base revision (gauss6.gate)."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..cli_args import EXIT_FAILED, EXIT_OK, error


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..gate import DEFAULT_CONFIG

    p = subparsers.add_parser("gate", help="fail when the working tree is slower, less accurate or violates a "
                                           "property compared with --base REV (thresholds: benchmarks/gate.toml)")
    p.add_argument("--base", help="the revision to compare against (any git revision: HEAD~1, main, a sha)")
    p.add_argument("--json", action="store_true", help="machine-readable result on stdout")
    p.add_argument("--config", type=Path, default=DEFAULT_CONFIG, help="thresholds (default benchmarks/gate.toml)")
    p.add_argument("--cache-dir", help="keep exported trees and builds here (reused when the revision matches); "
                                       "default: a new temporary folder")
    p.add_argument("--base-build", help="build tree of the base (reused as is when it holds the benchmarks)")
    p.add_argument("--base-source", help="with a prebuilt --base-build: its source tree (default: this repository)")
    p.add_argument("--work-build", help="build tree of the working tree (default <cache>/work-build)")
    p.add_argument("--no-build-work", action="store_true", help="use --work-build as it is, without building")
    p.add_argument("--filter", default=None, help="override [speed] filter")
    p.add_argument("--rounds", type=int, default=None, help="override [speed] rounds")
    p.add_argument("--repetitions", type=int, default=None, help="override [speed] repetitions")
    p.add_argument("--min-time", type=float, default=None, help="override [speed] min_time")
    p.add_argument("--no-count", action="store_true", help="skip the instruction counts (callgrind)")
    p.add_argument("--no-accuracy", action="store_true", help="skip the accuracy checks (speed and bench properties only)")
    return p


def run(args: argparse.Namespace) -> int:
    from ..gate import GateError, finite, format_report, run_gate

    def log(message: str) -> None:  # progress on stderr: stdout holds only the result
        print(message, file=sys.stderr)

    try:
        result = run_gate(args, log)
    except (GateError, FileNotFoundError, RuntimeError) as e:
        return error(str(e))
    print(json.dumps(finite(result), indent=1, default=str) if args.json else format_report(result))
    return EXIT_OK if result["passed"] else EXIT_FAILED
