# gauss6: the two commands of the README, and a few helpers.
#   make test       set up, then every test suite: ctest (Catch2), fuzz-short, sanitize, pytest,
#                   Coq proofs, checks
#   make reproduce  set up, then the project's main job (datasets, scenes, figures)
SHELL := /bin/bash
VENV := .venv/bin
JOBS ?= $(shell nproc)

.PHONY: setup test reproduce bench ctest pytest proofs checks datasets clean wheel-test fuzz fuzz-short campaigns soak sanitize

setup:
	@tools/setup.sh

ctest: setup
	cd build && ctest --output-on-failure -j $(JOBS)

pytest: setup
	$(VENV)/python -m pytest -q python/tests

proofs: setup
	@tools/check_proofs.sh

# The full cross-checks against exact ground truth (pytest runs `crosscheck qp` whole and
# samples the CCD sets): every shared CCD query through both implementations, every
# rigid CCD step set against the exact first contact.
SHARED_QUERIES := ../shared/data/ccd-sample-queries
checks: setup
	$(VENV)/gauss6 ccd queries $(SHARED_QUERIES) --impl optimized
	$(VENV)/gauss6 ccd queries $(SHARED_QUERIES) --impl reference
	$(VENV)/gauss6 crosscheck ccd

# The full seeded campaigns (README.md, "Collision detection"), on all cores; a rerun
# resumes from out/campaigns/. CCD_STEPS: the exact CCD judgement takes 0.05-0.4 s a step.
CCD_STEPS ?= 100000
QP_INSTANCES ?= 1000000
campaigns: setup
	$(VENV)/gauss6 crosscheck qp --seeded $(QP_INSTANCES) --out out/campaigns/qp-$(QP_INSTANCES)
	$(VENV)/gauss6 crosscheck ccd --seeded $(CCD_STEPS) --out out/campaigns/ccd-$(CCD_STEPS)

# libFuzzer on every parser (fuzz/, clang build in build-fuzz/), FUZZ_SECONDS each
# (10 targets: 30 minutes at the default); a crash is kept in fuzz/regressions/.
FUZZ_SECONDS ?= 180
fuzz: setup
	@tools/fuzz.sh $(FUZZ_SECONDS)

# The same for a fixed 20,000 inputs a target from a fixed seed (a few seconds each), as
# part of `make test` (about 1 minute, plus the clang build the first time).
FUZZ_SHORT_RUNS ?= 20000
fuzz-short: setup
	@FUZZ_RUNS=$(FUZZ_SHORT_RUNS) tools/fuzz.sh

# The C++ suites under the sanitizers, clang builds of their own beside build/ (tools/sanitize.sh):
#   build-asan/ ASan + UBSan (float-cast-overflow): gauss6_tests, gauss6_device_tests,
#               gauss6_trace_tests, gauss6_harness_tests, all but the [timing] tests and
#               three brute-force-bound core tests (ASAN_SKIP in the script);
#   build-tsan/ TSan: the [threaded] tests of gauss6_tests and gauss6_harness_tests, the
#               whole device and trace suites.
# Part of `make test`. Cost on the shared 2-core VM under others' builds (README, Sanitizers):
# cold (no ccache) 25 min wall, 13.8 CPU-min (ASan build 18 min, TSan build 6 min, runs 1.4 min);
# warm ccache in a fresh checkout 3.2 min; both trees built 54 s.
sanitize: setup
	@tools/sanitize.sh all

# A threaded run of SOAK_SECONDS (10 minutes) of SOAK_SCENE's script played over and
# over while one busy process a core loads the machine (harness/tools/soak.cpp): every
# force finite and within the limits, the resident set flat; deadline misses, jitter
# and events in out/soak.json. Not part of `make test`.
SOAK_SECONDS ?= 600
SOAK_SCENE ?= datasets_generated/scenes/peg_in_hole.toml
soak: setup
	cmake --build build --target gauss6_soak
	mkdir -p out && build/harness/gauss6_soak $(SOAK_SCENE) --seconds $(SOAK_SECONDS) --json out/soak.json

# Every suite runs even when an earlier one fails; the target fails if any did.
test: setup
	@status=0; \
	$(MAKE) --no-print-directory ctest || status=1; \
	$(MAKE) --no-print-directory fuzz-short || status=1; \
	$(MAKE) --no-print-directory sanitize || status=1; \
	$(MAKE) --no-print-directory pytest || status=1; \
	$(MAKE) --no-print-directory proofs || status=1; \
	$(MAKE) --no-print-directory checks || status=1; \
	if [ $$status -ne 0 ]; then echo "make test: FAILED"; else echo "make test: all suites passed"; fi; \
	exit $$status

# Every benchmark suite (JSON, table, plots in out/bench/) and the speed-against-error
# sweeps (Pareto plots in out/bench/sweeps/), the peers (out/bench/peers/): docs/benchmarks.md.
bench: setup
	$(VENV)/gauss6 bench --build build --out out/bench
	$(VENV)/gauss6 sweep --build build --out out/bench/sweeps
	$(VENV)/gauss6 report peers --sample 4 --out out/bench/peers

datasets: setup
	$(VENV)/gauss6 datasets generate

# Regenerates the datasets in place (byte-identical: `gauss6 datasets check`), then runs
# the paper's scenarios: out/summary.json, out/report.md, the figures and the traces; then
# the full-resolution bunnies (issue 20's third scenario, about 20 s): out/bunny_full/; then
# gauss6 and the third-party engines side by side, the paper's scenes and the conformance battery (out/engines/engines.md, docs/engine-adapters.md)
# on ENGINES_SLICE (--slice S: the first S seconds of each script; empty: whole scripts).
ENGINES_SLICE ?= --slice 4
reproduce: setup
	$(VENV)/gauss6 datasets generate
	$(VENV)/gauss6 reproduce all --out out
	$(VENV)/gauss6 reproduce bunny_full --out out/bunny_full
	$(VENV)/gauss6 reproduce engines --out out/engines $(ENGINES_SLICE)

clean:
	rm -rf build build-fuzz build-asan build-tsan out

# The wheel built from the checkout (pyproject.toml), installed into a fresh venv outside the
# checkout, where it runs the command, the viewer, validate, `datasets generate` (every file the
# committed bytes) and seeded campaigns (python/tests/test_packaging.py, also run by `make test`:
# its build of the extension reuses the main build's objects through ccache).
wheel-test: setup
	$(VENV)/python -m pytest -q python/tests/test_packaging.py
