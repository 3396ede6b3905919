"""`gauss6 validate`: drive an engine under test with the simulated device and judge its run, or judge a
run it recorded itself (docs/engine-contract.md).

    gauss6 validate --engine ENGINE --scene SCENE [--script NAME] [--duration S] --out DIR
    gauss6 validate RUN --scene SCENE [--script NAME] --out DIR      (RUN: a .g6trace, or a ticks CSV)
    gauss6 validate --engine ENGINE --suite conformance [--workers N | --scheduler ADDR] --out DIR
                                            (the battery, scene x check: gauss6.conformance)

ENGINE: a shared library that exports the C ABI (gauss6/engine.h), by path; a built one by name
(gauss6, box-penalty, fault); or a Python engine as `python:MODULE:FACTORY` (MODULE importable)
or `python:path/to/file.py:FACTORY` (FACTORY(config) returns an object with reset(scene) and
step(t, xh_p, xh_q), gauss6.engine). --config passes the engine its config text. The engine runs
in a child process (--isolation process, the default; gauss6.engine_host) under a per-step and a
per-run watchdog (--step-timeout, --run-timeout); its crash, exit, hang, exception or malformed
output ends the run with the check `engine_failure` and exit status 2, the trace holding the
ticks up to the last good one.

DIR receives: run.g6trace (the driven run), report.md (the verdict table, the plots, the
machine), validation.png/.svg (penetration depth or separation, distance from the force cone,
port energy over time, the script's phases marked) and validation.json:

    {"format": "gauss6-validation", "version": 1, "pass": bool, "failed": [names],
     "engine": {"name", "library", "config", "isolation", "declarations"} or null,
     "engine_failure": {"kind", "detail", "tick"} or null, "run": path of the judged trace,
     "scene": path, "script": path or null, "ticks": int, "duration": s,
     "coverage": a recorded RUN's trace.coverage (ticks, time span, complete or cut, sha256) or null,
     "thresholds": {"file": path, "version": int},
     "verdicts": [{"name", "title", "pass", "count", "worst", "unit", "first_time", "note", "details"}],
     "machine": {"platform", "processor", "cpus", "python"}}

Exit status (EXIT_CODES; docs/engine-contract.md): 0 a complete run, every check passed; 1 a check
failed; 2 the engine failed (nothing else gives 0 or 1 then); 3 a usage error.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from . import oracle as oracle_mod
from .engine import EngineScene, check_spec
from .engine_host import InlineHost, ProcessHost
from .machine import machine
from .thresholds import THRESHOLDS, load_thresholds
from .trace import coverage_line

FORMAT_VERSION = 1

EXIT_PASS, EXIT_CHECK_FAILED, EXIT_ENGINE_FAILED, EXIT_USAGE = 0, 1, 2, 3
EXIT_CODES = {EXIT_PASS: "every check passed on a complete run", EXIT_CHECK_FAILED: "a check failed",
              EXIT_ENGINE_FAILED: "the engine failed", EXIT_USAGE: "usage error"}


def _progress(quiet: bool):
    if quiet:
        return None, None
    state = {"last": 0.0}

    def run(t, end):
        print(f"\r  driving: {t:6.2f} / {end:.2f} s", end="", file=sys.stderr, flush=True)

    def judge(stage, done, total):
        if time.perf_counter() - state["last"] > 0.5:
            state["last"] = time.perf_counter()
            print(f"\r  judging: {stage} {done}/{total}        ", end="", file=sys.stderr, flush=True)
    return run, judge


def plot(result: oracle_mod.OracleResult, out: Path, title: str) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = result.series
    t = s["t"]
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    ax = axes[0]
    sep = s["separation"]
    ax.plot(t, np.where(sep >= 0, sep, np.nan), ".", ms=2, label="exact separation at ticks with force")
    ax.plot(t, np.where(sep < 0, sep, np.nan), ".", ms=2, color="C3", label="penetration depth (estimate)")
    if np.any(s["penetrating"]):
        ax.plot(t[s["penetrating"]], np.zeros(int(s["penetrating"].sum())), "|", color="C3", ms=8,
                label="penetrating pose (exact)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_ylabel("separation (delta)")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.legend(loc="upper right", fontsize=7)
    ax = axes[1]
    ax.plot(t, s["cone_distance"], ".", ms=2)
    ax.set_ylabel("distance from cone\n(share of |F|)")
    ax.set_yscale("symlog", linthresh=1e-6)
    ax = axes[2]
    ax.plot(t, s["energy"], lw=1)
    ax.set_ylabel("port energy W (J)")
    ax.set_xlabel("t (s)")
    for ax in axes:
        for name, start in result.phases:
            ax.axvline(start, color="0.6", lw=0.8, ls="--")
    for name, start in result.phases:
        axes[0].annotate(name, (start, 1.0), xycoords=("data", "axes fraction"), fontsize=8, va="bottom")
    fig.suptitle(title)
    fig.tight_layout()
    paths = [out / "validation.png", out / "validation.svg"]
    for p in paths:
        fig.savefig(p, dpi=110)
    plt.close(fig)
    return paths


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.3g}"
    return str(v)


def verdict_table(verdicts) -> str:
    rows = ["| check | verdict | count | worst | first violation (s) | note |", "| --- | --- | --- | --- | --- | --- |"]
    for v in verdicts:
        rows.append(f"| {v.title} | {'pass' if v.passed else '**FAIL**'} | {v.count} | {_fmt(v.worst)} {v.unit} | "
                    f"{_fmt(v.first_time)} | {v.note} |")
    return "\n".join(rows)


def failure_verdict(failure: dict, rate_hz: float) -> oracle_mod.Verdict:
    """The check engine_failure of a run the engine ended (the trace's extra["engine_failure"])."""
    return oracle_mod.Verdict("engine_failure", "0. engine failure", False, 1, None, "",
                              (failure["tick"] + 1) / rate_hz, f"{failure['kind']}: {failure['detail']}",
                              {"kind": failure["kind"], "last_good_tick": failure["tick"]})


def engine_lines(engine: dict) -> list[str]:
    """The report's lines on how the engine ran: its isolation and what it declared."""
    iso = engine["isolation"]
    cost = ", ".join(f"{k} {_fmt(v)}" for k, v in iso["round_trip_us"].items())
    return [f"- isolation: {iso['mode']} (transport per tick, us: {cost})",
            f"- declared: {json.dumps(engine['declarations']) if engine['declarations'] else 'nothing'}"]


def write_outputs(result, out: Path, info: dict, witnesses: str = "") -> dict:
    title = f"{info.get('engine_name') or 'recorded run'} on {Path(info['scene']).stem}"
    plotted = len(result.series.get("t", ())) > 0
    if plotted:
        plot(result, out, title)
    failure = info.get("engine_failure")
    doc = {"format": "gauss6-validation", "version": FORMAT_VERSION, "pass": result.passed, "failed": result.failed(),
           "engine": info.get("engine"), "engine_failure": failure, "run": info["run"], "scene": info["scene"],
           "script": info.get("script"),
           "ticks": info["ticks"], "duration": info["duration"], "coverage": info.get("coverage"),
           "thresholds": {"file": info["thresholds"], "version": info["thresholds_version"]},
           "verdicts": [v.to_json() for v in result.verdicts], "machine": machine()}
    (out / "validation.json").write_text(json.dumps(doc, indent=2) + "\n")
    lines = [f"# Validation: {title}", "",
             f"Verdict: **{'PASS' if result.passed else 'FAIL'}**"
             + ("" if result.passed else f" ({', '.join(result.failed())})"), "",
             f"- run: `{info['run']}` ({info['ticks']} ticks, {info['duration']:.3f} s)"
             + (f"; the trace: {coverage_line(info['coverage'])}" if info.get("coverage") else ""),
             f"- scene: `{info['scene']}`" + (f", script `{info['script']}`" if info.get("script") else ""),
             f"- engine: {info.get('engine_name') or 'recorded offline'}"
             + (f" (`{info['engine']['library']}`, config `{info['engine']['config']}`)" if info.get("engine") else ""),
             *(engine_lines(info["engine"]) if info.get("engine") else []),
             *([f"- **the engine failed** ({failure['kind']}) after tick {failure['tick']}: {failure['detail']}"]
               if failure else []),
             f"- thresholds: `{info['thresholds']}` (version {info['thresholds_version']})",
             f"- machine: {machine()['processor']}, {machine()['cpus']} cpus, {machine()['platform']}", "",
             verdict_table(result.verdicts), "",
             "Geometric verdicts are exact (gauss6's reference, CGAL); depths are estimates; lengths in units of "
             "the scene's delta. Definitions and thresholds: docs/engine-contract.md, harness/oracle.toml.", "",
             *(["![validation](validation.png)"] if plotted else []), "",
             *([witnesses] if witnesses else [])]
    (out / "report.md").write_text("\n".join(lines))
    return doc


def witness_section(result, trace, oracle, out: Path) -> str:
    """Writes the witnesses of the failed checks (witness.py) and, when there are any, the viewer page
    they link to (run.html, opened at each witness's tick); returns the report's section ('' if none)."""
    from .view import write_view
    from .witness import report_witnesses

    if not len(trace.ticks):
        return ""
    section = report_witnesses(result, trace, oracle, out, viewer_page="run.html")
    if section:
        write_view([trace.path], scene=oracle.scene_path, out=out / "run.html")
    return section


def read_run(run, scene) -> tuple:
    """A recorded RUN as judged offline: (trace, path). A .g6trace (a cut one read up to its
    last complete chunk, the cut stated by trace.coverage in the outputs, and warned of on
    stderr) or a ticks CSV; positions beyond the coordinate bound refused, quaternions
    rescaled (trace.checked_poses); a run without ticks refused (ValueError naming it)."""
    import warnings

    from .trace import TraceWarning, checked_poses, read_trace

    run_path = Path(run)
    if run_path.suffix == ".g6trace":
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", TraceWarning)
            trace = read_trace(run_path)
        for w in caught:
            print(f"gauss6 validate: warning: {w.message}; judged on the ticks it holds "
                  "(validation.json: coverage)", file=sys.stderr)
    else:
        from .logs import read_csv_dir

        trace = read_csv_dir(run_path, scene=str(scene))
    if len(trace.ticks) == 0:
        raise ValueError(f"{run_path}: the run holds no ticks: there is nothing to judge")
    for column in ("xh_q", "xs_q"):  # a zero quaternion is no rotation: the oracle cannot judge it
        zero = np.nonzero(np.all(trace.ticks[column] == 0, axis=1))[0]
        if len(zero):
            k = int(zero[0])
            raise ValueError(f"{run_path}: tick {k} (t = {float(trace.ticks['t'][k])!r}): {column} is the zero "
                             f"quaternion, which is no rotation ({len(zero)} such ticks)")
    return checked_poses(trace), run_path


def validate(args) -> int:
    from .paths import check_output_dir
    from .trace import coverage

    out = check_output_dir(args.out)
    thresholds_path = Path(args.thresholds) if args.thresholds else THRESHOLDS
    thresholds = load_thresholds(thresholds_path)
    run_progress, judge_progress = _progress(args.quiet)
    info = {"scene": str(args.scene), "thresholds": str(thresholds_path),
            "thresholds_version": thresholds.get("version")}
    from .driver import drive, scene_script, script_text

    failure = None
    if args.engine:
        check_spec(args.engine)
        scene = EngineScene.from_scene_file(args.scene)
        text, script_path = script_text(args.script, args.scene) if args.script else scene_script(args.scene)
        run_path = out / "run.g6trace"
        host = ProcessHost(args.engine, args.config, args.step_timeout, args.run_timeout) \
            if args.isolation == "process" else InlineHost.of(args.engine, args.config)
        try:
            trace = drive(host, scene, text, run_path, args.duration, run_progress,
                          extra={"engine_config": args.config, "script": script_path})
        finally:
            host.close()
        if run_progress:
            print(file=sys.stderr)
        extra = trace.meta["extra"]
        failure = extra.get("engine_failure")
        info.update(engine={"name": extra["engine"], "library": str(host.library), "config": args.config,
                            "isolation": extra["isolation"], "declarations": extra["declarations"]},
                    engine_name=extra["engine"], script=script_path, run=str(run_path), engine_failure=failure)
    else:
        trace, run_path = read_run(args.run, args.scene)
        info["coverage"] = coverage(trace)
        if args.script:
            from .driver import script_phases

            text, script_path = script_text(args.script, args.scene)
            trace.meta["phases"] = [{"name": n, "start": s} for n, s in script_phases(text)]
            info["script"] = script_path
        # A driven run that ended in the engine's failure stays one when judged again.
        failure = trace.meta.get("extra", {}).get("engine_failure")
        info.update(run=str(run_path), engine_name=trace.meta.get("extra", {}).get("engine"), engine_failure=failure)
    ticks = trace.ticks
    info.update(ticks=len(ticks), duration=float(ticks["t"][-1] - ticks["t"][0]) if len(ticks) else 0.0)
    oracle = oracle_mod.Oracle(args.scene, thresholds)
    if failure is None:
        result = oracle.judge(trace, judge_progress)
    else:
        # What ran is judged as well when it can be (two ticks at least); the failure is the verdict.
        result = oracle_mod.OracleResult([], {}, [(p["name"], float(p["start"])) for p in trace.meta.get("phases", [])])
        if len(ticks) >= 2:
            try:
                result = oracle.judge(trace, judge_progress)
            except Exception as e:  # a partial run the checks cannot take: the failure alone is reported
                print(f"gauss6 validate: the partial run was not judged ({type(e).__name__}: {e})", file=sys.stderr)
        result.verdicts.insert(0, failure_verdict(failure, trace.meta["device"]["rate_hz"]))
    if judge_progress:
        print("\r" + " " * 60 + "\r", end="", file=sys.stderr)
    doc = write_outputs(result, out, info, witness_section(result, trace, oracle, out))
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        print(verdict_table(result.verdicts))
        print(f"\n{'PASS' if result.passed else 'FAIL'}: {out / 'report.md'}")
        if failure is not None:
            print(f"gauss6 validate: the engine failed ({failure['kind']}): {failure['detail']}", file=sys.stderr)
    if failure is not None:
        return EXIT_ENGINE_FAILED
    return EXIT_PASS if result.passed and len(ticks) > 0 else EXIT_CHECK_FAILED
