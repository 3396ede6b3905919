"""Exact checks of recorded god-object poses against a scene, shared by the figures of
`gauss6 reproduce` (reproduce.py, reproduce_surfaces.py): the distinct poses of a trace and
how many of them exactly intersect an obstacle (the reference's CGAL test, through the
bindings), with a progress bar."""
from __future__ import annotations

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
