"""What every `gauss6` command shares: the argument types, the one error helper and the exit codes.

Command modules (gauss6/commands/) import from here, never from gauss6.cli, which only
assembles them. A bad value is refused at parse time (argparse's exit 2, the option named),
never turned into a traceback, a hang or a run without end. The exit codes are documented
once, in docs/cli.md (python/tests/test_cli.py keeps that table and EXIT_CODES in step);
`gauss6 validate` has codes of its own (validate.EXIT_CODES, docs/engine-contract.md).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import paths

EXIT_OK, EXIT_FAILED, EXIT_ERROR = 0, 1, 2
EXIT_CODES = {EXIT_OK: "success: every check passed",
              EXIT_FAILED: "a check failed (the failures on stderr)",
              EXIT_ERROR: "an argument refused or an input that cannot serve (the problem named on stderr)"}

MAX_RUN_SECONDS = 86400.0  # the longest run a command drives or replays: one day of run time


def error(message: str, command: str = "") -> int:
    """Prints `gauss6[ COMMAND]: error: MESSAGE` on stderr and returns EXIT_ERROR: every command's
    refusal of an input after parsing."""
    print(f"gauss6{' ' + command if command else ''}: error: {message}", file=sys.stderr)
    return EXIT_ERROR


def _arg_error(message: str) -> argparse.ArgumentTypeError:
    return argparse.ArgumentTypeError(message)


def run_seconds(text: str) -> float:
    """--duration: a finite number of seconds in (0, MAX_RUN_SECONDS]."""
    try:
        value = float(text)
    except ValueError:
        raise _arg_error(f"not a number of seconds: {text!r}") from None
    if not 0 < value <= MAX_RUN_SECONDS:  # NaN fails too
        raise _arg_error(f"{text}: a duration must be a finite number of seconds in (0, {MAX_RUN_SECONDS:g}]")
    return value


def check_run_span(seconds: float, what: str) -> None:
    """A recording or hand script's span, bounded as --duration is (ValueError naming it)."""
    if not seconds <= MAX_RUN_SECONDS:
        raise ValueError(f"{what} spans {seconds:g} s, more than a run can last ({MAX_RUN_SECONDS:g} s); "
                         "give --duration to run a part of it")


def _integer(text: str, lo: int, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise _arg_error(f"not an integer: {text!r}") from None
    if value < lo:
        raise _arg_error(f"{text}: {what} must be an integer >= {lo}")
    return value


def positive_int(text: str) -> int:
    """A count that must be at least 1 (--max-frames, --chunk-size, --seeded)."""
    return _integer(text, 1, "the value")


def nonnegative_int(text: str) -> int:
    """A count that may be 0 (--workers: 0 runs serially)."""
    return _integer(text, 0, "the value")


def _utf8(text: str) -> str:
    """A path given on the command line whose bytes are not UTF-8 (legal on Linux) reaches
    Python with surrogate escapes, which the C++ core cannot take: refused, named."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise _arg_error(f"{text.encode('utf-8', 'surrogateescape')!r}: the path holds bytes that are not "
                         "UTF-8; rename the file") from None
    return text


def input_file(what: str, directory_ok: bool = False):
    """An argparse type: an existing regular file (paths.check_input_file: not a FIFO, a device
    or a directory; a directory too when directory_ok), its path UTF-8."""
    def check(text: str) -> str:
        try:
            if not (directory_ok and Path(_utf8(text)).is_dir()):
                paths.check_input_file(_utf8(text), what)
        except paths.PathError as e:
            raise _arg_error(str(e)) from None
        return text
    check.__name__ = what  # argparse names the type in "invalid <name> value"
    return check


def _writable(text: str, want_dir: bool, what: str) -> str:
    problem = paths.output_problem(_utf8(text), want_dir, what)
    if problem:
        raise _arg_error(problem)
    return text


def output_dir(text: str) -> str:
    """An argparse type: a directory to write into (created later; an existing file, a path
    under a file or an unwritable place is refused)."""
    return _writable(text, True, "output directory")


def output_file(text: str) -> str:
    """An argparse type: a file to write (an existing directory, a path under a file or an
    unwritable place is refused)."""
    return _writable(text, False, "output file")


def add_budget_arguments(p: argparse.ArgumentParser) -> None:
    """--budget-cpu [S] and --budget-units N (gauss6 run, gauss6 reproduce)."""
    p.add_argument("--budget-cpu", type=_budget_seconds, nargs="?", const=RECOMMENDED_BUDGET_S, default=None,
                   metavar="S", help="each god-object update's CPU budget in seconds (alone: the recommended "
                   f"{RECOMMENDED_BUDGET_S * 1e3:g} ms; docs/sim-step.md, \"Budgeted updates\")")
    p.add_argument("--budget-units", type=_budget_units, default=0, metavar="N",
                   help="each god-object update's budget in work units (deterministic: repeats bit for bit)")


# The recommended CPU budget of an update (update_budget.h kRecommendedUpdateCpuSeconds; a test keeps them equal).
RECOMMENDED_BUDGET_S = 0.4e-3


def _budget_seconds(text: str) -> float:
    v = float(text)
    if not (v > 0 and v < 1):
        raise argparse.ArgumentTypeError(f"{text}: a CPU budget is in seconds, > 0 and < 1")
    return v


def _budget_units(text: str) -> int:
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError(f"{text}: a budget in work units is >= 1")
    return v
