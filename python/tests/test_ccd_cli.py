"""Tests of `gauss6 ccd queries`: every shared query file through both CCD implementations.

The shared data (../shared/data/ccd-sample-queries) carries the exact ground truth of
every query. The CCD contract (METHOD.md section 4) allows no false negative for either
implementation; the exact reference must also have no false positive. The checks are
exact counts (no tolerance): the reference is exact, and a conservative CCD either
reports a contact or not.
"""
from __future__ import annotations

import json
import shutil

import pytest

from gauss6 import cli, paths
from gauss6.ccd import query_files, run_queries

DATA = paths.SHARED_DATA_DIR / "ccd-sample-queries"
FILES = query_files(DATA, None) if DATA.is_dir() else []
needs_data = pytest.mark.skipif(not FILES, reason=f"{DATA} not present")


@needs_data
def test_the_shared_data_has_both_kinds():
    kinds = {k for _, k in FILES}
    assert kinds == {"vf", "ee"}
    assert len(FILES) >= 10


@needs_data
@pytest.mark.parametrize("impl", ["optimized", "reference"])
@pytest.mark.parametrize("path,kind", FILES, ids=[f"{p.split('ccd-sample-queries/')[-1]}" for p, _ in FILES])
def test_no_false_negative_on_shared_file(path, kind, impl):
    stats = run_queries(path, kind, impl)
    assert stats.queries > 0
    assert stats.false_negatives == 0, stats.missed[:10]
    if impl == "reference":
        assert stats.false_positives == 0


@needs_data
@pytest.mark.parametrize("impl", ["optimized", "reference"])
def test_cli_json_schema_and_exit_code(impl, capsys):
    target = DATA / "unit-tests"
    rc = cli.main(["ccd", "queries", str(target), "--impl", impl, "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    assert list(out) == ["queries", "positives", "false_negatives", "false_positives", "seconds"]
    assert out["queries"] == run_queries(target, None, "reference").queries
    assert 0 < out["positives"] < out["queries"]
    assert out["false_negatives"] == 0
    assert out["seconds"] > 0


@needs_data
def test_cli_single_file_with_kind(capsys):
    path, kind = next((p, k) for p, k in FILES if k == "ee")
    rc = cli.main(["ccd", "queries", path, "--kind", kind, "--impl", "reference", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["false_positives"] == 0 and out["false_negatives"] == 0


def _negative_query_rows(kind: str) -> list[str]:
    """The 8 rows of the first query of the shared data whose ground truth is 0."""
    path = next(p for p, k in FILES if k == kind)
    rows = [r for r in open(path).read().splitlines() if r.strip()]
    for i in range(0, len(rows), 8):
        if rows[i].rsplit(",", 1)[1].strip() == "0":
            return rows[i:i + 8]
    raise AssertionError(f"{path}: no negative query")


@needs_data
@pytest.mark.parametrize("kind,folder", [("vf", "vertex-face"), ("ee", "edge-edge")])
def test_a_wrong_ground_truth_is_reported_as_a_false_negative(kind, folder, tmp_path, capsys):
    # A query without contact relabelled as a contact: the reference (exact) must miss
    # it, and the command must say so and exit non-zero: the check can fail.
    rows = [r.rsplit(",", 1)[0] + ",1" for r in _negative_query_rows(kind)]
    bad = tmp_path / folder / "bad.csv"
    bad.parent.mkdir()
    bad.write_text("\n".join(rows) + "\n")
    rc = cli.main(["ccd", "queries", str(tmp_path), "--impl", "reference", "--json"])
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert rc == 1
    assert out["queries"] == 1 and out["positives"] == 1 and out["false_negatives"] == 1
    assert "bad.csv:1" in captured.err


def test_a_file_outside_a_named_folder_needs_kind(tmp_path, capsys):
    f = tmp_path / "queries.csv"
    f.write_text("")
    rc = cli.main(["ccd", "queries", str(f), "--json"])
    assert rc == 2
    assert "--kind" in capsys.readouterr().err


@needs_data
def test_a_malformed_file_is_an_error_naming_it(tmp_path, capsys):
    path, _ = FILES[0]
    bad = tmp_path / "edge-edge" / "short.csv"
    bad.parent.mkdir()
    shutil.copy(path, bad)
    bad.write_text("\n".join(bad.read_text().splitlines()[:7]) + "\n")  # 7 rows: not a multiple of 8
    rc = cli.main(["ccd", "queries", str(bad), "--json"])
    assert rc == 2
    assert "short.csv" in capsys.readouterr().err
