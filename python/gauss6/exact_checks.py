"""Exact checks of recorded god-object poses against a scene, shared by the figures of
`gauss6 reproduce` (reproduce.py, reproduce_surfaces.py) and `gauss6 certify` (certify.py): the
distinct poses of a trace and how many of them exactly intersect an obstacle (the reference's CGAL
test, through the bindings), with a progress bar; a scene's exact mesh pairs (ExactScene), the one
path by which both `gauss6 validate` (oracle.py) and `gauss6 certify` (certify.py, and its
--witness re-check) decide a pose, a motion or a separation."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def progress_bar(total, desc: str, unit: str, show: bool):
    """A tqdm bar (disabled when not show); unit "s" shows run seconds with one decimal."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, disable=not show, leave=True, dynamic_ncols=True,
                bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} {unit} [{elapsed}<{remaining}]"
                if unit == "s" else None)


def distinct_poses(trace) -> np.ndarray:
    """Every distinct god-object pose of the trace (N x 7: p, q), in order of first appearance."""
    poses = np.hstack([trace.ticks["xs_p"], trace.ticks["xs_q"]])
    _, first = np.unique(poses, axis=0, return_index=True)
    return poses[np.sort(first)]


def count_penetrating(scene: Path, poses: np.ndarray, show_progress: bool, label: str) -> tuple[int, float]:
    """(poses with at least one exactly intersecting triangle pair, wall time of the check in s)."""
    from ._gauss6 import runtime

    bar = progress_bar(len(poses), f"{label}: exact check", "pose", show_progress)
    done = [0]

    def progress(n: int) -> None:
        bar.update(n - done[0])
        done[0] = n

    result = runtime.count_intersecting_pairs(str(scene), np.ascontiguousarray(poses), progress)
    bar.close()
    return int(np.count_nonzero(result["counts"])), float(result["seconds"])


class ExactScene:
    """A scene's obstacles (world frame) and god-object as the reference's exact mesh pairs."""

    def __init__(self, scene_path, thresholds: dict | None = None):
        from ._gauss6 import ccd, runtime
        from .thresholds import load_thresholds

        g = runtime.scene_geometry(str(scene_path))
        self.delta = float(g["delta"])
        self.bound = float((thresholds or load_thresholds())["distance"]["bound"]) * self.delta
        god_V = np.asarray(g["god_V"], float)
        god_F = np.asarray(g["god_F"], np.int32)
        self.god_radius = float(np.linalg.norm(god_V, axis=1).max())
        obstacles = [(np.asarray(V, float), np.asarray(F, np.int32)) for _, V, F in g["obstacles"]]
        self.pairs = [ccd.MeshPair(V, F, god_V, god_F) for V, F in obstacles]
        self.boxes = [(V.min(axis=0), V.max(axis=0)) for V, _ in obstacles]

    def near(self, p0, p1) -> list[int]:
        """Obstacles whose box meets the god-object's swept box over the motion p0 -> p1 (G's segment grown
        by the radius, 1e-9 relative more for rounding): the others cannot be touched."""
        r = self.god_radius * (1 + 1e-9)
        lo = np.minimum(p0, p1) - r
        hi = np.maximum(p0, p1) + r
        return [i for i, (blo, bhi) in enumerate(self.boxes) if np.all(lo <= bhi) and np.all(hi >= blo)]

    def intersecting_pairs(self, p, q) -> int:
        return sum(int(mp.count_intersecting_pairs(p, q)) for mp in self.pairs)

    def first_contact(self, i: int, p0, q0, p1, q1):
        """The exact first contact of the in-between motion (METHOD.md s.4) from (p0, q0) to (p1, q1)
        with obstacle i (reference mesh_first_contact: .hit, .lower, .upper, .pairs). ValueError when
        there is no Cayley motion (an exact half turn): undecided."""
        return self.pairs[i].exact_first_contact(p0, q0, p1, q1)

    def motion_hits(self, p0, q0, p1, q1, obstacles=None) -> list:
        """The obstacles (among `obstacles`, default those near the motion) that the motion from
        (p0, q0) to (p1, q1) touches, each as (index, exact first contact); [] when it is free."""
        found = []
        for i in (self.near(p0, p1) if obstacles is None else obstacles):
            c = self.first_contact(i, p0, q0, p1, q1)
            if c.hit:
                found.append((i, c))
        return found

    def separation(self, p, q, max_distance: float) -> float:
        """The exact minimum distance (its lower double bracket) if <= max_distance, else +inf."""
        best = math.inf
        for mp in self.pairs:
            s = mp.separation(p, q, max_distance)
            if s["within"]:
                best = min(best, float(s["lower"]))
        return best

    def separation_side(self, p, q, bound: float, free_space: float) -> tuple[float, bool]:
        """The separation at a pose as far as a verdict against `bound` and `free_space` needs it: a
        value whose side of each is the exact separation's (<= bound; in (bound, free_space]; +inf
        beyond free_space), and whether the exact path was needed. The reference's certified bracket
        lower <= d <= upper decides when neither threshold lies inside it (the value is then its
        lower end); otherwise the exact separation decides."""
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

    def separation_within(self, p, q, max_distance: float) -> tuple[float, bool]:
        """(a certified upper bound of the exact minimum distance if it is <= max_distance, else +inf;
        whether exact arithmetic was needed): reference separation_within over the obstacles."""
        best, exact = math.inf, False
        for mp in self.pairs:
            s = mp.separation_within(p, q, max_distance)
            exact = exact or s["exact"]
            if s["within"]:
                best = min(best, float(s["upper"]))
        return best, exact
