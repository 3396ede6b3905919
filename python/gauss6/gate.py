"""`gauss6 gate --base REV [--json]`: the regression gate on speed, accuracy and properties.

    gauss6 gate --base REV [--json] [--config benchmarks/gate.toml]
                          [--cache-dir DIR] [--work-build DIR] [--base-build DIR]
                          [--filter REGEX] [--rounds N] [--repetitions N] [--no-accuracy]

1. Build. REV is exported (`git archive`, read-only: the repository's state is
   untouched) into <cache>/<sha>/src and built in <cache>/<sha>/build; the working
   tree is built in --work-build (default <cache>/work-build). Only the targets of
   gate.toml [build] are built. With overlay_benchmarks the working tree's
   benchmarks/ is compiled in both, so both sides run the same benchmark code.
   --base-build / --work-build given with an existing build skip the build.
2. Speed. The suites run interleaved, base, work, base, work, ... ([speed] rounds,
   each with Google Benchmark repetitions), so that drifts of the machine hit both
   sides alike. Per benchmark: ratio = median(work) / median(base) of the
   per-repetition statistic (p50_ns: median latency of single calls), and the
   two-sided Mann-Whitney U-test of the two sample sets (Google Benchmark's
   compare.py test, from /usr/share/benchmark/gbench when installed, else scipy).
   Slower: ratio > 1 + max_slowdown and p < alpha.
3. Counts. The fixed workloads of gauss6_count (benchmarks/count_main.cpp) run once a
   side under callgrind ([count]); per workload, instructions per call. Unlike times,
   these do not depend on the machine's load (the same binary and data give the same
   count to the instruction), so no test of significance is needed: more
   instructions: ratio work / base > 1 + max_increase.
4. Accuracy and properties. Each [[accuracy.check]] runs `python -m gauss6.cli ARGS`
   with each tree's own package and extension and reads its JSON; the error metrics
   of [accuracy.metrics] are compared (work > base (1 + rel) + abs fails) and the
   [properties] are checked on the working tree (and on the benchmark counters).

Exit status: 0 pass, 1 the gate failed (table says why), 2 the gate could not run
(build error, missing tool). Thresholds live in benchmarks/gate.toml only.
"""
from __future__ import annotations

import argparse
import filecmp
import json
import math
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path

from . import bench, paths

DEFAULT_CONFIG = paths.REPO_ROOT / "benchmarks" / "gate.toml"
COUNT_RELPATH = "benchmarks/gauss6_count"    # the fixed workloads counted under callgrind
GBENCH_DIR = Path("/usr/share/benchmark")  # Debian's libbenchmark-tools (compare.py and gbench)


class GateError(Exception):
    """The gate could not run (exit 2): a build failed, a tool is missing, a bad config."""


def load_config(path: Path) -> dict:
    try:
        cfg = tomllib.loads(Path(path).read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise GateError(f"{path}: {e}") from e
    for section in ("build", "speed", "accuracy", "properties"):
        if section not in cfg:
            raise GateError(f"{path}: missing [{section}]")
    return cfg


# --------------------------------------------------------------------------------------
# Statistics
# --------------------------------------------------------------------------------------

def u_test(base: list[float], work: list[float]) -> float | None:
    """Two-sided Mann-Whitney U p-value, or None with fewer than 2 samples a side."""
    if min(len(base), len(work)) < 2:
        return None
    if (GBENCH_DIR / "gbench" / "report.py").exists():
        sys.path.insert(0, str(GBENCH_DIR))
        try:
            from gbench import report  # compare.py's own test
            _, _, p = report.calc_utest([base, work], [base, work])
            return p
        except ImportError:
            pass
        finally:
            sys.path.remove(str(GBENCH_DIR))
    from scipy.stats import mannwhitneyu
    return float(mannwhitneyu(base, work, alternative="two-sided").pvalue)


def metric_samples(doc_samples: dict[str, list[dict]], metric: str) -> dict[str, list[float]]:
    """Per benchmark, the per-repetition values of the metric (ns); real_time without it."""
    out = {}
    for name, reps in doc_samples.items():
        out[name] = [float(r[metric]) if metric in r else bench.to_ns(r) for r in reps]
    return out


@dataclass
class SpeedRow:
    name: str
    base_ns: float
    work_ns: float
    ratio: float
    p_value: float | None
    base_p99_ns: float
    work_p99_ns: float
    samples: tuple[int, int]
    verdict: str  # "slower" (fails), "faster", "same", "not significant", "new", "gone"


def compare_speed(base: dict[str, list[dict]], work: dict[str, list[dict]], speed_cfg: dict) -> list[SpeedRow]:
    """Compares per-benchmark repetitions (bench.samples() of each side, all rounds merged)."""
    metric = speed_cfg.get("metric", "p50_ns")
    limit = 1.0 + float(speed_cfg["max_slowdown"])
    alpha = float(speed_cfg["alpha"])
    min_samples = int(speed_cfg.get("min_samples", 4))
    b, w = metric_samples(base, metric), metric_samples(work, metric)
    b99 = metric_samples(base, "p99_ns")
    w99 = metric_samples(work, "p99_ns")
    rows = []
    for name in sorted(set(b) | set(w)):
        if name not in w or name not in b:
            rows.append(SpeedRow(name, bench.median(b.get(name, [])), bench.median(w.get(name, [])), math.nan, None,
                                 math.nan, math.nan, (len(b.get(name, [])), len(w.get(name, []))),
                                 "gone" if name not in w else "new"))
            continue
        mb, mw = bench.median(b[name]), bench.median(w[name])
        ratio = mw / mb if mb > 0 else math.inf
        p = u_test(b[name], w[name])
        enough = min(len(b[name]), len(w[name])) >= min_samples
        significant = enough and p is not None and p < alpha
        if ratio > limit and significant:
            verdict = "slower"
        elif ratio < 1 / limit and significant:
            verdict = "faster"
        elif ratio > limit or ratio < 1 / limit:
            verdict = "not significant"
        else:
            verdict = "same"
        rows.append(SpeedRow(name, mb, mw, ratio, p, bench.median(b99[name]), bench.median(w99[name]),
                             (len(b[name]), len(w[name])), verdict))
    return rows


# --------------------------------------------------------------------------------------
# Accuracy and properties
# --------------------------------------------------------------------------------------

def flatten(doc, prefix: str = "") -> dict[str, object]:
    """JSON to {path: leaf}; list items are keyed by their "name" (else their index)."""
    out: dict[str, object] = {}
    if isinstance(doc, dict):
        for k, v in doc.items():
            out.update(flatten(v, f"{prefix}/{k}" if prefix else str(k)))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            key = v.get("name", i) if isinstance(v, dict) else i
            out.update(flatten(v, f"{prefix}/{key}"))
    else:
        out[prefix] = doc
    return out


@dataclass
class AccuracyRow:
    path: str
    base: object
    work: object
    limit: object
    verdict: str  # "ok", "less accurate" (fails), "violated" (fails), "new"


def compare_accuracy(base: dict[str, object], work: dict[str, object], cfg: dict) -> list[AccuracyRow]:
    """base, work: flattened results (path -> value). Error metrics by their last path
    component ([accuracy.metrics]); properties ([properties]) checked on work."""
    metrics = cfg["accuracy"].get("metrics", {})
    zero = set(cfg["properties"].get("must_be_zero", []))
    true = set(cfg["properties"].get("must_be_true", []))
    rows = []
    for path, w in sorted(work.items()):
        leaf = path.rsplit("/", 1)[-1]
        b = base.get(path)
        if leaf in zero:
            rows.append(AccuracyRow(path, b, w, 0, "ok" if w == 0 else "violated"))
        elif leaf in true:
            rows.append(AccuracyRow(path, b, w, True, "ok" if w is True else "violated"))
        elif leaf in metrics and isinstance(w, (int, float)):
            if not isinstance(b, (int, float)):
                rows.append(AccuracyRow(path, b, w, None, "new"))
                continue
            tol = metrics[leaf]
            limit = b * (1 + float(tol.get("rel", 0))) + float(tol.get("abs", 0))
            rows.append(AccuracyRow(path, b, w, limit, "ok" if w <= limit else "less accurate"))
    return rows


def bench_properties(work: dict[str, list[dict]], cfg: dict) -> dict[str, object]:
    """The benchmark counters named as properties, flattened like a check's JSON."""
    zero = set(cfg["properties"].get("must_be_zero", []))
    out = {}
    for name, reps in work.items():
        for k in zero:
            vals = [r[k] for r in reps if k in r]
            if vals:
                out[f"bench/{name}/{k}"] = max(vals)
    return out


# --------------------------------------------------------------------------------------
# Trees and builds
# --------------------------------------------------------------------------------------

def _run(cmd: list[str], what: str, cwd: Path | None = None, env: dict | None = None, log: Path | None = None):
    proc = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if log:
        log.write_text(proc.stdout)
    if proc.returncode != 0:
        raise GateError(f"{what} failed ({' '.join(map(str, cmd))}):\n{proc.stdout[-3000:]}")
    return proc.stdout


def resolve(rev: str, repo: Path) -> str:
    out = subprocess.run(["git", "-C", str(repo), "rev-parse", "--verify", f"{rev}^{{commit}}"],
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise GateError(f"{rev}: not a revision of {repo}: {out.stderr.strip()}")
    return out.stdout.strip()


def export_revision(sha: str, repo: Path, dest: Path) -> None:
    """The tree of sha in dest (git archive: reads the repository, changes nothing)."""
    marker = dest / ".gauss6-gate-revision"
    if marker.exists() and marker.read_text().strip() == sha:
        return
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    proc = subprocess.Popen(["git", "-C", str(repo), "archive", "--format=tar", sha], stdout=subprocess.PIPE)
    with tarfile.open(fileobj=proc.stdout, mode="r|") as tar:
        if hasattr(tarfile, "data_filter"):  # Python >= 3.11.4: refuse links and paths out of dest
            tar.extractall(dest, filter="data")
        else:
            tar.extractall(dest)
    if proc.wait() != 0:
        raise GateError(f"git archive {sha} failed")
    marker.write_text(sha + "\n")


def overlay(src: Path, dest: Path) -> None:
    """Copies src/ over dest/ (files that differ only: unchanged files keep their times)."""
    for f in src.rglob("*"):
        if f.is_file():
            t = dest / f.relative_to(src)
            if not t.exists() or not filecmp.cmp(f, t, shallow=False):
                t.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(f, t)


def build(source: Path, build_dir: Path, cfg: dict, python: str) -> None:
    """Configures (once) and builds the [build] targets of one tree."""
    build_dir.mkdir(parents=True, exist_ok=True)
    if not (build_dir / "CMakeCache.txt").exists():
        pybind = subprocess.run([python, "-m", "pybind11", "--cmakedir"], capture_output=True, text=True)
        extra = [f"-DPython_EXECUTABLE={python}"]
        if pybind.returncode == 0:
            extra.append(f"-Dpybind11_DIR={pybind.stdout.strip()}")
        _run(["cmake", "-S", str(source), "-B", str(build_dir), *cfg["build"]["cmake_args"], *extra],
             f"configure {source}", log=build_dir / "gate-configure.log")
    _run(["cmake", "--build", str(build_dir), "-j", str(cfg["build"].get("jobs", 2)), "--target",
          *cfg["build"]["targets"]], f"build {source}", log=build_dir / "gate-build.log")


def build_with_fallback(source: Path, build_dir: Path, cfg: dict, python: str, sha: str, repo: Path, log=print
                        ) -> list[str]:
    """build() of an overlaid base tree; a benchmark file of the working tree that does not
    compile against the base (it uses a newer API) goes back to the base's own version (or
    away, if the base has none), and the build is retried. Returns those files: their
    benchmarks run different code on the two sides (the report says so)."""
    fallbacks: list[str] = []
    cfg = {**cfg, "build": dict(cfg["build"])}
    for _ in range(16):
        try:
            build(source, build_dir, cfg, python)
            return fallbacks
        except GateError as e:
            lines = str(e).splitlines() + _last_log(build_dir)
            if any(line.startswith("FAILED: ") and "gauss6_count.dir/" in line for line in lines) \
                    and "gauss6_count" in cfg["build"]["targets"]:
                # The instruction-count workloads do not compile against the base: no counts
                # (run_gate says so), the rest of the gate as usual.
                cfg["build"]["targets"] = [t for t in cfg["build"]["targets"] if t != "gauss6_count"]
                log("gate: benchmarks/count_main.cpp does not compile against the base: no instruction counts")
                continue
            failed = sorted({line.split("gauss6_bench.dir/", 1)[1].rsplit(".o", 1)[0]
                             for line in lines
                             if line.startswith("FAILED: ") and "gauss6_bench.dir/" in line})
            failed = [f for f in failed if f not in fallbacks]
            if not failed:
                raise
            for f in failed:
                target = source / "benchmarks" / f
                own = subprocess.run(["git", "-C", str(repo), "show", f"{sha}:benchmarks/{f}"], capture_output=True)
                if own.returncode == 0:
                    target.write_bytes(own.stdout)
                else:
                    target.unlink()
                log(f"gate: benchmarks/{f} does not compile against the base: the base uses "
                    f"{'its own version' if own.returncode == 0 else 'none'}")
                fallbacks.append(f)
    raise GateError("too many benchmark files fail to compile against the base")


def _last_log(build_dir: Path) -> list[str]:
    log = build_dir / "gate-build.log"
    return log.read_text().splitlines() if log.exists() else []


@dataclass
class Side:
    label: str          # "base" or "work"
    source: Path        # the tree (its python/ package is used for the accuracy checks)
    build: Path


def run_speed(sides: tuple[Side, Side], cfg: dict, out_dir: Path, data_root: Path, log=print
              ) -> tuple[dict[str, list[dict]], dict[str, list[dict]]]:
    """Interleaved runs; returns (base samples, work samples), all rounds merged."""
    sp = cfg["speed"]
    merged: dict[str, dict[str, list[dict]]] = {"base": {}, "work": {}}
    for r in range(int(sp["rounds"])):
        for side in sides:
            log(f"gate: speed round {r + 1}/{sp['rounds']}: {side.label}")
            doc = bench.run_benchmarks(bench.bench_binary(side.build), out_dir / f"{side.label}-round{r}.json",
                                       sp.get("filter", ""), int(sp["repetitions"]), sp.get("min_time"),
                                       env={"GAUSS6_BENCH_DATA_ROOT": str(data_root)})
            for name, reps in bench.samples(doc).items():
                merged[side.label].setdefault(name, []).extend(reps)
    return merged["base"], merged["work"]


def count_binary(build_dir: Path) -> Path:
    path = Path(build_dir) / COUNT_RELPATH
    if not path.exists():
        raise GateError(f"{path}: not built (needs valgrind's valgrind/callgrind.h at configure time: "
                        "tools/setup.sh installs valgrind; then `cmake --build BUILD --target gauss6_count`)")
    return path


def read_callgrind_dumps(out_file: Path) -> dict[str, int]:
    """Instructions per client-request dump of a callgrind run: {dump name: Ir total}.

    gauss6_count dumps after each workload (CALLGRIND_DUMP_STATS_AT(name)): files
    OUT.1, OUT.2, ... each with a line "desc: Trigger: Client Request: <name>" and
    "totals: <Ir>"."""
    out: dict[str, int] = {}
    for f in sorted(out_file.parent.glob(out_file.name + ".*")):
        name = total = None
        for line in f.read_text(errors="replace").splitlines():
            if line.startswith("desc: Trigger: Client Request: "):
                name = line.split(": ", 3)[3].strip()
            elif line.startswith("totals:"):
                total = int(line.split()[1])
        if name is not None and total is not None:
            out[name] = total
    return out


def run_counts(side: Side, cfg: dict, out_dir: Path, data_root: Path, plant: float = 0.0,
               log=print) -> dict[str, float]:
    """Instructions per call of each gauss6_count workload, one callgrind run of the side's binary."""
    cc = cfg.get("count", {})
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        raise GateError("valgrind not found: the gate's instruction counts need it (tools/setup.sh installs it; "
                        "--no-count skips the counts)")
    run_dir = out_dir / f"count-{side.label}"
    shutil.rmtree(run_dir, ignore_errors=True)
    run_dir.mkdir(parents=True)
    cmd = [valgrind, "--tool=callgrind", f"--callgrind-out-file={run_dir / 'callgrind.out'}",
           str(count_binary(side.build)), "--calls", str(run_dir / "calls.json")]
    if cc.get("filter"):
        cmd += ["--filter", cc["filter"]]
    if plant:
        cmd += ["--plant", str(plant)]
    log(f"gate: instruction counts (callgrind): {side.label}")
    proc = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, GAUSS6_BENCH_DATA_ROOT=str(data_root)),
                          timeout=float(cc.get("timeout", 1800)))
    if proc.returncode != 0:
        raise GateError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    calls = json.loads((run_dir / "calls.json").read_text())
    totals = read_callgrind_dumps(run_dir / "callgrind.out")
    missing = sorted(set(calls) - set(totals))
    if missing:
        raise GateError(f"{run_dir}: no callgrind dump for {', '.join(missing)}")
    return {name: totals[name] / n for name, n in calls.items()}


@dataclass
class CountRow:
    name: str
    base: float | None   # instructions per call
    work: float | None
    ratio: float | None
    verdict: str  # "more instructions" (fails), "fewer", "same", "new", "gone"


def compare_counts(base: dict[str, float], work: dict[str, float], count_cfg: dict) -> list[CountRow]:
    limit = float(count_cfg["max_increase"])
    rows = []
    for name in sorted(set(base) | set(work)):
        if name not in base or name not in work:
            rows.append(CountRow(name, base.get(name), work.get(name), None, "new" if name in work else "gone"))
            continue
        ratio = work[name] / base[name] if base[name] else math.inf
        verdict = "more instructions" if ratio > 1 + limit else "fewer" if ratio < 1 - limit else "same"
        rows.append(CountRow(name, base[name], work[name], ratio, verdict))
    return rows


def run_accuracy(side: Side, cfg: dict, log=print) -> dict[str, object]:
    """Every [[accuracy.check]] through the side's own package; flattened results."""
    env = dict(os.environ, PYTHONPATH=str(side.source / "python"), GAUSS6_BUILD_DIR=str(side.build))
    out: dict[str, object] = {}
    for check in cfg["accuracy"].get("check", []):
        log(f"gate: accuracy {check['name']}: {side.label}")
        proc = subprocess.run([sys.executable, "-m", "gauss6.cli", *check["args"]], cwd=side.source, env=env,
                              capture_output=True, text=True)
        try:
            doc = json.loads(proc.stdout.strip().splitlines()[-1]) if proc.stdout.strip() else None
        except json.JSONDecodeError:
            doc = None
        if doc is None or proc.returncode not in (0, 1):  # 1: the check found a violation (still JSON)
            out[f"{check['name']}/runs"] = False
            out[f"{check['name']}/error"] = (proc.stderr or proc.stdout)[-500:]
            continue
        out.update(flatten(doc, check["name"]))
    return out


# --------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------

def _ns(x: float | None) -> str:
    if x is None or not math.isfinite(x):
        return "-"
    return f"{x / 1e6:.2f} ms" if x >= 1e6 else f"{x / 1e3:.2f} us" if x >= 1e3 else f"{x:.0f} ns"


def format_report(result: dict) -> str:
    lines = [f"gauss6 gate: base {result['base']} vs working tree ({result['metric']}, "
             f"threshold +{100 * result['max_slowdown']:.0f}% at p < {result['alpha']})", ""]
    lines.append(f"{'benchmark':<46}{'base':>11}{'work':>11}{'ratio':>8}{'p':>8}{'p99 base':>11}{'p99 work':>11}"
                 f"  verdict")
    for r in result["speed"]:
        p = "-" if r["p_value"] is None else f"{r['p_value']:.3f}"
        ratio = "-" if r["ratio"] is None or not math.isfinite(r["ratio"]) else f"{r['ratio']:.3f}"
        lines.append(f"{r['name'][:45]:<46}{_ns(r['base_ns']):>11}{_ns(r['work_ns']):>11}{ratio:>8}{p:>8}"
                     f"{_ns(r['base_p99_ns']):>11}{_ns(r['work_p99_ns']):>11}  {r['verdict'].upper() if r['verdict'] == 'slower' else r['verdict']}")
    if result.get("count"):
        lines += ["", f"{'instructions per call (callgrind)':<46}{'base':>14}{'work':>14}{'ratio':>8}  verdict"
                  f" (threshold +{100 * result['max_instruction_increase']:.0f}%)"]
        for r in result["count"]:
            def n(v):
                return "-" if v is None else f"{v:,.0f}"
            ratio = "-" if r["ratio"] is None else f"{r['ratio']:.4f}"
            verdict = r["verdict"].upper() if r["verdict"] == "more instructions" else r["verdict"]
            lines.append(f"{r['name'][:45]:<46}{n(r['base']):>14}{n(r['work']):>14}{ratio:>8}  {verdict}")
    if result["accuracy"]:
        lines += ["", f"{'accuracy / property':<66}{'base':>12}{'work':>12}{'limit':>12}  verdict"]
        for r in result["accuracy"]:
            def f(v):
                return f"{v:.3g}" if isinstance(v, float) else str(v)
            shown = r["verdict"] != "ok" or not r["path"].startswith("bench/")
            if shown:
                lines.append(f"{r['path'][:65]:<66}{f(r['base']):>12}{f(r['work']):>12}{f(r['limit']):>12}  "
                             f"{r['verdict'].upper() if r['verdict'] in ('less accurate', 'violated') else r['verdict']}")
    if result.get("benchmark_files_differing"):
        lines += ["", "note: these benchmark files do not compile against the base, which ran its own version: "
                  + ", ".join(result["benchmark_files_differing"])]
    if result.get("count_note"):
        lines += ["", "note: " + result["count_note"]]
    lines += ["", "FAILED: " + "; ".join(result["failures"]) if result["failures"] else "PASSED"]
    return "\n".join(lines)


def decide(speed: list[SpeedRow], accuracy: list[AccuracyRow], cfg: dict, base_label: str,
           count: list[CountRow] | None = None) -> dict:
    failures = [f"{r.name} slower x{r.ratio:.3f} (p = {r.p_value:.3g})" for r in speed if r.verdict == "slower"]
    failures += [f"{r.name} more instructions per call x{r.ratio:.4f}" for r in count or []
                 if r.verdict == "more instructions"]
    failures += [f"{r.path} less accurate ({r.work!r} > {r.limit!r})" for r in accuracy if r.verdict == "less accurate"]
    failures += [f"{r.path} violated ({r.work!r})" for r in accuracy if r.verdict == "violated"]
    sp = cfg["speed"]
    return {"base": base_label, "metric": sp.get("metric", "p50_ns"), "max_slowdown": float(sp["max_slowdown"]),
            "alpha": float(sp["alpha"]), "passed": not failures, "failures": failures,
            "speed": [asdict(r) for r in speed], "accuracy": [asdict(r) for r in accuracy],
            "count": [asdict(r) for r in count or []],
            "max_instruction_increase": float(cfg.get("count", {}).get("max_increase", math.nan))}


def run_gate(args: argparse.Namespace, log=print) -> dict:
    cfg = load_config(args.config)
    sp = cfg["speed"]
    if args.filter is not None:
        sp["filter"] = args.filter
    if args.rounds is not None:
        sp["rounds"] = args.rounds
    if args.repetitions is not None:
        sp["repetitions"] = args.repetitions
    if args.min_time is not None:
        sp["min_time"] = args.min_time
    repo = paths.REPO_ROOT
    cache = Path(args.cache_dir) if args.cache_dir else Path(tempfile.mkdtemp(prefix="gauss6-gate-"))
    python = sys.executable
    # The base tree.
    fallbacks: list[str] = []
    if args.base_build and bench_exists(args.base_build):
        base = Side("base", Path(args.base_source or repo), Path(args.base_build))
        base_label = args.base or "prebuilt"
    else:
        if not args.base:
            raise GateError("--base REV is required (or --base-build with a built tree)")
        sha = resolve(args.base, repo)
        src = cache / sha / "src"
        log(f"gate: exporting {args.base} ({sha[:12]}) to {src}")
        export_revision(sha, repo, src)
        if cfg["build"].get("overlay_benchmarks", True):
            overlay(repo / "benchmarks", src / "benchmarks")
        base = Side("base", src, Path(args.base_build) if args.base_build else cache / sha / "build")
        log(f"gate: building base in {base.build}")
        fallbacks = build_with_fallback(src, base.build, cfg, python, sha, repo, log)
        base_label = f"{args.base} ({sha[:12]})"
    # The working tree.
    work = Side("work", repo, Path(args.work_build) if args.work_build else cache / "work-build")
    if not (args.work_build and args.no_build_work):
        log(f"gate: building the working tree in {work.build}")
        build(repo, work.build, cfg, python)
    out_dir = cache / "runs"
    base_s, work_s = run_speed((base, work), cfg, out_dir, repo, log)
    speed = compare_speed(base_s, work_s, sp)
    count, count_note = None, ""
    if cfg.get("count", {}).get("enabled", False) and not args.no_count:
        if not (base.build / COUNT_RELPATH).exists() and (work.build / COUNT_RELPATH).exists():
            # A base older than the counts whose own benchmarks/ ran (overlay fallback).
            count_note = f"no instruction counts: the base build has no {COUNT_RELPATH}"
        else:
            count = compare_counts(run_counts(base, cfg, out_dir, repo, log=log),
                                   run_counts(work, cfg, out_dir, repo, log=log), cfg["count"])
    accuracy_base, accuracy_work = {}, bench_properties(work_s, cfg)
    if not args.no_accuracy:
        accuracy_base.update(run_accuracy(base, cfg, log))
        accuracy_work.update(run_accuracy(work, cfg, log))
    accuracy = compare_accuracy(accuracy_base, accuracy_work, cfg)
    for path, v in accuracy_work.items():  # a check that could not run in the working tree fails the gate
        if path.endswith("/runs") and v is False:
            accuracy.append(AccuracyRow(path, accuracy_base.get(path), False, True, "violated"))
    result = decide(speed, accuracy, cfg, base_label, count)
    result["runs_dir"] = str(out_dir)
    result["benchmark_files_differing"] = fallbacks
    result["count_note"] = count_note
    return result


def finite(x):
    """NaN and infinities as null: strict JSON."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite(v) for v in x]
    return x


def bench_exists(build_dir) -> bool:
    return (Path(build_dir) / bench.BENCH_RELPATH).exists()
