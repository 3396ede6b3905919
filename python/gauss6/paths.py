"""Where gauss6 finds its own files: the repository, the CMake build tree and its tools.

The package is installed editable from python/, so the repository root is two
levels above this file; GAUSS6_BUILD_DIR overrides the build tree (default build/).
"""
from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def build_dir() -> Path:
    """The CMake build tree (GAUSS6_BUILD_DIR, default <repo>/build)."""
    return Path(os.environ.get("GAUSS6_BUILD_DIR", REPO_ROOT / "build"))


def tool(relpath: str) -> Path:
    """A program built by CMake, e.g. tool("datasets_generated/gauss6_make_bunny").

    Raises FileNotFoundError naming the missing program and how to build it.
    """
    path = build_dir() / relpath
    if not path.exists():
        raise FileNotFoundError(f"{path}: not built; run `make test` or `cmake --build {build_dir()}`")
    return path


DATASETS_DIR = REPO_ROOT / "datasets_generated"
SHARED_DATA_DIR = REPO_ROOT.parent / "shared" / "data"
