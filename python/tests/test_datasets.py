"""The generated datasets: deterministic regeneration, the triangle counts METHOD.md
section 7 asks for, closed outward 2-manifolds, the peg-in-hole clearance, the bunny.

The committed files are checked as they are on disk; regeneration writes into
pytest's temporary directories, never in place.
"""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import gauss6
from gauss6 import datasets, paths
from gauss6.generators import peg_in_hole

PEG_DIR = paths.DATASETS_DIR / "peg_in_hole"
BUNNY_DIR = paths.DATASETS_DIR / "bunny"


def bunny_tool() -> Path:
    try:
        return paths.tool(datasets.BUNNY_TOOL)
    except FileNotFoundError as e:
        pytest.skip(f"gauss6_make_bunny is not built ({e})")


def read_off(path: Path) -> tuple[list[str], np.ndarray, np.ndarray]:
    """A strict reader for the generated OFF files: ('# ' header lines, V, F)."""
    lines = path.read_text(encoding="ascii").splitlines()
    assert lines[0] == "OFF"
    header = [ln[2:] for ln in lines[1:] if ln.startswith("# ")]
    body = [ln for ln in lines[1:] if not ln.startswith("#")]
    nv, nf, ne = (int(t) for t in body[0].split())
    assert ne == 0 and len(body) == 1 + nv + nf
    V = np.array([[float(t) for t in ln.split()] for ln in body[1:1 + nv]])
    F = np.array([[int(t) for t in ln.split()] for ln in body[1 + nv:]])
    assert V.shape == (nv, 3) and F.shape == (nf, 4) and (F[:, 0] == 3).all()
    return header, V, F[:, 1:]


def edge_use_problems(F: np.ndarray) -> list[str]:
    """Closed, consistently oriented, edge-manifold: every undirected edge is used by
    exactly two faces, once in each direction."""
    directed = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    uniq, counts = np.unique(directed, axis=0, return_counts=True)
    problems = []
    if (counts != 1).any():
        problems.append(f"{int((counts != 1).sum())} directed edges used more than once")
    have = {tuple(e) for e in uniq.tolist()}
    missing = sum((b, a) not in have for a, b in have)
    if missing:
        problems.append(f"{missing} half-edges without an opposite (open boundary)")
    return problems


def signed_volume(V: np.ndarray, F: np.ndarray) -> float:
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def committed_manifest(directory: Path) -> dict:
    return json.loads((directory / "MANIFEST.json").read_text())


# ---------------------------------------------------------------- regeneration


def assert_regenerates(name: str, committed_dir: Path, tmp_path: Path) -> None:
    committed = committed_manifest(committed_dir)
    fresh = datasets.generate(name, tmp_path)
    assert fresh == committed
    for filename, sha in committed["outputs"].items():
        assert datasets.sha256_file(committed_dir / filename) == sha, f"{filename} differs from MANIFEST.json"
        assert (tmp_path / name / filename).read_bytes() == (committed_dir / filename).read_bytes()
    assert (tmp_path / name / "MANIFEST.json").read_bytes() == (committed_dir / "MANIFEST.json").read_bytes()


def test_peg_in_hole_regenerates_byte_identical(tmp_path):
    assert_regenerates("peg_in_hole", PEG_DIR, tmp_path)


def test_bunny_regenerates_byte_identical(tmp_path):
    bunny_tool()
    assert_regenerates("bunny", BUNNY_DIR, tmp_path)


def test_full_resolution_bunny_regenerates_byte_identical(tmp_path):
    bunny_tool()
    assert_regenerates("bunny_full", paths.DATASETS_DIR / "bunny_full", tmp_path)


def test_check_all_reports_a_changed_file(tmp_path, monkeypatch):
    # A copy of the committed peg dataset with one coordinate changed in its last digit.
    shutil.copytree(PEG_DIR, tmp_path / "peg_in_hole")
    off = tmp_path / "peg_in_hole" / "peg.off"
    off.write_text(off.read_text().replace("0.01 -0.05 0.0\n", "0.010000000000000002 -0.05 0.0\n", 1))
    monkeypatch.setattr(datasets.paths, "DATASETS_DIR", tmp_path)
    monkeypatch.setattr(datasets, "DATASETS", ("peg_in_hole",))
    problems = datasets.check_all()
    assert problems == ["peg_in_hole/peg.off: the committed file does not match MANIFEST.json"]


def test_unknown_dataset_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="unknown dataset 'teapot'"):
        datasets.generate("teapot", tmp_path)


def test_off_headers_repeat_the_manifest():
    for directory in (PEG_DIR, BUNNY_DIR):
        m = committed_manifest(directory)
        for filename in m["outputs"]:
            header, _, _ = read_off(directory / filename)
            assert header == [f"generator: {m['generator']}",
                              f"generator_version: {m['generator_version']}",
                              f"parameters: {json.dumps(m['parameters'], sort_keys=True)}",
                              f"source_sha256: {m['source_sha256']}"]
            assert datasets.sha256_file(paths.REPO_ROOT / m["generator"]) == m["source_sha256"]


# ------------------------------------------------------------- peg in a hole


def test_peg_and_box_triangle_counts_and_topology():
    _, peg_V, peg_F = read_off(PEG_DIR / "peg.off")
    _, box_V, box_F = read_off(PEG_DIR / "box_with_hole.off")
    assert len(peg_F) == 288 and len(box_F) == 280
    assert edge_use_problems(peg_F) == [] and edge_use_problems(box_F) == []
    # Euler characteristic: the peg is a sphere (2), the box with a through-hole a torus (0).
    for V, F, chi in ((peg_V, peg_F, 2), (box_V, box_F, 0)):
        num_edges = 3 * len(F) // 2
        assert len(V) - num_edges + len(F) == chi
        assert len(np.unique(F)) == len(V)  # no unused vertex


def test_peg_and_box_are_outward_with_the_solids_volumes():
    p = peg_in_hole.PegInHoleParams()
    _, peg_V, peg_F = read_off(PEG_DIR / "peg.off")
    _, box_V, box_F = read_off(PEG_DIR / "box_with_hole.off")

    def polygon_area(circumradius, n):
        return 0.5 * n * circumradius**2 * np.sin(2 * np.pi / n)

    # Relative 1e-12: the coordinates are correctly rounded doubles; the sums lose ~1e-15.
    peg = polygon_area(p.peg_radius, p.peg_sides) * p.peg_length
    hole_r = (p.peg_radius + p.clearance) / np.cos(np.pi / p.hole_sides)
    box = p.box_size[1] * (p.box_size[0] * p.box_size[2] - polygon_area(hole_r, p.hole_sides))
    assert signed_volume(peg_V, peg_F) == pytest.approx(peg, rel=1e-12)
    assert signed_volume(box_V, box_F) == pytest.approx(box, rel=1e-12)


def test_peg_fits_the_hole_with_the_stated_clearance():
    gen = peg_in_hole
    p = gen.PegInHoleParams()
    assert p.clearance == pytest.approx(0.02 * p.peg_radius, rel=1e-15)
    _, peg_V, _ = read_off(PEG_DIR / "peg.off")
    _, box_V, _ = read_off(PEG_DIR / "box_with_hole.off")
    n = p.hole_sides
    hole = box_V[:n]  # the hole's ring at y = -Y/2, in order (the generator's layout)
    assert np.allclose(np.hypot(hole[:, 0], hole[:, 2]), p.hole_circumradius(), rtol=0, atol=1e-15)
    # Each wall plane: through hole[i], hole[i+1] and parallel to Y; unit normal away from the axis.
    gaps = []
    for i in range(n):
        a, b = hole[i], hole[(i + 1) % n]
        normal = np.array([b[2] - a[2], 0.0, a[0] - b[0]])
        normal /= np.linalg.norm(normal)
        if normal @ a < 0:
            normal = -normal
        gaps.append(normal @ a - peg_V @ normal)  # distance inside the plane, per peg vertex
    min_gap = float(np.min(gaps))
    # The peg's vertices are its outermost points, so this is the peg/wall clearance when
    # coaxial. Lower bound: the stated clearance (1e-12 m: rounding of ~1e-2 m coordinates is
    # ~1e-18 m). Upper bound: it is attained (a peg vertex faces a hole edge's middle).
    assert p.clearance - 1e-12 <= min_gap <= p.clearance + 1e-12
    # The peg is longer than the hole, so inserted it comes out at both ends.
    assert np.ptp(peg_V[:, 1]) > np.ptp(box_V[:, 1])


def test_generated_meshes_pass_the_exact_checks_and_the_loaders_reader():
    # CGAL's polygon-soup reader (the scene loader's) accepts the header comments; the
    # meshes are closed, manifold, outward, with no degenerate triangle and no
    # self-intersection (exact predicates).
    tool = bunny_tool()
    for path in (PEG_DIR / "peg.off", PEG_DIR / "box_with_hole.off", BUNNY_DIR / "bunny.off"):
        r = subprocess.run([str(tool), "--check", str(path)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        stats = json.loads(r.stdout)
        _, V, F = read_off(path)
        assert stats["triangles"] == len(F) and stats["vertices"] == len(V)
        assert stats["closed"] and stats["manifold"]
        assert stats["self_intersections"] == 0 and stats["degenerate_triangles"] == 0
        assert stats["volume"] > 0
        # The project's own reader gives the same arrays, bit for bit.
        if hasattr(gauss6, "read_mesh"):
            V2, F2 = gauss6.read_mesh(str(path))
            assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_check_mode_rejects_an_open_mesh(tmp_path):
    tool = bunny_tool()
    _, V, F = read_off(PEG_DIR / "peg.off")
    open_mesh = tmp_path / "open.off"
    open_mesh.write_text("OFF\n# one cap triangle removed\n" + f"{len(V)} {len(F) - 1} 0\n"
                         + "".join(" ".join(repr(x) for x in v) + "\n" for v in V.tolist())
                         + "".join("3 " + " ".join(map(str, f)) + "\n" for f in F[:-1].tolist()))
    r = subprocess.run([str(tool), "--check", str(open_mesh)], capture_output=True, text=True)
    assert r.returncode == 1 and "not closed" in r.stderr


# -------------------------------------------------------------------- bunny


def test_bunny_size_and_topology():
    _, V, F = read_off(BUNNY_DIR / "bunny.off")
    assert 26_000 <= len(F) <= 28_000
    assert edge_use_problems(F) == []
    assert len(V) - 3 * len(F) // 2 + len(F) == 2  # genus 0
    # 15 cm tall along Y, centred: decimation moves vertices by well under a millimetre.
    assert np.ptp(V[:, 1]) == pytest.approx(datasets.BUNNY_HEIGHT, abs=1e-3)
    assert np.abs(0.5 * (V.max(axis=0) + V.min(axis=0))).max() < 1e-3
    assert signed_volume(V, F) > 0
