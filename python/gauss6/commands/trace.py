"""`gauss6 trace export TRACE [--csv DIR] [--hapi FILE]` and `gauss6 trace import FILE --format
hapi|csv --out TRACE`: run traces to and from CSV files and HAPI device logs (gauss6.logs)."""
from __future__ import annotations

import argparse

from ..cli_args import EXIT_OK, error, input_file, output_dir, output_file


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("trace", help="run traces")
    tr = p.add_subparsers(dest="action", required=True)
    ex = tr.add_parser("export", help="write a trace as CSV files (one per stream) and/or a HAPI device log")
    ex.add_argument("trace", type=input_file("trace"), help="trace file (.g6trace)")
    ex.add_argument("--csv", type=output_dir,
                    help="output directory (ticks.csv, steps.csv, contacts.csv, events.csv, meta.json)")
    ex.add_argument("--hapi", type=output_file,
                    help="output HAPI DeviceLog, ASCII (TIME POSITION ORIENTATION FORCE TORQUE BUTTONS)")
    im = tr.add_parser("import", help="a HAPI device log or CSV recorded elsewhere -> a trace for replay")
    im.add_argument("file", type=input_file("log", directory_ok=True),
                    help="HAPI DeviceLog (ASCII), or a CSV directory (to_csv's files) or ticks CSV")
    im.add_argument("--format", required=True, choices=["hapi", "csv"])
    im.add_argument("--out", required=True, type=output_file, help="the trace to write (.g6trace)")
    im.add_argument("--scene", help="scene name to record in the trace's metadata (for gauss6 view)")
    return p


def run(args: argparse.Namespace) -> int:
    from .. import LoadError
    from ..logs import export_trace, import_log

    if args.action == "export" and not (args.csv or args.hapi):
        return error("trace export: give --csv DIR and/or --hapi FILE")
    try:
        if args.action == "export":
            print(export_trace(args.trace, hapi=args.hapi, csv=args.csv))
            return EXIT_OK
        out, tr = import_log(args.file, args.format, args.out, scene=args.scene or "")
    except (LoadError, ValueError, OSError) as e:
        return error(str(e))
    print(f"{args.file}: {len(tr.ticks)} ticks ({args.format}), {tr.ticks['t'][0]:g} to {tr.ticks['t'][-1]:g} s "
          f"-> {out} (a trace the replay device plays back)")
    return EXIT_OK
