"""`gauss6 certify TRACE --scene SCENE`: METHOD.md property 5 and the bound of property 6 on every step of a
recorded run, decided by the exact reference (never by the optimized code under test).

For the god-object poses of the trace's ticks (xs; consecutive ticks with the same pose are one pose):

  pose        every distinct pose is exactly free: no (god, obstacle) triangle pair intersects or touches
              (reference count_intersecting_pairs: CGAL's filtered predicate, intervals first, Gmpq where
              they cannot decide; the meshes' doubles taken exactly)
  motion      the in-between motion (METHOD.md s.4, the Cayley motion) between each pose and the next is free
              of contact: reference mesh_first_contact finds no contact in [0, 1]. Path: "boxes" when the
              swept box of the god-object (G's segment grown by its radius) misses every obstacle's box,
              "filter" when every candidate feature pair was ruled out by the reference's interval filter,
              "exact" when some pairs needed exact root isolation
  separation  at every distinct pose with contacts (num_contacts > 0: every stop pose of the sim loop and every
              pose the force acts at), the exact separation is at most the stated bound of property 6:
              distance.bound x delta of harness/oracle.toml (3 delta; gauss6 makes contacts within 1.5 delta)
              (reference separation_within: interval enclosures of the pairs' squared distances, Gmpq only
              when none decides; the report's maximum is of the certified upper bounds)

The work is a pure function of (scene, trace, tick range), `certify_chunk` (on files; `certify_range` on loaded
data), whose results merge (`merge`, in any order): a campaign can split a run into chunks of ticks and run them
anywhere. A chunk [start, stop)
judges the poses first shown at its ticks and the motions arriving at them (the motion into tick start
from the pose of tick start - 1 belongs to this chunk).

Output: certify.json ({"format": "gauss6-certify", "version": 1, "pass", "scene", "trace", "ticks",
"coverage", "counts", "paths", "max_separation_delta", "bound_delta", "first_violation", "violations",
"seconds", "machine"}; "ticks" the range certified, "coverage" what the trace held: trace.coverage, its
ticks, time span, complete or cut, sha256) and certify.md (which says INCOMPLETE for a cut trace).
A trace without ticks, or a tick range that is empty or beyond the trace, is refused.
Exit status: 0 certified, 1 a violation, 2 a usage or load error.
"""
from __future__ import annotations

import functools
import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .exact_checks import ExactScene
from .machine import machine
from .trace import coverage_line

FORMAT = "gauss6-certify"
FORMAT_VERSION = 1
KINDS = ("pose", "motion", "separation")


@dataclass
class Violation:
    kind: str            # pose | motion | separation | undecided
    tick: int
    t: float
    detail: str


@dataclass
class CertifyResult:
    """What a tick range certified; `merge` adds ranges together (in any order)."""
    start: int = 0
    stop: int = 0
    poses: int = 0                      # distinct poses checked
    motions: int = 0                    # motions between successive poses checked
    separations: int = 0                # poses with contacts whose separation was checked
    paths: dict = field(default_factory=lambda: {"boxes": 0, "filter": 0, "exact": 0})
    pairs: dict = field(default_factory=lambda: {"candidate": 0, "filtered": 0, "exact": 0})
    separation_paths: dict = field(default_factory=lambda: {"filter": 0, "exact": 0})
    max_separation: float = 0.0         # scene units: the largest certified upper bound of a pose's separation
    violations: list = field(default_factory=list)   # the first of each kind in the range, by tick
    num_violations: dict = field(default_factory=lambda: {k: 0 for k in KINDS + ("undecided",)})
    seconds: float = 0.0
    delta: float = 0.0                  # the scene's delta and the separation bound (scene units)
    bound: float = 0.0

    @property
    def passed(self) -> bool:
        return not any(self.num_violations.values())

    def first_violation(self) -> Violation | None:
        return min(self.violations, key=lambda v: v.tick) if self.violations else None

    def add(self, v: Violation) -> None:
        self.num_violations[v.kind] += 1
        if not any(o.kind == v.kind for o in self.violations):
            self.violations.append(v)


def merge(results) -> CertifyResult:
    """The result of the union of tick ranges (independent of their order)."""
    results = list(results)
    out = CertifyResult()
    if not results:
        return out
    out.start = min(r.start for r in results)
    out.stop = max(r.stop for r in results)
    for r in results:
        out.poses += r.poses
        out.motions += r.motions
        out.separations += r.separations
        for d, s in ((out.paths, r.paths), (out.pairs, r.pairs), (out.separation_paths, r.separation_paths),
                     (out.num_violations, r.num_violations)):
            for k, v in s.items():
                d[k] = d.get(k, 0) + v
        out.max_separation = max(out.max_separation, r.max_separation)
        out.seconds += r.seconds
        out.delta, out.bound = max(out.delta, r.delta), max(out.bound, r.bound)
    firsts: dict = {}
    for r in results:
        for v in r.violations:
            if v.kind not in firsts or v.tick < firsts[v.kind].tick:
                firsts[v.kind] = v
    out.violations = sorted(firsts.values(), key=lambda v: v.tick)
    return out


def certify_range(scene: ExactScene, ticks, start: int, stop: int) -> CertifyResult:
    """Certify the poses first shown at ticks [start, stop) of `ticks` (a trace's tick records) and the motions
    arriving at them. Pure: the same inputs give the same result, wherever it runs."""
    t0 = time.perf_counter()
    n = len(ticks)
    start, stop = max(0, start), min(stop, n)
    res = CertifyResult(start=start, stop=stop, delta=scene.delta, bound=scene.bound)
    lo = max(start - 1, 0)
    P = np.asarray(ticks["xs_p"][lo:stop], float)
    Q = np.asarray(ticks["xs_q"][lo:stop], float)
    T = np.asarray(ticks["t"][lo:stop], float)
    C = np.asarray(ticks["num_contacts"][lo:stop])
    for k in range(start, stop):
        j = k - lo
        if k > 0 and np.array_equal(P[j], P[j - 1]) and np.array_equal(Q[j], Q[j - 1]):
            continue  # the same pose: judged at its first tick
        t = float(T[j])
        if not (np.all(np.isfinite(P[j])) and np.all(np.isfinite(Q[j])) and np.any(Q[j] != 0)):
            res.add(Violation("pose", k, t, "non-finite pose or zero quaternion"))
            continue
        res.poses += 1
        count = scene.intersecting_pairs(P[j], Q[j])
        if count:
            res.add(Violation("pose", k, t, f"{count} intersecting triangle pairs"))
        if k > 0 and np.all(np.isfinite(P[j - 1])) and np.all(np.isfinite(Q[j - 1])):
            res.motions += 1
            near = scene.near(P[j - 1], P[j])
            if not near:
                res.paths["boxes"] += 1
            else:
                exact_pairs = 0
                try:
                    for i in near:
                        c = scene.first_contact(i, P[j - 1], Q[j - 1], P[j], Q[j])
                        res.pairs["candidate"] += c.num_candidate_pairs
                        res.pairs["filtered"] += c.num_filtered_pairs
                        res.pairs["exact"] += c.num_exact_pairs
                        exact_pairs += c.num_exact_pairs
                        if c.hit:
                            res.add(Violation("motion", k, t, f"contact at u* in [{c.lower!r}, {c.upper!r}] "
                                                              f"(obstacle {i}, pairs {c.pairs[:3]})"))
                            break
                except ValueError as e:  # no Cayley motion (an exact half turn): cannot be certified
                    res.add(Violation("undecided", k, t, f"motion: {e}"))
                res.paths["exact" if exact_pairs else "filter"] += 1
        if C[j] > 0:
            res.separations += 1
            s, exact = scene.separation_within(P[j], Q[j], scene.bound)
            res.separation_paths["exact" if exact else "filter"] += 1
            if math.isfinite(s):
                res.max_separation = max(res.max_separation, s)
            else:
                res.add(Violation("separation", k, t, f"{int(C[j])} contacts, exact separation beyond the bound "
                                                      f"{scene.bound / scene.delta:g} delta"))
    res.seconds = time.perf_counter() - t0
    return res


@functools.lru_cache(maxsize=4)
def _scene(scene_path: str) -> ExactScene:
    return ExactScene(scene_path)


@functools.lru_cache(maxsize=4)
def _trace(trace_path: str, mtime_ns: int):
    """The trace as certified: read (a cut trace with its warnings recorded in Trace.warnings, not
    printed), ticks in time order, positions within the coordinate bound, quaternions rescaled
    (trace.checked_poses)."""
    import warnings

    from .trace import TraceWarning, checked_poses, read_trace

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TraceWarning)  # stated in the outputs (coverage), not only printed
        return checked_poses(read_trace(trace_path))


def _ticks(trace_path: str, mtime_ns: int):
    return _trace(trace_path, mtime_ns).ticks


def load_trace(trace_path):
    """The trace certify judges (cached per process, as certify_chunk's workers read it)."""
    trace_path = Path(trace_path)
    return _trace(str(trace_path), trace_path.stat().st_mtime_ns)


def tick_range_problem(tick_range: tuple[int, int] | None, n: int) -> str:
    """'' when [a, b) is a non-empty range of the trace's n ticks (None: all of them, which must
    not be empty), else what is wrong with it."""
    if n == 0:
        return "the trace holds no ticks: there is no run to certify"
    if tick_range is None:
        return ""
    a, b = tick_range
    if not 0 <= a < b:
        return f"the tick range {a}:{b} is empty or negative (give A:B with 0 <= A < B)"
    if b > n:
        return f"the tick range {a}:{b} goes beyond the trace's {n} ticks"
    return ""


def certify_chunk(scene_path, trace_path, start: int, stop: int) -> CertifyResult:
    """A campaign's task: certify_range on the files (the scene's exact structures and the trace's ticks are
    kept per process, so a worker pays for them once). Its result is plain data (picklable) for `merge`."""
    trace_path = Path(trace_path)
    return certify_range(_scene(str(scene_path)), _ticks(str(trace_path), trace_path.stat().st_mtime_ns),
                         start, stop)


def chunks(n: int, size: int) -> list[tuple[int, int]]:
    """Tick ranges [a, b) of at most `size` ticks covering [0, n)."""
    return [(a, min(a + size, n)) for a in range(0, n, max(size, 1))]


def certify(scene_path, trace_path, chunk_ticks: int = 2000, tick_range: tuple[int, int] | None = None,
            progress=None) -> CertifyResult:
    """Certify a recorded run, chunk by chunk (serially; see certify_range to run chunks elsewhere).
    ValueError for a trace without ticks and a tick range that is empty or beyond the trace."""
    n = len(load_trace(trace_path).ticks)
    problem = tick_range_problem(tick_range, n)
    if problem:
        raise ValueError(f"{trace_path}: {problem}")
    a, b = tick_range or (0, n)
    results = []
    for lo, hi in chunks(b - a, chunk_ticks):
        results.append(certify_chunk(scene_path, trace_path, a + lo, a + hi))
        if progress:
            progress(hi, b - a)
    return merge(results)


def to_json(res: CertifyResult, scene_path, trace_path, coverage: dict | None = None) -> dict:
    """certify.json; coverage (trace.coverage of the whole trace) says what the run held: its ticks,
    time span, complete or cut, and its digest, beside the tick range certified ("ticks")."""
    delta, bound = res.delta, res.bound
    first = res.first_violation()
    return {"format": FORMAT, "version": FORMAT_VERSION, "pass": res.passed, "scene": str(scene_path),
            "trace": str(trace_path), "ticks": [res.start, res.stop], "coverage": coverage,
            "counts": {"poses": res.poses, "motions": res.motions, "separations": res.separations},
            "paths": dict(res.paths), "pairs": dict(res.pairs), "separation_paths": dict(res.separation_paths),
            "max_separation_delta": res.max_separation / delta if delta else 0.0,
            "bound_delta": bound / delta if delta else 0.0,
            "first_violation": asdict(first) if first else None,
            "violations": {"counts": dict(res.num_violations), "first_of_each": [asdict(v) for v in res.violations]},
            "seconds": res.seconds, "machine": machine()}


def to_markdown(doc: dict) -> str:
    c, p, pr = doc["counts"], doc["paths"], doc["pairs"]
    lines = [f"# Certification of `{doc['trace']}`", "",
             f"Scene `{doc['scene']}`, ticks [{doc['ticks'][0]}, {doc['ticks'][1]}): "
             f"**{'certified' if doc['pass'] else 'NOT certified'}** ({doc['seconds']:.1f} s).", "",
             *([f"The trace: {coverage_line(doc['coverage'])}."] if doc.get("coverage") else []),
             *(["**Only part of the run was certified**: the trace is cut; what it lost is not judged.", ""]
               if doc.get("coverage") and not doc["coverage"]["complete"] else [""] if doc.get("coverage") else []),
             "| property (METHOD.md s.5) | checked | by | result |", "| --- | --- | --- | --- |",
             f"| 5: every pose exactly free | {c['poses']} distinct poses | reference count_intersecting_pairs "
             f"(CGAL filtered predicate: intervals, Gmpq when undecided) | {doc['violations']['counts']['pose']} "
             f"violations |",
             f"| 5: the motion between successive poses free of contact | {c['motions']} motions | boxes "
             f"{p['boxes']}, interval filter {p['filter']}, exact roots {p['exact']} (feature pairs: "
             f"{pr['candidate']} candidates, {pr['filtered']} ruled out by the filter, {pr['exact']} solved "
             f"exactly) | {doc['violations']['counts']['motion']} violations, "
             f"{doc['violations']['counts']['undecided']} undecided |",
             f"| 6: separation at the poses with contacts <= {doc['bound_delta']:g} delta | {c['separations']} poses "
             f"| reference separation_within: intervals {doc['separation_paths']['filter']}, Gmpq "
             f"{doc['separation_paths']['exact']} | max {doc['max_separation_delta']:.3f} delta (upper bounds), "
             f"{doc['violations']['counts']['separation']} violations |", ""]
    f = doc["first_violation"]
    lines.append(f"First violation: tick {f['tick']} (t = {f['t']:.4f} s), {f['kind']}: {f['detail']}" if f
                 else "No violation.")
    m = doc["machine"]
    lines += ["", f"Machine: {m['processor']}, {m['cpus']} CPUs, {m['platform']}, Python {m['python']}.", ""]
    return "\n".join(lines)


def write_report(res: CertifyResult, scene_path, trace_path, out: Path, name: str = "certify",
                 coverage: dict | None = None) -> dict:
    """Writes OUT/<name>.json and OUT/<name>.md; returns the JSON document."""
    from .paths import check_output_dir

    if coverage is None:
        from .trace import coverage as trace_coverage

        coverage = trace_coverage(load_trace(trace_path))
    doc = to_json(res, scene_path, trace_path, coverage)
    check_output_dir(out)
    (out / f"{name}.json").write_text(json.dumps(doc, indent=2) + "\n")
    (out / f"{name}.md").write_text(to_markdown(doc))
    return doc
