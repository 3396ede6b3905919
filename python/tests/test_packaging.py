"""The pip-installable package: a wheel built from this checkout (pyproject.toml,
scikit-build-core), installed into a fresh venv, gives a working `gauss6` command whose
version is the top-level CMakeLists.txt's project() version.

Slow (a CMake build of the extension in build-<wheel tag>/, about 4 min here with a
warm compiler cache, much more without): it runs only with GAUSS6_TEST_WHEEL=1
(`make wheel-test`)."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from gauss6 import paths

pytestmark = pytest.mark.skipif(os.environ.get("GAUSS6_TEST_WHEEL") != "1",
                                reason="slow wheel build: set GAUSS6_TEST_WHEEL=1 (make wheel-test)")


def project_version() -> str:
    text = (paths.REPO_ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(gauss6 VERSION ([0-9.]+)", text).group(1)


def test_wheel_installs_into_a_fresh_venv_and_runs(tmp_path: Path):
    version = project_version()
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(paths.REPO_ROOT), "--no-deps", "-w", str(wheels)],
                   check=True)
    (wheel,) = wheels.glob("gauss6-*.whl")
    assert wheel.name.startswith(f"gauss6-{version}-")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run([venv / "bin" / "pip", "install", "-q", str(wheel)], check=True)
    # Run outside the checkout, so that nothing is imported from python/.
    out = subprocess.run([venv / "bin" / "gauss6", "--version"], cwd=tmp_path, check=True,
                         capture_output=True, text=True).stdout
    assert out.strip() == f"gauss6 {version}"
    scene = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"
    info = subprocess.run([venv / "bin" / "gauss6", "scene", "info", str(scene), "--json"], cwd=tmp_path,
                          check=True, capture_output=True, text=True).stdout
    assert '"bodies"' in info
