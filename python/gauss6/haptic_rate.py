"""`gauss6 rate`: a threaded run at a high haptic rate, its deadline misses and jitter.

    gauss6 rate [--scene peg|bunny] [--rate-hz 10000] [--duration 60] [--priority 80 | --no-realtime]
                [--no-pin] [--spin-us US] --out DIR

Runs the scene's scripted scenario threaded (run_threaded: the haptic loop paced
by sleep_until at --rate-hz, the sim loop free-running at most every 0.5 ms), the
hand holding still after the script's last key until --duration, and writes
DIR/rate.g6trace, DIR/rate.json and DIR/rate.md. Not part of `make test`: a
minute of wall time.

What the loops ask of the OS (RuntimeSettings::realtime_priority, pin_threads):
SCHED_FIFO for the haptic loop at --priority (the sim loop two below), the
haptic loop alone on the last CPU and the other loops on the others. Whether the
machine granted each is reported per loop (granted, or the errno it refused with).
And RuntimeSettings::spin_wait (--spin-us; by default one period when pinned):
the haptic loop sleeps until that long before each tick and waits the rest
busily, on its own CPU: a timer's wake-up on a VM lands 50-100 us late.

Reported, from the trace's tick start times t_k and the steps (start = end time
minus update time):
- haptic loop: period p = 1 / rate; jitter |(t_k - t_{k-1}) - p| per tick,
  p50 / p99 / max; deadline misses: ticks that started more than one period
  late (the runtime's overruns, after which the schedule resyncs), and periods
  over 2 p (a tick skipped);
- sim loop: the period between update starts and its jitter beside the 0.5 ms
  floor (sim_min_period), p50 / p99 / max; deadline misses: updates more than 1 ms
  apart (the issue's floor: a new constraint set at least every haptic millisecond);
  the update's wall and CPU time.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from . import _gauss6, paths
from .trace import read_trace

SCENES = {"peg": paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml",
          "bunny": paths.DATASETS_DIR / "scenes" / "bunnies.toml"}
SIM_DEADLINE = 1e-3  # s: a new constraint set at least every millisecond


def _q(x: np.ndarray, scale: float = 1e6) -> dict:
    x = np.asarray(x, dtype=float) * scale
    if x.size == 0:
        return {"p50": None, "p99": None, "max": None}
    return {"p50": float(np.median(x)), "p99": float(np.percentile(x, 99)), "max": float(x.max())}


def _granted(loop: dict) -> str:
    rt = loop["realtime"]
    fifo = (f"SCHED_FIFO {loop['realtime_priority']}" if rt == 1 else "default policy (not asked)" if rt == 0
            else f"SCHED_FIFO refused (errno {-rt})")
    pin = (f"pinned to CPU {loop['pinned_cpu']}" + (" alone" if loop.get("role") == "haptic" else "+")
           if loop["pinned_cpu"] >= 0 else f"pinning refused (errno {-loop['pin_error']})" if loop["pin_error"]
           else "not pinned")
    return f"{fifo}; {pin}"


def run(scene: str, rate_hz: float, duration: float, priority: int, pin: bool, out: Path,
        spin_us: float = 0.0) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    trace_path = out / "rate.g6trace"
    r = _gauss6.runtime.run_scenario(str(SCENES[scene]), str(trace_path), threaded=True, duration=duration,
                                     rate_hz=rate_hz, realtime_priority=priority, pin_threads=pin,
                                     hold_until=duration + 1.0, spin_wait=spin_us * 1e-6)
    tr = read_trace(trace_path)
    period = 1.0 / rate_hz
    t = np.asarray(tr.ticks["t"], dtype=float)
    dt = np.diff(t)
    steps = tr.steps
    starts = np.asarray(steps["t"] - steps["update_time"], dtype=float)
    sim_dt = np.diff(starts)
    sim_min = r["sim"]["nominal_period"]  # RuntimeSettings::sim_min_period
    result = {
        "scene": scene, "rate_hz": rate_hz, "duration_s": duration, "run_time_s": r["run_time"],
        "machine": {"cpus": len(os.sched_getaffinity(0)), "load_average": list(os.getloadavg())},
        "asked": {"realtime_priority": priority, "pin_threads": pin, "spin_us": spin_us},
        "haptic": {"ticks": int(len(t)), "granted": _granted({**r["haptic"], "role": "haptic"}),
                   "jitter_us": _q(np.abs(dt - period)), "period_us": _q(dt),
                   "late_starts": int(r["haptic"]["overruns"]), "skipped_periods": int((dt > 2 * period).sum()),
                   "work_us": {"mean": r["haptic"]["work_mean"] * 1e6, "max": r["haptic"]["work_max"] * 1e6}},
        "sim": {"steps": int(len(steps)), "granted": _granted({**r["sim"], "role": "sim"}),
                "period_us": _q(sim_dt), "jitter_us": _q(np.abs(sim_dt - sim_min)),
                "misses_over_1ms": int((sim_dt > SIM_DEADLINE).sum()),
                "update_wall_us": _q(steps["update_time"]), "update_cpu_us": _q(steps["update_cpu_time"])},
        "rows_dropped": r["rows_dropped"], "sim_min_period_ms": sim_min * 1e3,
    }
    (out / "rate.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "rate.md").write_text(format_result(result) + "\n")
    return result


def format_result(r: dict) -> str:
    h, s = r["haptic"], r["sim"]

    def q(d):
        return " / ".join("-" if d[k] is None else f"{d[k]:.3g}" for k in ("p50", "p99", "max"))

    return "\n".join([
        f"Threaded run of the {r['scene']} scenario at {r['rate_hz']:g} Hz for {r['run_time_s']:.1f} s "
        f"({r['machine']['cpus']} CPUs, load average {', '.join(f'{x:.1f}' for x in r['machine']['load_average'])}; "
        f"the haptic loop's busy wait {r['asked']['spin_us']:g} us a period).",
        "", "| loop | what it got from the OS | runs | period (us) p50 / p99 / max | jitter (us) p50 / p99 / max "
        "| deadline misses |", "|---|---|---|---|---|---|",
        f"| haptic | {h['granted']} | {h['ticks']} ticks | {q(h['period_us'])} | {q(h['jitter_us'])} | "
        f"{h['late_starts']} ticks over one period late, {h['skipped_periods']} periods over 2x |",
        f"| sim | {s['granted']} | {s['steps']} updates | {q(s['period_us'])} | {q(s['jitter_us'])} (beside the "
        f"{r['sim_min_period_ms']:g} ms floor) | {s['misses_over_1ms']} updates more than 1 ms apart |",
        "", f"Sim update (us), wall {q(s['update_wall_us'])}, the sim thread's CPU {q(s['update_cpu_us'])}; "
        f"haptic tick work mean {h['work_us']['mean']:.3g} us, max {h['work_us']['max']:.3g} us; trace rows dropped "
        f"{r['rows_dropped']}."])
