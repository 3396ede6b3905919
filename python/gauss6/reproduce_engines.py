"""`gauss6 reproduce engines`: gauss6 and the third-party engines (MuJoCo, PyBullet, Drake,
DART, Rapier: python/gauss6/adapters; Bullet's C++ library through the C ABI: engines/bullet) on
the peg and the bunny scripts, each driven by the same simulated hand (gauss6.driver) and judged
by the same oracle (gauss6.oracle); the conformance battery's summary for every engine
(gauss6.conformance, on a slice of each scene's script); plus, per adapter, the sweep of the one
parameter that trades penetration against force.

Writes to OUT:
  engines.json              per run: the engine, its config, the script (and the slice run),
                            the verdicts (validation.json's form); per sweep point: the value,
                            penetrating poses, the deepest (estimate), force median / p99 / max
  engines.md                the engine x property table (both scripts), the sweeps' tables,
                            the machine, the figures
  figure_engines.png|svg    the Fig. 13 analogue: on the same hand motion (the peg pressed and
                            slid on the box's top, phases a-b), the force each engine sends and
                            its tangential share against the nearest features' contact wrenches
                            (Oracle.nearest_rows: every tick with force, penetrating or free),
                            virtual couplings against gauss6's constraint-based force
  figure_sweeps.png|svg     each adapter's trade: penetration depth against force
  runs/ENGINE-SCRIPT.g6trace
  battery/ENGINE/           the battery on that engine (conformance.md and .json, each scene's
                            validate outputs); engines.md holds the engine x scene summary

The scripts run whole unless --slice is given (seconds from the start of each script); an
engine whose framework is not installed is reported as such, not run.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from . import adapters, paths
from .driver import drive, scene_script
from .engine import EngineScene, load_engine
from .oracle import CHECKS, Oracle
from .validate import failure_verdict

SCRIPTS = {"peg": "peg_in_hole.toml", "bunny": "bunnies.toml"}
ENGINES = ("gauss6", "mujoco", "pybullet", "drake", "dart", "rapier", "bullet")
# Bullet's C++ library behind the C ABI (engines/bullet), loaded by path from the build tree.
BULLET_LIBRARY = "engines/bullet/libgauss6_bullet_engine.so"
# The battery's slice: the first BATTERY_SLICE s of each scene's script (its approach and first
# contact phase in every scene), so that seven engines x eight scenes fit in `make reproduce`.
BATTERY_SLICE = 1.2
KC_SWEEP = [250.0, 1000.0, 4000.0, 16000.0, 64000.0]  # a coupling stiffness per unit mass (1/s^2)
KC_TRADE = "the coupling stiffness: lower lets the tool lag, higher drives it in"

# The swept parameter of each adapter: (config key, values, unit, what it trades). The other
# parameters stay at the adapter's defaults (docs/engine-adapters.md).
SWEEPS = {
    "mujoco": ("weld_timeconst", [0.002, 0.005, 0.01, 0.02, 0.05], "s",
               "the weld's time constant (solref[0]): softer lets the tool lag, stiffer drives it in"),
    "pybullet": ("max_force", [2.0, 5.0, 10.0, 20.0, 50.0], "N",
                 "the fixed constraint's force limit: lower lets the tool lag, higher drives it in"),
    "drake": ("kc", KC_SWEEP, "1/s^2", KC_TRADE),
    "dart": ("kc", KC_SWEEP, "1/s^2", KC_TRADE),
    "rapier": ("kc", KC_SWEEP, "1/s^2", KC_TRADE),
    "bullet": ("kc", KC_SWEEP, "1/s^2", KC_TRADE),
}
SWEEP_SCRIPT, SWEEP_SLICE = "peg", 4.0  # phase a and the start of b: pressing and sliding on the top
FIG13_SCRIPT, FIG13_PHASES = "peg", (0.0, 6.0)  # the peg's phases a and b (as far as the run goes)


def engine_spec(name: str) -> str:
    """The engine as `gauss6 validate --engine` takes it: a built library or a Python adapter."""
    if name == "gauss6":
        return "gauss6"
    if name == "bullet":
        return str(paths.build_dir() / BULLET_LIBRARY)
    return f"python:gauss6.adapters:{name}"


def make(name: str, config: str = ""):
    if name in ("gauss6", "bullet"):
        return load_engine(engine_spec(name), config)
    return adapters.FACTORIES[name](config)


def _available(name: str) -> bool:
    if name == "bullet":
        return (paths.build_dir() / BULLET_LIBRARY).exists()
    return name == "gauss6" or adapters.available(name)


def _fmt_verdict(v: dict) -> str:
    if v["pass"]:
        return "pass"
    worst = v["worst"]
    worst = f"{worst:.3g}" if isinstance(worst, (int, float)) else str(worst)
    return f"FAIL {v['count']} ({worst} {v['unit']})"


_ORACLES: dict = {}


def oracle_for(scene_path) -> Oracle:
    """One oracle a scene (its exact mesh pairs are built once)."""
    key = str(scene_path)
    if key not in _ORACLES:
        _ORACLES[key] = Oracle(scene_path)
    return _ORACLES[key]


def run_one(engine_name: str, script: str, out: Path, duration, bar, config: str = "") -> dict:
    scene_path = paths.DATASETS_DIR / "scenes" / SCRIPTS[script]
    scene = EngineScene.from_scene_file(scene_path)
    text, script_path = scene_script(scene_path)
    engine = make(engine_name, config)
    label = f"{engine_name}-{script}"
    run_path = out / "runs" / f"{label}.g6trace"
    run_path.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    done = [0.0]

    def progress(t, end):
        bar.set_postfix_str(f"{label} driving {t:.1f}/{end:.1f} s")
        bar.update(0)

    trace = drive(engine, scene, text, run_path, duration, progress, extra={"engine_config": config})
    drive_s = time.perf_counter() - start

    def judge_progress(stage, n, total):
        if time.perf_counter() - done[0] > 0.3:
            done[0] = time.perf_counter()
            bar.set_postfix_str(f"{label} judging {stage} {n}/{total}")

    failure = trace.meta["extra"].get("engine_failure")
    if hasattr(engine, "close"):
        engine.close()
    if failure is not None and len(trace.ticks) < 2:  # nothing to judge: the engine's failure is the verdict
        return {"engine": engine_name, "engine_name": engine.name, "config": config, "script": script,
                "script_path": script_path, "duration": 0.0, "ticks": len(trace.ticks), "run": str(run_path),
                "drive_seconds": drive_s, "judge_seconds": 0.0, "pass": False,
                "verdicts": [failure_verdict(failure, scene_rate(trace)).to_json()], "series": None}
    result = oracle_for(scene_path).judge(trace, judge_progress,
                                          nearest_window=FIG13_PHASES if script == FIG13_SCRIPT else None)
    if failure is not None:
        result.verdicts.insert(0, failure_verdict(failure, scene_rate(trace)))
    return {"engine": engine_name, "engine_name": engine.name, "config": config, "script": script,
            "script_path": script_path, "duration": float(trace.ticks["t"][-1]), "ticks": len(trace.ticks),
            "run": str(run_path), "drive_seconds": drive_s, "judge_seconds": time.perf_counter() - start - drive_s,
            "pass": result.passed, "verdicts": [v.to_json() for v in result.verdicts],
            "series": {k: result.series[k] for k in ("t", "force", "cone_distance", "nearest_tangential", "nearest_rank",
                                                       "separation")}}


def scene_rate(trace) -> float:
    return trace.meta["device"]["rate_hz"]


def sweep_point(engine_name: str, key: str, value: float, oracle: Oracle, scene, text, duration) -> dict:
    """One sweep point: the run's penetration (every distinct pose, exactly; the deepest by the
    oracle's estimate on a sample) and its force (median over ticks with force, p99, max)."""
    engine = make(engine_name, f"{key}={value!r}")
    tmp = paths.REPO_ROOT / "out" / ".sweep.g6trace"
    tmp.parent.mkdir(parents=True, exist_ok=True)
    tr = drive(engine, scene, text, tmp, duration)
    if hasattr(engine, "close"):
        engine.close()
    ticks = tr.ticks
    poses = np.unique(np.hstack([ticks["xs_p"], ticks["xs_q"]]), axis=0)
    pen = [k for k in range(len(poses)) if oracle.intersecting_pairs(poses[k, :3], poses[k, 3:]) > 0]
    sample = pen[:: max(1, len(pen) // 50)]
    depth = max((oracle.depth_estimate(poses[k, :3], poses[k, 3:]) for k in sample), default=0.0)
    f = np.linalg.norm(ticks["wrench"][:, :3], axis=1)
    on = f[f > 1e-6]
    return {"value": value, "poses": len(poses), "penetrating_poses": len(pen), "max_depth_m": depth,
            "force_median": float(np.median(on)) if len(on) else 0.0,
            "force_p99": float(np.percentile(on, 99)) if len(on) else 0.0, "force_max": float(f.max())}


def _save(fig, stem: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    paths_out = [stem.with_suffix(".png"), stem.with_suffix(".svg")]
    for p in paths_out:
        fig.savefig(p, dpi=110)
    plt.close(fig)
    return paths_out


def fig13_stats(runs: list) -> list[dict]:
    """Per engine on Fig. 13's motion: ticks with force, those measured, those whose nearest rows span
    every wrench (not measured), the tangential share's median, p90 and max (oracle.toml [direction]
    nearest_band)."""
    t0, t1 = FIG13_PHASES
    out = []
    for r in runs:
        if r["script"] != FIG13_SCRIPT or r["series"] is None:
            continue
        s = r["series"]
        m = (s["t"] >= t0) & (s["t"] <= t1)
        share = s["nearest_tangential"][m]
        got = share[np.isfinite(share)]
        out.append({"engine": r["engine_name"], "with_force": int((s["force"][m] > 1e-6).sum()), "measured": len(got),
                    "spanning": int((s["nearest_rank"][m] >= 6).sum()),
                    "median": float(np.median(got)) if len(got) else None,
                    "p90": float(np.percentile(got, 90)) if len(got) else None,
                    "max": float(got.max()) if len(got) else None})
    return out


def figure_fig13(runs: list, out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    t0, t1 = FIG13_PHASES
    for i, r in enumerate(x for x in runs if x["script"] == FIG13_SCRIPT and x["series"] is not None):
        s = r["series"]
        m = (s["t"] >= t0) & (s["t"] <= t1)
        style = dict(lw=1.4 if r["engine"] == "gauss6" else 0.9, color=f"C{i}", label=r["engine_name"])
        axes[0].plot(s["t"][m], s["force"][m], **style)
        # Below 1e-6 (gauss6's rounding, 1e-16): drawn at the axis floor, so that the points show.
        share = np.maximum(s["nearest_tangential"][m], 1e-6)
        axes[1].plot(s["t"][m], share, ".", ms=2, color=f"C{i}", label=r["engine_name"])
    axes[0].set_ylabel("|F| sent to the user (N)")
    axes[0].legend(fontsize=8, loc="upper right")
    axes[1].set_ylabel("tangential share of |F|\n(nearest features, M^-1)")
    axes[1].set_yscale("log")
    axes[1].set_ylim(5e-7, 2)
    axes[1].axhline(0.01, color="k", lw=0.6, ls="--")
    axes[1].annotate("1%: felt as friction (oracle.toml [direction])", (t0, 0.012), fontsize=7)
    axes[1].annotate("1e-6 and below (gauss6: 1e-16, rounding)", (t0, 1.2e-6), fontsize=7)
    axes[1].set_xlabel("t (s): peg phases a (tilted rim pressed and slid) and b (laid down, slid)")
    fig.suptitle("Same hand motion: constraint-based force (gauss6) against the engines' couplings\n"
                 "(the share of the force outside the nearest contacts' normals is artificial friction; Fig. 13 "
                 "of the paper)", fontsize=10)
    return _save(fig, out / "figure_engines")


def figure_sweeps(sweeps: dict, out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, max(len(sweeps), 1), figsize=(4.2 * max(len(sweeps), 1), 3.8), squeeze=False)
    for ax, (name, sw) in zip(axes[0], sweeps.items()):
        pts = sw["points"]
        x = [p["force_p99"] for p in pts]
        y = [p["max_depth_m"] * 1e3 for p in pts]
        ax.plot(x, y, "o-")
        for p, xi, yi in zip(pts, x, y):
            ax.annotate(f"{p['value']:g}", (xi, yi), fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.set_xlabel("force p99 over ticks with force (N)")
        ax.set_ylabel("deepest penetration (mm, estimate)")
        ax.set_title(f"{name}: {sw['key']} ({sw['unit']})", fontsize=9)
    return _save(fig, out / "figure_sweeps")


def battery_lines(battery: dict) -> list[str]:
    """engines.md's battery section: engine x scene, each cell pass or the checks that failed."""
    from .conformance import MACHINE_CHECKS

    by_engine = battery["runs"]
    scenes = [r["scene"] for r in next(iter(by_engine.values()), [])]
    rows = ["| engine | " + " | ".join(scenes) + " |", "|" + " --- |" * (len(scenes) + 1)]
    for name, runs in by_engine.items():
        cells = []
        for r in runs:
            if r["engine_failure"]:
                cells.append(f"**engine failed** ({r['engine_failure']['kind']})")
            else:
                cells.append("pass" if r["pass"] else "**FAIL** " + ", ".join(r["failed"]))
        rows.append(f"| {name} | " + " | ".join(cells) + " |")
    return ["## The conformance battery", "",
            f"Every engine on the battery's eight scenes (docs/conformance-battery.md), **on a short slice: the first "
            f"{battery['slice_seconds']:g} s of each scene's script** (the approach and the first contact phase; the "
            f"whole battery is `gauss6 validate --engine E --suite conformance`). A cell: pass, or the checks that "
            f"failed ({', '.join(MACHINE_CHECKS)} measures this loaded machine's timing). Each engine's table with "
            f"the worst values: `battery/ENGINE/conformance.md`; each scene's report and witnesses: "
            f"`battery/ENGINE/SCENE/`. Ran on {battery['workers'] or 'no'} Dask workers in "
            f"{battery['wall_seconds']:.0f} s.", "", *rows, ""]


def report(runs: list, sweeps: dict, missing: list, out: Path, slice_s, wall: float, sweep_slice: float,
           battery: dict | None = None) -> str:
    from .machine import machine

    names = [c[0] for c in CHECKS]
    head = "| engine | script | " + " | ".join(names) + " |"
    rows = [head, "|" + " --- |" * (len(names) + 2)]
    for r in runs:
        cells = {v["name"]: _fmt_verdict(v) for v in r["verdicts"]}
        failed = [f"; **the engine failed**: {v['note']}" for v in r["verdicts"] if v["name"] == "engine_failure"]
        rows.append(f"| {r['engine_name']} | {r['script']} ({r['duration']:.1f} s{''.join(failed)}) | "
                    + " | ".join(cells.get(n, "-") for n in names) + " |")
    m = machine()
    lines = ["# Engines side by side", "",
             f"gauss6 and the third-party engines on the same hand scripts, driven by the same simulated device "
             f"and judged by the same oracle (`harness/oracle.toml`; a cell gives the count and the worst value "
             f"of a failed check). Scripts: {'whole' if slice_s is None else f'the first {slice_s:g} s of each'}. "
             f"Adapters and their parameters: `docs/engine-adapters.md`.", "",
             "\n".join(rows), ""]
    if missing:
        lines += [f"Not run (framework not installed): {', '.join(missing)}.", ""]
    stats = fig13_stats(runs)
    lines += ["![engines](figure_engines.png)", "",
              f"Fig. 13 analogue, lower panel: at every tick with force on the {FIG13_SCRIPT} script's phases a-b, "
              "the share of the wrench outside the span of the contact wrenches of the features nearest to the "
              "displayed tool (gauss6's contact generation within the pose's own clearance -- its separation, or "
              "its penetration depth estimate -- plus `nearest_band` delta, `harness/oracle.toml` [direction]; "
              "metric M^-1). Not measured: poses beyond `free_space`, and poses whose nearest rows span every "
              "wrench (rank 6).", "",
              "| engine | ticks with force | measured | rows of rank 6 | tangential share median | p90 | max |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
    for st in stats:
        cells = [f"{st[k]:.2g}" if st[k] is not None else "-" for k in ("median", "p90", "max")]
        lines.append(f"| {st['engine']} | {st['with_force']} | {st['measured']} | {st['spanning']} | "
                     + " | ".join(cells) + " |")
    lines += ["", *(battery_lines(battery) if battery else []),
              "## Each adapter's trade: penetration against force", "",
              f"The peg script's first {sweep_slice:g} s (phase a and the start of b), one parameter swept, the others at "
              "the adapter's defaults. Penetrating poses: every distinct displayed pose, exactly; depth: the "
              "oracle's estimate (deepest tool vertex inside) on a sample of them.", ""]
    for name, sw in sweeps.items():
        lines += [f"### {name}: {sw['key']} ({sw['unit']}): {sw['what']}", "",
                  f"| {sw['key']} | penetrating poses | deepest (mm) | force median (N) | force p99 (N) | force max (N) |",
                  "| --- | --- | --- | --- | --- | --- |"]
        for p in sw["points"]:
            lines.append(f"| {p['value']:g} | {p['penetrating_poses']} / {p['poses']} | {p['max_depth_m'] * 1e3:.3g} | "
                         f"{p['force_median']:.3g} | {p['force_p99']:.3g} | {p['force_max']:.3g} |")
        lines.append("")
    lines += ["![sweeps](figure_sweeps.png)", "",
              f"Machine: {m['processor']}, {m['cpus']} cpus (shared, loaded), {m['platform']}; "
              f"the whole command took {wall:.0f} s.", ""]
    text = "\n".join(lines)
    (out / "engines.md").write_text(text)
    return text


def reproduce_engines(out: Path, slice_s: float | None = None, show_progress: bool = True,
                      engines=ENGINES, sweep: bool = True, sweep_slice: float = SWEEP_SLICE,
                      battery_slice: float | None = BATTERY_SLICE, workers: int | None = None) -> dict:
    """battery_slice None: no battery; workers: the battery's Dask workers (campaign.run_campaign)."""
    from tqdm import tqdm

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    wall = time.perf_counter()
    present = [e for e in engines if _available(e)]
    missing = [e for e in engines if not _available(e)]
    sweep_names = [e for e in present if e in SWEEPS] if sweep else []
    total = len(present) * len(SCRIPTS) + sum(len(SWEEPS[e][1]) for e in sweep_names)
    bar = tqdm(total=total, desc="engines", unit="run", disable=not show_progress, dynamic_ncols=True)
    runs = []
    for script in SCRIPTS:
        for name in present:
            runs.append(run_one(name, script, out, slice_s, bar))
            bar.update(1)
    sweeps = {}
    scene_path = paths.DATASETS_DIR / "scenes" / SCRIPTS[SWEEP_SCRIPT]
    if sweep_names:
        oracle = oracle_for(scene_path)
        scene = EngineScene.from_scene_file(scene_path)
        text, _ = scene_script(scene_path)
        for name in sweep_names:
            key, values, unit, what = SWEEPS[name]
            points = []
            for v in values:
                bar.set_postfix_str(f"sweep {name} {key}={v:g}")
                points.append(sweep_point(name, key, v, oracle, scene, text, sweep_slice))
                bar.update(1)
            sweeps[name] = {"key": key, "unit": unit, "what": what, "points": points}
    bar.close()
    battery = None
    if battery_slice is not None:
        from .conformance import run_engines

        battery_runs, meta = run_engines({name: engine_spec(name) for name in present}, out / "battery",
                                         duration=battery_slice, workers=workers, show_progress=show_progress)
        battery = {"slice_seconds": battery_slice, "wall_seconds": meta["wall_seconds"], "workers": meta["workers"],
                   "runs": battery_runs}
    figure_fig13(runs, out)
    if sweeps:
        figure_sweeps(sweeps, out)
    wall = time.perf_counter() - wall
    report(runs, sweeps, missing, out, slice_s, wall, sweep_slice, battery)
    doc = {"format": "gauss6-engines", "version": 1, "slice_seconds": slice_s, "missing": missing,
           "runs": [{k: v for k, v in r.items() if k != "series"} for r in runs], "sweeps": sweeps,
           "battery": battery,
           "fig13_tangential": fig13_stats(runs),
           "wall_seconds": wall}
    (out / "engines.json").write_text(json.dumps(doc, indent=2) + "\n")
    return doc


def cmd(args) -> int:
    doc = reproduce_engines(Path(args.out), args.slice, show_progress=not args.quiet)
    print((Path(args.out) / "engines.md").read_text())
    gauss6_failed = [r for r in doc["runs"] if r["engine"] == "gauss6" and not r["pass"]]
    for r in gauss6_failed:
        failed = [v["name"] for v in r["verdicts"] if not v["pass"]]
        print(f"gauss6 reproduce engines: gauss6's own engine fails {', '.join(failed)} on {r['script']}",
              file=sys.stderr)
    for r in ((doc["battery"] or {}).get("runs") or {}).get("gauss6", []):
        if not r["pass"]:
            print(f"gauss6 reproduce engines: gauss6's own engine fails {', '.join(r['failed'])} on the battery's "
                  f"{r['scene']}", file=sys.stderr)
    print(f"written to {args.out}/ (engines.md, engines.json, figures, runs/, battery/)")
    return 0
