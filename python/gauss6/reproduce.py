"""The paper's scenarios, figures and numbers, as `gauss6 reproduce peg|bunny|bunny_full|surfaces|all
--out DIR [--threaded]` runs them (commands/reproduce.py; bunny_full: the full-resolution bunnies,
issue 20's third scenario, not in `all`).

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

Each scenario runs through `gauss6 run`'s path (run.py: the lockstep repeats and each step's least
time, the certification, the figure, the viewer page; its docstring defines the common numbers:
force_time_us, update_time_ms, update_cpu_time_ms, constraint_update_hz, max_contacts,
penetrating_poses, max_rel_force_dot_ac, energy_injected). The paper's scenes add:
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

import json
import time
from pathlib import Path

import numpy as np

from . import paths
# gauss6 run's path; LOCKSTEP_RUNS and least_update_times are part of this module's interface too.
from .run import (COMMON_KEYS as RUN_KEYS, DEFINITIONS, LOCKSTEP_RUNS, _fmt, failures,  # noqa: F401
                  least_update_times, machine_line, report_footer, report_section,
                  run_scene, summarize as summarize_run)

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
COMMON_KEYS = RUN_KEYS + ["paper"]
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

# Peg scene geometry used by the let-go check (datasets_generated/scenes/peg_in_hole.toml):
# the hole's axis is the Y axis, the box spans |y| <= 3 cm.
HOLE_AXIS_TOLERANCE = 5e-4   # m: the peg's centre within this of the axis (clearance is about 0.2 mm)
BOX_HALF_LENGTH = 0.03       # m
SETTLE_TIME = 0.5            # s after the let-go before the drift and force are measured
MAX_DRIFT = 1e-3             # m
MAX_FINAL_FORCE = 0.05       # N


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


def scenario_checks(name: str, trace, let_go_time: float) -> tuple[dict, dict]:
    """The paper's figures and the scenario's own checks: (summary entries, report details). The peg: the force
    Y outside and inside phases (c), (d), the let-go, per phase contacts and forces."""
    s, extra = {"paper": PAPER[name]}, {}
    if name != "peg":
        return s, extra
    ticks = trace.ticks
    phases = [(p["name"], float(p["start"])) for p in trace.meta.get("phases", [])]
    fy = ticks["wrench"][:, 1]
    in_cd = _phase_mask(ticks["t"], phases, {"c", "d"})
    in_c = _phase_mask(ticks["t"], phases, {"c"})
    s["max_abs_fy_outside_cd"] = float(np.abs(fy[~in_cd]).max()) if np.any(~in_cd) else 0.0
    s["max_fy_in_c"] = float(fy[in_c].max()) if np.any(in_c) else 0.0
    extra["min_fy_in_c"] = float(fy[in_c].min()) if np.any(in_c) else 0.0
    ok, details = let_go_stable(trace, let_go_time)
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
    return s, extra


def _check_keys(name: str, s: dict) -> None:
    if sorted(s) != SUMMARY_KEYS[name]:
        raise RuntimeError(f"{name}: summary keys {sorted(s)} differ from {SUMMARY_KEYS[name]}")


def summarize(name: str, trace, run: dict, penetrating: int, threaded: bool) -> tuple[dict, dict]:
    """The summary.json entry of one scenario (exactly SUMMARY_KEYS[name]) and extra details for the report."""
    s, extra = summarize_run(trace, run, penetrating, threaded)
    more, more_extra = scenario_checks(name, trace, run["let_go_time"])
    s, extra = {**s, **more}, {**extra, **more_extra}
    _check_keys(name, s)
    return s, extra


def run_scenario(name: str, out: Path, threaded: bool = False, duration: float = -1.0,
                 lockstep_sim_period: int = 1, show_progress: bool = True, check_poses: bool = True,
                 figure: bool = True, budget_seconds: float = 0.0, budget_units: int = 0) -> tuple[dict, dict]:
    """Runs one scenario through `gauss6 run`'s path (run.run_scene: the trace, the lockstep repeats, the
    certification, the figure, the viewer page, in out); returns (summary entry, details) with the paper's
    figures and the scenario's own checks (scenario_checks)."""
    from .trace import read_trace

    s, extra = run_scene(SCENES[name], out, name=name, title=TITLES[name], threaded=threaded, duration=duration,
                         lockstep_sim_period=lockstep_sim_period, show_progress=show_progress,
                         check_poses=check_poses, figure=figure, force_axes="YZ",  # the paper's figures' rows
                         budget_seconds=budget_seconds, budget_units=budget_units)
    more, more_extra = scenario_checks(name, read_trace(out / f"{name}.g6trace"), extra["let_go_time"])
    s, extra = {**s, **more}, {**extra, **more_extra}
    _check_keys(name, s)
    return s, extra


def write_report(out: Path, summary: dict, details: dict, wall: float, surfaces: dict | None = None) -> Path:
    lines = ["# gauss6: the paper's scenarios reproduced", "",
             f"{machine_line()} The paper's: {PAPER['peg']['machine']}.", "",
             f"Total wall time of the runs and checks: {wall:.0f} s.", ""]
    for name in summary:
        s, d = summary[name], details[name]
        section = report_section(name, s, {"title": TITLES[name], **d}, paper=PAPER[name])
        if name == "peg":
            section.pop()  # the peg's rows join the table
            section.append(f"| max abs(force Y) outside phases c, d (N) | {_fmt(s['max_abs_fy_outside_cd'])} | 0 |")
            section.append(f"| max force Y in phase c (N); min | {_fmt(s['max_fy_in_c'])}; {_fmt(d['min_fy_in_c'])} "
                           f"| never positive |")
            section.append(f"| stable after let-go in the hole | {_fmt(s['let_go_stable'])} | yes |")
            section += ["", "Per phase: ticks with contacts, max abs(force Y), force Z range (N):", ""]
            for ph in "abcde":
                e = d[f"phase_{ph}"]
                section.append(f"- ({ph}): {e['ticks_with_contacts']} ticks, {e['max_abs_fy']:.3g}, "
                               f"[{e['min_fz']:.3g}, {e['max_fz']:.3g}]")
            section += ["", f"Let-go details: {json.dumps(d['let_go'])}", ""]
        lines += section + report_footer(d)
    lines += [DEFINITIONS, ""]
    if surfaces is not None:
        from .reproduce_surfaces import report_lines

        lines += report_lines(surfaces)
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def reproduce(which: str, out: Path, threaded: bool = False, show_progress: bool = True,
              budget_seconds: float = 0.0, budget_units: int = 0) -> dict:
    """Runs 'peg', 'bunny' or 'all'; writes the traces, figures, summary.json and report.md."""
    start = time.monotonic()
    names = ["peg", "bunny"] if which == "all" else ([] if which == "surfaces" else [which])
    out.mkdir(parents=True, exist_ok=True)
    summary, details = {}, {}
    for name in names:
        summary[name], details[name] = run_scenario(name, out, threaded=threaded, show_progress=show_progress,
                                                    budget_seconds=budget_seconds, budget_units=budget_units)
    surfaces = None
    if which in ("all", "surfaces"):
        from .reproduce_surfaces import reproduce_surfaces

        surfaces, _ = reproduce_surfaces(out, show_progress=show_progress)
    full = {**summary, **({"surfaces": surfaces} if surfaces is not None else {})}
    (out / "summary.json").write_text(json.dumps(full, indent=2) + "\n")
    (out / "details.json").write_text(json.dumps(details, indent=2) + "\n")
    write_report(out, summary, details, time.monotonic() - start, surfaces)
    return full
