"""The validation oracle: judges a run of any engine (a gauss6 trace: the driver's recording, or a
run the engine recorded itself) against the scene's true meshes, with every geometric verdict
decided by the exact reference (docs/engine-contract.md, "The checks").

    oracle = Oracle("datasets_generated/scenes/peg_in_hole.toml")
    result = oracle.judge(read_trace("run.g6trace"))   # an OracleResult: verdicts and time series

The checks (thresholds: harness/oracle.toml, each with its reason):
  penetration          every displayed pose, exactly (reference count_intersecting_pairs)
  tunnelling           the in-between motion (METHOD.md s.4) between successive free displayed
                       poses: swept boxes, then gauss6's conservative CCD, then the exact first
                       contact (reference mesh_first_contact) on every step the CCD stops
  force_at_distance    a wrench at a free pose whose exact separation exceeds the bound
  force_direction      the wrench's distance from the cone of contact wrenches (gauss6's contact
                       generation within the bound), metric M^-1: tangential and wrong-side shares
  no_force_when_free   a wrench in free space, or while the handle is on the free side of every
                       contact (METHOD.md property 3)
  energy               passivity observer on the device port, over the run and per contact episode
  force_jumps          the force (torque) a tick adds: its change from the last tick's, less
                       any release of that one (added_per_tick)
  wrench_sanity        non-finite or over-limit wrenches
  cost                 the engine's step time: the rate it sustains, its stalls
Geometric checks skip ticks with a non-finite pose or wrench (wrench_sanity counts them); the
force checks (3-5) judge free poses only (a penetrating pose has no contact cone, and has
already failed penetration).
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import paths
from .crosscheck_ccd import point_triangle_distance

# The checkout's thresholds; an installed wheel carries a copy (python/CMakeLists.txt).
THRESHOLDS = paths.REPO_ROOT / "harness" / "oracle.toml"
if not THRESHOLDS.exists():
    THRESHOLDS = Path(__file__).resolve().parent / "data" / "oracle.toml"

CHECKS = [
    ("penetration", "1. penetration of the displayed poses"),
    ("tunnelling", "2. tunnelling between successive poses"),
    ("force_at_distance", "3. force at a distance"),
    ("force_direction", "4. force outside the contact cone"),
    ("no_force_when_free", "5. force in free space or moving away"),
    ("energy", "6. energy (passivity)"),
    ("force_jumps", "7. force jumps"),
    ("wrench_sanity", "7. non-finite or over-limit wrench"),
    ("cost", "8. cost (step time)"),
]


def added_per_tick(V: np.ndarray) -> np.ndarray:
    """What each tick adds to the vector of the tick before (force or torque rows of V, shape (n,
    3)): min over a in [0, 1] of |V[k+1] - a V[k]|, the distance of the new vector from the segment
    [0, V[k]]. A release, whole or in part (a contact that breaks, a force that shrinks along
    itself), adds nothing; a force that appears, grows, or turns adds the rest. Shape (n - 1,)."""
    prev, cur = V[:-1], V[1:]
    pp = np.einsum("ij,ij->i", prev, prev)
    a = np.clip(np.einsum("ij,ij->i", cur, prev) / np.where(pp > 0, pp, 1.0), 0.0, 1.0)
    return np.linalg.norm(cur - a[:, None] * prev, axis=1)


def load_thresholds(path=None) -> dict:
    """The thresholds file (default harness/oracle.toml): a regular file (paths.read_input_text),
    valid TOML, not empty; ValueError naming the file otherwise."""
    from .paths import read_input_text

    path = Path(path or THRESHOLDS)
    try:
        thresholds = tomllib.loads(read_input_text(path, "thresholds file", 1 << 20))
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{path}: not valid TOML: {e}") from None
    if not thresholds:
        raise ValueError(f"{path}: the thresholds file is empty (no setting): give the file to judge by, "
                         "or none for the defaults")
    return thresholds


@dataclass
class Verdict:
    name: str
    title: str
    passed: bool
    count: int               # violating ticks (or poses, steps, episodes: see unit)
    worst: float             # the worst value (see unit); 0 when nothing was measured
    unit: str
    first_time: float | None  # s, the first violation
    note: str = ""
    details: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"name": self.name, "title": self.title, "pass": self.passed, "count": int(self.count),
                "worst": _num(self.worst), "unit": self.unit, "first_time": _num(self.first_time),
                "note": self.note, "details": {k: _num(v) for k, v in self.details.items()}}


def _num(v):
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else str(float(v))
    return v


@dataclass
class OracleResult:
    verdicts: list
    series: dict             # per tick arrays for the plots: t, separation, cone_distance, energy, ...
    phases: list             # (name, start)

    @property
    def passed(self) -> bool:
        return all(v.passed for v in self.verdicts)

    def verdict(self, name: str) -> Verdict:
        return next(v for v in self.verdicts if v.name == name)

    def failed(self) -> list[str]:
        return [v.name for v in self.verdicts if not v.passed]


# ---------------------------------------------------------------------------------------------
# Small geometry helpers (numpy, floating point: only for estimates and the cone, never a verdict
# that hinges on contact).

def rotation_matrices(q: np.ndarray) -> np.ndarray:
    """R(q / |q|) for quaternions (n, 4) = (w, x, y, z): (n, 3, 3)."""
    q = np.atleast_2d(q)
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    n = w * w + x * x + y * y + z * z
    R = np.empty((len(q), 3, 3))
    R[:, 0, 0] = w * w + x * x - y * y - z * z
    R[:, 0, 1] = 2 * (x * y - w * z)
    R[:, 0, 2] = 2 * (x * z + w * y)
    R[:, 1, 0] = 2 * (x * y + w * z)
    R[:, 1, 1] = w * w - x * x + y * y - z * z
    R[:, 1, 2] = 2 * (y * z - w * x)
    R[:, 2, 0] = 2 * (x * z - w * y)
    R[:, 2, 1] = 2 * (y * z + w * x)
    R[:, 2, 2] = w * w - x * x - y * y + z * z
    return R / n[:, None, None]


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def pose_difference(pa, qa, pb, qb) -> np.ndarray:
    """xa (-) xb = (pa - pb, rotation vector of qa conj(qb), shortest way round): (n, 6)."""
    qa = qa / np.linalg.norm(qa, axis=-1, keepdims=True)
    qb = qb / np.linalg.norm(qb, axis=-1, keepdims=True)
    conj = qb * np.array([1.0, -1, -1, -1])
    r = quat_mul(qa, conj)
    r = np.where(r[..., :1] < 0, -r, r)
    s = np.linalg.norm(r[..., 1:], axis=-1)
    angle = 2 * np.arctan2(s, r[..., 0])
    scale = np.where(s > 1e-300, angle / np.maximum(s, 1e-300), 2.0)
    return np.concatenate([pa - pb, r[..., 1:] * scale[..., None]], axis=-1)


def point_mesh_distance(P: np.ndarray, V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unsigned distance from points (n, 3) to a triangle mesh's surface (floating point)."""
    out = np.full(len(P), np.inf)
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    chunk = max(1, 2_000_000 // max(len(F), 1))
    for i in range(0, len(P), chunk):
        out[i:i + chunk] = np.asarray(point_triangle_distance(P[i:i + chunk, None, :], A, B, C)).min(axis=1)
    return out


def winding_inside(P: np.ndarray, V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Points (n, 3) inside a closed mesh: generalised winding number > 1/2 (floating point)."""
    inside = np.zeros(len(P), bool)
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    chunk = max(1, 2_000_000 // max(len(F), 1))
    for i in range(0, len(P), chunk):
        X = P[i:i + chunk, None, :]
        a, b, c = A[None] - X, B[None] - X, C[None] - X
        la, lb, lc = (np.linalg.norm(v, axis=-1) for v in (a, b, c))
        num = np.einsum("nmk,nmk->nm", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("nmk,nmk->nm", a, b) * lc + np.einsum("nmk,nmk->nm", b, c) * la
               + np.einsum("nmk,nmk->nm", c, a) * lb)
        inside[i:i + chunk] = np.abs(np.arctan2(num, den).sum(axis=1) / (2 * np.pi)) > 0.5
    return inside


def _nnls(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    from scipy.optimize import nnls

    return nnls(A, b, maxiter=50 * max(A.shape[1], 1))[0]


# ---------------------------------------------------------------------------------------------

class Oracle:
    """The checks of one scene: its exact mesh pairs (reference), contact generation, mass."""

    def __init__(self, scene_path, thresholds: dict | None = None):
        from ._gauss6 import ccd, load_scene as _load_scene, oracle as _oracle, runtime

        self.scene_path = str(scene_path)
        self.thresholds = thresholds or load_thresholds()
        g = runtime.scene_geometry(self.scene_path)
        settings = runtime.effective_settings(_load_scene(self.scene_path))
        self.delta = float(g["delta"])
        self.mass = float(g["mass"])
        self.inertia = np.asarray(g["inertia_G_B"], float)
        self.max_force = float(g["max_force"])
        self.max_torque = float(settings["device"]["max_torque"])
        self.rate_hz = float(g["rate_hz"])
        self.god_V = np.asarray(g["god_V"], float)
        self.god_F = np.asarray(g["god_F"], np.int32)
        self.god_radius = float(np.linalg.norm(self.god_V, axis=1).max())
        self.obstacles = [(name, np.asarray(V, float), np.asarray(F, np.int32)) for name, V, F in g["obstacles"]]
        self.pairs = [ccd.MeshPair(V, F, self.god_V, self.god_F) for _, V, F in self.obstacles]
        self.boxes = [(V.min(axis=0), V.max(axis=0)) for _, V, _ in self.obstacles]
        self.contacts = _oracle.ContactGenerator(self.scene_path)

    # -- exact geometry -------------------------------------------------------------------------
    def intersecting_pairs(self, p, q) -> int:
        return sum(int(mp.count_intersecting_pairs(p, q)) for mp in self.pairs)

    def separation(self, p, q, max_distance: float) -> float:
        """The exact minimum distance (its lower double bracket) if <= max_distance, else +inf."""
        best = math.inf
        for mp in self.pairs:
            s = mp.separation(p, q, max_distance)
            if s["within"]:
                best = min(best, float(s["lower"]))
        return best

    def separation_side(self, p, q, bound: float, free_space: float) -> tuple[float, bool]:
        """The separation at a pose as far as checks 3-5 need it: a value whose side of `bound`
        and of `free_space` is the exact separation's (<= bound; in (bound, free_space]; +inf
        beyond free_space), and whether the exact path was needed. The reference's certified
        bracket lower <= d <= upper (intervals, no exact arithmetic) decides when neither
        threshold lies inside it; the value is then the bracket's lower end. Otherwise the exact
        separation decides (separation)."""
        lower, upper = math.inf, math.inf
        for mp in self.pairs:
            lo, hi = mp.separation_bracket(p, q, 2 * free_space)
            lower, upper = min(lower, lo), min(upper, hi)
        if upper <= bound:
            return lower, False
        if lower > bound and upper <= free_space:
            return lower, False
        if lower > free_space:
            return math.inf, False
        s = self.separation(p, q, bound)
        if not math.isfinite(s):
            s = self.separation(p, q, free_space)
        return s, True

    def depth_estimate(self, p, q) -> float:
        """The deepest tool vertex inside an obstacle: its distance to that obstacle (floating point)."""
        X = (rotation_matrices(np.asarray(q, float))[0] @ self.god_V.T).T + np.asarray(p, float)
        depth = 0.0
        for (_, V, F), (lo, hi) in zip(self.obstacles, self.boxes):
            cand = X[np.all((X > lo) & (X < hi), axis=1)]
            if len(cand):
                inner = cand[winding_inside(cand, V, F)]
                if len(inner):
                    depth = max(depth, float(point_mesh_distance(inner, V, F).max()))
        return depth

    def mass_matrix(self, q) -> np.ndarray:
        R = rotation_matrices(np.asarray(q, float))[0]
        M = np.zeros((6, 6))
        M[:3, :3] = self.mass * np.eye(3)
        M[3:, 3:] = R @ self.inertia @ R.T
        return M

    # -- the judgement --------------------------------------------------------------------------
    def nearest_rows(self, p, q, clearance: float) -> np.ndarray:
        """The contact wrenches J (k, 6) of the features nearest to the tool at pose (p, q), for Fig.
        13's measure (oracle.toml [direction] nearest_band): gauss6's contact generation within
        clearance + nearest_band delta, clearance being the pose's own separation (free) or
        penetration depth (estimate)."""
        band = self.thresholds["direction"]["nearest_band"] * self.delta
        return np.asarray(self.contacts.contacts(p, q, max(clearance, 0.0) + band)["J"], float)

    def tangential_share(self, q, wrench, J) -> tuple[float, int]:
        """The wrench's share outside the span of the rows J, in the metric M^-1 at orientation q, and
        the rank of the rows. Sign-free (a span, not the cone): the crossing edges of a penetrating
        pose count either way. NaN without rows or force, and when the rows span every wrench (rank
        6: no tangential part can show)."""
        if len(J) == 0 or not np.linalg.norm(wrench) > 0:
            return math.nan, 0
        L = np.linalg.cholesky(self.mass_matrix(q))
        b = np.linalg.solve(L, wrench)
        A = np.linalg.solve(L, J.T)
        coef, _, rank, _ = np.linalg.lstsq(A, b, rcond=1e-9)
        if rank >= 6:
            return math.nan, int(rank)
        return float(np.linalg.norm(b - A @ coef) / np.linalg.norm(b)), int(rank)

    def judge(self, trace, progress=None, nearest_window=None) -> OracleResult:
        """Every check on a run. nearest_window (t0, t1): also the Fig. 13 series nearest_tangential
        (nearest_tangential_share at every tick with force there, penetrating poses included); off by
        default (a penetration depth estimate costs seconds a pose on the bunnies)."""
        th = self.thresholds
        delta = self.delta
        ticks = trace.ticks
        n = len(ticks)
        t = np.asarray(ticks["t"], float)
        xh_p, xh_q = np.asarray(ticks["xh_p"], float), np.asarray(ticks["xh_q"], float)
        xs_p, xs_q = np.asarray(ticks["xs_p"], float), np.asarray(ticks["xs_q"], float)
        W = np.asarray(ticks["wrench"], float)
        finite_pose = np.all(np.isfinite(xs_p), axis=1) & np.all(np.isfinite(xs_q), axis=1)
        finite_wrench = np.all(np.isfinite(W), axis=1)
        ok = finite_pose & finite_wrench
        f_norm = np.linalg.norm(np.where(finite_wrench[:, None], W[:, :3], 0), axis=1)
        tau_norm = np.linalg.norm(np.where(finite_wrench[:, None], W[:, 3:], 0), axis=1)
        forced = ok & ((f_norm > th["zero"]["force"]) | (tau_norm > th["zero"]["torque"]))
        phases = [(p["name"], float(p["start"])) for p in trace.meta.get("phases", [])]
        say = progress or (lambda *a: None)

        # Distinct displayed poses (consecutive ticks with the same pose share a verdict).
        X = np.hstack([xs_p, xs_q])
        new_pose = np.ones(n, bool)
        new_pose[1:] = np.any(X[1:] != X[:-1], axis=1)
        pose_id = np.cumsum(new_pose) - 1
        first_tick = np.flatnonzero(new_pose)
        pose_ok = finite_pose[first_tick]
        verdicts = []

        # 1. Penetration: every distinct finite pose, exactly.
        counts = np.zeros(len(first_tick), np.int64)
        for j, k in enumerate(first_tick):
            if pose_ok[j]:
                counts[j] = self.intersecting_pairs(xs_p[k], xs_q[k])
            if j % 200 == 0:
                say("penetration", j, len(first_tick))
        penetrating_pose = counts > 0
        pen_tick = penetrating_pose[pose_id] & finite_pose
        depth = np.zeros(len(first_tick))
        pen_ids = np.flatnonzero(penetrating_pose)
        sample = pen_ids[np.unique(np.linspace(0, len(pen_ids) - 1, min(len(pen_ids), th["penetration"]["depth_sample"])
                                               ).astype(int))] if len(pen_ids) else pen_ids
        for j in sample:
            k = first_tick[j]
            depth[j] = self.depth_estimate(xs_p[k], xs_q[k])
        max_depth = float(depth.max()) if len(depth) else 0.0
        verdicts.append(Verdict(
            "penetration", CHECKS[0][1], int(penetrating_pose.sum()) <= th["penetration"]["max_poses"],
            int(penetrating_pose.sum()), max_depth / delta, "delta (depth estimate)",
            float(t[first_tick[pen_ids[0]]]) if len(pen_ids) else None,
            f"{len(first_tick)} distinct poses checked exactly; depth estimated on {len(sample)}",
            {"poses": len(first_tick), "penetrating_ticks": int(pen_tick.sum()),
             "max_intersecting_pairs": int(counts.max()) if len(counts) else 0, "max_depth": max_depth}))

        # 2. Tunnelling: successive free distinct poses; swept boxes, conservative CCD, exact.
        tt = th["tunnelling"]
        free_ids = [j for j in range(len(first_tick)) if pose_ok[j] and not penetrating_pose[j]]
        near = flagged = exact = undecided = 0
        tunnels: list = []
        flagged_steps = []
        for a, b in zip(free_ids[:-1], free_ids[1:]):
            if b != a + 1:
                continue  # a penetrating or non-finite pose between: judged by check 1 / 7
            k0, k1 = first_tick[a], first_tick[b]
            lo = np.minimum(xs_p[k0], xs_p[k1]) - self.god_radius
            hi = np.maximum(xs_p[k0], xs_p[k1]) + self.god_radius
            hit_pairs = []
            for i, (blo, bhi) in enumerate(self.boxes):
                if np.all(lo <= bhi) and np.all(hi >= blo):
                    hit_pairs.append(i)
            if not hit_pairs:
                continue
            near += 1
            stops = False
            for i in hit_pairs:
                r = self.pairs[i].step(xs_p[k0], xs_q[k0], xs_p[k1], xs_q[k1], tt["min_separation"] * delta)
                if r["hit"] or r["status"] not in ("ok",):
                    stops = True
                    break
            if stops:
                flagged += 1
                flagged_steps.append((k0, k1, hit_pairs))
        if flagged_steps:
            chosen = np.unique(np.linspace(0, len(flagged_steps) - 1,
                                           min(len(flagged_steps), tt["max_exact"])).astype(int))
        else:
            chosen = np.zeros(0, int)
        for c, idx in enumerate(chosen):
            k0, k1, hit_pairs = flagged_steps[idx]
            say("tunnelling", c, len(chosen))
            try:
                hit = any(self.pairs[i].exact_first_contact(xs_p[k0], xs_q[k0], xs_p[k1], xs_q[k1]).hit
                          for i in hit_pairs)
            except Exception:  # a half turn: no Cayley motion; undecided
                undecided += 1
                continue
            exact += 1
            if hit:
                tunnels.append(k1)
        undecided += len(flagged_steps) - len(chosen)
        tunnel_travel = [float(np.linalg.norm(xs_p[k] - xs_p[first_tick[pose_id[k] - 1]])) for k in tunnels]
        verdicts.append(Verdict(
            "tunnelling", CHECKS[1][1], not tunnels and undecided == 0, len(tunnels),
            max(tunnel_travel) / delta if tunnel_travel else 0.0, "delta (step length)",
            float(t[tunnels[0]]) if tunnels else None,
            f"{max(len(free_ids) - 1, 0)} steps between free poses; {near} near an obstacle (swept boxes); "
            f"{flagged} stopped by the conservative CCD; {exact} decided exactly; {undecided} undecided",
            {"steps": max(len(free_ids) - 1, 0), "near": near, "ccd_flagged": flagged, "exact": exact,
             "undecided": undecided}))

        # Separation at the forced free poses (checks 3-5), decided against the two thresholds by
        # the reference's certified interval bracket, and exactly only when a threshold falls
        # inside the bracket (separation_side).
        bound, free_space = th["distance"]["bound"] * delta, th["distance"]["free_space"] * delta
        sep = np.full(n, np.nan)
        judged = forced & ~pen_tick
        cache: dict = {}
        exact_separations = 0
        for c, k in enumerate(np.flatnonzero(judged)):
            j = pose_id[k]
            if j not in cache:
                cache[j], was_exact = self.separation_side(xs_p[k], xs_q[k], bound, free_space)
                exact_separations += was_exact
            sep[k] = cache[j]
            if c % 500 == 0:
                say("separation", c, int(judged.sum()))
        at_distance = judged & (sep > bound) & (sep <= free_space)
        in_free_space = judged & ~(sep <= free_space)
        ad = np.flatnonzero(at_distance)
        verdicts.append(Verdict(
            "force_at_distance", CHECKS[2][1], len(ad) == 0, len(ad),
            float(np.nanmax(sep[ad])) / delta if len(ad) else 0.0, "delta (separation)",
            float(t[ad[0]]) if len(ad) else None,
            f"bound {th['distance']['bound']:g} delta; {int(judged.sum())} ticks with force at free poses "
            f"({len(cache)} distinct poses: {len(cache) - exact_separations} decided by the certified bracket, "
            f"{exact_separations} exactly)",
            {"ticks_with_force": int(judged.sum()), "exact_separations": exact_separations,
             "max_separation_with_force": float(np.nanmax(np.where(sep <= free_space, sep, np.nan)))
             if np.any(sep <= free_space) else 0.0}))

        # 4-5. The cone of contact wrenches at the forced free poses within the bound.
        in_band = judged & (sep <= bound)
        cone = np.full(n, np.nan)
        tangential = np.full(n, np.nan)
        wrong = np.full(n, np.nan)
        away = np.zeros(n, bool)
        margin = th["moving_away"]["margin"] * delta
        diff = pose_difference(xh_p, xh_q, xs_p, xs_q)
        no_contacts = 0
        for c, k in enumerate(np.flatnonzero(in_band)):
            cs = self.contacts.contacts(xs_p[k], xs_q[k], bound)
            J = np.asarray(cs["J"], float)
            M = self.mass_matrix(xs_q[k])
            L = np.linalg.cholesky(M)
            b = np.linalg.solve(L, W[k])
            nb = np.linalg.norm(b)
            if len(J) == 0:
                no_contacts += 1
                cone[k] = tangential[k] = 1.0
                wrong[k] = 0.0
                continue
            A = np.linalg.solve(L, J.T)
            lam = _nnls(A, b)
            r = b - A @ lam
            proj = A @ np.linalg.lstsq(A, r, rcond=None)[0]
            cone[k] = np.linalg.norm(r) / nb
            wrong[k] = np.linalg.norm(proj) / nb
            tangential[k] = np.linalg.norm(r - proj) / nb
            away[k] = bool(np.all(J @ diff[k] >= margin))
            if c % 500 == 0:
                say("force cone", c, int(in_band.sum()))
        td = th["direction"]
        bad_dir = in_band & ((tangential > td["max_tangential_share"]) | (wrong > td["max_wrong_side_share"]))
        bd = np.flatnonzero(bad_dir)
        verdicts.append(Verdict(
            "force_direction", CHECKS[3][1], len(bd) == 0, len(bd),
            float(np.nanmax(cone)) if np.any(in_band) else 0.0, "share of |F| (M^-1 metric)",
            float(t[bd[0]]) if len(bd) else None,
            f"{int(in_band.sum())} ticks with force within {th['distance']['bound']:g} delta; "
            f"max tangential {np.nanmax(tangential) if np.any(in_band) else 0:.3g}, "
            f"max wrong-side {np.nanmax(wrong) if np.any(in_band) else 0:.3g}"
            + (f"; {no_contacts} without contacts" if no_contacts else ""),
            {"ticks": int(in_band.sum()),
             "max_tangential_share": float(np.nanmax(tangential)) if np.any(in_band) else 0.0,
             "max_wrong_side_share": float(np.nanmax(wrong)) if np.any(in_band) else 0.0,
             "ticks_without_contacts": no_contacts}))

        # Fig. 13's measure at every tick with force in the window, penetrating or free (up to free_space).
        nearest = np.full(n, np.nan)
        nearest_rank = np.zeros(n, np.int64)
        if nearest_window is not None:
            rows_of: dict = {}
            chosen = forced & finite_pose & (t >= nearest_window[0]) & (t <= nearest_window[1])
            for c, k in enumerate(np.flatnonzero(chosen)):
                j = pose_id[k]
                if j not in rows_of:
                    if pen_tick[k]:
                        clearance = depth[j] if depth[j] > 0 else self.depth_estimate(xs_p[k], xs_q[k])
                    elif np.isfinite(sep[k]):
                        clearance = sep[k]
                    else:
                        clearance = None  # beyond free_space: no nearest features to speak of
                    rows_of[j] = None if clearance is None else self.nearest_rows(xs_p[k], xs_q[k], clearance)
                if rows_of[j] is not None:
                    nearest[k], nearest_rank[k] = self.tangential_share(xs_q[k], W[k], rows_of[j])
                if c % 500 == 0:
                    say("nearest features", c, int(chosen.sum()))

        free_bad = in_free_space | away
        fb = np.flatnonzero(free_bad)
        verdicts.append(Verdict(
            "no_force_when_free", CHECKS[4][1], len(fb) == 0, len(fb),
            float(max(f_norm[fb].max(), 0.0)) if len(fb) else 0.0, "N (force)",
            float(t[fb[0]]) if len(fb) else None,
            f"{int(in_free_space.sum())} ticks with force beyond {th['distance']['free_space']:g} delta; "
            f"{int(away.sum())} with the handle on the free side of every contact by "
            f"{th['moving_away']['margin']:g} delta",
            {"free_space_ticks": int(in_free_space.sum()), "moving_away_ticks": int(away.sum())}))

        # 6. Energy: passivity observer on the device port, run and contact episodes.
        from .driver import safe_wrench

        F_applied = np.array([safe_wrench(W[k], self.max_force, self.max_torque)[0] for k in range(n)]) \
            if n else np.zeros((0, 6))
        dx = pose_difference(xh_p[1:], xh_q[1:], xh_p[:-1], xh_q[:-1]) if n > 1 else np.zeros((0, 6))
        work = np.einsum("ij,ij->i", F_applied[:-1], dx) if n > 1 else np.zeros(0)
        # W(n) plus the energy stored in the coupling between the handle and the displayed tool, as a
        # spring: V = -1/2 F . (xh (-) xs) >= 0 (gauss6's F^T M^-1 F / (2 kh ks) for one contact; 0 for an
        # engine that displays the handle's pose).
        stored = np.maximum(0.0, -0.5 * np.einsum("ij,ij->i", F_applied, diff))
        energy = np.concatenate([[0.0], np.cumsum(work)]) + stored
        on = (np.linalg.norm(F_applied[:, :3], axis=1) > th["zero"]["force"]) | \
             (np.linalg.norm(F_applied[:, 3:], axis=1) > th["zero"]["torque"])
        episodes = []
        k = 0
        while k < n:
            if on[k]:
                e = k
                while e < n and on[e]:
                    e += 1
                episodes.append((k, e, float(work[k:min(e, n - 1)].sum())))
                k = e
            else:
                k += 1
        te = th["energy"]
        over_port = np.flatnonzero(energy > te["max_port_energy"])
        bad_eps = [ep for ep in episodes if ep[2] > te["max_episode_energy"]]
        firsts = ([float(t[over_port[0]])] if len(over_port) else []) + ([float(t[bad_eps[0][0]])] if bad_eps else [])
        max_episode = max((ep[2] for ep in episodes), default=0.0)
        verdicts.append(Verdict(
            "energy", CHECKS[5][1], not len(over_port) and not bad_eps, len(bad_eps) + (1 if len(over_port) else 0),
            float(max(energy.max() if n else 0.0, max_episode)), "J",
            min(firsts) if firsts else None,
            f"port energy max {energy.max() if n else 0:.3g} J, final {energy[-1] if n else 0:.3g} J; "
            f"{len(episodes)} contact episodes, max episode work {max_episode:.3g} J, "
            f"energy injected (positive episodes) {sum(max(ep[2], 0) for ep in episodes):.3g} J",
            {"port_energy_max": float(energy.max()) if n else 0.0, "port_energy_final": float(energy[-1]) if n else 0.0,
             "episodes": len(episodes), "max_episode_work": max_episode,
             "energy_injected": float(sum(max(ep[2], 0) for ep in episodes))}))

        # 7. Force jumps (the force a tick adds: a release adds none); non-finite and over-limit
        # wrenches. The whole change is reported beside it, with the time of the largest.
        tj = th["jumps"]
        both = finite_wrench[1:] & finite_wrench[:-1]
        Wf = np.where(finite_wrench[:, None], W, 0)
        df = np.where(both, np.linalg.norm(np.diff(Wf[:, :3], axis=0), axis=1), 0)
        dtau = np.where(both, np.linalg.norm(np.diff(Wf[:, 3:], axis=0), axis=1), 0)
        f_add = np.where(both, added_per_tick(Wf[:, :3]), 0)
        tau_add = np.where(both, added_per_tick(Wf[:, 3:]), 0)
        jumps = np.flatnonzero((f_add > tj["max_force_step"]) | (tau_add > tj["max_torque_step"])) + 1
        peak = {k: float(v.max()) if len(v) else 0.0
                for k, v in (("force_added", f_add), ("torque_added", tau_add), ("force_step", df), ("torque_step", dtau))}
        largest_time = float(t[int(np.argmax(df)) + 1]) if len(df) else None
        verdicts.append(Verdict(
            "force_jumps", CHECKS[6][1], len(jumps) == 0, len(jumps), peak["force_added"],
            "N added per tick", float(t[jumps[0]]) if len(jumps) else None,
            f"max force added {peak['force_added']:.3g} N, torque {peak['torque_added']:.3g} N m; "
            f"largest change {peak['force_step']:.3g} N"
            + (f" at {largest_time:.3f} s" if peak["force_step"] > 0 else "")
            + f", torque {peak['torque_step']:.3g} N m",
            {**{f"max_{k}": v for k, v in peak.items()}, "max_force_step_time": largest_time}))
        slack = 1 + th["limits"]["slack"]
        over = finite_wrench & ((f_norm > self.max_force * slack) | (tau_norm > self.max_torque * slack))
        insane = np.flatnonzero(~finite_wrench | ~finite_pose | over)
        verdicts.append(Verdict(
            "wrench_sanity", CHECKS[7][1], len(insane) == 0, len(insane),
            float(max(f_norm.max() / self.max_force, tau_norm.max() / self.max_torque)) if n else 0.0,
            "of the limit", float(t[insane[0]]) if len(insane) else None,
            f"{int((~finite_wrench).sum())} non-finite wrenches, {int((~finite_pose).sum())} non-finite poses, "
            f"{int(over.sum())} over the limits ({self.max_force:g} N, {self.max_torque:g} N m)",
            {"non_finite_wrench": int((~finite_wrench).sum()), "non_finite_pose": int((~finite_pose).sum()),
             "over_limit": int(over.sum())}))

        # 8. Cost.
        tc = th["cost"]
        st = np.asarray(ticks["force_time"], float)
        period = 1 / self.rate_hz
        med = float(np.median(st)) if n else 0.0
        p99 = float(np.percentile(st, 99)) if n else 0.0
        cost_ok = med <= tc["max_median_fraction_of_period"] * period and p99 <= tc["max_p99_seconds"]
        over_period = np.flatnonzero(st > period)
        verdicts.append(Verdict(
            "cost", CHECKS[8][1], cost_ok, len(over_period), float(st.max()) if n else 0.0, "s (max step)",
            float(t[over_period[0]]) if len(over_period) else None,
            f"median {med * 1e6:.1f} us (sustains {1 / med if med > 0 else math.inf:.0f} Hz), p99 {p99 * 1e3:.3g} ms, "
            f"{len(over_period)} steps over the {period * 1e3:g} ms tick",
            {"median_seconds": med, "p99_seconds": p99, "max_seconds": float(st.max()) if n else 0.0,
             "sustained_hz": 1 / med if med > 0 else None, "steps_over_period": len(over_period)}))

        signed = np.where(pen_tick, -depth[pose_id], sep)
        series = {"t": t, "separation": signed / delta, "cone_distance": cone, "nearest_tangential": nearest,
                  "nearest_rank": nearest_rank,
                  "energy": energy,
                  "force": f_norm, "penetrating": pen_tick, "step_seconds": st}
        return OracleResult(verdicts, series, phases)
