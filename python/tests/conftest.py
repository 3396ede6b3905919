"""Fixtures and markers shared by the Python tests (run a marked set alone with -m NAME)."""
from __future__ import annotations

import numpy as np
import pytest

import gauss6


@pytest.fixture
def nudged_projection(monkeypatch):
    """gauss6.project with its answer nudged off the optimum by 1e-6 of |ac|_inf: a
    planted error that a cross-check must catch (the checks can fail)."""
    real_project = gauss6.project

    class Nudged:
        def __init__(self, res):
            self._res = res
            self.ac = res.ac + 1e-6 * np.abs(res.ac).max()

        def __getattr__(self, name):
            return getattr(self._res, name)

    monkeypatch.setattr(gauss6, "project", lambda *a, **k: Nudged(real_project(*a, **k)))


def pytest_configure(config):
    config.addinivalue_line("markers", "adapters: the third-party engine adapters' smoke runs (a few hundred ticks "
                                       "each, about a minute together; the full runs are `gauss6 reproduce engines`)")
