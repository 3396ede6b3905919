"""The wrapper the test engines share: gauss6's engine (the C ABI library, config passed on) with a
hook that changes each step's answer, and the handle's motion that some of them need."""
from __future__ import annotations

import numpy as np

from gauss6.engine import EngineStep, load_engine


class Wrapped:
    """gauss6's engine behind `modify(t, xh_p, xh_q, step) -> EngineStep`; `declarations` as the
    driver records them (trace metadata extra["declarations"])."""

    name = "wrapped gauss6"
    declarations: dict = {}

    def __init__(self, inner_config: str = ""):
        self.inner = load_engine("gauss6", inner_config)

    def reset(self, scene) -> None:
        self.scene = scene
        self.dt = 1.0 / scene.rate_hz
        self.prev_p = None
        self.tick = 0
        self.inner.reset(scene)

    def velocity(self, xh_p) -> np.ndarray:
        """The handle's velocity over the last tick (backward difference; zero at the first)."""
        v = np.zeros(3) if self.prev_p is None else (np.asarray(xh_p) - self.prev_p) / self.dt
        return v

    def step(self, t, xh_p, xh_q) -> EngineStep:
        s = self.inner.step(t, xh_p, xh_q)
        out = self.modify(t, np.asarray(xh_p, float), np.asarray(xh_q, float), s)
        self.prev_p = np.array(xh_p, float)
        self.tick += 1
        return out

    def modify(self, t, xh_p, xh_q, s: EngineStep) -> EngineStep:
        return s


def with_wrench(s: EngineStep, wrench) -> EngineStep:
    return EngineStep(s.xs_p, s.xs_q, np.asarray(wrench, float), s.contacts, s.step_seconds)


def force_direction(s: EngineStep) -> np.ndarray | None:
    """The unit direction of the step's force (the contact normal for one contact); None without."""
    f = np.asarray(s.wrench[:3], float)
    n = np.linalg.norm(f)
    return f / n if n > 1e-9 else None


def contact_point(s: EngineStep):
    """The mean of the step's contact points (None without contacts)."""
    if s.contacts is None or len(s.contacts) == 0:
        return None
    return np.asarray(s.contacts, float)[:, :3].mean(axis=0)
