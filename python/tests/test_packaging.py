"""The pip-installable package: a wheel built from this checkout (pyproject.toml,
scikit-build-core), installed into a fresh venv outside the checkout, gives a working `gauss6`
command whose version is the top-level CMakeLists.txt's project() version, whose `gauss6 view`
writes a page with the viewer bundled into the wheel, and which, with no checkout, generates
every dataset byte for byte as committed (`gauss6 datasets generate`: the generators are a
package of the library, the bunny's CGAL program is in the wheel) and runs seeded campaigns
on them (`crosscheck qp --seeded`, `crosscheck ccd --seeded`). `make wheel-test` runs it alone.

The wheel's CMake build of the extension (build-<wheel tag>/) goes through the compiler
cache that tools/setup.sh fills (tools/ccache.env), without build isolation (the venv's
pinned scikit-build-core and pybind11), so that its objects are the main build's: about
1-2 min in `make test` after the main build, most of it linking and installing. Set
GAUSS6_SKIP_WHEEL=1 to leave it out of a quick local run."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from gauss6 import paths

pytestmark = pytest.mark.skipif(os.environ.get("GAUSS6_SKIP_WHEEL") == "1", reason="GAUSS6_SKIP_WHEEL=1")


def main_build_compiler() -> list[str]:
    """The compiler the main build was configured with (its CMakeCache.txt: tools/setup.sh
    chooses it), as a config setting, so that the wheel's build reuses its objects."""
    cache = paths.build_dir() / "CMakeCache.txt"
    found = re.search(r"^CMAKE_CXX_COMPILER:\w+=(.+)$", cache.read_text(), re.M) if cache.exists() else None
    return [f"--config-settings=cmake.define.CMAKE_CXX_COMPILER={found.group(1)}"] if found else []


def ccache_env() -> dict:
    """The environment of tools/setup.sh's builds: ccache with paths relative to the checkout."""
    env = dict(os.environ)
    env.update(CCACHE_BASEDIR=str(paths.REPO_ROOT), CCACHE_NOHASHDIR="1")
    return env


def project_version() -> str:
    text = (paths.REPO_ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(gauss6 VERSION ([0-9.]+)", text).group(1)


def test_wheel_installs_into_a_fresh_venv_and_runs(tmp_path: Path):
    version = project_version()
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(paths.REPO_ROOT), "--no-deps", "--no-build-isolation",
                    "--config-settings=cmake.define.CMAKE_CXX_COMPILER_LAUNCHER=ccache", *main_build_compiler(),
                    "-w", str(wheels)],
                   check=True, env=ccache_env())
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
    # The viewer's page, from the wheel's own copy of the bundled script (no checkout needed).
    trace = tmp_path / "short.g6trace"
    subprocess.run([venv / "bin" / "python", "-c",
                    "import sys; from gauss6._gauss6 import runtime; "
                    "runtime.run_scenario(sys.argv[1], sys.argv[2], duration=0.05)", str(scene), str(trace)],
                   cwd=tmp_path, check=True)
    page = tmp_path / "page.html"
    subprocess.run([venv / "bin" / "gauss6", "view", str(trace), "--scene", str(scene), "--out", str(page)],
                   cwd=tmp_path, check=True, capture_output=True, text=True)
    assert "three" in page.read_text()[:2_000_000].lower() and page.stat().st_size > 100_000
    # gauss6's engine and the oracle's thresholds come with the wheel: validate loads the engine
    # by name from the package (not the build tree) and judges a short run (0.3 s, free motion).
    r = subprocess.run([venv / "bin" / "gauss6", "validate", "--engine", "gauss6", "--scene", str(scene),
                        "--duration", "0.3", "--quiet", "--json", "--out", str(tmp_path / "validate")],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["pass"] and "site-packages/gauss6/engines/" in doc["engine"]["library"]
    assert doc["thresholds"]["file"].endswith("gauss6/data/oracle.toml")
    check_datasets_and_campaigns(venv / "bin" / "gauss6", tmp_path / "data")


# The datasets `gauss6 datasets generate` writes (qp after the meshes it samples); bunny and
# bunny_full need the system's glmark2-data (tools/debian-packages.txt).
GENERATED = ("peg_in_hole", "bunny", "bunny_full", "surfaces", "battery", "qp")


def check_datasets_and_campaigns(gauss6: Path, cwd: Path) -> None:
    """In an empty folder outside the checkout: every dataset generated into ./datasets_generated
    (the installed package's default), each file the same bytes as the committed one; then a
    seeded projection campaign and a seeded CCD campaign on those meshes, both passing."""
    cwd.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("GAUSS6_DATASETS_DIR", "GAUSS6_BUILD_DIR")}
    subprocess.run([gauss6, "datasets", "generate"], cwd=cwd, env=env, check=True, capture_output=True, text=True)
    for name in GENERATED:
        manifest = json.loads((paths.DATASETS_DIR / name / "MANIFEST.json").read_text())
        for filename in ["MANIFEST.json", *manifest["outputs"]]:
            made = (cwd / "datasets_generated" / name / filename).read_bytes()
            assert made == (paths.DATASETS_DIR / name / filename).read_bytes(), f"{name}/{filename}"
    for what, extra in (("qp", ["--seeded", "360"]), ("ccd", ["--seeded", "25", "--family", "random"])):
        r = subprocess.run([gauss6, "crosscheck", what, *extra, "--seed", "1", "--workers", "0", "--json"], cwd=cwd,
                           env=env, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        result = json.loads(r.stdout)
        assert result["ok"] and result["chunks_run"] >= 1, result
