#!/usr/bin/env bash
# The C++ suites under the sanitizers, in clang builds of their own beside the
# main build (no Python extension, no benchmarks; ccache as tools/ccache.env):
#   asan  build-asan/: ASan + UBSan (float-cast-overflow included, every report
#         fatal): the core, device, trace and harness suites (gauss6_tests,
#         gauss6_device_tests, gauss6_trace_tests, gauss6_harness_tests), all
#         their tests but the [timing] ones (timings only) and the three whose
#         time goes to the test's own brute force (ASAN_SKIP below: 6-25 min under
#         ASan on 2 cores); what they run (the projection, ccd_step with its
#         proximity cache and background fill) other tests of the run cover;
#   tsan  build-tsan/: TSan: the core and harness tests that run the loops in
#         threads ([threaded]: the threaded runs, their watchdogs, a device that
#         ends, the seqlock under a concurrent writer, the threaded scenario and
#         its crash safety), and the whole device and trace suites (the HID
#         device's helper thread, the trace writer's flush thread and its ring
#         under concurrent producers; under a second each).
# Usage: tools/sanitize.sh [asan|tsan|all] (default all). Called by `make sanitize`,
# part of `make test`. Fails if a test fails or a sanitizer reports anything.
# Reports of third-party code that are false positives would be suppressed in
# tools/sanitizer-suppressions/ with their reason; none is needed so far.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
. tools/ccache.env
what=${1:-all}
jobs=${GAUSS6_JOBS:-$(nproc)}

if ! command -v clang++ >/dev/null; then
  echo "gauss6 sanitize: clang++ not found (tools/debian-packages.txt: clang, libclang-rt-14-dev)" >&2
  exit 1
fi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

# configure DIR FLAGS: a clang build of the C++ suites with FLAGS on every unit and link.
configure() {
  local dir=$1 flags=$2
  if [ ! -f "$dir/build.ninja" ]; then
    cmake -S . -B "$dir" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DGAUSS6_BUILD_PYTHON=OFF -DGAUSS6_BUILD_BENCHMARKS=OFF "${launcher[@]}" \
      -DCMAKE_CXX_FLAGS="$flags -fno-omit-frame-pointer" \
      -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" >/dev/null
  fi
}

# The core suite's tests left out of the ASan run: each spends its time in the
# test's own brute force (a long-double KKT enumeration over 16 instances; a
# brute-force first contact of every triangle pair at each of 120-300 steps),
# 1-4 min in the main build and 6-25 min under ASan on 2 cores.
ASAN_SKIP=('~"regression: nearly parallel rows of the redundant family"'
           '~"ccd_step: a ball wandering among blocks*"'
           '~"ccd_step: steps served by the proximity cache*"')

status=0
# run NAME EXE [Catch2 filter...]: one suite, its log in the build dir.
run() {
  local name=$1 exe=$2
  shift 2
  local start=$SECONDS
  if "$exe" "$@" >"$(dirname "$exe")/../$name.log" 2>&1; then
    echo "gauss6 sanitize: $name: $(grep -E '^(All tests passed|test cases)' "$(dirname "$exe")/../$name.log" | tail -1) ($((SECONDS - start)) s)"
  else
    status=1
    echo "gauss6 sanitize: $name FAILED (log: $(dirname "$exe")/../$name.log)"
    grep -E 'ERROR: (Address|Thread|Undefined)Sanitizer|runtime error:|WARNING: ThreadSanitizer|FAILED' \
      "$(dirname "$exe")/../$name.log" | head -20 || true
  fi
}

if [ "$what" = asan ] || [ "$what" = all ]; then
  start=$SECONDS
  configure build-asan "-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all"
  cmake --build build-asan -j "$jobs" --target gauss6_tests gauss6_device_tests gauss6_trace_tests gauss6_harness_tests
  echo "gauss6 sanitize: asan build $((SECONDS - start)) s"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  run asan-core build-asan/optimized/gauss6_tests "~[timing]" "${ASAN_SKIP[@]}"
  run asan-device build-asan/device/gauss6_device_tests "~[timing]"
  run asan-trace build-asan/trace/gauss6_trace_tests "~[timing]"
  run asan-harness build-asan/harness/gauss6_harness_tests "~[timing]"
fi

if [ "$what" = tsan ] || [ "$what" = all ]; then
  start=$SECONDS
  configure build-tsan "-fsanitize=thread"
  cmake --build build-tsan -j "$jobs" --target gauss6_tests gauss6_harness_tests gauss6_device_tests gauss6_trace_tests
  echo "gauss6 sanitize: tsan build $((SECONDS - start)) s"
  export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
  run tsan-core build-tsan/optimized/gauss6_tests "[threaded]"
  run tsan-harness build-tsan/harness/gauss6_harness_tests "[threaded]"
  run tsan-device build-tsan/device/gauss6_device_tests
  run tsan-trace build-tsan/trace/gauss6_trace_tests
fi
exit $status
