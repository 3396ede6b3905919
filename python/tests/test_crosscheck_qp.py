"""`gauss6 crosscheck qp`: the optimized projection agrees with the exact reference
(certificate on every instance, exact solve on a sample) and with OSQP, on every family.

Tolerance: 1e-9 relative in the M-norm (the command's default). The solver's own
feasibility tolerance is 1e-13 relative and its dependence tolerance 1e-13 or the
rounding of W's sines (see quasistatics.h); errors above 1e-9 would mean a wrong active set, not rounding.
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from gauss6 import qp_instances


def test_crosscheck_qp_json_form_and_verdict():
    r = subprocess.run([sys.executable, "-m", "gauss6.cli", "crosscheck", "qp", "--json"],
                       capture_output=True, text=True)
    result = json.loads(r.stdout)
    assert list(result) == ["ok", "tolerance", "families"]
    assert result["tolerance"] == 1e-9
    names = [f["name"] for f in result["families"]]
    assert names == qp_instances.crosscheck_family_names()
    for f in result["families"]:
        assert list(f) == ["name", "count", "max_rel_err_ac", "max_rel_err_force", "max_kkt_residual",
                           "certificate_failures", "osqp_max_rel_err_ac", "statuses"]
        assert f["count"] > 0
        assert f["certificate_failures"] == 0, (f["name"], r.stderr[-2000:])
        assert f["max_rel_err_ac"] <= 1e-9 and f["max_rel_err_force"] <= 1e-9
        # OSQP is a peer, reported and not judged (its polish fails on jammed,
        # ill-conditioned instances); it must at least have produced a number.
        assert f["osqp_max_rel_err_ac"] >= 0.0
    assert result["ok"] and r.returncode == 0, r.stderr[-2000:]


def test_crosscheck_fails_on_a_planted_error(nudged_projection):
    """The check can fail: a solver whose answer is nudged off the optimum is caught."""
    from gauss6 import crosscheck_qp

    result, failures, _ = crosscheck_qp.crosscheck(["box"], with_osqp=False, show_progress=False)
    assert not result["ok"]
    assert any("max_rel_err_ac" in f for f in failures)


# Seeded campaign instances (qp_seeded "redundant", seed 1, rows perturbed by 1e-10) that
# failed once: iteration caps, certificate failures, forward errors of 5e-9..1.1e-6, rows
# left violated by 1e-12..4e-2 of their scale after a dependence test on the rounded
# span of an ill-conditioned working set, and jammed bodies (ac = 0) whose working set's
# own multipliers had a negative entry; and a box and a peg instance (families "box",
# "peg") whose rows J holds exactly dependent, which a dependence test without the rows'
# own rounding let into the working set (the C++ suite's "regression: seeded campaign
# instances ..." has the causes). Every one is now certified exactly, or by a backward
# error within the checker's tolerance, and the solver's own multipliers are dual
# feasible: the jammed bodies' working sets had exact multipliers down to -0.24 against
# |M au| = 0.0024 (relative KKT residual 98); nonnegative multipliers over the tight rows
# now replace them. Tolerances: the multipliers within 64 eps |M au|_inf of >= 0 (they
# come out >= 0 exactly); stationarity within 64 eps (|M au|_inf + sum lambda_k |J_k|_inf),
# the rounding of the sum J^T lambda it measures: a jammed body's multipliers of 1e7..2e8
# have ulps that alone give relative_kkt 2e-7..3e-4 against |M au| ~ 1e-3.
def test_seeded_regressions():
    from pathlib import Path

    from gauss6 import _gauss6, crosscheck_qp

    path = Path(__file__).resolve().parents[2] / "optimized/tests/data/qp_seeded_regressions.json"
    instances = qp_instances.load_family(path)
    assert len(instances) == 26
    for inst in instances:
        res = _gauss6.project(inst.M, inst.au, inst.J, inst.b)
        assert res.status == "optimal", inst.id
        rep = crosscheck_qp.FamilyReport("redundant")
        crosscheck_qp.check_instance(rep, inst, res, 0, with_osqp=False)  # index 0: with a full exact solve
        assert rep.failures == [], inst.id
        assert rep.max_rel_err_ac <= 1e-12 and rep.max_rel_err_force <= 1e-9, inst.id
        # A multiplier of the force's size has a rounding of a few dozen ulps of it.
        force_scale = float(np.abs(inst.M @ inst.au).max())
        assert res.dual_infeasibility <= 64 * np.finfo(float).eps * force_scale, inst.id
        lam = np.asarray(res.lam)[:len(inst.J)]
        sum_scale = force_scale + float(np.abs(lam) @ np.abs(inst.J).max(axis=1))
        assert res.stationarity <= 64 * np.finfo(float).eps * sum_scale, inst.id
