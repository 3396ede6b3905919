"""Tests of the rigid CCD step sets (datasets_generated/ccd/) and of `gauss6 crosscheck ccd`.

The full cross-check (every set, a few minutes) is `gauss6 crosscheck ccd`; here a few
steps per set go through the same per-step check, and the check is shown to fail on
fabricated violations. Comparisons with the exact reference are exact (compare_toi,
exact intersection counts): no tolerance.
"""
from __future__ import annotations

import hashlib
import importlib.util
import json

import numpy as np
import pytest

from gauss6 import cli, crosscheck_ccd as cc

SETS = cc.set_names()
MANIFEST = json.loads((cc.SETS_DIR / "MANIFEST.json").read_text())


def _generator():
    from gauss6.generators import ccd

    return ccd


def test_every_set_is_in_the_manifest_with_its_checksum():
    assert set(SETS) == set(_generator().SETS)
    for name in SETS:
        data = (cc.SETS_DIR / f"{name}.json").read_bytes()
        assert MANIFEST["outputs"][f"{name}.json"] == hashlib.sha256(data).hexdigest(), name


def test_regeneration_is_byte_identical(tmp_path):
    # The cheapest set: axis-aligned orientations, few exact rejections (about 1 s).
    gen = _generator()
    gen.write(tmp_path, ["parallel"])
    assert (tmp_path / "parallel.json").read_bytes() == (cc.SETS_DIR / "parallel.json").read_bytes()


@pytest.mark.parametrize("name", SETS)
def test_set_format(name):
    doc = cc.load_set(name)
    assert doc["set"] == name and doc["delta"] > 0 and len(doc["steps"]) >= 2
    ids = [s["id"] for s in doc["steps"]]
    assert len(set(ids)) == len(ids)
    for s in doc["steps"]:
        assert len(s["p0"]) == len(s["p1"]) == len(s["offset"]) == 3 and len(s["q0"]) == len(s["q1"]) == 4
        assert all(np.isfinite(s[k]).all() for k in ("p0", "q0", "p1", "q1", "offset"))
        assert (cc.paths.DATASETS_DIR / s["obstacle"]).is_file() and (cc.paths.DATASETS_DIR / s["god"]).is_file()


def test_motion_kinds_of_the_special_sets():
    assert all(cc.motion_kind(s) == "translation" for s in cc.load_set("zero_rotation")["steps"])
    assert all(cc.motion_kind(s) == "rotation_about_g" for s in cc.load_set("rotation_about_g")["steps"])
    # Large rotations: 10 to 170 degrees (qr's angle from its scalar part).
    for s in cc.load_set("large_rotation")["steps"]:
        q0, q1 = (np.asarray(s[k]) / np.linalg.norm(s[k]) for k in ("q0", "q1"))
        angle = 2 * np.degrees(np.arccos(min(abs(float(cc._qmul(q1, q0 * [1, -1, -1, -1])[0])), 1.0)))
        assert 10 - 1e-9 <= angle <= 170 + 1e-9


def test_start_poses_are_exactly_free():
    meshes = cc.Meshes()
    for name in ("random", "tunnelling", "peg_script"):
        for s in cc.load_set(name)["steps"][:5]:
            _, pair = meshes.get(s)
            assert pair.count_intersecting_pairs(np.asarray(s["p0"]), np.asarray(s["q0"])) == 0, s["id"]


def test_tunnelling_paths_meet_the_obstacle():
    # Both ends free, yet the exact in-between motion meets the obstacle: the case a
    # discrete check misses.
    meshes = cc.Meshes()
    for s in cc.load_set("tunnelling")["steps"][:1]:
        _, pair = meshes.get(s)
        p0, q0, p1, q1 = cc.poses(s)
        assert pair.count_intersecting_pairs(p1, q1) == 0
        assert pair.exact_first_contact(p0, q0, p1, q1).hit, s["id"]


@pytest.mark.parametrize("name", [n for n in SETS if n != "bunny_script"])
def test_first_steps_pass_the_crosscheck(name):
    doc = cc.load_set(name)
    meshes = cc.Meshes()
    res = cc.SetResult(name)
    count = 1 if name in ("large_rotation", "tunnelling") else 4  # their exact steps take 13-60 s
    for s in doc["steps"][:count]:
        _, pair = meshes.get(s)
        cc.check_step(pair, s, doc["delta"], res)
    assert res.failures == []
    out = res.as_json()
    assert out["steps"] == count and out["false_negatives"] == out["late_hits"] == out["intersecting_stop_poses"] == 0
    assert out["max_gap_u"] >= out["p99_gap_u"] >= 0
    # Which pair stopped each step: compared on every step where both hit, none wrong.
    assert out["pair_steps"] == out["pair_matches"] + out["pair_within_tolerance"] + out["pair_within_delta"]
    assert out["pair_violations"] == 0


class _Tampered:
    """A MeshPair whose optimized answer is replaced, to show that the check fails."""

    def __init__(self, pair, **override):
        self.pair, self.override = pair, override

    def step(self, *a, **k):
        return {**self.pair.step(*a, **k), **self.override}

    def __getattr__(self, name):
        return getattr(self.pair, name)


def _first_hit_step():
    meshes = cc.Meshes()
    doc = cc.load_set("zero_rotation")
    for s in doc["steps"]:
        _, pair = meshes.get(s)
        if pair.exact_first_contact(*cc.poses(s)).hit:
            return pair, s, doc["delta"]
    raise AssertionError("zero_rotation: no exact contact")


def test_a_missed_contact_and_its_pose_are_violations():
    pair, s, delta = _first_hit_step()
    p1, q1 = cc.poses(s)[2:]
    res = cc.SetResult("tampered")
    # No hit reported: a false negative, and the god-object would move to X1.
    cc.check_step(_Tampered(pair, hit=False, u_hit=1.0, stop_p=p1, stop_q=q1), s, delta, res)
    assert res.false_negatives == 1
    assert res.intersecting_stop_poses == int(pair.count_intersecting_pairs(p1, q1) > 0)


def test_a_late_hit_is_a_violation():
    pair, s, delta = _first_hit_step()
    ex = pair.exact_first_contact(*cc.poses(s))
    late_u = float(np.nextafter(ex.upper, 2.0))  # the first double past u*
    res = cc.SetResult("tampered")
    cc.check_step(_Tampered(pair, hit=True, u_hit=late_u), s, delta, res)
    assert res.late_hits == 1 and res.false_negatives == 0
    # And u_hit = lower (<= u*, exactly) is not late.
    res = cc.SetResult("tampered")
    cc.check_step(_Tampered(pair, hit=True, u_hit=ex.lower), s, delta, res)
    assert res.late_hits == 0


def test_a_stop_on_a_wrong_pair_is_a_violation():
    pair, s, delta = _first_hit_step()
    poses = cc.poses(s)
    opt = pair.step(*poses, delta)
    ex = pair.exact_first_contact(*poses)
    assert opt["hit"] and opt["pair_ids"] is not None and ex.pairs
    # The reference's own touching pair is a match, and solved alone it touches at u*.
    assert cc.classify_stop_pair(pair, s, {**opt, "pair_ids": ex.pairs[0]}, ex) == ("match", "")
    own = pair.pair_first_contact(ex.pairs[0], *poses)
    assert own.hit and own.lower == ex.lower and own.upper == ex.upper
    # A pair that never touches (a god-object vertex against an obstacle face), fed as the
    # step's stop pair: flagged, and check_step counts it as a violation.
    wrong = None
    for v in range(8):
        for f in range(8):
            ids = ("god_vertex/obstacle_face", ("vertex", v, -1), ("face", f, -1))
            if not pair.pair_first_contact(ids, *poses).hit:
                wrong = ids
                break
        if wrong:
            break
    assert wrong is not None
    verdict, why = cc.classify_stop_pair(pair, s, {**opt, "pair_ids": wrong}, ex)
    assert verdict == "violation" and "never touches" in why
    res = cc.SetResult("tampered")
    cc.check_step(_Tampered(pair, pair_ids=wrong), s, delta, res)
    assert res.pair_violations == 1 and res.pair_steps == 1 and res.late_hits == 0
    assert res.as_json()["pair_violations"] == 1
    # A stop after the pair's own contact (impossible for a sound step) is flagged, when the
    # pair is solved alone (the reference listing no touching pair).
    verdict, why = cc.classify_stop_pair(pair, s, {**opt, "pair_ids": ex.pairs[0], "u_hit": 1.0}, _NoPairs(ex))
    assert verdict == "violation" and "after its own contact" in why
    # The same pair at the exact u* bracket's lower end, not listed: within tolerance.
    assert cc.classify_stop_pair(pair, s, {**opt, "pair_ids": ex.pairs[0], "u_hit": ex.lower}, _NoPairs(ex))[0] \
        == "within"
    # Ids that do not fit the kind are refused.
    with pytest.raises(ValueError):
        pair.pair_first_contact(("edge/edge", ("vertex", 0, -1), ("face", 0, -1)), *poses)


class _NoPairs:
    """An exact contact that lists no touching pair (so the stop pair is solved alone)."""

    def __init__(self, ex):
        self.ex, self.pairs = ex, []

    def __getattr__(self, name):
        return getattr(self.ex, name)


def test_cli_json_schema(capsys):
    rc = cli.main(["crosscheck", "ccd", "--set", "parallel", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and list(out) == ["ok", "sets"] and out["ok"] is True
    assert list(out["sets"][0]) == ["name", "steps", "false_negatives", "late_hits", "max_gap_u", "p99_gap_u",
                                    "intersecting_stop_poses", "max_stop_separation", "optimized_us_per_step",
                                    "reference_s_per_step", "pair_steps", "pair_matches", "pair_within_tolerance",
                                    "pair_violations", "pair_within_delta"]
    # Stop poses keep about delta: the exact separation is at most the window and above 0.
    assert 0 < out["sets"][0]["max_stop_separation"] <= cc.STOP_SEPARATION_WINDOW * cc.load_set("parallel")["delta"]


def test_unknown_set_is_an_error(capsys):
    assert cli.main(["crosscheck", "ccd", "--set", "no_such_set", "--json"]) == 2
    assert "no_such_set" in capsys.readouterr().err


@pytest.mark.skipif(importlib.util.find_spec("fcl") is None, reason="python-fcl not installed")
def test_fcl_peers_run_on_the_translation_steps(capsys):
    rc = cli.main(["crosscheck", "ccd", "--set", "zero_rotation", "--peers"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    rows = {(p["motion"], p["solver"]): p for p in out["fcl"]}
    row = rows[("translation", "CCDC_NAIVE")]
    assert row["steps"] == len(cc.load_set("zero_rotation")["steps"]) and row["exact_hits"] > 0
    assert row["misses"] + row["late"] + row["false_positives"] <= row["steps"]
