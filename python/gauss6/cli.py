"""The `gauss6` command: one entry point for scenes, datasets, cross-checks and reproduction.

    gauss6 --version
    gauss6 scene info SCENE [--json]
    gauss6 datasets generate [--only NAME] [--out DIR] | check
    gauss6 crosscheck qp [--family NAME] [--json] [--seeded N [--seed S] [--workers N] [--scheduler ADDR] [--out DIR]]
    gauss6 ccd queries FILE.csv|DIR [--kind vf|ee] [--impl optimized|reference] [--json]
    gauss6 crosscheck ccd [--set NAME] [--json] [--peers] [--seeded N [--seed S] [--family F] [--workers N] ...]
    gauss6 report qp --out DIR
    gauss6 report peers [--out DIR] [--repeats N] [--ccd-only | --qp-only]
    gauss6 run SCENE [--script NAME|FILE] --out DIR [--threaded]
    gauss6 reproduce peg|bunny|all --out DIR [--threaded]
    gauss6 reproduce engines --out DIR [--slice S]
    gauss6 trace export TRACE [--csv DIR] [--hapi FILE]
    gauss6 trace import FILE --format hapi|csv --out TRACE
    gauss6 replay RECORDING --scene SCENE --out TRACE
    gauss6 view TRACE [TRACE ...] [--scene SCENE] [--out page.html]
    gauss6 validate (--engine ENGINE --scene SCENE | RUN) --out DIR
    gauss6 certify TRACE --scene SCENE | --witness FILE
    gauss6 reference-speed [--set NAME] [--both]
    gauss6 device list [--json]
    gauss6 bench [--build DIR] [--out DIR] [--filter REGEX]
    gauss6 rate [--rate-hz 10000] [--duration 60] --out DIR
    gauss6 sweep [--build DIR] [--out DIR]
    gauss6 gate --base REV [--json]

Each subcommand is a module of gauss6.commands (add_parser, run); this module only assembles
them. Every subcommand exits non-zero on a failed check, with a message naming the problem
(the exit codes: docs/cli.md).
"""
from __future__ import annotations

import argparse
import importlib
import sys

# The subcommands' modules (gauss6/commands/NAME.py), in the order `gauss6 --help` lists them.
COMMANDS = ("scene", "datasets", "crosscheck", "ccd", "report", "device", "reproduce", "trace", "run", "replay",
            "view", "validate", "certify", "reference_speed", "bench", "rate", "sweep", "gate")


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    p = argparse.ArgumentParser(prog="gauss6", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"gauss6 {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        command = importlib.import_module(f".commands.{name}", __package__)
        command.add_parser(sub).set_defaults(run_command=command.run)
    return p


def main(argv: list[str] | None = None) -> int:
    """The command's exit status: argparse's own (0 for --help and --version, 2 for an argument
    refused at parse time, its message on stderr; `validate` refuses with 3) or the subcommand's."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as e:
        return 0 if e.code is None else e.code if isinstance(e.code, int) else 2
    return args.run_command(args)


if __name__ == "__main__":
    sys.exit(main())
