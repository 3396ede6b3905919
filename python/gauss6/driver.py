"""The validation driver: the simulated device of METHOD.md section 7 (a handle held by a scripted
virtual user through a grip spring) in closed loop with an engine under test, lockstep at the
scene's rate (1 kHz), recorded as a gauss6 trace (docs/trace-format.md).

Tick k at t = k / rate_hz (the schedule of run_lockstep, runtime.h):
  xh = device.read(t)                  the handle, moved by the hand, the grip and the last wrench
  step = engine.step(t, xh)            the engine's displayed pose, wrench, contacts, step time
  device.write(t, safe(step.wrench))   what the handle feels: zero if not finite, each part
                                       scaled to the device's limit (as a device saturates)
The run stops at the script's end (or `duration`), or at the engine's failure (a crash, an exit,
a hang, an exception, a malformed output: gauss6.engine_host), whose trace then holds the ticks
up to the last good one. Every engine feels the same hand, and a run is repeatable: the device's
state depends only on the sequence of (t, wrench).

The engine is served by a host (gauss6.engine_host: in a child process, or inline), which times
every step call itself. The trace records, per tick, the engine's own wrench (not the saturated
one: a NaN stays a NaN, an over-limit wrench stays over), its displayed pose, its contact count
and its own reported step time (force_time, s; NaN when it reports none), the flags gripped and
force_clamped; one step row per tick with the driver's timing of the call (update_time: wall s,
update_cpu_time: CPU s) and the engine's contacts; the script's phases and the let-go as events.
Its metadata's "extra" names the engine and its config, and holds "isolation" (the host's mode and
the transport's cost per tick, us), "declarations" (what the engine declares: {} when nothing)
and, when the engine failed, "engine_failure" {kind, detail, tick: the last good tick, -1: none}.
"""
from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from . import trace as trace_mod
from .engine import EngineFailure, EngineScene
from .engine_host import Host, InlineHost

SATURATION_SLACK = 1e-12  # relative: a wrench part within this of the limit is within it (no rescale)


def scene_script(scene_path) -> tuple[str, str]:
    """The hand script a scene names (device.script): its JSON text and its path."""
    import tomllib

    scene_path = Path(scene_path)
    with open(scene_path, "rb") as f:
        name = tomllib.load(f).get("device", {}).get("script", "")
    if isinstance(name, dict):  # a [device.script] table: the script itself (docs/scene-format.md)
        return json.dumps(name), f"{scene_path}: device.script"
    if not name:
        raise ValueError(f"{scene_path}: device.script is not set: give --script")
    return script_text(name, scene_path, relative_to_scene=True)


def script_text(name: str, scene_path, relative_to_scene: bool = False) -> tuple[str, str]:
    """A hand script by name (NAME: scripts/NAME.json beside the scene's folder) or by a .json path:
    the scene's device.script relative to the scene file's folder, as the C++ loader reads it
    (harness/src/scenario.cpp, load_scene_script); a --script path relative to the working folder."""
    scene_dir = Path(scene_path).resolve().parent
    if name.endswith(".json"):
        path = scene_dir / name if relative_to_scene else Path(name)
    else:
        path = scene_dir.parent / "scripts" / f"{name}.json"
    if not path.exists():
        raise ValueError(f"{name}: no such hand script ({path})")
    from .paths import read_input_text  # a regular file (not a FIFO or a device), bounded

    return read_input_text(path, "hand script", 1 << 26), str(path)


def safe_wrench(F: np.ndarray, max_force: float, max_torque: float) -> tuple[np.ndarray, bool]:
    """The wrench a device applies: zero when not finite, each part scaled down to its limit."""
    if not np.all(np.isfinite(F)):
        return np.zeros(6), True
    out = F.copy()
    clamped = False
    f, tau = math.sqrt(F[0] ** 2 + F[1] ** 2 + F[2] ** 2), math.sqrt(F[3] ** 2 + F[4] ** 2 + F[5] ** 2)
    if f > max_force * (1 + SATURATION_SLACK):
        out[:3] *= max_force / f
        clamped = True
    if tau > max_torque * (1 + SATURATION_SLACK):
        out[3:] *= max_torque / tau
        clamped = True
    return out, clamped


def drive(engine, scene: EngineScene, script_json: str, out_path, duration: float | None = None,
          progress=None, extra: dict | None = None) -> trace_mod.Trace:
    """Runs `engine` (a host of gauss6.engine_host, started here; or an engine object of the Python
    protocol, served inline) on `scene` with the simulated device on the hand script `script_json`,
    writes the trace to out_path and returns it. An engine's failure ends the run (the trace's
    extra["engine_failure"]); the caller closes a host it made."""
    from ._gauss6 import device as _device

    host = engine if isinstance(engine, Host) else InlineHost(engine)
    dev = _device.SimulatedDevice(script_json, rate_hz=scene.rate_hz, max_force=scene.max_force,
                                  max_torque=scene.max_torque)
    end = dev.end_time if duration is None or duration < 0 else duration
    from .cli_args import check_run_span  # a script spanning 1e9 s would be a run without end

    check_run_span(end, "the hand script")
    num_ticks = int(math.floor(end * scene.rate_hz + 1e-9)) + 1
    ticks = np.zeros(num_ticks, dtype=trace_mod.DTYPES["ticks"])
    steps = np.zeros(num_ticks, dtype=trace_mod.DTYPES["steps"])
    contact_rows: list = []
    flags_gripped, flags_clamped = trace_mod.TICK_FLAGS["gripped"], trace_mod.TICK_FLAGS["force_clamped"]
    F_safe = np.zeros(6)
    n = 0
    t = 0.0
    wall = time.perf_counter()
    last_progress = wall
    failure = None
    try:
        host.start()
        host.reset(scene)
        for k in range(num_ticks):
            t = k / scene.rate_hz
            p, q, gripped, status = dev.read(t)
            if status == "ended":
                break
            stepped = host.step(t, p, q)
            step = stepped.step
            F = np.asarray(step.wrench, dtype=float)
            F_safe, clamped = safe_wrench(F, scene.max_force, scene.max_torque)
            dev.write(t, F_safe)
            row = ticks[n]
            row["t"], row["xh_p"], row["xh_q"] = t, p, q
            row["xs_p"], row["xs_q"], row["wrench"] = step.xs_p, step.xs_q, F
            m = -1 if step.contacts is None else len(step.contacts)
            row["num_contacts"] = max(m, 0)
            row["force_time"] = step.step_seconds if step.step_seconds is not None else np.nan
            row["flags"] = (flags_gripped if gripped else 0) | (flags_clamped if clamped else 0)
            steps[n] = (n, t, stepped.wall, max(m, 0), 0, stepped.cpu)
            if m > 0:
                c = np.asarray(step.contacts, dtype=float)
                block = np.zeros(m, dtype=trace_mod.DTYPES["contacts"])
                block["step"], block["t"] = n, t
                block["point"], block["normal"], block["separation"] = c[:, 0:3], c[:, 3:6], c[:, 6]
                contact_rows.append(block)
            n += 1
            if progress and time.perf_counter() - last_progress > 0.2:
                last_progress = time.perf_counter()
                progress(t, end)
    except EngineFailure as e:
        failure = e
    dev.write(t, np.zeros(6))
    if progress:
        progress(t, end)

    phases = dev.phases
    events = [(start, 1, i) for i, (_, start) in enumerate(phases)]
    if dev.let_go_time >= 0 and dev.let_go_time <= t:
        events.append((dev.let_go_time, 2, 0))
    events_arr = np.array(sorted(events), dtype=trace_mod.DTYPES["events"]) if events else \
        np.zeros(0, dtype=trace_mod.DTYPES["events"])
    info = {"engine": host.name or getattr(host, "spec", "") or type(engine).__name__,
            "wall_seconds": time.perf_counter() - wall, "isolation": host.isolation(),
            "declarations": host.declarations}
    if failure is not None:
        info["engine_failure"] = failure.to_json(n - 1)
    meta = trace_mod.trace_metadata(
        scene=scene.name, device={"name": "simulated (validation driver)", "rate_hz": scene.rate_hz,
                                  "renders_force": True},
        phases=phases, extra={**info, **(extra or {})})
    contacts = np.concatenate(contact_rows) if contact_rows else np.zeros(0, dtype=trace_mod.DTYPES["contacts"])
    tr = trace_mod.Trace(path=Path(out_path), version=trace_mod.VERSION, meta=meta, ticks=ticks[:n],
                         steps=steps[:n], contacts=contacts, events=events_arr, complete=True)
    trace_mod.write_trace(tr, out_path)
    return tr


def script_phases(script_json: str) -> list:
    """The (name, start) phases of a hand script's JSON text."""
    return [(p["name"], float(p["start"])) for p in json.loads(script_json).get("phases", [])]
