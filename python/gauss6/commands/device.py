"""`gauss6 device list [--json]`: the HID devices hidapi sees, with their gauss6 profile."""
from __future__ import annotations

import argparse
import json

from ..cli_args import EXIT_OK


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("device", help="haptic devices")
    dl = p.add_subparsers(dest="action", required=True).add_parser(
        "list", help="the HID devices hidapi sees, with their gauss6 profile")
    dl.add_argument("--json", action="store_true", help="machine-readable output")
    return p


def run(args: argparse.Namespace) -> int:
    from ..device import format_devices, list_devices

    devices = list_devices()
    print(json.dumps(devices, indent=2) if args.json else format_devices(devices))
    return EXIT_OK
