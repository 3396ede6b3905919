"""Denser copies of a generated mesh, the same surface: each triangle split into four by its edges'
midpoints, `levels` times (4^levels triangles per input triangle), as a dense CAD tessellation
would give. Made for issue 46's large scenes: the full bunny (datasets_generated/bunny_full/)
split into 4 (bunny_x4, 278,656 triangles) and into 16 (bunny_x16, 1,114,624 triangles).

Deterministic (no randomness): the input file's sha256 is a parameter; a midpoint is
0.5 * (a + b) in binary64, one rounding, so every new vertex lies on its edge to within half an
ulp of the coordinates and each input triangle's four children tile it. Edges are numbered in
sorted order of their (lower, higher) vertex pair, so the output's bytes depend only on the input.
The children keep their parent's orientation, so a closed, manifold, outward mesh stays one; the
generator then runs the exact checks of every generated mesh (gauss6_make_bunny --check:
closed, 2-manifold, outward, no degenerate triangle, no self-intersection) and fails on any.

The meshes are large (about 14 and 57 MB of OFF) and are not committed: `gauss6 datasets generate
--only bunny_x4` (or bunny_x16) writes them in place, with MANIFEST.json.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

GENERATOR_VERSION = "1"


def read_off(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n x 3 float64) and triangles (m x 3 int64) of an ASCII OFF with '#' comment lines."""
    lines = [ln for ln in Path(path).read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines or lines[0].strip() != "OFF":
        raise ValueError(f"{path}: not an OFF file (first line {lines[0] if lines else ''!r})")
    n, m = (int(x) for x in lines[1].split()[:2])
    V = np.array([ln.split() for ln in lines[2:2 + n]], dtype=float)
    F = np.array([ln.split() for ln in lines[2 + n:2 + n + m]], dtype=np.int64)
    if V.shape != (n, 3) or F.shape != (m, 4) or np.any(F[:, 0] != 3):
        raise ValueError(f"{path}: expected {n} vertices of 3 coordinates and {m} triangles")
    return V, F[:, 1:]


def split_in_four(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One level of midpoint subdivision: every edge gets one midpoint shared by its two triangles."""
    a, b, c = F[:, 0], F[:, 1], F[:, 2]
    ends = np.stack([np.stack([a, b], 1), np.stack([b, c], 1), np.stack([c, a], 1)], 1).reshape(-1, 2)
    ends = np.sort(ends, axis=1)
    edges, index = np.unique(ends, axis=0, return_inverse=True)  # sorted: deterministic numbering
    mid = len(V) + index.reshape(-1, 3)  # per triangle: midpoints of ab, bc, ca
    ab, bc, ca = mid[:, 0], mid[:, 1], mid[:, 2]
    V2 = np.vstack([V, 0.5 * (V[edges[:, 0]] + V[edges[:, 1]])])
    F2 = np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                   np.stack([ab, bc, ca], 1)], 1).reshape(-1, 3)
    return V2, F2


def subdivide(V: np.ndarray, F: np.ndarray, levels: int) -> tuple[np.ndarray, np.ndarray]:
    if levels < 1:
        raise ValueError(f"levels must be >= 1, not {levels}")
    for _ in range(levels):
        V, F = split_in_four(V, F)
    return V, F


def write_off(path: Path, V: np.ndarray, F: np.ndarray, header: list[str]) -> None:
    """ASCII OFF as gauss6_make_bunny writes it: 17 significant digits (exact doubles)."""
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("OFF\n" + "".join(f"# {line}\n" for line in header) + f"{len(V)} {len(F)} 0\n")
        np.savetxt(f, V, fmt="%.17g")
        np.savetxt(f, np.hstack([np.full((len(F), 1), 3, dtype=np.int64), F]), fmt="%d")
