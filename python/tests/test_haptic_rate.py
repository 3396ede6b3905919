"""Tests of `gauss6 rate` (python/gauss6/haptic_rate.py) on a half-second run: the report's
accounting and that what the loops asked of the OS is reported whether granted or refused.
The minute-long 10 kHz run itself is a command (docs/benchmarks.md), not a test."""
from __future__ import annotations

import re

import pytest

from gauss6 import haptic_rate


def test_short_threaded_run_reports_jitter_misses_and_policy(tmp_path):
    r = haptic_rate.run("peg", 10000.0, 0.5, priority=0, pin=False, out=tmp_path)
    h, s = r["haptic"], r["sim"]
    assert h["ticks"] > 1000 and s["steps"] > 10  # a loaded machine may run fewer than 5,000 ticks
    assert h["granted"] == "default policy (not asked); not pinned"
    for d in (h["jitter_us"], h["period_us"], s["period_us"], s["update_cpu_us"]):
        assert 0 <= d["p50"] <= d["p99"] <= d["max"]
    assert h["late_starts"] >= 0 and s["misses_over_1ms"] >= 0
    assert "| haptic |" in (tmp_path / "rate.md").read_text()


def test_realtime_request_is_reported_granted_or_refused(tmp_path):
    r = haptic_rate.run("peg", 10000.0, 0.3, priority=10, pin=True, out=tmp_path)
    assert re.match(r"SCHED_FIFO (10|refused \(errno \d+\))", r["haptic"]["granted"])
    assert re.match(r"SCHED_FIFO (8|refused \(errno \d+\))", r["sim"]["granted"])


def test_busy_wait_is_asked_and_reported(tmp_path):
    # RuntimeSettings::spin_wait (--spin-us): the run goes on as before, the report says it.
    r = haptic_rate.run("peg", 10000.0, 0.3, priority=0, pin=True, out=tmp_path, spin_us=100.0)
    assert r["asked"]["spin_us"] == 100.0
    assert r["haptic"]["ticks"] > 500
    assert "busy wait 100 us a period" in (tmp_path / "rate.md").read_text()


def test_busy_wait_out_of_range_is_refused(tmp_path):
    with pytest.raises(ValueError, match="spin_wait"):
        haptic_rate.run("peg", 10000.0, 0.1, priority=0, pin=False, out=tmp_path, spin_us=2e6)
