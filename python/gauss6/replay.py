"""`gauss6 replay RECORDING --scene SCENE --out TRACE`: a recorded session drives a scene's runtime.

The recording is a gauss6 trace: one of gauss6's own runs, or a session recorded by another
framework and imported with `gauss6 trace import` (a HAPI device log, or CSV). Its handle poses
drive the runtime through the replay device (device/include/gauss6/replay_device.h: interpolated
between recorded ticks, the grip and buttons as recorded), and the run is written as a trace of
its own, which `gauss6 view` shows, alone or beside the recording.
"""
from __future__ import annotations

import math

from tqdm import tqdm

from .trace import read_trace


def replay(recording, scene, out, threaded: bool = False, duration: float = -1.0, quiet: bool = True) -> dict:
    """Replays `recording` (a trace path) in `scene` (a scene path) and writes the run to `out`.

    Returns the run's statistics (the dict of gauss6._gauss6.runtime.replay). Raises
    gauss6.LoadError for a bad scene or recording, ValueError when the run cannot start."""
    from ._gauss6 import runtime

    from .cli_args import check_run_span

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
