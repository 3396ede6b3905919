"""Any number of simultaneous contacts: `gauss6.project` on 200 and 1,000 rows, redundant
and not, against the exact reference.

The instances are the seeded many-row families of gauss6.qp_seeded (contact rows on a
box or the peg, push labels all and some; redundant: 8-30 distinct rows and their
copies). Each goes through the same judgement as `gauss6 crosscheck qp`: the exact
certificate of the optimized active set, a full exact solve (CGAL, no row limit) where
the certificate is near-degenerate, and on a sample. Tolerance: 1e-9 relative in the
M-norm (the crosscheck's), since errors above it would mean a wrong active set.
"""
from __future__ import annotations

import numpy as np
import pytest

import gauss6
from gauss6 import _gauss6, crosscheck_qp, qp_seeded


@pytest.mark.parametrize("family", ["m200", "redundant_m200", "m1000", "redundant_m1000"])
def test_many_rows_against_the_exact_reference(family):
    instances = qp_seeded.chunk_instances(family, seed=1, index=0, size=4)
    m = qp_seeded.MANY_ROWS[family][1]
    assert [i.num_rows for i in instances] == [m] * 4
    rep = crosscheck_qp.check_instances(family, instances, with_osqp=False)
    assert rep.certificate_failures == 0, rep.failures
    assert rep.statuses["optimal"] == 4
    assert rep.max_rel_err_ac <= 1e-9 and rep.max_rel_err_force <= 1e-9
    # A full exact solve of one instance agrees (the exact QP takes any number of rows).
    inst = instances[1]
    exact = _gauss6.reference.project(inst.M, inst.au, inst.J, inst.b)
    assert exact["status"] == "optimal"
    ac = gauss6.project(inst.M, inst.au, inst.J, inst.b).ac
    assert crosscheck_qp.m_norm(inst.M, ac - np.asarray(exact["ac"])) <= 1e-9 * crosscheck_qp.m_norm(inst.M, inst.au)


def test_projector_grows_for_more_rows_and_keeps_answering():
    """A Projector built for the default 64 rows takes 200 (it resizes at the Python edge)."""
    small = qp_seeded.chunk_instances("box", seed=2, index=0, size=12)[5]
    big = qp_seeded.chunk_instances("m200", seed=2, index=0, size=1)[0]
    p = gauss6.Projector()
    for inst in (small, big, small):
        r = p.project(inst.M, inst.au, inst.J, inst.b)
        cold = gauss6.project(inst.M, inst.au, inst.J, inst.b)
        assert r.status == "optimal" and len(r.lam) == inst.num_rows
        assert crosscheck_qp.m_norm(inst.M, r.ac - cold.ac) <= 1e-12 * crosscheck_qp.m_norm(inst.M, inst.au)


def test_runtime_contact_capacity_from_python(tmp_path):
    """run_scenario's max_contacts is the runtime's contact capacity (RuntimeSettings::max_contacts):
    the peg's first 8 s hold sets of up to 3 contacts; at capacity 1 they are truncated and
    reported (contact_overflow), at the default (64) they are not; a capacity out of
    [1, 100000] is refused by name. (More than 64 contacts through the loops: the C++
    test "more than 64 contacts: a capacity of 256 carries them all to the coupling".)"""
    from gauss6 import reproduce

    runtime = _gauss6.runtime
    peg = str(reproduce.SCENES["peg"])
    full = runtime.run_scenario(peg, str(tmp_path / "full.g6trace"), duration=8.0)
    one = runtime.run_scenario(peg, str(tmp_path / "one.g6trace"), duration=8.0, max_contacts=1)
    assert "contact_overflow" not in full["sim"]["events"]
    assert one["sim"]["events"].get("contact_overflow", 0) >= 1
    assert one["rows_written"][2] < full["rows_written"][2]  # fewer contact rows traced
    with pytest.raises(ValueError, match="max_contacts"):
        runtime.run_scenario(peg, str(tmp_path / "x.g6trace"), duration=0.1, max_contacts=0)
