"""Witness files: every failed check of `gauss6 validate` written as its first and worst violations,
each a JSON file that `gauss6 certify --witness FILE` re-checks exactly (docs/engine-contract.md,
"Witnesses").

A witness holds the tick, the rows of the trace the check needs to decide it again (the tick alone for
a pose; the two ends of a motion; the contact episode for the energy observer; the window of a
latency), every double as a hex float (float.hex: exact), the contact rows at the displayed pose
(gauss6's contact generation within the bound), the engine's declarations, the thresholds and the
machine calibration the verdict used, and the verdict. Re-checking rebuilds those rows as a trace and
runs the same check of the oracle's table on them (the geometric ones through exact_checks.ExactScene,
the path `gauss6 certify` itself takes), and states the exact geometry of the violation: the
intersecting triangle pairs' count, the motion's first contact bracket, the separation.

    paths = write_witnesses(result, trace, scene, out_dir, thresholds, calibration)
    ok, text = recheck(json.loads(Path(paths[0]).read_text()))
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

FORMAT = "gauss6-witness"
FORMAT_VERSION = 1


def _hex(a) -> list | str:
    a = np.asarray(a, float)
    if a.ndim == 0:
        return float(a).hex()
    return [_hex(x) for x in a]


def _unhex(x):
    if isinstance(x, list):
        return [_unhex(v) for v in x]
    return float.fromhex(x)


def window(check: str, v: dict, thresholds: dict, declared: dict) -> tuple[int, int]:
    """The ticks [a, b] (inclusive) a check needs to decide violation v again."""
    k = int(v["tick"])
    if check == "tunnelling":
        return int(v["from_tick"]), k
    if check == "energy":
        return int(v["window_start"]), k
    if check == "force_jumps":  # the tick's change, and the handle's motion up to a declared latency before
        return max(k - 1 - declared.get("latency_ticks", 0), 0), k
    if check == "tracking":
        return max(k - thresholds["tracking"]["max_lag_ticks"] - declared.get("latency_ticks", 0), 0), k
    if check == "latency":
        L = thresholds["latency"]
        end = int(v["response_tick"])
        return max(end - L["window_ticks"] - L["onset_ticks"] - declared.get("latency_ticks", 0), 0), end
    return k, k


def _rows(arr: np.ndarray, a: int, b: int) -> dict:
    return {name: _hex(arr[name][a:b + 1]) for name in arr.dtype.names}


def make_witness(result, trace, scene_path, check: str, role: str, thresholds: dict, calibration=None,
                 oracle=None) -> dict:
    """The witness document of one violation (role "first" or "worst") of a failed check."""
    v = result.verdict(check)
    viol = v.violations[role]
    a, b = window(check, viol, thresholds, result.declarations)
    k = int(viol["tick"])
    ticks = trace.ticks
    steps = trace.steps if len(trace.steps) == len(ticks) else None
    doc = {"format": FORMAT, "version": FORMAT_VERSION, "check": check, "role": role, "scene": str(scene_path),
           "run": str(trace.path), "tick": k, "t": float(ticks["t"][k]).hex(), "t_seconds": float(ticks["t"][k]),
           "xs": {"p": _hex(ticks["xs_p"][k]), "q": _hex(ticks["xs_q"][k])},
           "xh": {"p": _hex(ticks["xh_p"][k]), "q": _hex(ticks["xh_q"][k])},
           "wrench": _hex(ticks["wrench"][k]),
           "window": [a, b], "ticks": _rows(ticks, a, b), "steps": _rows(steps, a, b) if steps is not None else None,
           "phases": trace.meta.get("phases", []), "declarations": result.declarations,
           "thresholds": thresholds, "calibration": calibration,
           "violation": {kk: (vv if not isinstance(vv, float) else vv) for kk, vv in viol.items()},
           "verdict": v.to_json()}
    if oracle is not None and all(math.isfinite(x) for x in np.concatenate([ticks["xs_p"][k], ticks["xs_q"][k]])):
        cs = oracle.contacts.contacts(ticks["xs_p"][k], ticks["xs_q"][k],
                                      thresholds["distance"]["bound"] * oracle.delta
                                      + result.declarations.get("skin", 0.0))
        doc["contacts"] = {key: _hex(cs[key]) for key in ("points", "normals", "separations", "J")}
    return doc


def write_witnesses(result, trace, scene_path, out_dir, thresholds: dict, calibration=None, oracle=None,
                    viewer_page: str | None = None) -> list[dict]:
    """Writes OUT/witnesses/<check>-<role>.json for the first and the worst violation of every failed
    check; returns [{check, role, tick, t, path, viewer}] (viewer: the page at that tick, when a page
    name is given: `gauss6 view` pages open at #t=SECONDS)."""
    out = Path(out_dir) / "witnesses"
    written = []
    for v in result.verdicts:
        if v.passed or not v.violations:
            continue
        for role in ("first", "worst"):
            if role not in v.violations:
                continue
            doc = make_witness(result, trace, scene_path, v.name, role, thresholds, calibration, oracle)
            out.mkdir(parents=True, exist_ok=True)
            path = out / f"{v.name}-{role}.json"
            path.write_text(json.dumps(doc, indent=1) + "\n")
            written.append({"check": v.name, "role": role, "tick": doc["tick"], "t": doc["t_seconds"], "path": str(path),
                            "viewer": f"{viewer_page}#t={doc['t_seconds']:.6f}" if viewer_page else None})
    return written


def report_witnesses(result, trace, oracle, out_dir, viewer_page: str = "run.html") -> str:
    """For `gauss6 validate`: writes the witnesses of a judged run (write_witnesses, with the oracle's
    scene, thresholds and the result's calibration) and returns the report's markdown section that
    links each to its file and to the viewer page at its tick ('' when every check passed)."""
    written = write_witnesses(result, trace, oracle.scene_path, out_dir, oracle.thresholds, result.calibration,
                              oracle, viewer_page)
    if not written:
        return ""
    rows = ["## Witnesses", "",
            f"Re-check one exactly: `gauss6 certify --witness FILE`. The viewer page `{viewer_page}`, written "
            f"beside this report, opens at each witness's tick (or make it: `gauss6 view {trace.path} --out "
            f"{Path(out_dir) / viewer_page}`).", "",
            "| check | violation | tick | t (s) | witness | viewer |", "| --- | --- | --- | --- | --- | --- |"]
    for w in written:
        rel = Path(w["path"]).relative_to(Path(out_dir))
        rows.append(f"| {w['check']} | {w['role']} | {w['tick']} | {w['t']:.4f} | [{rel}]({rel}) | "
                    f"[at {w['t']:.4f} s]({w['viewer']}) |")
    return "\n".join(rows) + "\n"


def _trace_of(doc: dict):
    """The witness's rows as a trace (ticks [a, b] renumbered from 0)."""
    from . import trace as trace_mod

    def table(name: str, rows: dict | None):
        n = len(doc["ticks"]["t"])
        arr = np.zeros(n, dtype=trace_mod.DTYPES[name])
        if rows is None:
            arr[:] = np.nan if name == "steps" else 0
            return arr
        for field, values in rows.items():
            arr[field] = np.asarray(_unhex(values), float)
        return arr

    ticks = table("ticks", doc["ticks"])
    steps = table("steps", doc.get("steps")) if doc.get("steps") else np.zeros(0, dtype=trace_mod.DTYPES["steps"])
    meta = trace_mod.trace_metadata(phases=[(p["name"], p["start"]) for p in doc.get("phases", [])],
                                    extra={"declarations": doc.get("declarations") or {}})
    return trace_mod.Trace(path=Path(doc.get("run", "witness")), version=trace_mod.VERSION, meta=meta, ticks=ticks,
                           steps=steps, contacts=np.zeros(0, dtype=trace_mod.DTYPES["contacts"]),
                           events=np.zeros(0, dtype=trace_mod.DTYPES["events"]), complete=True)


def recheck(doc: dict, scene_path=None) -> tuple[bool, str]:
    """Re-checks a witness: (the violation stands, a report). The same check of the oracle's table on
    the witness's rows, with the thresholds, declarations and calibration it records; for the
    geometric checks, the exact facts through exact_checks.ExactScene."""
    from .oracle import CHECK_NAMES, Oracle

    if doc.get("format") != FORMAT or doc.get("version") != FORMAT_VERSION:
        raise ValueError(f"not a gauss6 witness (format {doc.get('format')!r}, version {doc.get('version')!r})")
    check = doc.get("check")
    if check not in CHECK_NAMES:
        raise ValueError(f"witness: unknown check {check!r}")
    scene = scene_path or doc["scene"]
    oracle = Oracle(scene, doc["thresholds"])
    tr = _trace_of(doc)
    a, b = doc["window"]
    k = int(doc["tick"]) - a
    lines = [f"witness of `{check}` ({doc['role']} violation): tick {doc['tick']}, t = {doc['t_seconds']:.6f} s, "
             f"rows {a}..{b} of `{doc['run']}`"]
    P, Q = tr.ticks["xs_p"], tr.ticks["xs_q"]
    ex = oracle.exact
    if check == "penetration":
        n = ex.intersecting_pairs(P[k], Q[k])
        lines.append(f"exact: {n} intersecting or touching triangle pairs at the displayed pose")
    elif check == "tunnelling":
        hits = ex.motion_hits(P[0], Q[0], P[k], Q[k])
        for i, c in hits:
            lines.append(f"exact: the motion from tick {a} to {doc['tick']} touches obstacle {i} at u* in "
                         f"[{c.lower!r}, {c.upper!r}] (feature pairs {list(c.pairs)[:3]})")
        if not hits:
            lines.append("exact: the motion is free of contact")
    elif check == "force_at_distance":
        bound = float(doc["violation"].get("bound", 0.0))
        free = doc["thresholds"]["distance"]["free_space"] * oracle.delta
        s, was_exact = ex.separation_side(P[k], Q[k], bound, free)
        lines.append(f"exact: separation {s / oracle.delta:.6g} delta ({'exact' if was_exact else 'certified bracket'}) "
                     f"against the bound {bound / oracle.delta:g} delta, with |F| = "
                     f"{np.linalg.norm(tr.ticks['wrench'][k][:3]):.6g} N")
    result = oracle.judge(tr, checks=[check], calibration=doc.get("calibration") or {})
    v = result.verdict(check)
    ticks_named = {int(x["tick"]) for x in v.violations.values()}
    stands = (not v.passed) and (k in ticks_named or check in ("energy",) and not v.passed)
    lines.append(f"re-judged by the oracle's `{check}` on these rows: {'FAIL' if not v.passed else 'pass'}"
                 f" ({v.note})")
    lines.append("the violation stands" if stands else "the violation does NOT stand")
    return stands, "\n".join(lines)
