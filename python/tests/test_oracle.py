"""The oracle's own mechanics on synthetic runs (harness/oracle.toml, python/gauss6/oracle.py):
the passivity observer with no model of the engine (a damper and a sampled spring the device's
damping makes passive pass; a negative damper fails; a NaN handle pose is named, not printed as
nan), the engine's declarations checked, the checks' table, and a witness written by a failed
check and re-checked exactly by `gauss6 certify --witness`."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gauss6 import paths
from gauss6.oracle import CHECK_NAMES, CHECK_TABLE, Oracle, declarations, load_thresholds
from gauss6.trace import DTYPES, Trace, trace_metadata

PEG = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"


@pytest.fixture(scope="module")
def peg():
    return Oracle(PEG)


def synthetic(x: np.ndarray, force, declared=None, dt=1e-3) -> Trace:
    """A run of a handle moving along x (n, 3) far above the peg's block (free space for the geometry),
    the wrench force(k, x) applied, the displayed pose the handle's."""
    n = len(x)
    ticks = np.zeros(n, dtype=DTYPES["ticks"])
    ticks["t"] = np.arange(n) * dt
    ticks["xh_p"] = ticks["xs_p"] = x
    ticks["xh_q"] = ticks["xs_q"] = [1.0, 0, 0, 0]
    for k in range(n):
        ticks["wrench"][k, :3] = force(k, x)
    steps = np.zeros(n, dtype=DTYPES["steps"])
    steps["update_time"] = steps["update_cpu_time"] = 1e-5
    meta = trace_metadata(extra={"declarations": declared or {}})
    return Trace(path=paths.REPO_ROOT / "synthetic.g6trace", version=2, meta=meta, ticks=ticks, steps=steps,
                 contacts=np.zeros(0, dtype=DTYPES["contacts"]), events=np.zeros(0, dtype=DTYPES["events"]))


def _oscillation(n=2000, amp=2e-3, hz=2.0):
    t = np.arange(n) * 1e-3
    x = np.zeros((n, 3))
    x[:, 2] = 0.5 + amp * np.sin(2 * np.pi * hz * t)  # 0.5 m up: far from the peg's block
    return x


def _velocity(k, x, dt=1e-3):
    return (x[k] - x[k - 1]) / dt if k > 0 else np.zeros(3)


def test_the_checks_are_one_table():
    assert CHECK_NAMES == [c.name for c in CHECK_TABLE]
    assert len(set(CHECK_NAMES)) == len(CHECK_NAMES) and CHECK_NAMES[-1] == "cost"
    th = load_thresholds()
    assert all(c.section in th for c in CHECK_TABLE)  # each check's thresholds have a section


@pytest.mark.parametrize("force,passes", [
    (lambda k, x: -5.0 * _velocity(k, x), True),                          # a damper (B = 5 N s/m)
    (lambda k, x: -1500.0 * (x[k] - np.array([0, 0, 0.5])), True),        # a spring, K T / 2 = 0.75 < b = 1
    (lambda k, x: -3000.0 * (x[k] - np.array([0, 0, 0.5])), False),       # K T / 2 = 1.5 > b: active here
    (lambda k, x: +2.0 * _velocity(k, x), False),                         # a negative damper
], ids=["damper", "spring_b_covers_hold", "spring_hold_beyond_b", "negative_damper"])
def test_passivity_observer_without_a_model_of_the_engine(peg, force, passes):
    """Colgate and Schenkel: a sampled spring K is passive on a device of damping b when b > K T / 2.
    The observer credits the device's damping (oracle.toml [energy]) and no more."""
    v = peg.judge(synthetic(_oscillation(), force), checks=["energy"]).verdict("energy")
    assert v.passed == passes, v.note
    if not passes:
        assert v.violations["first"]["tick"] <= v.violations["worst"]["tick"]
        assert v.details["worst_out_power"] > 0 and v.details["worst_episode_phase"] is not None


def test_a_nan_handle_pose_is_named_not_printed_as_nan(peg):
    tr = synthetic(_oscillation(500), lambda k, x: -5.0 * _velocity(k, x))
    tr.ticks["xh_p"][123, 0] = np.nan
    v = peg.judge(tr, checks=["energy"]).verdict("energy")
    assert "nan" not in v.note.lower().replace("non-finite", "")
    assert "non-finite handle pose (first at tick 122" in v.note and v.details["skipped_handle_steps"] == 2
    assert math.isfinite(v.details["observer_min"])


def test_declarations_are_checked():
    tr = synthetic(_oscillation(10), lambda k, x: np.zeros(3),
                   {"friction": {"mu": 0.3}, "latency_ticks": 2, "skin": 1e-5})
    assert declarations(tr) == {"friction": {"mu": 0.3}, "latency_ticks": 2, "skin": 1e-5}
    assert declarations(synthetic(_oscillation(10), lambda k, x: np.zeros(3))) == {}
    for bad, field in (({"friction": {"mu": -1}}, "friction.mu"), ({"latency_ticks": 1.5}, "latency_ticks"),
                       ({"skin": float("nan")}, "skin")):
        with pytest.raises(ValueError, match=field):
            declarations(synthetic(_oscillation(10), lambda k, x: np.zeros(3), bad))


def test_deadlines_use_the_drivers_timing_and_the_machine_allowance(peg):
    tr = synthetic(_oscillation(1000), lambda k, x: np.zeros(3))
    cal = {"steps": 500, "over_fraction": 0.0, "quantile": 2e-5, "max": 1e-3}
    assert peg.judge(tr, checks=["cost"], calibration=cal).verdict("cost").passed
    tr.steps["update_cpu_time"][::10] = 2e-3                 # one step in ten at twice the period
    v = peg.judge(tr, checks=["cost"], calibration=cal).verdict("cost")
    assert not v.passed and v.count == 100
    tr.steps["update_cpu_time"][::10] = 1e-5
    tr.steps["update_time"][500] = 0.3                       # a freeze of 0.3 s (wall)
    assert not peg.judge(tr, checks=["cost"], calibration=cal).verdict("cost").passed
    # The machine's own allowance: gauss6's engine froze as long here, so the engine is not blamed.
    assert peg.judge(tr, checks=["cost"], calibration={**cal, "max": 0.31}).verdict("cost").passed


def test_a_witness_is_rechecked_exactly_by_certify(tmp_path, peg):
    """A displayed pose inside the block: penetration fails; its witness (hex doubles) re-checks
    through `gauss6 certify --witness` (exit 0: the violation stands), and a witness whose pose was
    moved out of the block no longer stands (exit 1)."""
    from gauss6.cli import main
    from gauss6.witness import write_witnesses

    x = _oscillation(50)
    tr = synthetic(x, lambda k, x: np.zeros(3))
    g = peg.exact
    lo, hi = g.boxes[0]
    tr.ticks["xs_p"][20] = lo + (hi - lo) * np.array([0.15, 0.15, 0.9])  # inside the block, beside its hole
    result = peg.judge(tr, checks=["penetration", "tracking"], calibration={})
    assert {"penetration"} <= set(result.failed())
    written = write_witnesses(result, tr, PEG, tmp_path, peg.thresholds, oracle=peg, viewer_page="run.html")
    pen = [w for w in written if w["check"] == "penetration"]
    assert [w["tick"] for w in pen] == [20, 20] and pen[0]["viewer"] == "run.html#t=0.020000"
    doc = json.loads(open(pen[0]["path"]).read())
    assert float.fromhex(doc["xs"]["p"][0]) == tr.ticks["xs_p"][20][0]  # exact doubles
    assert main(["certify", "--witness", pen[0]["path"]]) == 0
    doc["ticks"]["xs_p"][0] = [float(v).hex() for v in x[20]]  # moved back to the handle: free
    moved = tmp_path / "moved.json"
    moved.write_text(json.dumps(doc))
    assert main(["certify", "--witness", str(moved)]) == 1
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["certify", "--witness", str(bad)]) == 2
