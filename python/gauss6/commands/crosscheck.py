"""`gauss6 crosscheck qp|ccd`: the optimized projection and CCD step against exact ground truth
(and peers), on the stored families and sets or, with --seeded N, on a seeded campaign
(gauss6.campaign: chunks as tasks, serial or on Dask, resumable from --out)."""
from __future__ import annotations

import argparse
import json
import sys

from ..cli_args import EXIT_FAILED, EXIT_OK, error, nonnegative_int, output_dir, positive_int


def _add_campaign_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every seeded campaign shares."""
    parser.add_argument("--workers", type=nonnegative_int, default=None,
                        help="worker processes of the embedded LocalCluster (default: all cores; 0: serial, "
                             "in this process)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on an existing Dask cluster (tcp://host:port) instead of a LocalCluster")
    parser.add_argument("--out", type=output_dir, help="folder for the per-chunk results; a rerun into it resumes")


def _add_seeded(parser: argparse.ArgumentParser, generated_by: str) -> None:
    parser.add_argument("--seeded", type=positive_int, metavar="N",
                        help=f"instead of the stored data: a campaign of at least N generated from --seed on the fly "
                             f"({generated_by}), on Dask (--workers, --scheduler, --out)")
    parser.add_argument("--seed", type=int, default=1, help="with --seeded: the campaign's seed (default 1)")


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("crosscheck", help="optimized against exact (and peers)")
    cc = p.add_subparsers(dest="what", required=True)
    ccq = cc.add_parser("qp", help="the projection: certificate on every instance, exact solve on a sample, OSQP")
    ccq.add_argument("--family", action="append",
                     help="an instance family (repeatable with --seeded; default: all the stored ones; with "
                          "--seeded also m200, m1000, redundant_m200, redundant_m1000)")
    ccq.add_argument("--json", action="store_true", help="machine-readable output")
    ccq.add_argument("--tolerance", type=float, default=1e-9, help="max relative error in the M-norm (default 1e-9)")
    ccq.add_argument("--no-osqp", action="store_true", help="skip the OSQP cross-check")
    _add_seeded(ccq, "qp_seeded.py")
    ccq.add_argument("--osqp", action="store_true", help="with --seeded: add the OSQP cross-check (off by default)")
    ccq.add_argument("--chunk-size", type=positive_int, default=None,
                     help="with --seeded: instances a chunk (default 360, a multiple of every family's cycle)")
    _add_campaign_arguments(ccq)
    ccc = cc.add_parser("ccd", help="mesh CCD steps: optimized ccd_step against the exact first contact (and FCL)")
    ccc.add_argument("--set", dest="set_name", help="one step set of datasets_generated/ccd/ (default: all)")
    ccc.add_argument("--json", action="store_true", help="machine-readable output")
    ccc.add_argument("--peers", action="store_true", help="print FCL's misses and time (JSON) instead")
    _add_seeded(ccc, "ccd_seeded.py")
    ccc.add_argument("--family", action="append",
                     help="with --seeded: only these step families (repeatable; default all)")
    _add_campaign_arguments(ccc)
    return p


def run(args: argparse.Namespace) -> int:
    if args.seeded is not None:
        return _seeded_campaign(args)
    return _stored_qp(args) if args.what == "qp" else _stored_ccd(args)


def _report(result: dict, failures: list, text: str | None) -> int:
    """Prints the result (text, or JSON when text is None), the first 50 failures on stderr; the status."""
    print(json.dumps(result) if text is None else text)
    for f in failures[:50]:
        print(f"FAIL {f}", file=sys.stderr)
    return EXIT_OK if result["ok"] else EXIT_FAILED


def _stored_qp(args: argparse.Namespace) -> int:
    from ..crosscheck_qp import crosscheck, format_table

    result, failures, reports = crosscheck(args.family or None, tolerance=args.tolerance,
                                           with_osqp=not args.no_osqp, show_progress=not args.json)
    return _report(result, failures, None if args.json else format_table(result, reports))


def _stored_ccd(args: argparse.Namespace) -> int:
    from ..crosscheck_ccd import crosscheck, format_table

    names = [args.set_name] if args.set_name else None
    try:
        result, failures, peers, ours = crosscheck(names, with_peers=not args.json or args.peers,
                                                   show_progress=not (args.json or args.peers))
    except ValueError as e:
        return error(str(e))
    if args.peers:
        text = json.dumps({"ok": result["ok"], "fcl": None if peers is None else [p.as_json() for p in peers]})
    else:
        text = None if args.json else format_table(result, ours, peers)
    return _report(result, failures, text)


def _seeded_campaign(args: argparse.Namespace) -> int:
    """`crosscheck qp|ccd --seeded N`: the seeded campaign on the campaign module."""
    from ..campaign import CampaignError, run_campaign

    if args.what == "qp":
        from ..crosscheck_qp import format_table, seeded_campaign

        make = lambda: seeded_campaign(args.seeded, args.seed, args.family or None,  # noqa: E731
                                       with_osqp=args.osqp, tolerance=args.tolerance, chunk_size=args.chunk_size)
    else:
        from ..crosscheck_ccd import format_seeded_table as format_table, seeded_campaign

        make = lambda: seeded_campaign(args.seeded, args.seed, args.family)  # noqa: E731
    try:
        campaign = make()
        run = run_campaign(campaign, out=args.out, workers=args.workers, scheduler=args.scheduler,
                           show_progress=not args.json)
    except (ValueError, CampaignError) as e:
        return error(str(e))
    for problem in run.recomputed:
        print(f"gauss6: warning: chunk file {problem}", file=sys.stderr)
    result, failures, reports = run.summary
    result = {**result, "seed": args.seed, "chunks": len(campaign.chunks), "chunks_run": run.chunks_run,
              "chunks_resumed": run.chunks_resumed, "chunks_recomputed": run.recomputed, "workers": run.workers,
              "seconds": run.seconds}
    text = None
    if not args.json:
        text = (format_table(result, reports) + "\n"
                + f"{len(campaign.chunks)} chunks ({run.chunks_resumed} resumed from {args.out}"
                + (f", {len(run.recomputed)} damaged chunk files recomputed" if run.recomputed else "") + "), "
                f"{run.workers or 'serial, no'} workers, {run.seconds:.1f} s")
    return _report(result, failures, text)
