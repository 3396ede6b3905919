"""`gauss6 replay RECORDING --scene SCENE --out TRACE`: a recorded session drives a scene's runtime.

The recording is a gauss6 trace: one of gauss6's own runs, or a session recorded by another
framework and imported with `gauss6 trace import` (a HAPI device log, or CSV). Its handle poses
drive the runtime through the replay device (device/include/gauss6/replay_device.h: interpolated
between recorded ticks, the grip and buttons as recorded), and the run is written as a trace of
its own, which `gauss6 view` shows, alone or beside the recording.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .trace import read_trace


def replay(recording, scene, out, threaded: bool = False, duration: float = -1.0, quiet: bool = True) -> dict:
    """Replays `recording` (a trace path) in `scene` (a scene path) and writes the run to `out`.

    Returns the run's statistics (the dict of gauss6._gauss6.runtime.replay). Raises
    gauss6.LoadError for a bad scene or recording, ValueError when the run cannot start."""
    from ._gauss6 import runtime

    from .cli import check_run_span

    tr = read_trace(recording)
    phases = [(str(p["name"]), float(p["start"])) for p in tr.meta.get("phases", [])]
    end = float(tr.ticks["t"][-1]) if len(tr.ticks) else 0.0
    if not (duration < 0 or math.isfinite(duration)):
        raise ValueError(f"duration {duration!r} s is not finite")
    if duration < 0:  # the whole recording: bounded as --duration is
        check_run_span(end, f"{recording}: the recording")
    total = duration if duration >= 0 else end
    with tqdm(total=round(total, 3), unit="s", desc="replay", disable=quiet,
              bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.1f}/{total:.1f} s [{elapsed}<{remaining}]") as bar:
        def progress(t: float) -> None:
            bar.update(round(min(t, total), 3) - bar.n)

        return runtime.replay(str(scene), str(recording), str(out), phases=phases, threaded=threaded,
                              duration=duration, progress=progress)


def cmd_replay(args: argparse.Namespace) -> int:
    from . import LoadError

    try:
        r = replay(args.recording, args.scene, args.out, threaded=args.threaded, duration=args.duration,
                   quiet=args.quiet)
    except (LoadError, ValueError) as e:
        print(f"gauss6 replay: {e}", file=sys.stderr)
        return 2
    tr = read_trace(args.out)
    force = np.linalg.norm(tr.ticks["wrench"][:, :3], axis=1) if len(tr.ticks) else np.zeros(1)
    events = ", ".join(f"{k} {v}" for k, v in r["haptic"]["events"].items()) or "none"
    print(f"replayed {args.recording} in {args.scene}: {r['num_ticks']} haptic ticks, {r['num_sim_steps']} sim "
          f"steps, {r['run_time']:.3f} s of run time; max force {force.max():.4g} N; haptic events: {events}")
    print(f"written to {Path(args.out)}")
    return 0


def register(subparsers) -> None:
    """Adds `replay` to the gauss6 command's subparsers."""
    rp = subparsers.add_parser("replay", help="a recorded session (trace, or imported HAPI/CSV log) drives a scene")
    from .cli import input_file, output_file, run_seconds

    rp.add_argument("recording", type=input_file("recording"),
                    help="the recorded session, a trace (gauss6 trace import makes one from a log)")
    rp.add_argument("--scene", required=True, type=input_file("scene"), help="the scene file (.toml) to run")
    rp.add_argument("--out", required=True, type=output_file,
                    help="the trace of the replayed run to write (.g6trace)")
    rp.add_argument("--threaded", action="store_true", help="real threads and the wall clock (default: lockstep)")
    rp.add_argument("--duration", type=run_seconds, default=-1.0,
                    help="s of run time (default: the recording's; at most a day)")
    rp.add_argument("--quiet", action="store_true", help="no progress bar")
    rp.set_defaults(func=cmd_replay)
