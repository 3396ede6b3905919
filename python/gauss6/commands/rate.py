"""`gauss6 rate [--rate-hz 10000] [--duration 60] --out DIR`: a threaded run at a high haptic rate
(gauss6.haptic_rate): deadline misses, jitter."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cli_args import EXIT_OK, error, output_dir, run_seconds


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..haptic_rate import SCENES

    p = subparsers.add_parser("rate", help="a threaded run at a high haptic rate (10 kHz): deadline misses, jitter")
    p.add_argument("--scene", choices=sorted(SCENES), default="peg")
    p.add_argument("--rate-hz", type=float, default=10000.0)
    p.add_argument("--duration", type=run_seconds, default=60.0,
                   help="s of run time (the hand holds still after the script)")
    p.add_argument("--priority", type=int, default=80, help="SCHED_FIFO priority of the haptic loop")
    p.add_argument("--no-realtime", action="store_true", help="leave the default scheduling policy")
    p.add_argument("--no-pin", action="store_true", help="no CPU affinity")
    p.add_argument("--spin-us", type=float, default=None,
                   help="us of each haptic period waited busily before the tick (RuntimeSettings::spin_wait; "
                        "default: one period when pinned, else 0)")
    p.add_argument("--out", type=lambda text: Path(output_dir(text)), required=True)
    return p


def run(args: argparse.Namespace) -> int:
    from ..haptic_rate import format_result, run as run_rate

    try:
        spin_us = args.spin_us if args.spin_us is not None else (0.0 if args.no_pin else 1e6 / args.rate_hz)
        r = run_rate(args.scene, args.rate_hz, args.duration, 0 if args.no_realtime else args.priority,
                     not args.no_pin, args.out, spin_us)
    except ValueError as e:
        return error(str(e))
    print(format_result(r))
    return EXIT_OK
