"""`gauss6 datasets generate [--only NAME] [--out DIR] | check`: the seeded dataset generators
(gauss6.generators) writing datasets_generated/, or checking the committed files against them."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cli_args import EXIT_FAILED, EXIT_OK, error, output_dir


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..datasets import DATASETS, ON_DEMAND

    p = subparsers.add_parser("datasets", help="the seeded dataset generators")
    p.add_argument("action", choices=["generate", "check"],
                   help="generate: write in place; check: regenerate and compare checksums")
    p.add_argument("--only", choices=[*DATASETS, *ON_DEMAND], help="generate: this dataset only (bunny_x4, bunny_x16: "
                                                               "large, not committed, made only so)")
    p.add_argument("--out", type=output_dir,
                   help="generate: the datasets folder to write (default: GAUSS6_DATASETS_DIR, else the "
                        "checkout's datasets_generated/, else ./datasets_generated)")
    return p


def run(args: argparse.Namespace) -> int:
    from .. import datasets, paths, qp_instances

    root = Path(args.out) if args.out else paths.DATASETS_DIR
    if args.action == "check" and args.out:
        return error("datasets check compares the committed datasets (GAUSS6_DATASETS_DIR or the checkout's); "
                     "--out is for generate")
    try:
        if args.action == "generate" and args.only:
            datasets.generate(args.only, root)
            print(f"{args.only} written to {root / args.only}")
            return EXIT_OK
        if args.action == "generate":
            datasets.generate_all(root)
            qp_instances.generate(root / "qp")  # sampled on the meshes above: after them
            print(f"datasets written to {root}")
            return EXIT_OK
    except (OSError, RuntimeError) as e:
        return error(str(e))
    problems = datasets.check_all() + qp_instances.check_all()
    for p in problems:
        print(f"MISMATCH {p}")
    print("datasets: all checksums match" if not problems else f"datasets: {len(problems)} mismatches")
    return EXIT_FAILED if problems else EXIT_OK
