"""The conformance suite: `gauss6 validate --engine E --suite conformance --out DIR` runs the
battery (every scene of datasets.BATTERY_SCENES with its own hand script, docs/conformance-battery.md)
and writes one conformance table, scene x check.

Each (engine, config, scene) run is one chunk of a campaign (gauss6.campaign): run serially in this
process (--workers 0), on a local Dask cluster of N worker processes (--workers N) or on an existing
cluster (--scheduler tcp://host:port); the table is the same either way, since a chunk's result
depends on the chunk alone. A chunk is `gauss6 validate` on one scene (the engine in a child process,
its watchdogs, the witnesses of failed checks and the viewer page), written to DIR/<label>/; DIR
itself is the campaign's folder (DIR/campaign.json, DIR/chunks/), so a killed suite resumes.

DIR receives:
  conformance.md    the table: one row a scene, one column a check (oracle.CHECK_TABLE), each cell
                    pass or FAIL with the worst value; engine failures named
  conformance.json  {"format": "gauss6-conformance", "version": 1, "runs": [one per chunk: engine,
                    config, scene, script, duration asked, ticks, exit, pass, failed, engine_failure,
                    verdicts [{name, pass, count, worst, unit}]], "wall_seconds", "workers"}
  <scene>/          that scene's validate outputs (report.md, validation.json, run.g6trace, plots,
                    witnesses, run.html)

Exit status (validate.EXIT_CODES): 0 every check passed on every scene, 1 a check failed on some
scene, 2 the engine failed on some scene, 3 a usage error.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
from pathlib import Path

from . import paths
from .campaign import Campaign, CampaignError, run_campaign
from .datasets import BATTERY_SCENES
from .engine_host import RUN_TIMEOUT, STEP_TIMEOUT
from .validate import EXIT_CHECK_FAILED, EXIT_ENGINE_FAILED, EXIT_PASS, EXIT_USAGE, validate

SUITES = {"conformance": BATTERY_SCENES}
FORMAT_VERSION = 1
# Checks whose value measures the machine the run had (wall time of the step calls), not the run:
# their cells are shown but left out when two tables are compared (same_table).
MACHINE_CHECKS = ("cost",)


def scene_file(name: str) -> Path:
    """A battery scene's TOML by name (datasets_generated/scenes/NAME.toml)."""
    return paths.DATASETS_DIR / "scenes" / f"{name}.toml"


def run_label(run: dict) -> str:
    """The folder (and row) name of a run: the scene, with the engine's config when one is set."""
    cfg = "".join(c if c.isalnum() or c in "._-" else "_" for c in run["config"])
    return run["scene"] + (f"-{cfg}" if cfg else "")


def make_chunks(engine: str, scenes, out: Path, config: str = "", script: str | None = None,
                duration: float | None = None, isolation: str = "process", step_timeout: float | None = None,
                run_timeout: float | None = None, thresholds: str | None = None) -> list[dict]:
    """One chunk a scene: everything its run needs, JSON-ready (campaign.Campaign). A scene
    is a battery scene's name or a scene file's path."""
    out = Path(out).resolve()
    return [{"engine": engine, "config": config, "scene": Path(name).stem,
             "scene_file": str(Path(name).resolve() if str(name).endswith(".toml") else scene_file(name)),
             "script": script, "duration": duration,
             "isolation": isolation, "step_timeout": step_timeout, "run_timeout": run_timeout,
             "thresholds": thresholds, "out": str(out)}
            for name in scenes]


def run_chunk(chunk: dict) -> dict:
    """`gauss6 validate` on one scene (its outputs in OUT/<label>/); the run's row of the table,
    free of anything that depends on where or when it ran (paths, transport timings)."""
    out = Path(chunk["out"]) / run_label(chunk)
    args = argparse.Namespace(
        engine=chunk["engine"], run=None, config=chunk["config"], scene=Path(chunk["scene_file"]),
        script=chunk["script"], duration=chunk["duration"], out=out, thresholds=chunk["thresholds"],
        isolation=chunk["isolation"], step_timeout=chunk["step_timeout"] or STEP_TIMEOUT,
        run_timeout=chunk["run_timeout"] or RUN_TIMEOUT, json=False, quiet=True)
    with contextlib.redirect_stdout(io.StringIO()):  # the scene's own table is in its report.md
        code = validate(args)
    doc = json.loads((out / "validation.json").read_text())
    failure = doc["engine_failure"]
    return {"engine": chunk["engine"], "engine_name": (doc["engine"] or {}).get("name"), "config": chunk["config"],
            "scene": chunk["scene"], "label": run_label(chunk), "script": Path(doc["script"]).name if doc["script"] else None,
            "duration_asked": chunk["duration"], "ticks": doc["ticks"], "duration": doc["duration"], "exit": code,
            "pass": doc["pass"], "failed": doc["failed"],
            "engine_failure": None if failure is None else {k: failure[k] for k in ("kind", "detail", "tick")},
            "verdicts": [{k: v[k] for k in ("name", "pass", "count", "worst", "unit")} for v in doc["verdicts"]]}


def merge(results: list) -> list:
    return list(results)


def campaign(chunks: list[dict], parameters: dict | None = None) -> Campaign:
    return Campaign("conformance", chunks, run_chunk, merge, parameters or {},
                    sources=("gauss6.validate", "gauss6.oracle", "gauss6.driver"))


def exit_status(runs: list[dict]) -> int:
    if any(r["exit"] == EXIT_ENGINE_FAILED for r in runs):
        return EXIT_ENGINE_FAILED
    return EXIT_PASS if all(r["exit"] == EXIT_PASS for r in runs) else EXIT_CHECK_FAILED


def cell(v: dict | None) -> str:
    """A table cell: pass or FAIL with the check's worst value (and the count of violations)."""
    if v is None:
        return "-"
    worst = v["worst"]
    worst = "-" if worst is None else (f"{worst:.3g}" if isinstance(worst, (int, float)) else str(worst))
    unit = v["unit"].split(" (")[0].replace("|", "\\|")  # a unit like "share of |F|" inside a table cell
    if v["pass"]:
        return f"pass {worst} {unit}".rstrip()
    return f"**FAIL** {v['count']}: {worst} {unit}".rstrip()


def table(runs: list[dict]) -> str:
    """Markdown: one row a run (engine, scene, config), one column a check of the oracle's table."""
    from .oracle import CHECK_NAMES

    names = ["engine_failure", *CHECK_NAMES]
    used = [n for n in names if n != "engine_failure" or any(r["engine_failure"] for r in runs)]
    rows = ["| engine | scene | ticks | verdict | " + " | ".join(used) + " |", "|" + " --- |" * (len(used) + 4)]
    for r in runs:
        cells = {v["name"]: v for v in r["verdicts"]}
        engine = r["engine_name"] or r["engine"]
        verdict = "pass" if r["pass"] else ("**ENGINE FAILED**" if r["engine_failure"] else "**FAIL**")
        texts = {n: cell(cells.get(n)) for n in used}
        if r["engine_failure"]:
            texts["engine_failure"] = f"**FAIL** {r['engine_failure']['kind']} after tick {r['engine_failure']['tick']}"
        rows.append(f"| {engine}{' (' + r['config'] + ')' if r['config'] else ''} | {r['scene']} | {r['ticks']} | "
                    f"{verdict} | " + " | ".join(texts[n] for n in used) + " |")
    return "\n".join(rows)


def summary_line(runs: list[dict]) -> str:
    failed = [f"{r['label']} ({', '.join(r['failed'])})" for r in runs if not r["pass"]]
    return (f"{len(runs) - len(failed)} of {len(runs)} runs pass every check"
            + (f"; failed: {'; '.join(failed)}" if failed else ""))


def same_table(a: list[dict], b: list[dict]) -> bool:
    """Two tables agree on everything but the checks that measure the machine (MACHINE_CHECKS)."""
    def key(runs):
        return [{**r, "verdicts": [v for v in r["verdicts"] if v["name"] not in MACHINE_CHECKS],
                 "failed": [n for n in r["failed"] if n not in MACHINE_CHECKS], "pass": None, "exit": None}
                for r in runs]
    return json.dumps(key(a), sort_keys=True) == json.dumps(key(b), sort_keys=True)


def write_table(runs: list[dict], out: Path, meta: dict) -> str:
    """Writes OUT/conformance.md and conformance.json; returns the markdown."""
    slice_note = ("whole scripts" if meta.get("duration") is None
                  else f"the first {meta['duration']:g} s of each script (a short slice, not the whole battery)")
    text = "\n".join([
        f"# Conformance: {meta['engine']}", "",
        f"The battery (docs/conformance-battery.md), {slice_note}; each scene driven by the simulated hand and "
        f"judged by the oracle (harness/oracle.toml). A cell: pass or FAIL (count of violations: worst value). "
        f"Each scene's report, witnesses and viewer page: <scene>/report.md.", "",
        table(runs), "", summary_line(runs), "",
        f"Ran on {meta['workers'] or 'no'} Dask workers{' (serial)' if not meta['workers'] else ''} in "
        f"{meta['wall_seconds']:.0f} s ({meta['chunks_run']} runs computed, {meta['chunks_resumed']} resumed).", ""])
    (out / "conformance.md").write_text(text)
    doc = {"format": "gauss6-conformance", "version": FORMAT_VERSION, **meta, "runs": runs}
    (out / "conformance.json").write_text(json.dumps(doc, indent=2) + "\n")
    return text


def run_engines(engines: dict, out: Path, scenes=None, duration: float | None = None, workers: int | None = 0,
                scheduler: str | None = None, show_progress: bool = True, folders: dict | None = None,
                config: str = "", script: str | None = None, **validate_options) -> tuple[dict, dict]:
    """The battery (or `scenes`) on several engines ({label: engine spec}) as one campaign in OUT
    (engine x scene chunks, so that workers share all of them); each engine's table and scene
    folders in folders[label] (default OUT/label). Returns ({label: runs}, meta)."""
    scenes = [str(s) for s in (scenes or BATTERY_SCENES)]
    out = paths.check_output_dir(out)
    folders = folders or {label: out / label for label in engines}
    chunks, owner = [], []
    for label, spec in engines.items():
        part = make_chunks(spec, scenes, folders[label], config, script, duration, **validate_options)
        chunks += part
        owner += [label] * len(part)
    done = run_campaign(campaign(chunks, {"engines": engines, "scenes": scenes, "duration": duration}), out,
                        workers, scheduler, show_progress)
    for problem in done.recomputed:
        print(f"gauss6 validate: {problem}", file=sys.stderr)
    meta = {"duration": duration, "scenes": scenes, "workers": done.workers, "wall_seconds": done.seconds,
            "chunks_run": done.chunks_run, "chunks_resumed": done.chunks_resumed}
    runs = {label: [r for r, o in zip(done.summary, owner) if o == label] for label in engines}
    for label, spec in engines.items():
        write_table(runs[label], Path(folders[label]), {"engine": spec, "config": config, **meta})
    return runs, meta


def run_suite(engine: str, out: Path, scenes=None, config: str = "", script: str | None = None,
              duration: float | None = None, workers: int | None = 0, scheduler: str | None = None,
              show_progress: bool = True, **validate_options) -> tuple[list[dict], dict]:
    """The battery (or `scenes`) on one engine, as a campaign into OUT, its table OUT/conformance.md
    and each scene's outputs in OUT/<scene>/. Returns (runs, meta)."""
    runs, meta = run_engines({engine: engine}, out, scenes, duration, workers, scheduler, show_progress,
                             {engine: Path(out)}, config, script, **validate_options)
    return runs[engine], meta


def cmd_suite(args) -> int:
    """`gauss6 validate --suite NAME`: the suite's scenes (or --scene's one) as a campaign."""
    scenes = [str(args.scene)] if args.scene else SUITES[args.suite]
    try:
        runs, meta = run_suite(args.engine, args.out, scenes, args.config, args.script, args.duration,
                               args.workers, args.scheduler, not args.quiet, isolation=args.isolation,
                               step_timeout=args.step_timeout, run_timeout=args.run_timeout,
                               thresholds=str(args.thresholds) if args.thresholds else None)
    except CampaignError as e:
        print(f"gauss6 validate: {e}", file=sys.stderr)
        return EXIT_USAGE
    print((Path(args.out) / ("conformance.json" if args.json else "conformance.md")).read_text())
    return exit_status(runs)
