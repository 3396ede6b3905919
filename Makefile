# gauss6: the two commands of the README, and a few helpers.
#   make test       set up, then every test suite: ctest (Catch2), pytest, Coq proofs
#   make reproduce  set up, then the project's main job (datasets, scenes, figures)
SHELL := /bin/bash
VENV := .venv/bin
JOBS ?= $(shell nproc)

.PHONY: setup test reproduce ctest pytest proofs datasets clean

setup:
	@tools/setup.sh

ctest: setup
	cd build && ctest --output-on-failure -j $(JOBS)

pytest: setup
	$(VENV)/python -m pytest -q python/tests

proofs: setup
	@tools/check_proofs.sh

# Every suite runs even when an earlier one fails; the target fails if any did.
test: setup
	@status=0; \
	$(MAKE) --no-print-directory ctest || status=1; \
	$(MAKE) --no-print-directory pytest || status=1; \
	$(MAKE) --no-print-directory proofs || status=1; \
	if [ $$status -ne 0 ]; then echo "make test: FAILED"; else echo "make test: all suites passed"; fi; \
	exit $$status

datasets: setup
	$(VENV)/gauss6 datasets generate

reproduce: setup
	$(VENV)/gauss6 reproduce all --out out

clean:
	rm -rf build out
