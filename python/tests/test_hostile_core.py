"""Hostile inputs to the core: each accepted setting keeps every guarantee, or is refused
where it enters with a message naming it.

- the projection: its answer does not depend on how the rows are scaled (the feasible
  cone does not), it is exact against the reference on the row_scaled family, and
  lengths whose squares leave the doubles' range are refused by name, never "optimal";
- contact.delta: refused outside [1e-6, 1e-2] of the scene's extent, and the god-object
  slides at the floor; docs/scene-format.md states the code's bounds;
- coupling_force with kh <= 0, `ccd queries` with a time tolerance <= 0 and
  MeshPair.separation with an infinite max_distance: refused by name;
- mesh files holding more records than their headers state: refused, naming the line.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gauss6
from gauss6 import _gauss6, cli, crosscheck_qp, paths, qp_instances, qp_seeded

ROOT = paths.DATASETS_DIR.parent


# ---------------------------------------------------------------------------------------
# The projection


def test_row_scaled_family_is_exact_against_the_reference():
    """row_scaled (a subset: 30 instances of each family it draws from, both scalings)
    against the exact reference, to 1e-12 |au|_M: each answer is the exact projection to
    rounding whatever the rows' scales. The pairs (the same rows scaled twice) also agree
    with each other to 2e-12 (two answers each within 1e-12 of the same exact one)."""
    rng = np.random.default_rng(qp_instances.ROW_SCALED_SEED)
    instances = [x for name in qp_instances.family_names() if name not in qp_instances.ROW_SCALED_LEFT_OUT
                 for x in qp_instances.row_scaled(qp_instances.load_family(name)[:30], rng)]
    rep = crosscheck_qp.check_instances(qp_instances.ROW_SCALED, instances, with_osqp=False)
    assert rep.certificate_failures == 0, rep.failures[:5]
    assert rep.max_rel_err_ac <= 1e-12
    assert not crosscheck_qp.tolerance_failures([rep], crosscheck_qp.DEFAULT_TOLERANCE)
    worst = 0.0
    for a, b in zip(instances[0::2], instances[1::2]):
        ra, rb = gauss6.project(a.M, a.au, a.J, a.b), gauss6.project(b.M, b.au, b.J, b.b)
        assert ra.status == rb.status
        worst = max(worst, crosscheck_qp.m_norm(a.M, ra.ac - rb.ac) / (crosscheck_qp.m_norm(a.M, a.au) or 1.0))
    assert worst <= 2e-12


def test_seeded_row_scaled_chunks_are_pairs_of_scalings():
    chunk = qp_seeded.chunk_instances(qp_instances.ROW_SCALED, 3, 1, 20)
    assert len(chunk) == qp_seeded.chunk_size(qp_instances.ROW_SCALED, 20) == 20
    for a, b in zip(chunk[0::2], chunk[1::2]):
        assert a.id.endswith("/rows-a") and b.id.endswith("/rows-b")
        if a.num_rows:
            ratio = b.J[:, 0:6] / np.where(a.J == 0, 1, a.J)
            assert np.all(ratio[a.J != 0] > 0)  # positive factors only
    rep = crosscheck_qp.check_instances(qp_instances.ROW_SCALED, chunk, with_osqp=False)
    assert rep.certificate_failures == 0 and rep.max_rel_err_ac <= 1e-12


def test_crosscheck_holds_row_scaled_to_its_own_tolerance():
    """A row_scaled error of 1e-10 passes the command's 1e-9 elsewhere but not here."""
    rep = crosscheck_qp.FamilyReport(qp_instances.ROW_SCALED, count=1, max_rel_err_ac=1e-10)
    assert crosscheck_qp.tolerance_failures([rep], 1e-9)
    other = crosscheck_qp.FamilyReport("box", count=1, max_rel_err_ac=1e-10)
    assert not crosscheck_qp.tolerance_failures([other], 1e-9)


@pytest.mark.parametrize("what,make", [
    ("au", lambda J, au: (J, au * 1e155)),
    ("J", lambda J, au: (J * 1e160, au)),
    ("J", lambda J, au: (J * 1e-170, au)),
])
def test_projection_refuses_lengths_out_of_range_by_name(what, make):
    """|au| >= 1e155 was answered "optimal" with its row violated (the squares overflow)."""
    M = np.diag([2.0, 2, 2, 0.01, 0.01, 0.01])
    J = np.array([[0.0, 0, 1, 0, 0, 0]])
    au = np.array([0.3, 0, -1, 0, 0, 0])
    J, au = make(J, au)
    r = gauss6.project(M, au, J)
    assert r.status == "bad_input"
    assert r.problem.startswith(f"{what}:") and "1e-100, 1e100" in r.problem
    assert np.all(np.isfinite(r.ac))


def test_projection_answers_a_tiny_au_by_scaling_it():
    """|au|_M below 1e-100 (a god-object settling on a resting handle halves it every step)
    was refused; it is solved scaled up by a power of two: the answer is the ordinary
    one times the same power (exact), unless an offset beside it spans more than 1e200."""
    M = np.diag([2.0, 2, 2, 0.01, 0.01, 0.01])
    J = np.array([[0.0, 0, 1, 0, 0, 0], [0.0, 0.01, 0.9999, 0.001, 0, 0]])
    au = np.array([0.3, 0, -1, 0, 0.2, 0])
    ordinary = gauss6.project(M, au, J)
    assert ordinary.status == "optimal"
    for e in (-400, -1000):
        r = gauss6.project(M, np.ldexp(au, e), J)
        assert r.status == "optimal"
        assert np.allclose(r.ac, np.ldexp(ordinary.ac, e), rtol=1e-15, atol=0)
        assert np.allclose(r.lam, np.ldexp(ordinary.lam, e), rtol=1e-12, atol=0)
    far = gauss6.project(M, np.ldexp(au, -1000), J, b=np.array([-1e-3, 0.0]))
    assert far.status == "bad_input" and far.problem.startswith("au:")


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(au_exp=st.floats(-300, 300), row_exps=st.lists(st.floats(-300, 300), min_size=1, max_size=4),
       seed=st.integers(0, 2**32 - 1))
def test_projection_at_any_magnitude_is_right_or_refused(au_exp, row_exps, seed):
    """Magnitudes over the whole double range: the answer is "optimal" only when every row
    holds to the solver's feasibility tolerance in a scale-free form (slack over
    |J_k|_{M^-1} |au|_M), else the input is refused by name. Tolerance 1e-12: the solver
    meets each row to 1e-13 of that scale (feasibility_tol), plus rounding."""
    rng = np.random.default_rng(seed)
    M = np.diag([1.5, 1.5, 1.5, 0.02, 0.03, 0.04])
    J = rng.standard_normal((len(row_exps), 6)) * (10.0 ** np.array(row_exps))[:, None]
    au = rng.standard_normal(6) * 10.0 ** au_exp
    if not (np.all(np.isfinite(J)) and np.all(np.isfinite(au))):
        return
    r = gauss6.project(M, au, J)
    assert np.all(np.isfinite(r.ac))
    if r.status == "bad_input":
        assert r.problem.split(":")[0] in ("au", "J")
        return
    assert r.status == "optimal", r.status
    Minv = np.diag(1 / np.diag(M))
    for Jk in J:
        # Scaled first (a power of ten, exact enough): the scale-free slack without overflow.
        s = np.max(np.abs(Jk)) or 1.0
        a = np.max(np.abs(au)) or 1.0
        row_norm = math.sqrt((Jk / s) @ Minv @ (Jk / s))
        au_norm = max(math.sqrt((au / a) @ M @ (au / a)), 1e-300)
        slack = float((Jk / s) @ (r.ac / a))
        assert slack >= -1e-12 * row_norm * au_norm


def test_projection_certificate_tol_is_a_setting_in_range():
    s = gauss6.ProjectionSettings()
    assert s.certificate_tol == gauss6.defaults()["projection"]["certificate_tol"]
    s.certificate_tol = 0.0
    r = gauss6.project(np.eye(6), np.ones(6), np.zeros((0, 6)), settings=s)
    assert r.status == "bad_input" and r.problem.startswith("settings:")


def test_coupling_force_refuses_a_gain_that_is_not_positive():
    M, au, J = np.eye(6), np.array([0, 0, -0.01, 0, 0, 0.0]), np.array([[0, 0, 1.0, 0, 0, 0]])
    assert gauss6.coupling_force(M, au, J, 100.0)[2] > 0
    for kh in (-100.0, 0.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="kh must be finite and > 0"):
            gauss6.coupling_force(M, au, J, kh)


# ---------------------------------------------------------------------------------------
# contact.delta


def _cylinder_scene(tmp_path, delta: str):
    src = (ROOT / "datasets_generated" / "scenes" / "cylinder_plain.toml").read_text()
    src = src.replace('"../surfaces/', f'"{ROOT}/datasets_generated/surfaces/')
    src = re.sub(r"^delta = .*$", f"delta = {delta}", src, flags=re.M)
    path = tmp_path / f"cylinder_{delta}.toml"
    path.write_text(src)
    return path


def test_delta_out_of_its_range_is_refused_at_its_line(tmp_path):
    for delta, bound in (("1e-9", "at least 1e-6"), ("1e-14", "at least 1e-6"), ("0.5", "at most 1e-2"),
                         ("1e300", "at most 1e-2")):
        path = _cylinder_scene(tmp_path, delta)
        with pytest.raises(gauss6.LoadError, match=rf"{re.escape(path.name)}:\d+:\d+: contact.delta: must be {bound}"):
            _gauss6.load_scene(str(path))


def test_the_god_object_slides_at_the_smallest_delta_accepted(tmp_path):
    """Below 1e-7 of its extent the probe stopped on the cylinder (no sideways force, no
    event) while the hand moved on; at the floor (1e-6 of the extent) it follows the hand
    as at the scene's own delta (1e-6, 20 times the floor): the same travel to 1 mm of its
    6 cm, the same path to 3 mm (crossing an edge of the prism, the two bands let go of a
    facet a few steps apart; measured 1.2 mm)."""
    from gauss6.trace import read_trace

    extent = _gauss6.scene_summary(_gauss6.load_scene(str(_cylinder_scene(tmp_path, "1e-6"))))["extent"]
    floor = gauss6.defaults()["contact"]["min_delta_per_extent"] * extent
    paths_xs = []
    for delta in ("1e-6", repr(floor * (1 + 1e-9))):
        scene = _cylinder_scene(tmp_path, delta)
        trace = tmp_path / f"{delta}.g6trace"
        _gauss6.runtime.run_scenario(str(scene), str(trace), duration=4.0)
        paths_xs.append(read_trace(trace).ticks["xs_p"])
    travel = np.ptp(paths_xs[1][:, 0])
    assert travel > 0.05, f"the god-object moved {travel:.3g} m along x"
    assert abs(travel - np.ptp(paths_xs[0][:, 0])) < 1e-3
    assert np.max(np.abs(paths_xs[1] - paths_xs[0])) < 3e-3


def test_scene_format_states_the_code_s_delta_range():
    """docs/scene-format.md's [contact] rule row states check_delta_scale's constants."""
    doc = (ROOT / "docs" / "scene-format.md").read_text()
    row = next(line for line in doc.splitlines() if line.startswith("| `[contact]` |"))
    m = re.search(r"between ([0-9.e+-]+) and ([0-9.e+-]+) of the scene's extent.*at least ([0-9.e+-]+)", row)
    assert m, row
    c = gauss6.defaults()["contact"]
    assert (float(m.group(1)), float(m.group(2)), float(m.group(3))) == (
        c["min_delta_per_extent"], c["max_delta_per_extent"], c["min_delta"])


# ---------------------------------------------------------------------------------------
# CCD settings and distances


def test_ccd_queries_refuse_a_time_tolerance_that_is_not_positive(tmp_path, capsys):
    """A tolerance of 0 made every query an invalid input, counted as a miss (false negatives)."""
    folder = tmp_path / "vertex-face"
    folder.mkdir()
    # One query of the shared format: 8 points of 6 rationals (numerator, denominator), then
    # the expected answer; a vertex crossing a face (a hit).
    pts = [(0, 0, 1), (-1, -1, 0), (1, -1, 0), (0, 1, 0), (0, 0, -1), (-1, -1, 0), (1, -1, 0), (0, 1, 0)]
    lines = [",".join(f"{v},1" for v in p) + ",1" for p in pts]
    (folder / "q.csv").write_text("\n".join(lines) + "\n")
    for bad in ("0", "-1e-6", "nan", "inf"):
        rc = cli.main(["ccd", "queries", str(folder / "q.csv"), "--kind", "vf", "--impl", "optimized",
                       f"--time-tolerance={bad}"])
        err = capsys.readouterr().err
        assert rc == 2 and "time_tolerance must be finite and > 0" in err, (bad, err)
    assert cli.main(["ccd", "queries", str(folder / "q.csv"), "--kind", "vf", "--impl", "optimized"]) == 0


def test_separation_refuses_an_infinite_max_distance():
    """max_distance=inf killed the process (SIGFPE inside GMP's conversion of inf)."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    pair = _gauss6.ccd.MeshPair(V, F, V * 0.1, F)
    q = np.array([1.0, 0, 0, 0])
    for bad in (math.inf, math.nan, -1.0):
        with pytest.raises(ValueError, match="max_distance must be finite and >= 0"):
            pair.separation(np.array([0, 0, 3.0]), q, bad)
    assert pair.separation(np.array([0, 0, 3.0]), q, 10.0)["within"]


# ---------------------------------------------------------------------------------------
# Mesh files


def test_an_off_file_holding_more_faces_than_stated_is_refused(tmp_path):
    path = tmp_path / "more.off"
    path.write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n")
    with pytest.raises(gauss6.LoadError, match=r"more.off.*line 8: more records than the header states"):
        _gauss6.read_mesh(str(path))
