"""`gauss6 crosscheck ccd`: the optimized mesh CCD step against the exact first contact.

For every step of the sets in datasets_generated/ccd/ (README.md there), with the
set's separation delta (METHOD.md section 4):

- optimized: ccd_step(X0 -> X1) with min_separation = delta gives u_hit; the stop
  pose is make_stop_pose(motion, u_hit) on a hit, X1 otherwise;
- exact: mesh_first_contact(X0 -> X1) gives u* (poses with the exact meaning of
  METHOD.md section 1, the exact Cayley motion of section 4).

Violations (any one makes the command exit 1):
- false negative: an exact contact the optimized step did not report;
- late hit: u_hit > u*, decided exactly (compare_toi), never by rounding;
- intersecting stop pose: count_intersecting_pairs(stop pose) > 0, exactly;
- wrong stop pair (steps where both hit): the feature pair the optimized step
  stopped on (CcdStepResult::pair, in canonical ids: feature_ids.h) is not one the
  reference says touches at u*, and its own exact first contact (that one pair
  alone over [0, 1]) is earlier than u_hit (impossible for a sound step: u_hit <=
  u* <= the pair's own contact), never comes, or comes later than u* by more than
  the step's time_tolerance_reached plus PAIR_SLACK_U (below). A different pair
  within that window is reported as agreement within tolerance. A pair that is
  itself within the CCD's acceptance band at the stop pose (its distance <= STOP_BAND
  delta, computed in doubles: rounding is ~1e-17 m against a band of 0.1 delta =
  1e-7 m) is a stop within delta (counted apart, not a violation), whether it touches
  later or never: the step's contract is to stop where a pair may come within delta.
  A contact sliding at about delta (the seeded `sliding` family) has pairs that come
  within delta without ever touching, while another pair touches later; and a step
  whose start pose is already within delta of a pair stays at u = 0 on that pair,
  which may touch after another pair's contact, outside the window below (the
  100,000-step campaign of seed 1 has 37 such steps, starting 0.28-1.0 delta from their
  stop pair, in the random, zero_rotation and peg_scenario families). Measured: the
  other stops within delta are at 1.00001-1.00002 delta (the time tolerance's worth of
  motion).

Why the slack: the step stops where a pair may come within delta (min_separation),
not where one touches, and tests each pair only up to (best u so far) minus the
time tolerance, so of pairs that close together (a face landing flat: its corners
within a few time tolerances of each other) it may report any one. The window is
u* - u_hit (the time the touching pair took from within delta to contact: a pair
within delta at u_hit that closes at least half as fast touches within twice
that) plus PAIR_SLACK_U = 2 time tolerances (the two time tolerances the step
takes off: the per-pair search limit and the reported u).

Reported: gap = u* - u_hit over steps where both hit (max and 99th percentile),
the largest exact separation at a hit's stop pose (scene units; separations
beyond STOP_SEPARATION_WINDOW deltas are reported as that window, a lower bound),
the optimized time per step (fastest of 3 runs) and the reference's.

Peers (`--peers`, and the human-readable table): FCL's continuous collision on the
steps where its motion equals ours as a path: pure translation (CCDM_TRANS) and
pure rotation about G (CCDM_SCREW, rotation about the axis of qr through G; its
time t maps to our u = tan(t theta / 2) / tan(theta / 2)). Its misses and late
stops are counted against the same exact u*.
"""
from __future__ import annotations

import functools
import json
import math
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from . import _gauss6, paths

SETS_DIR = paths.DATASETS_DIR / "ccd"
FORMAT = "gauss6-ccd-steps"
FORMAT_VERSION = 1
STOP_SEPARATION_WINDOW = 100.0   # deltas: the exact separation is computed up to this distance
OPTIMIZED_REPEATS = 3            # timing: fastest of this many runs of each step
TIME_TOLERANCE = 1e-6            # the step's time_tolerance (MeshPair.step's default)
PAIR_SLACK_U = 2 * TIME_TOLERANCE  # see the top of this file
# The runtime accepts a CCD hit once a pair is proven within (1 + ccd_distance_tolerance)
# delta (runtime_model.h, default 0.1): a stop pair within that band at the stop pose
# stopped the step at delta (see the top of this file).
STOP_BAND = 1.1


def set_names() -> list[str]:
    return sorted(p.stem for p in SETS_DIR.glob("*.json") if p.name != "MANIFEST.json")


def load_set(name: str) -> dict:
    """One step set, checked for format and version (ValueError naming the file)."""
    path = SETS_DIR / f"{name}.json"
    if not path.is_file():
        raise ValueError(f"{path}: no such set (sets: {', '.join(set_names())})")
    doc = json.loads(path.read_text())
    if doc.get("format") != FORMAT or doc.get("version") != FORMAT_VERSION:
        raise ValueError(f"{path}: not a {FORMAT} version {FORMAT_VERSION} file")
    return doc


class Meshes:
    """MeshPair objects (optimized + exact) per (obstacle, god, offset), built once."""

    def __init__(self):
        self._pairs: dict[tuple, object] = {}
        self.god_body: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
        self.obstacle: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}

    def features(self, key: tuple) -> tuple:
        """(god V (body frame), god F, obstacle V, obstacle F) of a key from get()."""
        return (*self.god_body[key], *self.obstacle[key])

    def get(self, step: dict):
        key = (step["obstacle"], step["god"], tuple(step["offset"]))
        if key not in self._pairs:
            Vo, Fo = _gauss6.read_mesh(str(paths.DATASETS_DIR / step["obstacle"]))
            Vg, Fg = _gauss6.read_mesh(str(paths.DATASETS_DIR / step["god"]))
            Vg = Vg - np.asarray(step["offset"])  # body frame: origin at G (README.md)
            self._pairs[key] = _gauss6.ccd.MeshPair(Vo, Fo, Vg, Fg)
            self.obstacle[key], self.god_body[key] = (Vo, Fo), (Vg, Fg)
        return key, self._pairs[key]


def poses(step: dict) -> tuple[np.ndarray, ...]:
    return tuple(np.asarray(step[k], dtype=float) for k in ("p0", "q0", "p1", "q1"))


@dataclass
class SetResult:
    name: str
    steps: int = 0
    false_negatives: int = 0
    late_hits: int = 0
    gaps: list[float] = field(default_factory=list)
    intersecting_stop_poses: int = 0
    max_stop_separation: float = 0.0
    optimized_seconds: float = 0.0
    reference_seconds: float = 0.0
    exact_hits: int = 0
    optimized_hits: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    pair_steps: int = 0             # both hit, the optimized step on a feature pair: its pair compared
    pair_matches: int = 0           # ... stopped on a pair the reference says touches at u*
    pair_within_tolerance: int = 0  # ... on another pair whose own contact is within the window
    pair_within_delta: int = 0      # ... on a pair itself within delta at the stop, touching later or never (see the top)
    pair_violations: int = 0        # ... on a pair whose own contact is before u_hit, none, or past the window
    failures: list[str] = field(default_factory=list)

    def as_json(self) -> dict:
        n = max(self.steps, 1)
        return {"name": self.name, "steps": self.steps, "false_negatives": self.false_negatives,
                "late_hits": self.late_hits, "max_gap_u": max(self.gaps, default=0.0),
                "p99_gap_u": float(np.percentile(self.gaps, 99)) if self.gaps else 0.0,
                "intersecting_stop_poses": self.intersecting_stop_poses,
                "max_stop_separation": self.max_stop_separation,
                "optimized_us_per_step": 1e6 * self.optimized_seconds / n,
                "reference_s_per_step": self.reference_seconds / n,
                "pair_steps": self.pair_steps, "pair_matches": self.pair_matches,
                "pair_within_tolerance": self.pair_within_tolerance, "pair_violations": self.pair_violations,
                "pair_within_delta": self.pair_within_delta}

    # A campaign chunk's result travels as JSON (state) and chunks add up (absorb).
    MAX_FAILURES_KEPT = 20

    def state(self) -> dict:
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        d["failures"] = self.failures[:self.MAX_FAILURES_KEPT]
        d["num_failures"] = len(self.failures)
        return d

    def absorb(self, st: dict) -> None:
        for k in ("steps", "false_negatives", "late_hits", "intersecting_stop_poses", "optimized_seconds",
                  "reference_seconds", "exact_hits", "optimized_hits", "pair_steps", "pair_matches",
                  "pair_within_tolerance", "pair_within_delta", "pair_violations"):
            setattr(self, k, getattr(self, k) + st[k])
        self.max_stop_separation = max(self.max_stop_separation, st["max_stop_separation"])
        self.gaps += st["gaps"]
        for k, v in st["statuses"].items():
            self.statuses[k] = self.statuses.get(k, 0) + v
        self.failures += st["failures"][:max(self.MAX_FAILURES_KEPT - len(self.failures), 0)]


def _dot(x, y):
    return np.einsum("...k,...k->...", x, y)


def _scalar(x):
    return float(x) if np.ndim(x) == 0 else x


def point_segment_distance(p, a, b):
    """Euclidean distance from p to the closed segment ab (a point when a = b). Points (..., 3),
    broadcast against each other (the oracle's point_mesh_distance: points x triangles' edges): a
    float for single points, else an array."""
    p, a, b = (np.asarray(x, float) for x in (p, a, b))
    d = b - a
    dd = _dot(d, d)
    t = np.where(dd > 0, np.clip(_dot(p - a, d) / np.where(dd > 0, dd, 1.0), 0, 1), 0.0)
    return _scalar(np.linalg.norm(p - (a + t[..., None] * d), axis=-1))


def point_triangle_distance(p, a, b, c):
    """Euclidean distance from p to the closed triangle abc: the plane's foot when it
    lies inside, else the nearest edge. Broadcast as point_segment_distance."""
    p, a, b, c = (np.asarray(x, float) for x in (p, a, b, c))
    n = np.cross(b - a, c - a)
    nn = _dot(n, n)
    safe = np.where(nn > 0, nn, 1.0)
    h = _dot(p - a, n)
    foot = p - (h / safe)[..., None] * n
    w = [_dot(np.cross(y - x, foot - x), n) for x, y in ((a, b), (b, c), (c, a))]
    inside = (nn > 0) & ((np.minimum.reduce(w) >= 0) | (np.maximum.reduce(w) <= 0))
    edges = np.minimum.reduce([point_segment_distance(p, x, y) for x, y in ((a, b), (b, c), (c, a))])
    return _scalar(np.where(inside, np.abs(h) / np.sqrt(safe), edges))


def segment_distance(a0, a1, b0, b1) -> float:
    """Euclidean distance between the closed segments a0a1 and b0b1: the endpoint
    distances, and the lines' closest points when both lie inside their segments."""
    best = min(point_segment_distance(a0, b0, b1), point_segment_distance(a1, b0, b1),
               point_segment_distance(b0, a0, a1), point_segment_distance(b1, a0, a1))
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a, e, b, c, f = d1 @ d1, d2 @ d2, d1 @ d2, d1 @ r, d2 @ r
    den = a * e - b * b
    if den > 1e-300:
        s, t = (b * f - c * e) / den, (a * f - b * c) / den
        if 0 <= s <= 1 and 0 <= t <= 1:
            best = min(best, float(np.linalg.norm(a0 + s * d1 - (b0 + t * d2))))
    return best


def pair_distance(ids, meshes: tuple, p: np.ndarray, q: np.ndarray) -> float:
    """Distance in doubles of a feature pair (canonical ids) with the god-object at (p, q).
    meshes: (god V (body frame), god F, obstacle V, obstacle F)."""
    Vg, Fg, Vo, Fo = meshes
    kind, god, obs = ids
    from .ccd_seeded import generator  # the step sets' generator: R(q) of METHOD.md section 1

    Xg = p + Vg @ generator().rotation(q).T
    if kind == "god_vertex/obstacle_face":
        P, tri = Xg[god[1]], Vo[Fo[obs[1]]]
    elif kind == "obstacle_vertex/god_face":
        P, tri = Vo[obs[1]], Xg[Fg[god[1]]]
    elif kind == "edge/edge":
        return segment_distance(Xg[god[1]], Xg[god[2]], Vo[obs[1]], Vo[obs[2]])
    else:
        raise ValueError(f"unknown feature pair kind {kind!r}")
    return point_triangle_distance(P, *tri)


def classify_stop_pair(pair, step: dict, opt: dict, ex, meshes: tuple | None = None,
                       delta: float = 0.0) -> tuple[str, str]:
    """Which feature pair stopped a step where both hit: ("match", ""), ("within", ""),
    ("within_delta", ""), or ("violation", why). pair: the MeshPair; opt: its step() dict;
    ex: the exact contact; meshes (see pair_distance) and delta: to judge a stop pair that
    never touches (without them, such a pair is a violation)."""
    ids = opt["pair_ids"]
    if ids in ex.pairs:
        return "match", ""
    own = pair.pair_first_contact(ids, *poses(step))
    u_hit = opt["u_hit"]
    if own.hit and own.compare(u_hit) > 0:
        return "violation", f"stopped on {ids} at u_hit = {u_hit!r}, after its own contact in [{own.lower!r}, " \
                            f"{own.upper!r}]"
    if meshes is not None and pair_distance(
            ids, meshes, np.asarray(opt["stop_p"]), np.asarray(opt["stop_q"])) <= STOP_BAND * delta:
        return "within_delta", ""
    if not own.hit:
        return "violation", f"stopped on {ids}, which never touches (u* in [{ex.lower!r}, {ex.upper!r}])"
    window = opt["time_tolerance_reached"] + max(ex.lower - u_hit, 0.0) + PAIR_SLACK_U
    if own.lower > ex.upper + window:
        return "violation", f"stopped on {ids}, whose own contact in [{own.lower!r}, {own.upper!r}] is past " \
                            f"u* in [{ex.lower!r}, {ex.upper!r}] by more than {window!r}"
    return "within", ""


def check_step(pair, step: dict, delta: float, res: SetResult, meshes: tuple | None = None) -> object:
    """Runs one step both ways, adds it to res and returns the exact contact. meshes: see
    pair_distance (without them, a stop pair that never touches is a violation)."""
    p0, q0, p1, q1 = poses(step)
    opt = pair.step(p0, q0, p1, q1, delta, time_tolerance=TIME_TOLERANCE, repeats=OPTIMIZED_REPEATS)
    ex = pair.exact_first_contact(p0, q0, p1, q1)
    res.steps += 1
    res.optimized_seconds += opt["seconds"]
    res.reference_seconds += ex.seconds
    res.exact_hits += int(ex.hit)
    res.optimized_hits += int(opt["hit"])
    res.statuses[opt["status"]] = res.statuses.get(opt["status"], 0) + 1
    sid = step["id"]
    if ex.hit and not opt["hit"]:
        res.false_negatives += 1
        res.failures.append(f"{sid}: false negative (u* in [{ex.lower!r}, {ex.upper!r}], no optimized hit)")
    if opt["hit"] and ex.compare(opt["u_hit"]) > 0:
        res.late_hits += 1
        res.failures.append(f"{sid}: late hit u_hit = {opt['u_hit']!r} > u* in [{ex.lower!r}, {ex.upper!r}]")
    # The pose the god-object takes: the stop pose on a hit, X1 otherwise. Exactly free?
    sp, sq = np.asarray(opt["stop_p"]), np.asarray(opt["stop_q"])
    n_int = pair.count_intersecting_pairs(sp, sq)
    if n_int:
        res.intersecting_stop_poses += 1
        res.failures.append(f"{sid}: {n_int} intersecting triangle pairs at the stop pose")
    elif opt["hit"]:
        window = STOP_SEPARATION_WINDOW * delta
        sep = pair.separation(sp, sq, window)
        res.max_stop_separation = max(res.max_stop_separation, sep["upper"] if sep["within"] else window)
    if opt["hit"] and ex.hit:
        res.gaps.append(max(ex.lower - opt["u_hit"], 0.0) if ex.compare(opt["u_hit"]) <= 0 else 0.0)
        if opt["pair_ids"] is not None:
            verdict, why = classify_stop_pair(pair, step, opt, ex, meshes, delta)
            res.pair_steps += 1
            res.pair_matches += int(verdict == "match")
            res.pair_within_tolerance += int(verdict == "within")
            res.pair_within_delta += int(verdict == "within_delta")
            if verdict == "violation":
                res.pair_violations += 1
                res.failures.append(f"{sid}: {why}")
    return ex


# --------------------------------------------------------------------------------------
# FCL, side by side on the steps whose motion it shares
# --------------------------------------------------------------------------------------

@dataclass
class PeerResult:
    motion: str                 # "translation" or "rotation_about_g"
    solver: str
    steps: int = 0
    exact_hits: int = 0
    misses: int = 0             # exact contact, FCL none
    late: int = 0               # FCL's time (in our u) after u*
    false_positives: int = 0    # FCL contact, exact none
    seconds: float = 0.0

    def as_json(self) -> dict:
        n = max(self.steps, 1)
        return {"motion": self.motion, "solver": self.solver, "steps": self.steps, "exact_hits": self.exact_hits,
                "misses": self.misses, "late": self.late, "false_positives": self.false_positives,
                "us_per_step": 1e6 * self.seconds / n}


def _fcl():
    try:
        import fcl  # python-fcl (FCL 0.7)
    except ImportError:
        return None
    return fcl


def motion_kind(step: dict) -> str | None:
    """'translation' (q0 == q1), 'rotation_about_g' (p0 == p1, q0 != q1), or None."""
    if step["q0"] == step["q1"]:
        return "translation"
    if step["p0"] == step["p1"]:
        return "rotation_about_g"
    return None


class FclPeer:
    SOLVERS = ("CCDC_CONSERVATIVE_ADVANCEMENT", "CCDC_NAIVE")

    def __init__(self, fcl):
        self.fcl = fcl
        self._models: dict[tuple, tuple] = {}

    def _model(self, V: np.ndarray, F: np.ndarray):
        m = self.fcl.BVHModel()
        m.beginModel(len(V), len(F))
        m.addSubModel(np.ascontiguousarray(V), np.ascontiguousarray(F, dtype=np.int32))
        m.endModel()
        return m

    def run(self, meshes: Meshes, key: tuple, step: dict, kind: str, solver: str) -> tuple[bool, float, float]:
        """(hit, u in our parameter, seconds) of FCL on one step."""
        fcl = self.fcl
        if key not in self._models:
            self._models[key] = (self._model(*meshes.obstacle[key]), self._model(*meshes.god_body[key]))
        obs_model, god_model = self._models[key]
        p0, q0, p1, q1 = poses(step)
        q0n, q1n = q0 / np.linalg.norm(q0), q1 / np.linalg.norm(q1)
        god = fcl.CollisionObject(god_model, fcl.Transform(q0n, p0))
        obs = fcl.CollisionObject(obs_model, fcl.Transform())
        req = fcl.ContinuousCollisionRequest()
        req.ccd_motion_type = fcl.CCDMotionType.CCDM_TRANS if kind == "translation" else fcl.CCDMotionType.CCDM_SCREW
        req.ccd_solver_type = getattr(fcl.CCDSolverType, solver)
        res = fcl.ContinuousCollisionResult()
        t0 = time.perf_counter()
        fcl.continuousCollide(god, fcl.Transform(q1n, p1), obs, fcl.Transform(), req, res)
        seconds = time.perf_counter() - t0
        t = float(res.time_of_contact)
        if not res.is_collide:
            return False, 1.0, seconds
        if kind == "translation":
            return True, t, seconds
        # Screw motion: angle t theta; Cayley: angle 2 atan(u tan(theta / 2)).
        qr = _qmul(q1n, q0n * np.array([1, -1, -1, -1]))
        half = math.atan2(float(np.linalg.norm(qr[1:])), abs(float(qr[0])))
        return True, math.tan(t * half) / math.tan(half), seconds


def _qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw])


# --------------------------------------------------------------------------------------
# The run
# --------------------------------------------------------------------------------------

def crosscheck(names: list[str] | None = None, with_peers: bool = True, show_progress: bool = False):
    """Returns (result JSON, failures, peer results or None when FCL is absent)."""
    names = names or set_names()
    meshes = Meshes()
    fcl = _fcl() if with_peers else None
    peer = FclPeer(fcl) if fcl else None
    peers: dict[tuple[str, str], PeerResult] = {}
    results, failures = [], []
    for name in names:
        doc = load_set(name)
        res = SetResult(name)
        steps = doc["steps"]
        if show_progress:
            from tqdm import tqdm
            steps = tqdm(steps, desc=name, leave=False, file=sys.stderr)
        for step in steps:
            key, pair = meshes.get(step)
            ex = check_step(pair, step, float(doc["delta"]), res, meshes.features(key))
            kind = motion_kind(step) if peer else None
            if kind:
                for solver in FclPeer.SOLVERS:
                    pr = peers.setdefault((kind, solver), PeerResult(kind, solver))
                    hit, u, s = peer.run(meshes, key, step, kind, solver)
                    pr.steps += 1
                    pr.seconds += s
                    pr.exact_hits += int(ex.hit)
                    pr.misses += int(ex.hit and not hit)
                    pr.false_positives += int(hit and not ex.hit)
                    pr.late += int(hit and ex.hit and ex.compare(u) > 0)
        results.append(res)
        failures += [f"{name}/{f}" for f in res.failures]
    sets = [r.as_json() for r in results]
    ok = all(s["false_negatives"] == 0 and s["late_hits"] == 0 and s["intersecting_stop_poses"] == 0
             and s["pair_violations"] == 0 for s in sets)
    ours = {r.name: r for r in results}
    return {"ok": ok, "sets": sets}, failures, (list(peers.values()) if peer else None), ours


def format_table(result: dict, ours: dict[str, SetResult], peers: list[PeerResult] | None) -> str:
    lines = [f"{'set':<18}{'steps':>6}{'hits*':>6}{'FN':>4}{'late':>5}{'max gap u':>11}{'p99 gap u':>11}"
             f"{'isect':>6}{'max stop sep':>14}{'opt us/step':>13}{'ref s/step':>11}{'pairs =/~/d/x':>16}"]
    for s in result["sets"]:
        r = ours[s["name"]]
        pairs = f"{s['pair_matches']}/{s['pair_within_tolerance']}/{s['pair_within_delta']}/{s['pair_violations']}"
        lines.append(f"{s['name']:<18}{s['steps']:>6}{r.exact_hits:>6}{s['false_negatives']:>4}{s['late_hits']:>5}"
                     f"{s['max_gap_u']:>11.2e}{s['p99_gap_u']:>11.2e}{s['intersecting_stop_poses']:>6}"
                     f"{s['max_stop_separation']:>14.3e}{s['optimized_us_per_step']:>13.1f}"
                     f"{s['reference_s_per_step']:>11.3f}{pairs:>16}")
    lines.append("hits*: exact contacts; FN: false negatives; late: u_hit > u* (exact); isect: stop poses "
                 "that intersect (exact); stop sep in scene units")
    lines.append("pairs =/~/d/x: hit steps stopped on a pair touching at u* / on another pair within the window / "
                 "on a pair itself within delta at the stop (touching later or never) / on a wrong pair (violation)")
    if peers is None:
        lines.append("FCL: python-fcl not installed (pip install -r requirements.txt): peers skipped")
    else:
        lines.append("FCL 0.7 (python-fcl) on the same steps, same exact u*, where its motion equals ours:")
        for p in peers:
            lines.append(f"  {p.motion:<17} {p.solver:<31} {p.steps:>4} steps {p.exact_hits:>4} contacts: "
                         f"{p.misses:>3} missed, {p.late:>3} late, {p.false_positives:>3} false positives, "
                         f"{1e6 * p.seconds / max(p.steps, 1):9.1f} us/step")
    lines.append("ok" if result["ok"] else "FAILED")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# Seeded campaigns: steps generated on the fly (ccd_seeded.py), chunks as tasks (campaign.py)
# --------------------------------------------------------------------------------------

# Fields of the summary that are timings (not part of the verdict, which is the same
# serial or distributed, whatever the number of workers).
TIMING_FIELDS = ("optimized_us_per_step", "reference_s_per_step")


def seeded_campaign(count: int, seed: int = 1, families: list[str] | None = None):
    """The campaign of `count` seeded steps (ccd_seeded.plan)."""
    from . import ccd_seeded
    from .campaign import Campaign

    chunks = ccd_seeded.plan(count, seed, families)
    names = [f for f in ccd_seeded.FAMILIES if families is None or f in families]
    params = {"count": count, "seed": seed, "families": names}
    return Campaign("crosscheck-ccd", chunks, run_seeded_chunk, functools.partial(merge_seeded, names=names),
                    params, sources=("gauss6.ccd_seeded",))


_MESHES = Meshes()  # per process: the MeshPairs of the chunks it ran


def run_seeded_chunk(chunk: dict) -> dict:
    """One chunk: its steps generated and judged; the result's state."""
    from . import ccd_seeded

    steps, delta = ccd_seeded.chunk_steps(chunk["family"], chunk["seed"], chunk["index"], chunk["count"])
    res = SetResult(chunk["family"])
    for step in steps:
        key, pair = _MESHES.get(step)
        check_step(pair, step, delta, res, _MESHES.features(key))
    return res.state()


def merge_seeded(results: list[dict], names: list[str]) -> tuple[dict, list[str], dict]:
    """The chunks' results added up per family: (result JSON, failures, {family: SetResult})."""
    ours = {n: SetResult(n) for n in names}
    for st in results:
        ours[st["name"]].absorb(st)
    sets = [r.as_json() for r in ours.values() if r.steps]
    failures = [f"{r.name}/{f}" for r in ours.values() for f in r.failures]
    not_kept = sum(st["num_failures"] for st in results) - len(failures)
    if not_kept:
        failures.append(f"... and {not_kept} more failures (not kept)")
    ok = all(s["false_negatives"] == 0 and s["late_hits"] == 0 and s["intersecting_stop_poses"] == 0
             and s["pair_violations"] == 0 for s in sets)
    return {"ok": ok, "steps": sum(s["steps"] for s in sets), "sets": sets}, failures, ours


def format_seeded_table(result: dict, ours: dict) -> str:
    return format_table(result, ours, None).replace(
        "FCL: python-fcl not installed (pip install -r requirements.txt): peers skipped",
        f"{result['steps']} seeded steps (seed {result['seed']}); FCL peers: on the stored sets only")
