#!/usr/bin/env bash
# Compiles the Coq proofs of proofs/ and fails on any Admitted, admit or axiom:
# every theorem's `Print Assumptions` must answer "Closed under the global context".
set -euo pipefail
cd "$(dirname "$0")/../proofs"
shopt -s nullglob
files=( *.v )
if [ ${#files[@]} -eq 0 ]; then echo "proofs: none yet"; exit 0; fi
if grep -nE '\b(Admitted|admit|Axiom|Parameter|Conjecture)\b' "${files[@]}"; then
  echo "proofs: FAILED: the lines above admit or assume something" >&2; exit 1
fi
[ -f _CoqProject ] || { echo "proofs: missing _CoqProject" >&2; exit 1; }
coq_makefile -f _CoqProject -o CoqMakefile >/dev/null

# -B: always recompile, so that every Print Assumptions answers on every run.
make -B -s -f CoqMakefile 2>&1 | tee .build.log
if grep -q "Axioms:" .build.log; then
  echo "proofs: FAILED: a theorem depends on an axiom (see Print Assumptions above)" >&2; exit 1
fi
asked=$(cat "${files[@]}" | grep -c "^ *Print Assumptions" || true)
closed=$(grep -c "Closed under the global context" .build.log || true)
if [ "$asked" -eq 0 ] || [ "$closed" -ne "$asked" ]; then
  echo "proofs: FAILED: $asked Print Assumptions but $closed answered 'Closed under the global context'" >&2; exit 1
fi
echo "proofs: ${#files[@]} files compiled, $closed theorems closed under the global context"
