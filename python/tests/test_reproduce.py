"""Tests of `gauss6 reproduce` (gauss6.reproduce): short runs of the paper's scenarios through the
runtime, the trace round trip, the exact pose check, the summary's keys and the let-go check.

The full scenarios take minutes (`make reproduce`); these runs are the first 1.2 s of the peg
(phase (a): the tilted peg's tip pressed on the box's top) and the first 0.4 s of the bunnies.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from gauss6 import cli, reproduce
from gauss6.machine import machine
from gauss6.trace import COLUMNS, DTYPES, Trace, read_trace

runtime = pytest.importorskip("gauss6._gauss6").runtime


@pytest.fixture(scope="module")
def peg_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("peg")
    summary, extra = reproduce.run_scenario("peg", out, duration=1.2, show_progress=False, figure=True)
    return out, summary, extra


def test_summary_keys_are_exactly_the_issues(peg_run):
    _, summary, _ = peg_run
    assert sorted(summary) == sorted([
        "force_time_us", "update_time_ms", "update_cpu_time_ms", "constraint_update_hz", "max_contacts",
        "penetrating_poses", "max_abs_fy_outside_cd", "max_fy_in_c", "max_rel_force_dot_ac", "energy_injected", "let_go_stable",
        "paper"])
    for key in ("force_time_us", "update_time_ms", "update_cpu_time_ms"):
        assert sorted(summary[key]) == ["max", "median", "p99"]
        assert 0 < summary[key]["median"] <= summary[key]["p99"] <= summary[key]["max"]
    assert sorted(summary["constraint_update_hz"]) == ["mean", "min"]
    json.dumps(summary)  # serialisable as is


def test_lockstep_repeats_and_each_steps_least_time(peg_run, tmp_path):
    """The lockstep run is repeated LOCKSTEP_RUNS - 1 times, tick for tick, and report.md's least times are
    each step's least over the runs: at most the single run's, step by step. A repeat that differs fails."""
    out, summary, extra = peg_run
    least = extra["update_least"]
    assert least["runs"] == reproduce.LOCKSTEP_RUNS >= 3
    for key in ("update_cpu_time_ms", "update_time_ms"):
        for stat in ("median", "p99", "max"):
            assert 0 < least[key][stat] <= summary[key][stat]
    assert not list(out.glob(".*repeat*"))  # the repeats' traces are removed
    # A run that is not repeatable (a trace doctored after the fact) is refused.
    tr = read_trace(out / "peg.g6trace")
    tr.ticks["wrench"][600, 2] += 1e-9
    with pytest.raises(RuntimeError, match="differs from the first .wrench."):
        reproduce.least_update_times("peg", reproduce.SCENES["peg"], tr, tmp_path, 1.2, 1)


def test_peg_phase_a_contacts_and_forces(peg_run):
    out, summary, extra = peg_run
    tr = read_trace(out / "peg.g6trace")
    F = tr.ticks["wrench"]
    pressed = (tr.ticks["t"] >= 0.8) & (tr.ticks["t"] <= 1.2)
    # The hand is 1 cm below the touching height: contacts on every pressed tick, force up (+Z)
    # of about kh ks m * 1 cm = 4000 * 0.5 * 0.246 * 0.01 = 4.9 N less the handle's give (grip 500 N/m):
    # between 1.5 and 4 N; the top's normal is +Z, so Fx, Fy are rounding (1e-9 of Fz).
    assert np.all(tr.ticks["num_contacts"][pressed] > 0)
    assert np.all((F[pressed, 2] > 1.5) & (F[pressed, 2] < 4.0))
    assert np.all(np.abs(F[pressed, :2]) <= 1e-9 * F[pressed, 2:3])
    assert summary["max_contacts"] >= 1
    # Outside (c) and (d) the paper's force Y is zero. Ours is zero up to the edge/edge contacts of the
    # tilted rim with the top's interior diagonal edge (normal e1 x e2, tilted): below 1 % of Fz.
    assert summary["max_abs_fy_outside_cd"] <= 1e-2 * np.abs(F[:, 2]).max()
    assert summary["penetrating_poses"] == 0
    assert extra["distinct_poses"] > 500


def test_peg_properties(peg_run):
    _, summary, extra = peg_run
    # Orthogonality: the projection is solved to about 1e-12 relative; 1e-8 leaves rounding room.
    assert extra["orthogonality_checks"] > 100
    assert summary["max_rel_force_dot_ac"] <= 1e-8
    # The constraints only remove energy: au . Fc = -kh |ac - au|_M^2 <= 0 at every step.
    assert extra["constraint_energy_removed_j"] > 0
    assert summary["energy_injected"] <= 1e-12 * extra["constraint_energy_removed_j"]
    assert extra["rows_dropped"] == [0, 0, 0, 0]


def test_trace_round_trip_and_csv_export(peg_run, tmp_path):
    out, _, extra = peg_run
    tr = read_trace(out / "peg.g6trace")
    assert tr.complete and not tr.warnings
    assert len(tr.ticks) == extra["ticks"] == 1201
    assert np.array_equal(tr.ticks["t"], np.arange(1201) / 1000.0)  # the virtual clock, exactly
    assert len(tr.steps) == extra["sim_steps"]
    assert len(tr.contacts) == extra["contact_rows"] > 0
    assert [p["name"] for p in tr.meta["phases"]] == ["a", "b", "c", "d", "e"]
    assert list(tr.events["code"]) == [1.0]  # phase (a) only, within 1.2 s
    # The CSV export reads back to the same doubles.
    assert cli.main(["trace", "export", str(out / "peg.g6trace"), "--csv", str(tmp_path)]) == 0
    ticks = np.loadtxt(tmp_path / "ticks.csv", delimiter=",", skiprows=1)
    assert ticks.shape == (1201, sum(w for _, w in COLUMNS["ticks"]))
    assert np.array_equal(ticks[:, 0], tr.ticks["t"])
    assert np.array_equal(ticks[:, 15:21], tr.ticks["wrench"])
    # And the figure was drawn.
    assert (out / "figure_peg.png").stat().st_size > 10_000
    assert (out / "figure_peg.svg").stat().st_size > 10_000


def test_lockstep_runs_repeat(tmp_path):
    """Two lockstep runs give the same poses and forces, bit for bit."""
    scene = str(reproduce.SCENES["peg"])
    runtime.run_scenario(scene, str(tmp_path / "a.g6trace"), duration=0.7)
    runtime.run_scenario(scene, str(tmp_path / "b.g6trace"), duration=0.7)
    a, b = read_trace(tmp_path / "a.g6trace"), read_trace(tmp_path / "b.g6trace")
    for col in ("xh_p", "xh_q", "xs_p", "xs_q", "wrench", "num_contacts"):
        assert np.array_equal(a.ticks[col], b.ticks[col]), col


def test_exact_pose_check_finds_intersections_and_agrees_with_the_reference():
    """The scene-level check sums the reference's exact count over the obstacles: it finds the
    intersecting poses and gives, pose by pose, the count of the reference's MeshPair binding."""
    up = [0.7071067811865476, 0.7071067811865476, 0.0, 0.0]
    poses = np.array([
        [0, 0, 0.075, *up],          # upright peg 5 mm into the top: intersects
        [0, 0, 0.0801, *up],         # 0.1 mm above the top: free
        [0, 0, 0.08 + 2e-6, *up],    # 2 um above the top: free
        [0, -0.05, 0, 1, 0, 0, 0],   # on the hole's axis, half inside: free (0.17 mm clearance)
        [0, -0.05, 5e-4, 1, 0, 0, 0],  # 0.5 mm off the axis: cuts the hole's wall
    ])
    scene = str(reproduce.SCENES["peg"])
    result = runtime.count_intersecting_pairs(scene, poses)
    assert sorted(result) == ["counts", "seconds"]
    assert result["seconds"] >= 0
    assert [c > 0 for c in result["counts"]] == [True, False, False, False, True]
    ccd = pytest.importorskip("gauss6._gauss6").ccd
    geometry = runtime.scene_geometry(scene)
    pairs = [ccd.MeshPair(V, F, geometry["god_V"], geometry["god_F"]) for _, V, F in geometry["obstacles"]]
    for pose, count in zip(poses, result["counts"]):
        assert count == sum(pair.count_intersecting_pairs(pose[:3], pose[3:]) for pair in pairs)


def test_exact_pose_check_refuses_a_zero_quaternion():
    poses = np.array([[0, 0, 0.1, 0, 0, 0, 0]], dtype=float)
    with pytest.raises(ValueError, match="zero quaternion"):
        runtime.count_intersecting_pairs(str(reproduce.SCENES["peg"]), poses)


def _fake_trace(xs_p, F, flags, t):
    ticks = np.zeros(len(t), dtype=DTYPES["ticks"])
    ticks["t"], ticks["xs_p"], ticks["wrench"][:, :3], ticks["flags"] = t, xs_p, F, flags
    empty = {name: np.zeros(0, dtype=DTYPES[name]) for name in ("steps", "contacts", "events")}
    return Trace(path=None, version=1, meta={}, ticks=ticks, complete=True, **empty)


def test_let_go_stable_accepts_a_settled_peg_and_rejects_one_that_leaves():
    t = np.arange(0, 2.0, 0.001)
    still = np.zeros((len(t), 3))
    ok, details = reproduce.let_go_stable(_fake_trace(still, np.zeros((len(t), 3)), np.zeros(len(t)), t), 0.5)
    assert ok, details
    # Drifting out of the hole along its axis at 5 cm/s.
    drifting = np.zeros((len(t), 3))
    drifting[:, 1] = 0.05 * np.maximum(0, t - 0.5)
    ok, details = reproduce.let_go_stable(_fake_trace(drifting, np.zeros((len(t), 3)), np.zeros(len(t)), t), 0.5)
    assert not ok and details["drift_after_settle_m"] > 1e-3
    # Still pushed at the end (0.2 N), or still gripped.
    force = np.zeros((len(t), 3))
    force[:, 2] = 0.2
    assert not reproduce.let_go_stable(_fake_trace(still, force, np.zeros(len(t)), t), 0.5)[0]
    assert not reproduce.let_go_stable(_fake_trace(still, np.zeros((len(t), 3)), np.ones(len(t)), t), 0.5)[0]


def test_report_states_the_machine_and_the_paper(peg_run, tmp_path):
    _, summary, extra = peg_run
    path = reproduce.write_report(tmp_path, {"peg": summary}, {"peg": extra}, wall=1.0)
    text = path.read_text()
    assert "Machine:" in text and f"{machine()['cpus']} CPUs" in text
    assert "< 25.0" in text  # the paper's force time bound, beside ours
    assert "figure_peg.png" in text
