"""The conformance suite (gauss6.conformance: `gauss6 validate --engine E --suite conformance`) on
short slices of the battery's scripts: gauss6 on every scene, one third-party engine (Bullet's C++
library through the C ABI, else the first Python adapter installed) through the command, the table
the same serial and on 2 Dask workers, the exit status following the table, a rerun resumed from
the chunk files."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gauss6 import adapters, conformance, paths
from gauss6.datasets import BATTERY_SCENES
from gauss6.oracle import CHECK_NAMES
from gauss6.reproduce_engines import engine_spec
from gauss6.validate import EXIT_CHECK_FAILED, EXIT_ENGINE_FAILED, EXIT_PASS, EXIT_USAGE

# Seconds of each script: the approach of every scene and the first contacts where they come early
# (thin_wall's head-on hit at 0.3 s, the slot's entry at 0.3 s); short, to keep the tests near a minute.
SLICE = 0.5
RATE_HZ = 1000.0  # the battery scenes' device rate (datasets_generated/scenes/*.toml)
# gauss6's own defects the battery finds inside SLICE (issue 43: to be fixed in gauss6, not in the
# thresholds); strict, so that the fix makes this test fail until the mark is removed. None today.
KNOWN_DEFECTS: dict[str, str] = {}


def gauss6_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gauss6.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=paths.REPO_ROOT, timeout=600)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("suite-serial")
    runs, meta = conformance.run_suite("gauss6", out, duration=SLICE, workers=0, show_progress=False)
    return out, runs, meta


@pytest.mark.parametrize("scene", [pytest.param(s, marks=pytest.mark.xfail(strict=True, reason=KNOWN_DEFECTS[s]))
                                   if s in KNOWN_DEFECTS else s for s in BATTERY_SCENES])
def test_gauss6_passes_every_check_on_the_battery_slice(serial, scene):
    out, runs, _ = serial
    run = {r["scene"]: r for r in runs}[scene]
    assert run["ticks"] == round(SLICE * RATE_HZ) + 1
    assert [v["name"] for v in run["verdicts"]] == CHECK_NAMES
    assert run["pass"] and run["exit"] == EXIT_PASS, f"{scene}: {run['failed']} (see {out / scene / 'report.md'})"


def test_the_suite_writes_one_table_and_each_scenes_outputs(serial):
    out, runs, meta = serial
    assert [r["scene"] for r in runs] == list(BATTERY_SCENES)
    table = (out / "conformance.md").read_text()
    doc = json.loads((out / "conformance.json").read_text())
    assert doc["format"] == "gauss6-conformance" and doc["runs"] == runs and doc["duration"] == SLICE
    assert "short slice" in table
    for r in runs:
        assert f"| {r['scene']} |" in table
        for name in ("report.md", "validation.json", "run.g6trace"):
            assert (out / r["scene"] / name).is_file()
        # The viewer page opened at the witnesses is written for failed checks only (validate's own outputs).
        assert r["pass"] is False or not (out / r["scene"] / "run.html").exists()
    assert conformance.exit_status(runs) == (EXIT_PASS if all(r["pass"] for r in runs) else EXIT_CHECK_FAILED)


def test_two_dask_workers_give_the_serial_table(serial, tmp_path):
    _, runs, _ = serial
    two, meta = conformance.run_suite("gauss6", tmp_path, duration=SLICE, workers=2, show_progress=False)
    assert meta["workers"] == 2 and meta["chunks_run"] == len(BATTERY_SCENES)
    assert conformance.same_table(runs, two)
    # The comparison sees a changed worst value (it leaves out only the machine's timing checks).
    changed = json.loads(json.dumps(two))
    changed[0]["verdicts"][0]["worst"] = 1.0
    assert not conformance.same_table(runs, changed)


def third_party() -> str:
    """The Bullet engine's library (the C ABI) when built, else the first Python adapter installed."""
    if (paths.build_dir() / "engines/bullet/libgauss6_bullet_engine.so").exists():
        return engine_spec("bullet")
    for name in adapters.FACTORIES:
        if adapters.available(name):
            return engine_spec(name)
    pytest.skip("no third-party engine here (neither the Bullet engine built nor an adapter's framework installed)")


def test_a_third_party_engine_through_the_command_and_a_resumed_rerun(tmp_path):
    engine = third_party()
    first = None
    for attempt in range(2):
        p = gauss6_cli("validate", "--engine", engine, "--suite", "conformance", "--duration", SLICE, "--quiet",
                       "--out", tmp_path)
        doc = json.loads((tmp_path / "conformance.json").read_text())
        assert p.returncode == conformance.exit_status(doc["runs"]), p.stderr
        assert p.returncode in (EXIT_PASS, EXIT_CHECK_FAILED), f"the engine failed: {p.stderr}"
        assert [r["scene"] for r in doc["runs"]] == list(BATTERY_SCENES)
        for r in doc["runs"]:
            assert [v["name"] for v in r["verdicts"]] == CHECK_NAMES
            assert (tmp_path / r["scene"] / "report.md").is_file()
        # The rerun into the same folder reads every chunk file back and computes nothing.
        assert doc["chunks_resumed"] == attempt * len(BATTERY_SCENES)
        if first is None:
            first = doc["runs"]
        else:
            assert doc["runs"] == first


def test_exit_status_engine_failure_over_a_failed_check_over_a_pass():
    def run(code):
        return {"exit": code}
    assert conformance.exit_status([run(EXIT_PASS)] * 3) == EXIT_PASS
    assert conformance.exit_status([run(EXIT_PASS), run(EXIT_CHECK_FAILED)]) == EXIT_CHECK_FAILED
    assert conformance.exit_status([run(EXIT_CHECK_FAILED), run(EXIT_ENGINE_FAILED), run(EXIT_PASS)]) \
        == EXIT_ENGINE_FAILED


def test_an_engine_failure_is_a_row_and_exit_2(tmp_path):
    # The fault engine without its inner engine fails at create: every scene's row says so.
    p = gauss6_cli("validate", "--engine", "fault", "--suite", "conformance", "--duration", 0.1, "--quiet",
                   "--scene", paths.DATASETS_DIR / "scenes" / "lever.toml", "--out", tmp_path)
    assert p.returncode == EXIT_ENGINE_FAILED, p.stderr
    assert "**ENGINE FAILED**" in (tmp_path / "conformance.md").read_text()


@pytest.mark.parametrize("args, message", [
    (["--suite", "conformance"], "give --engine"),
    (["--engine", "no-such-engine", "--suite", "conformance"], "no such engine library"),
])
def test_suite_usage_errors(tmp_path, args, message):
    p = gauss6_cli("validate", *args, "--out", tmp_path / "o")
    assert p.returncode == EXIT_USAGE and message in p.stderr


def test_an_adapter_reports_the_deepest_contacts_within_the_contracts_capacity():
    # Rapier found 46,883 manifold points on the dense plate: the adapters report the deepest
    # CONTACT_CAPACITY of them, in the framework's order, and fewer unchanged.
    from gauss6.adapters.common import reported_contacts
    from gauss6.engine import CONTACT_CAPACITY

    rng = np.random.default_rng(43)
    rows = rng.normal(size=(3 * CONTACT_CAPACITY, 7))
    out = reported_contacts(rows)
    assert out.shape == (CONTACT_CAPACITY, 7)
    deepest = np.sort(rows[:, 6])[:CONTACT_CAPACITY]
    assert np.array_equal(np.sort(out[:, 6]), deepest)
    kept = [i for i in range(len(rows)) if rows[i, 6] <= deepest[-1]]
    assert np.array_equal(out, rows[kept])
    assert np.array_equal(reported_contacts(rows[:5]), rows[:5])
    assert reported_contacts([]).shape == (0, 7)
