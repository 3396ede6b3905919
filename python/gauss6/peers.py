"""`gauss6 report peers`: gauss6 against its peers in one run, every call from Python (part of `make bench`).

    gauss6 report peers [--out DIR] [--repeats N] [--sample K] [--ccd-only | --qp-only]

CCD (per query): every query of ../shared/data/ccd-sample-queries through
- gauss6: gauss6.ccd.vertex_face / edge_edge (linear motion, CcdSettings' defaults:
  time tolerance 1e-6, no separation);
- Tight-Inclusion: ipctk.tight_inclusion.point_triangle_ccd / edge_edge_ccd (the raw
  functions of the pinned ipctk wheel, min_distance 0, tolerance 1e-6,
  max_iterations 1e6 as in Tight-Inclusion's own benchmark (the wheel's default 1e7
  makes a sliding query take up to 10 s here), no numerical filter (the per-query
  default), breadth-first; its answer does not say when it stopped at the cap, so
  its "gave up" column is empty);
- exact: gauss6.ccd.exact_vertex_face / exact_edge_edge (the reference: root isolation).
--sample K keeps every K-th query of each file (`make bench`: K = 4; the slowest
peer queries take a second each on this machine, so the full 3,824 take several minutes).
Each call is timed in Python (time.perf_counter_ns around the call alone, the arguments
prepared before), the implementations interleaved query by query so that they share the
machine's load; a query's time is the fastest of --repeats calls (one call when it takes
over 10 ms: the noise is then small beside it, and the slowest peer queries take seconds). Per set and kind:
median, p99 and max over queries; false negatives (a ground-truth contact missed) and
false positives (a hit without contact) against the files' exact ground truth; late
hits (a reported time after u*, decided exactly by the reference's compare) and give-ups.

Projection (per QP family of datasets_generated/qp/): gauss6.project (cold), DAQP,
quadprog and proxsuite (dense ProxQP, eps_abs 1e-9) on every instance, each timed in
Python around the solver's call alone (the arguments in each solver's own form prepared
before), fastest of --repeats; failures (no solution: the offsets family holds 20
infeasible instances) and the largest M-norm distance to gauss6's answer,
|x - ac|_M / |au|_M (gauss6 agrees with the exact optimum to 1e-13 or better on the
well-posed instances: `gauss6 crosscheck qp`; DAQP at its default primal tolerance
1e-6 returns points violating rows by up to that much, hence its distances).

Writes DIR/peers.json and DIR/peers.md (the tables; the ratios to gauss6 are the
"x gauss6" columns, > 1 when the peer is slower).
"""
from __future__ import annotations

import json
import math
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from . import _gauss6, ccd, paths, qp_instances

CCD_DATA = paths.SHARED_DATA_DIR / "ccd-sample-queries"
TOLERANCE = 1e-6
TI_MAX_ITERATIONS = 1_000_000
REPEAT_BELOW_NS = 10_000_000  # CCD calls slower than this are not repeated
QP_FAMILIES = ["box", "peg", "bunny", "inertia", "redundant", "m50", "offsets"]


def _timed(fn, repeats: int, repeat_below_ns: float = math.inf):
    """(result of the last call, fastest of `repeats` calls in ns; a call slower than
    repeat_below_ns is not repeated)."""
    best = math.inf
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter_ns()
        out = fn()
        t = time.perf_counter_ns() - t0
        best = min(best, t)
        if t > repeat_below_ns:
            break
    return out, best


def _stats(ns: list[float]) -> dict:
    a = np.asarray(ns, dtype=float)
    return {"median_ns": float(np.median(a)), "p99_ns": float(np.percentile(a, 99)), "max_ns": float(a.max())}


def _set_name(path: str) -> str:
    rel = Path(path).relative_to(CCD_DATA)
    return rel.parts[0]


# --- CCD ---------------------------------------------------------------------

def _ccd_calls(kind: str, x: np.ndarray):
    """The three implementations' calls of one query (file layout: 4 points at u = 0, then at u = 1)."""
    import ipctk

    ti = ipctk.tight_inclusion
    if kind == "vf":
        v0, f0, v1, f1 = x[0], x[1:4], x[4], x[5:8]
        pts = [np.ascontiguousarray(p) for p in x]
        return {
            "gauss6": lambda: ccd.vertex_face(v0, f0, v1, f1),
            "Tight-Inclusion": lambda: ti.point_triangle_ccd(*pts, min_distance=0.0, tolerance=TOLERANCE,
                                                               max_iterations=TI_MAX_ITERATIONS),
            "exact": lambda: ccd.exact_vertex_face(v0, f0, v1, f1),
        }
    a0, b0, a1, b1 = x[0:2], x[2:4], x[4:6], x[6:8]
    pts = [np.ascontiguousarray(p) for p in x]
    return {
        "gauss6": lambda: ccd.edge_edge(a0, b0, a1, b1),
        "Tight-Inclusion": lambda: ti.edge_edge_ccd(*pts, min_distance=0.0, tolerance=TOLERANCE,
                                                          max_iterations=TI_MAX_ITERATIONS),
        "exact": lambda: ccd.exact_edge_edge(a0, b0, a1, b1),
    }


def _hit_and_u(name: str, result) -> tuple[bool, float, bool]:
    """(hit, time of impact, gave up) of one implementation's answer."""
    if name == "gauss6":
        return result.hit, result.u_hit, result.status != "ok"
    if name == "Tight-Inclusion":
        hit, toi, _ = result
        return bool(hit), float(toi), None
    return result.hit, result.lower, False


def run_ccd(repeats: int = 3, show_progress: bool = True, sample: int = 1, sets: list[str] | None = None) -> dict:
    from tqdm import tqdm

    files = [(p, k) for p, k in ccd.query_files(CCD_DATA, None) if sets is None or _set_name(p) in sets]
    groups: dict[tuple[str, str], dict] = {}
    impls = ("gauss6", "Tight-Inclusion", "exact")
    total = 0
    for path, kind in tqdm(files, desc="ccd peers", unit="file", disable=not show_progress):
        q = ccd.read_query_file(path, kind)
        g = groups.setdefault((_set_name(path), kind), {
            "queries": 0, "positives": 0, "ns": {n: [] for n in impls},
            "false_negatives": dict.fromkeys(impls, 0), "false_positives": dict.fromkeys(impls, 0),
            "late": dict.fromkeys(impls, 0), "gave_up": dict.fromkeys(impls, 0)})
        for x, expected in zip(q["points"][::sample], q["expected"][::sample]):
            calls = _ccd_calls(kind, x)
            results = {}
            for name, fn in calls.items():
                results[name], t = _timed(fn, repeats, REPEAT_BELOW_NS)
                g["ns"][name].append(t)
            exact = results["exact"]
            g["queries"] += 1
            g["positives"] += int(expected)
            total += 1
            for name in impls:
                hit, u, gave_up = _hit_and_u(name, results[name])
                if gave_up is None:
                    g["gave_up"][name] = None
                elif g["gave_up"][name] is not None:
                    g["gave_up"][name] += int(gave_up)
                if expected and not hit:
                    g["false_negatives"][name] += 1
                elif hit and not expected:
                    g["false_positives"][name] += 1
                elif hit and expected and exact.compare(u) > 0:
                    g["late"][name] += 1
    rows = []
    for (set_name, kind), g in sorted(groups.items()):
        row = {"set": set_name, "kind": kind, "queries": g["queries"], "positives": g["positives"]}
        for name in impls:
            row[name] = {**_stats(g["ns"][name]), "false_negatives": g["false_negatives"][name],
                         "false_positives": g["false_positives"][name], "late": g["late"][name],
                         "gave_up": g["gave_up"][name],
                         "over_100us": int(sum(t > 1e5 for t in g["ns"][name]))}
        rows.append(row)
    return {"queries": total, "sample": sample, "repeats": repeats, "tolerance": TOLERANCE, "ti_max_iterations": TI_MAX_ITERATIONS,
            "sets": rows}


# --- Projection --------------------------------------------------------------

def _qp_solvers(M, au, J, b):
    """Each solver's call with its arguments prepared (not timed), returning x or None."""
    import daqp
    import proxsuite
    import quadprog

    m = len(b)
    f, upper, sense = -M @ au, np.full(m, 1e30), np.zeros(m, dtype=np.int32)
    Jc, bc, Mau, Jt = np.ascontiguousarray(J), np.ascontiguousarray(b), M @ au, np.ascontiguousarray(J.T)
    inf = np.full(m, 1e20)

    def run_daqp():
        x, _, flag, _ = daqp.solve(M, f, Jc, upper, bc, sense)
        return np.asarray(x) if flag >= 1 else None

    def run_quadprog():
        try:
            return quadprog.solve_qp(M, Mau, Jt, bc, 0)[0]
        except ValueError:
            return None

    def run_proxsuite():
        r = proxsuite.proxqp.dense.solve(M, f, None, None, Jc if m else None, bc if m else None,
                                         inf if m else None, eps_abs=1e-9)
        ok = r.info.status == proxsuite.proxqp.QPSolverOutput.PROXQP_SOLVED
        return np.asarray(r.x) if ok else None

    def run_ours():
        p = _gauss6.project(M, au, J, b)
        return p.ac if p.status == "optimal" else None

    return {"gauss6": run_ours, "DAQP": run_daqp, "quadprog": run_quadprog, "proxsuite": run_proxsuite}


def run_qp(repeats: int = 3, families: list[str] | None = None, show_progress: bool = True) -> dict:
    from tqdm import tqdm

    rows = []
    for fam in tqdm(families or QP_FAMILIES, desc="qp peers", unit="family", disable=not show_progress):
        ns, fails, worst = defaultdict(list), defaultdict(int), defaultdict(float)
        n = 0
        for inst in qp_instances.load_family(fam):
            M, au, J, b = inst.M, inst.au, inst.J, inst.b
            scale = math.sqrt(max(float(au @ M @ au), 1e-300))
            solvers = _qp_solvers(M, au, J, b)
            ref = None
            n += 1
            for name, fn in solvers.items():
                x, t = _timed(fn, repeats)
                ns[name].append(t)
                if x is None:
                    fails[name] += 1
                    continue
                if name == "gauss6":
                    ref = np.asarray(x)
                elif ref is not None:
                    d = np.asarray(x) - ref
                    worst[name] = max(worst[name], math.sqrt(max(float(d @ M @ d), 0.0)) / scale)
        row = {"family": fam, "instances": n}
        for name in ns:
            row[name] = {**_stats(ns[name]), "failed": fails[name], "max_diff_to_gauss6": worst.get(name, 0.0)}
        rows.append(row)
    return {"repeats": repeats, "families": rows}


# --- Tables ------------------------------------------------------------------

def _us(ns: float) -> str:
    return f"{ns / 1e3:.3g}"


def format_ccd(result: dict) -> str:
    lines = [f"CCD per query, {result['queries']} queries (every {result['sample']}th of each file), tolerance {result['tolerance']:g}, time of one Python "
             f"call (fastest of {result['repeats']}), us: median / p99 / max; x gauss6 = peer median / gauss6 "
             "median (and p99, max); FN false negatives, FP false positives, late = hit after u* (exact), "
             ">100us = queries over 100 us.", "",
             "| set | kind | queries | impl | median | p99 | max | x gauss6 (median, p99, max) | FN | FP | late "
             "| gave up | >100us |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in result["sets"]:
        ours = r["gauss6"]
        for name in ("gauss6", "Tight-Inclusion", "exact"):
            s = r[name]
            ratio = "" if name == "gauss6" else ", ".join(
                f"{s[k] / ours[k]:.2g}" for k in ("median_ns", "p99_ns", "max_ns"))
            lines.append(f"| {r['set']} | {r['kind']} | {r['queries']} | {name} | {_us(s['median_ns'])} | "
                         f"{_us(s['p99_ns'])} | {_us(s['max_ns'])} | {ratio} | {s['false_negatives']} | "
                         f"{s['false_positives']} | {s['late']} | {'-' if s['gave_up'] is None else s['gave_up']} | "
                         f"{s['over_100us']} |")
    return "\n".join(lines)


def format_qp(result: dict) -> str:
    lines = [f"Projection per family, time of one Python call (fastest of {result['repeats']}), us: median / p99 / "
             "max; x gauss6 = peer / gauss6; diff = max |x - ac|_M / |au|_M to gauss6's answer.", "",
             "| family | instances | solver | median | p99 | max | x gauss6 (median, p99, max) | failed | diff |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in result["families"]:
        ours = r["gauss6"]
        for name in ("gauss6", "DAQP", "quadprog", "proxsuite"):
            s = r[name]
            ratio = "" if name == "gauss6" else ", ".join(
                f"{s[k] / ours[k]:.2g}" for k in ("median_ns", "p99_ns", "max_ns"))
            diff = "" if name == "gauss6" else f"{s['max_diff_to_gauss6']:.1e}"
            lines.append(f"| {r['family']} | {r['instances']} | {name} | {_us(s['median_ns'])} | {_us(s['p99_ns'])} | "
                         f"{_us(s['max_ns'])} | {ratio} | {s['failed']} | {diff} |")
    return "\n".join(lines)


def run(out_dir: Path, repeats: int = 3, do_ccd: bool = True, do_qp: bool = True, show_progress: bool = True,
        sample: int = 1) -> dict:
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    result = {}
    text = []
    if do_ccd:
        result["ccd"] = run_ccd(repeats, show_progress, sample)
        text.append(format_ccd(result["ccd"]))
    if do_qp:
        result["qp"] = run_qp(repeats, show_progress=show_progress)
        text.append(format_qp(result["qp"]))
    result["seconds"] = time.monotonic() - t0
    (out_dir / "peers.json").write_text(json.dumps(result, indent=1) + "\n")
    (out_dir / "peers.md").write_text("\n\n".join(text) + "\n")
    return result
