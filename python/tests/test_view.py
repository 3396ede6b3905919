"""Tests of `gauss6 view` (gauss6.view): the page's data, and the page in a real browser.

The browser test loads a page written for a short peg-in-the-hole trace into headless Chromium
(Debian's chromium and chromium-driver, driven by Selenium; WebGL through SwiftShader, no GPU):
the WebGL canvas is drawn, scrubbing the time cursor (window.gauss6View.seek) puts the displayed
god-object at the trace's xs of that time, two traces show side by side, and a screenshot of the
peg in the hole is kept as a test artefact: build/test-artifacts/viewer-peg.png.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from gauss6 import paths, view
from gauss6.trace import DTYPES, Trace, read_trace, trace_metadata, write_trace

PEG_SCENE = paths.DATASETS_DIR / "scenes" / "peg_in_hole.toml"
ARTIFACTS = paths.build_dir() / "test-artifacts"
CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"


def peg_in_hole_trace(path: Path, shift: float = 0.0) -> Path:
    """A 2 s trace of the peg (its axis along Y, as in phase (e)) slid along the hole's axis from
    y = -9 cm to its centre, resting on the hole's floor; the handle 4 mm lower (pressing down),
    a force of 2 N up, two contacts on the floor per sim step (every 10 ticks), phases d and e."""
    t = np.arange(2001) / 1000.0
    y = np.interp(t, [0.0, 1.4, 2.0], [-0.09, 0.0, 0.0]) + shift
    ticks = np.zeros(len(t), dtype=DTYPES["ticks"])
    ticks["t"] = t
    ticks["xs_p"] = np.stack([np.zeros_like(t), y, np.full_like(t, -1.7e-4)], axis=1)
    ticks["xs_q"] = [2.0, 0.0, 0.0, 0.0]  # the identity, not unit: the page normalises it
    ticks["xh_p"] = ticks["xs_p"] + [0.0, 0.0, -0.004]
    ticks["xh_q"] = [1.0, 0.0, 0.0, 0.0]
    ticks["wrench"] = [0.0, 0.0, 2.0, 0.01, 0.0, 0.0]
    ticks["num_contacts"] = 2
    ticks["force_time"] = 2e-6
    ticks["flags"] = 1
    k = np.arange(0, len(t), 10)
    steps = np.zeros(len(k), dtype=DTYPES["steps"])
    steps["step"], steps["t"], steps["update_time"], steps["num_contacts"] = np.arange(len(k)), t[k], 3e-4, 2
    contacts = np.zeros(2 * len(k), dtype=DTYPES["contacts"])
    contacts["step"] = np.repeat(steps["step"], 2)
    contacts["t"] = np.repeat(steps["t"], 2)
    contacts["point"] = np.stack([np.zeros(2 * len(k)), np.repeat(y[k], 2) + np.tile([-0.045, 0.045], len(k)),
                                  np.full(2 * len(k), -0.0102)], axis=1)
    contacts["normal"] = [0.0, 0.0, 1.0]
    events = np.zeros(3, dtype=DTYPES["events"])
    events["t"], events["code"], events["value"] = [0.0, 1.0, 1.8], [1, 1, 2], [0, 1, 0]
    meta = trace_metadata(scene="peg_in_hole", device={"name": "test", "rate_hz": 1000.0, "renders_force": True},
                          phases=[("d", 0.0), ("e", 1.0)])
    tr = Trace(path=path, version=1, meta=meta, ticks=ticks, steps=steps, contacts=contacts, events=events,
               complete=True)
    return write_trace(tr, path)


def test_page_is_self_contained_and_downsamples(tmp_path):
    trace = peg_in_hole_trace(tmp_path / "peg.g6trace")
    page = view.write_view([trace], PEG_SCENE, tmp_path / "small.html", max_frames=500)
    text = page.read_text()
    # No file or address outside the page: no script or style source, no link.
    assert not re.search(r"<script[^>]+src=|<link\b|@import", text)
    assert "down-sampled for this page to 500 ticks and 201 sim steps" in text
    data = json.loads(re.search(r'<script id="gauss6-data" type="application/json">(.*?)</script>', text, re.S)
                      .group(1).replace("<\\/", "</"))
    run = data["runs"][0]
    assert run["rows"] == {"ticks": [2001, 500], "steps": [201, 201], "contacts": [402, 402]}
    assert [p["name"] for p in run["phases"]] == ["d", "e"]
    assert [e["name"] for e in run["events"]] == ["phase", "phase", "let_go"]
    # The scene named in the metadata is found without --scene.
    assert view.default_scene(read_trace(trace)) == PEG_SCENE


def test_pick_keeps_the_ends_evenly():
    idx = view.pick(20_001, 1000)
    assert idx[0] == 0 and idx[-1] == 20_000 and len(idx) == 1000
    assert np.all(np.diff(idx) >= 20) and np.all(np.diff(idx) <= 21)
    assert np.array_equal(view.pick(7, 10), np.arange(7))


def test_view_command(tmp_path, capsys):
    from gauss6.cli import main

    a = peg_in_hole_trace(tmp_path / "a.g6trace")
    b = peg_in_hole_trace(tmp_path / "b.g6trace", shift=0.01)
    assert main(["view", str(a), "--trace", str(b), "--out", str(tmp_path / "ab.html")]) == 0
    assert "ab.html" in capsys.readouterr().out
    assert main(["view", str(tmp_path / "missing.g6trace")]) == 2
    assert "cannot open" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------
# In a real browser


@pytest.fixture(scope="module")
def browser():
    for exe in (CHROMIUM, CHROMEDRIVER):
        if not os.path.exists(exe):
            pytest.fail(f"{exe} is missing: tools/setup.sh installs Debian's chromium and chromium-driver")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="gauss6-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                f"--user-data-dir={profile}", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                "--window-size=1400,900", "--force-device-scale-factor=1"):
        options.add_argument(arg)
    driver = webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


def _open(driver, page: Path) -> None:
    driver.get(page.resolve().as_uri())
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        ready, error = driver.execute_script(
            "return [!!(window.gauss6View && window.gauss6View.ready), document.body.dataset.error || null]")
        assert error is None, f"the page's script failed: {error}"
        if ready:
            return
        time.sleep(0.05)
    pytest.fail(f"{page}: the viewer did not render within 30 s")


def _xs_at(trace: Trace, t: float) -> np.ndarray:
    i = max(0, int(np.searchsorted(trace.ticks["t"], t, side="right")) - 1)
    return trace.ticks["xs_p"][i]


def test_browser_draws_scrubs_and_keeps_a_screenshot(browser, tmp_path):
    trace_path = peg_in_hole_trace(tmp_path / "peg.g6trace")
    trace = read_trace(trace_path)
    page = view.write_view([trace_path], PEG_SCENE, tmp_path / "peg.html")
    _open(browser, page)

    # The WebGL canvas was drawn: most pixels differ from the background, in many colours.
    stats = browser.execute_script("return gauss6View.canvasStats()")
    assert stats["width"] > 400 and stats["height"] > 300
    assert stats["non_background"] > 0.05 * stats["width"] * stats["height"], stats
    assert stats["colours"] > 30, stats

    # Scrubbing moves the god-object to the trace's xs at the cursor's time (the last tick <= t).
    positions = []
    for t in (0.2, 0.7345, 1.9):
        state = browser.execute_script(f"gauss6View.seek({t}); return gauss6View.state(0)")
        assert state["time"] == pytest.approx(t)
        np.testing.assert_allclose(state["god_position"], _xs_at(trace, t), rtol=0, atol=1e-12)
        np.testing.assert_allclose(state["ghost_position"], _xs_at(trace, t) + [0, 0, -0.004], atol=1e-12)
        np.testing.assert_allclose(state["god_quaternion_wxyz"], [1, 0, 0, 0], atol=1e-15)  # normalised
        assert state["contacts_shown"] == 2 and state["force_arrow_visible"]
        positions.append(state["god_position"])
    assert positions[0][1] < positions[1][1] < positions[2][1]  # it moved along the hole

    # The screenshot of the peg in the hole: a picture, not a blank page.
    browser.execute_script("gauss6View.seek(1.6)")
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    shot = ARTIFACTS / "viewer-peg.png"
    assert browser.save_screenshot(str(shot))
    from PIL import Image

    pixels = np.asarray(Image.open(shot).convert("RGB"), dtype=float)
    assert pixels.shape[0] >= 700 and pixels.shape[1] >= 1300
    assert pixels.std() > 20 and len(np.unique(pixels.reshape(-1, 3) // 8, axis=0)) > 100


def test_browser_shows_two_runs_side_by_side(browser, tmp_path):
    a = peg_in_hole_trace(tmp_path / "a.g6trace")
    b = peg_in_hole_trace(tmp_path / "b.g6trace", shift=0.01)
    page = view.write_view([a, b], PEG_SCENE, tmp_path / "ab.html", labels=["engine A", "engine B"])
    _open(browser, page)
    assert browser.execute_script("return gauss6View.numRuns") == 2
    sa, sb = browser.execute_script("gauss6View.seek(0.5); return [gauss6View.state(0), gauss6View.state(1)]")
    np.testing.assert_allclose(sb["god_position"][1] - sa["god_position"][1], 0.01, atol=1e-12)
    labels = browser.execute_script("return [...document.querySelectorAll('.run-label')].map(d => d.textContent)")
    assert [s.split(":")[0] for s in labels] == ["engine A", "engine B"]


def test_browser_shows_the_run_of_a_nan_returning_engine(browser, tmp_path):
    """The fault engine returns a NaN force from 0.5 s (gauss6's engine inside it); to its run
    are added an event whose value is NaN, an infinite one and metadata numbers that are NaN, and
    a god-object pose that is NaN. The page loads (its JSON parses), draws, shows "NaN" in the
    readout at a NaN tick with no force arrow, and the god-object again after it."""
    from gauss6.driver import drive, scene_script
    from gauss6.engine import EngineScene, engine_library, load_engine

    engine = load_engine("fault", f"inner={engine_library('gauss6')};fault=nan;at=0.5")
    text, _ = scene_script(PEG_SCENE)
    run = drive(engine, EngineScene.from_scene_file(PEG_SCENE), text, tmp_path / "nan.g6trace", 0.8)
    nan_ticks = np.nonzero(~np.all(np.isfinite(run.ticks["wrench"]), axis=1))[0]
    assert len(nan_ticks), "the fault engine returned no NaN"
    ticks = run.ticks.copy()
    ticks["xs_p"][700] = np.nan
    events = np.zeros(2, dtype=DTYPES["events"])
    events["t"], events["code"], events["value"] = [0.3, 0.6], [3, 4], [np.nan, np.inf]
    meta = {**run.meta, "device": {**run.meta["device"], "rate_hz": float("nan")}}
    path = write_trace(Trace(**{**run.__dict__, "ticks": ticks, "events": events, "meta": meta}),
                       tmp_path / "nan-plus.g6trace")
    page = view.write_view([path], PEG_SCENE, tmp_path / "nan.html")
    _open(browser, page)
    stats = browser.execute_script("return gauss6View.canvasStats()")
    assert stats["non_background"] > 0.05 * stats["width"] * stats["height"], stats
    k = int(nan_ticks[0])
    state = browser.execute_script(f"gauss6View.seek({float(ticks['t'][k])}); return gauss6View.state(0)")
    assert state["tick"] == k and not state["force_arrow_visible"] and "NaN" in state["readout"], state
    state = browser.execute_script("gauss6View.seek(0.7); return gauss6View.state(0)")
    assert state["tick"] == 700 and not state["god_visible"], state
    state = browser.execute_script("gauss6View.seek(0.75); return gauss6View.state(0)")
    assert state["god_visible"] and np.all(np.isfinite(state["god_position"])), state
