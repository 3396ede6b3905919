"""Honest variants of gauss6's engine: each changes what is rendered without breaking a property of
METHOD.md section 5, or renders something on purpose and declares it (docs/engine-contract.md,
"Declarations"). The oracle must pass every one on both shipped scripts."""
from __future__ import annotations

import numpy as np

from gauss6.engine import EngineStep

from .base import Wrapped, contact_point, force_direction, with_wrench


class SimRate(Wrapped):
    """gauss6 itself with its sim step every `period` ticks (config sim_period): the god-object and its
    contacts are updated at 1 / period of the haptic rate, so the force can answer a crossing up to
    2 (period - 1) ticks late (measured: a response lag of period ticks in contact, 2 period at an onset); it declares that latency."""

    def __init__(self, period: int):
        super().__init__(f"sim_period={period}")
        self.name = f"gauss6 sim_period={period}"
        self.declarations = {"latency_ticks": 2 * (period - 1)} if period > 1 else {}


class Scaled(Wrapped):
    """The wrench scaled by a constant c < 1 (a softer rendering of the same contacts)."""

    def __init__(self, c: float):
        super().__init__()
        self.c, self.name = c, f"wrench x {c:g}"

    def modify(self, t, xh_p, xh_q, s):
        return with_wrench(s, self.c * np.asarray(s.wrench))


class NormalDamper(Wrapped):
    """A pure damper along the contact's wrench: while the handle moves into the contact, the wrench
    grows along itself by B |v_n| (B in N s/m), so it only removes energy and stays in the cone."""

    def __init__(self, B: float):
        super().__init__()
        self.B, self.name = B, f"normal damper B={B:g} N s/m"

    def modify(self, t, xh_p, xh_q, s):
        n = force_direction(s)
        if n is None:
            return s
        v_in = max(0.0, -float(self.velocity(xh_p) @ n))
        f = np.linalg.norm(s.wrench[:3])
        return with_wrench(s, np.asarray(s.wrench) * (1 + self.B * v_in / f))


class Friction(Wrapped):
    """Coulomb friction, declared: a tangential force -mu |F_n| v_t / |v_t| against the handle's sliding
    (regularised below v_eps), applied at the contacts' mean point (its torque about G), F_n gauss6's
    frictionless force. Declares friction {mu: declared}."""

    def __init__(self, mu: float, declared: float | None = None, v_eps: float = 0.02, sign: float = -1.0):
        super().__init__()
        self.mu, self.v_eps, self.sign = mu, v_eps, sign
        self.name = f"Coulomb friction mu={mu:g}"
        self.declarations = {} if declared is None else {"friction": {"mu": declared}}

    def modify(self, t, xh_p, xh_q, s):
        n = force_direction(s)
        if n is None:
            return s
        v = self.velocity(xh_p)
        vt = v - (v @ n) * n
        speed = np.linalg.norm(vt)
        fn = np.linalg.norm(s.wrench[:3])
        ft = self.sign * self.mu * fn * vt / max(speed, self.v_eps)
        c = contact_point(s)
        tau = np.cross(c - np.asarray(s.xs_p), ft) if c is not None else np.zeros(3)
        return with_wrench(s, np.asarray(s.wrench) + np.concatenate([ft, tau]))


class Delay(Wrapped):
    """The displayed pose and the wrench of `ticks` ticks ago (a transport delay), declaring latency
    `declared` ticks (None: nothing declared)."""

    def __init__(self, ticks: int, declared: int | None = None):
        super().__init__()
        self.d, self.name = ticks, f"delay {ticks} ticks"
        self.declarations = {} if declared is None else {"latency_ticks": declared}

    def reset(self, scene):
        super().reset(scene)
        self.queue = []

    def modify(self, t, xh_p, xh_q, s):
        self.queue.append(s)
        if len(self.queue) > self.d + 1:
            self.queue.pop(0)
        old = self.queue[0]
        if len(self.queue) <= self.d:  # the first ticks: the start pose, no force
            return EngineStep(old.xs_p, old.xs_q, np.zeros(6), old.contacts, s.step_seconds)
        return EngineStep(old.xs_p, old.xs_q, old.wrench, old.contacts, s.step_seconds)


class Skin(Wrapped):
    """The displayed tool kept `skin` (m) further out than gauss6 keeps it, along the mean normal of its
    contacts, with gauss6's wrench: a separation kept on purpose, declared as skin (None: undeclared)."""

    def __init__(self, skin: float, declared: float | None = None):
        super().__init__()
        self.skin, self.name = skin, f"skin {skin:g} m"
        self.declarations = {} if declared is None else {"skin": declared}

    def modify(self, t, xh_p, xh_q, s):
        if s.contacts is None or len(s.contacts) == 0:
            return s
        n = np.asarray(s.contacts, float)[:, 3:6].mean(axis=0)
        if np.linalg.norm(n) < 1e-9:
            return s
        n /= np.linalg.norm(n)
        return EngineStep(np.asarray(s.xs_p) + self.skin * n, s.xs_q, s.wrench, s.contacts, s.step_seconds)
