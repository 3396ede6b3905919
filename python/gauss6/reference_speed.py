"""`gauss6 reference-speed`: the exact reference's first contact (mesh_first_contact) on the rigid CCD step sets
(datasets_generated/ccd/, the families of `gauss6 crosscheck ccd`), filtered (the default: interval filter, exact
roots only where it cannot decide) and, with --both, exact-only (every candidate pair solved exactly, the path
before the filter), checking that the two give the same exact answer: the same u* bracket and hit, and the same
touching feature pairs.

    gauss6 reference-speed [--set NAME ...] [--steps N] [--both] [--json]

Per set: steps, CPU time per step (process time of this process around each call, in ms: median, p99, max) of
each path, and the candidate feature pairs, those the filter ruled out and those solved exactly. CPU time, not
wall time: the machines this runs on are shared. Exit 1 when the paths disagree on a step.
"""
from __future__ import annotations

import json
import time

import numpy as np


def _stats(ms: list[float]) -> dict:
    if not ms:
        return {"median": None, "p99": None, "max": None}
    a = np.asarray(ms)
    return {"median": float(np.median(a)), "p99": float(np.percentile(a, 99)), "max": float(a.max())}


def _same(a, b) -> bool:
    if a.hit != b.hit:
        return False
    if not a.hit:
        return True
    return a.lower == b.lower and a.upper == b.upper and sorted(map(repr, a.pairs)) == sorted(map(repr, b.pairs))


def measure(names: list[str] | None = None, steps: int | None = None, both: bool = False,
            progress=None) -> dict:
    """Per set: the timings of each path and the disagreements (step ids)."""
    from . import crosscheck_ccd as cc

    meshes = cc.Meshes()
    warm: set = set()
    out = {}
    for name in names or cc.set_names():
        data = cc.load_set(name)
        chosen = data["steps"][:steps] if steps else data["steps"]
        filtered, exact, mismatches = [], [], []
        pairs = {"candidate": 0, "filtered": 0, "exact": 0}
        for step in chosen:
            key, pair = meshes.get(step)
            if key not in warm:  # the exact meshes are built on first use: not part of a step's time
                pair.count_intersecting_pairs(*cc.poses(step)[:2])
                warm.add(key)
            t0 = time.process_time()
            a = pair.exact_first_contact(*cc.poses(step), filtered=True)
            filtered.append((time.process_time() - t0) * 1e3)
            pairs["candidate"] += a.num_candidate_pairs
            pairs["filtered"] += a.num_filtered_pairs
            pairs["exact"] += a.num_exact_pairs
            if both:
                t0 = time.process_time()
                b = pair.exact_first_contact(*cc.poses(step), filtered=False)
                exact.append((time.process_time() - t0) * 1e3)
                if not _same(a, b):
                    mismatches.append(step["id"])
            if progress:
                progress(name, len(filtered), len(chosen))
        out[name] = {"steps": len(chosen), "filtered_ms": _stats(filtered), "exact_only_ms": _stats(exact),
                     "pairs": pairs, "mismatches": mismatches}
    return out


def format_table(result: dict) -> str:
    def f(s):
        return "-" if s["median"] is None else f"{s['median']:.2f} / {s['p99']:.1f} / {s['max']:.1f}"

    lines = ["| set | steps | filtered ms (median / p99 / max) | exact-only ms | pairs: candidates, ruled out by "
             "the filter, solved exactly | disagreements |", "| --- | --- | --- | --- | --- | --- |"]
    for name, r in result.items():
        p = r["pairs"]
        lines.append(f"| {name} | {r['steps']} | {f(r['filtered_ms'])} | {f(r['exact_only_ms'])} | "
                     f"{p['candidate']}, {p['filtered']}, {p['exact']} | {len(r['mismatches'])} |")
    return "\n".join(lines)
