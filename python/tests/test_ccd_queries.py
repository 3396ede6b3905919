"""Tests of the per-query CCD of gauss6.ccd (vertex_face, edge_edge, the rigid queries) against the exact reference.

Every query of the shared sets (../shared/data/ccd-sample-queries) goes through the
Python call and through the exact reference (exact_vertex_face / exact_edge_edge):
- the exact answer equals the file's ground truth (the reference's own check);
- no false negative, and u_hit <= u* decided exactly (ExactToi.compare), never by
  rounding: the CCD contract of METHOD.md section 4, no tolerance;
- within tolerance: where both hit and the search finished (status "ok"), either
  u* - u_hit <= 2 time_tolerance (ccd.h: the accepted u-interval is at most
  time_tolerance wide and the contact may lie in the next one), or the stop is a
  near contact: the features' distance at u_hit (computed in numpy by crosscheck_ccd's plain geometry, from
  the interpolated points: closest points by plain geometry, independent of the
  optimized code) is at most distance_reached (+ 1e-12, the rounding of that
  computation on coordinates of size 1), and distance_reached is at most
  NEAR_FACTOR times what the tolerances allow: max(distance_tolerance,
  time_tolerance_reached x the features' relative speed bound). A motion that
  grazes, the features that close long before they touch, may stop that early;
  the stop is then where they first come within the distance reported.
Rigid queries: constructed motions with a known u*, and a fixed-seed random set
against the exact rigid reference.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from gauss6 import ccd, paths
from gauss6.crosscheck_ccd import point_triangle_distance, segment_distance

DATA = paths.SHARED_DATA_DIR / "ccd-sample-queries"
FILES = ccd.query_files(DATA, None) if DATA.is_dir() else []
needs_data = pytest.mark.skipif(not FILES, reason=f"{DATA} not present")
TOL = 1e-6                 # the default time_tolerance (CcdSettings)
DISTANCE_TOL = 1e-9        # the default distance_tolerance (CcdSettings)
# The accepted box's feature-parameter widths blur F beyond the u-width's motion:
# measured at most 1.35 x on the shared sets; 4 leaves room for other settings.
NEAR_FACTOR = 4.0


def distance_at(kind: str, x: np.ndarray, u: float) -> float:
    """Distance of the query's features at u (points interpolated linearly)."""
    y = x[:4] + u * (x[4:] - x[:4])
    if kind == "vf":
        return point_triangle_distance(*y)
    return segment_distance(*y)


def run_linear(kind: str, x: np.ndarray, **kw):
    """One query of the file layout (8 rows: 4 points at u = 0, then at u = 1) through gauss6.ccd."""
    if kind == "vf":
        return ccd.vertex_face(x[0], x[1:4], x[4], x[5:8], **kw)
    return ccd.edge_edge(x[0:2], x[2:4], x[4:6], x[6:8], **kw)


def exact_linear(kind: str, x: np.ndarray):
    if kind == "vf":
        return ccd.exact_vertex_face(x[0], x[1:4], x[4], x[5:8])
    return ccd.exact_edge_edge(x[0:2], x[2:4], x[4:6], x[6:8])


@needs_data
@pytest.mark.parametrize("path,kind", FILES, ids=[f"{p.split('ccd-sample-queries/')[-1]}" for p, _ in FILES])
def test_shared_queries_against_the_exact_reference(path, kind):
    q = ccd.read_query_file(path, kind)
    assert q["points"].shape[1:] == (8, 3)
    assert q["exact"].all(), "the shared data's coordinates are doubles"
    for x, expected, line in zip(q["points"], q["expected"], q["line"]):
        r = run_linear(kind, x)
        e = exact_linear(kind, x)
        where = f"{path}:{line}"
        assert e.hit == bool(expected), f"{where}: reference disagrees with the ground truth"
        if e.hit:
            assert r.hit, f"{where}: false negative ({r})"
            assert e.compare(r.u_hit) <= 0, f"{where}: u_hit {r.u_hit!r} after u* {e.lower!r}"
        if r.status != "ok" or not r.hit:
            continue
        assert r.time_tolerance_reached <= TOL, where
        if e.hit and e.lower - r.u_hit <= 2 * TOL:
            continue
        # Stopped earlier than 2 tolerances before u* (or no contact at all: a false
        # positive): a near contact, within the distance the result reports.
        speed = 2 * np.linalg.norm(x[4:] - x[:4], axis=1).max()
        allowed = NEAR_FACTOR * max(DISTANCE_TOL, r.time_tolerance_reached * speed)
        assert r.distance_reached <= allowed, f"{where}: {r.distance_reached} reported, tolerances allow {allowed}"
        d = distance_at(kind, x, r.u_hit)
        assert d <= r.distance_reached + 1e-12, f"{where}: distance {d} at u_hit, {r.distance_reached} reported"


def test_linear_vertex_face_known_contact():
    # The vertex falls from z = 1 to z = -2 through the face at z = 0: u* = 1/3.
    face = np.array([[-1.0, -1, 0], [1, -1, 0], [0, 1, 0]])
    r = ccd.vertex_face([0, 0, 1.0], face, [0, 0, -2.0], face)
    e = ccd.exact_vertex_face([0, 0, 1.0], face, [0, 0, -2.0], face)
    assert r.hit and r.status == "ok" and e.hit
    assert e.compare(r.u_hit) <= 0 and 1 / 3 - r.u_hit <= 2 * TOL
    # Beside the face: no contact.
    r = ccd.vertex_face([5, 0, 1.0], face, [5, 0, -2.0], face)
    assert not r.hit and r.u_hit == 1.0 and not ccd.exact_vertex_face([5, 0, 1.0], face, [5, 0, -2.0], face).hit
    # A window that ends before the contact, and a separation reached earlier.
    assert not ccd.vertex_face([0, 0, 1.0], face, [0, 0, -2.0], face, u_end=0.3).hit
    r = ccd.vertex_face([0, 0, 1.0], face, [0, 0, -2.0], face, min_separation=0.3)
    assert r.hit and r.u_hit <= (1 - 0.3) / 3 + 1e-12


def test_linear_edge_edge_known_contact():
    a = np.array([[-1.0, 0, 1], [1, 0, 1]])
    b = np.array([[0.0, -1, 0], [0, 1, 0]])
    r = ccd.edge_edge(a, b, a - [0, 0, 3], b)  # edge A drops through edge B: u* = 1/3
    e = ccd.exact_edge_edge(a, b, a - [0, 0, 3], b)
    assert r.hit and e.hit and e.compare(r.u_hit) <= 0 and 1 / 3 - r.u_hit <= 2 * TOL


def test_bad_input_is_a_status_or_a_clear_error():
    face = np.zeros((3, 3))
    r = ccd.vertex_face([math.nan, 0, 0], face, [0, 0, 0], face)
    assert r.status == "invalid_input"
    with pytest.raises(ValueError, match="finite"):
        ccd.exact_vertex_face([math.nan, 0, 0], face, [0, 0, 0], face)
    with pytest.raises(TypeError):
        ccd.vertex_face([0, 0], face, [0, 0, 0], face)  # a vertex must be (3,)
    with pytest.raises(ValueError, match="quaternion"):
        ccd.rigid_vertex_face([0, 0, 0], [0, 0, 0, 0], [0, 0, 0], [1, 0, 0, 0], [0, 0, 0], face)


ID = [1.0, 0, 0, 0]


def test_rigid_queries_known_contacts():
    face_W = np.array([[-1.0, -1, 0], [1, -1, 0], [0, 1, 0]])
    # Translation: the body point at G falls from z = 1 to z = -2: u* = 1/3.
    r = ccd.rigid_vertex_face([0, 0, 1.0], ID, [0, 0, -2.0], ID, [0, 0, 0], face_W)
    e = ccd.exact_rigid_vertex_face([0, 0, 1.0], ID, [0, 0, -2.0], ID, [0, 0, 0], face_W)
    assert r.hit and e.hit and r.status == "ok" and e.compare(r.u_hit) <= 0 and 1 / 3 - r.u_hit <= 2 * TOL
    # The moving face meets a static vertex, the moving edge a static edge.
    r = ccd.rigid_face_vertex([0, 0, -1.0], ID, [0, 0, 2.0], ID, face_W, [0, 0, 0])
    e = ccd.exact_rigid_face_vertex([0, 0, -1.0], ID, [0, 0, 2.0], ID, face_W, [0, 0, 0])
    assert r.hit and e.hit and e.compare(r.u_hit) <= 0 and 1 / 3 - r.u_hit <= 2 * TOL
    edge_B = np.array([[-1.0, 0, 0], [1, 0, 0]])
    edge_W = np.array([[0.0, -1, 0], [0, 1, 0]])
    r = ccd.rigid_edge_edge([0, 0, 1.0], ID, [0, 0, -2.0], ID, edge_B, edge_W)
    e = ccd.exact_rigid_edge_edge([0, 0, 1.0], ID, [0, 0, -2.0], ID, edge_B, edge_W)
    assert r.hit and e.hit and e.compare(r.u_hit) <= 0 and 1 / 3 - r.u_hit <= 2 * TOL
    assert 1 <= r.filter_intervals <= 256  # the u-filter ran (rigid), within its budget
    # A half turn is a status (split the step), reported as a conservative hit at 0.
    r = ccd.rigid_vertex_face([0, 0, 1.0], ID, [0, 0, 1.0], [0, 1.0, 0, 0], [0, 0, 0], face_W)
    assert r.status == "half_turn" and r.hit and r.u_hit == 0


def test_rigid_random_queries_against_the_exact_reference():
    # 300 random rigid queries (fixed seed) of each kind, the body passing through the
    # features' neighbourhood, rotations up to 90 degrees: the contract u_hit <= u*
    # exactly, no miss. (The tolerance side is checked on the linear sets above and on
    # the mesh steps by `gauss6 crosscheck ccd`.)
    rng = np.random.default_rng(20)
    counts = {"hits": 0, "queries": 0}
    for _ in range(300):
        p0 = rng.normal(0, 0.5, 3)
        p1 = -p0 + rng.normal(0, 0.1, 3)  # through the features' neighbourhood
        axis = rng.normal(size=3)
        angle = rng.uniform(0, math.pi / 2)
        q0 = np.array([1.0, 0, 0, 0])
        q1 = np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis / np.linalg.norm(axis)])
        tri, pt, e1, e2 = rng.normal(0, 0.5, (3, 3)), rng.normal(0, 0.5, 3), rng.normal(0, 0.5, (2, 3)), \
            rng.normal(0, 0.5, (2, 3))
        for fn, exact, args in ((ccd.rigid_vertex_face, ccd.exact_rigid_vertex_face, (pt, tri)),
                                (ccd.rigid_face_vertex, ccd.exact_rigid_face_vertex, (tri, pt)),
                                (ccd.rigid_edge_edge, ccd.exact_rigid_edge_edge, (e1, e2))):
            r = fn(p0, q0, p1, q1, *args)
            e = exact(p0, q0, p1, q1, *args)
            counts["queries"] += 1
            if e.hit:
                counts["hits"] += 1
                assert r.hit, (fn.__name__, p0, p1, q1, args)
                assert e.compare(r.u_hit) <= 0, (fn.__name__, r, e)
    assert counts["hits"] >= 50, counts  # the set exercises contacts, not only misses
