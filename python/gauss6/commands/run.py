"""`gauss6 run SCENE [--script NAME|FILE] --out DIR [--threaded]`: any scene run and reported as
the paper's are. The parser and the command are gauss6.run's `register` and `cmd_run`, beside the
run they drive."""
from __future__ import annotations

import argparse

from ..run import cmd_run as run, register  # noqa: F401  (run: this command's entry point)


def add_parser(subparsers) -> argparse.ArgumentParser:
    register(subparsers)
    return subparsers.choices["run"]
