"""Log formats other frameworks use, both ways: HAPI's device log (ASCII) and plain CSV per stream.

    export_hapi(trace, "run.log")            gauss6 trace -> HAPI DeviceLog ASCII form
    read_hapi("run.log") -> Trace            HAPI log -> a gauss6 trace (ticks only)
    read_csv_dir("csv/") -> Trace            to_csv()'s files (or one ticks.csv) -> a gauss6 trace
    import_log(path, "hapi"|"csv", out)      either, written as a .g6trace that replay reads

A session recorded by another framework becomes a gauss6 trace whose ticks carry the handle's
poses (xh), so the replay device (device/include/gauss6/replay_device.h, which reads a trace's
ticks) plays it back. Formats and conventions: docs/trace-format.md, "Other formats".

HAPI's DeviceLog (ASCII): a header line of column names separated by spaces (TIME, POSITION,
ORIENTATION, VELOCITY, FORCE, TORQUE, BUTTONS, RAW_POSITION, RAW_ORIENTATION, RAW_VELOCITY,
RAW_FORCE, RAW_TORQUE, TIMESTAMP, in any order and subset), then one row per logged haptic
frame of whitespace-separated values: TIME s since the log started; POSITION, VELOCITY x y z
(m, m/s); ORIENTATION an axis-angle rotation "x y z angle" (unit axis, radians); FORCE (N),
TORQUE (N m) x y z; BUTTONS the button bit mask; TIMESTAMP s. HAPI writes 5 decimals; the
export here writes each double's shortest repr, which reads back exactly.

A malformed log raises LogFormatError (a gauss6.LoadError) naming FILE:LINE:COLUMN and the
problem: an unknown column name, a wrong number of values, a value that is not a finite
number, a time that does not increase, an integer column (BUTTONS, flags, status, event
codes, counts) holding a value that is not an integer in its range, a position beyond the
coordinate bound, a line longer than MAX_LINE bytes (refused before the rest of it is read),
metadata (meta.json) whose fields have the wrong type. Every field is checked where it
enters, so that what import writes, the trace reader, replay, view and validate accept.
"""
from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path

import numpy as np

from ._gauss6 import LoadError
from .paths import PathError, read_input_lines, read_input_text
from .trace import (COLUMNS, DTYPES, INTEGER_COLUMNS, MAX_COORDINATE, MAX_COUNT, TICK_FLAGS, Trace, TraceWarning,
                    check_streams, export_csv, metadata_problem, read_trace, trace_metadata, write_trace)

# HAPI DeviceLog columns and their widths (values per column).
HAPI_WIDTHS = {"TIME": 1, "POSITION": 3, "ORIENTATION": 4, "VELOCITY": 3, "FORCE": 3, "TORQUE": 3, "BUTTONS": 1,
               "RAW_POSITION": 3, "RAW_ORIENTATION": 4, "RAW_VELOCITY": 3, "RAW_FORCE": 3, "RAW_TORQUE": 3,
               "TIMESTAMP": 1}
HAPI_EXPORT_COLUMNS = ["TIME", "POSITION", "ORIENTATION", "FORCE", "TORQUE", "BUTTONS"]
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
MAX_LINE = 1 << 16  # bytes: a row of these formats (at most 35 numbers) never comes near it
MAX_META = 1 << 24  # bytes of a CSV export's meta.json


class LogFormatError(LoadError):
    """A malformed foreign log: FILE:LINE:COLUMN: problem (a gauss6.LoadError, so a ValueError)."""


# ---------------------------------------------------------------------------------------------
# Orientation: trace quaternions (w, x, y, z), possibly not unit <-> HAPI axis-angle.

def quaternion_to_axis_angle(q: np.ndarray) -> np.ndarray:
    """(N, 4) quaternions (w, x, y, z) -> (N, 4) rotations (axis x, y, z, angle in [0, pi]).

    Normalised first; the sign with w >= 0 is taken (the shortest way round). The identity's
    axis is (1, 0, 0), as H3D's default Rotation."""
    q = np.asarray(q, dtype=float).reshape(-1, 4)
    n = np.linalg.norm(q, axis=1, keepdims=True)
    if np.any(n == 0) or not np.all(np.isfinite(n)):
        raise ValueError("a quaternion is zero or not finite")
    q = q / n * np.where(q[:, :1] < 0, -1.0, 1.0)
    s = np.linalg.norm(q[:, 1:], axis=1)
    angle = 2.0 * np.arctan2(s, q[:, 0])
    axis = np.where(s[:, None] > 0, q[:, 1:] / np.where(s > 0, s, 1.0)[:, None], [1.0, 0.0, 0.0])
    return np.hstack([axis, angle[:, None]])


def axis_angle_to_quaternion(r: np.ndarray) -> np.ndarray:
    """(N, 4) rotations (axis x, y, z, angle) -> (N, 4) unit quaternions (w, x, y, z).
    The axis is normalised; a zero axis is the identity."""
    r = np.asarray(r, dtype=float).reshape(-1, 4)
    n = np.linalg.norm(r[:, :3], axis=1)
    half = 0.5 * np.where(n > 0, r[:, 3], 0.0)
    axis = r[:, :3] / np.where(n > 0, n, 1.0)[:, None]
    return np.hstack([np.cos(half)[:, None], np.sin(half)[:, None] * axis])


# ---------------------------------------------------------------------------------------------
# A table of numbers, with errors that name the file, line and column.

def _tokens(line: str, sep: str | None):
    """(1-based character column, token) of each field of a line: whitespace- or sep-separated."""
    if sep is None:
        return [(m.start() + 1, m.group()) for m in re.finditer(r"\S+", line)]
    out, col = [], 1
    for field in line.split(sep):
        stripped = field.strip()
        out.append((col + (len(field) - len(field.lstrip())), stripped))
        col += len(field) + len(sep)
    return out


def _lines(path: Path) -> list[str]:
    """The file's lines (paths.read_input_lines: a regular file, no line over MAX_LINE bytes, UTF-8)."""
    try:
        return read_input_lines(path, "log", MAX_LINE)
    except PathError as e:
        raise LogFormatError(str(e)) from None


def _check_values(path: Path, values: np.ndarray, line_numbers: list, col_of, name: str, lo: float, hi: float,
                  integer: bool, meaning: str = "") -> None:
    """Each value of a column in [lo, hi] (an integer when `integer`): else FILE:LINE:COL naming
    the field. col_of(row index) -> the value's character column on its line."""
    v = np.asarray(values, dtype=float)
    with np.errstate(invalid="ignore"):
        ok = (v >= lo) & (v <= hi) & ((np.trunc(v) == v) if integer else True)
    bad = np.nonzero(~ok)[0]
    if len(bad):
        k = int(bad[0])
        what = f"an integer in [{lo:.0f}, {hi:.0f}]" if integer else f"within [{lo:g}, {hi:g}]"
        what = f"{meaning} ({what})" if meaning else what
        raise LogFormatError(f"{path}:{line_numbers[k]}:{col_of(k)}: {name} {float(v[k])!r} is not {what}")


def _read_table(path: Path, sep: str | None, names_of, lines: list[str] | None = None):
    """Reads a header line and rows of numbers. Returns (header tokens, values (N, C), line numbers).

    names_of(header tokens, line number) -> the number of values a row must have, or raises
    LogFormatError. lines: the file's lines when already read (default: read path)."""
    lines = _lines(path) if lines is None else lines
    header_at = next((i for i, line in enumerate(lines) if line.strip()), None)
    if header_at is None:
        raise LogFormatError(f"{path}: the file is empty (no header line)")
    header = _tokens(lines[header_at], sep)
    width = names_of(header, header_at + 1)
    rows, line_numbers = [], []
    for i in range(header_at + 1, len(lines)):
        line = lines[i]
        if not line.strip():
            continue
        fields = _tokens(line, sep)
        if len(fields) != width:
            col = fields[width][0] if len(fields) > width else len(line.rstrip()) + 1
            raise LogFormatError(f"{path}:{i + 1}:{col}: {len(fields)} values, the header names {width}")
        row = []
        for col, token in fields:
            if not _NUMBER.fullmatch(token):
                raise LogFormatError(f"{path}:{i + 1}:{col}: not a number: {token!r}")
            row.append(float(token))
            if not math.isfinite(row[-1]):
                raise LogFormatError(f"{path}:{i + 1}:{col}: not a finite number: {token!r}")
        rows.append(row)
        line_numbers.append(i + 1)
    values = np.asarray(rows, dtype=float).reshape(len(rows), width)
    return header, values, line_numbers


def _check_header(path: Path, line_no: int, header, known: list[str], kind: str, required: list[str]) -> list[str]:
    """The header's column names, checked: each known, none twice, the required ones there."""
    names: list[str] = []
    for col, token in header:
        if token not in known:
            raise LogFormatError(f"{path}:{line_no}:{col}: unknown {kind} column {token!r} (known: {', '.join(known)})")
        if token in names:
            raise LogFormatError(f"{path}:{line_no}:{col}: column {token} named twice")
        names.append(token)
    missing = [r for r in required if r not in names]
    if missing:
        raise LogFormatError(f"{path}:{line_no}:1: the header has no {', '.join(missing)} column")
    return names


def _check_times(path: Path, t: np.ndarray, line_numbers: list, value_index: int, sep: str | None) -> None:
    """Times must increase strictly: else an error at the first offending row's time value."""
    if len(t) == 0:
        raise LogFormatError(f"{path}: no rows after the header")
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if len(bad):
        k = int(bad[0]) + 1
        line = _lines(path)[line_numbers[k] - 1]
        col = _tokens(line, sep)[value_index][0]
        raise LogFormatError(f"{path}:{line_numbers[k]}:{col}: time {float(t[k])!r} does not increase "
                             f"(the row before has {float(t[k - 1])!r})")


def _ticks_from(t, xh_p, xh_q, wrench=None, buttons=None) -> np.ndarray:
    """Tick rows for a foreign session: the handle's poses; the god-object's pose is the handle's
    (the log has none); gripped throughout, so that the replay device holds the body."""
    ticks = np.zeros(len(t), dtype=DTYPES["ticks"])
    ticks["t"], ticks["xh_p"], ticks["xh_q"] = t, xh_p, xh_q
    ticks["xs_p"], ticks["xs_q"] = xh_p, xh_q
    if wrench is not None:
        ticks["wrench"] = wrench
    if buttons is not None:
        ticks["buttons"] = buttons
    ticks["flags"] = TICK_FLAGS["gripped"]
    return ticks


def _empty(name: str) -> np.ndarray:
    return np.zeros(0, dtype=DTYPES[name])


def _rate(t: np.ndarray) -> float:
    return float((len(t) - 1) / (t[-1] - t[0])) if len(t) > 1 and t[-1] > t[0] else 0.0


# ---------------------------------------------------------------------------------------------
# HAPI DeviceLog (ASCII)

def export_hapi(trace: Trace, path) -> Path:
    """Writes the trace's ticks as a HAPI DeviceLog (ASCII): TIME POSITION ORIENTATION FORCE
    TORQUE BUTTONS, with POSITION and ORIENTATION the handle's pose xh, FORCE and TORQUE the
    wrench sent to the device. Each double is written as its shortest repr (exact)."""
    ticks = trace.ticks
    rot = quaternion_to_axis_angle(ticks["xh_q"]) if len(ticks) else np.zeros((0, 4))
    lines = [" ".join(HAPI_EXPORT_COLUMNS)]
    for k in range(len(ticks)):
        values = [ticks["t"][k], *ticks["xh_p"][k], *rot[k], *ticks["wrench"][k]]
        lines.append(" ".join(repr(float(v)) for v in values) + f" {int(ticks['buttons'][k])}")
    path = Path(path)
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def read_hapi(path, scene: str = "") -> Trace:
    """Reads a HAPI DeviceLog (ASCII) into a trace of ticks (xh from POSITION and ORIENTATION,
    the wrench from FORCE and TORQUE, buttons from BUTTONS; the other columns are checked and
    left out). TIME and POSITION are required; ORIENTATION defaults to the identity."""
    path = Path(path)
    layout: dict[str, tuple[int, int]] = {}

    def names_of(header, line_no):
        offset = 0
        for name in _check_header(path, line_no, header, list(HAPI_WIDTHS), "HAPI log", ["TIME", "POSITION"]):
            layout[name] = (offset, HAPI_WIDTHS[name])
            offset += HAPI_WIDTHS[name]
        return offset

    lines = _lines(path)
    header, values, line_numbers = _read_table(path, None, names_of, lines)

    def column(name):
        off, w = layout[name]
        return values[:, off:off + w]

    t = column("TIME")[:, 0]
    _check_times(path, t, line_numbers, layout["TIME"][0], None)

    def col_of(name, k, i=0):  # the character column of value i of column `name` on row k
        return _tokens(lines[line_numbers[k] - 1], None)[layout[name][0] + i][0]

    for name in ("POSITION", "RAW_POSITION"):
        for i in range(3 if name in layout else 0):
            _check_values(path, column(name)[:, i], line_numbers, lambda k: col_of(name, k, i), name,
                          -MAX_COORDINATE, MAX_COORDINATE, False)
    if "BUTTONS" in layout:
        b = column("BUTTONS")[:, 0]
        _check_values(path, b, line_numbers, lambda k: col_of("BUTTONS", k), "BUTTONS", 0, 2 ** 32 - 1, True,
                      "a button mask")
    else:
        b = np.zeros(len(t))
    q = axis_angle_to_quaternion(column("ORIENTATION")) if "ORIENTATION" in layout else np.tile([1.0, 0, 0, 0],
                                                                                                 (len(t), 1))
    wrench = np.zeros((len(t), 6))
    if "FORCE" in layout:
        wrench[:, :3] = column("FORCE")
    if "TORQUE" in layout:
        wrench[:, 3:] = column("TORQUE")
    ignored = [n for n in layout if n not in ("TIME", "POSITION", "ORIENTATION", "FORCE", "TORQUE", "BUTTONS")]
    meta = trace_metadata(scene=scene, device={"name": f"hapi log: {path.name}", "rate_hz": _rate(t),
                                               "renders_force": False},
                          extra={"imported_from": {"format": "hapi", "file": str(path),
                                                   "columns": [n for _, n in header], "ignored": ignored}})
    return Trace(path=path, version=1, meta=meta, ticks=_ticks_from(t, column("POSITION"), q, wrench, b),
                 steps=_empty("steps"), contacts=_empty("contacts"), events=_empty("events"), complete=True)


# ---------------------------------------------------------------------------------------------
# CSV per stream (the files of trace.to_csv)

def _flat_names(name: str) -> list[str]:
    return [c if w == 1 else f"{c}_{i}" for c, w in COLUMNS[name] for i in range(w)]


def _read_stream_csv(path: Path, name: str, required: list[str]) -> np.ndarray:
    """One stream's CSV: a header of flat column names (to_csv's: xh_p_0, ...), in any order,
    a subset holding the required ones (the others are 0; events' last column, 'name', is skipped)."""
    known = _flat_names(name)
    order: list[int] = []

    def names_of(header, line_no):
        order.extend(known.index(t) for t in _check_header(path, line_no, header, known, name, required))
        return len(header)

    lines = _lines(path)
    if name == "events" and lines and lines[0].split(",")[-1].strip() == "name":
        lines = [line.rsplit(",", 1)[0] for line in lines]  # the event's name: text, after the numbers
    header, values, line_numbers = _read_table(path, ",", names_of, lines)
    flat = np.zeros((len(values), len(known)))
    for j, k in enumerate(order):
        flat[:, k] = values[:, j]
    if name == "ticks":
        _check_times(path, flat[:, 0], line_numbers, [tok for _, tok in header].index("t"), ",")
    names = [tok for _, tok in header]

    def col_of(j):
        return lambda k: _tokens(lines[line_numbers[k] - 1], ",")[j][0]

    checks = [(c, lo, hi, True) for stream, c, lo, hi in INTEGER_COLUMNS if stream == name]
    if name == "ticks":
        checks += [(f"{c}_{i}", -MAX_COORDINATE, MAX_COORDINATE, False) for c in ("xh_p", "xs_p") for i in range(3)]
    for column, lo, hi, integer in checks:
        if column in names:
            j = names.index(column)
            _check_values(path, values[:, j], line_numbers, col_of(j), column, lo, hi, integer)
    for q in ("xh_q", "xs_q") if name == "ticks" else ():  # replay and validate refuse a zero rotation
        if f"{q}_0" in names:
            at = known.index(f"{q}_0")
            zero = np.nonzero(np.all(flat[:, at:at + 4] == 0, axis=1))[0]
            if len(zero):
                k = int(zero[0])
                raise LogFormatError(f"{path}:{line_numbers[k]}:{col_of(names.index(f'{q}_0'))(k)}: {q} is the "
                                     "zero quaternion (no rotation)")
    return np.ascontiguousarray(flat).view(DTYPES[name]).reshape(-1)


def read_csv_dir(path, scene: str = "") -> Trace:
    """Reads to_csv()'s files back into a trace: a directory with ticks.csv (required),
    steps.csv, contacts.csv, events.csv and meta.json (each optional), or a single ticks CSV.

    A ticks file needs t and xh_p_0..2; xh_q defaults to the identity, xs to xh, flags to gripped."""
    path = Path(path)
    files = {"ticks": path / "ticks.csv"} if path.is_dir() else {"ticks": path}
    if path.is_dir():
        for name in ("steps", "contacts", "events"):
            if (path / f"{name}.csv").exists():
                files[name] = path / f"{name}.csv"
    if not files["ticks"].exists():
        raise LogFormatError(f"{files['ticks']}: cannot open the file: no such file")
    ticks = _read_stream_csv(files["ticks"], "ticks", ["t", "xh_p_0", "xh_p_1", "xh_p_2"])
    header = next(line for line in _lines(files["ticks"]) if line.strip()).split(",")
    header = [h.strip() for h in header]
    if "xh_q_0" not in header:
        ticks["xh_q"] = [1.0, 0.0, 0.0, 0.0]
    if "xs_p_0" not in header:
        ticks["xs_p"] = ticks["xh_p"]
    if "xs_q_0" not in header:
        ticks["xs_q"] = ticks["xh_q"]
    if "flags" not in header:
        ticks["flags"] = TICK_FLAGS["gripped"]
    streams = {name: _read_stream_csv(files[name], name, ["t"]) if name in files else _empty(name)
               for name in ("steps", "contacts", "events")}
    if "steps" in files and "update_cpu_time" not in (_lines(files["steps"]) or [""])[0]:
        streams["steps"]["update_cpu_time"] = np.nan  # not measured (a version 1 trace's export)
    meta_path = path / "meta.json" if path.is_dir() else None
    dropped: dict = {}
    if meta_path is not None and meta_path.exists():
        meta, dropped = _read_meta(meta_path)
    else:
        meta = trace_metadata(scene=scene, device={"name": f"csv: {path.name}", "rate_hz": _rate(ticks["t"]),
                                                   "renders_force": False},
                              extra={"imported_from": {"format": "csv", "file": str(path)}})
    return Trace(path=path, version=1, meta=meta, ticks=ticks, complete=True, dropped=dropped, **streams)


def _read_meta(meta_path: Path) -> tuple[dict, dict]:
    """A CSV export's meta.json: (metadata, dropped counts), each field checked as the trace
    reader checks it (LogFormatError naming the file and the field)."""
    try:
        text = read_input_text(meta_path, "metadata file", MAX_META)
    except PathError as e:
        raise LogFormatError(str(e)) from None
    try:
        meta = json.loads(text)
    except json.JSONDecodeError as e:
        raise LogFormatError(f"{meta_path}:{e.lineno}:{e.colno}: not valid JSON: {e.msg}") from None
    except (ValueError, RecursionError):
        raise LogFormatError(f"{meta_path}: not valid JSON (a number too long or nesting too deep)") from None
    if not isinstance(meta, dict):
        raise LogFormatError(f"{meta_path}: not a JSON object of trace metadata")
    meta.pop("complete", None)
    dropped = meta.pop("dropped", {}) or {}
    problem = metadata_problem(meta)
    if problem:
        raise LogFormatError(f"{meta_path}: {problem}")
    if not isinstance(dropped, dict) or not all(
            k in ("ticks", "steps", "contacts", "events") and not isinstance(v, bool) and isinstance(v, int)
            and 0 <= v <= MAX_COUNT for k, v in dropped.items()):
        raise LogFormatError(f"{meta_path}: dropped is not an object of stream -> count (an integer in [0, 2^53])")
    try:
        json.dumps(meta, allow_nan=False)
    except ValueError:
        raise LogFormatError(f"{meta_path}: a metadata number is not finite (NaN or Infinity)") from None
    return meta, dropped


# ---------------------------------------------------------------------------------------------
# Commands: gauss6 trace export --hapi FILE; gauss6 trace import FILE --format hapi|csv --out TRACE

def import_log(path, fmt: str, out, scene: str = "") -> tuple[Path, Trace]:
    """Reads a HAPI log or CSV and writes it as a gauss6 trace at out. Returns (out, the trace)."""
    trace = read_hapi(path, scene) if fmt == "hapi" else read_csv_dir(path, scene)
    problem = check_streams(trace)  # what the trace reader would refuse is never written
    if problem:
        raise LogFormatError(f"{path}: {problem}")
    return write_trace(trace, out), trace


def export_trace(trace_path, hapi=None, csv=None) -> str:
    """Exports a trace to CSV files (trace.export_csv) and/or a HAPI log; returns summary lines
    (and the reader's warnings)."""
    lines = [export_csv(trace_path, csv)] if csv else []
    if hapi:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", TraceWarning)
            tr = read_trace(trace_path)
        export_hapi(tr, hapi)
        lines.append(f"{tr.path}: {len(tr.ticks)} ticks -> HAPI device log {hapi} ({' '.join(HAPI_EXPORT_COLUMNS)})")
        if not csv:  # export_csv reported them
            lines += [f"warning: {w.message}" for w in caught]
    return "\n".join(lines)
