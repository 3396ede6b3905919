"""`gauss6 certify TRACE --scene SCENE [--out DIR] [--ticks A:B] [--json]`: a recorded run certified
exactly (gauss6.certify: every pose free, every motion between poses free of contact, separations
within the bound; exit 1 on a violation), or `--witness FILE`: a witness of `gauss6 validate`
re-checked exactly (exit 0 when the violation stands, 1 when it does not)."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..cli_args import EXIT_FAILED, EXIT_OK, error, input_file, output_dir


def tick_range_arg(text: str) -> tuple[int, int]:
    """--ticks A:B: two integers, 0 <= A < B (whether B is within the trace is checked once it is read)."""
    try:
        a, b = (int(x) for x in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--ticks must be A:B (integers), not {text!r}") from None
    if not 0 <= a < b:
        raise argparse.ArgumentTypeError(f"{text}: the tick range is empty or negative (give A:B with 0 <= A < B)")
    return a, b


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("certify", help="exactly certify a recorded run: every pose free, every motion "
                                              "between poses free of contact, separations within the bound "
                                              "(exit 1 on a violation)")
    p.add_argument("trace", nargs="?", type=input_file("trace"), help="a .g6trace")
    p.add_argument("--scene", type=input_file("scene"), help="the run's scene TOML file (a witness names its own)")
    p.add_argument("--witness", type=input_file("witness"),
                   help="re-check a witness file of `gauss6 validate` exactly instead (exit 0: the violation stands)")
    p.add_argument("--out", type=output_dir, help="directory for certify.json and certify.md (default: the trace's)")
    p.add_argument("--ticks", type=tick_range_arg, help="only the ticks A:B (a chunk, as a campaign runs it)")
    p.add_argument("--json", action="store_true", help="print certify.json instead of the table")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    return p


def _witness(args: argparse.Namespace) -> int:
    from ..paths import read_input_text
    from ..witness import recheck

    try:
        doc = json.loads(read_input_text(args.witness))
        stands, text = recheck(doc, args.scene)
    except (OSError, ValueError, KeyError, TypeError, RuntimeError) as e:
        return error(f"{args.witness}: {e}", "certify")
    print(text)
    return EXIT_OK if stands else EXIT_FAILED


def run(args: argparse.Namespace) -> int:
    from ..certify import certify, load_trace, to_markdown, write_report
    from ..trace import coverage

    if args.witness:
        return _witness(args)
    if not args.trace or not args.scene:
        return error("give a TRACE and --scene SCENE (or --witness FILE)", "certify")
    trace, scene = Path(args.trace), Path(args.scene)

    def progress(done: int, total: int) -> None:
        if not args.quiet:
            print(f"\rcertify: {done}/{total} ticks", end="", file=sys.stderr, flush=True)

    try:
        res = certify(scene, trace, tick_range=args.ticks, progress=progress)
        cov = coverage(load_trace(trace))
    except (ValueError, RuntimeError, OSError) as e:
        print(file=sys.stderr)
        return error(str(e), "certify")
    if not args.quiet:
        print(file=sys.stderr)
    if not cov["complete"]:
        print(f"gauss6 certify: warning: {trace}: the trace is incomplete ({'; '.join(cov['cut']) or 'not closed'}); "
              "only the ticks it holds are certified (certify.json: coverage)", file=sys.stderr)
    out = Path(args.out) if args.out else trace.parent
    try:
        doc = write_report(res, scene, trace, out, coverage=cov)
    except (ValueError, OSError) as e:
        return error(str(e), "certify")
    print(json.dumps(doc, indent=2) if args.json else to_markdown(doc))
    return EXIT_OK if res.passed else EXIT_FAILED
