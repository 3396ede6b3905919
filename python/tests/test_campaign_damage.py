"""Campaigns that check what they resume (gauss6.campaign): a finished campaign's chunk files are
damaged in every way a file system or a user can (cut, emptied, overwritten with bytes, replaced
by a directory, a FIFO, a link to /dev/zero, another chunk's copy, an older format, results
edited to null, another type or removed, the generator's hash changed), and the campaign process
is killed at random moments (seeded) between damages; each resumed run ends with the undamaged
summary bit for bit (its JSON, timings aside) and names every file it set aside. A campaign.json
that is not an object, and --workers -1 or --chunk-size 0, are refused with an error naming them.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from gauss6 import campaign, crosscheck_qp

CHUNK = 12
NUM_CHUNKS = 8
KILLS = 6
FAMILIES = ["box"]


def qp_campaign():
    return crosscheck_qp.seeded_campaign(NUM_CHUNKS * CHUNK, 5, FAMILIES, chunk_size=CHUNK)


def summary_json(summary) -> str:
    """The summary as JSON text, timings aside: compared bit for bit."""
    result, failures, _ = summary
    return json.dumps([result, failures], sort_keys=True)


@pytest.fixture(scope="module")
def undamaged():
    return summary_json(campaign.run_campaign(qp_campaign(), workers=0, show_progress=False).summary)


def _doc(path):
    return json.loads(path.read_text())


def _write(path, doc):
    path.write_text(json.dumps(doc))


def _damages(chunks, tmp_path):
    """name -> a function damaging the chunk files (index 1 to 7 are damaged, one way each, 0 kept)."""
    def edit(i, change):
        def go():
            doc = _doc(chunks / f"{i:06d}.json")
            change(doc)
            _write(chunks / f"{i:06d}.json", doc)
        return go

    def replace(i, make):
        def go():
            p = chunks / f"{i:06d}.json"
            p.unlink()
            make(p)
        return go

    return {
        "truncated": lambda: (chunks / "000001.json").write_bytes((chunks / "000001.json").read_bytes()[:57]),
        "empty": lambda: (chunks / "000002.json").write_bytes(b""),
        "binary": lambda: (chunks / "000003.json").write_bytes(bytes(range(256)) * 4),
        "directory": replace(4, lambda p: (p.mkdir(), (p / "inside").write_text("x"))),
        "fifo": replace(5, lambda p: os.mkfifo(p)),
        "link to /dev/zero": replace(6, lambda p: p.symlink_to("/dev/zero")),
        "another chunk's copy": lambda: shutil.copy(chunks / "000000.json", chunks / "000007.json"),
        "result null": edit(1, lambda d: d.update(result=None)),
        "result of another type": edit(2, lambda d: d.update(result="ok")),
        "result missing": edit(3, lambda d: d.pop("result")),
        "older format": edit(4, lambda d: [d.pop(k) for k in list(d) if k not in ("chunk", "result")]),
        "generator changed": edit(5, lambda d: d.update(generator_sha256="0" * 64)),
        "code version changed": edit(6, lambda d: d.update(code_version="0.0.0")),
        "index of another chunk": edit(7, lambda d: d.update(index=0)),
        "not an object": lambda: (chunks / "000001.json").write_text("[1, 2, 3]\n"),
    }


def test_every_damaged_chunk_file_is_recomputed_named_and_the_summary_is_unchanged(undamaged, tmp_path):
    out = tmp_path / "run"
    first = campaign.run_campaign(qp_campaign(), out=out, workers=0, show_progress=False)
    assert summary_json(first.summary) == undamaged and first.chunks_run == NUM_CHUNKS
    chunks = out / "chunks"
    for name, damage in _damages(chunks, tmp_path).items():
        damage()
        run = campaign.run_campaign(qp_campaign(), out=out, workers=0, show_progress=False)
        assert summary_json(run.summary) == undamaged, name
        assert run.chunks_run == 1 and run.chunks_resumed == NUM_CHUNKS - 1, name
        assert len(run.recomputed) == 1 and "recomputed" in run.recomputed[0], (name, run.recomputed)
        assert str(chunks) in run.recomputed[0], run.recomputed
        again = campaign.run_campaign(qp_campaign(), out=out, workers=0, show_progress=False)
        assert again.chunks_run == 0 and not again.recomputed, name  # the file written back is whole
    assert len(list(chunks.glob("*.damaged-*"))) == len(_damages(chunks, tmp_path))  # set aside, not deleted


@pytest.mark.parametrize("text,message", [("[1, 2]", "a JSON list, not an object"), ("null", "a JSON null"),
                                          ("{", "invalid JSON"), ("\xff\xfe", "not UTF-8")])
def test_a_campaign_json_that_is_not_an_object_is_an_error_naming_it(tmp_path, text, message):
    (tmp_path / "campaign.json").write_bytes(text.encode("latin-1"))
    with pytest.raises(campaign.CampaignError, match=f"campaign.json: not a campaign header.*{message}"):
        campaign.run_campaign(qp_campaign(), out=tmp_path, workers=0, show_progress=False)


def test_a_campaign_json_that_is_a_directory_and_bad_workers_are_errors(tmp_path):
    (tmp_path / "campaign.json").mkdir()
    with pytest.raises(campaign.CampaignError, match="campaign.json"):
        campaign.run_campaign(qp_campaign(), out=tmp_path, workers=0, show_progress=False)
    for workers in (-1, 1.5, True):
        with pytest.raises(campaign.CampaignError, match="workers must be an integer >= 0"):
            campaign.run_campaign(qp_campaign(), workers=workers, show_progress=False)
    with pytest.raises(ValueError, match="chunk_size must be an integer >= 1"):
        crosscheck_qp.seeded_campaign(10, 1, FAMILIES, chunk_size=0)


@pytest.mark.parametrize("option,value", [("--workers", "-1"), ("--chunk-size", "0"), ("--chunk-size", "-4"),
                                          ("--workers", "two")])
def test_bad_counts_are_refused_at_parse_time(option, value, capsys):
    from gauss6.cli import main

    assert main(["crosscheck", "qp", "--seeded", "10", option, value]) == 2
    assert option in capsys.readouterr().err


def test_killed_at_random_moments_and_damaged_between_kills_resumes_to_the_undamaged_summary(undamaged, tmp_path):
    """The command killed (SIGKILL) KILLS times at seeded moments (during its start-up, or after a
    seeded number of its chunk writes), a random chunk file damaged after each kill; then a run to the end:
    its JSON summary is the undamaged one, and it names the damaged file it met."""
    rng = np.random.default_rng(2047)
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "gauss6.cli", "crosscheck", "qp", "--seeded", str(NUM_CHUNKS * CHUNK),
           "--chunk-size", str(CHUNK), "--seed", "5", "--workers", "0", "--out", str(out), "--json"]
    for f in FAMILIES:
        cmd += ["--family", f]
    t0 = time.monotonic()
    whole = subprocess.run(cmd[:cmd.index("--out")] + cmd[cmd.index("--out") + 2:], capture_output=True, text=True,
                           check=True)
    span = time.monotonic() - t0  # a whole run's wall time, start-up included: kills fall inside it
    kills, written_at_kill, damaged = 0, [], []
    def chunk_files():
        return sorted(f for f in (out / "chunks").glob("0*.json")) if (out / "chunks").is_dir() else []

    for _ in range(KILLS):
        # The moment: after a seeded number of chunk writes, fewer than the run has left to write (the
        # chunks missing, and the one damaged last), so that it falls while the run still works
        # whatever the machine's speed; 0 writes: during its start-up, after a seeded delay.
        before = {f.name: f.stat().st_mtime_ns for f in chunk_files()}
        left = NUM_CHUNKS - len(before) + (1 if damaged else 0)
        writes = int(rng.integers(0, max(left, 1)))
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + (float(rng.uniform(0.0, 0.5)) * span if writes == 0 else 10 * span)
        while proc.poll() is None and time.monotonic() < deadline:
            written = sum(before.get(f.name) != f.stat().st_mtime_ns for f in chunk_files())
            if writes and written >= writes:
                break
            time.sleep(0.002)
        if proc.poll() is None:
            proc.send_signal(signal.SIGKILL)
            kills += 1
        proc.wait()
        files = chunk_files()
        written_at_kill.append(len(files))
        if files:
            victim = files[int(rng.integers(len(files)))]
            ways = [lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]),
                    lambda p: p.write_bytes(b"")]
            if len(files) > 1:  # another chunk's copy needs another chunk (one may be all a kill left)
                ways.append(lambda p: shutil.copy(files[0] if p != files[0] else files[-1], p))
            ways[int(rng.integers(len(ways)))](victim)
            damaged.append(victim.name)
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert kills >= KILLS // 2, (kills, written_at_kill)
    if damaged:  # the file damaged just before the last run is named by it
        assert any(f"chunks/{damaged[-1]}:" in p for p in result["chunks_recomputed"]), result
    for k in ("chunks_run", "chunks_resumed", "chunks_recomputed", "seconds", "workers"):
        result.pop(k)
    fresh = json.loads(whole.stdout)
    for k in ("chunks_run", "chunks_resumed", "chunks_recomputed", "seconds", "workers"):
        fresh.pop(k)
    assert json.dumps(result, sort_keys=True) == json.dumps(fresh, sort_keys=True)
    assert summary_json(campaign.run_campaign(qp_campaign(), out=out, workers=0, show_progress=False).summary) \
        == undamaged
    print(f"whole run {span:.1f} s; {kills} kills, chunk files written at each: {written_at_kill}; damaged: {damaged}")
