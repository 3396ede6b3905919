"""`gauss6 certify` (certify.py) and the reference's filtered first contact (reference_speed.py): a short peg run
is certified, its chunks merge to the whole, fabricated violations (a pose inside the box, a jump through it, a
force pose far from everything) are each reported with their tick and a non-zero exit; and the filtered and
exact-only paths of mesh_first_contact give the same exact answers on a fixed slice of every CCD step set."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from gauss6 import paths
from gauss6.certify import certify, certify_chunk, certify_range, chunks, merge
from gauss6.cli import main
from gauss6.exact_checks import ExactScene
from gauss6.trace import read_trace, write_trace

PEG = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"
RUN_SECONDS = 1.5   # of the peg script: the approach and the first contacts on the box's top


@pytest.fixture(scope="module")
def peg_run(tmp_path_factory):
    from gauss6._gauss6 import runtime

    out = tmp_path_factory.mktemp("certify") / "peg.g6trace"
    runtime.run_scenario(str(PEG), str(out), threaded=False, duration=RUN_SECONDS, lockstep_sim_period=1,
                         extra_json="{}", progress=None)
    return out


@pytest.fixture(scope="module")
def peg_scene():
    return ExactScene(PEG)


def _counts(r):
    return (r.poses, r.motions, r.separations, dict(r.paths), dict(r.pairs), dict(r.num_violations))


def test_a_gauss6_run_is_certified_and_its_chunks_merge_to_the_whole(peg_run, peg_scene):
    ticks = read_trace(peg_run).ticks
    whole = certify_range(peg_scene, ticks, 0, len(ticks))
    assert whole.passed, whole.violations
    assert whole.poses > 100 and whole.motions == whole.poses - 1
    assert whole.separations > 0  # the run reached the box: contacts, separations checked
    assert whole.paths["filter"] + whole.paths["exact"] > 0  # motions near the box went to the reference
    assert whole.max_separation <= peg_scene.bound
    parts = [certify_range(peg_scene, ticks, a, b) for a, b in chunks(len(ticks), 97)]
    assert _counts(merge(reversed(parts))) == _counts(whole)  # any chunking, any order
    assert merge(parts).max_separation == whole.max_separation
    # The campaign task on the files: the same as on the loaded data.
    assert _counts(merge(certify_chunk(PEG, peg_run, a, b) for a, b in chunks(len(ticks), 400))) == _counts(whole)


def _with_poses(trace, path, changes):
    """A copy of the trace with xs (and num_contacts) replaced at some ticks: {tick: (p, q, num_contacts)}."""
    ticks = trace.ticks.copy()
    for k, (p, q, c) in changes.items():
        ticks["xs_p"][k], ticks["xs_q"][k], ticks["num_contacts"][k] = p, q, c
    write_trace(dataclasses.replace(trace, ticks=ticks), path)
    return path


def test_fabricated_violations_are_each_found_at_their_tick(peg_run, peg_scene, tmp_path):
    trace = read_trace(peg_run)
    (lo, hi) = peg_scene.boxes[0]
    centre = 0.5 * (lo + hi)
    r = peg_scene.god_radius
    q = np.array([1.0, 0, 0, 0])
    above = np.array([centre[0], centre[1], hi[2] + 2 * r])
    below = np.array([centre[0], centre[1], lo[2] - 2 * r])
    on_top = np.array([centre[0], centre[1], hi[2]])  # G on the box's top face: half the peg inside
    far = above + np.array([0, 0, 1.0])
    k = 200
    # k: through the box's top (pose); k + 1 -> k + 2: above, then below it (a jump through the box: motion);
    # k + 3: far away but with contacts reported (separation).
    bad = _with_poses(trace, tmp_path / "bad.g6trace", {
        k: (on_top, q, 0), k + 1: (above, q, 0), k + 2: (below, q, 0), k + 3: (far, q, 1)})
    res = certify(PEG, bad, tick_range=(k - 5, k + 10))
    assert not res.passed
    first = {v.kind: v.tick for v in res.violations}
    assert first["pose"] == k
    assert first["motion"] == k + 2 or first["motion"] == k  # into the box at k, then through it at k + 2
    assert res.num_violations["motion"] >= 2
    assert first["separation"] == k + 3
    assert res.first_violation().tick == k
    # The command: non-zero exit, the report names the first violation.
    assert main(["certify", str(bad), "--scene", str(PEG), "--ticks", f"{k - 5}:{k + 10}", "--out",
                 str(tmp_path), "--quiet", "--json"]) == 1
    doc = json.loads((tmp_path / "certify.json").read_text())
    assert doc["pass"] is False and doc["first_violation"]["tick"] == k
    assert "First violation: tick" in (tmp_path / "certify.md").read_text()


def test_certify_command_certifies_a_run_and_refuses_bad_arguments(peg_run, tmp_path, capsys):
    assert main(["certify", str(peg_run), "--scene", str(PEG), "--ticks", "0:300", "--out", str(tmp_path),
                 "--quiet"]) == 0
    assert "**certified**" in (tmp_path / "certify.md").read_text()
    assert main(["certify", str(tmp_path / "missing.g6trace"), "--scene", str(PEG), "--quiet"]) == 2
    assert main(["certify", str(peg_run), "--scene", str(PEG), "--ticks", "a:b", "--quiet"]) == 2
    assert "--ticks must be A:B" in capsys.readouterr().err


def test_filtered_and_exact_only_first_contact_agree_on_every_step_set():
    # A fixed slice of each set of datasets_generated/ccd/ (the first steps: hits and misses); the
    # exact-only path takes seconds a step on the large rotations, so those sets are left to
    # `gauss6 reference-speed --both` (every step: run for the issue, no disagreement).
    from gauss6.reference_speed import measure

    sets = ["grazing", "parallel", "random", "rotation_about_g", "zero_rotation", "peg_script", "bunny_script"]
    result = measure(sets, steps=2, both=True)
    assert all(not r["mismatches"] for r in result.values()), {n: r["mismatches"] for n, r in result.items()}
    assert sum(r["pairs"]["filtered"] for r in result.values()) > 0
