"""Traces: C++ writer -> Python reader round trip, truncated and malformed files, CSV export."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from gauss6 import trace
from gauss6._gauss6 import device as _device


def quat(i: int) -> np.ndarray:
    q = np.array([1.0, 0.01 * i, -0.02 * i, 0.003 * i])
    return q / np.linalg.norm(q)


def write_sample(path, num_ticks=300, num_steps=20, close=True):
    w = _device.TraceWriter(str(path), scene="peg_in_hole", device="simulated", rate_hz=1000.0,
                            phases=[("a", 0.0), ("b", 0.1)], extra_json='{"ks": 0.5}', background_thread=False)
    for i in range(num_ticks):
        assert w.append_tick(i * 1e-3, [i / 3, -i / 7, 0.1 * i], quat(i), [1 / (i + 1), 2.0, -3.0 * i], quat(-i),
                             [np.sin(0.1 * i) * (k + 1) for k in range(6)], num_contacts=i % 5,
                             force_time=1e-6 * (1 + i % 3), status=0, flags=1 | (2 if i % 2 else 0), buttons=i % 4)
    for k in range(num_steps):
        assert w.append_step(k, 0.01 * k, 1e-4 * k, 2)
        for c in range(2):
            assert w.append_contact(k, 0.01 * k, [k, c, 1.0], [0.0, 0.0, 1.0], 1e-5 * c)
    assert w.append_event(0.1, 1, 1.0)
    assert w.append_event(0.2, 2)
    w.flush()
    if close:
        w.close()
    return w


def test_round_trip_cpp_write_python_read(tmp_path):
    path = tmp_path / "run.g6trace"
    write_sample(path)
    tr = trace.read_trace(path)
    assert tr.complete and tr.warnings == [] and tr.version == trace.VERSION == 2
    assert len(tr.ticks) == 300 and len(tr.steps) == 20 and len(tr.contacts) == 40 and len(tr.events) == 2
    i = np.arange(300)
    # Doubles are stored as they are: exact equality.
    np.testing.assert_array_equal(tr.ticks["t"], i * 1e-3)
    np.testing.assert_array_equal(tr.ticks["xh_p"], np.stack([i / 3, -i / 7, 0.1 * i], axis=1))
    np.testing.assert_array_equal(tr.ticks["xh_q"][17], quat(17))
    np.testing.assert_array_equal(tr.ticks["xs_q"][17], quat(-17))
    np.testing.assert_array_equal(tr.ticks["wrench"][:, 5], np.sin(0.1 * i) * 6)
    np.testing.assert_array_equal(tr.ticks["num_contacts"], i % 5)
    np.testing.assert_array_equal(tr.ticks["flags"], 1 + 2 * (i % 2))
    np.testing.assert_array_equal(tr.ticks["buttons"], i % 4)
    np.testing.assert_array_equal(tr.contacts["point"][7], [3.0, 1.0, 1.0])
    assert tr.event_names() == ["phase", "let_go"]
    assert tr.meta["format"] == "gauss6-trace" and tr.meta["scene"] == "peg_in_hole"
    assert tr.meta["phases"] == [{"name": "a", "start": 0.0}, {"name": "b", "start": 0.1}]
    assert tr.meta["extra"] == {"ks": 0.5}
    assert tr.dropped == {"ticks": 0, "steps": 0, "contacts": 0, "events": 0}
    # The metadata's column list is the one this reader uses.
    assert [tuple(c) for c in tr.meta["columns"]["ticks"]] == trace.COLUMNS["ticks"]


def test_update_cpu_time_round_trips_and_version_1_traces_stay_readable(tmp_path):
    # Version 2 added the steps' update_cpu_time (the sim thread's CPU time); a
    # writer call without it records NaN (not measured).
    path = tmp_path / "run.g6trace"
    w = _device.TraceWriter(str(path), scene="s", device="d", rate_hz=1000.0, phases=[], extra_json="{}",
                            background_thread=False)
    assert w.append_step(0, 0.001, 2e-4, 1, 0, update_cpu_time=1.5e-4)
    assert w.append_step(1, 0.002, 3e-4, 1)
    w.close()
    tr = trace.read_trace(path)
    np.testing.assert_array_equal(tr.steps["update_cpu_time"][:1], [1.5e-4])
    assert np.isnan(tr.steps["update_cpu_time"][1])
    # The same trace as a version 1 file (steps of 5 values, no update_cpu_time):
    # read with update_cpu_time NaN and every other column as written.
    v1 = trace.Trace(path=path, version=1, meta=dict(tr.meta, version=1), ticks=tr.ticks, steps=tr.steps,
                     contacts=tr.contacts, events=tr.events, complete=True, dropped=tr.dropped, warnings=[])
    data = bytearray(trace.write_trace(v1, tmp_path / "v2.g6trace").read_bytes())
    meta_len = trace.HEADER.unpack_from(data, 0)[3]
    out = bytearray(trace.HEADER.pack(trace.MAGIC, 1, 0, meta_len)) + data[trace.HEADER.size:trace.HEADER.size + meta_len]
    pos = trace.HEADER.size + meta_len
    while pos < len(data):
        ctype, ncols, nrows = trace.CHUNK.unpack_from(data, pos)
        rows = np.frombuffer(data, dtype="<f8", count=nrows * ncols, offset=pos + trace.CHUNK.size).reshape(nrows, ncols)
        if ctype == trace.STEPS:
            rows, ncols = rows[:, :5], 5
        out += trace.CHUNK.pack(ctype, ncols, nrows) + np.ascontiguousarray(rows).tobytes()
        pos += trace.CHUNK.size + 8 * nrows * trace.CHUNK.unpack_from(data, pos)[1]
    old = tmp_path / "v1.g6trace"
    old.write_bytes(bytes(out))
    steps = trace.read_trace(old).steps  # (the C++ reader: trace/tests/test_trace.cpp)
    assert np.isnan(steps["update_cpu_time"]).all()
    np.testing.assert_array_equal(steps["update_time"], [2e-4, 3e-4])
    np.testing.assert_array_equal(steps["step"], [0, 1])


def test_truncated_trace_reads_complete_chunks_with_a_warning(tmp_path):
    path = tmp_path / "cut.g6trace"
    w = _device.TraceWriter(str(path), background_thread=False)
    for k in range(3):  # three flushes: three tick chunks of 100 rows
        for i in range(100):
            w.append_tick(k * 0.1 + i * 1e-3, [0, 0, i], [1, 0, 0, 0], [0, 0, 0], [1, 0, 0, 0], [0] * 6)
        w.flush()
    w.close()
    data = path.read_bytes()
    chunk = 16 + 100 * 26 * 8
    first = len(data) - 3 * chunk - (16 + 4 * 8)  # end chunk: 16 + 4 values
    path.write_bytes(data[:first + 2 * chunk + 1000])  # cut inside the third chunk
    with pytest.warns(trace.TraceWarning, match="cut mid-chunk"):
        tr = trace.read_trace(path)
    assert len(tr.ticks) == 200 and not tr.complete
    np.testing.assert_array_equal(tr.ticks["xh_p"][150], [0, 0, 50])


def test_unclosed_trace_warns_that_it_was_not_closed(tmp_path):
    path = tmp_path / "open.g6trace"
    w = write_sample(path, close=False)
    with pytest.warns(trace.TraceWarning, match="no end chunk"):
        tr = trace.read_trace(path)
    assert len(tr.ticks) == 300
    w.close()


def test_malformed_traces_name_the_file_and_the_problem(tmp_path):
    good = tmp_path / "good.g6trace"
    write_sample(good, 10, 1)
    data = bytearray(good.read_bytes())
    bad = tmp_path / "bad.g6trace"
    cases = [
        (lambda b: b.__setitem__(0, ord("X")), "bad magic"),
        (lambda b: b.__setitem__(8, 99), "unsupported trace version 99"),
        (lambda b: b.__setitem__(24, ord("#")), "not valid JSON"),
    ]
    for mutate, message in cases:
        b = bytearray(data)
        mutate(b)
        bad.write_bytes(bytes(b))
        with pytest.raises(trace.TraceFormatError, match=message) as e:
            trace.read_trace(bad)
        assert "bad.g6trace" in str(e.value)
    meta_len = int.from_bytes(data[16:24], "little")
    b = bytearray(data)
    b[24 + meta_len + 4] = 7
    bad.write_bytes(bytes(b))
    with pytest.raises(trace.TraceFormatError, match="rows of 7 values, expected 26"):
        trace.read_trace(bad)
    bad.write_bytes(b"hello")
    with pytest.raises(trace.TraceFormatError, match="shorter than the header"):
        trace.read_trace(bad)
    with pytest.raises(trace.TraceFormatError, match="cannot open"):
        trace.read_trace(tmp_path / "absent.g6trace")


def test_background_flush_makes_rows_readable_before_close(tmp_path):
    import time

    path = tmp_path / "flush.g6trace"
    w = _device.TraceWriter(str(path), background_thread=True, flush_period=0.05)
    for i in range(50):
        w.append_tick(i * 1e-3, [0, 0, 0], [1, 0, 0, 0], [0, 0, 0], [1, 0, 0, 0], [0] * 6)
    deadline = time.monotonic() + 1.0  # 20 flush periods
    n = 0
    while time.monotonic() < deadline and n < 50:
        time.sleep(0.01)
        with pytest.warns(trace.TraceWarning):
            n = len(trace.read_trace(path).ticks)
    assert n == 50
    w.close()


def test_to_csv_round_trips_the_values(tmp_path):
    path = tmp_path / "run.g6trace"
    write_sample(path)
    tr = trace.read_trace(path)
    files = trace.to_csv(tr, tmp_path / "csv")
    assert sorted(f.name for f in files) == ["contacts.csv", "events.csv", "meta.json", "steps.csv", "ticks.csv"]
    with open(tmp_path / "csv" / "ticks.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 300
    assert float(rows[17]["xh_q_0"]) == tr.ticks["xh_q"][17][0]  # 17 digits: exact
    assert float(rows[299]["wrench_5"]) == tr.ticks["wrench"][299][5]
    with open(tmp_path / "csv" / "events.csv") as f:
        assert [r["name"] for r in csv.DictReader(f)] == ["phase", "let_go"]
    assert json.loads((tmp_path / "csv" / "meta.json").read_text())["complete"] is True
    summary = trace.export_csv(path, tmp_path / "csv2")
    assert "300 ticks" in summary
