"""Driving a test engine as `gauss6 validate` does: the driver (gauss6.driver.drive) on a slice of a
scene's script, each step call timed around the call (wall and CPU seconds, into the steps stream's
update_time and update_cpu_time, as the driver records them), the engine's declarations in the
trace's metadata (extra["declarations"])."""
from __future__ import annotations

import time

import numpy as np

from gauss6.driver import drive, scene_script
from gauss6.engine import EngineScene


class Timed:
    """An engine whose step calls are timed from outside (wall: perf_counter; CPU: thread_time)."""

    def __init__(self, engine):
        self.engine, self.name = engine, getattr(engine, "name", type(engine).__name__)
        self.wall, self.cpu = [], []

    def reset(self, scene):
        self.engine.reset(scene)

    def step(self, t, p, q):
        w, c = time.perf_counter(), time.thread_time()
        out = self.engine.step(t, p, q)
        self.cpu.append(time.thread_time() - c)
        self.wall.append(time.perf_counter() - w)
        return out


def declared(engine) -> dict:
    """What a test engine declares: its `declarations` dict (the wrapped variants) or the protocol's
    declarations() method (an engine of gauss6.engine, such as gauss6's own)."""
    d = getattr(engine, "declarations", {})
    return dict((d() if callable(d) else d) or {})


def run(engine, scene, path, duration: float):
    """The engine's trace on the first `duration` s of the scene's script."""
    text, _ = scene_script(scene)
    timed = Timed(engine)
    tr = drive(timed, EngineScene.from_scene_file(scene), text, path, duration,
               extra={"declarations": declared(engine)})
    n = len(tr.steps)
    tr.steps["update_time"] = np.asarray(timed.wall[:n])
    tr.steps["update_cpu_time"] = np.asarray(timed.cpu[:n])
    return tr
