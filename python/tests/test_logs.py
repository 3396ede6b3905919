"""Tests of the log formats others use (gauss6.logs): a gauss6 trace to a HAPI device log and to
CSV files and back, HAPI's own 5-decimal form read in, the errors a malformed log raises (file,
line, column), and `gauss6 trace export | import`."""
from __future__ import annotations

import math

import numpy as np
import pytest

import gauss6
from gauss6 import logs, reproduce
from gauss6.cli import main
from gauss6.trace import COLUMNS, read_trace, to_csv, write_trace

runtime = pytest.importorskip("gauss6._gauss6").runtime


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The first 0.9 s of the peg scenario: the tilted peg's tip pressed on the box's top."""
    path = tmp_path_factory.mktemp("run") / "peg.g6trace"
    runtime.run_scenario(str(reproduce.SCENES["peg"]), str(path), duration=0.9)
    tr = read_trace(path)
    tr.ticks["buttons"][::7] = 5  # some button presses, so that the column carries something
    return tr


def _same_rotation(q1, q2) -> float:
    """Largest difference between two arrays of quaternions, as unit quaternions with w >= 0."""
    def canon(q):
        q = q / np.linalg.norm(q, axis=1, keepdims=True)
        return q * np.where(q[:, :1] < 0, -1.0, 1.0)
    return float(np.abs(canon(q1) - canon(q2)).max())


def test_trace_to_hapi_and_back(run, tmp_path):
    log = logs.export_hapi(run, tmp_path / "peg.log")
    lines = log.read_text().splitlines()
    assert lines[0] == "TIME POSITION ORIENTATION FORCE TORQUE BUTTONS"
    assert len(lines) == len(run.ticks) + 1 and all(len(line.split()) == 15 for line in lines[1:])
    back = logs.read_hapi(log, scene="peg_in_hole")
    # Time, position, force, torque and buttons: the same doubles (shortest repr reads back exactly).
    for col in ("t", "xh_p", "wrench", "buttons"):
        assert np.array_equal(back.ticks[col], run.ticks[col]), col
    # Orientation through axis-angle: the same rotation within rounding (a few ulp).
    assert _same_rotation(back.ticks["xh_q"], run.ticks["xh_q"]) <= 4e-16
    # A foreign log has no god-object: xs is the handle's pose; the handle is held throughout.
    assert np.array_equal(back.ticks["xs_p"], back.ticks["xh_p"])
    assert np.all(back.ticks["flags"] == 1)
    assert back.meta["extra"]["imported_from"]["format"] == "hapi"
    assert back.meta["device"]["rate_hz"] == pytest.approx(1000.0)


def test_trace_to_csv_and_back_is_exact(run, tmp_path):
    to_csv(run, tmp_path / "csv")
    back = logs.read_csv_dir(tmp_path / "csv")
    for name in ("ticks", "steps", "contacts", "events"):
        assert len(getattr(back, name)) == len(getattr(run, name)) > 0 or name == "events"
        for col, _ in COLUMNS[name]:
            assert np.array_equal(getattr(back, name)[col], getattr(run, name)[col]), (name, col)
    assert back.meta == run.meta and back.dropped == run.dropped
    # And written as a trace, it reads back to the same doubles and metadata.
    again = read_trace(write_trace(back, tmp_path / "again.g6trace"))
    assert again.complete and again.meta == run.meta
    for name in ("ticks", "steps", "contacts", "events"):
        assert np.array_equal(getattr(again, name), getattr(run, name)), name


def test_hapi_own_format_reads(tmp_path):
    """HAPI writes fixed 5 decimals, columns in the order asked, extra columns such as VELOCITY."""
    log = tmp_path / "hapi.log"
    log.write_text(
        "TIME POSITION VELOCITY ORIENTATION BUTTONS\n"
        "0.00000 0.01000 0.02000 0.03000 0.00000 0.00000 0.00000 0.00000 0.00000 1.00000 1.57080 0\n"
        "0.00100 0.01100 0.02000 0.03000 1.00000 0.00000 0.00000 1.00000 0.00000 0.00000 0.00000 1\n"
        "\n"
        "0.00200 0.01200 0.02000 0.03000 1.00000 0.00000 0.00000 0.00000 0.00000 0.00000 0.00000 3\n")
    tr = logs.read_hapi(log)
    assert np.array_equal(tr.ticks["t"], [0.0, 0.001, 0.002])
    assert np.array_equal(tr.ticks["xh_p"][:, 0], [0.01, 0.011, 0.012])
    c = math.cos(0.5 * 1.5708)
    np.testing.assert_allclose(tr.ticks["xh_q"][0], [c, 0, 0, math.sin(0.5 * 1.5708)], atol=1e-15)
    np.testing.assert_allclose(tr.ticks["xh_q"][1], [1, 0, 0, 0], atol=0)
    np.testing.assert_allclose(tr.ticks["xh_q"][2], [1, 0, 0, 0], atol=0)  # zero axis: the identity
    assert list(tr.ticks["buttons"]) == [0, 1, 3]
    assert np.all(tr.ticks["wrench"] == 0)  # no FORCE, TORQUE columns
    assert tr.meta["extra"]["imported_from"]["ignored"] == ["VELOCITY"]


@pytest.mark.parametrize("text, where, problem", [
    ("TIME POSITION\n0 1 2 3\n0.1 1 2\n", ":3:8:", "3 values, the header names 4"),
    ("TIME POSITION\n0 1 2 3\n0.1 1 2 3 4\n", ":3:11:", "5 values, the header names 4"),
    ("TIME POSITION\n0 1 2 3\n0.1 1 abc 3\n", ":3:7:", "not a number: 'abc'"),
    ("TIME POSITION\n0 1 2 3\n0.1 1 nan 3\n", ":3:7:", "not a number: 'nan'"),
    ("TIME POSITION\n0 1 2 3\n0.1 1 1e999 3\n", ":3:7:", "not a finite number"),
    ("TIME POSITION\n0 1 2 3\n0.1 1 2 3\n0.1 1 2 3\n", ":4:1:", "time 0.1 does not increase"),
    ("POSITION TIME\n1 2 3 0.5\n1 2 3 0.2\n", ":3:7:", "time 0.2 does not increase"),
    ("TIME POSITION SPEED\n", ":1:15:", "unknown HAPI log column 'SPEED'"),
    ("TIME ORIENTATION\n", ":1:1:", "the header has no POSITION column"),
    ("TIME POSITION BUTTONS\n0 1 2 3 1.5\n", ":2:", "is not a button mask"),
])
def test_hapi_errors_name_file_line_and_column(tmp_path, text, where, problem):
    log = tmp_path / "bad.log"
    log.write_text(text)
    with pytest.raises(gauss6.LoadError) as e:
        logs.read_hapi(log)
    assert isinstance(e.value, logs.LogFormatError)
    assert str(e.value).startswith(f"{log}{where}") and problem in str(e.value), str(e.value)


def test_csv_errors_and_a_foreign_ticks_file(tmp_path):
    bad = tmp_path / "ticks.csv"
    bad.write_text("t,xh_p_0,xh_p_1,xh_p_2\n0,1,2,3\n0.001,1,x,3\n")
    with pytest.raises(logs.LogFormatError, match=r"ticks\.csv:3:9: not a number: 'x'"):
        logs.read_csv_dir(bad)
    bad.write_text("t,xh_p_0,xh_p_1,hand\n")
    with pytest.raises(logs.LogFormatError, match=r"ticks\.csv:1:17: unknown ticks column 'hand'"):
        logs.read_csv_dir(bad)
    # Another framework's ticks: time and positions only; the rest takes its defaults.
    bad.write_text("t,xh_p_0,xh_p_1,xh_p_2\n0,1,2,3\n0.001,1,2.5,3\n")
    tr = logs.read_csv_dir(bad)
    assert np.array_equal(tr.ticks["xh_p"][1], [1, 2.5, 3]) and np.array_equal(tr.ticks["xs_p"], tr.ticks["xh_p"])
    assert np.array_equal(tr.ticks["xh_q"], [[1, 0, 0, 0]] * 2) and np.all(tr.ticks["flags"] == 1)


def test_commands_export_and_import(run, tmp_path, capsys):
    src = write_trace(run, tmp_path / "run.g6trace")
    assert main(["trace", "export", str(src), "--hapi", str(tmp_path / "run.log"), "--csv", str(tmp_path / "csv")]) == 0
    out = capsys.readouterr().out
    assert "HAPI device log" in out and "ticks.csv" in out
    assert main(["trace", "import", str(tmp_path / "run.log"), "--format", "hapi", "--out",
                 str(tmp_path / "from_hapi.g6trace"), "--scene", "peg_in_hole"]) == 0
    assert main(["trace", "import", str(tmp_path / "csv"), "--format", "csv", "--out",
                 str(tmp_path / "from_csv.g6trace")]) == 0
    from_hapi, from_csv = read_trace(tmp_path / "from_hapi.g6trace"), read_trace(tmp_path / "from_csv.g6trace")
    assert np.array_equal(from_hapi.ticks["xh_p"], run.ticks["xh_p"]) and from_hapi.meta["scene"] == "peg_in_hole"
    assert np.array_equal(from_csv.ticks, run.ticks) and np.array_equal(from_csv.contacts, run.contacts)
    (tmp_path / "bad.log").write_text("TIME POSITION\n0 1 2\n")
    assert main(["trace", "import", str(tmp_path / "bad.log"), "--format", "hapi", "--out",
                 str(tmp_path / "x.g6trace")]) == 2
    assert "bad.log:2:6: 3 values, the header names 4" in capsys.readouterr().err
    assert main(["trace", "export", str(src)]) == 2


def test_an_imported_hapi_log_drives_the_replay_device(tmp_path):
    """A session recorded by another framework (a HAPI log: a handle circling at 1 kHz, turning
    about Z, a button pressed halfway) imported as a trace drives gauss6's replay device (C++)."""
    t = np.arange(401) / 1000.0
    pos = np.stack([0.02 * np.cos(5 * t), 0.02 * np.sin(5 * t), 0.1 - 0.05 * t], axis=1)
    angle = 0.8 * t
    rows = ["TIME POSITION ORIENTATION FORCE TORQUE BUTTONS"] + [
        f"{t[k]:.5f} {pos[k, 0]:.5f} {pos[k, 1]:.5f} {pos[k, 2]:.5f} 0.00000 0.00000 1.00000 {angle[k]:.5f} "
        f"0.00000 0.00000 0.00000 0.00000 0.00000 0.00000 {int(k >= 200)}" for k in range(len(t))]
    log = tmp_path / "session.log"
    log.write_text("\n".join(rows) + "\n")
    trace_path = tmp_path / "session.g6trace"
    assert main(["trace", "import", str(log), "--format", "hapi", "--out", str(trace_path)]) == 0

    replay = gauss6._gauss6.device.ReplayDevice(str(trace_path))
    assert replay.num_samples == 401 and replay.end_time == pytest.approx(0.4)
    assert replay.rate_hz == pytest.approx(1000.0)
    for k in (0, 1, 150, 200, 399):
        p, q, gripped, buttons, status = replay.read(t[k])
        np.testing.assert_allclose(p, np.round(pos[k], 5), atol=1e-15)
        np.testing.assert_allclose(q, [math.cos(0.5 * round(angle[k], 5)), 0, 0, math.sin(0.5 * round(angle[k], 5))],
                                   atol=1e-15)
        assert gripped and buttons == int(k >= 200) and status == "ok"
    # Between two logged frames the pose is interpolated; after the last the replay has ended.
    p, *_ = replay.read(0.1505)
    np.testing.assert_allclose(p, 0.5 * (np.round(pos[150], 5) + np.round(pos[151], 5)), atol=1e-12)
    assert replay.read(0.5)[4] == "ended"


def test_a_recorded_session_replays_through_the_runtime(run, tmp_path, capsys):
    """`gauss6 replay`: the peg run's handle, exported to CSV and imported as a foreign recording,
    drives the peg scene through the C++ replay device. The handle reaches the runtime at the
    recorded ticks, so the replayed run is the recorded one: same handle poses, god-object poses
    and wrenches tick for tick (bit for bit, or within 1e-12 where the replay device's
    interpolation at a recorded time rounds)."""
    to_csv(run, tmp_path / "csv")
    recording = tmp_path / "recording.g6trace"
    assert main(["trace", "import", str(tmp_path / "csv"), "--format", "csv", "--out", str(recording)]) == 0
    out = tmp_path / "replayed.g6trace"
    assert main(["replay", str(recording), "--scene", str(reproduce.SCENES["peg"]), "--out", str(out),
                 "--quiet"]) == 0
    assert "haptic ticks" in capsys.readouterr().out
    again = read_trace(out)
    n = len(run.ticks)
    assert len(again.ticks) == n
    assert again.meta["device"]["name"] == "replay"
    for col in ("t", "xh_p", "xh_q", "xs_p", "xs_q", "wrench"):
        np.testing.assert_allclose(again.ticks[col], run.ticks[col], rtol=0, atol=1e-12, err_msg=col)
    assert np.abs(again.ticks["wrench"][:, 2]).max() > 0.1  # the peg pressed on the box: a real force
    # A recording that cannot drive the device is refused with its reason.
    assert main(["replay", str(tmp_path / "missing.g6trace"), "--scene", str(reproduce.SCENES["peg"]),
                 "--out", str(tmp_path / "x.g6trace"), "--quiet"]) == 2
    assert "missing.g6trace" in capsys.readouterr().err
