"""The validation oracle: judges a run of any engine (a gauss6 trace: the driver's recording, or a
run the engine recorded itself) against the scene's true meshes, with every geometric verdict
decided by the exact reference through the path `gauss6 certify` uses (exact_checks.ExactScene;
docs/engine-contract.md, "The checks").

    oracle = Oracle("datasets_generated/scenes/peg_in_hole.toml")
    result = oracle.judge(read_trace("run.g6trace"))   # an OracleResult: verdicts and time series

The checks are a table (CHECK_TABLE): one small function a check, each reading its thresholds from
its section of harness/oracle.toml and the run's shared quantities from a RunData (the distinct
poses, the exact penetration of each, the separations and contact cones of the forced poses,
computed once, on first use):
  penetration          every displayed pose, exactly
  tunnelling           the in-between motion (METHOD.md s.4) between successive free displayed poses
  force_at_distance    a wrench at a free pose whose exact separation exceeds the bound (a declared
                       skin widens it)
  force_direction      the wrench's distance from the cone of contact wrenches, metric M^-1; with a
                       declared Coulomb friction mu, the friction cone and maximal dissipation instead
  no_force_when_free   a wrench in free space, or while the handle is on the free side of every
                       contact (METHOD.md property 3)
  energy               passivity observer on the device port (Hannaford and Ryu 2002): the energy the
                       user has put in, which may not go below zero beyond what the device's own
                       damping absorbs (Colgate and Schenkel); no model of the engine
  force_jumps          the force (torque) a tick adds beyond what the handle's motion explains at the
                       scene's coupling
  wrench_sanity        non-finite or over-limit wrenches and poses
  tracking             in free space, with nothing between tool and hand, the displayed pose lies in the
                       hull of the handle's recent poses
  latency              ticks from the handle's crossing into an obstacle to the force's response,
                       against the declared latency
  cost                 deadlines: the driver's timing of each step call against the haptic period,
                       with an allowance for the machine measured from gauss6's own engine
The engine's declarations (trace metadata extra["declarations"]: friction {mu}, latency_ticks, skin
in metres) change what checks 3, 4 and the latency judge; the report states them. Every failed check
names its first and worst violating ticks (Verdict.violations), which witness.py writes as files
that `gauss6 certify --witness` re-checks. Geometric checks skip ticks with a non-finite pose or
wrench (wrench_sanity names them); the force checks (3-5) judge free poses only.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np

from .crosscheck_ccd import point_triangle_distance
from .exact_checks import ExactScene
from .thresholds import load_thresholds

def added_per_tick(V: np.ndarray) -> np.ndarray:
    """What each tick adds to the vector of the tick before (force or torque rows of V, shape (n,
    3)): min over a in [0, 1] of |V[k+1] - a V[k]|, the distance of the new vector from the segment
    [0, V[k]]. A release, whole or in part (a contact that breaks, a force that shrinks along
    itself), adds nothing; a force that appears, grows, or turns adds the rest. Shape (n - 1,)."""
    prev, cur = V[:-1], V[1:]
    pp = np.einsum("ij,ij->i", prev, prev)
    a = np.clip(np.einsum("ij,ij->i", cur, prev) / np.where(pp > 0, pp, 1.0), 0.0, 1.0)
    return np.linalg.norm(cur - a[:, None] * prev, axis=1)


def unexplained_per_tick(W: np.ndarray, dx: np.ndarray, mass: float, inertia: np.ndarray, kh: float,
                         ks: float, limits=(1.0, 1.0)) -> tuple[np.ndarray, np.ndarray]:
    """The wrench each tick adds beyond what the handle's motion over that tick explains at the
    scene's stiffness (oracle.toml [jumps], version 6): (force N, torque N m), shape (n - 1,) each.

    W (n, 6): the wrenches; dx (n - 1, 6): the handle's motion over each tick, xh(k+1) (-) xh(k);
    inertia (n - 1, 3, 3): the tool's world-frame inertia about G at each tick's end (M = diag(m I3,
    I_G)). With the god-object and its constraints held, the coupling's wrench is W = -kh M Q(au),
    au = ks (xh (-) xs), Q the M-metric projection onto the polar of the contacts' (offset)
    constraints (METHOD.md s.3: Fc = kh M (ac - au), ac = au - Q(au)). A projection onto a closed
    convex set is firmly non-expansive, |Q(a + d) - Q(a)|_M^2 <= <Q(a + d) - Q(a), d>_M: the change
    z = Q(a + d) - Q(a) lies in the M-ball whose diameter is [0, d], d = ks dx. So the handle's
    motion explains, through any contacts whatever, the wrench changes -kh M z of that ball: the ball
    of centre c = -kh ks M dx / 2 and radius kh ks |dx|_M / 2 in the metric M^-1. Beside it, a
    release of the last tick's wrench explains -s W(k), s in [0, 1], each part its own s (as
    added_per_tick). The residual: the observed change less the nearest point of the release plus
    the ball (M^-1), its force and torque parts returned. The torque's release is taken at its
    Euclidean nearest (at rest this is added_per_tick exactly) and at its I^-1 nearest (which makes
    the joint M^-1 distance least), keeping the one whose residual is smaller against `limits`
    (force, torque): each is a point of what the hand and a release explain, so the residual is never
    below the true one. A handle at rest explains nothing; a change along the push that outgrows the
    handle's motion keeps its excess at any hand speed."""
    prev = W[:-1]
    M_dx = np.concatenate([mass * dx[:, :3], np.einsum("nij,nj->ni", inertia, dx[:, 3:])], axis=1)
    u = np.diff(W, axis=0) + kh * ks * M_dx / 2
    dx_M = np.sqrt(np.maximum(np.einsum("ij,ij->i", dx, M_dx), 0.0))
    radius = kh * ks * dx_M / 2

    def released(a, b, G=None):  # a + s b, s in [0, 1] nearest 0 in the metric G (Euclidean if None)
        Gb = b if G is None else np.linalg.solve(G, b[..., None])[..., 0]
        bb = np.einsum("ij,ij->i", b, Gb)
        s = np.clip(-np.einsum("ij,ij->i", a, Gb) / np.where(bb > 0, bb, 1.0), 0.0, 1.0)
        return a + s[:, None] * b

    f_part = released(u[:, :3], prev[:, :3])
    best = None
    for G in (None, inertia):
        v = np.concatenate([f_part, released(u[:, 3:], prev[:, 3:], G)], axis=1)
        v_Minv = np.sqrt(np.einsum("ij,ij->i", v[:, :3], v[:, :3]) / mass
                         + np.einsum("ni,ni->n", v[:, 3:], np.linalg.solve(inertia, v[:, 3:, None])[..., 0]))
        keep = np.where(v_Minv > radius, 1.0 - radius / np.where(v_Minv > 0, v_Minv, 1.0), 0.0)
        f, tau = np.linalg.norm(v[:, :3], axis=1) * keep, np.linalg.norm(v[:, 3:], axis=1) * keep
        if best is None:
            best = (f, tau)
        else:
            better = np.maximum(f / limits[0], tau / limits[1]) < np.maximum(best[0] / limits[0], best[1] / limits[1])
            best = (np.where(better, f, best[0]), np.where(better, tau, best[1]))
    return best


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
    # The first and the worst violation: {"first": {"tick": k, ...}, "worst": {...}}, each with what a
    # witness file needs beyond the tick's row (the motion's end ticks, an energy window, ...).
    violations: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"name": self.name, "title": self.title, "pass": self.passed, "count": int(self.count),
                "worst": _num(self.worst), "unit": self.unit, "first_time": _num(self.first_time),
                "note": self.note, "details": {k: _num(v) for k, v in self.details.items()},
                "violations": {k: {kk: _num(vv) for kk, vv in v.items()} for k, v in self.violations.items()}}


def _num(v):
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else str(float(v))
    if isinstance(v, (list, tuple)):
        return [_num(x) for x in v]
    return v


@dataclass
class OracleResult:
    verdicts: list
    series: dict             # per tick arrays for the plots: t, separation, cone_distance, energy, ...
    phases: list             # (name, start)
    declarations: dict = field(default_factory=dict)   # what the engine declared (and was judged by)
    calibration: dict = field(default_factory=dict)    # the deadlines' machine allowance (calibrate())

    @property
    def passed(self) -> bool:
        return all(v.passed for v in self.verdicts)

    def verdict(self, name: str) -> Verdict:
        return next(v for v in self.verdicts if v.name == name)

    def failed(self) -> list[str]:
        return [v.name for v in self.verdicts if not v.passed]


def declarations(trace) -> dict:
    """The engine's declarations from the trace's metadata (extra["declarations"]), checked: friction
    {"mu": finite >= 0}, latency_ticks (integer >= 0), skin (metres, finite >= 0); {} when none. A
    malformed declaration is a ValueError naming the field."""
    extra = trace.meta.get("extra") if isinstance(trace.meta.get("extra"), dict) else {}
    d = extra.get("declarations") or {}
    if not isinstance(d, dict):
        raise ValueError("trace metadata extra.declarations: not an object")
    out = {}
    if d.get("friction"):
        mu = d["friction"].get("mu") if isinstance(d["friction"], dict) else None
        if isinstance(mu, bool) or not isinstance(mu, (int, float)) or not math.isfinite(mu) or mu < 0:
            raise ValueError(f"trace metadata extra.declarations.friction.mu: {mu!r} is not a finite number >= 0")
        out["friction"] = {"mu": float(mu)}
    if d.get("latency_ticks") is not None:
        L = d["latency_ticks"]
        if isinstance(L, bool) or not isinstance(L, int) or L < 0:
            raise ValueError(f"trace metadata extra.declarations.latency_ticks: {L!r} is not an integer >= 0")
        out["latency_ticks"] = L
    if d.get("skin") is not None:
        s = d["skin"]
        if isinstance(s, bool) or not isinstance(s, (int, float)) or not math.isfinite(s) or s < 0:
            raise ValueError(f"trace metadata extra.declarations.skin: {s!r} is not a finite length >= 0 (m)")
        out["skin"] = float(s)
    return out


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


def deepest_inside(P: np.ndarray, V: np.ndarray, F: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """The largest distance to a closed mesh's surface of the points (n, 3) inside it (0 if none);
    lo, hi: the mesh's bounding box, which rules out most points at once (floating point)."""
    cand = P[np.all((P > lo) & (P < hi), axis=1)]
    inner = cand[winding_inside(cand, V, F)] if len(cand) else cand
    return float(point_mesh_distance(inner, V, F).max()) if len(inner) else 0.0


def friction_generators(r: np.ndarray, N: np.ndarray, mu: float, sides: int) -> np.ndarray:
    """The contact wrenches (k * sides, 6) spanning the Coulomb friction cones of contacts at r (from
    G, (k, 3)) with normals N (k, 3), coefficient mu: each cone by the pyramid of `sides` edges
    n + mu' t_j circumscribed about it (mu' = mu / cos(pi / sides)), so that the pyramid holds the
    whole cone (its excess over the cone is the test's resolution); wrench (d, r x d)."""
    rows = []
    mu_c = mu / math.cos(math.pi / sides)
    for ri, n in zip(r, N):
        a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
        u = np.cross(n, a)
        u /= np.linalg.norm(u)
        v = np.cross(n, u)
        for j in range(sides):
            th = 2 * math.pi * j / sides
            d = n + mu_c * (math.cos(th) * u + math.sin(th) * v)
            rows.append(np.concatenate([d, np.cross(ri, d)]))
    return np.asarray(rows).reshape(-1, 6)


def _nnls(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    from scipy.optimize import nnls

    return nnls(A, b, maxiter=50 * max(A.shape[1], 1))[0]


# ---------------------------------------------------------------------------------------------
# What the checks read: the run's arrays, and the quantities several checks share, each computed
# once on first use.

def _first_worst(ticks: np.ndarray, values: np.ndarray, **extra) -> dict:
    """The violations entry of a verdict: the first violating tick and the worst (largest value)."""
    if len(ticks) == 0:
        return {}
    w = int(ticks[int(np.nanargmax(values))]) if np.any(np.isfinite(values)) else int(ticks[0])
    return {"first": {"tick": int(ticks[0]), **extra}, "worst": {"tick": w, **extra}}


class RunData:
    """One run as the checks see it (the trace's tick records as float arrays, the declarations,
    the machine calibration) with the shared quantities as cached properties."""

    def __init__(self, oracle: "Oracle", trace, progress=None, calibration=None, nearest_window=None):
        self.o = oracle
        self.th = oracle.thresholds
        self.delta = oracle.delta
        self.trace = trace
        ticks = trace.ticks
        self.n = n = len(ticks)
        self.t = np.asarray(ticks["t"], float)
        self.xh_p, self.xh_q = np.asarray(ticks["xh_p"], float), np.asarray(ticks["xh_q"], float)
        self.xs_p, self.xs_q = np.asarray(ticks["xs_p"], float), np.asarray(ticks["xs_q"], float)
        self.W = np.asarray(ticks["wrench"], float)
        # A displayed pose is sane when finite, with a non-zero quaternion, and within pose_extent scene
        # radii of the scene's centre (a pose of 1e300 is finite but no pose): the others are left to
        # wrench_sanity, which names them.
        with np.errstate(invalid="ignore", over="ignore"):
            self.finite_pose = (np.all(np.isfinite(self.xs_p), axis=1) & np.all(np.isfinite(self.xs_q), axis=1)
                                & np.any(self.xs_q != 0, axis=1)
                                & (np.linalg.norm(self.xs_p - oracle.centre, axis=1)
                                   <= self.th["limits"]["pose_extent"] * oracle.scene_radius))
        self.finite_handle = np.all(np.isfinite(self.xh_p), axis=1) & np.all(np.isfinite(self.xh_q), axis=1)
        self.finite_wrench = np.all(np.isfinite(self.W), axis=1)
        self.ok = self.finite_pose & self.finite_wrench
        Wf = np.where(self.finite_wrench[:, None], self.W, 0)
        self.f_norm = np.linalg.norm(Wf[:, :3], axis=1)
        self.tau_norm = np.linalg.norm(Wf[:, 3:], axis=1)
        zero = self.th["zero"]
        self.forced = self.ok & ((self.f_norm > zero["force"]) | (self.tau_norm > zero["torque"]))
        self.phases = [(p["name"], float(p["start"])) for p in trace.meta.get("phases", [])]
        self.say = progress or (lambda *a: None)
        self.declared = declarations(trace)
        self.calibration = calibration
        self.nearest_window = nearest_window
        # The separation bound of checks 3-4 (delta units): a declared skin widens it by the skin.
        self.bound_delta = self.th["distance"]["bound"] + self.declared.get("skin", 0.0) / self.delta
        # Distinct displayed poses (consecutive ticks with the same pose share a verdict).
        X = np.hstack([self.xs_p, self.xs_q])
        new_pose = np.ones(n, bool)
        new_pose[1:] = np.any(X[1:] != X[:-1], axis=1)
        self.pose_id = np.cumsum(new_pose) - 1
        self.first_tick = np.flatnonzero(new_pose)
        self.pose_ok = self.finite_pose[self.first_tick]

    def phase_at(self, time: float) -> str:
        name = ""
        for p, start in self.phases:
            if start <= time:
                name = p
        return name

    @functools.cached_property
    def penetration(self) -> dict:
        """Per distinct pose: exactly intersecting triangle pairs; per tick: penetrating; the depth
        estimate on a sample of the penetrating poses."""
        o, ft = self.o, self.first_tick
        counts = np.zeros(len(ft), np.int64)
        for j, k in enumerate(ft):
            if self.pose_ok[j]:
                counts[j] = o.exact.intersecting_pairs(self.xs_p[k], self.xs_q[k])
            if j % 200 == 0:
                self.say("penetration", j, len(ft))
        pen = counts > 0
        depth = np.zeros(len(ft))
        ids = np.flatnonzero(pen)
        sample = ids[np.unique(np.linspace(0, len(ids) - 1, min(len(ids), self.th["penetration"]["depth_sample"])
                                           ).astype(int))] if len(ids) else ids
        for j in sample:
            depth[j] = o.depth_estimate(self.xs_p[ft[j]], self.xs_q[ft[j]])
        return {"counts": counts, "pose": pen, "tick": pen[self.pose_id] & self.finite_pose, "depth": depth,
                "sample": sample}

    @functools.cached_property
    def separations(self) -> dict:
        """The separation at the forced free ticks, decided against the bound and free_space by the
        certified bracket, exactly only when a threshold falls inside it (ExactScene.separation_side)."""
        bound, free_space = self.bound_delta * self.delta, self.th["distance"]["free_space"] * self.delta
        sep = np.full(self.n, np.nan)
        judged = self.forced & ~self.penetration["tick"]
        cache: dict = {}
        exact = 0
        for c, k in enumerate(np.flatnonzero(judged)):
            j = self.pose_id[k]
            if j not in cache:
                cache[j], was_exact = self.o.exact.separation_side(self.xs_p[k], self.xs_q[k], bound, free_space)
                exact += was_exact
            sep[k] = cache[j]
            if c % 500 == 0:
                self.say("separation", c, int(judged.sum()))
        return {"sep": sep, "judged": judged, "distinct": len(cache), "exact": exact,
                "in_band": judged & (sep <= bound), "in_free_space": judged & ~(sep <= free_space),
                "at_distance": judged & (sep > bound) & (sep <= free_space)}

    @functools.cached_property
    def diff(self) -> np.ndarray:
        """xh (-) xs per tick."""
        return pose_difference(self.xh_p, self.xh_q, self.xs_p, self.xs_q)

    @functools.cached_property
    def cone(self) -> dict:
        """At the forced free ticks within the bound: the wrench against the cone of contact wrenches
        {J^T lambda, lambda >= 0} of the pose's contacts (gauss6's contact generation within the bound),
        metric M^-1: the shares of the wrench outside the cone (cone), along the rows' span on the wrong
        side (wrong), outside the span (tangential), inside the cone (normal); the physical wrench of the
        tangential part (for maximal dissipation); whether the handle is on the free side of every row."""
        o, n = self.o, self.n
        in_band = self.separations["in_band"]
        out = {k: np.full(n, np.nan) for k in ("cone", "tangential", "wrong", "normal")}
        out["away"] = np.zeros(n, bool)
        out["tangential_wrench"] = np.zeros((n, 6))
        out["rows"] = np.zeros(n, np.int64)
        mu = self.declared.get("friction", {}).get("mu")
        out["friction"] = np.full(n, np.nan)
        out["tangential_force"] = np.zeros((n, 3))
        out["normals"] = [None] * n
        margin = self.th["moving_away"]["margin"] * self.delta
        no_contacts = 0
        for c, k in enumerate(np.flatnonzero(in_band)):
            cs = o.contacts.contacts(self.xs_p[k], self.xs_q[k], self.bound_delta * self.delta)
            J = np.asarray(cs["J"], float)
            L = np.linalg.cholesky(o.mass_matrix(self.xs_q[k]))
            b = np.linalg.solve(L, self.W[k])
            nb = np.linalg.norm(b)
            out["rows"][k] = len(J)
            if len(J) == 0:
                no_contacts += 1
                out["cone"][k] = out["tangential"][k] = out["friction"][k] = 1.0
                out["wrong"][k] = out["normal"][k] = 0.0
                out["tangential_wrench"][k] = self.W[k]
                continue
            A = np.linalg.solve(L, J.T)
            lam = _nnls(A, b)
            r = b - A @ lam
            proj = A @ np.linalg.lstsq(A, r, rcond=None)[0]
            out["cone"][k] = np.linalg.norm(r) / nb
            out["wrong"][k] = np.linalg.norm(proj) / nb
            out["tangential"][k] = np.linalg.norm(r - proj) / nb
            out["normal"][k] = np.linalg.norm(A @ lam) / nb
            out["tangential_wrench"][k] = L @ (r - proj)
            out["away"][k] = bool(np.all(J @ self.diff[k] >= margin))
            if mu is not None:
                N = np.asarray(cs["normals"], float)
                G = friction_generators(np.asarray(cs["points"], float) - self.xs_p[k], N, mu,
                                        self.th["direction"]["pyramid_sides"])
                Ag = np.linalg.solve(L, G.T)
                out["friction"][k] = np.linalg.norm(b - Ag @ _nnls(Ag, b)) / nb
                f = self.W[k, :3]
                out["tangential_force"][k] = f - N.T @ np.linalg.lstsq(N.T, f, rcond=None)[0]
                out["normals"][k] = N
            if c % 500 == 0:
                self.say("force cone", c, int(in_band.sum()))
        out["no_contacts"] = no_contacts
        out["in_band"] = in_band
        return out

    @functools.cached_property
    def applied(self) -> np.ndarray:
        """The wrench the device applied each tick (driver.safe_wrench: zero if not finite, each part
        scaled to the device's limit)."""
        from .driver import safe_wrench

        return np.array([safe_wrench(self.W[k], self.o.max_force, self.o.max_torque)[0] for k in range(self.n)]) \
            if self.n else np.zeros((0, 6))


# ---------------------------------------------------------------------------------------------
# The checks: each a function (RunData, its thresholds' section) -> Verdict, registered in
# CHECK_TABLE below.

def check_penetration(r: RunData, th: dict) -> Verdict:
    """Every distinct finite displayed pose, exactly: touching or intersecting fails."""
    P = r.penetration
    ids = np.flatnonzero(P["pose"])
    ticks = r.first_tick[ids]
    return Verdict(
        "penetration", "", len(ids) <= th["max_poses"], len(ids), float(P["depth"].max()) / r.delta if len(ids) else 0.0,
        "delta (depth estimate)", float(r.t[ticks[0]]) if len(ids) else None,
        f"{len(r.first_tick)} distinct poses checked exactly; depth estimated on {len(P['sample'])}"
        + (f" ({edges_only} of them cross by edges and faces only: no vertex of either body inside the other, "
           "depth not estimated)" if (edges_only := int((P["depth"][P["sample"]] == 0).sum())) else ""),
        {"poses": len(r.first_tick), "penetrating_ticks": int(P["tick"].sum()),
         "max_intersecting_pairs": int(P["counts"].max()) if len(P["counts"]) else 0,
         "max_depth": float(P["depth"].max()) if len(P["depth"]) else 0.0},
        _first_worst(ticks, P["counts"][ids].astype(float)))


def check_tunnelling(r: RunData, th: dict) -> Verdict:
    """The in-between motion between successive free distinct poses: swept boxes (ExactScene.near),
    gauss6's conservative CCD, then the exact first contact on every step the CCD stops."""
    o, ft, delta = r.o, r.first_tick, r.delta
    pen = r.penetration["pose"]
    free_ids = [j for j in range(len(ft)) if r.pose_ok[j] and not pen[j]]
    near_steps = flagged = exact = undecided = 0
    tunnels: list = []
    flagged_steps = []
    for a, b in zip(free_ids[:-1], free_ids[1:]):
        if b != a + 1:
            continue  # a penetrating or non-finite pose between: judged by penetration / wrench_sanity
        k0, k1 = ft[a], ft[b]
        near = o.exact.near(r.xs_p[k0], r.xs_p[k1])
        if not near:
            continue
        near_steps += 1
        for i in near:
            c = o.exact.pairs[i].step(r.xs_p[k0], r.xs_q[k0], r.xs_p[k1], r.xs_q[k1], th["min_separation"] * delta)
            if c["hit"] or c["status"] != "ok":
                flagged += 1
                flagged_steps.append((k0, k1, near))
                break
    chosen = np.unique(np.linspace(0, len(flagged_steps) - 1, min(len(flagged_steps), th["max_exact"])).astype(int)) \
        if flagged_steps else np.zeros(0, int)
    for c, idx in enumerate(chosen):
        k0, k1, near = flagged_steps[idx]
        r.say("tunnelling", c, len(chosen))
        try:
            hits = o.exact.motion_hits(r.xs_p[k0], r.xs_q[k0], r.xs_p[k1], r.xs_q[k1], near)
        except ValueError:  # a half turn: no Cayley motion; undecided
            undecided += 1
            continue
        exact += 1
        if hits:
            tunnels.append((k0, k1))
    undecided += len(flagged_steps) - len(chosen)
    travel = np.array([np.linalg.norm(r.xs_p[k1] - r.xs_p[k0]) for k0, k1 in tunnels])
    violations = {}
    if tunnels:
        w = tunnels[int(np.argmax(travel))]
        violations = {"first": {"tick": int(tunnels[0][1]), "from_tick": int(tunnels[0][0])},
                      "worst": {"tick": int(w[1]), "from_tick": int(w[0])}}
    return Verdict(
        "tunnelling", "", not tunnels and undecided == 0, len(tunnels),
        float(travel.max()) / delta if tunnels else 0.0, "delta (step length)",
        float(r.t[tunnels[0][1]]) if tunnels else None,
        f"{max(len(free_ids) - 1, 0)} steps between free poses; {near_steps} near an obstacle (swept boxes); "
        f"{flagged} stopped by the conservative CCD; {exact} decided exactly; {undecided} undecided",
        {"steps": max(len(free_ids) - 1, 0), "near": near_steps, "ccd_flagged": flagged, "exact": exact,
         "undecided": undecided}, violations)


def check_force_at_distance(r: RunData, th: dict) -> Verdict:
    """A wrench at a free pose whose exact separation exceeds the bound (plus a declared skin) but
    not free_space."""
    S = r.separations
    ad = np.flatnonzero(S["at_distance"])
    sep, free_space = S["sep"], th["free_space"] * r.delta
    skin = r.declared.get("skin")
    return Verdict(
        "force_at_distance", "", len(ad) == 0, len(ad), float(np.nanmax(sep[ad])) / r.delta if len(ad) else 0.0,
        "delta (separation)", float(r.t[ad[0]]) if len(ad) else None,
        f"bound {r.bound_delta:g} delta" + (f" (declared skin {skin:g} m + {th['bound']:g} delta)" if skin else "")
        + f"; {int(S['judged'].sum())} ticks with force at free poses ({S['distinct']} distinct poses: "
        f"{S['distinct'] - S['exact']} decided by the certified bracket, {S['exact']} exactly)",
        {"ticks_with_force": int(S["judged"].sum()), "exact_separations": S["exact"], "bound_delta": r.bound_delta,
         "max_separation_with_force": float(np.nanmax(np.where(sep <= free_space, sep, np.nan)))
         if np.any(sep <= free_space) else 0.0},
        _first_worst(ad, sep[ad], bound=r.bound_delta * r.delta))


def check_force_direction(r: RunData, th: dict) -> Verdict:
    """The wrench's distance from the cone of contact wrenches (M^-1 metric): its wrong-side share,
    and its tangential share. With a declared Coulomb friction mu the tangential share is judged by
    the friction cone instead (tangential <= mu x normal, to the cone test's resolution
    max_tangential_share), and by maximal dissipation: where the displayed tool slides, the
    tangential force may not drive the slide (cosine with the slide <= max_dissipation_cosine)."""
    C = r.cone
    ib = C["in_band"]
    mu = r.declared.get("friction", {}).get("mu")
    tol = th["max_tangential_share"]
    if mu is None:
        tangential_excess = C["tangential"] - tol
        slide_bad = np.zeros(r.n, bool)
    else:
        # The friction cone: the wrench's distance from the cone of the contacts' friction pyramids
        # (friction_generators), M^-1 metric, as a share of it; within the cone test's resolution.
        tangential_excess = C["friction"] - tol
        # Maximal dissipation: the slide of the displayed tool over the tick, in the contacts' tangent
        # space, against the tangential force (the force less its part in the normals' span).
        d = np.zeros((r.n, 3))
        d[:-1] = r.xs_p[1:] - r.xs_p[:-1]
        for k in np.flatnonzero(ib):
            N = C["normals"][k]
            if N is not None and len(N):
                d[k] -= N.T @ np.linalg.lstsq(N.T, d[k], rcond=None)[0]
        ft = C["tangential_force"]
        nd, nf = np.linalg.norm(d, axis=1), np.linalg.norm(ft, axis=1)
        sliding = ib & (nd > th["slide"] * r.delta) & (nf > tol * np.maximum(r.f_norm, 1e-300))
        cosine = np.where(sliding, np.einsum("ij,ij->i", d, ft) / np.maximum(nd * nf, 1e-300), np.nan)
        slide_bad = sliding & (cosine > th["max_dissipation_cosine"])
    wrong_bad = (C["wrong"] > th["max_wrong_side_share"]) if mu is None else np.zeros(r.n, bool)
    bad = ib & ((tangential_excess > 0) | wrong_bad | slide_bad)
    bd = np.flatnonzero(bad)
    any_ib = bool(np.any(ib))
    mx = (lambda a: float(np.nanmax(a)) if any_ib and np.any(np.isfinite(a[ib])) else 0.0)
    judged = ("friction cone (declared mu %g) and maximal dissipation" % mu) if mu is not None else "frictionless cone"
    return Verdict(
        "force_direction", "", len(bd) == 0, len(bd), mx(C["cone"]), "share of |F| (M^-1 metric)",
        float(r.t[bd[0]]) if len(bd) else None,
        f"{judged}; {int(ib.sum())} ticks with force within {r.bound_delta:g} delta; "
        f"max tangential {mx(C['tangential']):.3g}, max wrong-side {mx(C['wrong']):.3g}"
        + (f", max distance from the friction cone {mx(C['friction']):.3g}, "
           f"{int(slide_bad.sum())} ticks whose friction drives the slide" if mu is not None else "")
        + (f"; {C['no_contacts']} without contacts" if C["no_contacts"] else ""),
        {"ticks": int(ib.sum()), "max_tangential_share": mx(C["tangential"]), "max_wrong_side_share": mx(C["wrong"]),
         "ticks_without_contacts": C["no_contacts"], "declared_mu": mu,
         "friction_cone_violations": int((ib & (tangential_excess > 0)).sum()) if mu is not None else None,
         "dissipation_violations": int(slide_bad.sum()) if mu is not None else None},
        _first_worst(bd, np.maximum(tangential_excess[bd], C["wrong"][bd])))


def check_no_force_when_free(r: RunData, th: dict) -> Verdict:
    """A wrench beyond free_space, or while the handle is on the free side of every contact by the
    margin (METHOD.md property 3)."""
    S, C = r.separations, r.cone
    bad = S["in_free_space"] | C["away"]
    fb = np.flatnonzero(bad)
    return Verdict(
        "no_force_when_free", "", len(fb) == 0, len(fb), float(r.f_norm[fb].max()) if len(fb) else 0.0, "N (force)",
        float(r.t[fb[0]]) if len(fb) else None,
        f"{int(S['in_free_space'].sum())} ticks with force beyond {r.th['distance']['free_space']:g} delta; "
        f"{int(C['away'].sum())} with the handle on the free side of every contact by {th['margin']:g} delta",
        {"free_space_ticks": int(S["in_free_space"].sum()), "moving_away_ticks": int(C["away"].sum())},
        _first_worst(fb, r.f_norm[fb]))


def port_energy(r: RunData, th: dict) -> dict:
    """The passivity observer on the device port (Hannaford and Ryu 2002), without a model of the
    engine. Sign: the energy the user has put in through the handle, E(n) = -sum_{k<n} F_k . dx_k,
    F_k the wrench the device applied over tick k (held constant until the next tick: zero-order
    hold, so the work over the tick is exactly F_k . dx_k for the translation) and dx_k = xh_{k+1} (-)
    xh_k the handle's motion over it (translation, rotation vector). A passive engine never gives
    back more than it was given: E(n) >= 0. The zero-order hold alone makes any sampled stiffness K
    active (as a negative damping K T / 2); a real device's own damping b absorbs it when b > K T / 2
    + |B| (Colgate and Schenkel 1997). So the observer credits, over the ticks with a wrench, what the
    device's damping (b, b_r: oracle.toml [energy]) at least absorbed: the integral of b v^2 dt over a
    tick is >= b |dx|^2 / T (Cauchy-Schwarz), the credit. P(n) = E(n) + D(n) may not go below
    -max_deficit. Each contact episode's own observer (restarted at its first tick with a wrench)
    locates where energy came out; it is not a verdict, since an engine may hold energy across a
    tick without a wrench (gauss6's offsets lend and return it), and assuming otherwise would be a
    model of the engine."""
    n, t = r.n, r.t
    if n < 2:
        z = np.zeros(n)
        return {"P": z, "E": z, "episodes": [], "bad_handle": 0, "on": np.zeros(n, bool)}
    F = r.applied
    good = r.finite_handle[:-1] & r.finite_handle[1:]
    xh_p = np.where(r.finite_handle[:, None], r.xh_p, 0.0)
    xh_q = np.where(r.finite_handle[:, None], r.xh_q, np.array([1.0, 0, 0, 0]))
    dx = np.where(good[:, None], pose_difference(xh_p[1:], xh_q[1:], xh_p[:-1], xh_q[:-1]), 0.0)
    T = np.diff(t)
    zero = r.th["zero"]
    on = (np.linalg.norm(F[:, 3:], axis=1) > zero["torque"]) | (np.linalg.norm(F[:, :3], axis=1) > zero["force"])
    e = -np.einsum("ij,ij->i", F[:-1], dx)
    credit = np.where(on[:-1], (th["device_damping"] * np.einsum("ij,ij->i", dx[:, :3], dx[:, :3])
                                + th["device_angular_damping"] * np.einsum("ij,ij->i", dx[:, 3:], dx[:, 3:]))
                      / np.where(T > 0, T, np.inf), 0.0)
    P = np.concatenate([[0.0], np.cumsum(e + credit)])
    E = np.concatenate([[0.0], np.cumsum(e)])
    episodes = []
    k = 0
    while k < n - 1:
        if on[k]:
            s = k
            while k < n - 1 and on[k]:
                k += 1
            Pe = np.concatenate([[0.0], np.cumsum((e + credit)[s:k])])
            m = int(np.argmin(Pe))
            peak = int(np.argmax(Pe[:m + 1]))
            episodes.append({"start": s, "end": k, "min": float(Pe[m]), "min_tick": s + m, "peak_tick": s + peak,
                             "out": float(Pe[peak] - Pe[m]), "credit": float(credit[s:k].sum()),
                             "user_energy": float(e[s:k].sum())})
        else:
            k += 1
    return {"P": P, "E": E, "episodes": episodes, "bad_handle": int((~good).sum()), "on": on,
            "first_bad_handle": int(np.flatnonzero(~good)[0]) if not np.all(good) else None}


def check_energy(r: RunData, th: dict) -> Verdict:
    """Passivity on the device port (port_energy): the observer P(n) stays above -max_deficit. The
    report says where and when energy came out: the episode whose own observer falls lowest, its
    span, phase, energy and mean power (from its observer's peak to its minimum)."""
    O = port_energy(r, th)
    P, t, floor = O["P"], r.t, th["max_deficit"]
    eps = O["episodes"]
    run_min = float(P.min()) if r.n else 0.0
    m = int(np.argmin(P)) if r.n else 0
    below = [ep for ep in eps if ep["min"] < -floor]
    run_bad = run_min < -floor
    E = O["E"]
    e_min = int(np.argmin(E)) if r.n else 0
    worst = min(eps, key=lambda ep: ep["min"], default=None)
    if worst is not None and worst["min"] >= 0:  # no deficit: the largest energy return instead
        worst = max(eps, key=lambda ep: ep["out"])
    details = {"observer_min": run_min, "observer_min_time": float(t[m]) if r.n else None,
               "observer_final": float(P[-1]) if r.n else 0.0, "user_energy_final": float(O["E"][-1]) if r.n else 0.0,
               "damping_credit": float(P[-1] - O["E"][-1]) if r.n else 0.0, "episodes": len(eps),
               "episodes_below": len(below), "skipped_handle_steps": O["bad_handle"],
               "user_energy_min": float(E[e_min]) if r.n else 0.0, "user_energy_min_time": float(t[e_min]) if r.n else None}
    note = (f"observer min {run_min:.3g} J at {details['observer_min_time'] or 0:.3f} s (floor -{floor:g} J); "
            f"user energy in {details['user_energy_final']:.3g} J, device damping credit "
            f"{details['damping_credit']:.3g} J (user energy alone: min {details['user_energy_min']:.3g} J at "
            f"{details['user_energy_min_time'] or 0:.3f} s); {len(eps)} contact episodes, {len(below)} whose own "
            f"observer goes below the floor")
    violations = {}
    if worst is not None:
        t0, t1 = float(t[worst["peak_tick"]]), float(t[worst["min_tick"]])
        power = worst["out"] / (t1 - t0) if t1 > t0 else 0.0
        details.update(worst_episode_start=float(t[worst["start"]]), worst_episode_end=float(t[min(worst["end"], r.n - 1)]),
                       worst_episode_phase=r.phase_at(float(t[worst["start"]])), worst_episode_min=worst["min"],
                       worst_out_start=t0, worst_out_end=t1, worst_out_energy=worst["out"], worst_out_power=power,
                       worst_out_phase=r.phase_at(t0))
        note += (f"; worst episode {details['worst_episode_start']:.3f}-{details['worst_episode_end']:.3f} s "
                 f"({details['worst_episode_phase'] or 'no phase'}): observer min {worst['min']:.3g} J, "
                 f"{worst['out']:.3g} J out from {t0:.3f} to {t1:.3f} s ({power:.3g} W)")
    if O["bad_handle"]:
        k = O["first_bad_handle"]
        note += f"; {O['bad_handle']} steps skipped: non-finite handle pose (first at tick {k}, t = {t[k]:.4f} s)"
    if run_bad:
        first = int(np.flatnonzero(P < -floor)[0])
        violations = {role: {"tick": k, "window_start": 0, "window_end": k, "observer": float(P[k]), "floor": -floor}
                      for role, k in (("first", first), ("worst", m))}
    return Verdict("energy", "", not run_bad, int((P < -floor).sum()), max(-run_min, 0.0) + 0.0, "J (deficit)",
                   float(t[violations["first"]["tick"]]) if violations else None, note, details, violations)


def handle_motion(r: RunData, lag: int) -> np.ndarray:
    """The handle's motion over the tick `lag` ticks before each tick's end: row k (the tick from k to
    k + 1) is xh(k + 1 - lag) (-) xh(k - lag), zero where that tick is before the run or either pose
    is not finite. Shape (n - 1, 6)."""
    n = r.n
    dx = np.zeros((max(n - 1, 0), 6))
    if n - 1 - lag <= 0:
        return dx
    good = r.finite_handle[1:] & r.finite_handle[:-1]
    p = np.where(r.finite_handle[:, None], r.xh_p, 0.0)
    q = np.where(r.finite_handle[:, None], r.xh_q, np.array([1.0, 0, 0, 0]))
    d = np.where(good[:, None], pose_difference(p[1:], q[1:], p[:-1], q[:-1]), 0.0)
    dx[lag:] = d[:n - 1 - lag]
    return dx


def check_force_jumps(r: RunData, th: dict) -> Verdict:
    """The force (torque) a tick adds beyond what the handle's motion over that tick explains at the
    scene's stiffness (unexplained_per_tick: the change less any release of the last tick's force,
    less the ball of changes the handle's motion makes through a coupling kh ks M onto any contacts);
    with a declared latency L, the handle's motion of any of the L ticks before may explain it. The
    force a tick adds with no discount (added_per_tick) and the whole change are reported beside it,
    with the time of the largest."""
    o = r.o
    both = r.finite_wrench[1:] & r.finite_wrench[:-1]
    Wf = np.where(r.finite_wrench[:, None], r.W, 0)
    df = np.where(both, np.linalg.norm(np.diff(Wf[:, :3], axis=0), axis=1), 0)
    dtau = np.where(both, np.linalg.norm(np.diff(Wf[:, 3:], axis=0), axis=1), 0)
    f_add = np.where(both, added_per_tick(Wf[:, :3]), 0)
    tau_add = np.where(both, added_per_tick(Wf[:, 3:]), 0)
    # The tool's world-frame inertia at each tick's end (the displayed orientation; the body frame's
    # where that is not a pose).
    qs = np.where(r.finite_pose[1:, None], r.xs_q[1:], np.array([1.0, 0, 0, 0]))
    R = rotation_matrices(qs) if len(qs) else np.zeros((0, 3, 3))
    inertia = R @ o.inertia @ np.transpose(R, (0, 2, 1))
    limit = np.array([th["max_force_step"], th["max_torque_step"]])
    f_un = tau_un = None
    for lag in range(r.declared.get("latency_ticks", 0) + 1):
        f, tau = unexplained_per_tick(Wf, handle_motion(r, lag), o.mass, inertia, o.kh, o.ks, limit)
        if f_un is None:
            f_un, tau_un = f, tau
        else:  # the lag that explains most (the smaller excess over the thresholds)
            better = np.maximum(f / limit[0], tau / limit[1]) < np.maximum(f_un / limit[0], tau_un / limit[1])
            f_un, tau_un = np.where(better, f, f_un), np.where(better, tau, tau_un)
    f_un, tau_un = np.where(both, f_un, 0), np.where(both, tau_un, 0)
    jumps = np.flatnonzero((f_un > limit[0]) | (tau_un > limit[1])) + 1
    peak = {k: float(v.max()) if len(v) else 0.0
            for k, v in (("force_unexplained", f_un), ("torque_unexplained", tau_un), ("force_added", f_add),
                         ("torque_added", tau_add), ("force_step", df), ("torque_step", dtau))}
    largest_time = float(r.t[int(np.argmax(df)) + 1]) if len(df) else None
    # Worst: the larger excess over its threshold, force or torque.
    excess = np.maximum(f_un / limit[0], tau_un / limit[1])
    return Verdict(
        "force_jumps", "", len(jumps) == 0, len(jumps), peak["force_unexplained"],
        "N added per tick beyond the hand's motion", float(r.t[jumps[0]]) if len(jumps) else None,
        f"max force added beyond the hand's motion (at kh ks M = {o.kh:g} x {o.ks:g} x M) "
        f"{peak['force_unexplained']:.3g} N, torque {peak['torque_unexplained']:.3g} N m; added in all "
        f"{peak['force_added']:.3g} N, torque {peak['torque_added']:.3g} N m; largest change "
        f"{peak['force_step']:.3g} N" + (f" at {largest_time:.3f} s" if peak["force_step"] > 0 else "")
        + f", torque {peak['torque_step']:.3g} N m",
        {**{f"max_{k}": v for k, v in peak.items()}, "max_force_step_time": largest_time},
        _first_worst(jumps, excess[jumps - 1]))


def check_wrench_sanity(r: RunData, th: dict) -> Verdict:
    """A non-finite wrench or pose (displayed or handle), or a wrench over the device's limits."""
    o = r.o
    slack = 1 + th["slack"]
    over = r.finite_wrench & ((r.f_norm > o.max_force * slack) | (r.tau_norm > o.max_torque * slack))
    insane = np.flatnonzero(~r.finite_wrench | ~r.finite_pose | over)
    severity = np.where(~r.finite_wrench | ~r.finite_pose, np.inf,
                        np.maximum(r.f_norm / o.max_force, r.tau_norm / o.max_torque))
    return Verdict(
        "wrench_sanity", "", len(insane) == 0, len(insane),
        float(max(r.f_norm.max() / o.max_force, r.tau_norm.max() / o.max_torque)) if r.n else 0.0,
        "of the limit", float(r.t[insane[0]]) if len(insane) else None,
        f"{int((~r.finite_wrench).sum())} non-finite wrenches, {int((~r.finite_pose).sum())} non-finite or "
        f"far-off poses (beyond {th['pose_extent']:g} scene radii), "
        f"{int(over.sum())} over the limits ({o.max_force:g} N, {o.max_torque:g} N m)",
        {"non_finite_wrench": int((~r.finite_wrench).sum()), "non_finite_pose": int((~r.finite_pose).sum()),
         "over_limit": int(over.sum())},
        {"first": {"tick": int(insane[0])}, "worst": {"tick": int(insane[int(np.argmax(severity[insane]))])}}
        if len(insane) else {})


def hull_error(D: np.ndarray, radius: float) -> tuple[float, np.ndarray]:
    """The pose error of a displayed pose against the convex hull of handle poses: D (m, 6) the
    handle poses relative to the displayed one (xh_j (-) xs: translation, rotation vector), the error
    of a point y of the hull |y_p| + radius |y_r|. Returned at the hull's point nearest to the
    displayed pose in the Euclidean 6-metric of (p, radius r) (non-negative least squares with the
    weights' sum held at 1 by a heavy row, then the weights normalised): a point of the hull, so the
    error is never below the hull's own, and at most sqrt(2) times it. Also the weights."""
    Y = np.concatenate([D[:, :3], radius * D[:, 3:]], axis=1)
    scale = float(np.abs(Y).max())
    if not scale > 0:
        w = np.zeros(len(D))
        w[-1] = 1.0
        return 0.0, w
    heavy = 1e6
    A = np.vstack([Y.T / scale, heavy * np.ones(len(D))])
    b = np.concatenate([np.zeros(6), [heavy]])
    w = _nnls(A, b)
    w = w / w.sum() if w.sum() > 0 else np.full(len(D), 1.0 / len(D))
    y = w @ Y
    return float(np.linalg.norm(y[:3]) + np.linalg.norm(y[3:])), w


def tool_blocked(r: RunData, k: int) -> bool:
    """Whether an obstacle stands between the displayed tool and the hand at tick k: the in-between
    motion (METHOD.md s.4) from the displayed pose to the handle's touches an obstacle, exactly
    (swept boxes, then gauss6's conservative CCD, then the exact first contact on the motions it
    stops; a half turn, which has no such motion, counts as free). A god-object held on the near side
    of a wall the hand has gone through cannot follow the hand, whatever the force."""
    o = r.o
    p0, q0, p1, q1 = r.xs_p[k], r.xs_q[k], r.xh_p[k], r.xh_q[k]
    near = o.exact.near(p0, p1)
    min_sep = r.th["tunnelling"]["min_separation"] * r.delta
    stopped = [i for i in near if (lambda c: c["hit"] or c["status"] != "ok")(o.exact.pairs[i].step(p0, q0, p1, q1,
                                                                                                   min_sep))]
    if not stopped:
        return False
    try:
        return bool(o.exact.motion_hits(p0, q0, p1, q1, stopped))
    except ValueError:
        return False


def check_tracking(r: RunData, th: dict) -> Verdict:
    """In free space the displayed pose follows the handle: at ticks without a wrench whose handle
    pose is beyond free_space from every obstacle (the certified bracket), the displayed pose lies
    in the convex hull of the handle's poses of the last max_lag_ticks ticks (plus a declared
    latency), within the bound: error = distance from the hull (hull_error), position plus radius x
    angle, delta units. METHOD.md's god-object steps xs <- xs (+) ks (xh (-) xs) in free space: a
    convex combination of past handle poses, between the samples of a fast hand and inside the
    corner of a curved path, not on a sample. A quaternion in another order, a frame offset off the
    hand's recent path, or a pose that lags beyond the window are named here. The distance to the
    nearest of those handle poses (the rule up to version 5) is reported beside it. Ticks with an
    obstacle between the displayed tool and the hand (tool_blocked) are not judged: the tool must not
    follow there."""
    o, delta = r.o, r.delta
    lag = th["max_lag_ticks"] + r.declared.get("latency_ticks", 0)
    cand = np.flatnonzero(~r.forced & r.finite_pose & r.finite_handle & r.finite_wrench)
    cand = cand[cand >= lag]
    if len(cand) > th["max_poses"]:
        cand = cand[np.unique(np.linspace(0, len(cand) - 1, th["max_poses"]).astype(int))]
    free_space = r.th["distance"]["free_space"] * delta
    err = np.full(r.n, np.nan)
    nearest = np.full(r.n, np.nan)
    judged = blocked = 0
    for c, k in enumerate(cand):
        s, _ = o.exact.separation_side(r.xh_p[k], r.xh_q[k], free_space, free_space)
        if math.isfinite(s):
            continue  # the handle is near an obstacle: not free space
        if tool_blocked(r, k):
            blocked += 1
            continue  # an obstacle between the displayed tool and the hand: it may not follow
        judged += 1
        js = np.arange(k - lag, k + 1)
        d = pose_difference(r.xh_p[js], r.xh_q[js], np.repeat(r.xs_p[k][None], len(js), 0),
                            np.repeat(r.xs_q[k][None], len(js), 0))
        sample = np.linalg.norm(d[:, :3], axis=1) + o.god_radius * np.linalg.norm(d[:, 3:], axis=1)
        nearest[k] = float(sample.min()) / delta
        err[k] = min(hull_error(d, o.god_radius)[0] / delta, nearest[k])
        if c % 200 == 0:
            r.say("tracking", c, len(cand))
    bad = np.flatnonzero(err > th["bound"])
    worst = float(np.nanmax(err)) if judged else 0.0
    worst_sample = float(np.nanmax(nearest)) if judged else 0.0
    return Verdict(
        "tracking", "", len(bad) == 0, len(bad), worst, "delta (pose error)", float(r.t[bad[0]]) if len(bad) else None,
        f"{judged} free-space ticks judged (of {len(cand)} sampled without force; {blocked} with an obstacle "
        f"between the displayed tool and the hand, not judged); displayed pose within "
        f"{th['bound']:g} delta of the hull of the handle's poses of the last {lag} ticks; max error "
        f"{worst:.3g} delta (from the nearest of those poses: {worst_sample:.3g} delta)",
        {"ticks": judged, "blocked_ticks": blocked, "max_error_delta": worst, "max_sample_error_delta": worst_sample,
         "lag_ticks": lag},
        _first_worst(bad, err[bad]))


def check_latency(r: RunData, th: dict) -> Verdict:
    """Latency: at each fresh contact (no wrench in the window before it), the ticks from the
    handle's crossing into an obstacle (its pose first intersects one, exactly, after being clear
    by more than `approach` delta at the window's start) to the first tick with a wrench, judged
    against onset_ticks plus the declared latency. (The force's lag in contact is not judged: in
    closed loop the handle's motion answers the force, and a regression of the one on the other
    finds that feedback, not the engine's delay.)"""
    o, delta = r.o, r.delta
    declared = r.declared.get("latency_ticks")
    allowed_onset = th["onset_ticks"] + (declared or 0)
    window = th["window_ticks"] + allowed_onset
    pen_cache: dict = {}

    def handle_in(k: int) -> bool:
        if k not in pen_cache:
            pen_cache[k] = bool(r.finite_handle[k]) and o.exact.intersecting_pairs(r.xh_p[k], r.xh_q[k]) > 0
        return pen_cache[k]

    onsets = np.flatnonzero(r.forced & ~np.concatenate([[False], r.forced[:-1]]))[:th["max_crossings"]]
    latencies, crossings = [], []
    approach = th["approach"] * delta
    for c, k_on in enumerate(onsets):
        r.say("latency", c, len(onsets))
        lo = max(0, k_on - window)
        if np.any(r.forced[lo:k_on]) or not r.finite_handle[lo]:
            continue  # force within the window before: not a fresh contact
        if o.exact.separation_side(r.xh_p[lo], r.xh_q[lo], approach, approach)[0] <= approach:
            continue  # the handle was not clear at the window's start
        k = next((j for j in range(lo + 1, k_on + 1) if handle_in(j) and not handle_in(j - 1)), None)
        if k is None:
            continue  # the force answered before the handle crossed
        latencies.append(int(k_on - k))
        crossings.append(int(k))
    lat = np.asarray(latencies, int)
    bad_onset = np.flatnonzero(lat > allowed_onset)
    violations = {}
    if len(bad_onset):
        kb = crossings[bad_onset[0]]
        kw = crossings[bad_onset[int(np.argmax(lat[bad_onset]))]]
        violations = {"first": {"tick": kb, "response_tick": kb + int(lat[bad_onset[0]])},
                      "worst": {"tick": kw, "response_tick": kw + int(lat[bad_onset].max())}}
    return Verdict(
        "latency", "", not len(bad_onset), len(bad_onset), float(lat.max()) if len(lat) else 0.0, "ticks",
        float(r.t[crossings[bad_onset[0]]]) if len(bad_onset) else None,
        f"{len(lat)} crossings measured (handle into an obstacle, exactly, to the first tick with force): max "
        f"{int(lat.max()) if len(lat) else 0}, median {float(np.median(lat)) if len(lat) else 0:g} ticks "
        f"({allowed_onset} allowed); " + (f"declared latency {declared} ticks" if declared is not None
                                          else "no latency declared"),
        {"crossings": len(lat), "max_onset_ticks": int(lat.max()) if len(lat) else 0,
         "allowed_onset_ticks": allowed_onset, "declared_ticks": declared}, violations)


def step_times(trace) -> tuple[np.ndarray, np.ndarray]:
    """The driver's timing of each engine step call: (wall, CPU) seconds, one steps row per tick (the
    steps stream's update_time, update_cpu_time); never the engine's own figure (ticks force_time)."""
    st = trace.steps
    wall = np.asarray(st["update_time"], float) if len(st) else np.zeros(0)
    cpu = np.asarray(st["update_cpu_time"], float) if len(st) else np.zeros(0)
    return wall, cpu


def timing_summary(wall: np.ndarray, cpu: np.ndarray, period: float, quantile: float) -> dict:
    """The figures the deadlines check judges: the steps' cost (CPU seconds of the call when measured,
    else wall) -- its median, quantile, the share over the period -- and the wall time's max."""
    w = wall[np.isfinite(wall)]
    if not len(w):
        return {"steps": 0}
    measured_cpu = len(cpu) == len(wall) and np.all(np.isfinite(cpu))
    cost = cpu if measured_cpu else wall
    c = cost[np.isfinite(cost)]
    return {"steps": int(len(w)), "cost_clock": "cpu" if measured_cpu else "wall", "median": float(np.median(c)),
            "quantile": float(np.quantile(c, quantile)), "over": int((c > period).sum()),
            "over_fraction": float((c > period).mean()), "max": float(w.max()), "wall_median": float(np.median(w))}


def check_cost(r: RunData, th: dict) -> Verdict:
    """Deadlines, from the driver's timing of each step call (never the engine's own figure).
    The cost of a step is its CPU time: a loaded machine preempts a step for tens of ms (wall), which
    is no cost of the engine (without the CPU timing only the stall bound is judged). Fails when more
    than max_over_fraction of the steps cost over the period T, when the quantile's cost exceeds T,
    or when a step's wall time (a freeze: sleeping, waiting, or computing) exceeds max_stall_seconds
    -- each beyond the machine's allowance: what gauss6's own engine does on this machine in the same
    run (Oracle.calibrate). Not judged without the driver's timings (a run recorded elsewhere)."""
    period = 1 / r.o.rate_hz
    wall, cpu = step_times(r.trace)
    s = timing_summary(wall, cpu, period, th["quantile"])
    if not s["steps"]:
        return Verdict("cost", "", True, 0, 0.0, "s (max step)", None,
                       "not judged: the run has no driver timings of its steps (update_time)", {"judged": False})
    cal = r.calibration or {}
    allow_fraction = th["max_over_fraction"] + cal.get("over_fraction", 0.0)
    allow_q = max(period, cal.get("quantile", 0.0))
    allow_max = max(th["max_stall_seconds"], cal.get("max", 0.0))
    cost = cpu if s["cost_clock"] == "cpu" else wall
    over = np.flatnonzero(np.isfinite(cost) & (cost > period))
    fails = []
    # Without the driver's CPU timing (a driver that records the wall time only), the step's wall time
    # mixes the engine's cost with the machine's preemptions: only the stall bound is judged then.
    costs_judged = s["cost_clock"] == "cpu"
    if costs_judged and s["over_fraction"] > allow_fraction:
        fails.append(f"{s['over_fraction']:.2%} of steps cost over the period (allowed {allow_fraction:.2%})")
    if costs_judged and s["quantile"] > allow_q:
        fails.append(f"p{100 * th['quantile']:g} {s['quantile'] * 1e3:.3g} ms over {allow_q * 1e3:.3g} ms")
    if s["max"] > allow_max:
        fails.append(f"a stall of {s['max'] * 1e3:.3g} ms wall (allowed {allow_max * 1e3:.3g} ms)")
    q = f"p{100 * th['quantile']:g}"
    note = (f"driver's timing of {s['steps']} step calls ({s['cost_clock']} time as the cost): median "
            f"{s['median'] * 1e6:.1f} us (sustains {1 / s['median'] if s['median'] > 0 else math.inf:.0f} Hz), {q} "
            f"{s['quantile'] * 1e3:.3g} ms, {s['over']} over the {period * 1e3:g} ms tick; wall median "
            f"{s['wall_median'] * 1e6:.1f} us, max {s['max'] * 1e3:.3g} ms"
            + (f"; machine allowance from gauss6's engine here ({cal['steps']} steps: {cal['over_fraction']:.2%} "
               f"over, {q} {cal['quantile'] * 1e3:.3g} ms, wall max {cal['max'] * 1e3:.3g} ms)"
               if cal.get("steps") else "; no machine calibration")
            + ("" if costs_judged else "; no CPU timing of the calls: only the stall bound judged")
            + ("; " + "; ".join(fails) if fails else ""))
    worst = int(np.nanargmax(wall))
    return Verdict(
        "cost", "", not fails, len(over), s["max"], "s (max step, wall)",
        float(r.t[over[0]]) if len(over) else (float(r.t[worst]) if fails else None),
        note,
        {"judged": True, "cost_clock": s["cost_clock"], "median_seconds": s["median"], "quantile_seconds": s["quantile"],
         "max_seconds": s["max"], "steps_over_period": s["over"], "over_fraction": s["over_fraction"],
         "sustained_hz": 1 / s["median"] if s["median"] > 0 else None,
         "allowed_over_fraction": allow_fraction, "allowed_quantile_seconds": allow_q, "allowed_max_seconds": allow_max,
         "calibration_steps": cal.get("steps", 0)},
        {"first": {"tick": int(over[0]) if len(over) else worst}, "worst": {"tick": worst}} if fails else {})


@dataclass(frozen=True)
class Check:
    name: str
    title: str
    section: str                                  # its thresholds: this section of oracle.toml
    run: Callable[[RunData, dict], Verdict]


# The checks, in report order (the deadlines last).
CHECK_TABLE = [
    Check("penetration", "penetration of the displayed poses", "penetration", check_penetration),
    Check("tunnelling", "tunnelling between successive poses", "tunnelling", check_tunnelling),
    Check("force_at_distance", "force at a distance", "distance", check_force_at_distance),
    Check("force_direction", "force outside the contact (or declared friction) cone", "direction",
          check_force_direction),
    Check("no_force_when_free", "force in free space or moving away", "moving_away", check_no_force_when_free),
    Check("energy", "energy (passivity observer on the device port)", "energy", check_energy),
    Check("force_jumps", "force jumps", "jumps", check_force_jumps),
    Check("wrench_sanity", "non-finite or over-limit wrench or pose", "limits", check_wrench_sanity),
    Check("tracking", "displayed pose follows the handle in free space", "tracking", check_tracking),
    Check("latency", "latency of the force's response", "latency", check_latency),
    Check("cost", "deadlines (the driver's timing of each step)", "cost", check_cost),
]
# A check's title is numbered by its place in the table.
CHECK_TABLE = [replace(c, title=f"{i}. {c.title}") for i, c in enumerate(CHECK_TABLE, 1)]
CHECKS = [(c.name, c.title) for c in CHECK_TABLE]
CHECK_NAMES = [c.name for c in CHECK_TABLE]


@functools.lru_cache(maxsize=4)
def calibrate(scene_path: str, seconds: float, quantile: float) -> dict:
    """The machine allowance of the deadlines check: gauss6's own engine (the C ABI library) driven on
    the scene's script for `seconds`, each step call timed as the driver times an engine's (wall), in
    this process. Measured once per scene and process (the same validate run), never assumed."""
    import tempfile
    import time

    from .driver import drive, scene_script
    from .engine import EngineScene, load_engine

    inner = load_engine("gauss6")
    walls: list = []
    cpus: list = []

    class Timed:
        name = "gauss6 (calibration)"

        def reset(self, scene):
            inner.reset(scene)

        def step(self, t, p, q):
            start, cpu = time.perf_counter(), time.thread_time()
            out = inner.step(t, p, q)
            cpus.append(time.thread_time() - cpu)
            walls.append(time.perf_counter() - start)
            return out

    text, _ = scene_script(scene_path)
    scene = EngineScene.from_scene_file(scene_path)
    with tempfile.TemporaryDirectory() as tmp:
        drive(Timed(), scene, text, Path(tmp) / "calibration.g6trace", seconds)
    return timing_summary(np.asarray(walls), np.asarray(cpus), 1 / scene.rate_hz, quantile)


# ---------------------------------------------------------------------------------------------

class Oracle:
    """The checks of one scene: its exact mesh pairs (exact_checks.ExactScene, shared with `gauss6
    certify`), contact generation, mass."""

    def __init__(self, scene_path, thresholds: dict | None = None):
        from ._gauss6 import load_scene as _load_scene, oracle as _oracle, runtime

        self.scene_path = str(scene_path)
        self.thresholds = thresholds or load_thresholds()
        g = runtime.scene_geometry(self.scene_path)
        settings = runtime.effective_settings(_load_scene(self.scene_path))
        self.exact = ExactScene(self.scene_path, self.thresholds)
        self.delta = float(g["delta"])
        self.mass = float(g["mass"])
        self.inertia = np.asarray(g["inertia_G_B"], float)
        self.kh, self.ks = float(g["kh"]), float(g["ks"])  # the scene's coupling: force_jumps' stiffness
        self.max_force = float(g["max_force"])
        self.max_torque = float(settings["device"]["max_torque"])
        self.rate_hz = float(g["rate_hz"])
        self.god_V = np.asarray(g["god_V"], float)
        self.god_F = np.asarray(g["god_F"], np.int32)
        self.god_radius = self.exact.god_radius
        self.obstacles = [(name, np.asarray(V, float), np.asarray(F, np.int32)) for name, V, F in g["obstacles"]]
        self.boxes = self.exact.boxes
        lo = np.min([b[0] for b in self.boxes], axis=0)
        hi = np.max([b[1] for b in self.boxes], axis=0)
        self.centre = (lo + hi) / 2
        self.scene_radius = float(np.linalg.norm(hi - lo) / 2 + self.god_radius)
        self.contacts = _oracle.ContactGenerator(self.scene_path)

    # -- geometry (exact through ExactScene; estimates in floating point) -------------------------
    def intersecting_pairs(self, p, q) -> int:
        return self.exact.intersecting_pairs(p, q)

    def depth_estimate(self, p, q) -> float:
        """The deepest vertex of either body inside the other: its distance to the other's surface
        (floating point). 0 when the bodies cross by edges and faces only (a blade through a thin
        wall): no vertex of either is inside the other, and the depth is not estimated."""
        R = rotation_matrices(np.asarray(q, float))[0]
        p = np.asarray(p, float)
        X = (R @ self.god_V.T).T + p
        g_lo, g_hi = self.god_V.min(axis=0), self.god_V.max(axis=0)
        depth = 0.0
        for (_, V, F), (lo, hi) in zip(self.obstacles, self.boxes):
            # The tool's vertices inside the obstacle; the obstacle's inside the tool, in its own frame.
            depth = max(depth, deepest_inside(X, V, F, lo, hi),
                        deepest_inside((V - p) @ R, self.god_V, self.god_F, g_lo, g_hi))
        return depth

    def mass_matrix(self, q) -> np.ndarray:
        R = rotation_matrices(np.asarray(q, float))[0]
        M = np.zeros((6, 6))
        M[:3, :3] = self.mass * np.eye(3)
        M[3:, 3:] = R @ self.inertia @ R.T
        return M

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

    # -- the judgement --------------------------------------------------------------------------
    def judge(self, trace, progress=None, nearest_window=None, checks=None, calibration=None) -> OracleResult:
        """The checks of CHECK_TABLE on a run (only those named in `checks` when given). calibration:
        the deadlines check's machine allowance (calibrate()); measured here when None and the run has
        the driver's step timings. nearest_window (t0, t1): also the Fig. 13 series nearest_tangential
        (off by default: a penetration depth estimate costs seconds a pose on the bunnies)."""
        wanted = CHECK_NAMES if checks is None else list(checks)
        unknown = [c for c in wanted if c not in CHECK_NAMES]
        if unknown:
            raise ValueError(f"unknown checks {unknown} (the oracle's: {', '.join(CHECK_NAMES)})")
        if calibration is None and "cost" in wanted and len(trace.steps) \
                and np.any(np.isfinite(np.asarray(trace.steps["update_time"], float))):
            calibration = calibrate(self.scene_path, self.thresholds["cost"]["calibration_seconds"],
                                    self.thresholds["cost"]["quantile"])
        r = RunData(self, trace, progress, calibration, nearest_window)
        verdicts = []
        for c in CHECK_TABLE:
            if c.name in wanted:
                v = c.run(r, self.thresholds[c.section])
                v.title = c.title
                verdicts.append(v)
        return OracleResult(verdicts, self._series(r, wanted), r.phases, r.declared, calibration or {})

    def _series(self, r: RunData, wanted) -> dict:
        """Per tick arrays for the plots (from the shared quantities the checks computed)."""
        n = r.n
        series = {"t": r.t, "force": r.f_norm, "step_seconds": step_times(r.trace)[0]}
        if "penetration" in r.__dict__:
            pen = r.penetration
            series["penetrating"] = pen["tick"]
            sep = r.separations["sep"] if "separations" in r.__dict__ else np.full(n, np.nan)
            series["separation"] = np.where(pen["tick"], -pen["depth"][r.pose_id], sep) / self.delta
        if "cone" in r.__dict__:
            series["cone_distance"] = r.cone["cone"]
        if "energy" in wanted:
            series["energy"] = port_energy(r, self.thresholds["energy"])["P"]
        nearest = np.full(n, np.nan)
        nearest_rank = np.zeros(n, np.int64)
        if r.nearest_window is not None:
            pen = r.penetration
            sep = r.separations["sep"]
            rows_of: dict = {}
            chosen = r.forced & r.finite_pose & (r.t >= r.nearest_window[0]) & (r.t <= r.nearest_window[1])
            for c, k in enumerate(np.flatnonzero(chosen)):
                j = r.pose_id[k]
                if j not in rows_of:
                    if pen["tick"][k]:
                        depth = pen["depth"][j]
                        clearance = depth if depth > 0 else self.depth_estimate(r.xs_p[k], r.xs_q[k])
                    elif np.isfinite(sep[k]):
                        clearance = sep[k]
                    else:
                        clearance = None  # beyond free_space: no nearest features to speak of
                    rows_of[j] = None if clearance is None else self.nearest_rows(r.xs_p[k], r.xs_q[k], clearance)
                if rows_of[j] is not None:
                    nearest[k], nearest_rank[k] = self.tangential_share(r.xs_q[k], r.W[k], rows_of[j])
                if c % 500 == 0:
                    r.say("nearest features", c, int(chosen.sum()))
        series["nearest_tangential"], series["nearest_rank"] = nearest, nearest_rank
        return series
