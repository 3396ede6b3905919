"""`gauss6 view TRACE [TRACE ...] [--scene SCENE] [--out page.html]`: a self-contained web page of
one or more runs (gauss6.view: 3D, timeline, plots)."""
from __future__ import annotations

import argparse

from ..cli_args import EXIT_OK, error, input_file, output_file, positive_int


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..view import MAX_FRAMES

    v = subparsers.add_parser("view", help="a self-contained web page of one or more runs (3D, timeline, plots)")
    v.add_argument("traces", nargs="+", type=input_file("trace"),
                   help="trace file(s) (.g6trace); several are drawn side by side")
    v.add_argument("--trace", action="append", type=input_file("trace"),
                   help="another trace to draw beside the first (repeatable)")
    v.add_argument("--scene", type=input_file("scene"),
                   help="scene TOML (default: the generated scene the trace's metadata names)")
    v.add_argument("--out", type=output_file, help="the page to write (default: the first trace with .html)")
    v.add_argument("--label", action="append", help="a run's label, in the order of the traces (repeatable)")
    v.add_argument("--max-frames", type=positive_int, default=MAX_FRAMES,
                   help=f"ticks (and sim steps) per run kept in the page (default {MAX_FRAMES}); more are down-sampled")
    return v


def run(args: argparse.Namespace) -> int:
    from .. import LoadError
    from ..view import ViewerBuildError, write_view

    traces = list(args.traces) + list(args.trace or [])
    try:
        out = write_view(traces, args.scene, args.out, labels=args.label, max_frames=args.max_frames)
    except (LoadError, ValueError, ViewerBuildError) as e:
        return error(str(e))
    print(f"written {out} ({out.stat().st_size / 1e6:.1f} MB); open it in a web browser (works from file://)")
    return EXIT_OK
