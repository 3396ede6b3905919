"""`gauss6 report qp`: writes the time-against-error plot and table for every solver."""
from __future__ import annotations

import json
import subprocess
import sys


def test_report_qp_writes_plot_table_and_results(tmp_path):
    r = subprocess.run([sys.executable, "-m", "gauss6.cli", "report", "qp", "--out", str(tmp_path),
                        "--family", "m50"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    for name in ("time_vs_error.png", "time_vs_error.svg", "table.md", "results.json"):
        assert (tmp_path / name).stat().st_size > 0, name
    res = json.loads((tmp_path / "results.json").read_text())
    solvers = {s["solver"]: s for s in res["solvers"]}
    assert set(solvers) == {"gauss6 (cold)", "gauss6 (warm)", "OSQP (defaults)", "OSQP (1e-10, polished)",
                            "DAQP", "quadprog", "CGAL exact"}
    # The exact solver is the yardstick: its error is exactly zero.
    assert solvers["CGAL exact"]["max_err"] == 0.0
    # Ours on m = 50 instances: within the crosscheck's tolerance of the exact optimum.
    assert solvers["gauss6 (cold)"]["max_err"] <= 1e-9
    assert solvers["gauss6 (cold)"]["solved"] == res["instances"]
