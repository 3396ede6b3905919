"""Python engines that misbehave on purpose, for python/tests/test_engine_isolation.py, loaded as
`python:path/to/isolation_engines.py:probe` (by path: the module need not be importable).

probe(config): an engine that displays the handle's pose and sends no wrench, but for one
misbehaviour named by `probe=NAME` at the step `at=K` (default 0):
  raise_create / raise_reset / raise_step   an exception (ValueError, KeyError, ZeroDivisionError)
  sys_exit_step                             sys.exit(0) (a SystemExit)
  os_exit_step                              os._exit(0): the process ends with status 0
  segv_step                                 a read at address 0 (SIGSEGV)
  hang_step                                 sleeps for ever
  slow_steps                                every step from `at` on sleeps 2 ms
  nan_pose / huge_pose                      a NaN, or a 1e300 m, displayed position
  nan_time / negative_time                  a NaN, or -0.5 s, reported step time
  not_a_step                                returns a tuple instead of an EngineStep
  bad_declarations                          declares friction mu = -1
and `declare_mu=MU`, `declare_latency=N`, `declare_skin=S` declare as given.
"""
from __future__ import annotations

import ctypes
import os
import sys
import time

import numpy as np

from gauss6.engine import EngineStep


class Probe:
    name = "python probe engine"

    def __init__(self, config: str):
        self.cfg = dict(item.split("=", 1) for item in config.split())
        self.probe, self.at, self.tick = self.cfg.get("probe", ""), int(self.cfg.get("at", 0)), 0
        if self.probe == "raise_create":
            raise ValueError("a planted error in the constructor")

    def declarations(self):
        if self.probe == "bad_declarations":
            return {"friction": {"mu": -1.0}}
        d = {}
        if "declare_mu" in self.cfg:
            d["friction"] = {"mu": float(self.cfg["declare_mu"])}
        if "declare_latency" in self.cfg:
            d["latency_ticks"] = int(self.cfg["declare_latency"])
        if "declare_skin" in self.cfg:
            d["skin"] = float(self.cfg["declare_skin"])
        return d

    def reset(self, scene):
        if self.probe == "raise_reset":
            raise KeyError("a planted error in reset")
        self.tick = 0

    def step(self, t, xh_p, xh_q):
        out = EngineStep(np.array(xh_p, float), np.array(xh_q, float), np.zeros(6), np.zeros((0, 7)))
        k, self.tick = self.tick, self.tick + 1
        if self.probe == "slow_steps" and k >= self.at:
            time.sleep(0.002)
        if k != self.at:
            return out
        if self.probe == "raise_step":
            return 1 / 0
        if self.probe == "sys_exit_step":
            sys.exit(0)
        if self.probe == "os_exit_step":
            os._exit(0)
        if self.probe == "segv_step":
            ctypes.string_at(0)
        if self.probe == "hang_step":
            while True:
                time.sleep(1)
        if self.probe == "nan_pose":
            out.xs_p[0] = np.nan
        if self.probe == "huge_pose":
            out.xs_p[2] = 1e300
        if self.probe == "nan_time":
            out.step_seconds = float("nan")
        if self.probe == "negative_time":
            out.step_seconds = -0.5
        if self.probe == "not_a_step":
            return (out.xs_p, out.xs_q, out.wrench)
        return out


def probe(config: str = ""):
    return Probe(config)
