"""`gauss6 ccd queries`: continuous-collision query files through one CCD implementation.

The files are those of ../shared/data/ccd-sample-queries (the Tight-Inclusion
benchmark format: 8 rows per query, exact rational coordinates, exact ground
truth; read by the C++ reader, optimized/include/gauss6/ccd_queries.h). Every
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
