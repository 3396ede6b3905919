"""Read gauss6 run traces (docs/trace-format.md) into numpy arrays, and export them to CSV.

    tr = read_trace("run.g6trace")
    tr.ticks["t"], tr.ticks["xh_p"] (N, 3), tr.ticks["wrench"] (N, 6), ...
    tr.steps, tr.contacts, tr.events   (numpy structured arrays)
    tr.meta                            (the header's JSON metadata, a dict)
    to_csv(tr, "out/")                 (ticks.csv, steps.csv, contacts.csv, events.csv, meta.json)

Pure Python and numpy: no extension needed. A file cut mid-chunk (a crash) reads up to
its last complete chunk with a TraceWarning (and Trace.complete False: `coverage(tr)` states
what a trace covers, for verdicts to say so); a malformed file raises TraceFormatError naming
the file and the problem: among them ticks whose times repeat or go back, and a path that is
not a regular file (paths.check_input_file: a FIFO or a device is never read).
"""
from __future__ import annotations

import hashlib
import json
import math
import struct
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._gauss6 import LoadError

MAGIC = b"G6TRACE\0"
VERSION = 2             # written; version 2 added the steps' update_cpu_time
OLDEST_VERSION = 1      # read: versions 1 and 2 (a version 1 step has update_cpu_time NaN)
HEADER = struct.Struct("<8sIIQ")  # magic, version, flags, metadata length
CHUNK = struct.Struct("<IIQ")     # type, row width (float64 values), row count

TICKS, STEPS, CONTACTS, EVENTS, END = 1, 2, 3, 4, 5
STREAMS = {TICKS: "ticks", STEPS: "steps", CONTACTS: "contacts", EVENTS: "events"}

# Version 2 columns (name, width); the metadata repeats them under "columns".
COLUMNS = {
    "ticks": [("t", 1), ("xh_p", 3), ("xh_q", 4), ("xs_p", 3), ("xs_q", 4), ("wrench", 6),
              ("num_contacts", 1), ("force_time", 1), ("status", 1), ("flags", 1), ("buttons", 1)],
    "steps": [("step", 1), ("t", 1), ("update_time", 1), ("num_contacts", 1), ("status", 1),
              ("update_cpu_time", 1)],
    "contacts": [("step", 1), ("t", 1), ("point", 3), ("normal", 3), ("separation", 1)],
    "events": [("t", 1), ("code", 1), ("value", 1)],
}
EVENT_CODES = {1: "phase", 2: "let_go", 3: "watchdog", 4: "device_lost", 5: "device_reconnected",
               6: "device_ended"}
TICK_FLAGS = {"gripped": 1, "new_contact_set": 2, "force_clamped": 4, "watchdog": 8}
DEVICE_STATUS = {0: "ok", 1: "not_connected", 2: "timeout", 3: "ended", 4: "error"}


class TraceFormatError(LoadError):
    """A malformed trace: the message names the file and the problem. A gauss6.LoadError
    (so a ValueError), as the C++ reader's TraceError is."""


class TraceWarning(UserWarning):
    """A readable but incomplete trace (cut mid-chunk, or never closed)."""


def _dtype(columns) -> np.dtype:
    return np.dtype([(name, "<f8") if width == 1 else (name, "<f8", (width,)) for name, width in columns])


DTYPES = {name: _dtype(cols) for name, cols in COLUMNS.items()}


@dataclass
class Trace:
    path: Path
    version: int
    meta: dict
    ticks: np.ndarray       # structured: t, xh_p (3), xh_q (4: w x y z), xs_p, xs_q, wrench (6), ...
    steps: np.ndarray
    contacts: np.ndarray
    events: np.ndarray
    complete: bool = False  # the end chunk was found: the writer closed the file
    dropped: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    sha256: str = ""        # of the file read (read_trace); "" for a trace built in memory

    def event_names(self) -> list[str]:
        codes = {int(k): v for k, v in self.meta.get("event_codes", {}).items()} or EVENT_CODES
        return [codes.get(int(c), f"code_{int(c)}") for c in self.events["code"]]


def read_trace(path) -> Trace:
    """Reads a trace; see the module docstring for truncated and malformed files."""
    from .paths import PathError, read_input_bytes

    path = Path(path)
    try:
        data = read_input_bytes(path, "trace")
    except PathError as e:
        raise TraceFormatError(str(e)) from None

    def fail(problem: str) -> TraceFormatError:
        return TraceFormatError(f"{path}: {problem}")

    if len(data) < HEADER.size:
        raise fail(f"not a gauss6 trace: {len(data)} bytes, shorter than the header")
    magic, version, _flags, meta_len = HEADER.unpack_from(data, 0)
    if magic != MAGIC:
        raise fail('not a gauss6 trace: bad magic (expected "G6TRACE\\0")')
    if not OLDEST_VERSION <= version <= VERSION:
        raise fail(f"unsupported trace version {version} (this reader reads versions {OLDEST_VERSION} to {VERSION})")
    if meta_len > len(data) - HEADER.size:
        raise fail(f"metadata block of {meta_len} bytes runs past the end of the file")
    try:
        meta = json.loads(data[HEADER.size:HEADER.size + meta_len].decode("utf-8"))
    except (ValueError, RecursionError):  # bad UTF-8 or JSON, too many digits, nesting too deep
        raise fail("the metadata block is not valid JSON") from None
    if not isinstance(meta, dict):
        raise fail("the metadata block is not a JSON object")
    problem = metadata_problem(meta)
    if problem:
        raise fail(f"metadata: {problem}")

    parts: dict[str, list[np.ndarray]] = {name: [] for name in COLUMNS}
    widths = {name: sum(w for _, w in cols) for name, cols in COLUMNS.items()}
    if version == 1:
        widths["steps"] -= 1  # without update_cpu_time
    complete, dropped, notes = False, {}, []
    pos = HEADER.size + meta_len
    while pos < len(data):
        if len(data) - pos < CHUNK.size:
            notes.append(f"{path}: cut mid-chunk at byte {pos} (partial chunk header); "
                         "read up to the last complete chunk")
            break
        ctype, ncols, nrows = CHUNK.unpack_from(data, pos)
        name = STREAMS.get(ctype)
        expected = widths[name] if name else (4 if ctype == END else 0)
        if expected and ncols != expected:
            raise fail(f"chunk at byte {pos} of type {ctype} has rows of {ncols} values, expected {expected}")
        if ncols == 0:
            raise fail(f"chunk at byte {pos} has rows of 0 values")
        remaining = len(data) - pos - CHUNK.size
        if nrows > remaining // (8 * ncols):
            notes.append(f"{path}: cut mid-chunk at byte {pos} ({nrows} rows announced, {remaining} bytes left); "
                         "read up to the last complete chunk")
            break
        start, nbytes = pos + CHUNK.size, nrows * ncols * 8
        if name == "steps" and version == 1:  # widened: update_cpu_time NaN (not measured)
            old = np.frombuffer(data, dtype=_dtype(COLUMNS["steps"][:-1]), count=nrows, offset=start)
            rows = np.full(nrows, np.nan, dtype=DTYPES["steps"])
            for field in old.dtype.names:
                rows[field] = old[field]
            parts[name].append(rows)
        elif name:
            parts[name].append(np.frombuffer(data, dtype=DTYPES[name], count=nrows, offset=start))
        elif ctype == END:
            complete = True
            if nrows >= 1:
                d = np.frombuffer(data, dtype="<f8", count=4, offset=start)
                if not _integers_in(d, 0, MAX_COUNT):
                    raise fail(f"end chunk at byte {pos}: dropped counts {d.tolist()} are not integers in [0, 2^53]")
                dropped = dict(zip(["ticks", "steps", "contacts", "events"], (int(x) for x in d)))
        else:
            notes.append(f"{path}: skipped a chunk of unknown type {ctype} at byte {pos}")
        pos = start + nbytes
    if not complete and not notes:
        notes.append(f"{path}: no end chunk: the writer did not close the file "
                     "(a crash loses the last flush period)")
    for note in notes:
        warnings.warn(note, TraceWarning, stacklevel=2)

    def table(name: str) -> np.ndarray:
        return np.concatenate(parts[name]) if parts[name] else np.zeros(0, dtype=DTYPES[name])

    tr = Trace(path=path, version=version, meta=meta, ticks=table("ticks"), steps=table("steps"),
               contacts=table("contacts"), events=table("events"), complete=complete,
               dropped=dropped, warnings=notes, sha256=hashlib.sha256(data).hexdigest())
    problem = check_streams(tr)
    if problem:
        raise fail(problem)
    return tr


def metadata_problem(meta: dict) -> str:
    """'' when the metadata's typed fields are well-formed (event_codes an object of code ->
    name, codes integers in [0, 2^32 - 1]; phases a list of {name: string, start: finite
    number}; scene a string; device an object), else the first problem (the field named)."""
    codes = meta.get("event_codes", {})
    if not isinstance(codes, dict) or not all(
            isinstance(k, str) and k.isdigit() and len(k) < 10 and int(k) <= 2 ** 32 - 1 and isinstance(v, str)
            for k, v in codes.items()):
        return "event_codes is not an object of code (an integer in [0, 2^32 - 1], as a string) -> name"
    phases = meta.get("phases", [])
    if not isinstance(phases, list) or not all(
            isinstance(p, dict) and isinstance(p.get("name"), str) and _finite_number(p.get("start"))
            for p in phases):
        return "phases is not a list of {name: string, start: finite number}"
    if not isinstance(meta.get("scene", ""), str):
        return "scene is not a string"
    if not isinstance(meta.get("device", {}), dict):
        return "device is not an object"
    return ""


def _finite_number(x) -> bool:
    """x is a JSON number (not a bool) that is a finite double."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return False
    try:
        return math.isfinite(float(x))
    except OverflowError:
        return False


MAX_COUNT = float(2 ** 53)  # every count a double holds exactly


def _integers_in(values: np.ndarray, lo: float, hi: float) -> bool:
    """Every value is an integer in [lo, hi] (False for NaN and infinities)."""
    v = np.asarray(values, dtype="<f8")
    with np.errstate(invalid="ignore"):
        return bool(np.all((v >= lo) & (v <= hi) & (np.trunc(v) == v)))


# The columns that stand for integers, with their ranges (the C++ reader's check_integer_columns).
INTEGER_COLUMNS = [
    ("ticks", "num_contacts", 0, 2 ** 31 - 1), ("ticks", "status", 0, max(DEVICE_STATUS)),
    ("ticks", "flags", 0, 2 ** 32 - 1), ("ticks", "buttons", 0, 2 ** 32 - 1),
    ("steps", "step", 0, MAX_COUNT), ("steps", "num_contacts", 0, 2 ** 31 - 1),
    ("steps", "status", -2 ** 31, 2 ** 31 - 1), ("contacts", "step", 0, MAX_COUNT),
    ("events", "code", 0, 2 ** 32 - 1),
]


def check_streams(tr: Trace) -> str:
    """'' when tr's streams hold what read_trace accepts: tick times finite and increasing, the
    columns that stand for integers holding integers in range (the C++ reader's
    check_integer_columns); else the first problem."""
    t = tr.ticks["t"]
    if not np.all(np.isfinite(t)):
        return "ticks: t is not finite"
    back = np.nonzero(np.diff(t) <= 0)[0]
    if len(back):
        k = int(back[0]) + 1
        return (f"ticks: tick {k} has t = {float(t[k])!r}, {'the same as' if t[k] == t[k - 1] else 'before'} "
                f"tick {k - 1}'s {float(t[k - 1])!r} (ticks repeated or out of time order)")
    for stream, column, lo, hi in INTEGER_COLUMNS:
        if not _integers_in(getattr(tr, stream)[column], lo, hi):
            return f"{stream}: {column} is not an integer in [{lo}, {hi}]"
    return ""


MAX_COORDINATE = 1e12  # the C++ kMaxSceneCoordinate (scene.h): positions beyond it are refused


def coverage(tr: Trace) -> dict:
    """What a trace covers, for a verdict or a certificate to state: its ticks, their time span,
    whether it is complete (closed by its writer) and why not, and a digest of the run (the
    file's sha256, or of the tick rows for a trace read from CSV)."""
    t = tr.ticks["t"]
    digest = tr.sha256 or hashlib.sha256(np.ascontiguousarray(tr.ticks).tobytes()).hexdigest()
    return {"ticks": int(len(t)), "t_first": float(t[0]) if len(t) else None,
            "t_last": float(t[-1]) if len(t) else None, "span": float(t[-1] - t[0]) if len(t) else 0.0,
            "complete": bool(tr.complete), "cut": list(tr.warnings), "dropped": dict(tr.dropped),
            "sha256": digest, "digest_of": "file" if tr.sha256 else "tick rows"}


def coverage_line(cov: dict) -> str:
    """coverage() in one sentence for a report."""
    span = (f"t = {cov['t_first']:.6g} to {cov['t_last']:.6g} s ({cov['span']:.6g} s)" if cov["ticks"]
            else "no time")
    state = "complete" if cov["complete"] else "**INCOMPLETE** (" + "; ".join(cov["cut"] or ["not closed"]) + ")"
    return f"{cov['ticks']} ticks, {span}, {state}; sha256 {cov['sha256'][:16]}... of the {cov['digest_of']}"


def checked_poses(tr: Trace) -> Trace:
    """The trace with its quaternions (xh_q, xs_q) scaled by powers of two to a largest
    component in [0.5, 1) (exact: the same rotation; a pose's meaning does not depend on the
    quaternion's size, and 1e300 or 1e-300 would overflow or underflow a norm); TraceFormatError
    for a finite position beyond MAX_COORDINATE (tick and column named). Non-finite and zero
    poses are left for the verdicts to judge."""
    ticks = tr.ticks.copy()
    for column in ("xh_p", "xs_p"):
        v = ticks[column]
        with np.errstate(invalid="ignore"):
            far = np.nonzero(np.any(np.isfinite(v) & (np.abs(v) > MAX_COORDINATE), axis=1))[0]
        if len(far):
            k = int(far[0])
            raise TraceFormatError(f"{tr.path}: tick {k} (t = {float(ticks['t'][k])!r}): {column} "
                                   f"{v[k].tolist()} is beyond {MAX_COORDINATE:g}, the largest coordinate "
                                   f"gauss6 takes ({len(far)} such ticks)")
    for column in ("xh_q", "xs_q"):
        q = ticks[column]
        with np.errstate(invalid="ignore"):
            big = np.max(np.where(np.isfinite(q), np.abs(q), 0.0), axis=1)
        _, e = np.frexp(big)
        ok = np.all(np.isfinite(q), axis=1) & (big > 0)
        ticks[column] = np.where(ok[:, None], np.ldexp(q, -np.where(ok, e, 0)[:, None]), q)
    out = Trace(**{**tr.__dict__, "ticks": ticks})
    return out


def _flat(arr: np.ndarray, name: str) -> tuple[list[str], np.ndarray]:
    """Column headers and a 2-D float array: subarray fields become name_0, name_1, ..."""
    headers, cols = [], []
    for field_name, width in COLUMNS[name]:
        col = arr[field_name]
        if width == 1:
            headers.append(field_name)
            cols.append(col.reshape(-1, 1))
        else:
            headers += [f"{field_name}_{i}" for i in range(width)]
            cols.append(col.reshape(-1, width))
    return headers, (np.hstack(cols) if cols else np.zeros((0, 0)))


def to_csv(trace: Trace, out_dir) -> list[Path]:
    """Writes ticks.csv, steps.csv, contacts.csv, events.csv and meta.json into out_dir.

    Quaternions are (w, x, y, z): xh_q_0 is w. Values are written with 17 significant
    digits, so a CSV reads back to the same doubles. Returns the files written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name in ("ticks", "steps", "contacts", "events"):
        headers, values = _flat(getattr(trace, name), name)
        if name == "events":
            headers = headers + ["name"]
            names = trace.event_names()
            lines = [",".join(headers)] + [",".join([*(f"{v:.17g}" for v in row), n]) for row, n in zip(values, names)]
        else:
            lines = [",".join(headers)] + [",".join(f"{v:.17g}" for v in row) for row in values]
        p = out / f"{name}.csv"
        p.write_text("\n".join(lines) + "\n")
        written.append(p)
    p = out / "meta.json"
    p.write_text(json.dumps({**trace.meta, "complete": trace.complete, "dropped": trace.dropped}, indent=2) + "\n")
    written.append(p)
    return written


def export_csv(trace_path, out_dir) -> str:
    """`gauss6 trace export TRACE --csv DIR`: reads the trace, writes the CSV files, returns a summary line."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", TraceWarning)
        tr = read_trace(trace_path)
    files = to_csv(tr, out_dir)
    summary = (f"{tr.path}: {len(tr.ticks)} ticks, {len(tr.steps)} steps, {len(tr.contacts)} contacts, "
               f"{len(tr.events)} events -> {', '.join(f.name for f in files)} in {out_dir}")
    notes = [str(w.message) for w in caught]
    return "\n".join([summary] + [f"warning: {n}" for n in notes])


def trace_metadata(scene: str = "", device: dict | None = None, phases=(), extra: dict | None = None) -> dict:
    """A trace's metadata with the fields the C++ writer fills (format, version, columns, event codes)."""
    return {
        "format": "gauss6-trace", "version": VERSION, "scene": scene,
        "device": device or {"name": "", "rate_hz": 0.0, "renders_force": False},
        "phases": [{"name": str(n), "start": float(s)} for n, s in phases],
        "columns": {**{name: [[c, w] for c, w in cols] for name, cols in COLUMNS.items()},
                    "end": [["ticks", 1], ["steps", 1], ["contacts", 1], ["events", 1]]},
        "event_codes": {str(k): v for k, v in EVENT_CODES.items()},
        "extra": extra or {},
    }


def write_trace(trace: Trace, path) -> Path:
    """Writes trace (its meta and four streams, one chunk each, then the end chunk with
    trace.dropped) as a current-version file that read_trace reads back to the same doubles."""
    path = Path(path)
    meta = dict(trace.meta)
    meta.setdefault("format", "gauss6-trace")
    meta.setdefault("version", VERSION)
    meta_bytes = json.dumps(meta, separators=(",", ":")).encode("utf-8")
    parts = [HEADER.pack(MAGIC, VERSION, 0, len(meta_bytes)), meta_bytes]
    for ctype, name in STREAMS.items():
        rows = np.ascontiguousarray(getattr(trace, name), dtype=DTYPES[name])
        width = sum(w for _, w in COLUMNS[name])
        parts.append(CHUNK.pack(ctype, width, len(rows)) + rows.view("<f8").tobytes())
    dropped = [float(trace.dropped.get(k, 0)) for k in ("ticks", "steps", "contacts", "events")]
    parts.append(CHUNK.pack(END, 4, 1) + np.asarray(dropped, dtype="<f8").tobytes())
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"".join(parts))
    return path
