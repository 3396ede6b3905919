"""`gauss6 bench [--build DIR] [--out DIR] [--filter REGEX]`: every benchmark suite (gauss6.bench);
JSON, table and latency plot in out/bench/."""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import paths
from ..cli_args import EXIT_OK, error, positive_int


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("bench", help="run the benchmark suites; JSON, table and plot in out/bench/")
    p.add_argument("--build", type=Path, default=None, help="CMake build tree (default: GAUSS6_BUILD_DIR or build/)")
    p.add_argument("--out", type=Path, default=paths.REPO_ROOT / "out" / "bench", help="output folder")
    p.add_argument("--filter", default="", help="Google Benchmark filter (regex)")
    p.add_argument("--repetitions", type=positive_int, default=3)
    p.add_argument("--min-time", type=float, default=None, help="seconds per benchmark (Google Benchmark default 0.5)")
    return p


def run(args: argparse.Namespace) -> int:
    from ..bench import format_table, run as run_bench

    try:
        rows = run_bench(args.build, args.out, args.filter, args.repetitions, args.min_time)
    except (FileNotFoundError, RuntimeError) as e:
        return error(str(e))
    print(format_table(rows))
    print(f"written to {args.out}")
    return EXIT_OK
