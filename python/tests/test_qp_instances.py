"""The projection-instance families (datasets_generated/qp/): reproducible from their seeds,
true push labels, documented sizes, sound offset certificates, and one reading in Python and C++."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gauss6 import qp_instances as qp

# Family -> (instances, smallest m, largest m), as documented in datasets_generated/qp/README.md.
SIZES = {
    "box": (300, 1, 12), "peg": (300, 1, 12), "bunny": (300, 1, 12), "m50": (80, 50, 50),
    "redundant": (240, 3, 50), "inertia": (200, 1, 12), "offsets": (200, 1, 12), "warm": (1000, 1, 5),
}


@pytest.fixture(scope="module", params=sorted(SIZES))
def family(request):
    return request.param, qp.load_family(request.param)


def test_family_names():
    assert sorted(qp.family_names()) == sorted(SIZES)


def test_regeneration_matches_manifest():
    assert qp.check_all() == []


def test_sizes_as_documented(family):
    name, instances = family
    count, m_lo, m_hi = SIZES[name]
    assert len(instances) == count
    ms = [q.num_rows for q in instances]
    assert (min(ms), max(ms)) == (m_lo, m_hi)
    assert len({q.id for q in instances}) == count
    if name == "warm":
        assert sorted({q.sequence for q in instances}) == list(range(20))
        for s in range(20):
            assert [q.step for q in instances if q.sequence == s] == list(range(50))
    else:
        assert all(q.sequence == -1 and q.step == -1 for q in instances)


def test_push_labels_are_true(family):
    # Exact signs of J au as numpy computes it; the generator keeps every |J_k au| above
    # 1e-9 sum_i |J_ki au_i|, so the label does not hinge on rounding.
    _, instances = family
    for q in instances:
        d = q.J @ q.au
        if q.push == "all":
            assert np.all(d < 0), q.id
        elif q.push == "none":
            assert np.all(d >= 0), q.id
        else:
            assert q.push == "some" and np.any(d < 0) and np.any(d >= 0), q.id


def test_mass_matrices_and_rows(family):
    name, instances = family
    for q in instances:
        assert np.array_equal(q.M, q.M.T), q.id
        assert np.linalg.eigvalsh(q.M).min() > 0, q.id
        assert np.all(np.linalg.norm(q.J, axis=1) > 0), q.id
        if name != "offsets":
            assert not np.any(q.b), q.id
        if name not in ("redundant", "offsets"):
            # Contact rows: unit normal, torque part orthogonal to it (r x n . n = 0);
            # 1e-12 covers the rounding of a normalised 3-vector and a cross product.
            n = q.J[:, :3]
            assert np.allclose(np.linalg.norm(n, axis=1), 1, rtol=0, atol=1e-12), q.id
            dots = np.abs(np.einsum("ij,ij->i", n, q.J[:, 3:]))
            assert np.all(dots <= 1e-12 * np.linalg.norm(q.J[:, 3:], axis=1) + 1e-300), q.id


def test_offset_certificates():
    kinds = {"ramp": 0, "positive": 0, "infeasible": 0}
    for q in qp.load_family("offsets"):
        t = q.tags
        kinds[t["kind"]] += 1
        if t["feasible"]:
            # The witness satisfies every row (the generator leaves a 5% slack on b).
            w = np.array(t["witness"])
            assert np.all(q.J @ w >= q.b), q.id
        else:
            # Farkas: y >= 0, y^T J = 0 exactly (an exact opposite row), y^T b > 0.
            y = np.array(t["farkas_y"])
            assert np.all(y >= 0) and not np.any(y @ q.J) and y @ q.b > 0, q.id
        if t["kind"] == "ramp":
            # b_k = f_k(t) in [d_k, 0] (METHOD.md section 3): never positive; some row still
            # offset unless the ramp is over (t = T).
            assert np.all(q.b <= 0) and (t["t_over_T"] == 1 or np.any(q.b < 0)), q.id
        if t["kind"] == "positive":
            assert np.any(q.b > 0), q.id
    assert kinds == {"ramp": 120, "positive": 60, "infeasible": 20}


def test_redundant_rows_come_from_the_base_rows():
    # Each row is a positive multiple of a base row (duplicate, x0.5, x3), a perturbation
    # of one by at most 1e-6 relative, or the average of two: its distance to the nearest
    # such candidate is <= 1e-6 |row| (the largest perturbation) plus rounding (1e-8 spare).
    tol = 1e-6 * (1 + 1e-2)
    for q in qp.load_family("redundant"):
        base = q.J[q.tags["base_rows"]]
        assert len(base) == q.tags["distinct"]
        pairs = [0.5 * (base[i] + base[j]) for i in range(len(base)) for j in range(i + 1, len(base))]
        for k, row in enumerate(q.J):
            c = np.maximum(base @ row / np.einsum("ij,ij->i", base, base), 0)
            dist = np.linalg.norm(row - c[:, None] * base, axis=1).min()
            if pairs:
                dist = min(dist, np.linalg.norm(np.array(pairs) - row, axis=1).min())
            assert dist <= tol * np.linalg.norm(row), (q.id, k)


def test_inertia_ratios():
    ratios = {}
    for q in qp.load_family("inertia"):
        ev = np.linalg.eigvalsh(q.M[3:, 3:])
        # The box's ratio (L^2 + w^2) / (2 w^2) is the target up to rounding of L and w; the
        # rotation and eigvalsh err by ~1e-16 of the largest eigenvalue, i.e. ~1e-10 relative
        # on the smallest at a 1e6 ratio: 1e-6 is a generous bound that still sees a wrong body.
        assert ev[-1] / ev[0] == pytest.approx(q.tags["inertia_ratio_target"], rel=1e-6), q.id
        ratios[q.tags["inertia_ratio_target"]] = ratios.get(q.tags["inertia_ratio_target"], 0) + 1
    assert ratios == {1.0: 50, 1e2: 50, 1e4: 50, 1e6: 50}


def test_readers_agree(family):
    # With the extension's C++ reader, compare it number by number with the Python
    # reader; without it, compare the Python reader with a plain json.load.
    name, instances = family
    path = qp.FAMILIES_DIR / f"{name}.json"
    try:
        from gauss6 import _gauss6
        cpp_read = getattr(_gauss6, "read_qp_instances", None)
    except ImportError:
        cpp_read = None
    if cpp_read is not None:
        other = [dict(id=r.id, M=r.M, au=r.au, J=r.J, b=r.b, push=r.push) for r in cpp_read(str(path))]
    else:
        other = json.loads(path.read_text())["instances"]
    assert len(other) == len(instances)
    for q, r in zip(instances, other):
        assert q.id == r["id"] and q.push == r["push"]
        for key in ("M", "au", "b"):
            assert np.array_equal(getattr(q, key), np.array(r[key], dtype=float)), (q.id, key)
        assert np.array_equal(q.J, np.array(r["J"], dtype=float).reshape(-1, 6)), q.id


def test_malformed_files_are_rejected(tmp_path):
    good = {"id": "t", "M": np.eye(6).tolist(), "au": [0.0] * 6, "J": [[0, 0, 1, 0, 0, 0]], "b": [0.0],
            "push": "none", "sequence": -1, "step": -1}
    doc = {"format": qp.FORMAT, "version": 1, "instances": [good]}
    ok = tmp_path / "ok.json"
    ok.write_text(json.dumps(doc))
    assert len(qp.load_family(ok)) == 1
    bad = [
        {**doc, "format": "other"},
        {**doc, "version": 2},
        {**doc, "instances": [{**good, "b": [0.0, 0.0]}]},
        {**doc, "instances": [{**good, "J": [[0, 0, 1, 0, 0]]}]},
        {**doc, "instances": [{**good, "au": ["x"] * 6}]},
        {**doc, "instances": [{**good, "push": "most"}]},
        {**doc, "instances": [{**good, "step": 1.5}]},
        {**doc, "instances": [{k: v for k, v in good.items() if k != "M"}]},
    ]
    texts = [json.dumps(d) for d in bad] + ['{"format": ']
    for i, text in enumerate(texts):
        p = tmp_path / f"bad{i}.json"
        p.write_text(text)
        with pytest.raises(ValueError, match=str(p)):
            qp.load_family(p)
