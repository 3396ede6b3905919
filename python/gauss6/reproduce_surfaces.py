"""The surface-property figures of `gauss6 reproduce` (METHOD.md section 6): the
paper's Figure 8 (force shading) and Figure 9 (texture) analogues, their numbers
for summary.json and their report.md section.

- Figure 8 (`shading`): the faceted cylinder (datasets_generated/scenes/cylinder_plain.toml,
  cylinder_shaded.toml) explored by the probe's tip slid around its axis across five
  edges, without and with force shading, and with shading and a sine texture combined
  (cylinder_textured.toml, bumps of 0.4 mm every 1 cm along X). Numbers, per run:
    max_direction_jump_deg   the largest change of the force's direction over 1 mm of the
                             hand's path during the slide, every tick counted (one whose
                             force is under 0.5 N has no direction: a change to or from it
                             counts as 180 degrees): at an edge of the flat facets the force
                             turns by the 30-degree dihedral within that; shading spreads it
                             over the facet
    max_direction_step_deg   the same between successive ticks
    slide_ticks_without_contact   ticks of the slide whose contact set was empty (no force):
                             the god-object lifted off the surface it was pressed on
- Figure 9 (`texture`): the sine texture (wavelength 1 cm, bumps of 0.8 mm: steepest
  slope 0.503) on a flat slab explored at 0.1 m/s and 0.4 m/s with a sim step every 20
  ticks (a 50 Hz constraint update rate, the paper's low rates on large models): the
  stated bound is v_max = L_min f / 2 = 0.25 m/s. Numbers, per run:
    bumps_traversed, bumps_missed   whole periods of the texture the god-object crossed
                             during the slide, and those in which the force's tilt along X
                             (ticks with |Fz| > 0.5 N) did not reach half the texture's
                             steepest slope both ways (a bump is its rise and its fall)
    texture_events           kTextureUndersampled onsets (the runtime's warning)
    speed_bound              v_max (m/s) at the run's update rate
    max_direction_jump_deg, max_direction_step_deg   as for Figure 8 (the texture sampled at
                             each sim step turns the force between two steps by design)
- Height map (`heightmap`): the bumps of datasets_generated/surfaces/bumps.png (14 round
  bumps of radius 0.8 to 5.5 mm, bumps.json lists them) on the slab (heightmap.toml),
  explored by the Figure 9 slow slide (0.1 m/s along the bump row) with a sim step every
  tick (1 kHz: bound 0.25 m/s) and every 20 ticks (50 Hz: bound 12.5 mm/s for the image's
  two-pixel wavelength; a bump of radius R is about a period of 2 R, felt while the contact
  moves less than R per update). Numbers, per run:
    bumps_traversed, bumps_missed   bumps whose whole extent the god-object crossed during
                             the slide, and those over which the force's tilt along X (ticks
                             with |Fz| > 0.5 N) did not reach half the bump's steepest slope
                             both ways (the rise tilts it back, the fall forward)
    missed_radii             the missed bumps' radii (m)
    max_god_object_step      the god-object's largest move between two ticks of the slide (m)
    texture_events, speed_bound, update_hz   as for Figure 9
    port_energy_max, port_energy_final, shading_work_*   the energy figures below
- For every run: property 7 (max_rel_constraint_violation over every sim step), the
  shaded orthogonality (max_rel_force_dot_asc over the coupling steps), penetrating
  poses (exact check), and the energy figures: the constraint stage's (energy_injected,
  <= 0 up to rounding), the shading's work on the god-object's motion
  (shading_work_injected / _removed, J) and the device-port passivity observer's maximum
  (port_energy_max, J); offset_steps, the coupling steps with an offset row running (on a
  shaded run the offsets apply to the shading rows).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import paths

SCENES = paths.DATASETS_DIR / "scenes"
SHADING_RUNS = {"plain": "cylinder_plain.toml", "shaded": "cylinder_shaded.toml",
                "textured": "cylinder_textured.toml"}  # textured: shading and a texture combined
TEXTURE_RUNS = {"slow": "texture_slow.toml", "fast": "texture_fast.toml"}
TEXTURE_SIM_PERIOD = 20          # haptic ticks per sim step in the texture runs (50 Hz)
HEIGHTMAP_SCENE = "heightmap.toml"
HEIGHTMAP_RUNS = {"1khz": 1, "50hz": TEXTURE_SIM_PERIOD}  # label: haptic ticks per sim step
MIN_FORCE = 0.5                  # N: ticks with a weaker force have no meaningful direction


def _run(scene: Path, out: Path, label: str, sim_period: int, show_progress: bool) -> tuple[dict, object]:
    from ._gauss6 import runtime
    from .exact_checks import count_penetrating, distinct_poses
    from .trace import read_trace

    trace_path = out / f"{label}.g6trace"
    run = runtime.run_scenario(str(scene), str(trace_path), lockstep_sim_period=sim_period,
                               extra_json=json.dumps({"scenario": label, "mode": "lockstep"}))
    trace = read_trace(trace_path)
    penetrating, _ = count_penetrating(scene, distinct_poses(trace), show_progress, label)
    sim = run["sim"]
    numbers = {
        "penetrating_poses": penetrating,
        "slide_ticks": int(_slide_mask(trace).sum()),
        "slide_ticks_without_contact": int((_slide_mask(trace) & (trace.ticks["num_contacts"] == 0)).sum()),
        "max_rel_constraint_violation": run["max_rel_constraint_violation"],
        "constraint_checks": run["num_constraint_checks"],
        "max_rel_force_dot_asc": run["max_rel_force_dot_ac"],
        "shaded_coupling_steps": run["num_shaded_steps"],
        "offset_steps": run["num_offset_steps"],
        "energy_injected": run["constraint_energy_injected"],
        "shading_work_injected": run["shading_work_injected"],
        "shading_work_removed": run["shading_work_removed"],
        "port_energy_max": run["port_energy_max"],
        "port_energy_final": run["port_energy_final"],
        "max_force": float(np.max(np.linalg.norm(trace.ticks["wrench"][:, :3], axis=1))),
        "events": sim.get("events", {}),
    }
    return numbers, trace


def _slide_mask(trace) -> np.ndarray:
    phases = trace.meta.get("phases", []) if hasattr(trace, "meta") else []
    t = trace.ticks["t"]
    start = next((p["start"] for p in phases if p.get("name") == "slide"), None)
    end = next((p["start"] for p in phases if p.get("name") == "lift"), None)
    mask = np.ones(t.shape, dtype=bool)
    if start is not None:
        mask &= t >= start + 0.05
    if end is not None:
        mask &= t < end
    return mask


def direction_jumps(trace) -> tuple[float, float]:
    """(largest direction change over 1 mm of hand path, largest between successive ticks), degrees,
    over every tick of the slide: a tick whose force is under MIN_FORCE (a contact dropout: the
    force vanished) has no direction, and a change to or from it counts as 180 degrees."""
    F = trace.ticks["wrench"][:, :3]
    xh = trace.ticks["xh_p"]
    idx = np.flatnonzero(_slide_mask(trace))
    if idx.size < 2:
        return 0.0, 0.0
    norm = np.linalg.norm(F[idx], axis=1)
    has = norm > MIN_FORCE
    d = np.where(has[:, None], F[idx] / np.where(has, norm, 1.0)[:, None], 0.0)

    def angle(i, j):  # between ticks i and j (arrays or scalars), degrees
        a = np.degrees(np.arccos(np.clip(np.sum(d[i] * d[j], axis=-1), -1, 1)))
        return np.where(has[i] & has[j], a, 180.0)

    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xh[idx], axis=0), axis=1))])
    steps = angle(np.arange(1, idx.size), np.arange(idx.size - 1))
    # Each tick against the earliest one at most 1 mm of hand path before it (s is non-decreasing).
    first = np.searchsorted(s, s - 1e-3, side="left")
    worst = angle(np.arange(idx.size), first).max(initial=0.0)
    return float(worst), float(steps.max(initial=0.0))


def sine_texture(scene: Path) -> dict:
    """The scene's sine texture along X: wavelength, amplitude (scene units), origin's x and
    steepest slope 2 pi A / L (surface.h), read from its TOML."""
    import tomllib

    s = tomllib.loads(Path(scene).read_text())["surface"]
    if s.get("texture", "sine") != "sine" or s.get("axis", "x") != "x":
        raise ValueError(f"{scene}: the Figure 9 analysis needs a sine texture along x")
    L, A = float(s["wavelength"]), float(s["amplitude"])
    return {"wavelength": L, "amplitude": A, "origin_x": float(s.get("origin", [0.0])[0]),
            "slope": 2 * np.pi * A / L}


def bumps(trace, texture: dict) -> tuple[int, int]:
    """(whole periods the god-object crossed during the slide, those whose force tilt did not
    reach half the texture's steepest slope both ways)."""
    F = trace.ticks["wrench"][:, :3]
    x = trace.ticks["xs_p"][:, 0]
    slide = _slide_mask(trace)
    if not slide.any():
        return 0, 0
    ok = slide & (np.abs(F[:, 2]) > MIN_FORCE)
    tilt = F[ok, 0] / F[ok, 2]
    L, x0, half = texture["wavelength"], texture["origin_x"], 0.5 * texture["slope"]
    k = np.floor((x[ok] - x0) / L).astype(int)
    crossed = range(int(np.floor((x[slide].min() - x0) / L)) + 1, int(np.floor((x[slide].max() - x0) / L)))
    missed = 0
    for period in crossed:
        t = tilt[k == period]
        if not (t.size and t.max() > half and t.min() < -half):
            missed += 1
    return len(crossed), missed


def height_map_texture(scene: Path) -> dict:
    """The scene's height map: its [surface] table (origin, amplitude, pitch = wavelength / the
    image's width) and the bump list the generator wrote beside the image (bumps.json)."""
    import tomllib

    scene = Path(scene)
    s = tomllib.loads(scene.read_text())["surface"]
    if s.get("texture") != "height_map" or s.get("axis", "x") != "x":
        raise ValueError(f"{scene}: the height-map analysis needs a height map along x")
    listing = json.loads((scene.parent / s["image"]).resolve().with_name("bumps.json").read_text())
    return {"origin": [float(v) for v in s.get("origin", [0.0, 0.0, 0.0])], "amplitude": float(s["amplitude"]),
            "pitch": float(s["wavelength"]) / listing["pixels"][0], "bumps": listing["bumps"]}


def height_profile(texture: dict, x: np.ndarray) -> np.ndarray:
    """The bumps' height along their row at world x (the generator's raised cosines)."""
    h = np.zeros_like(x)
    for b in texture["bumps"]:
        d = np.abs(x - texture["origin"][0] - b["x"])
        h = np.maximum(h, np.where(d < b["radius"], 0.5 * b["height"] * (1 + np.cos(np.pi * d / b["radius"])), 0))
    return h


def height_map_bumps(trace, texture: dict) -> tuple[int, list[float]]:
    """(bumps whose extent the god-object crossed during the slide, the radii of those over which
    the force's tilt did not reach half the bump's steepest slope both ways)."""
    F = trace.ticks["wrench"][:, :3]
    x = trace.ticks["xs_p"][:, 0]
    slide = _slide_mask(trace)
    ok = slide & (np.abs(F[:, 2]) > MIN_FORCE)
    tilt = np.where(ok, F[:, 0] / np.where(ok, F[:, 2], 1.0), 0.0)
    x0 = texture["origin"][0]
    crossed, missed = 0, []
    for b in texture["bumps"]:
        lo, hi = x0 + b["x"] - b["radius"], x0 + b["x"] + b["radius"]
        if not (x[slide].min() < lo and x[slide].max() > hi):
            continue
        crossed += 1
        t = tilt[ok & (x >= lo) & (x <= hi)]
        if not (t.size and t.min() < -0.5 * b["slope"] and t.max() > 0.5 * b["slope"]):
            missed.append(float(b["radius"]))
    return crossed, missed


def max_slide_step(trace) -> float:
    """The god-object's largest move between two ticks of the slide (m)."""
    idx = np.flatnonzero(_slide_mask(trace))
    if idx.size < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(trace.ticks["xs_p"][idx], axis=0), axis=1).max())


def reproduce_surfaces(out: Path, show_progress: bool = True) -> tuple[dict, dict]:
    """Runs the surface runs; writes their traces and figures; returns (summary, details)."""
    out.mkdir(parents=True, exist_ok=True)
    summary: dict = {"shading": {}, "texture": {}, "heightmap": {}}
    traces = {}
    for label, scene in SHADING_RUNS.items():
        numbers, trace = _run(SCENES / scene, out, f"cylinder_{label}", 1, show_progress)
        numbers["max_direction_jump_deg"], numbers["max_direction_step_deg"] = direction_jumps(trace)
        summary["shading"][label] = numbers
        traces[f"cylinder_{label}"] = trace
    rate = 1000.0 / TEXTURE_SIM_PERIOD
    for label, scene in TEXTURE_RUNS.items():
        texture = sine_texture(SCENES / scene)
        numbers, trace = _run(SCENES / scene, out, f"texture_{label}", TEXTURE_SIM_PERIOD, show_progress)
        numbers["bumps_traversed"], numbers["bumps_missed"] = bumps(trace, texture)
        numbers["texture_events"] = int(numbers["events"].get("texture_undersampled", 0))
        numbers["update_hz"] = rate
        numbers["speed_bound"] = 0.5 * texture["wavelength"] * rate
        numbers["texture_slope"] = texture["slope"]
        numbers["max_direction_jump_deg"], numbers["max_direction_step_deg"] = direction_jumps(trace)
        summary["texture"][label] = numbers
        traces[f"texture_{label}"] = trace
    hm = height_map_texture(SCENES / HEIGHTMAP_SCENE)
    for label, period in HEIGHTMAP_RUNS.items():
        numbers, trace = _run(SCENES / HEIGHTMAP_SCENE, out, f"heightmap_{label}", period, show_progress)
        numbers["bumps_traversed"], missed = height_map_bumps(trace, hm)
        numbers["bumps_missed"], numbers["missed_radii"] = len(missed), sorted(missed)
        numbers["max_god_object_step"] = max_slide_step(trace)
        numbers["texture_events"] = int(numbers["events"].get("texture_undersampled", 0))
        numbers["update_hz"] = 1000.0 / period
        numbers["speed_bound"] = 0.5 * 2 * hm["pitch"] * numbers["update_hz"]  # two pixels: L_min f / 2
        summary["heightmap"][label] = numbers
        traces[f"heightmap_{label}"] = trace
    figures = plot_surfaces(traces, out, sine_texture(SCENES / TEXTURE_RUNS["slow"]))
    figures += plot_height_map(traces, out, hm)
    return summary, {"figures": figures}


def _save(fig, out: Path, stem: str) -> list[str]:
    """Writes stem.png and stem.svg, closes the figure; returns the file names."""
    import matplotlib.pyplot as plt

    names = []
    for ext in ("png", "svg"):
        fig.savefig(out / f"{stem}.{ext}", dpi=120)
        names.append(f"{stem}.{ext}")
    plt.close(fig)
    return names


def _tilt_panel(ax, trace, x_ref: np.ndarray, tilt_ref: np.ndarray, ref_label: str, title: str) -> None:
    """One axis: the surface's tilt against x (dotted) and the force's tilt Fx/Fz at the god-object's x
    over the slide's ticks with a force."""
    F, x = trace.ticks["wrench"][:, :3], trace.ticks["xs_p"][:, 0]
    ok = _slide_mask(trace) & (np.abs(F[:, 2]) > MIN_FORCE)
    ax.plot(x_ref * 100, tilt_ref, "k:", lw=0.8, label=ref_label)
    ax.plot(x[ok] * 100, F[ok, 0] / F[ok, 2], ".", ms=2, label="force tilt Fx/Fz")
    ax.set_ylabel("tilt")
    ax.set_title(title)
    ax.legend(fontsize=7, loc="upper right")


def plot_surfaces(traces: dict, out: Path, texture: dict) -> list[str]:
    """figure_shading.png/svg (Figure 8) and figure_texture.png/svg (Figure 9)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    for label in ("plain", "shaded"):
        tr = traces[f"cylinder_{label}"]
        F, xs, xh = tr.ticks["wrench"][:, :3], tr.ticks["xs_p"], tr.ticks["xh_p"]
        ok = _slide_mask(tr) & (np.linalg.norm(F, axis=1) > MIN_FORCE)
        hand_deg = np.degrees(np.arctan2(xh[ok, 2], xh[ok, 0]))
        force_deg = np.degrees(np.arctan2(F[ok, 2], F[ok, 0]))
        ax[0].plot(hand_deg, force_deg, label=label)
        ax[1].plot(xs[:, 0] * 100, xs[:, 2] * 100, label=f"god-object, {label}")
        stride = max(1, int(ok.sum() // 40))
        sel = np.flatnonzero(ok)[::stride]
        ax[1].quiver(xs[sel, 0] * 100, xs[sel, 2] * 100, F[sel, 0], F[sel, 2], angles="xy", width=0.003,
                     color="C0" if label == "plain" else "C1")
    ring = np.radians(np.arange(0, 361, 30))
    ax[1].plot(3 * np.cos(ring), 3 * np.sin(ring), "k-", lw=0.8, label="cylinder (12 facets)")
    ax[0].set_xlabel("hand angle around the axis (deg)")
    ax[0].set_ylabel("force direction in the XZ plane (deg)")
    ax[0].set_title("Force direction over the slide")
    ax[0].legend()
    ax[1].set_aspect("equal")
    ax[1].set_xlim(-4, 4)
    ax[1].set_ylim(0, 4.2)
    ax[1].set_xlabel("x (cm)")
    ax[1].set_ylabel("z (cm)")
    ax[1].set_title("Path and force")
    ax[1].legend(fontsize=7)
    fig.suptitle("Force shading on a faceted cylinder (Figure 8 analogue)")
    fig.tight_layout()
    written += _save(fig, out, "figure_shading")

    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    x = np.linspace(-0.06, 0.06, 1200)
    for i, label in enumerate(("slow", "fast")):
        phase = 2 * np.pi * (x - texture["origin_x"]) / texture["wavelength"]
        _tilt_panel(ax[i], traces[f"texture_{label}"], x, -texture["slope"] * np.cos(phase), "texture's tilt (-dh/dx)",
                    f"{label}: {'0.1' if label == 'slow' else '0.4'} m/s (bound 0.25 m/s at 50 Hz)")
    ax[1].set_xlabel("x (cm)")
    fig.suptitle("Bump-and-hole texture at two speeds (Figure 9 analogue)")
    fig.tight_layout()
    written += _save(fig, out, "figure_texture")
    return written


def plot_height_map(traces: dict, out: Path, texture: dict) -> list[str]:
    """figure_heightmap.png/svg: the bump row's height and the force's tilt against x at both rates."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs = np.linspace(-0.064, 0.064, 4001)
    row = height_profile(texture, xs)
    fig, ax = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    ax[0].plot(xs * 100, row * 1000, "k-", lw=0.8)
    ax[0].set_ylabel("height (mm)")
    ax[0].set_title("the bumps of bumps.png along the slide (y = 0)")
    for i, label in enumerate(HEIGHTMAP_RUNS, start=1):
        _tilt_panel(ax[i], traces[f"heightmap_{label}"], xs, -np.gradient(row, xs), "bumps' tilt (-dh/dx)",
                    f"0.1 m/s, constraints updated at {1000 // HEIGHTMAP_RUNS[label]} Hz")
    ax[2].set_xlabel("x (cm)")
    fig.suptitle("Height-map texture: bumps felt and skipped")
    fig.tight_layout()
    return _save(fig, out, "figure_heightmap")


def report_lines(summary: dict) -> list[str]:
    """The report.md section of the surface runs."""
    s, t = summary["shading"], summary["texture"]
    lines = ["## Surface properties (Figures 8 and 9 analogues)", "",
             "![shading](figure_shading.png)", "", "![texture](figure_texture.png)", "",
             "| run | largest direction jump over 1 mm (deg) | per tick (deg) | slide ticks without contact "
             "| property 7 (max rel. violation) "
             "| Fc.asc (max rel.) | shading work in / out (J) | port energy max (J) | penetrating poses |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for label, n in s.items():
        lines.append(f"| cylinder, {label} | {n['max_direction_jump_deg']:.3g} | {n['max_direction_step_deg']:.3g} | "
                     f"{n['slide_ticks_without_contact']} of {n['slide_ticks']} | "
                     f"{n['max_rel_constraint_violation']:.3g} | {n['max_rel_force_dot_asc']:.3g} | "
                     f"{n['shading_work_injected']:.3g} / {n['shading_work_removed']:.3g} | "
                     f"{n['port_energy_max']:.3g} | {n['penetrating_poses']} |")
    lifted = {label: n for label, n in s.items() if n["slide_ticks_without_contact"]}
    for label, n in lifted.items():
        lines += ["", f"**Contact dropouts, cylinder {label}:** the contact set is empty on "
                  f"{n['slide_ticks_without_contact']} of {n['slide_ticks']} ticks of the slide (the force drops to "
                  "zero there; the direction jumps above count a change to or from such a tick as 180 degrees)."]
    if "textured" in s:
        n = s["textured"]
        lines += ["", "Cylinder, textured (shading under a sine texture of slope 0.25): the texture tilts the shaded "
                  "force by up to 14 degrees, and turns it by up to 9 degrees per mm of the god-object's path on its "
                  f"own; largest turn between successive ticks {n['max_direction_step_deg']:.3g} degrees. Before the "
                  "texture's average was weighted by the forces the contacts carry (surface.h) it was 24.9 degrees "
                  "(30.6 over 1 mm): the probe lies on a facet with its tip and a second vertex half a wavelength "
                  "apart (opposite perturbations); a contact that carried no force still entered the plain average, "
                  "and pass 2, holding the pressed tip with its own row alone, pushed the second vertex out of its "
                  "face and so lifted the tip (4e-8 m a step) until the tip, which carried the whole force, left "
                  "the contact band: the force jumped to the second vertex's phase. Pass 2 now holds a pressed "
                  "contact at its gap together with its own rows."]
    lines += ["", "| run | speed bound (m/s) | bumps crossed | bumps missed | texture events | largest direction "
              "jump over 1 mm / per tick (deg) | property 7 | shading work in / out (J) | port energy max (J) "
              "| penetrating poses |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for label, n in t.items():
        lines.append(f"| texture, {label} | {n['speed_bound']:.3g} | {n['bumps_traversed']} | {n['bumps_missed']} | "
                     f"{n['texture_events']} | {n['max_direction_jump_deg']:.3g} / {n['max_direction_step_deg']:.3g} | "
                     f"{n['max_rel_constraint_violation']:.3g} | "
                     f"{n['shading_work_injected']:.3g} / {n['shading_work_removed']:.3g} | "
                     f"{n['port_energy_max']:.3g} | {n['penetrating_poses']} |")
    slow, fast = t.get("slow"), t.get("fast")
    if slow and fast:
        # The paper's Figure 9: every bump felt under the speed bound, some skipped over it.
        lines += ["", f"Under the bound ({slow['speed_bound']:.3g} m/s) the slow run feels "
                  f"{slow['bumps_traversed'] - slow['bumps_missed']} of {slow['bumps_traversed']} bumps; over it the "
                  f"fast run misses {fast['bumps_missed']} of {fast['bumps_traversed']} (sampled at most "
                  "1.25 times a period, the texture aliases) and raises `texture_undersampled`."]
        lines += ["", "The slab runs' direction steps are the texture sampled at the 50 Hz constraint update: the "
                  "rows, and so the force's direction, change only at a sim step, by the texture's turn over the "
                  "contact's path since the last (at 0.1 m/s 2 mm, a fifth of a wavelength, and up to 3.4 mm "
                  "where the god-object catches up with the hand); a tick without force "
                  "(the fast run's tip off the slab between bumps) counts as 180 degrees."]
        if slow["bumps_missed"] > 0 or fast["bumps_missed"] == 0:
            lines += ["", "**Not the paper's Figure 9:** every bump should be felt under the bound and some "
                      "missed over it."]
    hm = summary.get("heightmap", {})
    if hm:
        lines += ["", "![height map](figure_heightmap.png)", "",
                  "| run | update rate (Hz) | speed bound (m/s) | bumps crossed | bumps missed (radii, mm) | "
                  "texture events | property 7 | shading work in / out (J) | port energy max / final (J) "
                  "| penetrating poses |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for label, n in hm.items():
            radii = ", ".join(f"{r * 1000:.2g}" for r in n["missed_radii"])
            lines.append(f"| height map, {label} | {n['update_hz']:.0f} | {n['speed_bound']:.3g} | "
                         f"{n['bumps_traversed']} | {n['bumps_missed']}{f' ({radii})' if radii else ''} | "
                         f"{n['texture_events']} | {n['max_rel_constraint_violation']:.3g} | "
                         f"{n['shading_work_injected']:.3g} / {n['shading_work_removed']:.3g} | "
                         f"{n['port_energy_max']:.3g} / {n['port_energy_final']:.3g} | {n['penetrating_poses']} |")
        fast, slow = hm.get("1khz"), hm.get("50hz")
        lines += ["", "The height map's bound counts its finest detail, two pixels (0.5 mm): 0.25 m/s at 1 kHz, "
                  "12.5 mm/s at 50 Hz, so the 50 Hz run is over it and says so (`texture_undersampled`). Its "
                  "bumps are coarser than that: a bump of radius R is about a period of 2 R, which the same bound "
                  "asks to sample in steps under R."]
        if fast and slow:
            lines += ["", f"At 50 Hz the god-object moves up to {slow['max_god_object_step'] * 1000:.2g} mm between "
                      f"updates and misses {slow['bumps_missed']} of {slow['bumps_traversed']} bumps; at 1 kHz "
                      f"{fast['bumps_missed']} of {fast['bumps_traversed']}: there the hand moves 0.1 mm a tick, but "
                      "the god-object, held back on a bump's rise by the tilted rows (pass 2 follows asc along the "
                      f"surface) and released on its fall, slips by up to {fast['max_god_object_step'] * 1000:.2g} "
                      f"mm a step, past the bound on the narrowest bumps ({fast['texture_events']} "
                      "`texture_undersampled` onsets)."]
    lines += ["", "Shading and textures can inject energy: the shaded force is orthogonal to the shaded motion asc, "
              "not to the motion ac the god-object takes, and its work on it is Fs . (ac - asc) (Coq: "
              "`shading_work`). That work is bounded per step by |Fs| |ac - asc|, which grows with the angle "
              "between the shading and the true normals (at most the crease angle, and never more than 60 "
              "degrees); the constraint stage itself still removes energy (energy_injected stays at rounding).", ""]
    return lines
