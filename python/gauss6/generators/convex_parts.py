"""Convex decompositions of the scenes' meshes, for engines that collide convex shapes only
(MuJoCo's mesh geoms, a dynamic PyBullet body, Drake's compliant hydroelastic and point
contact): CoACD (Wei et al. 2022, the `coacd` wheel pinned in requirements.txt) with fixed
parameters and a fixed seed, written as one Wavefront OBJ with one object (`o part_N`) per
convex part, vertices as repr() doubles, so that the same input and parameters give the same
bytes (checked: two runs on the box with the hole, byte-identical).

A part set is named by the sha256 of the input mesh's arrays (float64 vertices, int32 faces,
C order) and of the parameters: the adapters (python/gauss6/adapters/geometry.py) find it in
datasets_generated/convex_parts/ (committed, with its MANIFEST.json) or make it into their
cache on first use. The bunny takes about 7 minutes on the 2-core machine, the box 20 s.

Usage as a program: python -m gauss6.generators.convex_parts MESH.off OUT_DIR (writes OUT_DIR/<key>.obj).
"""
from __future__ import annotations

import hashlib
import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from . import source as source_of

GENERATOR_VERSION = "1"


@dataclass(frozen=True)
class ConvexPartsParams:
    # CoACD's defaults (its paper's): concavity threshold 0.05 of the mesh's size, the manifold
    # preprocessing at resolution 50, the tree search at 150 iterations, depth 3, 20 nodes; the
    # seed fixed so that the search is repeatable.
    threshold: float = 0.05
    preprocess_mode: str = "auto"
    preprocess_resolution: int = 50
    resolution: int = 2000
    mcts_nodes: int = 20
    mcts_iterations: int = 150
    mcts_max_depth: int = 3
    max_convex_hull: int = -1
    seed: int = 1

    def to_json(self) -> dict:
        return asdict(self)


def mesh_key(V: np.ndarray, F: np.ndarray, params: ConvexPartsParams) -> str:
    """The name of a part set: sha256 of the mesh's arrays and the parameters (16 hex digits)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(V, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(F, dtype=np.int32).tobytes())
    h.update(json.dumps(params.to_json(), sort_keys=True).encode())
    h.update(GENERATOR_VERSION.encode())
    return h.hexdigest()[:16]


def decompose(V: np.ndarray, F: np.ndarray, params: ConvexPartsParams) -> list[tuple[np.ndarray, np.ndarray]]:
    """CoACD's convex parts of a closed mesh: [(vertices, faces)], each part a convex hull."""
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(np.asarray(V, np.float64), np.asarray(F, np.int64)),
                            threshold=params.threshold, preprocess_mode=params.preprocess_mode,
                            preprocess_resolution=params.preprocess_resolution, resolution=params.resolution,
                            mcts_nodes=params.mcts_nodes, mcts_iterations=params.mcts_iterations,
                            mcts_max_depth=params.mcts_max_depth, max_convex_hull=params.max_convex_hull,
                            seed=params.seed)
    return [(np.asarray(v, np.float64), np.asarray(f, np.int64)) for v, f in parts]


def write_obj(path: Path, parts, header: list[str]) -> None:
    lines = [f"# {h}" for h in header]
    base = 1
    for i, (v, f) in enumerate(parts):
        lines.append(f"o part_{i}")
        lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in f.tolist()]
        base += len(v)
    Path(path).write_text("\n".join(lines) + "\n", encoding="ascii")


def read_obj(path: Path) -> list[tuple[np.ndarray, np.ndarray]]:
    """The parts of an OBJ written by write_obj: [(vertices, faces)] with part-local indices."""
    parts, V, F, base = [], [], [], 1
    for line in Path(path).read_text(encoding="ascii").splitlines():
        if line.startswith("o "):
            if V:
                parts.append((np.array(V, float), np.array(F, np.int64) - base))
                base += len(V)
            V, F = [], []
        elif line.startswith("v "):
            V.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            F.append([int(x) for x in line.split()[1:4]])
    if V:
        parts.append((np.array(V, float), np.array(F, np.int64) - base))
    if not parts:
        raise ValueError(f"{path}: no convex part")
    return parts


def generate(V, F, out_dir: Path, params: ConvexPartsParams = ConvexPartsParams(), source: str = "") -> Path:
    """Decomposes (V, F) and writes out_dir/<key>.obj; returns its path."""
    from importlib.metadata import version

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    key = mesh_key(V, F, params)
    parts = decompose(V, F, params)
    header = [f"convex parts of {source or 'a mesh'} ({len(V)} vertices, {len(F)} faces): {len(parts)} parts",
              f"generator: {source_of(__spec__.name)[0]} version {GENERATOR_VERSION}",
              f"coacd {version('coacd')}, parameters {json.dumps(params.to_json(), sort_keys=True)}"]
    path = out_dir / f"{key}.obj"
    write_obj(path, parts, header)
    return path


def _read_off(path: Path) -> tuple[np.ndarray, np.ndarray]:
    rows = [line for line in Path(path).read_text().splitlines() if line.strip() and not line.startswith("#")]
    nv, nf = map(int, rows[1].split()[:2])
    V = np.array([[float(x) for x in r.split()[:3]] for r in rows[2:2 + nv]])
    F = np.array([[int(x) for x in r.split()[1:4]] for r in rows[2 + nv:2 + nv + nf]], np.int32)
    return V, F


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python -m gauss6.generators.convex_parts MESH.off OUT_DIR")
    V, F = _read_off(Path(sys.argv[1]))
    print(generate(V, F, Path(sys.argv[2]), source=Path(sys.argv[1]).name))
