"""What the engine's isolation costs per tick (docs/engine-contract.md, "Isolation"): the peg
script driven with gauss6's own engine inline and in a child process (gauss6.engine_host), the
transport's cost per tick (the driver's wall time for a step less the engine call's own: median,
p99, max, us), the engine call's wall time and the run's wall time per tick, side by side.

    .venv/bin/python benchmarks/isolation_overhead.py [--duration S] [--repeat N] [--engine E]

A benchmark, not a test: run it on a quiet machine (the numbers move with the load); it prints
a table and, with --json FILE, writes the figures.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from gauss6 import paths
from gauss6.driver import drive, scene_script
from gauss6.engine import EngineScene
from gauss6.engine_host import InlineHost, ProcessHost

PEG = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"


def run(host, scene, text, duration, folder: Path) -> dict:
    try:
        tr = drive(host, scene, text, folder / f"{host.mode}.g6trace", duration)
    finally:
        host.close()
    extra = tr.meta["extra"]
    if "engine_failure" in extra:
        raise SystemExit(f"the engine failed: {extra['engine_failure']}")
    wall = np.asarray(tr.steps["update_time"], float) * 1e6
    return {"ticks": len(tr.ticks), "transport_us": extra["isolation"]["round_trip_us"],
            "engine_call_us": {"median": float(np.median(wall)), "p99": float(np.quantile(wall, 0.99))},
            "run_us_per_tick": extra["wall_seconds"] / len(tr.ticks) * 1e6}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=None, help="seconds of the script (default: all of it)")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each mode (interleaved)")
    ap.add_argument("--engine", default="gauss6")
    ap.add_argument("--json", help="write the figures to this file")
    args = ap.parse_args()
    scene = EngineScene.from_scene_file(PEG)
    text, _ = scene_script(PEG)
    results: dict = {"inline": [], "process": []}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            results["inline"].append(run(InlineHost.of(args.engine), scene, text, args.duration, Path(tmp)))
            results["process"].append(run(ProcessHost(args.engine), scene, text, args.duration, Path(tmp)))
    print("| mode | ticks | transport median (us) | p99 | max | engine call median (us) | p99 | run per tick (us) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for mode, rows in results.items():
        for r in rows:
            t, e = r["transport_us"], r["engine_call_us"]
            print(f"| {mode} | {r['ticks']} | {t['median']:.1f} | {t['p99']:.1f} | {t['max']:.0f} | "
                  f"{e['median']:.1f} | {e['p99']:.1f} | {r['run_us_per_tick']:.1f} |")
    load = os.getloadavg()
    print(f"\n{os.cpu_count()} cpus, load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} (the figures grow with it)")
    if args.json:
        Path(args.json).write_text(json.dumps({"load_average": load, **results}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
