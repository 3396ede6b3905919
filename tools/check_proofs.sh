#!/usr/bin/env bash
# Compiles the Coq proofs of proofs/ (Coq 8.16; Flocq, Gappa's Coq tactic and
# mathcomp from tools/debian-packages.txt) and fails when any of them
# admits or assumes more than it may, or has come apart from the code:
#  1. no Admitted, admit, Axiom, Parameter or Conjecture in any proofs/*.v, and
#     every proofs/*.v is listed in _CoqProject;
#  2. every file compiles (the `gappa` tactic runs Gappa and Coq checks the
#     certificate it returns, so Gappa's proofs are checked here too);
#  3. every `Theorem` has its `Print Assumptions`, and each answer is either
#     "Closed under the global context" or lists only the axioms of
#     ALLOWED_AXIOMS below;
#  4. every `(* covers FILE "SIGNATURE" sha256:HASH *)` line of a proof file
#     still matches the code: HASH is the hash of the function of FILE whose
#     first line holds SIGNATURE, its comments and blank space removed (so a
#     change of the code a theorem speaks for fails here until the theorem is
#     looked at and the hash renewed: `tools/check_proofs.sh --hashes` prints
#     the current ones);
#  5. every `(* allowance NAME = VALUE *)` line of a proof file states the value
#     error_allowances.h gives NAME, character for character.
# The summary line counts the theorems checked.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root/proofs"
shopt -s nullglob
files=( *.v )
if [ ${#files[@]} -eq 0 ]; then echo "proofs: none yet"; exit 0; fi

# The axioms a theorem may rest on, by name, and why:
#  - ClassicalDedekindReals.sig_forall_dec, ClassicalDedekindReals.sig_not_dec:
#    the two axioms of Coq's standard-library construction of the real numbers
#    (Reals), on which every statement about R rests;
#  - FunctionalExtensionality.functional_extensionality_dep: also used by the
#    standard library's reals (Print Assumptions Rle_dec lists it);
#  - Classical_Prop.classic: excluded middle, which Flocq's proofs about
#    rounding use (its Raux and Generic_fmt).
# The proofs over mathcomp's ordered fields (Projection.v, Shading.v) need none.
ALLOWED_AXIOMS=(
  ClassicalDedekindReals.sig_forall_dec
  ClassicalDedekindReals.sig_not_dec
  FunctionalExtensionality.functional_extensionality_dep
  Classical_Prop.classic
)

hashes() {  # prints "FILE|SIGNATURE|HASH|WANTED" for every covers line
  python3 - "$root" "${files[@]}" <<'EOF'
import hashlib, re, sys
root, files = sys.argv[1], sys.argv[2:]
pat = re.compile(r'\(\* covers (\S+) "([^"]+)" sha256:([0-9a-f]*) \*\)')
for f in files:
    for m in pat.finditer(open(f).read()):
        path, sig, want = m.groups()
        lines = open(f"{root}/{path}").read().split("\n")
        start = [i for i, l in enumerate(lines) if sig in l and not l.lstrip().startswith("//")]
        if len(start) != 1:
            print(f"{path}|{sig}|{'missing' if not start else 'ambiguous'}|{want}"); continue
        body, depth, seen = [], 0, False
        for l in lines[start[0]:]:
            code = re.sub(r"//.*", "", l)
            body.append(code)
            depth += code.count("{") - code.count("}")
            seen = seen or "{" in code
            if seen and depth <= 0: break
        text = re.sub(r"\s+", "", "".join(body))
        print(f"{path}|{sig}|{hashlib.sha256(text.encode()).hexdigest()[:16]}|{want}")
EOF
}
if [ "${1:-}" = "--hashes" ]; then hashes; exit 0; fi

if grep -nE '\b(Admitted|admit|Axiom|Parameter|Conjecture)\b' "${files[@]}"; then
  echo "proofs: FAILED: the lines above admit or assume something" >&2; exit 1
fi
[ -f _CoqProject ] || { echo "proofs: missing _CoqProject" >&2; exit 1; }
for f in "${files[@]}"; do
  grep -qx "$f" _CoqProject || { echo "proofs: FAILED: $f is not in _CoqProject" >&2; exit 1; }
done

stale=$(hashes | awk -F'|' '$3 != $4')
if [ -n "$stale" ]; then
  echo "$stale" | awk -F'|' '{print "proofs: " $1 " \"" $2 "\": code hash " $3 ", proof states " $4}' >&2
  echo "proofs: FAILED: the code above changed since its theorem was checked against it" >&2; exit 1
fi
allowances="$root/optimized/gauss6/numeric/error_allowances.h"
while IFS= read -r line; do
  name=$(sed -E 's/.*allowance ([A-Za-z0-9_]+) = (.*) \*\).*/\1/' <<<"$line")
  value=$(sed -E 's/.*allowance ([A-Za-z0-9_]+) = (.*) \*\).*/\2/' <<<"$line")
  code=$(sed -nE "s/^constexpr double $name = ([^;]*);.*/\1/p" "$allowances")
  if [ "$code" != "$value" ]; then
    echo "proofs: FAILED: $name is '$code' in error_allowances.h but '$value' in the proof" >&2; exit 1
  fi
done < <(grep -h "(\* allowance " "${files[@]}" || true)

coq_makefile -f _CoqProject -o CoqMakefile >/dev/null
# -B: always recompile, so that every Print Assumptions answers on every run.
make -B -s -f CoqMakefile 2>&1 | tee .build.log
if grep -qE "^(File|Error)" .build.log; then echo "proofs: FAILED: see the errors above" >&2; exit 1; fi

for f in "${files[@]}"; do
  for t in $(sed -nE 's/^Theorem ([A-Za-z0-9_]+).*/\1/p' "$f"); do
    grep -q "^Print Assumptions $t\." "$f" ||
      { echo "proofs: FAILED: $f: Theorem $t has no Print Assumptions" >&2; exit 1; }
  done
done
# Every axiom an answer lists (a qualified name at the start of a line,
# its type after " : ", on the same line or on indented lines below) must be
# allowed.
bad=$(awk '/^Axioms:/ {a=1; next}
           a && /^[A-Za-z_][A-Za-z0-9_.\x27]*( : .*)?$/ {print $1; next}
           a && /^ / {next}
           {a=0}' .build.log | sort -u | grep -vxF -f <(printf '%s\n' "${ALLOWED_AXIOMS[@]}") || true)
if [ -n "$bad" ]; then
  echo "$bad" >&2; echo "proofs: FAILED: a theorem rests on the axioms above, not allowed" >&2; exit 1
fi
asked=$(cat "${files[@]}" | grep -c "^Print Assumptions" || true)
closed=$(grep -c "Closed under the global context" .build.log || true)
listed=$(grep -c "^Axioms:" .build.log || true)
if [ "$asked" -eq 0 ] || [ $((closed + listed)) -ne "$asked" ]; then
  echo "proofs: FAILED: $asked Print Assumptions but $((closed + listed)) answers" >&2; exit 1
fi
echo "proofs: ${#files[@]} files compiled, $asked theorems checked ($closed closed under the" \
     "global context, $listed on the allowed axioms of the reals only)"
