"""`gauss6 validate`: an engine under test driven with the simulated device and judged, or a
recorded run judged (gauss6.validate), or the conformance battery run on it (--suite:
gauss6.conformance). Its exit codes are its own (validate.EXIT_CODES, docs/engine-contract.md):
argparse's usage errors exit 3 here, since 2 means "the engine failed"."""
from __future__ import annotations

import argparse
import sys

from ..cli_args import input_file, nonnegative_int, output_dir, run_seconds
from ..engine_host import RUN_TIMEOUT, STEP_TIMEOUT


def run(args: argparse.Namespace) -> int:
    from ..conformance import cmd_suite
    from ..engine import EngineError, check_spec
    from ..validate import EXIT_USAGE, validate

    if args.suite and not args.engine:
        print("gauss6 validate: --suite drives an engine: give --engine ENGINE", file=sys.stderr)
        return EXIT_USAGE
    if bool(args.engine) == bool(args.run):
        print("gauss6 validate: give either --engine ENGINE or a recorded RUN (not both)", file=sys.stderr)
        return EXIT_USAGE
    if args.suite:
        try:
            check_spec(args.engine)
        except (EngineError, ValueError) as e:
            print(f"gauss6 validate: {e}", file=sys.stderr)
            return EXIT_USAGE
        return cmd_suite(args)
    if args.scene is None:
        print("gauss6 validate: give --scene SCENE (or --suite conformance)", file=sys.stderr)
        return EXIT_USAGE
    try:
        return validate(args)
    except (EngineError, ValueError, FileNotFoundError) as e:
        print(f"gauss6 validate: {e}", file=sys.stderr)
        return EXIT_USAGE


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("validate", help="drive an engine with the simulated device and judge its run, or "
                                               "judge a recorded run (exit 1: a check failed, 2: the engine "
                                               "failed, 3: usage)")
    p.add_argument("run", nargs="?", type=input_file("run", directory_ok=True),
                   help="a recorded run to judge: a .g6trace, or a ticks CSV (docs/engine-contract.md)")
    p.add_argument("--engine", help="engine library path, a built engine (gauss6, box-penalty, fault), "
                                    "python:MODULE:FACTORY or python:path/to/file.py:FACTORY")
    p.add_argument("--isolation", choices=("process", "inline"), default="process",
                   help="run the engine in a child process (default; a crash or hang is reported) or inline")
    p.add_argument("--step-timeout", type=run_seconds, default=STEP_TIMEOUT, metavar="S",
                   help=f"per-step watchdog: a step with no answer in S s is a hang "
                        f"(default {STEP_TIMEOUT:g})")
    p.add_argument("--run-timeout", type=run_seconds, default=RUN_TIMEOUT, metavar="S",
                   help=f"per-run watchdog: a run (create and reset included) not done S s after the engine's start "
                        f"is a hang "
                        f"(default {RUN_TIMEOUT:g})")
    p.add_argument("--config", default="", help="the engine's config text (default: empty)")
    p.add_argument("--scene", type=input_file("scene"), help="scene TOML file (with --suite: run only this scene)")
    p.add_argument("--suite", choices=("conformance",),
                   help="run every scene of the suite with its script (conformance: the battery, "
                        "docs/conformance-battery.md) and write one table, DIR/conformance.md and .json")
    p.add_argument("--workers", type=nonnegative_int, default=0,
                   help="with --suite: Dask worker processes of a local cluster (default 0: serial, in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="with --suite: run on an existing Dask cluster (tcp://host:port)")
    p.add_argument("--script", help="hand script name or .json path (default: the scene's device.script)")
    p.add_argument("--duration", type=run_seconds, default=None, help="run only the first S seconds of the script")
    p.add_argument("--out", required=True, type=output_dir, help="output directory")
    p.add_argument("--thresholds", type=input_file("thresholds file"),
                   help="thresholds file (default harness/oracle.toml)")
    p.add_argument("--json", action="store_true", help="print validation.json instead of the table")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=run)

    def usage_error(message):  # argparse's own errors exit 2, which here means "the engine failed"
        from ..validate import EXIT_USAGE

        p.print_usage(sys.stderr)
        print(f"gauss6 validate: error: {message}", file=sys.stderr)
        sys.exit(EXIT_USAGE)
    p.error = usage_error
    return p
