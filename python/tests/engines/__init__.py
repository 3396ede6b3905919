"""Engines for the oracle's tests (python/tests/test_oracle_engines.py): Python engines that wrap
gauss6's own engine (the C ABI library) and change what it renders, either honestly (variants.py:
nothing of METHOD.md section 5 broken, or a declared intent) or with one planted fault (faults.py).
Each has `name`, `declarations` (what it declares: docs/engine-contract.md) and the engine protocol
(reset, step)."""
