"""Campaigns on Dask distributed (gauss6.campaign) and the seeded cross-check campaigns.

- the same summary serial, on an embedded LocalCluster of 2 worker processes, and on
  an existing cluster reached by its address (loopback), whatever the chunk order;
- a worker process killed (SIGKILL) mid-campaign: its chunks run again elsewhere and
  the summary is unchanged;
- a campaign process killed mid-run resumes from the chunks it wrote;
- a folder holding another campaign is refused;
- fixed-seed slices of `crosscheck qp --seeded` and `crosscheck ccd --seeded` pass, and
  each fails on a planted error (the checks can fail).
Timings (seconds, us per step) are not part of the verdict and are left out of the
comparisons.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from gauss6 import campaign, crosscheck_ccd, crosscheck_qp, qp_seeded

pytest.importorskip("distributed")

# Two chunks of 36 instances (m = 1..12, three push labels) of each of two families.
QP_FAMILIES = ["box", "peg"]
QP_CHUNK = 36


def qp_campaign(count=4 * QP_CHUNK, seed=7):
    return crosscheck_qp.seeded_campaign(count, seed, QP_FAMILIES, chunk_size=QP_CHUNK)


def verdict(summary):
    """The summary without the run's timings."""
    result, failures, _ = summary
    result = json.loads(json.dumps(result))
    for s in result.get("sets", []):
        for k in crosscheck_ccd.TIMING_FIELDS:
            s.pop(k)
    return result, failures


@pytest.fixture(scope="module")
def serial_qp():
    return campaign.run_campaign(qp_campaign(), workers=0, show_progress=False)


def test_qp_campaign_same_serial_and_on_two_worker_processes(serial_qp, tmp_path):
    result, failures, _ = serial_qp.summary
    assert result["ok"], failures
    assert result["instances"] == 4 * QP_CHUNK
    assert [f["name"] for f in result["families"]] == QP_FAMILIES
    run = campaign.run_campaign(qp_campaign(), out=tmp_path, workers=2, show_progress=False)
    assert run.workers == 2 and run.chunks_run == 4
    assert verdict(run.summary) == verdict(serial_qp.summary)
    assert len(list((tmp_path / "chunks").glob("*.json"))) == 4
    # A rerun into the folder computes nothing and gives the same summary.
    again = campaign.run_campaign(qp_campaign(), out=tmp_path, workers=0, show_progress=False)
    assert again.chunks_run == 0 and again.chunks_resumed == 4
    assert verdict(again.summary) == verdict(serial_qp.summary)


def test_worker_killed_mid_campaign_on_an_existing_cluster(serial_qp, tmp_path):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        pids = list(client.run(os.getpid).values())
        assert len(pids) == 2 and os.getpid() not in pids
        killed = []

        def kill_one_worker_after_first_chunk():
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline:
                if list((tmp_path / "chunks").glob("*.json")):
                    os.kill(pids[0], signal.SIGKILL)
                    killed.append(pids[0])
                    return
                time.sleep(0.02)

        killer = threading.Thread(target=kill_one_worker_after_first_chunk)
        killer.start()
        run = campaign.run_campaign(qp_campaign(), out=tmp_path, scheduler=cluster.scheduler_address,
                                    show_progress=False)
        killer.join()
    assert killed, "no chunk finished: the worker was never killed"
    assert run.chunks_run == 4
    assert verdict(run.summary) == verdict(serial_qp.summary)


def test_killed_campaign_resumes_where_it_stopped(serial_qp, tmp_path):
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "gauss6.cli", "crosscheck", "qp", "--seeded", str(4 * QP_CHUNK),
           "--chunk-size", str(QP_CHUNK), "--seed", "7", "--workers", "0", "--out", str(out), "--json"]
    cmd += ["--family", "box"]  # the resumed run is compared with a fresh run of the same command
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list((out / "chunks").glob("*.json"))) < 1:
        time.sleep(0.02)
    proc.kill()
    proc.wait()
    done = len(list((out / "chunks").glob("*.json")))
    assert 1 <= done < 4, f"{done} chunks written before the kill"
    resumed = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    assert resumed["chunks_resumed"] == done and resumed["chunks_run"] == 4 - done
    fresh = json.loads(subprocess.run(cmd[:cmd.index("--out")] + cmd[cmd.index("--out") + 2:],
                                      capture_output=True, text=True, check=True).stdout)
    for k in ("chunks_run", "chunks_resumed", "seconds", "workers"):
        resumed.pop(k), fresh.pop(k)
    assert resumed == fresh and resumed["ok"]


def test_a_folder_of_another_campaign_is_refused(tmp_path):
    campaign.run_campaign(crosscheck_qp.seeded_campaign(1, 3, ["box"], chunk_size=12), out=tmp_path, workers=0,
                          show_progress=False)
    with pytest.raises(campaign.CampaignError, match="holds another campaign"):
        campaign.run_campaign(crosscheck_qp.seeded_campaign(1, 4, ["box"], chunk_size=12), out=tmp_path,
                              workers=0, show_progress=False)


def test_seeded_chunks_depend_on_their_description_alone():
    a = qp_seeded.chunk_instances("m50", 5, 3, 8)
    b = qp_seeded.chunk_instances("m50", 5, 3, 8)
    c = qp_seeded.chunk_instances("m50", 5, 4, 8)
    assert len(a) == 8 and all(i.num_rows == 50 for i in a)
    assert all(np.array_equal(x.J, y.J) and np.array_equal(x.au, y.au) for x, y in zip(a, b))
    assert not np.array_equal(a[0].J, c[0].J)


def test_qp_campaign_fails_on_a_planted_error(nudged_projection):
    run = campaign.run_campaign(crosscheck_qp.seeded_campaign(1, 1, ["box"], chunk_size=36), workers=0,
                                show_progress=False)
    result, failures, _ = run.summary
    assert not result["ok"] and any("max_rel_err_ac" in f for f in failures)


# The fixed-seed CCD slice of make test: 100 steps (the first chunks of a round: random,
# sliding, near_parallel, peg_scenario), serial and on 2 worker processes.
CCD_SLICE = 100


def test_ccd_campaign_slice_same_serial_and_on_two_workers(tmp_path):
    c = crosscheck_ccd.seeded_campaign(CCD_SLICE, seed=1)
    assert [ch["family"] for ch in c.chunks] == ["random", "sliding", "near_parallel", "peg_scenario"]
    serial = campaign.run_campaign(c, workers=0, show_progress=False)
    result, failures, _ = serial.summary
    assert result["ok"], failures[:10]
    assert result["steps"] == CCD_SLICE
    two = campaign.run_campaign(crosscheck_ccd.seeded_campaign(CCD_SLICE, seed=1), out=tmp_path, workers=2,
                                show_progress=False)
    assert verdict(two.summary) == verdict(serial.summary)


def test_ccd_plan_covers_every_family_in_proportion():
    from gauss6 import ccd_seeded

    chunks = ccd_seeded.plan(2 * ccd_seeded.STEPS_PER_ROUND + 10, seed=1)
    per = {}
    for ch in chunks:
        per[ch["family"]] = per.get(ch["family"], 0) + ch["count"]
    assert sum(per.values()) == 2 * ccd_seeded.STEPS_PER_ROUND + 10
    for f, n, _ in ccd_seeded.ROUND:
        assert per[f] >= 2 * n
    # Each family's chunks are numbered 0, 1, ... (their streams never overlap).
    for f in per:
        assert [ch["index"] for ch in chunks if ch["family"] == f] == list(range(len([c for c in chunks
                                                                                      if c["family"] == f])))


def test_ccd_plan_without_the_hand_scripts_names_them(monkeypatch, tmp_path):
    """Without a checkout's datasets (an installed package's generated folder has no hand
    scripts), a campaign of the scenario families is refused up front, the script named;
    the other families plan as before."""
    from gauss6 import ccd_seeded, paths

    monkeypatch.setattr(paths, "DATASETS_DIR", tmp_path)
    with pytest.raises(ValueError, match=r"scripts/bunny\.json: missing.*--family"):
        ccd_seeded.plan(ccd_seeded.STEPS_PER_ROUND, seed=1)
    assert ccd_seeded.plan(50, seed=1, families=["random"])


def test_seeded_ccd_steps_start_free_and_near_parallel_is_tilted():
    from gauss6 import ccd_seeded

    for fam in ("sliding", "near_parallel", "peg_scenario"):
        steps, delta = ccd_seeded.chunk_steps(fam, 3, 0, 6)
        assert len(steps) == 6 and delta == 1e-6
        pair = ccd_seeded.mesh_pair(*ccd_seeded.builder(fam)[1])
        for s in steps:
            assert pair.free(np.asarray(s["p0"]), np.asarray(s["q0"])), s["id"]
        if fam == "near_parallel":
            assert all(1e-12 <= s["tags"]["tilt_rad"] <= 1e-4 for s in steps)
    # The same chunk cut shorter is a prefix of the longer one.
    a, _ = ccd_seeded.chunk_steps("sliding", 3, 0, 3)
    b, _ = ccd_seeded.chunk_steps("sliding", 3, 0, 6)
    assert a == b[:3]


def test_ccd_campaign_fails_on_a_planted_miss(monkeypatch):
    """A step that reports no hit where the exact reference has one is a false negative."""
    from gauss6 import _gauss6

    real_step = _gauss6.ccd.MeshPair.step

    class Blind:
        def __init__(self, pair):
            self._pair = pair

        def step(self, *a, **k):
            r = dict(real_step(self._pair, *a, **k))
            r["hit"] = False
            return r

        def __getattr__(self, name):
            return getattr(self._pair, name)

    monkeypatch.setattr(crosscheck_ccd._MESHES, "get", lambda step, g=crosscheck_ccd.Meshes.get,
                        m=crosscheck_ccd._MESHES: (lambda kp: (kp[0], Blind(kp[1])))(g(m, step)))
    run = campaign.run_campaign(crosscheck_ccd.seeded_campaign(25, seed=1), workers=0, show_progress=False)
    result, failures, _ = run.summary
    assert not result["ok"] and any("false negative" in f for f in failures)


def seeded_stop(family: str, chunk: int, count: int, i: int):
    """Step i of a seeded chunk (seed 1) run both ways: (step, delta, MeshPair, its
    features, the optimized step's dict, the exact contact)."""
    from gauss6 import ccd_seeded

    cc = crosscheck_ccd
    steps, delta = ccd_seeded.chunk_steps(family, 1, chunk, count)
    st = steps[i]
    key, pair = cc._MESHES.get(st)
    p0, q0, p1, q1 = cc.poses(st)
    opt = pair.step(p0, q0, p1, q1, delta, time_tolerance=cc.TIME_TOLERANCE, repeats=1)
    return st, delta, pair, cc._MESHES.features(key), opt, pair.exact_first_contact(p0, q0, p1, q1)


def test_a_stop_pair_sliding_at_delta_is_within_delta_and_a_far_one_a_violation():
    """Seeded sliding step 5 of chunk 0 (seed 1): the step stops on a vertex/face pair
    that comes within delta and never touches, while another pair touches later."""
    cc = crosscheck_ccd
    st, delta, pair, meshes, opt, ex = seeded_stop("sliding", 0, 6, 5)
    p0, q0, p1, q1 = cc.poses(st)
    assert opt["hit"] and ex.hit and opt["pair_ids"] not in ex.pairs
    assert not pair.pair_first_contact(opt["pair_ids"], p0, q0, p1, q1).hit
    assert cc.classify_stop_pair(pair, st, opt, ex)[0] == "violation"  # without the meshes: strict
    assert cc.classify_stop_pair(pair, st, opt, ex, meshes, delta) == ("within_delta", "")
    stop_p, stop_q = np.asarray(opt["stop_p"]), np.asarray(opt["stop_q"])
    d = cc.pair_distance(opt["pair_ids"], meshes, stop_p, stop_q)
    sep = pair.separation(stop_p, stop_q, 1e-4)
    # The pair's distance in doubles is the stop pose's exact separation (it is the closest
    # pair) to rounding, and about delta.
    assert abs(d - sep["upper"]) <= 1e-9 * delta and delta <= d <= cc.STOP_BAND * delta
    # A pair far from contact, fed as the stop pair: still a violation.
    far = next(ids for v in range(8) for f in range(8)
               for ids in [("god_vertex/obstacle_face", ("vertex", v, -1), ("face", f, -1))]
               if not pair.pair_first_contact(ids, p0, q0, p1, q1).hit
               and cc.pair_distance(ids, meshes, stop_p, stop_q) > 10 * delta)
    assert cc.classify_stop_pair(pair, st, {**opt, "pair_ids": far}, ex, meshes, delta)[0] == "violation"


def test_a_failing_chunk_is_named():
    with pytest.raises(campaign.CampaignError, match=r"chunk 0 .*no QP family 'nope'"):
        campaign.run_campaign(campaign.Campaign("bad", [{"family": "nope", "seed": 1, "index": 0, "size": 1,
                                                         "osqp": False}], crosscheck_qp.run_seeded_chunk,
                                                lambda r: r), workers=0, show_progress=False)


def test_a_step_starting_within_delta_of_a_pair_is_within_delta_though_it_touches_later():
    """Seeded zero_rotation step 12 of chunk 37 (seed 1), one of the 37 stops that the
    100,000-step campaign once called wrong pairs: the step starts 0.88 delta from a
    vertex/face pair, so it stays at u = 0 on that pair, which touches only at 3.5 u*
    (after another pair's contact, outside the pair window). It is within delta at the
    stop pose, so the step kept its contract. Fed with a u_hit past the pair's own
    contact, the same pair is still a violation."""
    cc = crosscheck_ccd
    st, delta, pair, meshes, opt, ex = seeded_stop("zero_rotation", 37, 25, 12)
    assert st["id"] == "zero_rotation-s1-c37-012"
    p0, q0, p1, q1 = cc.poses(st)
    assert opt["hit"] and ex.hit and opt["pair_ids"] not in ex.pairs
    own = pair.pair_first_contact(opt["pair_ids"], p0, q0, p1, q1)
    assert own.hit and own.lower > 2 * ex.upper
    assert cc.classify_stop_pair(pair, st, opt, ex)[0] == "violation"  # without the meshes: strict
    assert cc.classify_stop_pair(pair, st, opt, ex, meshes, delta) == ("within_delta", "")
    d = cc.pair_distance(opt["pair_ids"], meshes, np.asarray(opt["stop_p"]), np.asarray(opt["stop_q"]))
    assert opt["u_hit"] == 0.0 and 0.0 < d <= cc.STOP_BAND * delta
    late = {**opt, "u_hit": min(1.0, own.upper * 1.5)}
    assert cc.classify_stop_pair(pair, st, late, ex, meshes, delta)[0] == "violation"
