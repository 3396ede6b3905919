#!/usr/bin/env bash
# Runs every libFuzzer target of fuzz/ (one per parser) for FUZZ_SECONDS each
# (argument 1, default 180), in the clang build build-fuzz/ (ASan, UBSan with
# float-cast-overflow), which it configures and builds first. Each target starts
# from its checked-in seeds and regressions (fuzz/corpus/<t>/, fuzz/regressions/<t>/)
# and grows a working corpus in build-fuzz/corpus/<t>/. A crash is copied into
# fuzz/regressions/<t>/ (check it in: the ctest test fuzz/replay/<t> replays it
# in every `make test`), and the script fails. Called by `make fuzz` and, for a
# few seconds a target, by `make test`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
. tools/ccache.env
seconds=${1:-${FUZZ_SECONDS:-180}}
# FUZZ_RUNS=N: a fixed number of inputs per target from a fixed seed instead of a time
# budget, so that a short run (make test's) does as much on a slow machine as on a fast
# one. It does not fix the inputs themselves: two runs of the same build and seed
# still part ways within a few thousand inputs (seen here: 20,000 OFF inputs ended at
# coverage 654, 660 and 664 in three runs), so a short run can find what the last one
# did not. Run `make fuzz` (minutes a target) after touching a parser.
if [ -n "${FUZZ_RUNS:-}" ]; then
  budget=(-runs="$FUZZ_RUNS" -seed="${FUZZ_SEED:-1}")
  what="$FUZZ_RUNS inputs (seed ${FUZZ_SEED:-1})"
else
  budget=(-max_total_time="$seconds")
  what="${seconds}s"
fi
# FUZZ_TARGETS="a b": only these targets (default all).
targets=(${FUZZ_TARGETS:-scene obj off ply stl trace ccd_queries qp_instances hand_script height_map})

if ! command -v clang++ >/dev/null; then
  echo "gauss6 fuzz: clang++ not found (tools/debian-packages.txt: clang, libclang-rt-14-dev)" >&2
  exit 1
fi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [ ! -f build-fuzz/build.ninja ]; then
  cmake -S fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >/dev/null
fi
cmake --build build-fuzz -j "${GAUSS6_JOBS:-$(nproc)}"

status=0
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/artifacts/$t"
  rm -f "build-fuzz/artifacts/$t"/*  # only what this run finds is copied below
  # Quiet unless something is found; the last line says how far it got.
  if ! build-fuzz/fuzz_"$t" "build-fuzz/corpus/$t" "fuzz/corpus/$t" "fuzz/regressions/$t" \
       "${budget[@]}" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
       -artifact_prefix="build-fuzz/artifacts/$t/" -print_final_stats=0 >"build-fuzz/fuzz_$t.log" 2>&1; then
    status=1
    echo "gauss6 fuzz: $t FOUND A CRASH (log: build-fuzz/fuzz_$t.log)"
    for a in build-fuzz/artifacts/"$t"/*; do
      [ -f "$a" ] && cp "$a" "fuzz/regressions/$t/" && echo "  kept as fuzz/regressions/$t/$(basename "$a")"
    done
  else
    echo "gauss6 fuzz: $t: $(grep -Eo '#[0-9]+.*(cov|DONE)[^ ]* *[0-9]*' "build-fuzz/fuzz_$t.log" | tail -1) in $what, no crash"
  fi
done
exit $status
