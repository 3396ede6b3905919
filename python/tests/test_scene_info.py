"""`gauss6 scene info`: its exact JSON form on both generated scenes, and clear errors for bad scenes."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from gauss6 import paths

BODY_KEYS = ["name", "role", "triangles", "vertices", "closed", "manifold", "self_intersections",
             "mass", "center_of_mass", "inertia", "bbox_min", "bbox_max"]

SCENES = {"peg": paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml",
          "bunny": paths.DATASETS_DIR / "scenes" / "bunnies.toml"}


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gauss6.cli", *args], capture_output=True, text=True)


@pytest.mark.parametrize("scene,obstacle_tris,god_tris", [
    ("peg", 280, 288),
    ("bunny", None, None),
])
def test_scene_info_json_form(scene, obstacle_tris, god_tris):
    r = run_cli("scene", "info", str(SCENES[scene]), "--json")
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert list(info) == ["scene", "bodies"]
    roles = [b["role"] for b in info["bodies"]]
    assert roles.count("god_object") == 1 and roles.count("obstacle") >= 1
    for b in info["bodies"]:
        assert list(b) == BODY_KEYS
        assert b["closed"] and b["manifold"] and b["self_intersections"] == 0
        assert b["mass"] > 0
        inertia = np.array(b["inertia"])
        # Symmetric positive definite (rounding: 1e-12 relative).
        assert np.allclose(inertia, inertia.T, rtol=0, atol=1e-12 * np.abs(inertia).max())
        assert np.linalg.eigvalsh(inertia).min() > 0
        lo, hi = np.array(b["bbox_min"]), np.array(b["bbox_max"])
        assert np.all(lo < hi)
        # The centre of mass of a closed body lies inside its bounding box.
        com = np.array(b["center_of_mass"])
        assert np.all(lo <= com) and np.all(com <= hi)
    god = next(b for b in info["bodies"] if b["role"] == "god_object")
    obstacles = [b for b in info["bodies"] if b["role"] == "obstacle"]
    if god_tris is not None:
        assert god["triangles"] == god_tris
        assert obstacles[0]["triangles"] == obstacle_tris
    else:
        assert 26000 <= god["triangles"] <= 28000
        assert all(26000 <= b["triangles"] <= 28000 for b in obstacles)


def test_self_intersection_check_can_be_skipped():
    # The scene summary must at least place the god-object somewhere finite.
    r = run_cli("scene", "info", str(SCENES["peg"]), "--json", "--no-self-intersections")
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert all(b["self_intersections"] == -1 for b in info["bodies"])
    assert all(np.isfinite(b["bbox_min"]).all() for b in info["bodies"])


def test_bad_scene_is_a_clear_error(tmp_path):
    text = SCENES["peg"].read_text().replace("[gains]", "[gains]\nbogus = 1", 1)
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    r = run_cli("scene", "info", str(bad))
    assert r.returncode != 0
    assert "bad.toml" in r.stderr and "gains.bogus: unknown key" in r.stderr


def test_missing_scene_file_is_a_clear_error(tmp_path):
    r = run_cli("scene", "info", str(tmp_path / "absent.toml"))
    assert r.returncode != 0
    assert "absent.toml" in r.stderr


def test_python_mesh_api_matches_closed_forms():
    from gauss6 import mass_properties, validate_mesh
    # Unit cube, outward triangles.
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                  [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]], np.int32)
    rep = validate_mesh(V, F, self_intersections=True)
    assert rep.closed and rep.manifold and rep.num_self_intersections == 0 and rep.ok()
    mp = mass_properties(V, F, 3.0)
    assert mp["mass"] == pytest.approx(3.0, rel=1e-14)
    assert np.allclose(mp["center_of_mass"], 0.5, atol=1e-15)
    assert np.allclose(mp["inertia"], np.eye(3) * 3.0 * 2 / 12, atol=1e-14)
    # An open mesh is reported, not accepted.
    rep = validate_mesh(V, F[:-1])
    assert not rep.closed and rep.num_boundary_edges == 3 and not rep.ok()


@pytest.mark.parametrize("scene", ["peg", "bunny"])
def test_scene_info_effective_settings(scene):
    """The settings a run uses, derived from the scene's delta as runtime_model.h states.
    Exact equality: each is one product of delta by a constant, computed the same way
    (doubles) on both sides; 0.2 delta is added after delta (1 + contact_factor)."""
    r = run_cli("scene", "info", str(SCENES[scene]), "--json", "--settings", "--no-self-intersections")
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert list(info) == ["scene", "bodies", "effective_settings"]
    s = info["effective_settings"]
    d = s["delta"]
    assert d > 0
    assert s["ccd"]["min_separation"] == d
    assert s["ccd"]["distance_tolerance"] == 0.1 * d
    assert s["ccd"]["cache_margin"] == 64 * d and s["ccd"]["cache_margin_max"] == 256 * d
    contact_distance = d * (1 + s["contacts"]["contact_factor"])
    assert s["contacts"]["distance"] == contact_distance
    assert s["ccd"]["near_distance"] == contact_distance + 0.2 * d
    # Not derived from delta: the C++ defaults (gauss6.defaults()).
    import gauss6
    shipped = gauss6.defaults()
    assert s["ccd"]["time_tolerance"] == shipped["ccd"]["time_tolerance"]
    assert s["projection"]["feasibility_tol"] == shipped["projection"]["feasibility_tol"]
    # The text form lists them too.
    text = run_cli("scene", "info", str(SCENES[scene]), "--no-self-intersections")
    assert text.returncode == 0 and "effective settings (delta = " in text.stdout


def test_scene_info_texture_speed_bound():
    """A textured scene's effective settings state the method's sampling bound (METHOD.md 6.2):
    a texture of shortest wavelength L is felt up to the exploration speed L f / 2 at a constraint
    update rate f (the default lockstep runs update every tick, so f is the device's rate). The
    scene's own numbers are read back from its TOML; a plain scene has no texture group."""
    import tomllib

    path = SCENES["peg"].parent / "texture_slow.toml"
    toml = tomllib.loads(path.read_text())
    r = run_cli("scene", "info", str(path), "--json", "--settings", "--no-self-intersections")
    assert r.returncode == 0, r.stderr
    t = json.loads(r.stdout)["effective_settings"]["texture"]
    L, f = toml["surface"]["wavelength"], toml["device"]["rate_hz"]
    assert t["shortest_wavelength"] == L and t["sim_rate_hz"] == f
    assert t["max_exploration_speed"] == 0.5 * L * f
    r = run_cli("scene", "info", str(SCENES["peg"]), "--json", "--settings", "--no-self-intersections")
    assert "texture" not in json.loads(r.stdout)["effective_settings"]
