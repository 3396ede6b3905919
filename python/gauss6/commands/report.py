"""`gauss6 report qp|peers`: speed against error reports. qp: the projection solvers on the same
instances; peers: CCD per query against Tight-Inclusion, the projection against DAQP, quadprog and
proxsuite, in one run."""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import paths
from ..cli_args import EXIT_OK, error, output_dir, positive_int


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("report", help="speed against error reports")
    report = p.add_subparsers(dest="what", required=True)
    rq = report.add_parser("qp", help="projection solvers: time against error on the same instances")
    rq.add_argument("--out", required=True, type=output_dir, help="output directory")
    rq.add_argument("--family", help="one instance family (default: all but warm)")
    rp = report.add_parser("peers", help="CCD per query against Tight-Inclusion, the projection against "
                                         "DAQP, quadprog and proxsuite, in one run")
    rp.add_argument("--out", type=Path, default=paths.REPO_ROOT / "out" / "bench" / "peers", help="output folder")
    rp.add_argument("--repeats", type=positive_int, default=3, help="calls per query; its time is the fastest")
    rp.add_argument("--sample", type=positive_int, default=1, help="CCD: every K-th query of each file (default: all)")
    g = rp.add_mutually_exclusive_group()
    g.add_argument("--ccd-only", action="store_true")
    g.add_argument("--qp-only", action="store_true")
    return p


def run(args: argparse.Namespace) -> int:
    return _qp(args) if args.what == "qp" else _peers(args)


def _qp(args: argparse.Namespace) -> int:
    from ..report_qp import format_table, run as run_report

    result = run_report(Path(args.out), [args.family] if args.family else None)
    print(format_table(result))
    print(f"written to {args.out}/ (time_vs_error.png, .svg, table.md, results.json)")
    return EXIT_OK


def _peers(args: argparse.Namespace) -> int:
    from ..peers import format_ccd, format_qp, run as run_peers

    try:
        result = run_peers(args.out, args.repeats, not args.qp_only, not args.ccd_only, sample=args.sample)
    except (FileNotFoundError, ValueError, ImportError) as e:
        return error(str(e))
    if "ccd" in result:
        print(format_ccd(result["ccd"]))
    if "qp" in result:
        print(format_qp(result["qp"]))
    print(f"written to {args.out}")
    return EXIT_OK
