"""Tests of the dense bunnies' generator (gauss6.generators.subdivide): one level of
midpoint subdivision on the peg (the bunny's 1.1M triangles take minutes: `gauss6 datasets generate
--only bunny_x16`) keeps a closed, manifold, outward mesh with no self-intersection, the same surface
(volume and area), four times the triangles; the output is deterministic.
"""
from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from gauss6 import datasets, paths
from gauss6.generators import subdivide


def generator():
    return subdivide


def area_volume(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cross = np.cross(b - a, c - a)
    return 0.5 * np.linalg.norm(cross, axis=1).sum(), np.einsum("ij,ij->", a, np.cross(b, c)) / 6


def test_split_in_four_keeps_the_surface_and_its_checks(tmp_path):
    gen = generator()
    V, F = gen.read_off(paths.DATASETS_DIR / "peg_in_hole" / "peg.off")
    V2, F2 = gen.subdivide(V, F, 2)
    assert len(F2) == 16 * len(F)
    # Euler: a closed genus-0 mesh keeps V - E + F = 2 (E = 3 F / 2).
    assert len(V2) - 3 * len(F2) // 2 + len(F2) == 2
    # The same surface: area and volume equal up to rounding (midpoints are one rounding off their
    # edges: 1e-12 relative is many orders of magnitude above it and far below any real change).
    for x, y in zip(area_volume(V, F), area_volume(V2, F2)):
        assert abs(x - y) <= 1e-12 * abs(x)
    path = tmp_path / "peg16.off"
    gen.write_off(path, V2, F2, ["test"])
    tool = paths.tool(datasets.BUNNY_TOOL)
    r = subprocess.run([str(tool), "--check", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    assert stats["closed"] and stats["manifold"] and stats["self_intersections"] == 0
    assert stats["triangles"] == len(F2)
    # Deterministic: the same input gives the same bytes.
    again = tmp_path / "again.off"
    gen.write_off(again, *gen.subdivide(V, F, 2), ["test"])
    assert again.read_bytes() == path.read_bytes()
    with pytest.raises(ValueError, match="levels"):
        gen.subdivide(V, F, 0)


def test_the_dense_bunnies_are_generated_on_demand_only():
    assert set(datasets.ON_DEMAND) == {"bunny_x4", "bunny_x16"}
    assert not set(datasets.ON_DEMAND) & set(datasets.DATASETS)  # not in generate / check of everything
    for name in datasets.ON_DEMAND:
        manifest = json.loads((paths.DATASETS_DIR / name / "MANIFEST.json").read_text())
        assert manifest["parameters"]["levels"] == datasets.ON_DEMAND[name]
        assert manifest["parameters"]["input_sha256"] == datasets.sha256_file(
            paths.DATASETS_DIR / "bunny_full" / "bunny.off")
