"""A constant the documents quote is the code's: every "`kName` = value" in README.md,
docs/*.md and proofs/README.md is compared with the `constexpr ... kName = value;` that
defines it in the library or the benchmarks, so a changed constant cannot leave its
documented value behind (a number the code defines is written once; the documents cite it)."""
from __future__ import annotations

import re

from gauss6 import paths

ROOT = paths.DATASETS_DIR.parent
SOURCES = ["optimized/gauss6", "benchmarks"]
DOCUMENTS = ["README.md", "docs", "proofs/README.md"]

_DEFINITION = re.compile(r"constexpr\s[^=;(]*?\b(k[A-Z]\w*)\s*=\s*([-+]?[0-9][0-9.eE+'-]*)\s*;")
# A quoted constant and its value, across a line break; thousands separated by commas.
_QUOTE = re.compile(r"`(k[A-Z]\w*)`\s*=\s*([-+]?[0-9](?:[0-9.eE+-]|,(?=[0-9]{3}\b))*)")


def code_constants() -> dict[str, float]:
    found: dict[str, float] = {}
    for top in SOURCES:
        for path in sorted((ROOT / top).rglob("*")):
            if path.suffix not in (".h", ".cpp"):
                continue
            for name, value in _DEFINITION.findall(path.read_text()):
                found.setdefault(name, float(value.replace("'", "")))
    return found


def documented_constants() -> list[tuple[str, str, float]]:
    quotes = []
    for entry in DOCUMENTS:
        path = ROOT / entry
        files = sorted(path.rglob("*.md")) if path.is_dir() else [path]
        for f in files:
            text = " ".join(f.read_text().split())
            for name, value in _QUOTE.findall(text):
                quotes.append((str(f.relative_to(ROOT)), name, float(value.rstrip(".").replace(",", ""))))
    return quotes


def test_the_parsers_find_what_they_compare():
    code = code_constants()
    assert "kUpdateOverrunBound" in code and "kBenchWorkUnits" in code
    assert len(code) > 20
    assert len(documented_constants()) >= 5  # the budget's constants at least


def test_every_documented_constant_is_the_codes():
    code = code_constants()
    wrong = []
    for where, name, value in documented_constants():
        if name not in code:
            wrong.append(f"{where}: `{name}` is not a constant of {', '.join(SOURCES)}")
        elif value != code[name]:
            wrong.append(f"{where}: `{name}` = {value:g}, the code says {code[name]:g}")
    assert not wrong, "\n".join(wrong)
