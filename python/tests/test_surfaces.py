"""The surface-property runs (METHOD.md section 6): the Figure 9 analogue's texture runs
(datasets_generated/scenes/texture_slow.toml and texture_fast.toml, lockstep, a sim step
every 20 ticks: the speed bound is 0.25 m/s). Each run takes about a second."""
from __future__ import annotations

import numpy as np
import pytest

from gauss6 import reproduce_surfaces as rs
from gauss6._gauss6 import runtime
from gauss6.trace import read_trace


@pytest.fixture(scope="module")
def texture_runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("texture")
    runs = {}
    for label, scene in rs.TEXTURE_RUNS.items():
        path = out / f"{label}.g6trace"
        run = runtime.run_scenario(str(rs.SCENES / scene), str(path), lockstep_sim_period=rs.TEXTURE_SIM_PERIOD)
        runs[label] = (run, read_trace(path), rs.sine_texture(rs.SCENES / scene))
    return runs


def test_slow_texture_run_keeps_its_contact_and_feels_every_bump(texture_runs):
    """Under the bound the tip stays on the slab (the pressed contact is held: it lifted off
    by up to 0.9 mm on uphill slopes and the force dropped to zero for a sim step, 9 of 11
    bumps missed) and the force tilts as the texture's slope at the god-object's position."""
    run, trace, texture = texture_runs["slow"]
    slide = rs._slide_mask(trace)
    assert np.all(trace.ticks["num_contacts"][slide] > 0)
    assert np.max(np.abs(trace.ticks["xs_p"][slide, 2])) < 1e-5  # on the slab (top z = 0), within 10 delta
    crossed, missed = rs.bumps(trace, texture)
    assert crossed >= 10 and missed == 0
    assert run["sim"].get("events", {}).get("texture_undersampled", 0) == 0
    assert run["max_rel_constraint_violation"] <= 1e-9  # property 7, the stated tolerance (runtime_events.h)


def test_fast_texture_run_misses_bumps_and_says_so(texture_runs):
    """Over the bound (0.4 m/s: 8 mm a sim step on a 1 cm texture) most bumps are skipped,
    and the runtime raises texture_undersampled."""
    run, trace, texture = texture_runs["fast"]
    crossed, missed = rs.bumps(trace, texture)
    assert crossed >= 8 and missed > crossed // 2
    assert run["sim"]["events"]["texture_undersampled"] >= 1
    assert run["max_rel_constraint_violation"] <= 1e-9
