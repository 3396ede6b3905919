"""Continuous collision detection from Python: per-query calls, and `gauss6 ccd queries`.

Per query (the optimized narrow phase of optimized/gauss6/ccd/ccd.h, one call
each; the exact twin of reference/ccd.h beside it):

    from gauss6 import ccd
    r = ccd.vertex_face(vertex_start, face_start, vertex_end, face_end)   # linear motion
    r = ccd.edge_edge(edge_a_start, edge_b_start, edge_a_end, edge_b_end)
    r = ccd.rigid_vertex_face(p0, q0, p1, q1, vertex_B, face_W)           # Cayley rigid motion
    r = ccd.rigid_face_vertex(p0, q0, p1, q1, face_B, vertex_W)
    r = ccd.rigid_edge_edge(p0, q0, p1, q1, edge_B, edge_W)
    r.hit, r.u_hit, r.status, r.time_tolerance_reached, r.distance_reached, r.iterations, r.filter_intervals

Linear: every vertex moves on x(u) = x_start + u (x_end - x_start), u in [0, 1];
a vertex is (3,), a face (3, 3) and an edge (2, 3), one point a row. Rigid: the
feature named _B is a body point of the moving body (body frame, origin at G),
moved by the Cayley motion from pose (p0, q0) to (p1, q1) (q = (w, x, y, z), not
necessarily unit: METHOD.md sections 1 and 4); the feature named _W is static
(world frame). Keyword settings (CcdSettings of ccd.h, its defaults when not
given): u_end (search [0, u_end]), min_separation (report the first u where the
distance may be <= this; 0: contact), time_tolerance, distance_tolerance,
max_iterations, and for rigid queries use_u_filter and early_hit.

The answer (QueryResult) is conservative: u_hit <= u*, the exact first contact;
hit is never False where a contact exists. status is "ok" when the search
finished within the tolerances; "max_iterations" or "workspace_full" when it gave
up (hit is then True, u_hit the earliest u not proven free); "invalid_input"
(non-finite or huge coordinate, bad window); "half_turn" (rigid: a relative
rotation near 180 degrees, split the step; hit True, u_hit 0).
time_tolerance_reached is the u-width of the accepted box and distance_reached
a distance within which the features lie at u_hit; iterations counts the boxes
of the bisection and filter_intervals the u-intervals the u-filter examined
(rigid queries and the linear ones a short bisection did not decide; at most
256, past which the rest of the window goes to the bisection whole). The tests
(python/tests/test_ccd_queries.py) check u_hit <= u* exactly on every shared
query and bound u* - u_hit.

The exact answers: exact_vertex_face, exact_edge_edge (same arguments) and
exact_rigid_vertex_face, exact_rigid_face_vertex, exact_rigid_edge_edge (same
arguments, u_end keyword) return an ExactToi: hit, lower <= u* <= upper
(adjacent doubles or equal) and compare(u), the exact sign of u - u*. The
doubles are taken as the rationals they denote. Slow (GMP): for checks.
read_query_file(path, kind) returns a query file's points (n, 8, 3), expected,
line and exact as arrays.

`gauss6 ccd queries`: continuous-collision query files through one CCD implementation.

The files are those of ../shared/data/ccd-sample-queries (the Tight-Inclusion
benchmark format: 8 rows per query, exact rational coordinates, exact ground
truth; read by the C++ reader, optimized/gauss6/io/ccd_queries.h). Every
query runs through the linear-motion primitive of the chosen implementation:

- optimized: ccd_linear_vertex_face / ccd_linear_edge_edge (conservative:
  a hit may be reported where there is none, never the reverse);
- reference: the exact time of impact (query_toi), so its answer must equal the
  ground truth.

Counts: `positives` is the number of queries whose ground truth is a contact;
a false negative is a ground-truth contact the implementation missed (a
violation of the CCD contract); a false positive is a reported hit without a
contact (allowed for the optimized CCD, a bug for the reference). `seconds` is
the time spent in the primitive calls alone, measured in C++.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from . import _gauss6
from ._gauss6.ccd import (  # noqa: F401  (per-query CCD, documented above)
    ExactToi,
    QueryResult,
    edge_edge,
    exact_edge_edge,
    exact_rigid_edge_edge,
    exact_rigid_face_vertex,
    exact_rigid_vertex_face,
    exact_vertex_face,
    read_query_file,
    rigid_edge_edge,
    rigid_face_vertex,
    rigid_vertex_face,
    vertex_face,
)

KINDS = ("vf", "ee")
IMPLS = ("optimized", "reference")
# Folder names of the shared data, as the C++ lister knows them.
KIND_OF_FOLDER = {"vertex-face": "vf", "edge-edge": "ee"}


@dataclass
class QueryStats:
    """Totals over one or more query files (the JSON of `gauss6 ccd queries`)."""

    queries: int = 0
    positives: int = 0
    false_negatives: int = 0
    false_positives: int = 0
    seconds: float = 0.0
    missed: list[str] = field(default_factory=list)  # "file:line" of each false negative

    def as_json(self) -> dict:
        return {"queries": self.queries, "positives": self.positives, "false_negatives": self.false_negatives,
                "false_positives": self.false_positives, "seconds": self.seconds}

    def add_file(self, path: str, kind: str, impl: str, time_tolerance: float | None = None) -> None:
        if time_tolerance is None:  # the narrow phase's default (CcdSettings, ccd.h)
            time_tolerance = _gauss6.defaults()["ccd"]["time_tolerance"]
        r = _gauss6.ccd.run_query_file(str(path), kind, impl, time_tolerance)
        for hit, expected, line in zip(r["hit"], r["expected"], r["line"]):
            self.queries += 1
            self.positives += int(expected)
            if expected and not hit:
                self.false_negatives += 1
                self.missed.append(f"{path}:{line}")
            elif hit and not expected:
                self.false_positives += 1
        self.seconds += r["seconds"]


def query_files(target: Path, kind: str | None) -> list[tuple[str, str]]:
    """(path, kind) of every file to run: one file (kind required), or every CSV below a
    directory in a vertex-face/ or edge-edge/ folder (kind, if given, filters them)."""
    target = Path(target)
    if target.is_dir():
        files = [(p, k) for p, k in _gauss6.ccd.list_query_files(str(target)) if kind is None or k == kind]
        if not files:
            raise ValueError(f"{target}: no *.csv under a vertex-face/ or edge-edge/ folder"
                             + (f" of kind {kind}" if kind else ""))
        return files
    if not target.is_file():
        raise ValueError(f"{target}: no such file or directory")
    if kind is None:
        kind = KIND_OF_FOLDER.get(target.parent.name)
        if kind is None:
            raise ValueError(f"{target}: --kind vf|ee is required (the folder name does not tell)")
    return [(str(target), kind)]


def run_queries(target: Path, kind: str | None, impl: str, time_tolerance: float | None = None) -> QueryStats:
    """Runs every query of target (a file or a directory) through impl."""
    if impl not in IMPLS:
        raise ValueError(f"impl must be one of {IMPLS}")
    stats = QueryStats()
    for path, k in query_files(target, kind):
        stats.add_file(path, k, impl, time_tolerance)
    return stats


def format_stats(stats: QueryStats, impl: str) -> str:
    per_query_us = 1e6 * stats.seconds / stats.queries if stats.queries else 0.0
    return (f"{impl}: {stats.queries} queries, {stats.positives} positives, "
            f"{stats.false_negatives} false negatives, {stats.false_positives} false positives, "
            f"{stats.seconds:.3f} s ({per_query_us:.1f} us/query)")
