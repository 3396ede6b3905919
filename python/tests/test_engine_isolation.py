"""The engine's isolation, the loader's probes and the exit codes of `gauss6 validate`
(docs/engine-contract.md, "Isolation", "Exit codes"):

- each misbehaving engine (C: engine/tests/probe_engine.c, built several times; Python:
  isolation_engines.py, loaded by file path) ends the command with exit status 2, a report whose
  check engine_failure names the failure (signal, exit status, hang, exception, malformed table
  or output), and a trace holding the ticks up to the last good one; none crashes, hangs or
  passes the validator;
- a well-behaved version 2 engine's declarations reach the trace and the report, and the C and
  Python paths record the same; a version 1 engine still loads;
- the driver times every step itself (wall and CPU in the steps stream) and records the
  isolation's per-tick cost;
- unknown config keys are refused by the shipped engines and adapters; usage errors exit 3; the exit codes
  documented are the command's.

Runs are 0.1 s of the peg script (the tool in free space), the misbehaviour at tick 50.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from gauss6 import paths
from gauss6.cli import main
from gauss6.engine import CANARY, CONTACT_CAPACITY, POSE_RANGE, EngineFailure, load_engine
from gauss6.engine_host import RUN_TIMEOUT, SPIN_SECONDS, STEP_TIMEOUT
from gauss6.trace import read_trace
from gauss6.validate import EXIT_CODES, EXIT_ENGINE_FAILED, EXIT_PASS, EXIT_USAGE

PEG = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"
PY_PROBE = f"python:{Path(__file__).with_name('isolation_engines.py')}:probe"
AT = 50          # the tick a step's probe acts at
DURATION = 0.1   # s: 101 ticks
WATCHDOG = 1.0  # s: the step watchdog in these tests (a hang is detected this long after it starts)


def probe_library(variant: str = "") -> str:
    return str(paths.tool(f"engine/libgauss6_probe_engine{'_' + variant if variant else ''}.so"))


def validate(tmp_path, engine: str, config: str = "", *extra) -> tuple[int, dict, Path]:
    out = tmp_path / "out"
    code = main(["validate", "--engine", engine, "--config", config, "--scene", str(PEG), "--duration", str(DURATION),
                 "--out", str(out), "--quiet", "--step-timeout", str(WATCHDOG), *extra])
    return code, json.loads((out / "validation.json").read_text()), out


def assert_engine_failure(tmp_path, engine, config, kind, pattern, last_good_tick, *extra):
    code, doc, out = validate(tmp_path, engine, config, *extra)
    assert code == EXIT_ENGINE_FAILED, doc
    failure = doc["engine_failure"]
    assert failure["kind"] == kind and re.search(pattern, failure["detail"]), failure
    assert failure["tick"] == last_good_tick
    assert doc["pass"] is False and doc["failed"][0] == "engine_failure"
    verdict = doc["verdicts"][0]
    assert verdict["name"] == "engine_failure" and not verdict["pass"] and kind in verdict["note"]
    assert "the engine failed" in (out / "report.md").read_text()
    trace = read_trace(out / "run.g6trace")
    assert trace.complete and len(trace.ticks) == last_good_tick + 1
    assert trace.meta["extra"]["engine_failure"] == failure
    return doc


# (probe, kind, what the detail must say, last good tick)
STEP_PROBES = [
    ("exit_step", "exit", r"exited with status 0 in the step at tick 50", AT - 1),
    ("abort_step", "signal", r"SIGABRT.* in the step at tick 50", AT - 1),
    ("segv_step", "signal", r"SIGSEGV.* in the step at tick 50", AT - 1),
    ("hang_step", "hang", r"no answer in the step at tick 50 .*within the step watchdog", AT - 1),
    ("error_step", "exception", r"tick 50: .*returned an error: probe engine: a planted error", AT - 1),
    ("overflow_out", "abi", r"wrote past the end of its output struct", AT - 1),
    ("overflow_contacts", "abi", r"wrote past the end of its contact buffer", AT - 1),
    ("nan_pose", "abi", r"displayed pose not finite", AT - 1),
    ("huge_pose", "abi", r"displayed position .* is beyond", AT - 1),
    ("nan_time", "abi", r"reported step time nan", AT - 1),
    ("negative_time", "abi", r"reported step time -0.5", AT - 1),
]
SETUP_PROBES = [
    ("exit_create", "exit", r"exited with status 0 in create"),
    ("abort_create", "signal", r"SIGABRT.* in create"),
    ("hang_create", "hang", r"no answer in create .*within the run watchdog \(3 s\)"),
    ("exit_reset", "exit", r"exited with status 0 in reset"),
]


def test_a_failed_run_judged_offline_is_still_a_failure(tmp_path):
    """The partial trace of a failed run, judged again as a recorded RUN, exits 2 (not 0: what ran passes)."""
    assert_engine_failure(tmp_path, probe_library(), f"probe=exit_step;at={AT}", "exit", "status 0", AT - 1)
    off = tmp_path / "offline"
    code = main(["validate", str(tmp_path / "out" / "run.g6trace"), "--scene", str(PEG), "--out", str(off), "--quiet"])
    doc = json.loads((off / "validation.json").read_text())
    assert code == EXIT_ENGINE_FAILED and doc["failed"] == ["engine_failure"], doc["failed"]


@pytest.mark.parametrize("probe,kind,pattern,last", STEP_PROBES, ids=[p[0] for p in STEP_PROBES])
def test_a_misbehaving_c_step_is_a_named_engine_failure(tmp_path, probe, kind, pattern, last):
    assert_engine_failure(tmp_path, probe_library(), f"probe={probe};at={AT}", kind, pattern, last)


@pytest.mark.parametrize("probe,kind,pattern", SETUP_PROBES, ids=[p[0] for p in SETUP_PROBES])
def test_a_misbehaving_c_create_or_reset_is_a_named_engine_failure(tmp_path, probe, kind, pattern):
    assert_engine_failure(tmp_path, probe_library(), f"probe={probe}", kind, pattern, -1, "--run-timeout", "3")


MALFORMED = [
    ("null_pointers", "abi", r"the table's create is NULL"),
    ("wrong_version", "abi", r"asked for version 2, gauss6_engine_get returned a table of version 1"),
    ("data_entry", "abi", r"gauss6_engine_get is not code"),
    ("constructor_exit", "exit", r"exited with status 0 in create \(loading the engine\)"),
]


@pytest.mark.parametrize("variant,kind,pattern", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_a_malformed_library_is_a_named_engine_failure(tmp_path, variant, kind, pattern):
    assert_engine_failure(tmp_path, probe_library(variant), "", kind, pattern, -1)


PY_PROBES = [
    ("raise_create", "exception", r"create: ValueError: a planted error in the constructor", -1),
    ("raise_reset", "exception", r"reset: KeyError: 'a planted error in reset'", -1),
    ("raise_step", "exception", r"tick 50: step at t = 0.05: ZeroDivisionError: division by zero "
                                r"\(isolation_engines.py:\d+ in step\)", AT - 1),
    ("sys_exit_step", "exception", r"SystemExit: 0", AT - 1),
    ("os_exit_step", "exit", r"exited with status 0 in the step at tick 50", AT - 1),
    ("segv_step", "signal", r"SIGSEGV", AT - 1),
    ("hang_step", "hang", r"no answer in the step at tick 50", AT - 1),
    ("nan_pose", "abi", r"displayed pose not finite", AT - 1),
    ("huge_pose", "abi", r"is beyond 1000 scene radii", AT - 1),
    ("nan_time", "abi", r"reported step time nan", AT - 1),
    ("negative_time", "abi", r"reported step time -0.5", AT - 1),
    ("not_a_step", "abi", r"returned tuple, not an EngineStep", AT - 1),
    ("bad_declarations", "abi", r"declared friction mu = -1.0: not a finite float >= 0", -1),
]


@pytest.mark.parametrize("probe,kind,pattern,last", PY_PROBES, ids=[p[0] for p in PY_PROBES])
def test_a_misbehaving_python_engine_is_a_named_engine_failure(tmp_path, probe, kind, pattern, last):
    assert_engine_failure(tmp_path, PY_PROBE, f"probe={probe} at={AT}", kind, pattern, last)


def test_inline_isolation_reports_what_it_can_catch(tmp_path):
    """Inline, an exception or a malformed output is still a failure with exit 2 (a crash is not
    catchable there: the process mode is the default)."""
    assert_engine_failure(tmp_path, PY_PROBE, f"probe=raise_step at={AT}", "exception", "ZeroDivisionError", AT - 1,
                          "--isolation", "inline")
    assert_engine_failure(tmp_path / "c", probe_library(), f"probe=overflow_contacts;at={AT}", "abi",
                          "contact buffer", AT - 1, "--isolation", "inline")


def test_the_run_watchdog_ends_a_slow_run(tmp_path):
    """Each step answers in time (2 ms), but the run as a whole exceeds --run-timeout (2 s for 10 s
    of the script: at least 20 s of steps)."""
    code, doc, _ = validate(tmp_path, PY_PROBE, "probe=slow_steps", "--run-timeout", "2", "--duration", "10")
    assert code == EXIT_ENGINE_FAILED
    failure = doc["engine_failure"]
    assert failure["kind"] == "hang" and failure["tick"] > 0, failure
    assert re.search(r"in the step at tick \d+ .*within the run watchdog \(2 s\)", failure["detail"]), failure


@pytest.mark.parametrize("engine,config", [("c", "declare_mu=0.3;declare_latency=2;declare_skin=1e-5"),
                                           (PY_PROBE, "declare_mu=0.3 declare_latency=2 declare_skin=1e-5")],
                         ids=["c-version-2", "python"])
def test_declarations_and_timing_reach_the_trace(tmp_path, engine, config):
    code, doc, out = validate(tmp_path, probe_library() if engine == "c" else engine, config)
    assert code == EXIT_PASS, [v for v in doc["verdicts"] if not v["pass"]]
    declared = {"friction": {"mu": 0.3}, "latency_ticks": 2, "skin": 1e-5}
    assert doc["engine"]["declarations"] == declared and doc["engine_failure"] is None
    trace = read_trace(out / "run.g6trace")
    extra = trace.meta["extra"]
    assert extra["declarations"] == declared
    assert extra["isolation"]["mode"] == "process"
    rt = extra["isolation"]["round_trip_us"]
    assert 0 < rt["median"] <= rt["p99"] <= rt["max"]
    # The driver's own timing of each call, one steps row per tick; the engine reports none.
    assert len(trace.steps) == len(trace.ticks) == 101
    assert np.all(trace.steps["update_time"] > 0) and np.all(trace.steps["update_cpu_time"] >= 0)
    assert np.all(np.isnan(trace.ticks["force_time"]))


def test_a_version_1_engine_loads_and_declares_nothing():
    engine = load_engine("box-penalty")
    assert engine.abi_version == 1 and engine.declarations() == {}


def test_gauss6_declares_the_latency_of_a_slower_sim_step(tmp_path):
    assert load_engine("gauss6").abi_version == 2
    assert load_engine("gauss6").declarations() == {}
    assert load_engine("gauss6", "sim_period=3").declarations() == {"latency_ticks": 4}
    code, doc, out = validate(tmp_path, "gauss6")
    assert code == EXIT_PASS and doc["engine"]["declarations"] == {}
    ticks = read_trace(out / "run.g6trace").ticks
    assert np.all(ticks["force_time"] > 0)  # gauss6's engine reports its own step time


@pytest.mark.parametrize("engine,config,key", [("gauss6", "sim_perod=2", "sim_perod=2"),
                                               ("box-penalty", "stifness=100", "stifness=100"),
                                               ("fault", "inner=x;faul=nan", "faul=nan")])
def test_shipped_engines_refuse_unknown_config_keys(engine, config, key):
    with pytest.raises(EngineFailure, match=f"config item '{key}': expected key=value with key one of"):
        load_engine(engine, config)


def test_gauss6_engine_refuses_a_bad_sim_period():
    for bad in ("sim_period=0", "sim_period=2x", "sim_period="):
        with pytest.raises(EngineFailure, match="sim_period must be an integer >= 1"):
            load_engine("gauss6", bad)
    assert load_engine("gauss6", "sim_period=2").name


def test_usage_errors_exit_3(tmp_path):
    out = str(tmp_path / "out")
    base = ["validate", "--scene", str(PEG), "--out", out, "--quiet"]
    assert main(base) == EXIT_USAGE                                             # neither engine nor run
    assert main([*base, "--engine", str(tmp_path / "missing.so")]) == EXIT_USAGE
    assert main([*base, "--engine", "python:no_such_module_here:factory"]) == EXIT_USAGE
    assert main([*base, "--engine", f"python:{tmp_path / 'missing.py'}:probe"]) == EXIT_USAGE
    assert main([*base, "--engine", "gauss6", "--step-timeout", "0"]) == EXIT_USAGE
    with pytest.raises(SystemExit) as e:                                        # argparse's own errors
        main(["validate", "--engine", "gauss6", "--out", out])
    assert e.value.code == EXIT_USAGE


def test_the_documented_exit_codes_and_limits_are_the_commands():
    doc = (paths.REPO_ROOT / "docs" / "engine-contract.md").read_text()
    start = doc.index("## Exit codes")
    section = doc[start:doc.index("\n## ", start + 1)]
    rows = re.findall(r"^\| (\d) \| ([^|]+) \|", section, re.M)
    assert {int(code): text.strip() for code, text in rows} == EXIT_CODES
    for said in (f"`--step-timeout S` (default {STEP_TIMEOUT:g} s", f"`--run-timeout S` (default {RUN_TIMEOUT:g} s",
                 f"for up to {SPIN_SECONDS * 1e6:g} us", f"farther than {POSE_RANGE:g} scene radii",
                 f"more than {CONTACT_CAPACITY}", f"with {CANARY} bytes of a known pattern", "k <= "
                 f"{CONTACT_CAPACITY}"):
        assert said in doc, said


@pytest.mark.parametrize("factory", ["mujoco", "pybullet", "drake"])
def test_shipped_adapters_refuse_unknown_config_keys(factory):
    import gauss6.adapters as adapters

    with pytest.raises(ValueError, match=r"config 'bogus=1': expected key=value with key one of"):
        getattr(adapters, factory)("bogus=1")
