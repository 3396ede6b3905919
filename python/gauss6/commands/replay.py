"""`gauss6 replay RECORDING --scene SCENE --out TRACE [--threaded] [--duration S]`: a recorded
session (a trace, or an imported HAPI/CSV log) drives a scene (gauss6.replay)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cli_args import EXIT_OK, error, input_file, output_file, run_seconds


def add_parser(subparsers) -> argparse.ArgumentParser:
    rp = subparsers.add_parser("replay", help="a recorded session (trace, or imported HAPI/CSV log) drives a scene")
    rp.add_argument("recording", type=input_file("recording"),
                    help="the recorded session, a trace (gauss6 trace import makes one from a log)")
    rp.add_argument("--scene", required=True, type=input_file("scene"), help="the scene file (.toml) to run")
    rp.add_argument("--out", required=True, type=output_file,
                    help="the trace of the replayed run to write (.g6trace)")
    rp.add_argument("--threaded", action="store_true", help="real threads and the wall clock (default: lockstep)")
    rp.add_argument("--duration", type=run_seconds, default=-1.0,
                    help="s of run time (default: the recording's; at most a day)")
    rp.add_argument("--quiet", action="store_true", help="no progress bar")
    return rp


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from .. import LoadError
    from ..replay import replay
    from ..trace import read_trace

    try:
        r = replay(args.recording, args.scene, args.out, threaded=args.threaded, duration=args.duration,
                   quiet=args.quiet)
    except (LoadError, ValueError) as e:
        return error(str(e), "replay")
    tr = read_trace(args.out)
    force = np.linalg.norm(tr.ticks["wrench"][:, :3], axis=1) if len(tr.ticks) else np.zeros(1)
    events = ", ".join(f"{k} {v}" for k, v in r["haptic"]["events"].items()) or "none"
    print(f"replayed {args.recording} in {args.scene}: {r['num_ticks']} haptic ticks, {r['num_sim_steps']} sim "
          f"steps, {r['run_time']:.3f} s of run time; max force {force.max():.4g} N; haptic events: {events}")
    print(f"written to {Path(args.out)}")
    return EXIT_OK
