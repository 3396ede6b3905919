"""`gauss6 view TRACE [TRACE ...] --scene SCENE [--out page.html]`: a self-contained web page of runs.

The page shows the scene's meshes, the god-object (xs) and the handle's ghost (xh) over time, the
contact points and normals of the last sim step, the force and torque as arrows at G, the phases
on a timeline with play, pause and scrub, and the force, torque, contacts and timing plots linked
to the time cursor. Several traces (two engines' runs of one scene, say) are drawn side by side.

The page needs no network: its script (viewer/src/viewer.js bundled with three.js from the npm
registry, pinned in viewer/package-lock.json; `npm ci && npm run build` in viewer/, which
tools/setup.sh runs) and the run data are inlined. Runs longer than MAX_FRAMES ticks are
down-sampled for the page (evenly spaced ticks, the page says so); so are their sim steps.
The page's script exposes window.gauss6View (seek(t), play(), pause(), state(k), canvasStats()).

Non-finite values (the run of an engine that returned NaN, an event value or a metadata number
that is NaN or infinite) never reach the inlined JSON, which a browser could not parse: numbers
in it are finite or null (`_finite_json`), the arrays carry NaN and infinities in their bytes,
and the page draws them as gaps in the plots, a hidden body and "NaN"/"inf" in its readout.
"""
from __future__ import annotations

import base64
import html
import json
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np

from . import paths

MAX_FRAMES = 20_000  # ticks per run kept in a page; sim steps likewise
VIEWER_DIR = paths.REPO_ROOT / "viewer"
BUNDLE = VIEWER_DIR / "dist" / "gauss6-viewer.js"
TEMPLATE = VIEWER_DIR / "src" / "page.html"
# An installed wheel carries both in the package (python/CMakeLists.txt); a checkout uses viewer/.
_INSTALLED = Path(__file__).resolve().parent / "viewer"
if not VIEWER_DIR.is_dir() and (_INSTALLED / "gauss6-viewer.js").is_file():
    BUNDLE, TEMPLATE = _INSTALLED / "gauss6-viewer.js", _INSTALLED / "page.html"


class ViewerBuildError(RuntimeError):
    """The viewer's script bundle is missing and cannot be built here."""


def _array(values, dtype: str) -> dict:
    """A numeric array for the page: little-endian bytes, base64 ({"__a": dtype, "b": ...})."""
    with np.errstate(over="ignore", invalid="ignore"):  # a double beyond float32's range is inf in the page
        a = np.ascontiguousarray(np.asarray(values), dtype={"f4": "<f4", "f8": "<f8", "u4": "<u4"}[dtype])
    return {"__a": dtype, "b": base64.b64encode(a.tobytes()).decode("ascii")}


def _finite_json(value):
    """value with every float that is NaN or infinite replaced by None (JSON null): JSON has no
    such numbers, and a page holding them does not load."""
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite_json(v) for v in value]
    return value


def _finite_max(values) -> float:
    """The largest finite value (0 when there is none)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return float(v.max()) if len(v) else 0.0


def pick(n: int, max_n: int) -> np.ndarray:
    """Indices of at most max_n of n rows, evenly spaced, the first and the last included."""
    if n <= max_n:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max_n)).astype(np.int64))


def bundle_script() -> str:
    """The viewer's bundled script; built first (npm run build) when missing or older than its source."""
    sources = list((VIEWER_DIR / "src").glob("*.js")) + [VIEWER_DIR / "package-lock.json"]
    stale = not BUNDLE.exists() or any(s.stat().st_mtime > BUNDLE.stat().st_mtime for s in sources if s.exists())
    if stale:
        npm = shutil.which("npm")
        if npm is None or not (VIEWER_DIR / "node_modules" / "three").is_dir():
            if BUNDLE.exists():
                return BUNDLE.read_text(encoding="utf-8")  # older than its source, but the best there is
            raise ViewerBuildError(f"{BUNDLE}: not built; run tools/setup.sh (npm ci && npm run build in {VIEWER_DIR})")
        done = subprocess.run([npm, "run", "--silent", "build"], cwd=VIEWER_DIR, capture_output=True, text=True)
        if done.returncode != 0:
            raise ViewerBuildError(f"npm run build in {VIEWER_DIR} failed:\n{done.stdout}{done.stderr}")
    return BUNDLE.read_text(encoding="utf-8")


def scene_data(scene) -> dict:
    """Meshes for the page: the obstacles in the world frame and the god-object in its body frame
    (origin at G), from the scene loader (gauss6._gauss6.runtime.scene_geometry)."""
    from ._gauss6 import runtime

    g = runtime.scene_geometry(str(scene))
    return {
        "name": g["name"],
        "obstacles": [{"name": name, "V": _array(V, "f4"), "F": _array(F, "u4")} for name, V, F in g["obstacles"]],
        "god_V": _array(g["god_V"], "f4"),
        "god_F": _array(g["god_F"], "u4"),
    }


def run_data(trace, label: str, max_frames: int = MAX_FRAMES) -> dict:
    """One run for the page: its ticks and steps (down-sampled to max_frames rows each), the
    contacts of the steps kept, its events and phases, and what was left out."""
    ticks, steps, contacts = trace.ticks, trace.steps, trace.contacts
    ti = pick(len(ticks), max_frames)
    si = pick(len(steps), max_frames)
    tk, st = ticks[ti], steps[si]
    # Contacts of each kept step: rows of the contacts stream with its step index.
    order = np.argsort(contacts["step"], kind="stable")
    c_sorted = contacts[order]
    start = np.searchsorted(c_sorted["step"], st["step"], side="left")
    end = np.searchsorted(c_sorted["step"], st["step"], side="right")
    keep = np.concatenate([np.arange(a, b) for a, b in zip(start, end)]) if len(st) else np.zeros(0, np.int64)
    kept = c_sorted[keep.astype(np.int64)]
    counts = end - start
    new_start = np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(counts) else np.zeros(0)
    wrench = tk["wrench"]
    names = trace.event_names()
    return {
        "label": label,
        "path": str(trace.path),
        "scene": trace.meta.get("scene", ""),
        "device": trace.meta.get("device", {}),
        "phases": [{"name": str(p["name"]), "start": float(p["start"])} for p in trace.meta.get("phases", [])],
        "events": [{"t": float(e["t"]), "name": n, "value": float(e["value"])} for e, n in zip(trace.events, names)],
        "ticks": {
            "t": _array(tk["t"], "f8"),
            "xs_p": _array(tk["xs_p"], "f8"), "xs_q": _array(tk["xs_q"], "f8"),
            "xh_p": _array(tk["xh_p"], "f8"), "xh_q": _array(tk["xh_q"], "f8"),
            "wrench": _array(wrench, "f4"),
            "num_contacts": _array(tk["num_contacts"], "u4"),
            "force_time": _array(tk["force_time"], "f4"),
        },
        "steps": {
            "t": _array(st["t"], "f8"),
            "update_time": _array(st["update_time"], "f4"),
            "num_contacts": _array(st["num_contacts"], "u4"),
            "contact_start": _array(new_start, "u4"),
            "contact_end": _array(new_start + counts, "u4"),
        },
        "contacts": {"point": _array(kept["point"], "f4"), "normal": _array(kept["normal"], "f4")},
        "max_contacts": int(counts.max()) if len(counts) else 0,
        "max_force": _finite_max(_norms(ticks["wrench"][:, :3])),
        "max_torque": _finite_max(_norms(ticks["wrench"][:, 3:])),
        "non_finite": {"wrench_ticks": int(np.sum(~np.all(np.isfinite(ticks["wrench"]), axis=1))),
                       "pose_ticks": int(np.sum(~(np.all(np.isfinite(ticks["xs_p"]), axis=1)
                                                  & np.all(np.isfinite(ticks["xs_q"]), axis=1))))},
        "rows": {"ticks": [int(len(ticks)), int(len(ti))], "steps": [int(len(steps)), int(len(si))],
                 "contacts": [int(len(contacts)), int(len(kept))]},
    }


def _norms(v: np.ndarray) -> np.ndarray:
    """Row norms, without overflow warnings (an infinite or huge row's norm is inf)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return np.linalg.norm(np.asarray(v, dtype=float).reshape(len(v), -1), axis=1)


def _label(trace, path: Path, taken: set) -> str:
    """A run's default label: its engine or device name from the metadata, else the file's stem."""
    extra = trace.meta.get("extra") if isinstance(trace.meta.get("extra"), dict) else {}
    label = str(extra.get("engine") or path.stem)
    while label in taken:
        label += "'"
    taken.add(label)
    return label


def default_scene(trace) -> Path | None:
    """The generated scene a trace names in its metadata (datasets_generated/scenes/<scene>.toml), if any."""
    name = str(trace.meta.get("scene", ""))
    candidate = paths.DATASETS_DIR / "scenes" / f"{Path(name).stem}.toml"
    return candidate if name and candidate.exists() else None


def write_view(traces, scene=None, out=None, labels=None, title: str | None = None,
               max_frames: int = MAX_FRAMES) -> Path:
    """Writes the page for one or more traces (paths) of one scene; returns its path.

    scene: the scene TOML (default: the generated scene the first trace names); out: the page
    (default: the first trace's path with .html). Raises gauss6.LoadError for a bad trace or scene.
    """
    from .trace import TraceWarning, read_trace

    paths_in = [Path(t) for t in traces]
    if not paths_in:
        raise ValueError("no trace to view")
    loaded = []
    for p in paths_in:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TraceWarning)  # a cut trace shows what it has
            loaded.append(read_trace(p))
        if len(loaded[-1].ticks) == 0:
            raise ValueError(f"{p}: the trace holds no ticks: there is no run to view")
    if scene is None:
        scene = default_scene(loaded[0])
        if scene is None:
            raise ValueError(f"{paths_in[0]}: its metadata names no known scene ({loaded[0].meta.get('scene')!r}); "
                             "pass --scene")
    taken: set = set()
    names = list(labels or []) + [None] * (len(loaded) - len(labels or []))
    runs = [run_data(tr, name or _label(tr, p, taken), max_frames) for tr, p, name in zip(loaded, paths_in, names)]
    notes = [f"scene {Path(scene).name}"]
    for r in runs:
        (n_t, k_t), (n_s, k_s) = r["rows"]["ticks"], r["rows"]["steps"]
        line = f"{r['label']}: {r['path']} ({n_t} ticks, {n_s} sim steps, {r['rows']['contacts'][0]} contact rows)"
        if k_t < n_t or k_s < n_s:
            line += (f"; down-sampled for this page to {k_t} ticks and {k_s} sim steps, evenly spaced "
                     f"(the trace holds every one)")
        bad = r["non_finite"]
        if bad["wrench_ticks"] or bad["pose_ticks"]:
            line += (f"; non-finite wrench at {bad['wrench_ticks']} ticks, non-finite god-object pose at "
                     f"{bad['pose_ticks']} ticks (drawn as gaps)")
        notes.append(line)
    data = _finite_json({"scene": scene_data(scene), "runs": runs})
    title = title or "gauss6 run: " + " | ".join(r["label"] for r in runs)
    page = TEMPLATE.read_text(encoding="utf-8")
    # Inline the data and the script; "</" inside them could end their <script> element early.
    page = page.replace("@@TITLE@@", html.escape(title)).replace("@@NOTE@@", html.escape("; ".join(notes)))
    page = page.replace("@@DATA@@", json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/"))
    page = page.replace("@@SCRIPT@@", bundle_script().replace("</script", "<\\/script"))
    if max_frames < 1:
        raise ValueError(f"max_frames must be at least 1, not {max_frames}")
    out = paths.check_output_file(Path(out) if out else paths_in[0].with_suffix(".html"), "page")
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        out.write_text(page, encoding="utf-8")
    except OSError as e:
        raise paths.PathError(f"{out}: cannot write the page: {e.strerror or e}") from None
    return out
