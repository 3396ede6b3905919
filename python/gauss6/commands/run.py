"""`gauss6 run SCENE [--script NAME|FILE] --out DIR [--threaded]`: any scene run and reported as
the paper's are (gauss6.run: the trace, the figure, the certification, the viewer page, the report)."""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from ..cli_args import add_budget_arguments, input_file, output_dir, run_seconds


def run(args: argparse.Namespace) -> int:
    from .. import LoadError
    from ..run import failures, run_scene, script_path, write_report

    scene, out = Path(args.scene), Path(args.out)
    start = time.monotonic()
    try:
        script = script_path(args.script) if args.script else None
        if not scene.is_file():
            raise ValueError(f"{scene}: no such scene file")
        summary, details = run_scene(scene, out, name=args.name, script=script, threaded=args.threaded,
                                     duration=args.duration, show_progress=not args.quiet,
                                     check_poses=not args.no_certify, budget_seconds=args.budget_cpu or 0.0,
                                     budget_units=args.budget_units)
    except (LoadError, ValueError) as e:
        print(f"gauss6 run: error: {e}", file=sys.stderr)
        return 2
    name = args.name or scene.stem
    (out / "summary.json").write_text(json.dumps({name: summary}, indent=2) + "\n")
    (out / "details.json").write_text(json.dumps({name: details}, indent=2) + "\n")
    write_report(out, name, summary, details, time.monotonic() - start)
    print(json.dumps(summary, indent=2))
    problems = failures(name, summary, details)
    for p in problems:
        print(f"gauss6 run: error: {p}", file=sys.stderr)
    print(f"written to {out}/ (report.md, summary.json, figure_{name}.png, view_{name}.html, certify_{name}.md, "
          f"{name}.g6trace)")
    return 1 if problems else 0


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("run", help="run a scene with a hand script: trace, figure, certification, "
                                          "viewer page and report (as `gauss6 reproduce` runs the paper's)")
    p.add_argument("scene", type=input_file("scene"), help="the scene's TOML file (docs/scene-format.md)")
    p.add_argument("--script", help="the hand script: a shipped one's name (bunny, peg_in_hole) or a JSON file "
                                    "(default: the scene's [device] script)")
    p.add_argument("--out", required=True, type=output_dir, help="output directory")
    p.add_argument("--threaded", action="store_true", help="real threads and the wall clock (default: lockstep)")
    p.add_argument("--duration", type=run_seconds, default=-1.0,
                   help="run only the first S seconds of the script (default: all of it)")
    p.add_argument("--name", help="the run's name in the output files (default: the scene file's stem)")
    p.add_argument("--no-certify", action="store_true",
                   help="skip the exact certification (slow on large scenes); the report says so")
    add_budget_arguments(p)
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)
    return p
