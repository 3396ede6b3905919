"""`gauss6 sweep`: speed against error for each accuracy knob, as Pareto fronts.

    gauss6 sweep [--out out/bench/sweeps] [--build DIR] [--knob NAME ...] [--quick]

Knobs, each swept with the others at their defaults, on the same data for speed
and error, the error measured against the exact reference (reference/):

  projection_feasibility_tol, projection_dependence_tol (ProjectionSettings,
      quasistatics.h): error |ac - ac*|_M / |au|_M against the exact optimum
      (crosscheck_qp.certified_optimum), on the well-posed instances of the
      families of report_qp.FAMILIES; speed: the ProjectionSweep benchmarks
      (cold solves over the same instances, benchmarks/bench_projection_sweep.cpp).
      Peers on the same plot: OSQP, DAQP, quadprog, CGAL (report_qp.SOLVERS).
  ccd_time_tolerance (CcdSettings::time_tolerance, ccd.h): error u* - u_hit (motion
      parameter) against the exact first contact (mesh_first_contact), over the
      steps of CCD_SETS where both hit; speed: ccd_step per step, native (fastest
      of 3). Peer: FCL (crosscheck_ccd.FclPeer) on the steps whose motion it shares.
  separation_delta (CcdSettings::min_separation, as a multiple of the set's delta):
      error: the exact separation at the stop pose (scene units: the force at a
      distance of METHOD.md property 6); speed: ccd_step per step.
  bvh_leaf_size (build_bvh): speed: the CcdStepLeafSize benchmarks over the same
      sets; error: the exact gap at the default leaf size plus the largest change
      of u_hit against it (counter u_hit_max_diff): a bound.

Every step must stay conservative (no false negative, no late hit, no intersecting
stop pose): violations are counted in the table. Writes <knob>.png/.svg, table.md
and results.json into --out.
"""
from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

import gauss6

from . import bench

CCD_SETS = ["peg_script", "grazing", "zero_rotation", "random", "bunny_script"]
DELTA_SETS = ["peg_script", "grazing"]  # exact separations are costly on the bunny
LEAF_SETS = ["peg_script", "random", "bunny_script"]  # those of bench_bvh.cpp
CCD_TOLERANCES = [1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2]
DELTA_FACTORS = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0]
FEASIBILITY_TOLS = ["1e-15", "1e-14", "1e-13", "1e-12", "1e-10", "1e-08", "1e-06"]
DEPENDENCE_TOLS = ["1e-14", "1e-12", "1e-10", "1e-08", "1e-06"]
# The shipped value of each knob: the settings' defaults come from the C++ core
# (gauss6.defaults()); the separation is delta itself, the leaf size the BVH build's.
_SHIPPED = gauss6.defaults()
DEFAULTS = {"projection_feasibility_tol": _SHIPPED["projection"]["feasibility_tol"],
            "projection_dependence_tol": _SHIPPED["projection"]["dependence_tol"],
            "ccd_time_tolerance": _SHIPPED["ccd"]["time_tolerance"],
            "separation_delta": 1.0, "bvh_leaf_size": 4}
KNOBS = list(DEFAULTS)
ERROR_FLOOR = 1e-17  # zero errors are drawn here on log axes


# --------------------------------------------------------------------------------------
# Pareto front and plot
# --------------------------------------------------------------------------------------

def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats in both time and error (lower is better)."""
    front = []
    for i, (t, e) in enumerate(points):
        dominated = any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points) if j != i)
        if not dominated:
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def plot_front(rows: list[dict], peers: list[dict], title: str, xlabel: str, ylabel: str, path_stem: Path) -> None:
    """rows: {"label", "time", "time_p99", "error", "default"}; peers: {"label", "time", "error"}."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5))
    pts = [(r["time"], max(r["error"], ERROR_FLOOR)) for r in rows]
    front = pareto_front(pts)
    ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "-", color="C0", alpha=0.4, lw=2,
            label="Pareto front (gauss6)")
    for i, (r, (t, e)) in enumerate(zip(rows, pts)):
        xerr = [[0], [max(r.get("time_p99", t) - t, 0)]]
        ax.errorbar([t], [e], xerr=xerr, fmt="*" if r["default"] else "o", ms=16 if r["default"] else 6,
                    color="C3" if r["default"] else "C0", mec="k", capsize=2, zorder=3 if r["default"] else 2)
        if "median_error" in r:  # hollow: the median error of the same setting
            ax.plot([t], [max(r["median_error"], ERROR_FLOOR)], "o", mfc="none", mec="C0", ms=5)
        # Labels staggered: settings with equal errors would print over each other.
        ax.annotate(r["label"] + (" (default)" if r["default"] else ""), (t, e), textcoords="offset points",
                    xytext=(8, -14 + 10 * (i % 4)), fontsize=7, color="C3" if r["default"] else "k")
    for k, p in enumerate(peers):
        ax.plot([p["time"]], [max(p["error"], ERROR_FLOOR)], "s", ms=8, color=f"C{k + 4}", mec="k", label=p["label"])
        if "median_error" in p:
            ax.plot([p["time"]], [max(p["median_error"], ERROR_FLOOR)], "s", ms=6, mfc="none", mec=f"C{k + 4}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(path_stem.with_suffix("." + ext), dpi=120)
    plt.close(fig)


# --------------------------------------------------------------------------------------
# Benchmark timings (native) from the suites
# --------------------------------------------------------------------------------------

def bench_timings(build: Path | None, filter_regex: str, out_json: Path, min_time: float) -> dict[str, dict]:
    doc = bench.run_benchmarks(bench.bench_binary(build), out_json, filter_regex, repetitions=3, min_time=min_time)
    return {r["name"]: r for r in bench.summarize(doc)}


# --------------------------------------------------------------------------------------
# Projection
# --------------------------------------------------------------------------------------

def projection_sweeps(build: Path | None, out: Path, quick: bool) -> dict:
    from . import _gauss6, qp_instances, report_qp
    from .crosscheck_qp import certified_optimum, m_norm

    families = ["box", "peg", "m50"] if quick else report_qp.FAMILIES
    data = []  # (M, au, J, b, ac*, scale) of the well-posed instances
    excluded = 0
    for f in families:
        for inst in qp_instances.load_family(f):
            M, au, J, b = inst.M, inst.au, inst.J, inst.b
            if m_norm(M, au) == 0:
                continue
            ours = _gauss6.project(M, au, J, b)
            ac_star, how, _ = certified_optimum(M, au, J, b, list(ours.active)) if ours.status == "optimal" else (
                None, "infeasible", "")
            if how != "certificate":
                excluded += 1
                continue
            data.append((M, au, J, b, ac_star, m_norm(M, au)))
    timings = bench_timings(build, "ProjectionSweep", out / "projection_sweep_bench.json", 0.1 if quick else 0.5)

    def errors(settings) -> tuple[np.ndarray, int]:
        e, failed = [], 0
        for M, au, J, b, ac_star, scale in data:
            r = _gauss6.project(M, au, J, b, settings=settings)
            if r.status != "optimal":
                failed += 1
                continue
            e.append(m_norm(M, np.asarray(r.ac) - ac_star) / scale)
        return np.array(e), failed

    results = {}
    for knob, values, attr in (("projection_feasibility_tol", FEASIBILITY_TOLS, "feasibility_tol"),
                               ("projection_dependence_tol", DEPENDENCE_TOLS, "dependence_tol")):
        rows = []
        for v in values:
            s = _gauss6.ProjectionSettings()
            setattr(s, attr, float(v))
            e, failed = errors(s)
            t = timings.get(f"ProjectionSweep/{attr}:{v}", {})
            rows.append({"label": v, "value": float(v), "time": t.get("p50_ns", math.nan) / 1e3,
                         "time_p99": t.get("p99_ns", math.nan) / 1e3, "error": float(e.max()) if len(e) else math.nan,
                         "median_error": float(np.median(e)) if len(e) else math.nan, "failed": failed,
                         "default": float(v) == DEFAULTS[knob]})
        results[knob] = {"rows": rows, "instances": len(data), "excluded_ill_posed": excluded}
    # Peers, on the same instances.
    peers = []
    for name, (clock, solve) in report_qp.SOLVERS.items():
        if name.startswith("gauss6"):
            continue
        ts, es, failed = [], [], 0
        for M, au, J, b, ac_star, scale in data:
            x, t = solve(M, au, J, b)
            if x is None:
                failed += 1
                continue
            ts.append(t * 1e6)
            es.append(m_norm(M, np.asarray(x) - ac_star) / scale)
        peers.append({"label": f"{name} ({clock} time; {failed} failed)", "time": float(np.median(ts)),
                      "time_p99": float(np.percentile(ts, 99)), "error": float(max(es)),
                      "median_error": float(np.median(es)), "failed": failed})
    for knob in ("projection_feasibility_tol", "projection_dependence_tol"):
        results[knob]["peers"] = peers
        plot_front(results[knob]["rows"], peers,
                   f"Projection, {knob.split('_', 1)[1]}: {len(data)} well-posed instances\n({', '.join(families)})",
                   "median time per cold solve (us; bar to p99)",
                   "max error |ac - ac*|_M / |au|_M (filled; hollow: median)",
                   out / knob)
    return results


# --------------------------------------------------------------------------------------
# CCD
# --------------------------------------------------------------------------------------

class _CcdData:
    """The steps of the sets, their mesh pairs and their exact first contacts (computed once)."""

    def __init__(self, sets: list[str]):
        from . import crosscheck_ccd as cc

        self.cc = cc
        self.meshes = cc.Meshes()
        self.steps = []  # (set, delta, key, pair, step, exact)
        for name in sets:
            doc = cc.load_set(name)
            for step in doc["steps"]:
                key, pair = self.meshes.get(step)
                p0, q0, p1, q1 = cc.poses(step)
                self.steps.append((name, float(doc["delta"]), key, pair, step,
                                   pair.exact_first_contact(p0, q0, p1, q1)))


def _ccd_run(data: _CcdData, sets: list[str], time_tolerance: float, delta_factor: float,
             with_separation: bool) -> dict:
    times, gaps, seps = [], [], []
    violations = 0
    for name, delta, key, pair, step, ex in data.steps:
        if name not in sets:
            continue
        p0, q0, p1, q1 = data.cc.poses(step)
        r = pair.step(p0, q0, p1, q1, delta * delta_factor, time_tolerance=time_tolerance, repeats=3)
        times.append(r["seconds"] * 1e6)
        late = r["hit"] and ex.compare(r["u_hit"]) > 0
        violations += int(ex.hit and not r["hit"]) + int(late)
        if r["hit"] and ex.hit and not late:
            gaps.append(max(ex.lower - r["u_hit"], 0.0))
        if with_separation and r["hit"]:
            sp, sq = np.asarray(r["stop_p"]), np.asarray(r["stop_q"])
            if pair.count_intersecting_pairs(sp, sq):
                violations += 1
            else:
                window = 100 * delta * max(delta_factor, 1.0)
                s = pair.separation(sp, sq, window)
                seps.append(s["upper"] if s["within"] else window)
    t = np.array(times)
    return {"time": float(np.median(t)), "time_p99": float(np.percentile(t, 99)), "mean_time": float(t.mean()),
            "max_gap": float(max(gaps, default=0.0)), "median_gap": float(np.median(gaps)) if gaps else 0.0,
            "max_separation": float(max(seps, default=math.nan)) if with_separation else math.nan,
            "violations": violations, "steps": len(times)}


def ccd_sweeps(build: Path | None, out: Path, knobs: list[str], quick: bool) -> dict:
    sets = ["peg_script", "grazing"] if quick else CCD_SETS
    data = _CcdData(sorted(set(sets) | set(DELTA_SETS)))
    results = {}
    if "ccd_time_tolerance" in knobs:
        rows = []
        for tol in CCD_TOLERANCES[2:6] if quick else CCD_TOLERANCES:
            # min_separation 0: the gap to u* is then the tolerance's doing alone (with delta > 0
            # the stand-off before contact dominates it, see separation_delta).
            r = _ccd_run(data, sets, tol, 0.0, with_separation=False)
            rows.append({"label": f"{tol:.0e}", "value": tol, "error": r["max_gap"], **r, "time": r["mean_time"],
                         "default": tol == DEFAULTS["ccd_time_tolerance"]})
        peers = fcl_peer(data)
        results["ccd_time_tolerance"] = {"rows": rows, "sets": sets, "peers": peers}
        plot_front(rows, [p for p in peers if p["steps"]],
                   f"CCD time tolerance: ccd_step on {sum(r['steps'] for r in rows[:1])} steps ({', '.join(sets)})",
                   "mean time per step (us; bar to p99), min_separation 0", "max gap u* - u_hit (motion parameter)",
                   out / "ccd_time_tolerance")
    if "separation_delta" in knobs:
        rows = []
        for f in DELTA_FACTORS[1:4] if quick else DELTA_FACTORS:
            r = _ccd_run(data, DELTA_SETS, 1e-6, f, with_separation=True)
            rows.append({"label": f"{f:g} delta", "value": f, "error": r["max_separation"], **r, "time": r["mean_time"],
                         "default": f == DEFAULTS["separation_delta"]})
        results["separation_delta"] = {"rows": rows, "sets": DELTA_SETS, "peers": []}
        plot_front(rows, [], f"Separation delta (x the scene's delta, 1e-6 m): ccd_step on {', '.join(DELTA_SETS)}",
                   "mean time per step (us; bar to p99)", "max exact separation at a stop pose (m)",
                   out / "separation_delta")
    if "bvh_leaf_size" in knobs:
        timings = bench_timings(build, "CcdStepLeafSize", out / "leaf_size_bench.json", 0.1)
        base = {name: _ccd_run(data, [name], 1e-6, 1.0, with_separation=False)
                for name in LEAF_SETS if name in {s[0] for s in data.steps}}
        rows = []
        for leaf in (1, 2, 4, 8, 16):
            ts = [timings.get(f"CcdStepLeafSize/{s}/leaf:{leaf}") for s in base]
            ts = [t for t in ts if t]
            if not ts:
                continue
            err = max(base[s]["max_gap"] + timings[f"CcdStepLeafSize/{s}/leaf:{leaf}"].get("u_hit_max_diff", 0)
                      for s in base if f"CcdStepLeafSize/{s}/leaf:{leaf}" in timings)
            diff = max(t.get("u_hit_max_diff", 0) for t in ts)
            # Plotted error: how far the leaf size moves u_hit from the default's (0: the same
            # answers); the exact gap u* - u_hit is then at most error_bound.
            rows.append({"label": f"leaf {leaf}", "value": leaf, "time": float(np.mean([t["mean_ns"] for t in ts])) / 1e3,
                         "time_p99": float(np.mean([t["p99_ns"] for t in ts])) / 1e3, "error": diff,
                         "error_bound": err, "default": leaf == DEFAULTS["bvh_leaf_size"]})
        default_gap = max(b["max_gap"] for b in base.values())
        results["bvh_leaf_size"] = {"rows": rows, "sets": list(base), "peers": [], "default_max_gap": default_gap}
        plot_front(rows, [], f"BVH leaf size: ccd_step on {', '.join(base)} at delta\n"
                   f"(time: mean over the sets; exact gap u* - u_hit at leaf 4: {default_gap:.3g})",
                   "mean time per step (us; bar to p99)", "max |u_hit - u_hit(leaf 4)| (1e-17: the same)",
                   out / "bvh_leaf_size")
    return results


def fcl_peer(data: _CcdData) -> list[dict]:
    """FCL on the steps whose motion it shares (pure translation, rotation about G)."""
    cc = data.cc
    fcl = cc._fcl()
    if fcl is None:
        return []
    peer = cc.FclPeer(fcl)
    sources = [data]
    if "rotation_about_g" not in {s[0] for s in data.steps}:  # FCL's screw motion: rotation about G
        sources.append(_CcdData(["rotation_about_g"]))
    out = []
    for solver in cc.FclPeer.SOLVERS:
        times, errs, misses, late, n = [], [], 0, 0, 0
        for src in sources:
            for name, delta, key, pair, step, ex in src.steps:
                kind = cc.motion_kind(step)
                if not kind:
                    continue
                hit, u, s = peer.run(src.meshes, key, step, kind, solver)
                n += 1
                times.append(s * 1e6)
                if ex.hit and not hit:
                    misses += 1
                elif ex.hit and hit:
                    late += int(ex.compare(u) > 0)
                    errs.append(abs(ex.lower - u))
        out.append({"label": f"FCL {solver.replace('CCDC_', '').lower()} ({n} steps: {misses} missed, {late} late)",
                    "time": float(np.mean(times)) if times else math.nan,
                    "time_p99": float(np.percentile(times, 99)) if times else math.nan, "error": float(max(errs, default=math.nan)), "misses": misses, "late": late, "steps": n})
    return out


# --------------------------------------------------------------------------------------
# Table and entry points
# --------------------------------------------------------------------------------------

def format_table(results: dict) -> str:
    lines = ["Time: projection, median per cold solve; CCD knobs, mean per step (most steps are"
             " trivial misses, so a median hides the steps with contacts). p99 of single calls.", ""]
    for knob, res in results.items():
        lines += [f"### {knob}", "", "| value | time | p99 time | max error | violations / failures | default |",
                  "|---|---|---|---|---|---|"]
        for r in res["rows"]:
            bad = r.get("violations", r.get("failed", 0))
            lines.append(f"| {r['label']} | {r['time']:.3g} us | {r['time_p99']:.3g} us | {r['error']:.3g} | {bad} | "
                         f"{'**yes**' if r['default'] else ''} |")
        for p in res.get("peers", []):
            lines.append(f"| peer: {p['label']} | {p['time']:.3g} us | {p.get('time_p99', math.nan):.3g} us | "
                         f"{p['error']:.3g} | {p.get('failed', p.get('misses', 0))} | |")
        lines.append("")
    return "\n".join(lines)


def run(out: Path, build: Path | None, knobs: list[str], quick: bool = False) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    t0 = time.time()
    if any(k.startswith("projection") for k in knobs):
        results.update({k: v for k, v in projection_sweeps(build, out, quick).items() if k in knobs})
    ccd_knobs = [k for k in knobs if not k.startswith("projection")]
    if ccd_knobs:
        results.update(ccd_sweeps(build, out, ccd_knobs, quick))
    results = {k: results[k] for k in knobs if k in results}
    (out / "results.json").write_text(json.dumps({"seconds": time.time() - t0, "knobs": results}, indent=1,
                                                 default=str) + "\n")
    (out / "table.md").write_text(format_table(results))
    return results
