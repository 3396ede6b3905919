"""Bad input at the Python API's edges (issue: every input gets the method's
guarantees or is refused with a clear error): crafted traces raise TraceFormatError
(never ValueError, OverflowError, RecursionError or AttributeError of their own),
face indices that do not fit in 32 bits are refused instead of wrapping, and
property tests (Hypothesis) that poses, meshes and projection inputs either give
finite answers or raise a clear error, never a NaN and never a crash."""
from __future__ import annotations

import json
import math
import struct

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gauss6
from gauss6 import _gauss6, trace

# ---------------------------------------------------------------------------
# Crafted traces


def _trace_bytes(meta, chunks):
    meta_bytes = meta if isinstance(meta, bytes) else json.dumps(meta).encode()
    out = trace.HEADER.pack(trace.MAGIC, trace.VERSION, 0, len(meta_bytes)) + meta_bytes
    for ctype, rows in chunks:
        rows = np.asarray(rows, dtype="<f8")
        out += trace.CHUNK.pack(ctype, rows.shape[1], rows.shape[0]) + rows.tobytes()
    return out


def _tick(**over):
    row = np.zeros(26)
    row[4] = row[11] = 1.0  # unit quaternions
    for k, v in over.items():
        row[{"t": 0, "num_contacts": 21, "status": 23, "flags": 24, "buttons": 25}[k]] = v
    return row


CRAFTED = {
    "dropped count NaN": ({}, [(trace.END, [[math.nan, 0, 0, 0]])]),
    "dropped count inf": ({}, [(trace.END, [[math.inf, 0, 0, 0]])]),
    "metadata nested 100000 deep": (b"[" * 100000 + b"]" * 100000, []),
    "metadata integer of 5000 digits": (b'{"a": ' + b"9" * 5000 + b"}", []),
    "metadata not an object": ([1, 2, 3], []),
    "event codes not an object": ({"event_codes": [1]}, []),
    "phases not a list of objects": ({"phases": [1]}, []),
    "phase start beyond a double": ({"phases": [{"name": "a", "start": 10 ** 400}]}, []),
    "tick num_contacts NaN": ({}, [(trace.TICKS, [_tick(num_contacts=math.nan)])]),
    "tick status 1e300": ({}, [(trace.TICKS, [_tick(status=1e300)])]),
    "tick flags negative": ({}, [(trace.TICKS, [_tick(flags=-1)])]),
    "tick time inf": ({}, [(trace.TICKS, [_tick(t=math.inf)])]),
    "event code 0.5": ({}, [(trace.EVENTS, [[0.0, 0.5, 0.0]])]),
    "step index 1e20": ({}, [(trace.STEPS, [[1e20, 0, 0, 0, 0]])]),
}


@pytest.mark.parametrize("name", sorted(CRAFTED))
def test_crafted_traces_raise_trace_format_error_in_both_readers(tmp_path, name):
    meta, chunks = CRAFTED[name]
    path = tmp_path / "crafted.g6trace"
    path.write_bytes(_trace_bytes(meta, chunks))
    with pytest.raises(trace.TraceFormatError, match="crafted.g6trace"):
        trace.read_trace(path)
    # The C++ reader (through the replay device) refuses the same integer columns;
    # its metadata check is JSON validity only.
    if name.startswith(("tick", "dropped", "event code 0.5", "step", "metadata nested", "metadata not")):
        with pytest.raises(gauss6.LoadError, match="crafted.g6trace"):
            _gauss6.device.ReplayDevice(str(path))


# ---------------------------------------------------------------------------
# Face indices and poses at the bindings

CUBE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                   [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])


def test_face_indices_beyond_32_bits_are_refused_not_wrapped():
    F = CUBE_F.astype(np.int64)
    F[0, 0] += 2 ** 32  # would wrap to 0: a valid-looking cube
    for call in (lambda: _gauss6.validate_mesh(CUBE_V, F), lambda: _gauss6.mass_properties(CUBE_V, F, 1.0),
                 lambda: _gauss6.ccd.MeshPair(CUBE_V, F, CUBE_V, CUBE_F)):
        with pytest.raises(ValueError, match=r"\[0, 2\^31 - 1\]"):
            call()
    with pytest.raises(ValueError, match="integer array"):
        _gauss6.validate_mesh(CUBE_V, CUBE_F.astype(float))
    with pytest.raises(ValueError, match=r"\[0, 2\^31 - 1\]"):
        _gauss6.validate_mesh(CUBE_V, np.full((1, 3), 2 ** 64 - 1, dtype=np.uint64))
    # The cube itself, in any integer dtype, is accepted.
    assert _gauss6.mass_properties(CUBE_V, CUBE_F.astype(np.uint16), 1.0)["volume"] == pytest.approx(1.0)


def test_huge_quaternions_are_rescaled_not_nan():
    d = _gauss6.pose_difference([0, 0, 0], [1e300, 1e300, 0, 0], [0, 0, 0], [1, 0, 0, 0])
    assert np.all(np.isfinite(d))
    assert d[3] == pytest.approx(math.pi / 2)
    p, q = _gauss6.pose_update([0, 0, 0], [1e-300, 1e-300, 0, 0], np.zeros(6))
    assert np.allclose(q, [math.sqrt(0.5), math.sqrt(0.5), 0, 0])
    R = _gauss6.rotation_matrix([1e200, 0, 0, 1e200])
    assert np.allclose(R, [[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    for q in ([0, 0, 0, 0], [math.nan, 1, 0, 0], [math.inf, 0, 0, 0]):
        with pytest.raises(ValueError, match="quaternion"):
            _gauss6.pose_difference([0, 0, 0], q, [0, 0, 0], [1, 0, 0, 0])


# ---------------------------------------------------------------------------
# Property tests: bad numbers give a clear error or a finite answer, never a NaN.

doubles = st.floats(allow_nan=True, allow_infinity=True, width=64)
finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
quats = st.lists(doubles, min_size=4, max_size=4)
vec3 = st.lists(doubles, min_size=3, max_size=3)


@settings(max_examples=300, deadline=None)
@given(p=vec3, q=quats, ps=vec3, qs=quats)
def test_pose_difference_is_finite_or_refused(p, q, ps, qs):
    try:
        d = _gauss6.pose_difference(p, q, ps, qs)
    except ValueError as e:
        assert "finite" in str(e) or "quaternion" in str(e)
        return
    # Accepted: finite input. The angular part is always finite; the linear part
    # is a difference of finite doubles, which may overflow only to +-inf, never NaN.
    assert not np.any(np.isnan(d))
    assert np.all(np.isfinite(d[3:]))


@settings(max_examples=300, deadline=None)
@given(q=quats)
def test_rotation_matrix_is_a_rotation_or_refused(q):
    try:
        R = _gauss6.rotation_matrix(q)
    except ValueError:
        assert not all(map(math.isfinite, q)) or all(x == 0 for x in q)
        return
    assert np.all(np.isfinite(R))
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(V=st.lists(st.lists(st.one_of(st.floats(min_value=-1e100, max_value=1e100), st.just(math.nan),
                                    st.just(math.inf)), min_size=3, max_size=3), min_size=3, max_size=6),
       F=st.lists(st.lists(st.integers(-2 ** 40, 2 ** 40), min_size=3, max_size=3), min_size=1, max_size=4))
def test_mass_properties_of_bad_meshes_are_refused(V, F):
    try:
        out = _gauss6.mass_properties(np.array(V, float), np.array(F, np.int64), 1.0)
    except ValueError:
        return
    assert all(np.all(np.isfinite(np.asarray(v))) for v in out.values())


@settings(max_examples=300, deadline=None)
@given(M=st.lists(doubles, min_size=36, max_size=36), au=st.lists(doubles, min_size=6, max_size=6),
       J=st.lists(st.lists(doubles, min_size=6, max_size=6), min_size=0, max_size=8))
def test_projection_never_returns_nan(M, au, J):
    M = np.array(M, float).reshape(6, 6)
    J = np.array(J, float).reshape(-1, 6)
    r = _gauss6.project(M, np.array(au, float), J)
    assert np.all(np.isfinite(r.ac))
    assert r.status in ("optimal", "bad_input", "iteration_cap", "uncertified")


@settings(max_examples=200, deadline=None)
@given(scale=st.floats(min_value=-300, max_value=300), au=st.lists(finite, min_size=6, max_size=6))
def test_projection_of_any_spd_scale_is_finite(scale, au):
    M = np.eye(6) * 10.0 ** scale
    J = np.array([[0, 0, 1, 0, 0, 0]], float)
    r = _gauss6.project(M, np.array(au, float), J)
    assert np.all(np.isfinite(r.ac))


# ---------------------------------------------------------------------------
# Hand scripts: their errors are gauss6.LoadError, as every file's


@pytest.mark.parametrize("script", [
    {"keys": []},
    {"keys": [{"t": 0, "p": [0, 0, 0]}, {"t": 0, "p": [0, 0, 1]}]},
    {"keys": [{"t": 0, "p": [0, 0, 0], "q": [0, 0, 0, 0]}]},
])
def test_hand_script_errors_are_load_errors(script):
    with pytest.raises(gauss6.LoadError, match="my_script.json: .*hand script"):
        _gauss6.device.SimulatedDevice(json.dumps(script), origin="my_script.json")
