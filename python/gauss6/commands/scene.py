"""`gauss6 scene info SCENE [--json] [--settings] [--no-self-intersections]`: per body
triangles, closed, manifold, mass, inertia, bounding box; the effective settings."""
from __future__ import annotations

import argparse
import json

from ..cli_args import EXIT_OK, error, input_file


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("scene", help="scene files")
    info = p.add_subparsers(dest="action", required=True).add_parser(
        "info", help="per body: triangles, closed, manifold, mass, inertia, bbox; the effective settings")
    info.add_argument("scene", type=input_file("scene"), help="scene TOML file")
    info.add_argument("--json", action="store_true", help="machine-readable output")
    info.add_argument("--settings", action="store_true",
                      help="with --json: add the effective settings (always in the text output)")
    info.add_argument("--no-self-intersections", action="store_true",
                      help="skip the exact self-intersection test (reported as -1)")
    return p


def run(args: argparse.Namespace) -> int:
    from .. import LoadError
    from ..scene import effective_settings, format_effective_settings, format_scene_info, load_scene, scene_info

    try:
        scene = load_scene(args.scene)  # once: the summary and the settings read it
        info = scene_info(scene, self_intersections=not args.no_self_intersections)
        settings = effective_settings(scene)
    except LoadError as e:
        return error(str(e))
    if args.json:  # the documented form; the effective settings only on request
        print(json.dumps({**info, "effective_settings": settings} if args.settings else info, indent=2))
    else:
        print(format_scene_info(info) + "\n" + format_effective_settings(settings))
    return EXIT_OK
