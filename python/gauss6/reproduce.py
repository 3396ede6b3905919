"""`gauss6 reproduce peg|bunny|bunny_full|surfaces|all --out DIR [--threaded]`: the paper's scenarios, figures and numbers
(bunny_full: the full-resolution bunnies, issue 20's third scenario, not in `all`).

Also the `gauss6 trace export|import` commands (CSV and HAPI device logs: gauss6.logs).

Each scenario (METHOD.md section 7) runs its scene with the simulated device following the
scene's hand script (datasets_generated/scripts/), through the runtime's three loops
(lockstep by default: a virtual 1 kHz clock, repeatable bit for bit; --threaded: real
threads and the wall clock), and writes into DIR:

    <name>.g6trace           the run's trace (docs/trace-format.md)
    figure_<name>.png/.svg   the Figure 11 (peg) / Figure 12 (bunny) analogue
    view_<name>.html         the run in 3D with its timeline and plots (gauss6 view; opens from file://)
    summary.json             per scenario, exactly the keys of SUMMARY_KEYS; "surfaces": the Figure 8 and 9
                             analogues' numbers (reproduce_surfaces.py, which defines them; lockstep only)
    figure_shading.*, figure_texture.*   the Figure 8 / Figure 9 analogues
    report.md                our numbers beside the paper's, the figures, the machine

Definitions of the summary's numbers:
  force_time_us          per haptic tick, the coupling step's wall time (us): median, p99, max
  update_time_ms         per sim step, the god-object update's wall time (ms): median, p99, max
  update_cpu_time_ms     per sim step, the sim thread's CPU time in the update (ms; CLOCK_THREAD_CPUTIME_ID:
                         without the time the thread was preempted, which on a loaded machine is most of
                         a wall-clock p99 or max): median, p99, max. Lockstep runs are run LOCKSTEP_RUNS
                         times (each repeat must be the first run tick for tick, or reproduce fails) and
                         report.md gives beside it each step's least time over them (the benchmarks'
                         method: the machine's noise, not the step, sets a single run's max)
  constraint_update_hz   the rate of new constraint sets. Lockstep: the rate a free-running sim loop
                         would reach, min = 1 / max update time, mean = 1 / mean update time.
                         Threaded: from the steps' start times, min = 1 / max period, mean = steps / time
  max_contacts           the largest contact set of a sim step
  penetrating_poses      god-object poses (every distinct xs of the trace's ticks: in lockstep runs every
                         pose the sim loop took; in --threaded runs the poses the haptic loop saw) at
                         which the exact check finds an intersecting triangle pair: must be 0. The
                         check is `gauss6 certify`'s (certify.py), which also certifies the motion between
                         successive poses and the separations at the poses with contacts (properties 5
                         and 6), written to certify_<name>.md/.json; a run it does not certify fails
  max_abs_fy_outside_cd  peg: max |force Y| (N) over ticks outside phases (c) and (d)
  max_fy_in_c            peg: max force Y (N) during phase (c): the paper's is never positive
  max_rel_force_dot_ac   per coupling step, |Fc . ac| / (|Fc| |ac|) (max; steps with a running offset excluded)
  energy_injected        passivity: the energy (J) the constraint stage adds to the user's command,
                         the sum over coupling steps of max(0, au . Fc) (METHOD.md 5.4: au . Fc =
                         -kh |ac - au|_M^2 <= 0); the device-port passivity observer is in report.md
  let_go_stable          peg: after the let-go the peg stays in the hole (axis within 0.5 mm, centre
                         inside the box), moves less than 1 mm after 0.5 s, the force dies out below
                         0.05 N, and no watchdog fires
  paper                  the paper's figures for the same quantities (METHOD.md section 7)
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from . import paths
from .exact_checks import distinct_poses, progress_bar

SCENES = {
    "peg": paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml",
    "bunny": paths.DATASETS_DIR / "scenes" / "bunnies.toml",
    "bunny_full": paths.DATASETS_DIR / "scenes" / "bunnies_full.toml",  # not in `all`: its own command
}
TITLES = {
    "peg": "Peg in a hole (Figure 11 analogue)",
    "bunny": "Two bunnies (Figure 12 analogue)",
    "bunny_full": "Two full-resolution bunnies (69,664 triangles each; the bunny script)",
}
COMMON_KEYS = ["force_time_us", "update_time_ms", "update_cpu_time_ms", "constraint_update_hz", "max_contacts", "penetrating_poses",
               "max_rel_force_dot_ac", "energy_injected", "paper"]
PEG_KEYS = ["max_abs_fy_outside_cd", "max_fy_in_c", "let_go_stable"]
SUMMARY_KEYS = {"peg": sorted(COMMON_KEYS + PEG_KEYS), "bunny": sorted(COMMON_KEYS),
                "bunny_full": sorted(COMMON_KEYS)}

# The paper's figures (METHOD.md section 7): bounds read off Figures 11 and 12 and the text.
PAPER = {
    "peg": {
        "force_time_us": {"max": 25.0},
        "update_time_ms": {"max": 10.0},
        "max_contacts": "few",
        "force_y": "non-zero only in phases c and d, never positive in c",
        "force_z": "high when pushing on the top; small variations in the hole",
        "let_go_stable": True,
        "machine": "3.2 GHz dual-processor Xeon (2007), SPIDAR-G at 1 kHz",
    },
    "bunny": {
        "force_time_us": {"max": 12.5, "note": "force in a few microseconds (> 80,000 Hz)"},
        "update_time_ms": {"max": 15.0},
        "constraint_update_hz": {"min": 70.0, "mean": 300.0},
        "machine": "3.2 GHz dual-processor Xeon (2007), SPIDAR-G at 1 kHz",
    },
    # Not in the paper: issue 20's floors (update p99 <= 0.3 ms, max under 1 ms) as the bounds.
    "bunny_full": {
        "update_time_ms": {"max": 1.0},
        "machine": "issue 20's floor, not the paper",
    },
}

LOCKSTEP_RUNS = 5  # lockstep runs of each scenario: the first is the trace; all give each step's least time

# Peg scene geometry used by the let-go check (datasets_generated/scenes/peg_in_hole.toml):
# the hole's axis is the Y axis, the box spans |y| <= 3 cm.
HOLE_AXIS_TOLERANCE = 5e-4   # m: the peg's centre within this of the axis (clearance is about 0.2 mm)
BOX_HALF_LENGTH = 0.03       # m
SETTLE_TIME = 0.5            # s after the let-go before the drift and force are measured
MAX_DRIFT = 1e-3             # m
MAX_FINAL_FORCE = 0.05       # N


def _stats3(values: np.ndarray, scale: float) -> dict:
    v = np.asarray(values, dtype=float) * scale
    if v.size == 0:
        return {"median": None, "p99": None, "max": None}
    return {"median": float(np.median(v)), "p99": float(np.percentile(v, 99)), "max": float(v.max())}


def _phase_mask(t: np.ndarray, phases: list, names: set) -> np.ndarray:
    mask = np.zeros(t.shape, dtype=bool)
    for i, (name, start) in enumerate(phases):
        end = phases[i + 1][1] if i + 1 < len(phases) else np.inf
        if name in names:
            mask |= (t >= start) & (t < end)
    return mask


def let_go_stable(trace, let_go_time: float) -> tuple[bool, dict]:
    """The peg after the let-go: in the hole, settled, force gone, no watchdog. Returns (ok, details)."""
    ticks = trace.ticks
    after = ticks[ticks["t"] >= let_go_time]
    settled = after[after["t"] >= let_go_time + SETTLE_TIME]
    if len(settled) == 0:
        return False, {"reason": "the run ends before the peg could settle"}
    p = after["xs_p"]
    off_axis = float(np.max(np.hypot(p[:, 0], p[:, 2])))
    inside = bool(np.all(np.abs(p[:, 1]) <= BOX_HALF_LENGTH))
    drift = float(np.max(np.linalg.norm(settled["xs_p"] - settled["xs_p"][0], axis=1)))
    final_force = float(np.max(np.linalg.norm(settled["wrench"][-min(len(settled), 500):, :3], axis=1)))
    watchdog = bool(np.any(after["flags"].astype(np.int64) & 8))
    gripped = bool(np.any(settled["flags"].astype(np.int64) & 1))
    ok = (off_axis <= HOLE_AXIS_TOLERANCE and inside and drift <= MAX_DRIFT and final_force <= MAX_FINAL_FORCE
          and not watchdog and not gripped)
    return ok, {"max_off_axis_m": off_axis, "centre_inside_box": inside, "drift_after_settle_m": drift,
                "final_force_n": final_force, "watchdog": watchdog, "still_gripped": gripped}


def update_rate(trace, threaded: bool) -> dict:
    steps = trace.steps
    if len(steps) < 2:
        return {"min": None, "mean": None}
    if threaded:
        dt = np.diff(steps["t"])
        return {"min": float(1 / dt.max()), "mean": float((len(steps) - 1) / (steps["t"][-1] - steps["t"][0]))}
    u = steps["update_time"]
    return {"min": float(1 / u.max()), "mean": float(1 / u.mean())}


def summarize(name: str, trace, run: dict, penetrating: int, threaded: bool) -> tuple[dict, dict]:
    """The summary.json entry of one scenario (exactly SUMMARY_KEYS[name]) and extra details for the report."""
    ticks, steps = trace.ticks, trace.steps
    phases = [(p["name"], float(p["start"])) for p in trace.meta.get("phases", [])]
    s = {
        "force_time_us": _stats3(ticks["force_time"], 1e6),
        "update_time_ms": _stats3(steps["update_time"], 1e3),
        "update_cpu_time_ms": _stats3(steps["update_cpu_time"], 1e3),
        "constraint_update_hz": update_rate(trace, threaded),
        "max_contacts": int(steps["num_contacts"].max()) if len(steps) else 0,
        "penetrating_poses": int(penetrating),
        "max_rel_force_dot_ac": float(run["max_rel_force_dot_ac"]),
        "energy_injected": float(run["constraint_energy_injected"]),
        "paper": PAPER[name],
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
    }
    fy = ticks["wrench"][:, 1]
    if name == "peg":
        in_cd = _phase_mask(ticks["t"], phases, {"c", "d"})
        in_c = _phase_mask(ticks["t"], phases, {"c"})
        s["max_abs_fy_outside_cd"] = float(np.abs(fy[~in_cd]).max()) if np.any(~in_cd) else 0.0
        s["max_fy_in_c"] = float(fy[in_c].max()) if np.any(in_c) else 0.0
        extra["min_fy_in_c"] = float(fy[in_c].min()) if np.any(in_c) else 0.0
        ok, details = let_go_stable(trace, run["let_go_time"])
        s["let_go_stable"] = ok
        extra["let_go"] = details
        for ph in "abcde":
            m = _phase_mask(ticks["t"], phases, {ph})
            extra[f"phase_{ph}"] = {
                "ticks_with_contacts": int(np.count_nonzero(ticks["num_contacts"][m] > 0)),
                "max_abs_fy": float(np.abs(fy[m]).max()) if np.any(m) else 0.0,
                "max_fz": float(ticks["wrench"][m, 2].max()) if np.any(m) else 0.0,
                "min_fz": float(ticks["wrench"][m, 2].min()) if np.any(m) else 0.0,
            }
    if sorted(s) != SUMMARY_KEYS[name]:
        raise RuntimeError(f"{name}: summary keys {sorted(s)} differ from {SUMMARY_KEYS[name]}")
    return s, extra


def least_update_times(name: str, scene: Path, trace, out: Path, duration: float, lockstep_sim_period: int) -> dict:
    """The lockstep run again, LOCKSTEP_RUNS - 1 times: each must repeat `trace` tick for tick (handle, god-object,
    wrench; else RuntimeError), and each step's update time (CPU and wall) is the least over the runs."""
    from ._gauss6 import runtime
    from .trace import read_trace

    cpu, wall = [trace.steps["update_cpu_time"]], [trace.steps["update_time"]]
    repeat_path = out / f".{name}.repeat.g6trace"
    try:
        for _ in range(LOCKSTEP_RUNS - 1):
            runtime.run_scenario(str(scene), str(repeat_path), threaded=False, duration=duration,
                                 lockstep_sim_period=lockstep_sim_period)
            again = read_trace(repeat_path)
            for col in ("xh_p", "xh_q", "xs_p", "xs_q", "wrench"):
                if not np.array_equal(again.ticks[col], trace.ticks[col]):
                    raise RuntimeError(f"{name}: a repeat of the lockstep run differs from the first ({col})")
            cpu.append(again.steps["update_cpu_time"])
            wall.append(again.steps["update_time"])
    finally:
        repeat_path.unlink(missing_ok=True)
    return {"runs": LOCKSTEP_RUNS, "update_cpu_time_ms": _stats3(np.min(cpu, axis=0), 1e3),
            "update_time_ms": _stats3(np.min(wall, axis=0), 1e3)}


def run_scenario(name: str, out: Path, threaded: bool = False, duration: float = -1.0,
                 lockstep_sim_period: int = 1, show_progress: bool = True, check_poses: bool = True,
                 figure: bool = True) -> tuple[dict, dict]:
    """Runs one scenario, writes its trace and figure into out; returns (summary entry, details)."""
    from ._gauss6 import runtime
    from .trace import TraceWarning, read_trace

    scene = SCENES[name]
    out.mkdir(parents=True, exist_ok=True)
    trace_path = out / f"{name}.g6trace"
    end = json.loads((paths.DATASETS_DIR / "scripts" / ("peg_in_hole.json" if name == "peg" else "bunny.json"))
                     .read_text())["end_time"]
    total = duration if duration >= 0 else end
    bar = progress_bar(total, f"{name}: {'threaded' if threaded else 'lockstep'} run", "s", show_progress)
    last = [0.0]

    def progress(t: float) -> None:
        bar.update(max(0.0, min(t, total) - last[0]))
        last[0] = max(last[0], min(t, total))

    run = runtime.run_scenario(str(scene), str(trace_path), threaded=threaded, duration=duration,
                               lockstep_sim_period=lockstep_sim_period,
                               extra_json=json.dumps({"scenario": name, "mode": "threaded" if threaded else "lockstep"}),
                               progress=progress)
    bar.close()
    with warnings.catch_warnings():
        warnings.simplefilter("error", TraceWarning)  # the writer closed cleanly: a warning is a bug
        trace = read_trace(trace_path)
    least = None if threaded else least_update_times(name, scene, trace, out, duration, lockstep_sim_period)
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
    summary, extra = summarize(name, trace, run, penetrating, threaded)
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
    if figure:
        from .figures import plot_run

        extra["figures"] = [p.name for p in plot_run(trace, TITLES[name], out / f"figure_{name}",
                                                      run["let_go_time"])]
        from .view import write_view

        extra["figures"].append(write_view([trace_path], scene, out / f"view_{name}.html", labels=[name],
                                           title=f"gauss6: {TITLES[name]}").name)
    return summary, extra


def machine() -> dict:
    """CPU model and core count from /proc/cpuinfo (Linux), with the Python platform as fallback."""
    model, cores = platform.processor() or platform.machine(), os.cpu_count()
    try:
        info = Path("/proc/cpuinfo").read_text()
        models = [line.split(":", 1)[1].strip() for line in info.splitlines() if line.startswith("model name")]
        if models:
            model, cores = models[0], len(models)
    except OSError:
        pass
    return {"cpu": model, "cores": cores, "system": f"{platform.system()} {platform.release()}",
            "python": platform.python_version()}


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.3g}"
    return str(v)


def write_report(out: Path, summary: dict, details: dict, wall: float, surfaces: dict | None = None) -> Path:
    m = machine()
    lines = ["# gauss6: the paper's scenarios reproduced", "",
             f"Machine: {m['cpu']}, {m['cores']} cores ({m['system']}, Python {m['python']}). "
             f"The paper's: {PAPER['peg']['machine']}.", "",
             f"Total wall time of the runs and checks: {wall:.0f} s.", ""]
    for name in summary:
        s, d, p = summary[name], details[name], PAPER[name]
        lines += [f"## {TITLES[name]}", "", f"Mode: {d['mode']}; {d['ticks']} haptic ticks, {d['sim_steps']} sim "
                  f"steps, {d['ticks_with_contacts']} ticks with contacts; run {d['run_time_s']:.2f} s in "
                  f"{d['wall_s']:.1f} s of wall time.", "",
                  f"![{TITLES[name]}](figure_{name}.png)", "",
                  *([f"The run in 3D, with its timeline and plots: [view_{name}.html](view_{name}.html) "
                     "(opens in a web browser from file://).", ""] if f"view_{name}.html" in d.get("figures", []) else []),
                  "| quantity | ours | paper |", "|---|---|---|"]
        ft, ut, hz = s["force_time_us"], s["update_time_ms"], s["constraint_update_hz"]
        pf = p.get("force_time_us", {})
        lines.append(f"| force computation (us), median / p99 / max | {_fmt(ft['median'])} / {_fmt(ft['p99'])} / "
                     f"{_fmt(ft['max'])} | < {pf.get('max')} {pf.get('note', '')} |")
        lines.append(f"| god-object update (ms), median / p99 / max | {_fmt(ut['median'])} / {_fmt(ut['p99'])} / "
                     f"{_fmt(ut['max'])} | < {p['update_time_ms']['max']} |")
        uc = s["update_cpu_time_ms"]
        lines.append(f"| god-object update, the sim thread's CPU time (ms), median / p99 / max | "
                     f"{_fmt(uc['median'])} / {_fmt(uc['p99'])} / {_fmt(uc['max'])} | - |")
        if "update_least" in d:
            lc, lw = d["update_least"]["update_cpu_time_ms"], d["update_least"]["update_time_ms"]
            lines.append(f"| the same, each step's least over {d['update_least']['runs']} identical lockstep runs: "
                         f"CPU (ms) median / p99 / max; wall | {_fmt(lc['median'])} / {_fmt(lc['p99'])} / "
                         f"{_fmt(lc['max'])}; {_fmt(lw['median'])} / {_fmt(lw['p99'])} / {_fmt(lw['max'])} | - |")
        ph = p.get("constraint_update_hz", {})
        lines.append(f"| constraint updates (Hz), min / mean | {_fmt(hz['min'])} / {_fmt(hz['mean'])} | "
                     f"{ph.get('min', '-')} / {ph.get('mean', '-')} |")
        lines.append(f"| max contacts | {s['max_contacts']} | {p.get('max_contacts', '-')} |")
        lines.append(f"| penetrating poses (exact check of {d['distinct_poses']} distinct poses in "
                     f"{d.get('pose_check_s', 0.0):.1f} s) | {s['penetrating_poses']} | 0 |")
        if "certify" in d:
            c = d["certify"]
            lines.append(f"| certified exactly ([certify_{name}.md](certify_{name}.md)): {c['poses']} poses free, "
                         f"{c['motions']} motions between them free of contact, {c['separations']} separations "
                         f"with contacts within the bound | {'yes' if c['certified'] else 'NO'} | - |")
        lines.append(f"| max abs(Fc . ac) / (abs(Fc) abs(ac)), {d['orthogonality_checks']} steps | "
                     f"{_fmt(s['max_rel_force_dot_ac'])} | 0 (footnote 3) |")
        lines.append(f"| energy injected by the constraints (J); removed | {_fmt(s['energy_injected'])}; "
                     f"{_fmt(d['constraint_energy_removed_j'])} | 0 (footnote 4) |")
        lines.append(f"| device-port passivity observer max(W + V) (J); final | {_fmt(d['port_energy_max_j'])}; "
                     f"{_fmt(d['port_energy_final_j'])} | - |")
        if name == "peg":
            lines.append(f"| max abs(force Y) outside phases c, d (N) | {_fmt(s['max_abs_fy_outside_cd'])} | 0 |")
            lines.append(f"| max force Y in phase c (N); min | {_fmt(s['max_fy_in_c'])}; {_fmt(d['min_fy_in_c'])} "
                         f"| never positive |")
            lines.append(f"| stable after let-go in the hole | {_fmt(s['let_go_stable'])} | yes |")
        lines.append("")
        if name == "peg":
            lines += ["Per phase: ticks with contacts, max abs(force Y), force Z range (N):", ""]
            for ph in "abcde":
                e = d[f"phase_{ph}"]
                lines.append(f"- ({ph}): {e['ticks_with_contacts']} ticks, {e['max_abs_fy']:.3g}, "
                             f"[{e['min_fz']:.3g}, {e['max_fz']:.3g}]")
            lines += ["", f"Let-go details: {json.dumps(d['let_go'])}", ""]
        lines += [f"Runtime events: {json.dumps(d['events'])}; trace rows dropped: {d['rows_dropped']}.", ""]
    lines += ["Definitions: see `python/gauss6/reproduce.py`. In lockstep runs the clock is virtual (1 kHz), "
              "work times are real; the constraint update rate is the rate a free-running sim loop would reach "
              "(1 / update time).", ""]
    if surfaces is not None:
        from .reproduce_surfaces import report_lines

        lines += report_lines(surfaces)
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def reproduce(which: str, out: Path, threaded: bool = False, show_progress: bool = True) -> dict:
    """Runs 'peg', 'bunny' or 'all'; writes the traces, figures, summary.json and report.md."""
    start = time.monotonic()
    names = ["peg", "bunny"] if which == "all" else ([] if which == "surfaces" else [which])
    out.mkdir(parents=True, exist_ok=True)
    summary, details = {}, {}
    for name in names:
        summary[name], details[name] = run_scenario(name, out, threaded=threaded, show_progress=show_progress)
    surfaces = None
    if which in ("all", "surfaces"):
        from .reproduce_surfaces import reproduce_surfaces

        surfaces, _ = reproduce_surfaces(out, show_progress=show_progress)
    full = {**summary, **({"surfaces": surfaces} if surfaces is not None else {})}
    (out / "summary.json").write_text(json.dumps(full, indent=2) + "\n")
    (out / "details.json").write_text(json.dumps(details, indent=2) + "\n")
    write_report(out, summary, details, time.monotonic() - start, surfaces)
    return full


def cmd_reproduce(args: argparse.Namespace) -> int:
    if args.scenario == "engines":
        from .reproduce_engines import cmd

        return cmd(args)
    summary = reproduce(args.scenario, Path(args.out), threaded=args.threaded, show_progress=not args.quiet)
    print(json.dumps(summary, indent=2))
    failed = [n for n, s in summary.items() if n != "surfaces" and s["penetrating_poses"] != 0]
    details = json.loads((Path(args.out) / "details.json").read_text())
    uncertified = [n for n, d in details.items() if not d.get("certify", {}).get("certified", True)]
    for n in uncertified:
        print(f"gauss6: error: {n}: not certified (certify_{n}.md: {details[n]['certify']['first_violation']})",
              file=sys.stderr)
    failed += [n for n in uncertified if n not in failed]
    for kind, runs in summary.get("surfaces", {}).items():
        # Property 7 at its stated tolerance (runtime_events.h), plain runs included.
        failed += [f"{kind}/{label}" for label, s in runs.items()
                   if s["penetrating_poses"] != 0 or not s["max_rel_constraint_violation"] <= 1e-9]
    for n in failed:
        print(f"gauss6: error: {n}: god-object poses interpenetrate or violate the true constraints "
              "(property 7)", file=sys.stderr)
    print(f"written to {args.out}/ (summary.json, report.md, figures, traces)")
    return 1 if failed else 0


def cmd_trace_export(args: argparse.Namespace) -> int:
    from . import LoadError
    from .logs import export_trace

    if not (args.csv or args.hapi):
        print("gauss6: error: trace export: give --csv DIR and/or --hapi FILE", file=sys.stderr)
        return 2
    try:
        print(export_trace(args.trace, hapi=args.hapi, csv=args.csv))
    except (LoadError, ValueError, OSError) as e:
        print(f"gauss6: error: {e}", file=sys.stderr)
        return 2
    return 0


def cmd_trace_import(args: argparse.Namespace) -> int:
    from . import LoadError
    from .logs import import_log

    try:
        out, tr = import_log(args.file, args.format, args.out, scene=args.scene or "")
    except (LoadError, ValueError, OSError) as e:
        print(f"gauss6: error: {e}", file=sys.stderr)
        return 2
    print(f"{args.file}: {len(tr.ticks)} ticks ({args.format}), {tr.ticks['t'][0]:g} to {tr.ticks['t'][-1]:g} s "
          f"-> {out} (a trace the replay device plays back)")
    return 0


def register(subparsers) -> None:
    """Adds `reproduce` and `trace export` to the gauss6 command's subparsers."""
    rep = subparsers.add_parser("reproduce", help="run the paper's scenarios and write figures and summaries")
    rep.add_argument("scenario", choices=["peg", "bunny", "bunny_full", "surfaces", "all", "engines"],
                     help="all: peg, bunny and surfaces; bunny_full (the full-resolution bunnies) and engines (gauss6, MuJoCo, "
                          "PyBullet, Drake side by side: reproduce_engines.py) run alone")
    from .cli import input_file, output_dir, output_file, run_seconds

    rep.add_argument("--out", required=True, type=output_dir, help="output directory")
    rep.add_argument("--threaded", action="store_true", help="real threads and the wall clock (default: lockstep)")
    rep.add_argument("--quiet", action="store_true", help="no progress bars")
    rep.add_argument("--slice", type=run_seconds, default=None,
                     help="engines: run only the first S seconds of each script (default: whole)")
    rep.set_defaults(func=cmd_reproduce)
    tr = subparsers.add_parser("trace", help="run traces").add_subparsers(dest="action", required=True)
    ex = tr.add_parser("export", help="write a trace as CSV files (one per stream) and/or a HAPI device log")
    ex.add_argument("trace", type=input_file("trace"), help="trace file (.g6trace)")
    ex.add_argument("--csv", type=output_dir,
                    help="output directory (ticks.csv, steps.csv, contacts.csv, events.csv, meta.json)")
    ex.add_argument("--hapi", type=output_file,
                    help="output HAPI DeviceLog, ASCII (TIME POSITION ORIENTATION FORCE TORQUE BUTTONS)")
    ex.set_defaults(func=cmd_trace_export)
    im = tr.add_parser("import", help="a HAPI device log or CSV recorded elsewhere -> a trace for replay")
    im.add_argument("file", type=input_file("log", directory_ok=True), help="HAPI DeviceLog (ASCII), or a CSV directory (to_csv's files) or ticks CSV")
    im.add_argument("--format", required=True, choices=["hapi", "csv"])
    im.add_argument("--out", required=True, type=output_file, help="the trace to write (.g6trace)")
    im.add_argument("--scene", help="scene name to record in the trace's metadata (for gauss6 view)")
    im.set_defaults(func=cmd_trace_import)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m gauss6.reproduce", description=__doc__.splitlines()[0])
    register(p.add_subparsers(dest="command", required=True))
    args = p.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
