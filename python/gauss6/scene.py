"""Scene summaries for `gauss6 scene info`: the exact JSON form later checks read."""
from __future__ import annotations

import math
from typing import Any

from . import _gauss6


def _number(x: float) -> float | None:
    """JSON has no NaN: an undefined number (an open obstacle's mass) is null."""
    return None if math.isnan(x) else float(x)


def _vector(v) -> list[float | None]:
    return [_number(x) for x in v]


def load_scene(path) -> _gauss6.Scene:
    """Loads and validates a scene file and its meshes once; scene_info() and
    effective_settings() take the result (or a path, which they load).

    Raises gauss6.LoadError (a ValueError naming file, line and key) for a bad scene or mesh."""
    return _gauss6.load_scene(str(path))


def _loaded(scene) -> _gauss6.Scene:
    return scene if isinstance(scene, _gauss6.Scene) else load_scene(scene)


def scene_info(scene, self_intersections: bool = True) -> dict[str, Any]:
    """{"scene": PATH, "bodies": [...]} with exactly the keys of the documented form,
    for a loaded scene (load_scene) or a scene file's path.

    Raises gauss6.LoadError (a ValueError naming file, line and key) for a bad scene or mesh.
    """
    scene = _loaded(scene)
    raw = _gauss6.scene_summary(scene, self_intersections)
    bodies = []
    for b in raw["bodies"]:
        bodies.append({
            "name": b["name"],
            "role": b["role"],
            "triangles": int(b["triangles"]),
            "vertices": int(b["vertices"]),
            "closed": bool(b["closed"]),
            "manifold": bool(b["manifold"]),
            "self_intersections": int(b["self_intersections"]),
            "mass": _number(b["mass"]),
            "center_of_mass": _vector(b["center_of_mass"]),
            "inertia": [_vector(row) for row in b["inertia"]],
            "bbox_min": _vector(b["bbox_min"]),
            "bbox_max": _vector(b["bbox_max"]),
        })
    return {"scene": scene.path, "bodies": bodies}


def format_scene_info(info: dict[str, Any]) -> str:
    """Human-readable table of scene_info()."""
    lines = [f"scene {info['scene']}"]
    for b in info["bodies"]:
        mass = "n/a (open mesh)" if b["mass"] is None else f"{b['mass']:.6g}"
        lo, hi = b["bbox_min"], b["bbox_max"]
        lines.append(f"  {b['role']:<10} {b['name']}")
        lines.append(f"    triangles {b['triangles']}, vertices {b['vertices']}, closed {b['closed']}, "
                     f"manifold {b['manifold']}, self-intersections {b['self_intersections']}")
        label = "mass" if b["role"] == "god_object" else "mass at density 1 (volume)"
        lines.append(f"    {label} {mass}")
        if b["mass"] is not None:
            com = ", ".join(f"{x:.6g}" for x in b["center_of_mass"])
            lines.append(f"    centre of mass ({com})")
            for i, row in enumerate(b["inertia"]):
                lines.append(("    inertia        " if i == 0 else "                   ")
                             + "  ".join(f"{x: .6e}" for x in row))
        lines.append("    bbox [" + ", ".join(f"{x:.6g}" for x in lo) + "] .. ["
                     + ", ".join(f"{x:.6g}" for x in hi) + "]")
    return "\n".join(lines)


def effective_settings(scene) -> dict[str, Any]:
    """The settings a run of the scene (loaded, or a path) uses: the scene's values and
    the C++ defaults, with the CCD and contact distances derived from delta
    (resolve_runtime_settings).

    Raises gauss6.LoadError for a bad scene."""
    return _gauss6.runtime.effective_settings(_loaded(scene))


def format_effective_settings(settings: dict[str, Any]) -> str:
    """Human-readable list of effective_settings(), one group a line."""
    lines = [f"effective settings (delta = {settings['delta']:.6g})"]
    for group, values in settings.items():
        if isinstance(values, dict):
            lines.append(f"  {group:<11}" + ", ".join(f"{k} {v:.6g}" for k, v in values.items()))
    return "\n".join(lines)

