"""`gauss6 validate`: an engine under test driven with the simulated device and judged, or a
recorded run judged (exit codes of its own: validate.EXIT_CODES, docs/engine-contract.md; its
usage errors exit 3). The parser and the command are gauss6.validate's `register` and
`cmd_validate`, beside the driver and the oracle they call."""
from __future__ import annotations

import argparse

from ..validate import cmd_validate as run, register  # noqa: F401  (run: this command's entry point)


def add_parser(subparsers) -> argparse.ArgumentParser:
    register(subparsers)
    return subparsers.choices["validate"]
