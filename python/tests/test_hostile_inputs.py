"""Hostile inputs to the commands that came after the first probe set (README.md, "Bad input:
refused, repaired or reported"), one class a section:

- verdicts on runs that are not there: traces without ticks, cut, with repeated or
  back-going tick times, empty or out-of-range tick ranges, quaternions of any size,
  positions beyond the coordinate bound; what certify and validate covered is stated;
- files that are not files: FIFOs, devices, directories, lines longer than a format's row,
  an empty thresholds file;
- importers: every field checked where it enters, so that nothing is written that the
  trace reader refuses;
- the viewer page: non-finite values never reach its JSON;
- arguments and outputs: durations, counts, output paths, paths that are not UTF-8.
Campaign chunk files are in test_campaign_damage.py, the browser test in test_view.py.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest

from gauss6 import LoadError, logs, paths, trace
from gauss6.cli import main
from gauss6.cli_args import MAX_RUN_SECONDS
from gauss6.trace import DTYPES, Trace, TraceFormatError, read_trace, trace_metadata, write_trace
from gauss6.validate import EXIT_USAGE

from test_certify import PEG, peg_run  # noqa: F401  (a 1.5 s peg run, shared)


def _trace(t, **columns) -> Trace:
    ticks = np.zeros(len(t), dtype=DTYPES["ticks"])
    ticks["t"] = t
    ticks["xh_q"] = ticks["xs_q"] = [1.0, 0, 0, 0]
    for k, v in columns.items():
        ticks[k] = v
    empty = {name: np.zeros(0, dtype=DTYPES[name]) for name in ("steps", "contacts", "events")}
    return Trace(path="x", version=2, meta=trace_metadata("peg_in_hole"), ticks=ticks, complete=True, **empty)


def _exit(argv, capsys) -> tuple[int, str]:
    """main(argv)'s exit status (parse-time refusals included) and its stderr."""
    return main(argv), capsys.readouterr().err


def refused(code: int, argv) -> bool:
    """A command's refusal of its input: argparse's 2, or validate's usage code (its 2 means the engine failed)."""
    return code == (EXIT_USAGE if argv[0] == "validate" else 2)


# ---------------------------------------------------------------------------------------------
# Verdicts on runs that are not there

@pytest.mark.parametrize("t", [[0.0, 0.001, 0.001, 0.002], [0.0, 0.002, 0.001]], ids=["repeated", "back"])
def test_trace_reader_refuses_ticks_repeated_or_out_of_time_order(tmp_path, t):
    path = write_trace(_trace(t), tmp_path / "bad.g6trace")
    with pytest.raises(TraceFormatError, match=r"bad.g6trace: ticks: tick 2 .*repeated or out of time order"):
        read_trace(path)


def _cut(src, dst, keep) -> object:
    data = src.read_bytes()
    dst.write_bytes(data[:keep if isinstance(keep, int) else int(keep * len(data))])
    return dst


def _header_size(path) -> int:
    magic, version, flags, meta_len = trace.HEADER.unpack_from(path.read_bytes(), 0)
    return trace.HEADER.size + meta_len


def test_certify_validate_and_view_refuse_a_run_without_ticks(tmp_path, capsys, peg_run):
    no_ticks = write_trace(_trace([]), tmp_path / "empty.g6trace")
    header_only = _cut(peg_run, tmp_path / "header.g6trace", _header_size(peg_run))
    in_first_chunk = _cut(peg_run, tmp_path / "chunk.g6trace", _header_size(peg_run) + trace.CHUNK.size + 100)
    for run in (no_ticks, header_only, in_first_chunk):
        code, err = _exit(["view", str(run), "--scene", str(PEG), "--out", str(tmp_path / "p.html")], capsys)
        assert code == 2 and "holds no ticks" in err, err
        code, err = _exit(["certify", str(run), "--scene", str(PEG), "--out", str(tmp_path / "c"), "--quiet"], capsys)
        assert code == 2 and "holds no ticks" in err, err
        code, err = _exit(["validate", str(run), "--scene", str(PEG), "--out", str(tmp_path / "v"), "--quiet"], capsys)
        assert code == EXIT_USAGE and "holds no ticks" in err, err
    assert not (tmp_path / "c" / "certify.json").exists() and not (tmp_path / "v" / "validation.json").exists()


@pytest.mark.parametrize("ticks,message", [("5:5", "empty"), ("7:3", "empty"), ("-1:4", "empty or negative"),
                                           ("0:1000000", "beyond the trace"), ("a:b", "integers")])
def test_certify_refuses_an_empty_tick_range_or_one_beyond_the_trace(tmp_path, capsys, peg_run, ticks, message):
    code, err = _exit(["certify", str(peg_run), "--scene", str(PEG), f"--ticks={ticks}", "--out", str(tmp_path),
                       "--quiet"], capsys)
    assert code == 2 and any(m in err for m in message.split("|")), err


def test_a_cut_trace_is_judged_with_the_cut_stated_in_every_output(tmp_path, capsys, peg_run):
    cut = _cut(peg_run, tmp_path / "cut.g6trace", 0.6)
    whole = read_trace(peg_run)
    with pytest.warns(trace.TraceWarning):
        survived = read_trace(cut)
    assert 0 < len(survived.ticks) < len(whole.ticks)

    code, err = _exit(["certify", str(cut), "--scene", str(PEG), "--out", str(tmp_path / "c"), "--quiet"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "c" / "certify.json").read_text())
    cov = doc["coverage"]
    assert cov["complete"] is False and cov["cut"] and cov["ticks"] == len(survived.ticks)
    assert cov["t_last"] == float(survived.ticks["t"][-1]) and cov["digest_of"] == "file"
    assert doc["ticks"] == [0, len(survived.ticks)]
    import hashlib

    assert cov["sha256"] == hashlib.sha256(cut.read_bytes()).hexdigest()
    md = (tmp_path / "c" / "certify.md").read_text()
    assert "INCOMPLETE" in md and "Only part of the run" in md

    code, err = _exit(["validate", str(cut), "--scene", str(PEG), "--out", str(tmp_path / "v"), "--quiet"], capsys)
    assert code in (0, 1) and "judged on the ticks it holds" in err
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["coverage"]["complete"] is False and doc["coverage"]["ticks"] == len(survived.ticks)
    assert "INCOMPLETE" in (tmp_path / "v" / "report.md").read_text()

    # The whole run says it is complete.
    assert _exit(["certify", str(peg_run), "--scene", str(PEG), "--out", str(tmp_path / "w"), "--quiet"], capsys)[0] == 0
    assert json.loads((tmp_path / "w" / "certify.json").read_text())["coverage"]["complete"] is True


@pytest.mark.parametrize("scale", [1e-300, 1e300, 2.0 ** -1000])
def test_quaternions_of_any_size_are_judged_as_their_rotation(tmp_path, capsys, peg_run, scale):
    """The verdicts on a run whose quaternions are scaled are the verdicts on the run (the
    rescaling is by powers of two: exact)."""
    tr = read_trace(peg_run)
    scaled = Trace(**{**tr.__dict__, "ticks": tr.ticks.copy()})
    with np.errstate(under="ignore"):
        scaled.ticks["xs_q"] *= scale
        scaled.ticks["xh_q"] *= scale
    path = write_trace(scaled, tmp_path / "scaled.g6trace")
    docs = []
    for run, name in ((peg_run, "plain"), (path, "scaled")):
        code, err = _exit(["validate", str(run), "--scene", str(PEG), "--out", str(tmp_path / name), "--quiet"],
                          capsys)
        assert code == 0, err
        docs.append(json.loads((tmp_path / name / "validation.json").read_text()))
    strip = [[(v["name"], v["pass"], v["count"]) for v in d["verdicts"]] for d in docs]
    assert strip[0] == strip[1]
    code, err = _exit(["certify", str(path), "--scene", str(PEG), "--out", str(tmp_path / "c"), "--quiet", "--ticks",
                       "0:300"], capsys)
    assert code == 0, err


@pytest.mark.parametrize("column", ["xs_p", "xh_p"])
def test_positions_beyond_the_coordinate_bound_are_refused_by_name(tmp_path, capsys, peg_run, column):
    tr = read_trace(peg_run)
    far = Trace(**{**tr.__dict__, "ticks": tr.ticks.copy()})
    far.ticks[column][17] = [1e13, 0.0, 0.0]
    path = write_trace(far, tmp_path / "far.g6trace")
    for argv in (["validate", str(path), "--scene", str(PEG), "--out", str(tmp_path / "v"), "--quiet"],
                 ["certify", str(path), "--scene", str(PEG), "--out", str(tmp_path / "c"), "--quiet"]):
        code, err = _exit(argv, capsys)
        assert refused(code, argv) and f"tick 17" in err and column in err and "beyond 1e+12" in err, err


@pytest.mark.parametrize("column", ["xs_q", "xh_q"])
def test_offline_validate_refuses_a_zero_quaternion_by_tick(tmp_path, capsys, peg_run, column):
    tr = read_trace(peg_run)
    ticks = tr.ticks.copy()
    ticks[column][23] = 0.0
    path = write_trace(Trace(**{**tr.__dict__, "ticks": ticks}), tmp_path / "zero.g6trace")
    code, err = _exit(["validate", str(path), "--scene", str(PEG), "--out", str(tmp_path / "v"), "--quiet"], capsys)
    assert code == EXIT_USAGE and f"tick 23 (t = {float(ticks['t'][23])!r}): {column} is the zero quaternion" in err, err


def test_the_coordinate_bound_is_the_cpp_one():
    text = (paths.REPO_ROOT / "optimized" / "gauss6" / "io" / "scene.h").read_text()
    assert f"kMaxSceneCoordinate = {trace.MAX_COORDINATE:.0e}".replace("+", "") in text


# ---------------------------------------------------------------------------------------------
# Files that are not files

@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "fifo"
    os.mkfifo(path)
    return path


def _not_files(tmp_path, fifo):
    return {"fifo": (fifo, "a FIFO"), "dev-zero": ("/dev/zero", "a character device"),
            "directory": (tmp_path, "a directory")}


def test_readers_refuse_what_is_not_a_regular_file_without_reading(tmp_path, fifo):
    for name, (path, kind) in _not_files(tmp_path, fifo).items():
        with pytest.raises(TraceFormatError, match=kind):
            read_trace(path)
        with pytest.raises(LoadError, match=kind):
            logs.read_hapi(path)
        with pytest.raises(paths.PathError, match=kind):
            paths.read_input_text(path, "thresholds file")


def test_commands_refuse_what_is_not_a_regular_file(tmp_path, fifo):
    """In a child process with a timeout: a reader that opened the FIFO would hang."""
    good_trace = write_trace(_trace([0.0, 0.001]), tmp_path / "ok.g6trace")
    cases = []
    for name, (path, kind) in _not_files(tmp_path, fifo).items():
        cases += [
            (["scene", "info", str(path)], kind),
            (["certify", str(path), "--scene", str(PEG)], kind),
            (["certify", str(good_trace), "--scene", str(path)], kind),
            (["view", str(path), "--scene", str(PEG), "--out", str(tmp_path / "p.html")], kind),
            (["replay", str(path), "--scene", str(PEG), "--out", str(tmp_path / "r.g6trace")], kind),
            (["validate", str(good_trace), "--scene", str(PEG), "--thresholds", str(path), "--out",
              str(tmp_path / "v")], kind),
            (["trace", "import", str(path), "--format", "hapi", "--out", str(tmp_path / "i.g6trace")], kind),
            (["trace", "export", str(path), "--csv", str(tmp_path / "csv")], kind),
        ]
    cases.append((["validate", str(fifo), "--scene", str(PEG), "--out", str(tmp_path / "v")], "a FIFO"))
    for argv, kind in cases:
        done = subprocess.run([sys.executable, "-m", "gauss6.cli", *argv], capture_output=True, text=True,
                              timeout=60)
        assert refused(done.returncode, argv) and kind in done.stderr and "Traceback" not in done.stderr, (argv, done.stderr)


def _scene_naming(tmp_path, source: str, target: str, path) -> object:
    """A copy of a shipped scene whose files are absolute paths, `target` replaced by path."""
    text = (paths.DATASETS_DIR / "scenes" / source).read_text()
    text = text.replace('"../', f'"{paths.DATASETS_DIR}/').replace(target, str(path))
    scene = tmp_path / f"named-{source}"
    scene.write_text(text)
    return scene


def test_files_a_scene_names_are_refused_when_they_are_not_regular_files(tmp_path, fifo):
    """The C++ loaders (scene, height map, hand script) check what a path is before opening it
    (gauss6/io/regular_file.h): in a child process with a timeout, as a FIFO would hang a reader."""
    fifo_json = tmp_path / "script.json"
    os.mkfifo(fifo_json)
    code = ("import sys; from gauss6._gauss6 import runtime\n"
            "from gauss6.scene import load_scene\n"
            "try:\n    {}\nexcept Exception as e:\n    print(type(e).__name__, e); sys.exit(3)\n")
    cases = [
        (code.format(f"load_scene({str(fifo)!r})"), "a FIFO, not a regular file"),
        (code.format("load_scene('/dev/zero')"), "a character device, not a regular file"),
        (code.format(f"load_scene({str(_scene_naming(tmp_path, 'heightmap.toml', '{0}/surfaces/bumps.png'.format(paths.DATASETS_DIR), fifo))!r})"),
         "a FIFO, not a regular file"),
        (code.format(f"runtime.run_scenario({str(_scene_naming(tmp_path, 'peg_in_hole.toml', chr(34) + 'peg_in_hole' + chr(34), repr(str(fifo_json)).replace(chr(39), chr(34))))!r}, "
                     f"{str(tmp_path / 'r.g6trace')!r}, threaded=False, duration=0.1, lockstep_sim_period=1, "
                     "extra_json='{}', progress=None)"), "a FIFO, not a regular file"),
    ]
    for source, message in cases:
        done = subprocess.run([sys.executable, "-c", source], capture_output=True, text=True, timeout=60)
        assert done.returncode == 3 and message in done.stdout, (source, done.stdout, done.stderr)


def test_a_log_line_longer_than_a_row_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "long.log"
    with open(path, "w") as f:
        f.write("TIME POSITION\n0 1 2 3\n")
        f.write("1" * (40 << 20))
        f.write(" 0 0 0\n")
    tracemalloc.start()
    try:
        with pytest.raises(LoadError, match=r"long.log:3: line longer than 65536 bytes"):
            logs.read_hapi(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 4 << 20, peak  # bytes held while refusing a 40 MB line: one row's bound, not the line


def test_an_empty_thresholds_file_is_an_error(tmp_path):
    from gauss6.thresholds import load_thresholds

    for text in ("", "\n# nothing\n"):
        (tmp_path / "t.toml").write_text(text)
        with pytest.raises(ValueError, match="t.toml: the thresholds file is empty"):
            load_thresholds(tmp_path / "t.toml")


# ---------------------------------------------------------------------------------------------
# Importers: each field checked where it enters

HAPI_BAD = [
    ("TIME POSITION BUTTONS\n0 0 0 0 1\n0.001 0 0 0 1e20\n", r":3:13: BUTTONS 1e\+20 is not a button mask"),
    ("TIME POSITION BUTTONS\n0 0 0 0 -1\n", r":2:9: BUTTONS -1.0 is not a button mask"),
    ("TIME POSITION BUTTONS\n0 0 0 0 0.5\n", r":2:9: BUTTONS 0.5 is not a button mask"),
    ("TIME POSITION\n0 0 2e12 0\n", r":2:5: POSITION 2000000000000.0 is not within"),
]


@pytest.mark.parametrize("text,message", HAPI_BAD)
def test_hapi_import_refuses_fields_out_of_range_by_line_and_column(tmp_path, text, message):
    (tmp_path / "in.log").write_text(text)
    with pytest.raises(LoadError, match="in.log" + message):
        logs.import_log(tmp_path / "in.log", "hapi", tmp_path / "out.g6trace")
    assert not (tmp_path / "out.g6trace").exists()


CSV_BAD = [
    ("ticks.csv", "t,xh_p_0,xh_p_1,xh_p_2,num_contacts\n0,0,0,0,0.5\n", r"ticks.csv:2:9: num_contacts 0.5"),
    ("ticks.csv", "t,xh_p_0,xh_p_1,xh_p_2,status\n0,0,0,0,0\n1,0,0,0,99\n", r"ticks.csv:3:9: status 99.0"),
    ("ticks.csv", "t,xh_p_0,xh_p_1,xh_p_2,flags\n0,0,0,0,-3\n", r"ticks.csv:2:9: flags -3.0"),
    ("ticks.csv", "t,xh_p_0,xh_p_1,xh_p_2,buttons\n0,0,0,0,1e20\n", r"ticks.csv:2:9: buttons 1e\+20"),
    ("ticks.csv", "t,xh_p_0,xh_p_1,xh_p_2,xh_q_0,xh_q_1,xh_q_2,xh_q_3\n0,0,0,0,0,0,0,0\n",
     r"ticks.csv:2:9: xh_q is the zero quaternion"),
    ("ticks.csv", "t,xh_p_0,xh_p_1,xh_p_2,xs_q_0,xs_q_1,xs_q_2,xs_q_3\n0,0,0,0,1,0,0,0\n1,0,0,0,0,0,0,0\n",
     r"ticks.csv:3:9: xs_q is the zero quaternion"),
    ("events.csv", "t,code,value\n0,1e20,0\n", r"events.csv:2:3: code 1e\+20"),
    ("events.csv", "t,code,value\n0,-1,0\n", r"events.csv:2:3: code -1.0"),
    ("steps.csv", "step,t,update_time,num_contacts,status\n0.5,0,0,0,0\n", r"steps.csv:2:1: step 0.5"),
    ("contacts.csv", "step,t\n-3,0\n", r"contacts.csv:2:1: step -3.0"),
    ("meta.json", '{"phases": ["approach", "press"]}', r"meta.json: phases is not a list"),
    ("meta.json", '{"event_codes": [1, 2]}', r"meta.json: event_codes is not an object"),
    ("meta.json", '{"event_codes": {"-1": "x"}}', r"meta.json: event_codes is not an object"),
    ("meta.json", '{"event_codes": {"100000000000000000000": "x"}}', r"meta.json: event_codes is not an object"),
    ("meta.json", '{"scene": 3}', r"meta.json: scene is not a string"),
    ("meta.json", '{"device": [1]}', r"meta.json: device is not an object"),
    ("meta.json", '[1, 2]', r"meta.json: not a JSON object"),
    ("meta.json", '{"dropped": {"ticks": -1}}', r"meta.json: dropped is not an object"),
    ("meta.json", '{"device": {"rate_hz": NaN}}', r"meta.json: a metadata number is not finite"),
]


@pytest.mark.parametrize("name,text,message", CSV_BAD, ids=[f"{n}-{i}" for i, (n, _, _) in enumerate(CSV_BAD)])
def test_csv_import_refuses_fields_of_the_wrong_type_naming_file_line_and_field(tmp_path, name, text, message):
    d = tmp_path / "csv"
    d.mkdir()
    (d / "ticks.csv").write_text("t,xh_p_0,xh_p_1,xh_p_2\n0,0,0,0\n0.001,0,0,0\n")
    (d / name).write_text(text)
    with pytest.raises(LoadError, match=message):
        logs.import_log(d, "csv", tmp_path / "out.g6trace")
    assert not (tmp_path / "out.g6trace").exists()


CORPUS = paths.REPO_ROOT / "python" / "tests" / "corpus" / "import"


def _mutations(data: bytes, rng, n: int):
    """Seeded byte-level mutations of a corpus file: numbers swapped for hostile ones, bytes
    flipped, lines dropped or repeated."""
    hostile = [b"1e20", b"-1", b"0.5", b"99", b"-3", b"nan", b"inf", b"1e300", b"", b"\xff", b"4294967296"]
    for _ in range(n):
        lines = data.split(b"\n")
        for _ in range(rng.integers(1, 4)):
            k = int(rng.integers(len(lines)))
            kind = rng.integers(4)
            fields = lines[k].split(b"," if b"," in lines[k] else b" ")
            if kind == 0 and fields:
                fields[int(rng.integers(len(fields)))] = hostile[int(rng.integers(len(hostile)))]
                lines[k] = (b"," if b"," in lines[k] else b" ").join(fields)
            elif kind == 1 and lines[k]:
                b = bytearray(lines[k])
                b[int(rng.integers(len(b)))] = int(rng.integers(256))
                lines[k] = bytes(b)
            elif kind == 2:
                del lines[k]
            else:
                lines.insert(k, lines[k])
            if not lines:
                break
        yield b"\n".join(lines)


def test_import_regression_corpus_and_its_mutations_never_write_what_the_reader_refuses(tmp_path):
    """Every file of python/tests/corpus/import/ (HAPI logs *.log, CSV directories) and 150 seeded
    mutations of each: import either refuses it (a LoadError naming the file) or writes a trace
    that read_trace reads back to the same ticks. Nothing else: no traceback."""
    rng = np.random.default_rng(47)
    entries = sorted(CORPUS.iterdir())
    assert len(entries) >= 4
    outcomes = {"refused": 0, "written": 0}
    for entry in entries:
        fmt = "hapi" if entry.suffix == ".log" else "csv"
        files = [entry] if fmt == "hapi" else sorted(entry.iterdir())
        for f in files:
            for i, data in enumerate([f.read_bytes(), *_mutations(f.read_bytes(), rng, 150)]):
                work = tmp_path / f"{entry.name}-{f.name}-{i}"
                if fmt == "csv":
                    work.mkdir()
                    for other in files:
                        (work / other.name).write_bytes(other.read_bytes())
                    (work / f.name).write_bytes(data)
                else:
                    work.write_bytes(data)
                out = tmp_path / "out.g6trace"
                out.unlink(missing_ok=True)
                try:
                    _, tr = logs.import_log(work, fmt, out)
                except LoadError as e:
                    assert str(work) in str(e), e
                    outcomes["refused"] += 1
                    continue
                back = read_trace(out)
                np.testing.assert_array_equal(back.ticks.view("<f8"), tr.ticks.view("<f8"))
                outcomes["written"] += 1
    assert outcomes["refused"] > 100 and outcomes["written"] > 10, outcomes


# ---------------------------------------------------------------------------------------------
# The viewer page: no non-finite number in its JSON

def test_view_page_data_is_strict_json_with_non_finite_values(tmp_path, peg_run):
    from gauss6 import view

    tr = read_trace(peg_run)
    ticks = tr.ticks.copy()
    ticks["wrench"][10:20] = np.nan
    ticks["wrench"][30, 2] = np.inf
    ticks["xs_p"][40] = np.nan
    events = np.zeros(2, dtype=DTYPES["events"])
    events["t"], events["code"], events["value"] = [0.1, 0.2], [3, 4], [np.nan, -np.inf]
    meta = {**tr.meta, "device": {**tr.meta["device"], "rate_hz": float("nan"), "max_force": float("inf")}}
    bad = write_trace(Trace(**{**tr.__dict__, "ticks": ticks, "events": events, "meta": meta}), tmp_path / "nan.g6trace")
    page = view.write_view([bad], PEG, tmp_path / "nan.html").read_text()
    start = page.index('<script id="gauss6-data" type="application/json">') + len(
        '<script id="gauss6-data" type="application/json">')
    text = page[start:page.index("</script>", start)]

    def refuse(name):
        raise AssertionError(f"{name} in the page's JSON")

    data = json.loads(text, parse_constant=refuse)
    run = data["runs"][0]
    assert [e["value"] for e in run["events"]] == [None, None]
    assert run["device"]["rate_hz"] is None and run["device"]["max_force"] is None
    assert np.isfinite(run["max_force"]) and run["max_force"] > 0
    assert run["non_finite"] == {"wrench_ticks": 11, "pose_ticks": 1}


# ---------------------------------------------------------------------------------------------
# Arguments and outputs

@pytest.mark.parametrize("argv", [
    ["validate", "--engine", "gauss6", "--duration", "inf"],
    ["validate", "--engine", "gauss6", "--duration", "nan"],
    ["validate", "--engine", "gauss6", "--duration", "1e7"],
    ["validate", "--engine", "gauss6", "--duration", "-1"],
    ["rate", "--duration", "inf"],
    ["rate", "--duration", "1e7"],
    ["replay", "REC", "--duration", "inf"],
    ["replay", "REC", "--duration", "0"],
    ["view", "REC", "--max-frames", "-5"],
    ["view", "REC", "--max-frames", "0"],
    ["crosscheck", "qp", "--seeded", "10", "--workers", "-1"],
    ["crosscheck", "qp", "--seeded", "10", "--chunk-size", "0"],
    ["crosscheck", "ccd", "--seeded", "0"],
    ["reproduce", "engines", "--slice", "nan"],
], ids=lambda a: " ".join(a[:1] + a[-2:]))
def test_counts_and_durations_out_of_range_are_refused_at_parse_time(tmp_path, capsys, peg_run, argv):
    argv = [str(peg_run) if a == "REC" else a for a in argv]
    needs = {"validate": ["--scene", str(PEG)], "replay": ["--scene", str(PEG)], "reproduce": []}
    argv += needs.get(argv[0], []) + ["--out", str(tmp_path / "out")]
    code, err = _exit(argv, capsys)
    assert refused(code, argv) and "Traceback" not in err and ("must be" in err or "duration" in err), err
    assert not (tmp_path / "out").exists()


def test_a_recording_spanning_more_than_a_run_can_last_is_refused(tmp_path, capsys):
    rec = write_trace(_trace([0.0, 0.001, 1e9], xh_p=[[0, 0, 0.1]] * 3, xs_p=[[0, 0, 0.1]] * 3), tmp_path / "long.g6trace")
    code, err = _exit(["replay", str(rec), "--scene", str(PEG), "--out", str(tmp_path / "r.g6trace")], capsys)
    assert code == 2 and "spans 1e+09 s" in err and f"{MAX_RUN_SECONDS:g} s" in err, err


def test_a_hand_script_spanning_more_than_a_run_can_last_is_refused(tmp_path, capsys):
    script = json.loads((paths.DATASETS_DIR / "scripts" / "peg_in_hole.json").read_text())
    script["keys"][-1]["t"] = script["end_time"] = 1e9
    (tmp_path / "long.json").write_text(json.dumps(script))
    code, err = _exit(["validate", "--engine", "gauss6", "--scene", str(PEG), "--script", str(tmp_path / "long.json"),
                       "--out", str(tmp_path / "v"), "--quiet"], capsys)
    assert code == EXIT_USAGE and "the hand script spans 1e+09 s" in err, err


def _outputs(tmp_path):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    locked = tmp_path / "locked"
    locked.mkdir()
    return a_file, locked


def test_out_paths_that_cannot_be_written_are_refused_cleanly(tmp_path, capsys, peg_run):
    a_file, _ = _outputs(tmp_path)
    under_file = a_file / "sub"
    hapi = tmp_path / "x.log"
    hapi.write_text("TIME POSITION\n0 0 0 0\n")
    cases = [
        (["validate", str(peg_run), "--scene", str(PEG), "--out", str(a_file)], "not a directory"),
        (["validate", str(peg_run), "--scene", str(PEG), "--out", str(under_file)], "not a directory"),
        (["certify", str(peg_run), "--scene", str(PEG), "--out", str(a_file)], "not a directory"),
        (["view", str(peg_run), "--scene", str(PEG), "--out", str(tmp_path)], "existing directory"),
        (["view", str(peg_run), "--scene", str(PEG), "--out", str(under_file / "p.html")], "not a directory"),
        (["trace", "import", str(hapi), "--format", "hapi", "--out", str(tmp_path)], "existing directory"),
        (["trace", "export", str(peg_run), "--csv", str(a_file)], "not a directory"),
        (["trace", "export", str(peg_run), "--hapi", str(tmp_path)], "existing directory"),
        (["reproduce", "peg", "--out", str(a_file)], "not a directory"),
        (["crosscheck", "qp", "--seeded", "10", "--out", str(a_file)], "not a directory"),
        (["replay", str(peg_run), "--scene", str(PEG), "--out", str(tmp_path)], "existing directory"),
        (["report", "qp", "--out", str(under_file)], "not a directory"),
    ]
    if os.geteuid() != 0:  # root writes anywhere
        _, locked = _outputs(tmp_path / "perm")
        locked.chmod(0o500)
        cases.append((["certify", str(peg_run), "--scene", str(PEG), "--out", str(locked / "c")], "not writable"))
    for argv, message in cases:
        code, err = _exit(argv, capsys)
        assert refused(code, argv) and message in err and "Traceback" not in err, (argv, err)


def test_a_scene_path_that_is_not_utf8_is_refused_by_name(tmp_path):
    name = os.fsencode(tmp_path) + b"/sc\xe8ne.toml"
    with open(name, "wb") as f:
        f.write(PEG.read_bytes())
    run = write_trace(_trace([0.0, 0.001]), tmp_path / "x.g6trace")
    for argv in (["scene", "info", name], ["certify", os.fsencode(run), "--scene", name]):
        done = subprocess.run([sys.executable, "-m", "gauss6.cli", *argv], capture_output=True, timeout=60)
        err = done.stderr.decode("utf-8", "replace")
        assert done.returncode == 2 and "not UTF-8" in err and "Traceback" not in err, err


def test_the_readme_states_these_bounds_as_the_code_defines_them():
    readme = (paths.REPO_ROOT / "README.md").read_text()
    assert f"({logs.MAX_LINE // 1024} KiB; a 40 MB line)" in readme
    assert MAX_RUN_SECONDS == 86400.0 and "over a day (`cli_args.MAX_RUN_SECONDS`)" in readme
    assert trace.MAX_COORDINATE == 1e12 and "positions beyond 1e12 (`trace.MAX_COORDINATE`" in readme
