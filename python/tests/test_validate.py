"""The engine contract, the driver and the validation oracle (docs/engine-contract.md):

- the C ABI loader refuses what is not an engine; the example C engine runs;
- gauss6's own engine behind the ABI, driven by the simulated device, is the run of
  `gauss6 reproduce` tick for tick, and a driven run is repeatable;
- each planted fault of the fault engine (C, through the ABI, around gauss6's engine) is caught
  and named by its check alone, and gauss6's engine raises no alarm on either scene;
- the example engine's known flaws are reported; `gauss6 validate` exits 1 on a failure, and
  judges a recorded run (trace or CSV) as it judges a driven one.

Runs are short slices of the shipped scripts (the first 1.2-1.6 s: the approach and the first
contacts) to keep `make test` fast.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from gauss6 import paths
from gauss6.driver import drive, scene_script
from gauss6.engine import CEngine, EngineError, EngineScene, engine_library, load_engine
from gauss6.oracle import Oracle, added_per_tick
from gauss6.trace import read_trace, to_csv

PEG = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"
BUNNY = paths.DATASETS_DIR / "scenes" / "bunnies.toml"
PEG_SLICE = 1.6    # s: the approach (tip 1 cm above the top), first force at 0.39 s, pressing and sliding on the top
BUNNY_SLICE = 1.6  # s: the approach and the ear's first contacts on the ridge


@pytest.fixture(scope="module")
def peg_oracle():
    return Oracle(PEG)


def _run(tmp_path, engine, scene=PEG, duration=PEG_SLICE, name="run"):
    text, _ = scene_script(scene)
    return drive(engine, EngineScene.from_scene_file(scene), text, tmp_path / f"{name}.g6trace", duration)


def test_loader_refuses_a_library_that_is_not_an_engine(tmp_path):
    with pytest.raises(EngineError, match="no such engine library"):
        load_engine(str(tmp_path / "missing.so"))
    import gauss6._gauss6 as ext  # a shared library without gauss6_engine_get

    with pytest.raises(EngineError, match="not an engine library"):
        CEngine(ext.__file__)
    with pytest.raises(EngineError, match="create failed: fault engine: config needs inner=PATH"):
        load_engine("fault", "")


def test_gauss6_engine_is_the_reproduce_run_tick_for_tick(tmp_path):
    from gauss6._gauss6 import runtime

    driven = _run(tmp_path, load_engine("gauss6"), duration=1.2)
    runtime.run_scenario(str(PEG), str(tmp_path / "ref.g6trace"), duration=1.2)
    ref = read_trace(tmp_path / "ref.g6trace")
    n = len(driven.ticks)
    assert n == len(ref.ticks) == 1201
    # Same hand, same loop: the handle, the god-object and the wrench, bit for bit.
    for col in ("t", "xh_p", "xh_q", "xs_p", "xs_q", "wrench"):
        np.testing.assert_array_equal(driven.ticks[col], ref.ticks[col][:n], err_msg=col)
    assert np.abs(driven.ticks["wrench"]).max() > 0.1  # the slice reaches contact


def test_a_driven_run_is_repeatable(tmp_path):
    a = _run(tmp_path, load_engine("box-penalty"), duration=1.0, name="a")
    b = _run(tmp_path, load_engine("box-penalty"), duration=1.0, name="b")
    for col in ("xh_p", "xh_q", "xs_p", "xs_q", "wrench"):
        np.testing.assert_array_equal(a.ticks[col], b.ticks[col])


def test_gauss6_engine_raises_no_alarm_on_the_peg(tmp_path, peg_oracle):
    result = peg_oracle.judge(_run(tmp_path, load_engine("gauss6")))
    assert result.failed() == [], [v.to_json() for v in result.verdicts if not v.passed]
    # The slice exercises the checks: forces at contact, exactly checked steps.
    assert result.verdict("force_direction").details["ticks"] > 100
    assert result.verdict("penetration").details["poses"] > 500


def test_gauss6_engine_raises_no_alarm_on_the_bunny(tmp_path):
    """No alarm on the bunny either. Two true findings were fixed in the runtime and stay checked here.
    Three steps whose direct in-between motion touched the bunny though each leg was free (the settled
    end is now kept only when the CCD proves the direct motion free: METHOD.md property 5). And a graze
    in the approach: from 0.191 s the god-object rested on an edge/edge contact at 1.001-1.015 delta,
    inside the CCD's distance-tolerance band (delta to 1.1 delta), so every sim step's leg stopped at
    u_hit 6e-4 to 5e-3; it crept, held 5 mm behind the hand (out of the bunny from 0.236 s), until at
    0.257 s it slid off and the force fell from 0.84 N to 0 in a tick (the leg now runs again from a
    waypoint that lifts the contacts out of the band: sim_loop.cpp lift_out_of_graze)."""
    result = Oracle(BUNNY).judge(_run(tmp_path, load_engine("gauss6"), scene=BUNNY, duration=BUNNY_SLICE))
    assert result.failed() == [], [v.to_json() for v in result.verdicts if not v.passed]
    tunnels, jumps = result.verdict("tunnelling"), result.verdict("force_jumps")
    assert tunnels.count == 0 and tunnels.details["undecided"] == 0 and tunnels.details["near"] > 1000
    assert jumps.details["max_force_step"] < 0.3  # the graze's release was 0.84 N
    assert result.verdict("force_direction").details["ticks"] > 100


def test_force_jumps_judge_the_force_a_tick_adds():
    """Property 7 (harness/oracle.toml [jumps], version 4): a release adds nothing, whole or in part;
    a force that appears, grows along itself or turns counts whole. Exact to rounding (1e-12)."""
    F = np.array([[0, -1.29, 0],     # pressed
                  [0, 0, 0],         # released at once (the peg's wedge at 11.574 s): adds 0
                  [0, 0.8, 0],       # a new contact's knock: adds 0.8
                  [0, 0.4, 0],       # half released: adds 0
                  [0, 1.0, 0],       # grows along itself: adds 0.6
                  [0.3, 1.0, 0],     # turns: adds 0.3
                  [-0.3, -1.0, 0]])  # turned round: adds all of it
    added = added_per_tick(F)
    np.testing.assert_allclose(added, [0, 0.8, 0, 0.6, 0.3, np.hypot(0.3, 1.0)], atol=1e-12)
    # Never more than the whole change (a = 1), so whatever passed before still passes.
    assert np.all(added <= np.linalg.norm(np.diff(F, axis=0), axis=1) + 1e-15)
    # A drop-out and its return: the return is the knock.
    np.testing.assert_allclose(added_per_tick(np.array([[0, 1.0, 0], [0, 0, 0], [0, 1.0, 0]])), [0, 1.0])


def test_fig13_tangential_share_against_the_nearest_features(tmp_path, peg_oracle):
    """Fig. 13's measure (Oracle.nearest_rows, tangential_share): gauss6's force lies in the span of
    the nearest features' contact wrenches to rounding; the planted 5% tangential part shows on every
    tick with force after it, at 1-10% (the M^-1 metric weighs it against the torque)."""
    window = (1.0, PEG_SLICE)
    plain = peg_oracle.judge(_run(tmp_path, load_engine("gauss6"), name="plain"), nearest_window=window)
    engine = load_engine("fault", f"inner={engine_library('gauss6')};fault=tangential;at=1.0")
    fault = peg_oracle.judge(_run(tmp_path, engine, name="fault"), nearest_window=window)
    for result, low, high in ((plain, 0.0, 1e-9), (fault, 0.01, 0.1)):
        share = result.series["nearest_tangential"]
        measured = share[np.isfinite(share)]
        assert len(measured) > 400
        assert low <= measured.min() and measured.max() <= high, (measured.min(), measured.max())
    assert np.all(np.isnan(plain.series["nearest_tangential"][plain.series["t"] < window[0]]))


FAULTS = [
    # (fault, at (s), the one check that must fail)
    ("penetrate", 1.0, "penetration"),
    ("tangential", 1.0, "force_direction"),
    ("distance", 1.0, "force_at_distance"),
    ("energy", 0.0, "energy"),
    ("nan", 1.0, "wrench_sanity"),
    ("tunnel", 0.3, "tunnelling"),
]


@pytest.mark.parametrize("fault,at,check", FAULTS, ids=[f[0] for f in FAULTS])
def test_each_planted_fault_is_caught_by_its_check_alone(tmp_path, peg_oracle, fault, at, check):
    inner = engine_library("gauss6")
    engine = load_engine("fault", f"inner={inner};fault={fault};at={at}")
    result = peg_oracle.judge(_run(tmp_path, engine))
    # The tunnel's pose below the box is shown while the handle is in free space: it does not follow
    # the handle there either (the tracking check), a second true finding.
    also = {"tunnel": ["tracking"]}.get(fault, [])
    assert [c for c in result.failed() if c not in also] == [check], \
        [v.to_json() for v in result.verdicts if not v.passed]
    v = result.verdict(check)
    assert v.first_time is not None and v.first_time >= at


def test_the_example_engine_shows_its_known_flaws(tmp_path, peg_oracle):
    result = peg_oracle.judge(_run(tmp_path, load_engine("box-penalty")))
    # Penalty: its displayed poses penetrate the box's top.
    assert "penetration" in result.failed()
    assert result.verdict("penetration").details["max_depth"] > 1e-5  # m: far beyond delta


def test_validate_command_exit_codes_and_offline_runs(tmp_path):
    from gauss6.cli import main

    out = tmp_path / "gauss6"
    assert main(["validate", "--engine", "gauss6", "--scene", str(PEG), "--duration", "1.0", "--out", str(out),
                 "--quiet"]) == 0
    doc = json.loads((out / "validation.json").read_text())
    assert doc["pass"] is True and doc["format"] == "gauss6-validation" and doc["ticks"] == 1001
    assert {v["name"] for v in doc["verdicts"]} >= {"penetration", "tunnelling", "energy", "cost"}
    assert (out / "report.md").read_text().count("| pass |") == len(doc["verdicts"])
    assert (out / "validation.png").stat().st_size > 0

    # The same run, judged offline from its trace and from its ticks CSV: the same verdicts.
    for run in (out / "run.g6trace", to_csv(read_trace(out / "run.g6trace"), tmp_path / "csv")[0]):
        off = tmp_path / f"offline-{run.suffix[1:]}"
        assert main(["validate", str(run), "--scene", str(PEG), "--script", "peg_in_hole", "--out", str(off),
                     "--quiet"]) == 0
        doc2 = json.loads((off / "validation.json").read_text())
        assert [v["count"] for v in doc2["verdicts"][:-1]] == [v["count"] for v in doc["verdicts"][:-1]]

    bad = tmp_path / "penalty"
    assert main(["validate", "--engine", "box-penalty", "--scene", str(PEG), "--duration", "1.0", "--out", str(bad),
                 "--quiet"]) == 1
    assert main(["validate", "--scene", str(PEG), "--out", str(bad), "--quiet"]) == 3  # usage
