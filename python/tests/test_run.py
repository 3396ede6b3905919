"""Tests of `gauss6 run` (gauss6.run): a scene that is not the repository's, made here from meshes the
test writes (a cube pressed on and slid over a wavy plate), with its own hand script in the scene
file, run through the command to a certified report; another hand script from a JSON file given
with --script; bad scripts refused before the run with an error naming the file and the key.
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from gauss6 import cli_args, run as run_mod
from gauss6.trace import read_trace

pytest.importorskip("gauss6._gauss6")


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gauss6.cli", *args], capture_output=True, text=True)


def write_off(path, V, F) -> None:
    path.write_text(f"OFF\n{len(V)} {len(F)} 0\n" + "".join(" ".join(repr(float(x)) for x in v) + "\n" for v in V)
                    + "".join("3 " + " ".join(str(int(i)) for i in f) + "\n" for f in F))


def cube(half: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed, outward cube centred on the origin."""
    V = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)])
    F = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
         [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return V, np.array(F)


def wavy_plate(size: float, n: int, amplitude: float, wavelength: float, thickness: float):
    """A closed, outward slab over [-size/2, size/2]^2 (x, y) whose top is z = A sin(2 pi x / L) and bottom
    z = -thickness: an n x n grid on each face, the sides stitched along the boundary."""
    xs = np.linspace(-size / 2, size / 2, n + 1)
    top = np.array([[x, y, amplitude * np.sin(2 * np.pi * x / wavelength)] for y in xs for x in xs])
    bottom = np.array([[x, y, -thickness] for y in xs for x in xs])
    V = np.vstack([top, bottom])
    nb = len(top)

    def vid(i, j):  # column i (x), row j (y) of the top grid
        return j * (n + 1) + i

    F = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)
            F += [[a, b, c], [a, c, d], [a + nb, c + nb, b + nb], [a + nb, d + nb, c + nb]]
    ring = ([vid(i, 0) for i in range(n)] + [vid(n, j) for j in range(n)] + [vid(i, n) for i in range(n, 0, -1)]
            + [vid(0, j) for j in range(n, 0, -1)])  # counter-clockwise seen from +z
    for a, b in zip(ring, ring[1:] + ring[:1]):
        F += [[a, a + nb, b + nb], [a, b + nb, b]]
    return V, np.array(F)


SCENE = """# A user's scene: a 2 cm cube pressed on a wavy plate and slid across its waves.
format = "gauss6-scene"
version = 2
name = "cube_on_waves"

[gains]
ks = 0.5
kh = 20000.0

[contact]
delta = 1e-6

[[obstacle]]
name = "plate"
mesh = "plate.off"

[god_object]
name = "cube"
mesh = "cube.off"
position = [0.0, 0.0, 0.03]
density = 1000.0

[device]
kind = "simulated"
{device_script}
"""

TABLE_SCRIPT = """
[device.script]
end_time = 1.0
keys = [
  { t = 0.0, p = [-0.02, 0.0, 0.03] },
  { t = 0.3, p = [-0.02, 0.0, 0.006] },
  { t = 0.8, p = [0.02, 0.0, 0.006] },
  { t = 1.0, p = [0.02, 0.0, 0.03] },
]
phases = [{ name = "press", start = 0.0 }, { name = "slide", start = 0.3 }, { name = "lift", start = 0.8 }]
"""


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("user_scene")
    write_off(d / "cube.off", *cube(0.01))
    # Waves of 1 mm over 2 cm: the cube (2 cm wide) rides their crests.
    write_off(d / "plate.off", *wavy_plate(0.1, 40, 0.001, 0.02, 0.01))
    (d / "scene.toml").write_text(SCENE.replace("{device_script}", TABLE_SCRIPT))
    return d


@pytest.fixture(scope="module")
def table_run(scene_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    r = run_cli("run", str(scene_dir / "scene.toml"), "--out", str(out), "--quiet")
    return out, r


def test_a_users_scene_runs_to_a_certified_report(table_run):
    out, r = table_run
    assert r.returncode == 0, r.stderr
    summary = json.loads((out / "summary.json").read_text())["scene"]
    assert sorted(summary) == sorted(run_mod.COMMON_KEYS)
    details = json.loads((out / "details.json").read_text())["scene"]
    # Certified exactly: every pose free, every motion between poses free of contact, over the whole
    # script (1001 ticks). The certificate covers the trace's distinct poses: while the cube rests on
    # the crest it was pressed onto, a tick repeats the last pose bit for bit and adds none (the press
    # and the lift move it at every tick).
    tr = read_trace(out / "scene.g6trace")
    assert len(tr.ticks) == 1001
    assert details["certify"]["certified"] and summary["penetrating_poses"] == 0
    poses = len(np.unique(np.hstack([tr.ticks["xs_p"], tr.ticks["xs_q"]]), axis=0))
    assert details["certify"]["poses"] == details["distinct_poses"] == poses > 300
    assert details["certify"]["motions"] == poses - 1
    # The cube touched the plate (pressed 6 mm past its crest at z = 0.011 for 0.5 s) and was pushed up:
    # never pulled down (every contact normal of the plate's top points up), 0.26 N at rest on the
    # crest; over the slide the force is off for the few ticks in which the command leaves the contacts
    # to first order (down a crest's far side, levelling the cube), so its mean is lower (0.15 N).
    pressed = (tr.ticks["t"] > 0.35) & (tr.ticks["t"] < 0.8)
    assert np.all(tr.ticks["num_contacts"][pressed] > 0)
    assert np.all(tr.ticks["wrench"][pressed, 2] >= 0)
    assert tr.ticks["wrench"][pressed, 2].mean() > 0.1
    # The cube slid after the hand over the waves (the hand 4 cm along x in 0.5 s): each leg of the
    # slide starts in contact, and a leg the CCD stops at its start is a graze lifted out of, not a
    # stop for the rest of the slide: the cube covers at least 3 of the hand's 4 cm. (A lift whose own
    # leg stops at once is refused, its lift pose a waypoint no CCD proved separated: the cube lags a
    # few millimetres there rather than standing on an unproven pose.)
    x = tr.ticks["xs_p"][:, 0]
    at = lambda t: int(np.argmin(np.abs(tr.ticks["t"] - t)))
    assert x[at(0.3)] < -0.019 and x[at(0.55)] > x[at(0.3)] + 0.01 and x[at(0.8)] > x[at(0.3)] + 0.03
    assert np.all(tr.ticks["xs_p"][:, 2] - 0.01 > -0.001 - 1e-9)  # never below the lowest trough
    # The script's phases are the trace's, the lockstep repeats gave each step's least time.
    assert [p["name"] for p in tr.meta["phases"]] == ["press", "slide", "lift"]
    least = details["update_least"]
    assert least["runs"] == run_mod.LOCKSTEP_RUNS
    assert 0 < least["update_cpu_time_ms"]["max"] <= summary["update_cpu_time_ms"]["max"]
    # The properties: orthogonality (the projection is solved to about 1e-12 relative; 1e-8 leaves room),
    # no energy injected by the constraints.
    assert summary["max_rel_force_dot_ac"] <= 1e-8
    assert summary["energy_injected"] <= 1e-12 * details["constraint_energy_removed_j"]
    # The figure, the viewer page, the certificate and the report.
    assert (out / "figure_scene.png").stat().st_size > 10_000
    assert (out / "view_scene.html").stat().st_size > 10_000
    assert json.loads((out / "certify_scene.json").read_text())["pass"]
    report = (out / "report.md").read_text()
    assert "figure_scene.png" in report and "Machine:" in report and "device.script" in report
    assert "updates over 1 ms" in report


def test_the_validation_driver_reads_a_script_table(scene_dir):
    """gauss6 validate's driver takes the scene's [device.script] table as the runs do."""
    from gauss6 import driver
    from gauss6._gauss6 import device, runtime

    text, origin = driver.scene_script(scene_dir / "scene.toml")
    assert origin.endswith("scene.toml: device.script")
    dev = device.SimulatedDevice(text, origin=origin)
    hand = runtime.hand_script(str(scene_dir / "scene.toml"))
    assert dev.end_time == hand["end_time"] == 1.0
    assert [name for name, _ in dev.phases] == [name for name, _ in hand["phases"]] == ["press", "slide", "lift"]


def test_a_script_file_replaces_the_scenes(scene_dir, tmp_path):
    script = tmp_path / "tap.json"
    script.write_text(json.dumps({"keys": [{"t": 0.0, "p": [0.0, 0.0, 0.03]}, {"t": 0.3, "p": [0.0, 0.0, 0.008]}],
                                  "end_time": 0.4}))
    out = tmp_path / "out"
    r = run_cli("run", str(scene_dir / "scene.toml"), "--script", str(script), "--out", str(out), "--quiet",
                "--name", "tap")
    assert r.returncode == 0, r.stderr
    tr = read_trace(out / "tap.g6trace")
    assert len(tr.ticks) == 401 and not tr.meta["phases"]
    assert json.loads((out / "details.json").read_text())["tap"]["script"] == str(script)


BAD_JSON = [
    ({"keys": [{"t": 0, "p": [0, 0, 0.03]}, {"t": 0.5, "p": [0, 0.01]}]}, "keys[1].p: must be 3 numbers"),
    ({"keys": [{"t": 0, "p": [0, 0, 0.03]}, {"t": 0, "p": [0, 0, 0.02]}]}, "keys[1].t: times must increase strictly"),
    ({"keys": [{"t": 0, "p": [0, 0, 0.03]}], "let_go": 1.0}, "let_go: unknown key"),
    ({"keys": [{"t": 0, "p": [0, 0, 0.03], "q": [0, 0, 0, 0]}]}, "keys[0]: invalid pose"),
    ({"keys": [{"t": 0, "p": [0, 0, 0.03]}], "phases": [{"name": "a"}]}, "phases[0].start: missing"),
    ({"kees": []}, "kees: unknown key"),
]


@pytest.mark.parametrize("script,message", BAD_JSON)
def test_bad_script_files_are_refused_naming_the_file_and_the_key(scene_dir, tmp_path, script, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(script))
    r = run_cli("run", str(scene_dir / "scene.toml"), "--script", str(path), "--out", str(tmp_path / "out"))
    assert r.returncode == 2
    assert str(path) in r.stderr and message in r.stderr, r.stderr
    assert not (tmp_path / "out").exists()  # refused before anything runs


@pytest.mark.parametrize("table,message", [
    ("[device.script]\nkeys = [{ t = 0.0, p = [0.0, 0.0] }]\n", "device.script: hand script: keys[0].p: must be 3"),
    ("[device.script]\nkeys = [{ t = 0.0, p = [0.0, 0.0, 0.03] }]\nlet_go = 1.0\n", "let_go: unknown key"),
    # At its line and column (the keys line: the second of the table).
    ("[device.script]\nkeys = [{ t = nan, p = [0.0, 0.0, 0.03] }]\n",
     f"scene.toml:{SCENE.split('{device_script}')[0].count(chr(10)) + 2}:15: device.script.keys[0].t: must be finite"),
    ("script = 3\n", "device.script: must be a script's name"),
    ("", "device.script: missing (a script's name, a .json file or a [device.script] table"),
])
def test_bad_script_tables_are_refused_naming_the_scene_and_the_key(tmp_path, scene_dir, table, message):
    for mesh in ("cube.off", "plate.off"):
        (tmp_path / mesh).write_bytes((scene_dir / mesh).read_bytes())
    (tmp_path / "scene.toml").write_text(SCENE.replace("{device_script}", table))
    r = run_cli("run", str(tmp_path / "scene.toml"), "--out", str(tmp_path / "out"))
    assert r.returncode == 2
    assert "scene.toml" in r.stderr and message in r.stderr, r.stderr


def test_script_names_and_files(tmp_path):
    assert run_mod.script_path("bunny").name == "bunny.json"
    with pytest.raises(ValueError, match="neither a .json file nor a shipped hand script .*peg_in_hole"):
        run_mod.script_path("no_such_script")
    with pytest.raises(ValueError, match="no such hand script file"):
        run_mod.script_path(str(tmp_path / "absent.json"))
    (tmp_path / "script.txt").write_text("{}")
    with pytest.raises(ValueError, match="ends in .json"):
        run_mod.script_path(str(tmp_path / "script.txt"))


def test_threaded_without_certification_says_so(scene_dir, tmp_path):
    r = run_cli("run", str(scene_dir / "scene.toml"), "--out", str(tmp_path), "--threaded", "--no-certify",
                "--duration", "0.3", "--quiet")
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "summary.json").read_text())["scene"]
    assert summary["penetrating_poses"] == -1  # not checked, and not passed off as 0
    details = json.loads((tmp_path / "details.json").read_text())["scene"]
    assert details["mode"] == "threaded" and "update_least" not in details and "certify" not in details
    report = (tmp_path / "report.md").read_text()
    assert "not run (--no-certify)" in report and "not checked" in report


def test_a_budgeted_run_is_certified_and_reports_its_budget(scene_dir, tmp_path):
    # A work-unit budget small enough that some updates of the landing and the slide run out of it:
    # certified all the same, its cost in the report.
    r = run_cli("run", str(scene_dir / "scene.toml"), "--out", str(tmp_path), "--quiet",
                "--budget-units", str(BUDGET_UNITS), "--duration", "0.6")
    assert r.returncode == 0, r.stderr
    details = json.loads((tmp_path / "details.json").read_text())["scene"]
    assert details["certify"]["certified"]
    b = details["budget"]
    assert b["exhausted"] > 0 and b["deferred_max"] > 0 and b["longest_run"] >= 1
    assert "update_least" in details  # a work-unit budget repeats bit for bit: the repeats ran
    assert "work units" in details["mode"]
    report = (tmp_path / "report.md").read_text()
    assert "run out of their budget" in report and "between successive haptic ticks" in report


BUDGET_UNITS = 100


def test_the_recommended_budget_is_the_libraries(scene_dir, tmp_path):
    from gauss6 import paths

    header = (paths.REPO_ROOT / "optimized/gauss6/step/update_budget.h").read_text()
    line = next(l for l in header.splitlines() if "kRecommendedUpdateCpuSeconds =" in l)
    assert float(line.split("=")[1].strip().rstrip(";")) == cli_args.RECOMMENDED_BUDGET_S
    r = run_cli("run", str(scene_dir / "scene.toml"), "--out", str(tmp_path), "--budget-cpu", "2")
    assert r.returncode == 2 and "a CPU budget is in seconds" in r.stderr
