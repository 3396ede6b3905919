"""`gauss6 bench`: run the Google Benchmark suites (benchmarks/) and write out/bench/.

    gauss6 bench [--build DIR] [--out DIR] [--filter REGEX] [--repetitions N] [--min-time S]

Writes into --out (default out/bench/):
  benchmarks.json   Google Benchmark's own JSON (every repetition and its aggregates);
  table.md          per benchmark: median and p99 of single-call latency (the fixtures'
                    p50_ns / p99_ns counters, median over repetitions), the mean per call
                    and the fixture's other counters;
  latency.png/.svg  the same medians and p99 as a bar chart (log scale).

The suites time every call (benchmarks/latency.h), so the median and the 99th
percentile are of single calls, which is what a haptic loop feels; Google
Benchmark's own real_time is a mean and is dragged by rare interruptions.
This module also holds what the gate (gate.py) and the sweeps (sweeps.py) share:
finding the benchmark binary, running it, and reading its JSON.
"""
from __future__ import annotations

import json
import math
import os
import re
import subprocess
from collections import defaultdict
from pathlib import Path

from . import paths

BENCH_TARGET = "gauss6_bench"
BENCH_RELPATH = "benchmarks/gauss6_bench"
# Counters that are latency statistics (nanoseconds), not properties of the workload.
LATENCY_COUNTERS = ("p50_ns", "p99_ns", "max_ns")


def bench_binary(build_dir: Path | None = None) -> Path:
    """The benchmark executable in a build tree (FileNotFoundError naming how to build it)."""
    build = Path(build_dir) if build_dir else paths.build_dir()
    path = build / BENCH_RELPATH
    if not path.exists():
        raise FileNotFoundError(f"{path}: not built; configure with -DGAUSS6_BUILD_BENCHMARKS=ON and run "
                                f"`cmake --build {build} --target {BENCH_TARGET}`")
    return path


def run_benchmarks(binary: Path, out_json: Path, filter_regex: str = "", repetitions: int = 1,
                   min_time: float | None = None, env: dict | None = None, timeout: float | None = None) -> dict:
    """Runs the binary with JSON output to out_json; returns the parsed JSON.

    Raises RuntimeError with the binary's stderr when it fails."""
    out_json.parent.mkdir(parents=True, exist_ok=True)
    cmd = [str(binary), f"--benchmark_out={out_json}", "--benchmark_out_format=json",
           f"--benchmark_repetitions={max(repetitions, 1)}"]
    if filter_regex:
        cmd.append(f"--benchmark_filter={filter_regex}")
    if min_time is not None:
        cmd.append(f"--benchmark_min_time={min_time}")  # seconds (Google Benchmark 1.7: a plain number)
    full_env = dict(os.environ, **(env or {}))
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=full_env,
                          timeout=timeout)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-4000:]}")
    # Google Benchmark exits 0 and writes an empty file when the filter matches no benchmark.
    text = out_json.read_text() if out_json.exists() else ""
    if not text.strip():
        raise RuntimeError(f"{binary.name}: no benchmark matches the filter {filter_regex!r}"
                           if filter_regex else f"{' '.join(cmd)} wrote no results:\n{proc.stderr[-4000:]}")
    doc = json.loads(text)
    errors = [b["name"] for b in doc.get("benchmarks", []) if b.get("error_occurred")]
    if errors:
        doc.setdefault("errors", errors)
    return doc


def base_name(entry: dict) -> str:
    """The benchmark's name without Google Benchmark's suffixes (/iterations:N, /manual_time)."""
    name = entry.get("run_name", entry["name"])
    name = re.sub(r"/iterations:\d+", "", name)
    return re.sub(r"/(manual|real)_time$", "", name)


def samples(doc: dict) -> dict[str, list[dict]]:
    """Per benchmark (base name): its repetitions (run_type "iteration"), in run order.
    Benchmarks that reported an error are left out."""
    out: dict[str, list[dict]] = defaultdict(list)
    for b in doc.get("benchmarks", []):
        if b.get("run_type", "iteration") == "iteration" and not b.get("error_occurred"):
            out[base_name(b)].append(b)
    return dict(out)


def to_ns(entry: dict, field: str = "real_time") -> float:
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[entry.get("time_unit", "ns")]
    return float(entry[field]) * scale


def median(xs: list[float]) -> float:
    s = sorted(xs)
    n = len(s)
    if not n:
        return math.nan
    return s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2])


def summarize(doc: dict) -> list[dict]:
    """One row per benchmark: median over repetitions of p50_ns, p99_ns, max_ns and the mean
    per call (ns), with the other counters (medians too)."""
    rows = []
    for name, reps in samples(doc).items():
        row = {"name": name, "repetitions": len(reps), "iterations": int(median([r["iterations"] for r in reps])),
               "mean_ns": median([to_ns(r) for r in reps])}
        counters = sorted({k for r in reps for k, v in r.items() if isinstance(v, (int, float)) and k not in (
            "family_index", "per_family_instance_index", "repetitions", "repetition_index", "threads",
            "iterations", "real_time", "cpu_time")})
        for k in counters:
            row[k] = median([float(r[k]) for r in reps if k in r])
        rows.append(row)
    return rows


def _fmt_ns(ns: float) -> str:
    if not math.isfinite(ns):
        return "-"
    for unit, scale in (("s", 1e9), ("ms", 1e6), ("us", 1e3)):
        if ns >= scale:
            return f"{ns / scale:.3g} {unit}"
    return f"{ns:.3g} ns"


def format_table(rows: list[dict], context: dict | None = None) -> str:
    lines = []
    if context:
        lines.append(f"Host {context.get('host_name', '?')}, {context.get('num_cpus', '?')} CPUs, "
                     f"load average {context.get('load_avg', '?')}, {context.get('date', '')}.")
        lines.append("")
    lines += ["| benchmark | median (p50) | p99 | max | mean | calls | other counters (median over repetitions) |",
              "|---|---|---|---|---|---|---|"]
    for r in rows:
        other = ", ".join(f"{k} {r[k]:.4g}" for k in r if k not in (
            "name", "repetitions", "iterations", "mean_ns") + LATENCY_COUNTERS)
        lines.append(f"| {r['name']} | {_fmt_ns(r.get('p50_ns', math.nan))} | {_fmt_ns(r.get('p99_ns', math.nan))} | "
                     f"{_fmt_ns(r.get('max_ns', math.nan))} | {_fmt_ns(r['mean_ns'])} | {r['iterations']} x "
                     f"{r['repetitions']} | {other} |")
    return "\n".join(lines)


def plot(rows: list[dict], path_stem: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if "p50_ns" in r]
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(9, 0.28 * len(rows) + 1.5))
    y = range(len(rows))
    ax.barh(list(y), [r["p99_ns"] for r in rows], color="C1", alpha=0.5, label="p99")
    ax.barh(list(y), [r["p50_ns"] for r in rows], color="C0", label="median")
    ax.set_yticks(list(y))
    ax.set_yticklabels([r["name"] for r in rows], fontsize=6)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("latency of one call (ns)")
    ax.set_title("gauss6 benchmarks: median and p99 per call")
    ax.grid(True, axis="x", which="major", alpha=0.3)
    ax.legend(loc="lower right")
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(path_stem.with_suffix("." + ext), dpi=120)
    plt.close(fig)


def run(build_dir: Path | None, out_dir: Path, filter_regex: str = "", repetitions: int = 3,
        min_time: float | None = None) -> list[dict]:
    doc = run_benchmarks(bench_binary(build_dir), out_dir / "benchmarks.json", filter_regex, repetitions, min_time)
    rows = summarize(doc)
    (out_dir / "table.md").write_text(format_table(rows, doc.get("context")) + "\n")
    plot(rows, out_dir / "latency")
    return rows
