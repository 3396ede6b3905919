#!/usr/bin/env bash
# Brings a clone of gauss6 to a working state, idempotently: Debian packages,
# the Python venv at .venv (pinned requirements.txt), the run viewer's npm packages
# (viewer/package-lock.json) and its bundled script, the CMake build (Release
# with debug info) with the Python extension, and the `gauss6` package and command in the venv
# (the checkout's python/ on its path).
# A second run only rebuilds incrementally. Called by `make test` and `make reproduce`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

# 1. Debian packages (one list: tools/debian-packages.txt).
mapfile -t pkgs < <(grep -v '^\s*#' tools/debian-packages.txt | grep -v '^\s*$')
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "gauss6 setup: missing Debian packages; run:" >&2
    echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  echo "gauss6 setup: installing ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# 2. Python venv with pinned requirements (re-installed only when requirements.txt changes).
py=${PYTHON:-python3}
stamp=.venv/.requirements.sha256
want=$(sha256sum requirements.txt | cut -d' ' -f1)
if [ ! -x .venv/bin/python ]; then
  echo "gauss6 setup: creating .venv from $($py --version)"
  "$py" -m venv .venv
fi
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "gauss6 setup: installing Python requirements"
  .venv/bin/python -m pip install -q --disable-pip-version-check -r requirements.txt
  echo "$want" > "$stamp"
fi

# 3. The run viewer's script (gauss6 view): three.js and esbuild pinned in viewer/package-lock.json,
#    installed with `npm ci` (again only when the lock file changes), bundled into viewer/dist/.
if ! command -v npm >/dev/null; then
  echo "gauss6 setup: npm not found: install Node.js 20 and npm (the run viewer needs them)" >&2
  exit 1
fi
vstamp=viewer/node_modules/.package-lock.sha256
vwant=$(sha256sum viewer/package-lock.json | cut -d' ' -f1)
if [ "$(cat "$vstamp" 2>/dev/null)" != "$vwant" ]; then
  echo "gauss6 setup: installing the viewer's npm packages"
  (cd viewer && npm ci --no-audit --no-fund --loglevel=error)
  echo "$vwant" > "$vstamp"
fi
if [ ! -f viewer/dist/gauss6-viewer.js ] || [ -n "$(find viewer/src viewer/package-lock.json -newer viewer/dist/gauss6-viewer.js)" ]; then
  (cd viewer && npm run --silent build)
fi

# 4. CMake build (configured once; later runs build incrementally). Compiled through
#    ccache (tools/ccache.env: paths relative to the checkout), so that the wheel's own
#    build of the extension (build-<wheel tag>/, python/tests/test_packaging.py) and
#    other checkouts' builds reuse these objects.
#    The compiler is Debian's clang 14 (GAUSS6_CXX to change it): the real-time loops
#    take less CPU per step than with g++ 12 at the same -O3, with the same results
#    bit for bit (the replay benchmarks of docs/benchmarks.md measure it). A build configured with another
#    compiler is configured again (its cache only: the artefacts under build/ stay).
. tools/ccache.env
cxx=$(command -v "${GAUSS6_CXX:-clang++}") || { echo "gauss6 setup: ${GAUSS6_CXX:-clang++} not found" >&2; exit 1; }
if [ -f build/CMakeCache.txt ] && ! grep -qx "CMAKE_CXX_COMPILER:[A-Z]*=$cxx" build/CMakeCache.txt; then
  echo "gauss6 setup: build/ was configured with another compiler: configuring it for $cxx"
  rm -rf build/CMakeCache.txt build/CMakeFiles build/build.ninja
fi
if [ ! -f build/build.ninja ]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER="$cxx" \
    -DCMAKE_CXX_COMPILER_LAUNCHER=ccache \
    -DPython_EXECUTABLE="$root/.venv/bin/python" \
    -Dpybind11_DIR="$(.venv/bin/python -m pybind11 --cmakedir)"
fi
cmake --build build -j "${GAUSS6_JOBS:-$(nproc)}"

# 5. The gauss6 package and command in the venv, from the checkout: python/ on the venv's path
#    (a .pth file; CMake writes the extension gauss6._gauss6 and _version.py into python/gauss6),
#    and a `gauss6` script that runs `python -m gauss6`. pyproject.toml (scikit-build-core) is
#    for wheels (`make wheel-check`): an editable install of it would build the extension a
#    second time. An earlier set-up's pip install of python/ is removed first.
site=$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
if .venv/bin/python -m pip show -q gauss6 >/dev/null 2>&1; then
  .venv/bin/python -m pip uninstall -q -y --disable-pip-version-check gauss6
fi
echo "$root/python" > "$site/gauss6-checkout.pth"
printf '#!/bin/sh\n# The gauss6 command of the checkout %s (tools/setup.sh).\nexec "%s/.venv/bin/python" -m gauss6 "$@"\n' \
  "$root" "$root" > .venv/bin/gauss6
chmod +x .venv/bin/gauss6
