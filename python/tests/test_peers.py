"""Tests of `gauss6 report peers` (python/gauss6/peers.py) on a small slice: the shared
unit-test CCD queries and one QP family, one call each. What is checked is the
accounting (every query counted once per implementation, the exact reference's
answers equal the ground truth, gauss6 has no false negative and no late hit) and
the tables; the timings themselves are `make bench`'s, not a test's."""
from __future__ import annotations

import pytest

from gauss6 import cli, paths, peers

pytest.importorskip("ipctk")
needs_data = pytest.mark.skipif(not peers.CCD_DATA.is_dir(), reason=f"{peers.CCD_DATA} not present")


@needs_data
def test_ccd_peers_on_the_unit_tests():
    r = peers.run_ccd(repeats=1, show_progress=False, sets=["unit-tests"])
    assert {row["kind"] for row in r["sets"]} == {"vf", "ee"}
    for row in r["sets"]:
        for name in ("gauss6", "Tight-Inclusion", "exact"):
            assert row[name]["median_ns"] > 0
        assert row["exact"]["false_negatives"] == row["exact"]["false_positives"] == 0
        assert row["gauss6"]["false_negatives"] == 0 and row["gauss6"]["late"] == 0
        assert row["Tight-Inclusion"]["gave_up"] is None  # its answer does not say
    assert sum(row["queries"] for row in r["sets"]) == r["queries"] > 0
    assert "Tight-Inclusion" in peers.format_ccd(r)


def test_qp_peers_on_one_family():
    r = peers.run_qp(repeats=1, families=["box"], show_progress=False)
    (row,) = r["families"]
    assert row["instances"] > 0
    for name in ("gauss6", "DAQP", "quadprog", "proxsuite"):
        assert row[name]["failed"] == 0
    assert row["quadprog"]["max_diff_to_gauss6"] < 1e-9  # an exact active-set solver agrees to rounding
    assert "proxsuite" in peers.format_qp(r)


def test_cli_refuses_bad_arguments(capsys):
    assert cli.main(["report", "peers", "--sample", "0", "--out", str(paths.REPO_ROOT / "out" / "never")]) == 2
    assert "--sample" in capsys.readouterr().err
