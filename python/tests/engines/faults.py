"""Planted faults: gauss6's engine with one realistic defect each (beyond the C fault engine's six,
engine/tests/fault_engine.c), and the check whose job it is to name it (FAULTS in
test_oracle_engines.py)."""
from __future__ import annotations

import time

import numpy as np

from gauss6.engine import EngineStep

from .base import Wrapped, force_direction, with_wrench
from .variants import Delay, Friction, Skin


class NegativeDamping(Wrapped):
    """Energy injected slowly: a negative damper beta (N s/m) on the handle's velocity while in contact,
    F += beta v -- it pushes the hand along wherever it goes."""

    def __init__(self, beta: float):
        super().__init__()
        self.beta, self.name = beta, f"negative damping {beta:g} N s/m"

    def modify(self, t, xh_p, xh_q, s):
        if force_direction(s) is None:
            return s
        return with_wrench(s, np.asarray(s.wrench) + np.concatenate([self.beta * self.velocity(xh_p), np.zeros(3)]))


class SlowSteps(Wrapped):
    """Deadlines: every `every`-th step spins for `seconds` of CPU (twice the period by default) and
    reports the inner engine's own (short) step time."""

    def __init__(self, every: int = 10, seconds: float = 2e-3, sleep: bool = False, once_at: int | None = None):
        super().__init__()
        self.every, self.seconds, self.sleep, self.once_at = every, seconds, sleep, once_at
        self.name = f"slow step {seconds * 1e3:g} ms" + (f" once at tick {once_at}" if once_at is not None
                                                          else f" every {every}")

    def modify(self, t, xh_p, xh_q, s):
        due = self.tick == self.once_at if self.once_at is not None else self.tick % self.every == 0
        if due:
            if self.sleep:
                time.sleep(self.seconds)
            else:
                end = time.perf_counter() + self.seconds
                while time.perf_counter() < end:
                    pass
        return EngineStep(s.xs_p, s.xs_q, s.wrench, s.contacts, 1e-6)  # claims 1 us


class QuaternionOrder(Wrapped):
    """The displayed orientation returned as (x, y, z, w) instead of (w, x, y, z)."""
    name = "quaternion (x, y, z, w)"

    def modify(self, t, xh_p, xh_q, s):
        q = np.asarray(s.xs_q)
        return EngineStep(s.xs_p, np.array([q[1], q[2], q[3], q[0]]), s.wrench, s.contacts, s.step_seconds)


class FreeOffset(Wrapped):
    """In free space (no force) the displayed pose is offset (0.3 mm along x by default): a frame error."""

    def __init__(self, offset=(3e-4, 0.0, 0.0)):
        super().__init__()
        self.offset = np.asarray(offset, float)
        self.name = f"free-space offset {np.round(self.offset * 1e3, 3).tolist()} mm"

    def modify(self, t, xh_p, xh_q, s):
        if np.any(np.asarray(s.wrench) != 0):
            return s
        return EngineStep(np.asarray(s.xs_p) + self.offset, s.xs_q, s.wrench, s.contacts, s.step_seconds)


class FreeLag(Wrapped):
    """In free space the displayed pose is the handle's of 30 ticks ago (a display pipeline's lag)."""
    name = "free-space display 30 ticks late"

    def reset(self, scene):
        super().reset(scene)
        self.past = []

    def modify(self, t, xh_p, xh_q, s):
        self.past.append((np.array(s.xs_p), np.array(s.xs_q)))
        self.past = self.past[-31:]
        if np.any(np.asarray(s.wrench) != 0):
            return s
        p, q = self.past[0]
        return EngineStep(p, q, s.wrench, s.contacts, s.step_seconds)


class LateOnset(Wrapped):
    """The force withheld for the first `ticks` ticks of each contact episode (a late response), the
    rest untouched."""

    def __init__(self, ticks: int):
        super().__init__()
        self.d, self.name = ticks, f"force onset {ticks} ticks late"

    def reset(self, scene):
        super().reset(scene)
        self.run = 0

    def modify(self, t, xh_p, xh_q, s):
        self.run = self.run + 1 if np.any(np.asarray(s.wrench) != 0) else 0
        return s if self.run > self.d or self.run == 0 else with_wrench(s, np.zeros(6))


class Knock(Wrapped):
    """A 1 N knock along the force for one tick, `at` ticks (20 by default) into each contact episode."""

    def __init__(self, at: int = 20):
        super().__init__()
        self.at, self.name = at, f"1 N knock {at} ticks into each contact"

    def reset(self, scene):
        super().reset(scene)
        self.run = 0

    def modify(self, t, xh_p, xh_q, s):
        n = force_direction(s)
        self.run = self.run + 1 if n is not None else 0
        if self.run == self.at:
            return with_wrench(s, np.asarray(s.wrench) + np.concatenate([n, np.zeros(3)]))
        return s


class OverLimit(Wrapped):
    """One tick, 30 ticks into the first contact: the force scaled to 1.5 times the device's limit."""
    name = "force over the limit"

    def reset(self, scene):
        super().reset(scene)
        self.run, self.done = 0, False

    def modify(self, t, xh_p, xh_q, s):
        n = force_direction(s)
        self.run = self.run + 1 if n is not None else 0
        if self.run == 30 and not self.done:
            self.done = True
            return with_wrench(s, np.concatenate([1.5 * self.scene.max_force * n, s.wrench[3:]]))
        return s


class FarPose(Wrapped):
    """One tick: the displayed pose `radii` scene radii (the half diagonal of the bodies' box) from the
    scene's centre: 300 is finite and judgeable, beyond the oracle's pose_extent; 1e300 is no pose
    at all, which the driver refuses as the engine's failure."""

    def __init__(self, radii: float):
        super().__init__()
        self.radii, self.name = radii, f"pose at {radii:g} scene radii"

    def reset(self, scene) -> None:
        super().reset(scene)
        # Each body's vertices about its position, unrotated: the scale (within a factor of about 2)
        # is all this needs, 300 radii lying well inside (100, 1000).
        points = np.concatenate([np.asarray(b.V, float) + np.asarray(b.p, float)
                                 for b in [*scene.obstacles, scene.tool] if len(b.V)])
        lo, hi = points.min(axis=0), points.max(axis=0)
        self.far = (lo + hi) / 2 + np.array([self.radii * np.linalg.norm(hi - lo) / 2, 0.0, 0.0])

    def modify(self, t, xh_p, xh_q, s):
        if self.tick == 200:
            return EngineStep(self.far, s.xs_q, s.wrench, s.contacts, s.step_seconds)
        return s


class FreeForce(Wrapped):
    """A constant 0.01 N along z in free space (a gravity compensation left on)."""
    name = "0.01 N in free space"

    def modify(self, t, xh_p, xh_q, s):
        if np.any(np.asarray(s.wrench) != 0):
            return s
        return with_wrench(s, np.array([0, 0, 0.01, 0, 0, 0]))


class StickyRelease(Wrapped):
    """The last contact force held for 40 ticks after gauss6 releases it (the hand moving away)."""
    name = "force held 40 ticks after release"

    def reset(self, scene):
        super().reset(scene)
        self.last, self.hold = np.zeros(6), 0

    def modify(self, t, xh_p, xh_q, s):
        if np.any(np.asarray(s.wrench) != 0):
            self.last, self.hold = np.array(s.wrench), 40
            return s
        if self.hold > 0:
            self.hold -= 1
            return with_wrench(s, self.last)
        return s


class Unconstrained(Wrapped):
    """The displayed pose is the handle's (a coupling without the constraint), with gauss6's force."""
    name = "displayed pose = handle"

    def modify(self, t, xh_p, xh_q, s):
        return EngineStep(np.array(xh_p), np.array(xh_q), s.wrench, s.contacts, s.step_seconds)


class Adhesion(Wrapped):
    """5% of the force reversed: a pull into the contact (adhesion) on top of gauss6's push... as a pull
    alone: the wrench's sign flipped on one tick in ten while in contact."""
    name = "pull (wrench reversed 1 tick in 10)"

    def modify(self, t, xh_p, xh_q, s):
        if force_direction(s) is not None and self.tick % 10 == 0:
            return with_wrench(s, -0.2 * np.asarray(s.wrench))
        return s


class WhileFast(Wrapped):
    """Another fault's change applied only while the hand moves faster than `speed` (m/s; over the last
    tick), gauss6's answer otherwise: a fault that shows only at speed. The fault sees every tick (its
    state, such as a history of poses, is kept) through its `modify`; its own inner engine is unused."""

    def __init__(self, fault: Wrapped, speed: float = 1.0):
        super().__init__()
        self.fault, self.speed = fault, speed
        self.name = f"{fault.name}, while the hand moves over {speed:g} m/s"
        self.declarations = fault.declarations

    def reset(self, scene):
        super().reset(scene)
        self.fault.reset(scene)

    def modify(self, t, xh_p, xh_q, s):
        self.fault.tick, self.fault.prev_p = self.tick, self.prev_p
        out = self.fault.modify(t, xh_p, xh_q, s)
        return out if np.linalg.norm(self.velocity(xh_p)) > self.speed else s


def undeclared_friction():
    return Friction(0.3, declared=None)


def friction_beyond_declared():
    e = Friction(0.6, declared=0.1)
    e.name = "friction mu 0.6 declared 0.1"
    return e


def friction_driving_slide():
    e = Friction(0.2, declared=0.3, sign=+1.0)
    e.name = "friction along the slide, declared mu 0.3"
    return e


def undeclared_delay():
    return Delay(4, declared=None)


def delay_beyond_declared():
    e = Delay(5, declared=2)
    e.name = "delay 5 ticks declared 2"
    return e


def undeclared_skin(delta: float):
    return Skin(20 * delta, declared=None)


def skin_beyond_declared(delta: float):
    e = Skin(40 * delta, declared=5 * delta)
    e.name = "skin 40 delta declared 5"
    return e
