"""Tests of the regression gate (python/gauss6/gate.py, thresholds in benchmarks/gate.toml).

Cheap enough for every CI run: the comparisons are tested on synthetic and on
pre-recorded benchmark JSON (no rebuild of another revision), plus one real
interleaved run of a filtered benchmark through the gate's command, with the same
build as both sides. Required behaviour: a planted slowdown and a planted accuracy
loss fail the gate; identical revisions pass it; a violated property fails it.
"""
from __future__ import annotations

import copy
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gauss6 import bench, gate, paths

CONFIG = gate.load_config(gate.DEFAULT_CONFIG)


def synthetic(name: str, p50s: list[float]) -> dict[str, list[dict]]:
    """bench.samples()-shaped data: one benchmark, one repetition per p50 value (ns)."""
    return {name: [{"name": name, "run_type": "iteration", "iterations": 1000, "real_time": v, "time_unit": "ns",
                    "p50_ns": v, "p99_ns": 3 * v} for v in p50s]}


def noisy(center: float, n: int, seed: int, spread: float = 0.03) -> list[float]:
    """n samples around center with a few percent of noise (as a quiet machine gives)."""
    return list(center * (1 + spread * np.random.default_rng(seed).standard_normal(n)))


def speed_verdicts(base, work) -> dict[str, str]:
    return {r.name: r.verdict for r in gate.compare_speed(base, work, CONFIG["speed"])}


# ---------------------------------------------------------------------------------------
# Speed
# ---------------------------------------------------------------------------------------

def test_planted_slowdown_fails():
    base = synthetic("ForceCold/box", noisy(1000, 9, seed=1))
    work = synthetic("ForceCold/box", [1.3 * v for v in noisy(1000, 9, seed=2)])  # 30% slower
    rows = gate.compare_speed(base, work, CONFIG["speed"])
    assert [r.verdict for r in rows] == ["slower"]
    result = gate.decide(rows, [], CONFIG, "synthetic")
    assert not result["passed"] and "slower" in result["failures"][0]
    assert "FAILED" in gate.format_report(result)


def test_identical_samples_pass():
    s = noisy(1000, 9, seed=3)
    rows = gate.compare_speed(synthetic("X", s), synthetic("X", s), CONFIG["speed"])
    assert rows[0].verdict == "same" and rows[0].ratio == 1.0
    assert gate.decide(rows, [], CONFIG, "synthetic")["passed"]


def test_slowdown_below_threshold_passes():
    # 5% slower, clearly significant, but under max_slowdown (10%): not a failure.
    base = synthetic("X", noisy(1000, 9, seed=4, spread=0.005))
    work = synthetic("X", [1.05 * v for v in noisy(1000, 9, seed=5, spread=0.005)])
    assert speed_verdicts(base, work) == {"X": "same"}


def test_large_but_insignificant_difference_passes():
    # Two samples a side: too few to claim anything (min_samples), whatever the ratio.
    assert speed_verdicts(synthetic("X", [1000, 1010]), synthetic("X", [2000, 2020])) == {"X": "not significant"}


def test_u_test_matches_scipy():
    from scipy.stats import mannwhitneyu

    a, b = noisy(1000, 9, seed=6), noisy(1100, 9, seed=7)
    expected = mannwhitneyu(a, b, alternative="two-sided").pvalue
    assert gate.u_test(a, b) == pytest.approx(expected, rel=1e-12)


# ---------------------------------------------------------------------------------------
# Accuracy and properties (pre-recorded check output: the shape of `crosscheck qp/ccd --json`)
# ---------------------------------------------------------------------------------------

RECORDED_QP = {"ok": True, "tolerance": 1e-09, "families": [
    {"name": "box", "count": 300, "max_rel_err_ac": 5.01e-15, "max_rel_err_force": 8.62e-14,
     "max_kkt_residual": 4.92e-14, "certificate_failures": 0, "statuses": {"optimal": 300}},
    {"name": "peg", "count": 300, "max_rel_err_ac": 2.27e-15, "max_rel_err_force": 5.73e-14,
     "max_kkt_residual": 1.63e-14, "certificate_failures": 0, "statuses": {"optimal": 300}}]}
RECORDED_CCD = {"ok": True, "sets": [
    {"name": "peg_script", "steps": 38, "false_negatives": 0, "late_hits": 0, "max_gap_u": 0.0458,
     "p99_gap_u": 0.0454, "intersecting_stop_poses": 0, "max_stop_separation": 1.000018e-06}]}


def flat(qp, ccd) -> dict:
    return {**gate.flatten(qp, "qp"), **gate.flatten(ccd, "ccd")}


def test_flatten_keys_list_items_by_name():
    f = gate.flatten(RECORDED_QP, "qp")
    assert f["qp/families/peg/max_rel_err_ac"] == 2.27e-15
    assert f["qp/ok"] is True


def test_identical_accuracy_passes():
    rows = gate.compare_accuracy(flat(RECORDED_QP, RECORDED_CCD), flat(RECORDED_QP, RECORDED_CCD), CONFIG)
    assert rows and all(r.verdict == "ok" for r in rows)
    assert gate.decide([], rows, CONFIG, "recorded")["passed"]


def test_rounding_level_change_passes():
    # 5e-15 -> 9e-15: rounding noise (under abs = 1e-13 of gate.toml), not a loss.
    work = copy.deepcopy(RECORDED_QP)
    work["families"][0]["max_rel_err_ac"] = 9e-15
    rows = gate.compare_accuracy(flat(RECORDED_QP, RECORDED_CCD), flat(work, RECORDED_CCD), CONFIG)
    assert all(r.verdict == "ok" for r in rows)


def test_planted_accuracy_loss_fails():
    # The projection's error grows from 5e-15 to 1e-9 (e.g. a looser feasibility tolerance).
    work = copy.deepcopy(RECORDED_QP)
    work["families"][0]["max_rel_err_ac"] = 1e-9
    rows = gate.compare_accuracy(flat(RECORDED_QP, RECORDED_CCD), flat(work, RECORDED_CCD), CONFIG)
    bad = [r for r in rows if r.verdict != "ok"]
    assert [(r.path, r.verdict) for r in bad] == [("qp/families/box/max_rel_err_ac", "less accurate")]
    result = gate.decide([], rows, CONFIG, "recorded")
    assert not result["passed"] and "less accurate" in gate.format_report(result).lower()


def test_planted_ccd_gap_loss_fails():
    # The CCD stops 10% earlier than before on its worst step: more than rel = 5%.
    work = copy.deepcopy(RECORDED_CCD)
    work["sets"][0]["max_gap_u"] *= 1.10
    rows = gate.compare_accuracy(flat(RECORDED_QP, RECORDED_CCD), flat(RECORDED_QP, work), CONFIG)
    assert [r.path for r in rows if r.verdict == "less accurate"] == ["ccd/sets/peg_script/max_gap_u"]


def test_violated_property_fails_even_if_base_violates_it():
    base, work = copy.deepcopy(RECORDED_CCD), copy.deepcopy(RECORDED_CCD)
    for d in (base, work):
        d["sets"][0]["false_negatives"] = 1
        d["ok"] = False
    rows = gate.compare_accuracy(flat(RECORDED_QP, base), flat(RECORDED_QP, work), CONFIG)
    assert {r.path for r in rows if r.verdict == "violated"} == {"ccd/sets/peg_script/false_negatives", "ccd/ok"}


def test_benchmark_counter_property():
    work = synthetic("CcdQuery/unit-tests/vf", [500.0, 510.0])
    work["CcdQuery/unit-tests/vf"][1]["missed_contacts"] = 2.0
    rows = gate.compare_accuracy({}, gate.bench_properties(work, CONFIG), CONFIG)
    assert [(r.path, r.verdict) for r in rows] == [("bench/CcdQuery/unit-tests/vf/missed_contacts", "violated")]


def test_config_is_complete():
    for key in ("max_slowdown", "alpha", "rounds", "repetitions", "metric", "filter"):
        assert key in CONFIG["speed"]
    assert CONFIG["speed"]["rounds"] >= 2, "interleaving needs at least A B A B"
    assert CONFIG["accuracy"]["check"], "at least one accuracy check"


# ---------------------------------------------------------------------------------------
# One real run: the same build on both sides (identical revisions), interleaved.
# ---------------------------------------------------------------------------------------

# ---------------------------------------------------------------------------------------
# Instruction counts (callgrind): deterministic, a plain threshold.
# ---------------------------------------------------------------------------------------

def test_count_comparison_flags_an_increase_beyond_the_threshold():
    limit = CONFIG["count"]["max_increase"]
    base = {"CcdQuery/unit-tests": 1000.0, "ForceCold/box": 500.0}
    rows = gate.compare_counts(base, {"CcdQuery/unit-tests": 1000.0 * (1 + 2 * limit), "ForceCold/box": 500.0},
                               CONFIG["count"])
    assert {r.name: r.verdict for r in rows} == {"CcdQuery/unit-tests": "more instructions", "ForceCold/box": "same"}
    result = gate.decide([], [], CONFIG, "synthetic", rows)
    assert not result["passed"] and "more instructions" in result["failures"][0]
    assert "MORE INSTRUCTIONS" in gate.format_report(result)
    within = gate.compare_counts(base, {k: v * (1 + limit / 2) for k, v in base.items()}, CONFIG["count"])
    assert gate.decide([], [], CONFIG, "synthetic", within)["passed"]


def _build_with_count() -> Path | None:
    for b in (paths.build_dir(), paths.REPO_ROOT / "build-gate"):
        if (b / gate.COUNT_RELPATH).exists():
            return b
    return None


@pytest.mark.skipif(_build_with_count() is None or shutil.which("valgrind") is None,
                    reason="gauss6_count not built or valgrind missing (tools/setup.sh installs it)")
def test_real_counts_are_deterministic_and_flag_a_planted_regression(tmp_path):
    # One workload (the cold projection of the box family: 300 calls, a few seconds
    # under callgrind), the same binary three times: twice as it is (the counts must
    # be equal to the instruction, whatever the load), once with a planted
    # regression of 5% more work (gauss6_count --plant 0.05), which must fail.
    cfg = copy.deepcopy(CONFIG)
    cfg["count"]["filter"] = "ForceCold/box"
    side = gate.Side("work", paths.REPO_ROOT, _build_with_count())
    first = gate.run_counts(side, cfg, tmp_path / "a", paths.REPO_ROOT, log=lambda m: None)
    again = gate.run_counts(side, cfg, tmp_path / "b", paths.REPO_ROOT, log=lambda m: None)
    planted = gate.run_counts(side, cfg, tmp_path / "c", paths.REPO_ROOT, plant=0.05, log=lambda m: None)
    assert set(first) == {"ForceCold/box"} and first["ForceCold/box"] > 1000
    assert first == again
    rows = gate.compare_counts(first, again, cfg["count"])
    assert [r.verdict for r in rows] == ["same"] and rows[0].ratio == 1.0
    rows = gate.compare_counts(first, planted, cfg["count"])
    assert [r.verdict for r in rows] == ["more instructions"], rows
    assert not gate.decide([], [], cfg, "planted", rows)["passed"]


def _build_with_bench() -> Path | None:
    for b in (paths.build_dir(), paths.REPO_ROOT / "build-gate"):
        if (b / bench.BENCH_RELPATH).exists():
            return b
    return None


@pytest.mark.skipif(_build_with_bench() is None, reason="benchmarks not built (-DGAUSS6_BUILD_BENCHMARKS=ON)")
def test_real_identical_run_passes_and_planted_slowdown_fails(tmp_path):
    build = _build_with_bench()
    cmd = [sys.executable, "-m", "gauss6", "gate", "--base-build", str(build), "--work-build", str(build),
           "--no-build-work", "--no-accuracy", "--no-count", "--json",
           "--filter", "ForceWarm/box/m|CcdQuery/unit-tests/vf", "--rounds", "3", "--repetitions", "3",
           "--min-time", "0.02"]
    env = dict(os.environ, PYTHONPATH=str(paths.REPO_ROOT / "python"))
    # Wall time on a shared 2-core VM: an identical build was once judged slower (CcdQuery/unit-tests/vf,
    # 390 -> 501 ns at the median, p = 0.0035, under other tenants' load). So up to three tries, each
    # with its own runs; every try that fails may fail on speed alone, and one must pass: a gate that
    # flags identical builds every time still fails here.
    outputs = []
    for attempt in range(3):
        proc = subprocess.run(cmd + ["--cache-dir", str(tmp_path / f"try{attempt}")], capture_output=True,
                              text=True, env=env, timeout=300)
        outputs.append(proc.stdout + proc.stderr)
        assert proc.returncode in (0, 1), outputs[-1]
        result = json.loads(proc.stdout)
        assert all(f.split()[0] in {"ForceWarm/box/m<=12", "CcdQuery/unit-tests/vf"} and " slower x" in f
                   for f in result["failures"]), outputs[-1]
        if proc.returncode == 0:
            break
    assert proc.returncode == 0, "\n".join(outputs)
    assert result["passed"]
    names = {r["name"] for r in result["speed"]}
    assert names == {"ForceWarm/box/m<=12", "CcdQuery/unit-tests/vf"}
    assert all(r["samples"] == [9, 9] for r in result["speed"])
    # The CCD's conservativeness counter was checked as a property.
    assert any(r["path"].endswith("missed_contacts") and r["verdict"] == "ok" for r in result["accuracy"])

    # Plant a slowdown in the recorded working-tree runs: every call at least
    # twice as slow, and more where this shared machine's noise spread the
    # repetitions (one preempted repetition of the sub-microsecond CCD query
    # can take twice the others' median): past the slowest base repetition,
    # so the planted slowdown is one the rank test can see in 9 samples.
    runs = Path(result["runs_dir"])
    base, work = {}, {}
    for f in sorted(runs.glob("*.json")):
        side = base if f.name.startswith("base") else work
        for name, reps in bench.samples(json.loads(f.read_text())).items():
            side.setdefault(name, []).extend(reps)
    b50, w50 = gate.metric_samples(base, "p50_ns"), gate.metric_samples(work, "p50_ns")
    factor = {n: 1.1 * max(2.0, max(b50[n]) / min(w50[n])) for n in work}
    slowed = {n: [dict(r, p50_ns=factor[n] * r["p50_ns"]) for r in reps] for n, reps in work.items()}
    verdicts = speed_verdicts(base, slowed)
    assert set(verdicts.values()) == {"slower"}, verdicts
