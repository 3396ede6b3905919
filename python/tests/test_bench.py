"""Tests of the benchmark runner (gauss6.bench) and of the sweeps' Pareto front (gauss6.sweeps).

Cheap: pre-recorded Google Benchmark JSON (the shape of Google Benchmark 1.7's
output with the latency counters of benchmarks/latency.h) and, when the suites
are built, one real filtered run into a temporary folder.
"""
from __future__ import annotations

import json

import pytest

from gauss6 import bench, paths, sweeps

RECORDED = {"context": {"host_name": "ci", "num_cpus": 2, "load_avg": [0.1], "date": "now"}, "benchmarks": [
    {"name": "HapticTick/peg/pressing_sliding/iterations:2000/manual_time", "run_type": "iteration",
     "run_name": "HapticTick/peg/pressing_sliding/iterations:2000/manual_time", "repetition_index": i,
     "iterations": 2000, "real_time": rt, "cpu_time": rt, "time_unit": "ns", "p50_ns": p50, "p99_ns": p99,
     "max_ns": 9000.0, "rows_per_call": 64.0}
    for i, (rt, p50, p99) in enumerate([(2300.0, 2100.0, 2600.0), (2500.0, 2150.0, 2700.0), (9000.0, 2120.0, 2650.0)])
] + [
    {"name": "HapticTick/peg/pressing_sliding/iterations:2000/manual_time_median", "run_type": "aggregate",
     "aggregate_name": "median", "run_name": "HapticTick/peg/pressing_sliding/iterations:2000/manual_time",
     "iterations": 3, "real_time": 2500.0, "cpu_time": 2500.0, "time_unit": "ns", "p50_ns": 2120.0},
    {"name": "LockstepTick/peg/pressing_sliding/iterations:2000/manual_time", "run_type": "iteration",
     "iterations": 2000, "real_time": 350.0, "cpu_time": 340.0, "time_unit": "us", "p50_ns": 3.4e5, "p99_ns": 4.5e6},
]}


def test_base_name_strips_suffixes():
    assert bench.base_name(RECORDED["benchmarks"][0]) == "HapticTick/peg/pressing_sliding"


def test_samples_keep_repetitions_not_aggregates():
    s = bench.samples(RECORDED)
    assert len(s["HapticTick/peg/pressing_sliding"]) == 3
    assert len(s["LockstepTick/peg/pressing_sliding"]) == 1


def test_summary_reports_median_over_repetitions_and_units():
    rows = {r["name"]: r for r in bench.summarize(RECORDED)}
    tick = rows["HapticTick/peg/pressing_sliding"]
    assert tick["p50_ns"] == 2120.0 and tick["p99_ns"] == 2650.0  # medians of the 3 repetitions
    assert tick["mean_ns"] == 2500.0  # the 9000 ns outlier repetition does not move the median
    assert rows["LockstepTick/peg/pressing_sliding"]["mean_ns"] == 350e3  # us -> ns
    table = bench.format_table(list(rows.values()), RECORDED["context"])
    assert "| HapticTick/peg/pressing_sliding | 2.12 us | 2.65 us |" in table


def test_pareto_front():
    pts = [(1.0, 1e-3), (2.0, 1e-6), (3.0, 1e-6), (0.5, 1e-2), (2.5, 1e-9), (1.5, 1e-2)]
    # (3, 1e-6) is beaten by (2, 1e-6); (1.5, 1e-2) by (1, 1e-3).
    assert sweeps.pareto_front(pts) == [3, 0, 1, 4]


def _built() -> bool:
    try:
        bench.bench_binary()
        return True
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not _built(), reason="benchmarks not built (-DGAUSS6_BUILD_BENCHMARKS=ON)")
def test_real_filtered_run_writes_json_table_and_plot(tmp_path):
    rows = bench.run(None, tmp_path, "ForceWarm/box/m|BvhBuild/peg_in_hole/peg.off/leaf:4/", repetitions=2,
                     min_time=0.02)
    names = {r["name"] for r in rows}
    assert names == {"ForceWarm/box/m<=12", "BvhBuild/peg_in_hole/peg.off/leaf:4"}
    for r in rows:
        assert 0 < r["p50_ns"] <= r["p99_ns"] <= r["max_ns"]
    doc = json.loads((tmp_path / "benchmarks.json").read_text())
    assert doc["benchmarks"]
    assert (tmp_path / "table.md").read_text().count("\n| ") >= 3
    assert (tmp_path / "latency.png").stat().st_size > 1000


@pytest.mark.skipif(not _built(), reason="benchmarks not built (-DGAUSS6_BUILD_BENCHMARKS=ON)")
def test_a_filter_that_matches_nothing_is_named(tmp_path):
    # Google Benchmark exits 0 with an empty output file then: the runner says so, no traceback.
    with pytest.raises(RuntimeError, match="no benchmark matches the filter 'NoSuchBenchmark'"):
        bench.run_benchmarks(bench.bench_binary(), tmp_path / "out.json", "NoSuchBenchmark")
