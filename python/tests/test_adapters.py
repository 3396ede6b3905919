"""The third-party engine adapters (python/gauss6/adapters): short smoke runs, a few hundred
ticks each (marked `adapters`: about 30 s together on the 2-core machine; the full runs
are `gauss6 reproduce engines`), the frames and signs of their wrenches, the config
errors, and the convex parts they collide with.
"""
from __future__ import annotations

import numpy as np
import pytest

from gauss6 import adapters
from gauss6.adapters import common
from gauss6.engine import EngineScene
from gauss6.oracle import quat_mul, rotation_matrices
from gauss6.paths import DATASETS_DIR

PEG = DATASETS_DIR / "scenes" / "peg_in_hole.toml"
BUNNIES = DATASETS_DIR / "scenes" / "bunnies.toml"
ENGINES = [pytest.param(name, marks=[pytest.mark.adapters,
                                     pytest.mark.skipif(not adapters.available(name), reason=f"{name} not installed")])
           for name in adapters.FACTORIES]


@pytest.fixture(scope="module")
def peg():
    return EngineScene.from_scene_file(PEG)


@pytest.fixture(scope="module")
def bunnies():
    return EngineScene.from_scene_file(BUNNIES)


# Rapier pushes the peg while it is 6 mm or more above the box (its contact manifolds with the
# box's triangle mesh, at 0.3 s of this motion): the wrench is then off by 0.24 N and 9.5 mN m.
# Without the box its wrench is the inertial reaction to 1e-4 (python/tests/test_battery.py).
FREE_MOTION_ENGINES = [pytest.param(p.values[0], marks=[*p.marks, pytest.mark.xfail(
    reason="Rapier's contact force at a distance from the box", strict=True)]) if p.values[0] == "rapier" else p
    for p in ENGINES]


@pytest.mark.parametrize("name", FREE_MOTION_ENGINES)
def test_free_motion_wrench_is_the_tools_inertial_reaction(name, peg):
    """In free space the handle accelerates (1 m/s^2 along x) and turns (2 rad/s^2 about an
    oblique axis); the tool follows, and the wrench the user feels is -(M a + w x I w) of the
    tool, in the world frame about G. The peg: a rotated tool (90 degrees about x) with
    unequal moments, so that a frame or sign slip shows (the same test on the bunnies, a full
    inertia tensor, passes too; its Drake model takes 20 s to build). Tolerance 5%: the
    couplings settle within 0.3 s (time constants of 5-20 ms), what is left is their lag."""
    s = peg
    engine = adapters.FACTORIES[name]("")
    engine.reset(s)
    axis = np.array([0.3, 0.5, 0.8]) / np.linalg.norm([0.3, 0.5, 0.8])
    a, alpha = 1.0, 2.0
    for k in range(400):
        t = k / s.rate_hz
        ang = 0.5 * alpha * t * t
        q = quat_mul(np.concatenate([[np.cos(ang / 2)], np.sin(ang / 2) * axis]), s.tool.q)
        out = engine.step(t, s.tool.p + [0.5 * a * t * t, 0, 0], q)
        assert np.all(np.isfinite(out.wrench)) and np.all(np.isfinite(out.xs_p))
    R = rotation_matrices(out.xs_q)[0]
    I_W = R @ s.inertia_G_B @ R.T
    w = alpha * t * axis
    expect_f = -s.mass * np.array([a, 0, 0])
    expect_tau = -(I_W @ (alpha * axis) + np.cross(w, I_W @ w))
    assert np.linalg.norm(out.wrench[:3] - expect_f) <= 0.05 * np.linalg.norm(expect_f)
    assert np.linalg.norm(out.wrench[3:] - expect_tau) <= 0.05 * np.linalg.norm(expect_tau)


@pytest.mark.parametrize("name", ENGINES)
def test_pressing_on_the_box_pushes_back(name, peg):
    """The peg script's first 700 ticks: the hand lowers the tilted peg onto the box's top
    (first touch near 0.4 s) and presses 1 cm past it. Each engine must push the hand up
    (a force of at least 0.5 N along +z: the grip spring alone gives about 5 N at 1 cm),
    keep its pose and wrench finite, and not let the peg sink into the box: the peg's
    lowest vertex stays above the box's top (z = 3 cm) minus 2 mm (a bound for soft
    contacts, far less than the 1 cm the hand goes past)."""
    from gauss6.driver import drive, scene_script

    text, _ = scene_script(PEG)
    engine = adapters.FACTORIES[name]("")
    tr = drive(engine, peg, text, _tmp_trace(name), duration=0.7)
    ticks = tr.ticks
    assert np.all(np.isfinite(ticks["wrench"])) and np.all(np.isfinite(ticks["xs_p"]))
    assert ticks["wrench"][:, 2].max() > 0.5
    lowest = min(((rotation_matrices(q)[0] @ peg.tool.V.T).T + p)[:, 2].min()
                 for p, q in zip(ticks["xs_p"][::10], ticks["xs_q"][::10]))
    assert lowest > 0.03 - 2e-3


def _tmp_trace(name):
    import tempfile
    from pathlib import Path

    return Path(tempfile.mkdtemp(prefix=f"gauss6-adapter-{name}-")) / "run.g6trace"


@pytest.mark.parametrize("name", ENGINES)
def test_config_errors_name_the_key(name):
    with pytest.raises(ValueError, match="nonsense"):
        adapters.FACTORIES[name]("nonsense=1")
    key = next(iter(__import__(f"gauss6.adapters.{name}_engine", fromlist=["DEFAULTS"]).DEFAULTS))
    with pytest.raises(ValueError, match=key):
        adapters.FACTORIES[name](f"{key}=abc")


def test_parse_config():
    d = {"a": 1.0, "b": 2, "c": "x"}
    assert common.parse_config("a=3, b=4 c=y", d) == {"a": 3.0, "b": 4, "c": "y"}
    assert common.parse_config("", d) == d
    for bad in ("a", "a=nan", "b=1.5", "z=1"):
        with pytest.raises(ValueError):
            common.parse_config(bad, d)


def test_committed_convex_parts_are_convex_and_inside_the_mesh(peg, bunnies):
    """Each scene mesh has its committed part set (so no run waits for CoACD); each part is a
    closed convex polyhedron (every vertex on the inner side of every face plane, to 1e-9 m)
    and lies within the mesh's box grown by 1 mm (CoACD's parts are hulls of pieces of the
    mesh: they cannot leave it by more than its remeshing error, 1/50 of the size at most)."""
    for s in (peg, bunnies):
        for b in s.obstacles + [s.tool]:
            path = common.convex_parts_file(b.V, b.F)
            assert path.parent == common.COMMITTED_PARTS, f"{s.name}:{b.name} has no committed convex parts"
            lo, hi = b.V.min(axis=0) - 1e-3, b.V.max(axis=0) + 1e-3
            for v, f in common.convex_parts(b.V, b.F):
                assert np.all(v >= lo) and np.all(v <= hi)
                A, B, C = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
                n = np.cross(B - A, C - A)
                n /= np.linalg.norm(n, axis=1, keepdims=True)
                side = np.einsum("fk,vfk->vf", n, v[:, None, :] - A[None])
                assert side.max() <= 1e-9 or (-side).max() <= 1e-9  # all on one side (either orientation)


@pytest.mark.adapters
def test_convex_parts_are_reproducible(peg, tmp_path):
    """CoACD with the fixed seed makes byte-identical parts: the box with the hole (8 parts,
    about 20 s) remade into a temporary folder equals the committed file."""
    gen = common.generator
    box = peg.obstacles[0]
    path = gen.generate(box.V, box.F, tmp_path, source=f"{peg.name}:{box.name}")
    assert path.read_bytes() == common.convex_parts_file(box.V, box.F).read_bytes()
