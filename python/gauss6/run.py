"""`gauss6 run SCENE [--script NAME|FILE] --out DIR [--threaded]`: any scene, run and reported as the paper's are.

The scene runs with the simulated device following a hand script (the scene's [device] script, a
name, a JSON file or a [device.script] table: docs/scene-format.md, "Hand scripts"; or --script,
which replaces it) through the runtime's three loops (lockstep by default: a virtual 1 kHz clock,
repeatable bit for bit; --threaded: real threads and the wall clock), and writes into DIR, with
NAME the scene file's stem (or --name):

    NAME.g6trace          the run's trace (docs/trace-format.md)
    figure_NAME.png/.svg  force computation time, update time, contacts and the force (X, Y, Z) over time,
                          the script's phases shaded and named, the let-go marked (figures.py)
    view_NAME.html        the run in 3D with its timeline and plots (gauss6 view; opens from file://)
    certify_NAME.md/.json the exact certification of every pose and every motion (gauss6 certify)
    summary.json          {NAME: the numbers below}; details.json: everything else the report shows
    report.md             the numbers, the figure, the machine

The numbers (also `gauss6 reproduce`'s, which runs the paper's scenes through this module):
  force_time_us          per haptic tick, the coupling step's wall time (us): median, p99, max
  update_time_ms         per sim step, the god-object update's wall time (ms): median, p99, max
  update_cpu_time_ms     per sim step, the sim thread's CPU time in the update (ms; CLOCK_THREAD_CPUTIME_ID:
                         without the time the thread was preempted, which on a loaded machine is most of
                         a wall-clock p99 or max): median, p99, max. Lockstep runs are run LOCKSTEP_RUNS
                         times (each repeat must be the first run tick for tick, or the run fails) and the
                         report gives beside it each step's least time over them (the benchmarks' method:
                         the machine's noise, not the step, sets a single run's max), with the count of
                         updates over UPDATE_BUDGET_MS
  constraint_update_hz   the rate of new constraint sets. Lockstep: the rate a free-running sim loop
                         would reach, min = 1 / max update time, mean = 1 / mean update time.
                         Threaded: from the steps' start times, min = 1 / max period, mean = steps / time
  max_contacts           the largest contact set of a sim step
  penetrating_poses      god-object poses (every distinct xs of the trace's ticks: in lockstep runs every
                         pose the sim loop took; in --threaded runs the poses the haptic loop saw) at
                         which the exact check finds an intersecting triangle pair: must be 0. The
                         check is `gauss6 certify`'s (certify.py), which also certifies the motion between
                         successive poses and the separations at the poses with contacts (properties 5
                         and 6), written to certify_NAME.md/.json; a run it does not certify fails
                         (-1: not certified, --no-certify)
  max_rel_force_dot_ac   per coupling step, |Fc . ac| / (|Fc| |ac|) (max; steps with a running offset excluded)
  energy_injected        passivity: the energy (J) the constraint stage adds to the user's command,
                         the sum over coupling steps of max(0, au . Fc) (METHOD.md 5.4: au . Fc =
                         -kh |ac - au|_M^2 <= 0); the device-port passivity observer is in report.md
The report also states the process's peak resident memory (ru_maxrss) after the runs and its growth
over the run, per triangle of the scene, and the force's continuity: the largest and the 99th percentile
change of the force sent between successive haptic ticks (N).
--budget-cpu S / --budget-units N run every god-object update under a budget (RuntimeSettings::budget,
docs/sim-step.md "Budgeted updates"; --budget-cpu without a value: the recommended 0.4 ms); the report
gives its statistics: the updates that ran out of it, the most in a row, the command they left to the
next updates (distance from the target: travel plus turn times the god-object's radius), the most work
units and CPU time of an update. A CPU budget's cut points depend on the machine's speed and load: such
a lockstep run is not repeatable, and is run once (no least-of-repeats); a work-unit budget is.
"""
from __future__ import annotations

import json
import os
import resource
import warnings
from pathlib import Path

import numpy as np

from . import paths
from .exact_checks import distinct_poses, progress_bar
from .machine import machine_line

LOCKSTEP_RUNS = 5  # lockstep runs of a scene: the first is the trace; all give each step's least time
UPDATE_BUDGET_MS = 1.0  # a 1 kHz sim loop's period: the report counts the updates over it
COMMON_KEYS = ["force_time_us", "update_time_ms", "update_cpu_time_ms", "constraint_update_hz", "max_contacts",
               "penetrating_poses", "max_rel_force_dot_ac", "energy_injected"]


def _stats3(values: np.ndarray, scale: float) -> dict:
    v = np.asarray(values, dtype=float) * scale
    if v.size == 0:
        return {"median": None, "p99": None, "max": None}
    return {"median": float(np.median(v)), "p99": float(np.percentile(v, 99)), "max": float(v.max())}


def script_path(script: str) -> Path:
    """--script NAME|FILE: a JSON file (a path that exists, or any path ending in .json), else the name of
    a shipped script (datasets_generated/scripts/NAME.json). ValueError naming the problem."""
    path = Path(script)
    if path.suffix == ".json" or path.exists():
        if not path.is_file():
            raise ValueError(f"{script}: no such hand script file")
        if path.suffix != ".json":
            raise ValueError(f"{script}: a hand script file is JSON and its name ends in .json")
        return path.resolve()
    shipped = paths.DATASETS_DIR / "scripts" / f"{script}.json"
    if not shipped.is_file():
        names = sorted(p.stem for p in (paths.DATASETS_DIR / "scripts").glob("*.json"))
        raise ValueError(f"{script}: neither a .json file nor a shipped hand script ({', '.join(names)})")
    return shipped


def update_rate(trace, threaded: bool) -> dict:
    steps = trace.steps
    if len(steps) < 2:
        return {"min": None, "mean": None}
    if threaded:
        dt = np.diff(steps["t"])
        return {"min": float(1 / dt.max()), "mean": float((len(steps) - 1) / (steps["t"][-1] - steps["t"][0]))}
    u = steps["update_time"]
    return {"min": float(1 / u.max()), "mean": float(1 / u.mean())}


def summarize(trace, run: dict, penetrating: int, threaded: bool) -> tuple[dict, dict]:
    """The summary entry of one run (exactly COMMON_KEYS) and extra details for the report."""
    ticks, steps = trace.ticks, trace.steps
    s = {
        "force_time_us": _stats3(ticks["force_time"], 1e6),
        "update_time_ms": _stats3(steps["update_time"], 1e3),
        "update_cpu_time_ms": _stats3(steps["update_cpu_time"], 1e3),
        "constraint_update_hz": update_rate(trace, threaded),
        "max_contacts": int(steps["num_contacts"].max()) if len(steps) else 0,
        "penetrating_poses": int(penetrating),
        "max_rel_force_dot_ac": float(run["max_rel_force_dot_ac"]),
        "energy_injected": float(run["constraint_energy_injected"]),
    }
    extra = {
        "ticks": int(len(ticks)), "sim_steps": int(len(steps)), "contact_rows": int(len(trace.contacts)),
        "run_time_s": run["run_time"], "wall_s": run["wall_seconds"],
        "orthogonality_checks": run["num_orthogonality_checks"], "offset_steps": run["num_offset_steps"],
        "constraint_energy_removed_j": run["constraint_energy_removed"],
        "port_energy_max_j": run["port_energy_max"], "port_energy_final_j": run["port_energy_final"],
        "rows_dropped": run["rows_dropped"], "events": {k: run[k]["events"] for k in ("haptic", "coupling", "sim")},
        "ticks_with_contacts": int(np.count_nonzero(ticks["num_contacts"] > 0)),
        "max_force_n": float(np.max(np.linalg.norm(ticks["wrench"][:, :3], axis=1))) if len(ticks) else 0.0,
        "let_go_time": run["let_go_time"],
        "force_jump_n": force_jumps(ticks["wrench"]),
        "budget": run["sim"]["budget"],
    }
    return s, extra


def force_jumps(wrench: np.ndarray) -> dict:
    """The force's continuity: the change of the force sent (N) between successive haptic ticks, max and p99."""
    if len(wrench) < 2:
        return {"max": 0.0, "p99": 0.0}
    jump = np.linalg.norm(np.diff(np.asarray(wrench)[:, :3], axis=0), axis=1)
    return {"max": float(jump.max()), "p99": float(np.percentile(jump, 99))}


def least_update_times(name: str, scene: Path, trace, out: Path, duration: float, lockstep_sim_period: int,
                       script: Path | None = None, progress=None, budget_units: int = 0) -> dict:
    """The lockstep run again, LOCKSTEP_RUNS - 1 times: each must repeat `trace` tick for tick (handle, god-object,
    wrench; else RuntimeError), and each step's update time (CPU and wall) is the least over the runs."""
    from ._gauss6 import runtime
    from .trace import read_trace

    cpu, wall = [trace.steps["update_cpu_time"]], [trace.steps["update_time"]]
    repeat_path = out / f".{name}.repeat.g6trace"
    try:
        for _ in range(LOCKSTEP_RUNS - 1):
            runtime.run_scenario(str(scene), str(repeat_path), threaded=False, duration=duration,
                                 lockstep_sim_period=lockstep_sim_period, script=str(script or ""),
                                 budget_units=budget_units)
            again = read_trace(repeat_path)
            for col in ("xh_p", "xh_q", "xs_p", "xs_q", "wrench"):
                if not np.array_equal(again.ticks[col], trace.ticks[col]):
                    raise RuntimeError(f"{name}: a repeat of the lockstep run differs from the first ({col})")
            cpu.append(again.steps["update_cpu_time"])
            wall.append(again.steps["update_time"])
            if progress:
                progress()
    finally:
        repeat_path.unlink(missing_ok=True)
    least_cpu = np.min(cpu, axis=0)
    return {"runs": LOCKSTEP_RUNS, "update_cpu_time_ms": _stats3(least_cpu, 1e3),
            "update_time_ms": _stats3(np.min(wall, axis=0), 1e3),
            "cpu_over_budget": int(np.count_nonzero(least_cpu * 1e3 > UPDATE_BUDGET_MS))}


def _rss_bytes() -> int:
    """The process's resident memory now (Linux /proc/self/statm; 0 elsewhere)."""
    try:
        return int(Path("/proc/self/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def run_scene(scene: Path, out: Path, name: str | None = None, title: str | None = None, script: Path | None = None,
              threaded: bool = False, duration: float = -1.0, lockstep_sim_period: int = 1,
              show_progress: bool = True, check_poses: bool = True, figure: bool = True,
              extra_json: dict | None = None, force_axes: str = "XYZ", budget_seconds: float = 0.0,
              budget_units: int = 0) -> tuple[dict, dict]:
    """Runs one scene (with `script`, a hand script file, instead of the scene's when given), writes its trace,
    certification, figure and viewer page into out; returns (summary entry: COMMON_KEYS, details).
    gauss6.LoadError for a scene or hand script that does not load (before anything runs)."""
    from ._gauss6 import runtime
    from .trace import TraceWarning, read_trace

    scene = Path(scene)
    name = name or scene.stem
    title = title or f"{name} ({scene.name})"
    rss_before = _rss_bytes()  # before the scene is first loaded
    hand = runtime.hand_script(str(scene), script=str(script or ""))  # refuses a bad script before the run
    out.mkdir(parents=True, exist_ok=True)
    trace_path = out / f"{name}.g6trace"
    total = duration if duration >= 0 else hand["end_time"]
    bar = progress_bar(total, f"{name}: {'threaded' if threaded else 'lockstep'} run", "s", show_progress)
    last = [0.0]

    def progress(t: float) -> None:
        bar.update(max(0.0, min(t, total) - last[0]))
        last[0] = max(last[0], min(t, total))

    run = runtime.run_scenario(str(scene), str(trace_path), threaded=threaded, duration=duration,
                               lockstep_sim_period=lockstep_sim_period, script=str(script or ""),
                               extra_json=json.dumps({"scenario": name, "mode": "threaded" if threaded else "lockstep",
                                                      "script": hand["origin"], **(extra_json or {})}),
                               progress=progress, budget_seconds=budget_seconds, budget_units=budget_units)
    bar.close()
    with warnings.catch_warnings():
        warnings.simplefilter("error", TraceWarning)  # the writer closed cleanly: a warning is a bug
        trace = read_trace(trace_path)
    least = None
    if not threaded and budget_seconds == 0:
        lbar = progress_bar(LOCKSTEP_RUNS - 1, f"{name}: lockstep repeats", "run", show_progress)
        least = least_update_times(name, scene, trace, out, duration, lockstep_sim_period, script,
                                   progress=lambda: lbar.update(1), budget_units=budget_units)
        lbar.close()
    memory = {"peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
              "rss_before_run_bytes": rss_before}
    penetrating, check_seconds, cert = -1, 0.0, None
    if check_poses:
        # Properties 5 and 6 on every step of the run, exactly (gauss6 certify): its pose check gives
        # penetrating_poses; certify_<name>.md/.json say what else it certified, by which path.
        from .certify import certify, write_report as write_certificate

        cbar = progress_bar(len(trace.ticks), f"{name}: certify", "tick", show_progress)
        cert = certify(scene, trace_path, progress=lambda done, total: cbar.update(done - cbar.n))
        cbar.close()
        write_certificate(cert, scene, trace_path, out, name=f"certify_{name}")
        penetrating, check_seconds = cert.num_violations["pose"], cert.seconds
        memory["peak_rss_after_certify_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    summary, extra = summarize(trace, run, penetrating, threaded)
    extra["scene"], extra["script"], extra["title"] = str(scene), hand["origin"], title
    geometry = runtime.scene_geometry(str(scene))
    extra["triangles"] = int(len(geometry["god_F"]) + sum(len(F) for _, _, F in geometry["obstacles"]))
    extra["mass_kg"], extra["coupling_stiffness_n_per_m"] = geometry["mass"], geometry["kh"] * geometry["mass"]
    extra["memory"] = memory
    extra["pose_check_s"] = check_seconds
    if least is not None:
        extra["update_least"] = least
    if cert is not None:
        first = cert.first_violation()
        extra["certify"] = {"certified": cert.passed, "poses": cert.poses, "motions": cert.motions,
                            "separations": cert.separations, "paths": dict(cert.paths),
                            "violations": dict(cert.num_violations), "seconds": cert.seconds,
                            "first_violation": None if first is None else
                            {"kind": first.kind, "tick": first.tick, "t": first.t, "detail": first.detail}}
    extra["distinct_poses"] = int(len(distinct_poses(trace)))
    extra["mode"] = "threaded" if threaded else f"lockstep (sim step every {lockstep_sim_period} tick(s))"
    if budget_seconds > 0 or budget_units > 0:
        extra["mode"] += (f"; each update's budget: {budget_seconds * 1e3:g} ms of CPU" if budget_seconds > 0 else
                          "; each update's budget:") + (f" {budget_units} work units" if budget_units > 0 else "")
    if figure:
        from .figures import plot_run
        from .view import write_view

        extra["figures"] = [p.name for p in plot_run(trace, title, out / f"figure_{name}", run["let_go_time"],
                                                      force_axes)]
        extra["figures"].append(write_view([trace_path], scene, out / f"view_{name}.html", labels=[name],
                                           title=f"gauss6: {title}").name)
    return summary, extra


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.3g}"
    return str(v)


def report_section(name: str, s: dict, d: dict, paper: dict | None = None) -> list[str]:
    """One run's part of report.md: the mode, the figure, the viewer page and the table of its numbers
    (with the paper's beside them when `paper` is given: gauss6 reproduce)."""
    title = d["title"]
    head = ["| quantity | ours | paper |", "|---|---|---|"] if paper is not None else ["| quantity | value |", "|---|---|"]
    lines = [f"## {title}", "", f"Mode: {d['mode']}; {d['ticks']} haptic ticks, {d['sim_steps']} sim "
             f"steps, {d['ticks_with_contacts']} ticks with contacts; run {d['run_time_s']:.2f} s in "
             f"{d['wall_s']:.1f} s of wall time.", "",
             f"![{title}](figure_{name}.png)", "",
             *([f"The run in 3D, with its timeline and plots: [view_{name}.html](view_{name}.html) "
                "(opens in a web browser from file://).", ""] if f"view_{name}.html" in d.get("figures", []) else []),
             *head]

    def row(quantity: str, ours: str, theirs: str = "-") -> None:
        lines.append(f"| {quantity} | {ours} |" + (f" {theirs} |" if paper is not None else ""))

    p = paper or {}
    ft, ut, hz, uc = s["force_time_us"], s["update_time_ms"], s["constraint_update_hz"], s["update_cpu_time_ms"]
    pf = p.get("force_time_us", {})
    row("force computation (us), median / p99 / max", f"{_fmt(ft['median'])} / {_fmt(ft['p99'])} / {_fmt(ft['max'])}",
        f"< {pf.get('max')} {pf.get('note', '')}")
    row("god-object update (ms), median / p99 / max", f"{_fmt(ut['median'])} / {_fmt(ut['p99'])} / {_fmt(ut['max'])}",
        f"< {p.get('update_time_ms', {}).get('max')}")
    row("god-object update, the sim thread's CPU time (ms), median / p99 / max",
        f"{_fmt(uc['median'])} / {_fmt(uc['p99'])} / {_fmt(uc['max'])}")
    if "update_least" in d:
        least = d["update_least"]
        lc, lw = least["update_cpu_time_ms"], least["update_time_ms"]
        row(f"the same, each step's least over {least['runs']} identical lockstep runs: CPU (ms) median / p99 / max; "
            f"wall", f"{_fmt(lc['median'])} / {_fmt(lc['p99'])} / {_fmt(lc['max'])}; {_fmt(lw['median'])} / "
            f"{_fmt(lw['p99'])} / {_fmt(lw['max'])}")
        if "cpu_over_budget" in least:
            row(f"updates over {UPDATE_BUDGET_MS:g} ms (least CPU time)", str(least["cpu_over_budget"]), "-")
    ph = p.get("constraint_update_hz", {})
    row("constraint updates (Hz), min / mean", f"{_fmt(hz['min'])} / {_fmt(hz['mean'])}",
        f"{ph.get('min', '-')} / {ph.get('mean', '-')}")
    row("max contacts", str(s["max_contacts"]), str(p.get("max_contacts", "-")))
    if s["penetrating_poses"] >= 0:
        row(f"penetrating poses (exact check of {d['distinct_poses']} distinct poses in {d.get('pose_check_s', 0.0):.1f} s)",
            str(s["penetrating_poses"]), "0")
    else:
        row(f"penetrating poses ({d['distinct_poses']} distinct poses)", "not checked (--no-certify)", "0")
    if "certify" in d:
        c = d["certify"]
        row(f"certified exactly ([certify_{name}.md](certify_{name}.md)): {c['poses']} poses free, {c['motions']} "
            f"motions between them free of contact, {c['separations']} separations with contacts within the bound",
            "yes" if c["certified"] else "NO")
    else:
        row("certified exactly", "not run (--no-certify)", "-")
    row(f"max abs(Fc . ac) / (abs(Fc) abs(ac)), {d['orthogonality_checks']} steps", _fmt(s["max_rel_force_dot_ac"]),
        "0 (footnote 3)")
    row("energy injected by the constraints (J); removed",
        f"{_fmt(s['energy_injected'])}; {_fmt(d['constraint_energy_removed_j'])}", "0 (footnote 4)")
    row("device-port passivity observer max(W + V) (J); final",
        f"{_fmt(d['port_energy_max_j'])}; {_fmt(d['port_energy_final_j'])}")
    row("max force (N)", _fmt(d["max_force_n"]))
    if "force_jump_n" in d:
        row("the force's change between successive haptic ticks (N), p99 / max",
            f"{_fmt(d['force_jump_n']['p99'])} / {_fmt(d['force_jump_n']['max'])}")
    b = d.get("budget")
    if b and b["max_work_units"] > 0:
        row("budgeted updates: run out of their budget; the most in a row (ms at 1 kHz); the command left "
            "to the next updates (mm, max / mean); the most work units and CPU time (ms) of an update",
            f"{b['exhausted']} of {b['updates']}; {b['longest_run']}; "
            f"{_fmt(b['deferred_max'] * 1e3)} / {_fmt(b['deferred_sum'] * 1e3 / max(b['exhausted'], 1))}; "
            f"{b['max_work_units']}, {_fmt(b['max_cpu'] * 1e3)}")
    if "mass_kg" in d:
        row("god-object mass (kg); the coupling's stiffness kh M (N/m: the force is about kh M ks times how far the "
            "hand is past the contact)", f"{_fmt(d['mass_kg'])}; {_fmt(d['coupling_stiffness_n_per_m'])}")
    if "memory" in d and "triangles" in d:
        m, n = d["memory"], d["triangles"]
        grown = m["peak_rss_bytes"] - m["rss_before_run_bytes"]
        row(f"memory: the process's peak resident (MB); its growth over the runs (MB), per triangle of the scene's {n} "
            "(bytes; a small scene's is mostly fixed costs)",
            f"{m['peak_rss_bytes'] / 2**20:.0f}; {grown / 2**20:.0f}, {grown / n:.0f}")
    return lines + [""]


def report_footer(d: dict) -> list[str]:
    return [f"Runtime events: {json.dumps(d['events'])}; trace rows dropped: {d['rows_dropped']}.", ""]


DEFINITIONS = ("Definitions: see `python/gauss6/run.py`. In lockstep runs the clock is virtual (1 kHz), "
               "work times are real; the constraint update rate is the rate a free-running sim loop would reach "
               "(1 / update time).")


def write_report(out: Path, name: str, summary: dict, details: dict, wall: float) -> Path:
    """report.md of `gauss6 run`."""
    lines = [f"# gauss6 run: {details['title']}", "", machine_line(), "",
             f"Scene `{details['scene']}`, hand script `{details['script']}`.", "",
             f"Total wall time of the runs and checks: {wall:.0f} s.", "",
             *report_section(name, summary, details), *report_footer(details), DEFINITIONS, ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def failures(name: str, summary: dict, details: dict) -> list[str]:
    """What makes a run fail, one message each: a pose that interpenetrates, a run not certified."""
    problems = []
    if summary["penetrating_poses"] > 0:
        problems.append(f"{name}: {summary['penetrating_poses']} god-object poses interpenetrate an obstacle")
    c = details.get("certify")
    if c is not None and not c["certified"]:
        problems.append(f"{name}: not certified (certify_{name}.md: {c['first_violation']})")
    return problems
