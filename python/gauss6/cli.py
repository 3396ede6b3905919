"""The `gauss6` command: one entry point for scenes, datasets, cross-checks and reproduction.

    gauss6 --version
    gauss6 scene info SCENE [--json]
    gauss6 datasets generate | check
    gauss6 crosscheck qp [--family NAME] [--json] [--seeded N [--seed S] [--workers N] [--scheduler ADDR] [--out DIR]]
    gauss6 ccd queries FILE.csv|DIR [--kind vf|ee] [--impl optimized|reference] [--json]
    gauss6 crosscheck ccd [--set NAME] [--json] [--peers] [--seeded N [--seed S] [--family F] [--workers N] ...]
    gauss6 report qp --out DIR
    gauss6 report peers [--out DIR] [--repeats N] [--ccd-only | --qp-only]
    gauss6 run SCENE [--script NAME|FILE] --out DIR [--threaded]
    gauss6 reproduce peg|bunny|all --out DIR [--threaded]
    gauss6 reproduce engines --out DIR [--slice S]
    gauss6 trace export TRACE [--csv DIR] [--hapi FILE]
    gauss6 trace import FILE --format hapi|csv --out TRACE
    gauss6 view TRACE [TRACE ...] [--scene SCENE] [--out page.html]
    gauss6 device list [--json]
    gauss6 bench [--build DIR] [--out DIR] [--filter REGEX]
    gauss6 sweep [--build DIR] [--out DIR]
    gauss6 gate --base REV [--json]
    gauss6 rate [--rate-hz 10000] [--duration 60] --out DIR

Every subcommand exits non-zero on a failed check, with a message naming the problem.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import paths

SCENES = {
    "peg": paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml",
    "bunny": paths.DATASETS_DIR / "scenes" / "bunnies.toml",
}


# ---------------------------------------------------------------------------------------------
# Argument types every subcommand shares: a bad value is refused at parse time (exit 2, the
# option named), never turned into a traceback, a hang or a run without end.

MAX_RUN_SECONDS = 86400.0  # the longest run a command drives or replays: one day of run time


def _arg_error(message: str) -> argparse.ArgumentTypeError:
    return argparse.ArgumentTypeError(message)


def run_seconds(text: str) -> float:
    """--duration: a finite number of seconds in (0, MAX_RUN_SECONDS]."""
    try:
        value = float(text)
    except ValueError:
        raise _arg_error(f"not a number of seconds: {text!r}") from None
    if not 0 < value <= MAX_RUN_SECONDS:  # NaN fails too
        raise _arg_error(f"{text}: a duration must be a finite number of seconds in (0, {MAX_RUN_SECONDS:g}]")
    return value


def check_run_span(seconds: float, what: str) -> None:
    """A recording or hand script's span, bounded as --duration is (ValueError naming it)."""
    if not seconds <= MAX_RUN_SECONDS:
        raise ValueError(f"{what} spans {seconds:g} s, more than a run can last ({MAX_RUN_SECONDS:g} s); "
                         "give --duration to run a part of it")


def _integer(text: str, lo: int, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise _arg_error(f"not an integer: {text!r}") from None
    if value < lo:
        raise _arg_error(f"{text}: {what} must be an integer >= {lo}")
    return value


def positive_int(text: str) -> int:
    """A count that must be at least 1 (--max-frames, --chunk-size, --seeded)."""
    return _integer(text, 1, "the value")


def nonnegative_int(text: str) -> int:
    """A count that may be 0 (--workers: 0 runs serially)."""
    return _integer(text, 0, "the value")


def _utf8(text: str) -> str:
    """A path given on the command line whose bytes are not UTF-8 (legal on Linux) reaches
    Python with surrogate escapes, which the C++ core cannot take: refused, named."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise _arg_error(f"{text.encode('utf-8', 'surrogateescape')!r}: the path holds bytes that are not "
                         "UTF-8; rename the file") from None
    return text


def input_file(what: str, directory_ok: bool = False):
    """An argparse type: an existing regular file (paths.check_input_file: not a FIFO, a device
    or a directory; a directory too when directory_ok), its path UTF-8."""
    def check(text: str) -> str:
        try:
            if not (directory_ok and Path(_utf8(text)).is_dir()):
                paths.check_input_file(_utf8(text), what)
        except paths.PathError as e:
            raise _arg_error(str(e)) from None
        return text
    check.__name__ = what  # argparse names the type in "invalid <name> value"
    return check


def _writable(text: str, want_dir: bool, what: str) -> str:
    problem = paths.output_problem(_utf8(text), want_dir, what)
    if problem:
        raise _arg_error(problem)
    return text


def output_dir(text: str) -> str:
    """An argparse type: a directory to write into (created later; an existing file, a path
    under a file or an unwritable place is refused)."""
    return _writable(text, True, "output directory")


def output_file(text: str) -> str:
    """An argparse type: a file to write (an existing directory, a path under a file or an
    unwritable place is refused)."""
    return _writable(text, False, "output file")


def _error(message: str) -> int:
    print(f"gauss6: error: {message}", file=sys.stderr)
    return 2


def cmd_scene_info(args: argparse.Namespace) -> int:
    from . import LoadError
    from .scene import effective_settings, format_effective_settings, format_scene_info, load_scene, scene_info

    try:
        scene = load_scene(args.scene)  # once: the summary and the settings read it
        info = scene_info(scene, self_intersections=not args.no_self_intersections)
        settings = effective_settings(scene)
    except LoadError as e:
        return _error(str(e))
    if args.json:  # the documented form; the effective settings only on request
        print(json.dumps({**info, "effective_settings": settings} if args.settings else info, indent=2))
    else:
        print(format_scene_info(info) + "\n" + format_effective_settings(settings))
    return 0


def cmd_datasets(args: argparse.Namespace) -> int:
    from . import datasets, qp_instances

    if args.action == "generate" and args.only:
        datasets.generate(args.only, paths.DATASETS_DIR)
        print(f"{args.only} written to {paths.DATASETS_DIR / args.only}")
        return 0
    if args.action == "generate":
        datasets.generate_all()
        qp_instances.generate()  # sampled on the meshes above: after them
        print(f"datasets written to {paths.DATASETS_DIR}")
        return 0
    problems = datasets.check_all() + qp_instances.check_all()
    for p in problems:
        print(f"MISMATCH {p}")
    print("datasets: all checksums match" if not problems else f"datasets: {len(problems)} mismatches")
    return 1 if problems else 0


def cmd_crosscheck_qp(args: argparse.Namespace) -> int:
    from .crosscheck_qp import crosscheck, format_table

    if args.seeded is not None:
        return run_seeded_campaign(args, "qp")
    result, failures, reports = crosscheck(args.family or None, tolerance=args.tolerance,
                                  with_osqp=not args.no_osqp, show_progress=not args.json)
    if args.json:
        print(json.dumps(result))
    else:
        print(format_table(result, reports))
    for f in failures[:50]:
        print(f"FAIL {f}", file=sys.stderr)
    return 0 if result["ok"] else 1


def run_seeded_campaign(args: argparse.Namespace, what: str) -> int:
    """`crosscheck qp|ccd --seeded N`: the seeded campaign on the campaign module."""
    from .campaign import CampaignError, run_campaign

    if what == "qp":
        from .crosscheck_qp import format_table, seeded_campaign

        families = args.family or None
        make = lambda: seeded_campaign(args.seeded, args.seed, families, with_osqp=args.osqp,  # noqa: E731
                                       tolerance=args.tolerance, chunk_size=args.chunk_size)
    else:
        from .crosscheck_ccd import format_seeded_table as format_table, seeded_campaign

        make = lambda: seeded_campaign(args.seeded, args.seed, args.family)  # noqa: E731
    try:
        campaign = make()
        run = run_campaign(campaign, out=args.out, workers=args.workers, scheduler=args.scheduler,
                           show_progress=not args.json)
    except (ValueError, CampaignError) as e:
        return _error(str(e))
    for problem in run.recomputed:
        print(f"gauss6: warning: chunk file {problem}", file=sys.stderr)
    result, failures, reports = run.summary
    result = {**result, "seed": args.seed, "chunks": len(campaign.chunks), "chunks_run": run.chunks_run,
              "chunks_resumed": run.chunks_resumed, "chunks_recomputed": run.recomputed, "workers": run.workers,
              "seconds": run.seconds}
    if args.json:
        print(json.dumps(result))
    else:
        print(format_table(result, reports))
        print(f"{len(campaign.chunks)} chunks ({run.chunks_resumed} resumed from {args.out}"
              + (f", {len(run.recomputed)} damaged chunk files recomputed" if run.recomputed else "") + "), "
              f"{run.workers or 'serial, no'} workers, {run.seconds:.1f} s")
    for f in failures[:50]:
        print(f"FAIL {f}", file=sys.stderr)
    return 0 if result["ok"] else 1


def cmd_report_qp(args: argparse.Namespace) -> int:
    from .report_qp import format_table, run

    result = run(Path(args.out), [args.family] if args.family else None)
    print(format_table(result))
    print(f"written to {args.out}/ (time_vs_error.png, .svg, table.md, results.json)")
    return 0


def cmd_ccd_queries(args: argparse.Namespace) -> int:
    from .ccd import format_stats, run_queries

    try:
        stats = run_queries(Path(args.target), args.kind, args.impl, time_tolerance=args.time_tolerance)
    except (ValueError, RuntimeError) as e:
        return _error(str(e))
    print(json.dumps(stats.as_json()) if args.json else format_stats(stats, args.impl))
    for m in stats.missed[:50]:
        print(f"FALSE NEGATIVE {m}", file=sys.stderr)
    return 1 if stats.false_negatives else 0


def cmd_crosscheck_ccd(args: argparse.Namespace) -> int:
    from .crosscheck_ccd import run_cli

    if args.seeded is not None:
        return run_seeded_campaign(args, "ccd")
    return run_cli(args)


def cmd_device_list(args: argparse.Namespace) -> int:
    from .device import format_devices, list_devices

    devices = list_devices()
    print(json.dumps(devices, indent=2) if args.json else format_devices(devices))
    return 0


def build_parser() -> argparse.ArgumentParser:
    from . import __version__, defaults  # the C++ settings' defaults, for the options that share them

    from .campaign import add_arguments as add_campaign_arguments

    p = argparse.ArgumentParser(prog="gauss6", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"gauss6 {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    scene = sub.add_parser("scene", help="scene files").add_subparsers(dest="action", required=True)
    info = scene.add_parser("info", help="per body: triangles, closed, manifold, mass, inertia, bbox; the effective settings")
    info.add_argument("scene", type=input_file("scene"), help="scene TOML file")
    info.add_argument("--json", action="store_true", help="machine-readable output")
    info.add_argument("--settings", action="store_true",
                      help="with --json: add the effective settings (always in the text output)")
    info.add_argument("--no-self-intersections", action="store_true",
                      help="skip the exact self-intersection test (reported as -1)")
    info.set_defaults(func=cmd_scene_info)

    ds = sub.add_parser("datasets", help="the seeded dataset generators")
    ds.add_argument("action", choices=["generate", "check"],
                    help="generate: write in place; check: regenerate and compare checksums")
    from .datasets import DATASETS, ON_DEMAND

    ds.add_argument("--only", choices=[*DATASETS, *ON_DEMAND], help="generate: this dataset only (bunny_x4, bunny_x16: "
                                                                "large, not committed, made only so)")
    ds.set_defaults(func=cmd_datasets)

    cc = sub.add_parser("crosscheck", help="optimized against exact (and peers)").add_subparsers(
        dest="what", required=True)
    ccq = cc.add_parser("qp", help="the projection: certificate on every instance, exact solve on a sample, OSQP")
    ccq.add_argument("--family", action="append",
                     help="an instance family (repeatable with --seeded; default: all the stored ones; with "
                          "--seeded also m200, m1000, redundant_m200, redundant_m1000)")
    ccq.add_argument("--json", action="store_true", help="machine-readable output")
    ccq.add_argument("--tolerance", type=float, default=1e-9, help="max relative error in the M-norm (default 1e-9)")
    ccq.add_argument("--no-osqp", action="store_true", help="skip the OSQP cross-check")
    ccq.add_argument("--seeded", type=positive_int, metavar="N",
                     help="instead of the stored families: a campaign of at least N instances generated from "
                          "--seed on the fly (qp_seeded.py), on Dask (--workers, --scheduler, --out)")
    ccq.add_argument("--seed", type=int, default=1, help="with --seeded: the campaign's seed (default 1)")
    ccq.add_argument("--osqp", action="store_true", help="with --seeded: add the OSQP cross-check (off by default)")
    ccq.add_argument("--chunk-size", type=positive_int, default=None,
                     help="with --seeded: instances a chunk (default 360, a multiple of every family's cycle)")
    add_campaign_arguments(ccq)
    ccq.set_defaults(func=cmd_crosscheck_qp)
    ccc = cc.add_parser("ccd", help="mesh CCD steps: optimized ccd_step against the exact first contact (and FCL)")
    ccc.add_argument("--set", dest="set_name", help="one step set of datasets_generated/ccd/ (default: all)")
    ccc.add_argument("--json", action="store_true", help="machine-readable output")
    ccc.add_argument("--peers", action="store_true", help="print FCL's misses and time (JSON) instead")
    ccc.add_argument("--seeded", type=positive_int, metavar="N",
                     help="instead of the stored sets: a campaign of N steps generated from --seed on the fly "
                          "(ccd_seeded.py), on Dask (--workers, --scheduler, --out)")
    ccc.add_argument("--seed", type=int, default=1, help="with --seeded: the campaign's seed (default 1)")
    ccc.add_argument("--family", action="append",
                     help="with --seeded: only these step families (repeatable; default all)")
    add_campaign_arguments(ccc)
    ccc.set_defaults(func=cmd_crosscheck_ccd)

    ccd = sub.add_parser("ccd", help="continuous collision detection").add_subparsers(dest="action", required=True)
    cq = ccd.add_parser("queries", help="run a CCD query file (or a folder of them) through one implementation")
    cq.add_argument("target", help="query CSV file, or a directory (every CSV under vertex-face/ or edge-edge/)")
    cq.add_argument("--kind", choices=["vf", "ee"], help="vertex/face or edge/edge (default: from the folder name)")
    cq.add_argument("--impl", choices=["optimized", "reference"], default="optimized", help="default: optimized")
    time_tolerance = defaults()["ccd"]["time_tolerance"]
    cq.add_argument("--time-tolerance", type=float, default=time_tolerance,
                    help=f"optimized CCD time tolerance (default {time_tolerance:g})")
    cq.add_argument("--json", action="store_true", help="machine-readable output")
    cq.set_defaults(func=cmd_ccd_queries)

    report = sub.add_parser("report", help="speed against error reports").add_subparsers(dest="what", required=True)
    rq = report.add_parser("qp", help="projection solvers: time against error on the same instances")
    rq.add_argument("--out", required=True, type=output_dir, help="output directory")
    rq.add_argument("--family", help="one instance family (default: all but warm)")
    rq.set_defaults(func=cmd_report_qp)
    from . import peers  # CCD and projection peers, in one run

    peers.register(report)

    dev = sub.add_parser("device", help="haptic devices").add_subparsers(dest="action", required=True)
    dl = dev.add_parser("list", help="the HID devices hidapi sees, with their gauss6 profile")
    dl.add_argument("--json", action="store_true", help="machine-readable output")
    dl.set_defaults(func=cmd_device_list)

    from .reproduce import register as register_reproduce

    register_reproduce(sub)  # reproduce {peg,bunny,all} --out DIR [--threaded]; trace export | import

    from . import run  # any scene, run and reported as the paper's are

    run.register(sub)

    from . import replay, view  # a recorded session driving a scene; the web page of runs

    replay.register(sub)
    view.register(sub)

    from . import validate  # an engine under test driven and judged, or a recorded run judged

    validate.register(sub)

    from . import certify  # a recorded run certified exactly (properties 5 and 6)

    certify.register(sub)

    from . import reference_speed  # the exact first contact's speed, filtered and exact-only

    reference_speed.register(sub)

    from . import bench, gate, haptic_rate, sweeps  # benchmarks, speed against error, the gate, the 10 kHz run

    bench.register(sub)
    haptic_rate.register(sub)
    sweeps.register(sub)
    gate.register(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """The command's exit status: argparse's own (0 for --help and --version, 2 for an argument
    refused at parse time, its message on stderr) or the subcommand's."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as e:
        return 0 if e.code is None else e.code if isinstance(e.code, int) else 2
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
