"""The thresholds the judges read: the oracle's checks (`gauss6 validate`) and the distance bound of
the exact certification (exact_checks, `gauss6 certify`) come from one TOML file, harness/oracle.toml
(docs/engine-contract.md states each setting)."""
from __future__ import annotations

import tomllib
from pathlib import Path

from . import paths

# The checkout's thresholds; an installed wheel carries a copy (python/CMakeLists.txt).
THRESHOLDS = paths.REPO_ROOT / "harness" / "oracle.toml"
if not THRESHOLDS.exists():
    THRESHOLDS = Path(__file__).resolve().parent / "data" / "oracle.toml"


def load_thresholds(path=None) -> dict:
    """The thresholds file (default THRESHOLDS): a regular file (paths.read_input_text), valid TOML,
    not empty; ValueError naming the file otherwise."""
    path = Path(path or THRESHOLDS)
    try:
        thresholds = tomllib.loads(paths.read_input_text(path, "thresholds file", 1 << 20))
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{path}: not valid TOML: {e}") from None
    if not thresholds:
        raise ValueError(f"{path}: the thresholds file is empty (no setting): give the file to judge by, "
                         "or none for the defaults")
    return thresholds
