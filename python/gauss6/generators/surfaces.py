"""The surface-property scenes of METHOD.md section 6 (the paper's Figures 8 and 9):
meshes and hand scripts.

- faceted_cylinder.off: a 12-sided prism (circumradius 3 cm, length 8 cm, axis Y,
  centred on the origin), the low-polygon cylinder that force shading makes feel
  round (Figure 8). Made by the peg generator's make_peg (same code, other sizes).
- slab.off: a 20 x 6 x 1 cm block (X, Y, Z), top face at z = 0, the surface the
  bump-and-hole texture is drawn on (Figure 9).
- probe.off: a regular octahedron of circumradius 5 mm, the held probe; the scenes
  put its reference point G at its lowest vertex (the tip that explores).
- cylinder_slide.json: the tip pressed 4 mm past the cylinder's flats, slid over the
  top half around the axis (15 to 165 degrees) across five edges, then lifted.
- bumps.png, bumps.json: the height map of the height-map scene (heightmap.toml): a 16-bit
  grey PNG of round raised-cosine bumps, h = a (1 + cos(pi r / R)) / 2 within r < R, in a
  row along the image's middle line, their radii (log-uniform 0.75 to 6 mm), steepest
  slopes (0.3 to 0.5) and gaps (2 to 5 mm) drawn from numpy's PCG64 with a fixed seed;
  pixel pitch 0.25 mm, values scaled so that the highest bump is 1 (the scene's amplitude
  is its height). bumps.json lists each bump's centre, radius, height and steepest slope
  (scene units, the tile's first pixel at the origin) for the analysis. Written with
  Pillow at a fixed compression level (the same bytes on a rerun with the pinned Pillow).
- texture_slow.json / texture_fast.json: the tip pressed 6 mm into the slab and slid
  along +X over 12 cm at 0.1 m/s and at 0.4 m/s. The press is deep against the
  hand's lead over the god-object (2 to 4 mm along X at a 50 Hz sim step and
  ks = 0.5): on a texture's downhill slope the tilted constraint plane drops by
  the slope times that lead, and a shallower press leaves the hand above it
  (no force) at the slopes the figure must show.

Coordinates are correctly rounded doubles (angles through the peg generator's
40-digit cos/sin), so the files do not depend on the platform's libm.

Made by `gauss6 datasets generate [--only surfaces]` (gauss6.datasets).
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from . import peg_in_hole as peg, source

GENERATOR_VERSION = "3"  # 3: the height map bumps.png, bumps.json; 2: the texture scripts press 6 mm (1: 3 mm)


@dataclass(frozen=True)
class SurfacesParams:
    """Lengths in metres, times in seconds."""

    cylinder_radius: float = 0.03
    cylinder_length: float = 0.08
    cylinder_sides: int = 12
    slab_size: tuple = (0.2, 0.06, 0.01)
    probe_radius: float = 0.005
    press: float = 0.004            # cylinder: the hand this far inside the flats (apothem)
    slide_from_deg: int = 15        # cylinder: the slide's start and end angles (from +X towards +Z)
    slide_to_deg: int = 165
    slide_time: float = 3.0
    texture_press: float = 0.006
    texture_start_x: float = -0.06
    texture_length: float = 0.12
    texture_speeds: tuple = (0.1, 0.4)
    heightmap_pixels: tuple = (512, 64)  # width (along X), height (along Y)
    heightmap_pitch: float = 0.00025
    heightmap_seed: int = 1
    heightmap_radii: tuple = (0.00075, 0.006)
    heightmap_slopes: tuple = (0.15, 0.3)
    heightmap_gaps: tuple = (0.002, 0.005)

    def to_json(self) -> dict:
        d = asdict(self)
        return {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}


def make_slab(p: SurfacesParams) -> tuple[np.ndarray, np.ndarray]:
    """The slab: 8 vertices, 12 outward triangles, top face at z = 0."""
    sx, sy, sz = (0.5 * p.slab_size[0], 0.5 * p.slab_size[1], p.slab_size[2])
    V = [(x, y, z) for z in (-sz, 0.0) for y in (-sy, sy) for x in (-sx, sx)]
    # Vertex i = 4 z + 2 y + x (bits); faces counter-clockwise seen from outside.
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    F = []
    for a, b, c, d in quads:
        F += [(a, b, c), (a, c, d)]
    return np.array(V, dtype=np.float64), np.array(F, dtype=np.int64)


def make_probe(p: SurfacesParams) -> tuple[np.ndarray, np.ndarray]:
    """The octahedron: vertices on the axes at distance probe_radius, 8 outward triangles."""
    r = p.probe_radius
    V = [(r, 0.0, 0.0), (-r, 0.0, 0.0), (0.0, r, 0.0), (0.0, -r, 0.0), (0.0, 0.0, r), (0.0, 0.0, -r)]
    F = []
    for sx, sy, sz in [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]:
        F.append((sx, sy, sz))
    return np.array(V, dtype=np.float64), np.array(F, dtype=np.int64)


def _key(t: float, p: tuple) -> dict:
    return {"t": round(t, 9), "p": [float(x) + 0.0 for x in p], "q": [1.0, 0.0, 0.0, 0.0]}


def cylinder_script(p: SurfacesParams) -> dict:
    """The tip (G) around the cylinder's axis at the flats' apothem less `press`."""
    n = p.cylinder_sides
    c15, _ = peg._cos_sin(1, 2 * n)                 # cos(pi / n): apothem / circumradius
    import decimal
    ctx = peg._CTX
    radius = ctx.subtract(ctx.multiply(decimal.Decimal(p.cylinder_radius), c15), decimal.Decimal(p.press))
    far = decimal.Decimal(p.cylinder_radius + 0.01)

    def at(deg: int, r) -> tuple:
        c, s = peg._cos_sin(deg, 360)
        return (float(ctx.multiply(r, c)), 0.0, float(ctx.multiply(r, s)))

    a0, a1 = p.slide_from_deg, p.slide_to_deg
    keys = [_key(0.0, at(a0, far)), _key(0.5, at(a0, far)), _key(1.0, at(a0, radius))]
    for i, deg in enumerate(range(a0, a1 + 1)):
        keys.append(_key(1.5 + p.slide_time * i / (a1 - a0), at(deg, radius)))
    end = 1.5 + p.slide_time
    keys += [_key(end + 0.5, at(a1, far))]
    return {"description": "Figure 8 analogue: the probe's tip pressed past the faceted cylinder's flats and slid "
                           f"around its axis from {a0} to {a1} degrees (from +X towards +Z) across its edges.",
            "keys": keys,
            "phases": [{"name": "approach", "start": 0.0}, {"name": "slide", "start": 1.5},
                       {"name": "lift", "start": end}],
            "end_time": end + 1.0}


def texture_script(p: SurfacesParams, speed: float) -> dict:
    """The tip pressed into the slab's top and slid along +X at `speed`."""
    x0, z = p.texture_start_x, -p.texture_press
    t_slide = p.texture_length / speed
    keys = [_key(0.0, (x0, 0.0, 0.01)), _key(0.3, (x0, 0.0, 0.01)), _key(0.8, (x0, 0.0, z)),
            _key(1.0, (x0, 0.0, z)), _key(1.0 + t_slide, (x0 + p.texture_length, 0.0, z)),
            _key(1.5 + t_slide, (x0 + p.texture_length, 0.0, 0.01))]
    return {"description": f"Figure 9 analogue: the probe's tip pressed {p.texture_press * 1000:g} mm into the "
                           f"textured slab and slid along +X over {p.texture_length * 100:g} cm at {speed:g} m/s.",
            "keys": keys,
            "phases": [{"name": "approach", "start": 0.0}, {"name": "slide", "start": 1.0},
                       {"name": "lift", "start": 1.0 + t_slide}],
            "end_time": round(2.0 + t_slide, 9)}


def height_map(p: SurfacesParams) -> tuple[np.ndarray, list[dict]]:
    """(image in [0, 1] as uint16, rows along Y; the bumps) of bumps.png: raised-cosine bumps on the
    image's middle row, drawn left to right until the next would not fit with a margin of one gap."""
    width, height = p.heightmap_pixels
    pitch = p.heightmap_pitch
    rng = np.random.Generator(np.random.PCG64(p.heightmap_seed))
    bumps = []
    x = p.heightmap_gaps[1]
    while True:
        r = float(np.exp(rng.uniform(np.log(p.heightmap_radii[0]), np.log(p.heightmap_radii[1]))))
        slope = float(rng.uniform(*p.heightmap_slopes))
        gap = float(rng.uniform(*p.heightmap_gaps))
        if x + 2 * r + p.heightmap_gaps[1] > width * pitch or r > 0.5 * height * pitch:
            break
        # Steepest slope of a (1 + cos(pi r / R)) / 2 is a pi / (2 R).
        bumps.append({"x": x + r, "y": 0.5 * height * pitch, "radius": r, "height": slope * 2 * r / np.pi,
                      "slope": slope})
        x += 2 * r + gap
    X, Y = np.meshgrid(np.arange(width) * pitch, np.arange(height) * pitch)
    h = np.zeros((height, width))
    for b in bumps:
        d = np.hypot(X - b["x"], Y - b["y"])
        h = np.maximum(h, np.where(d < b["radius"], 0.5 * b["height"] * (1 + np.cos(np.pi * d / b["radius"])), 0))
    top = max(b["height"] for b in bumps)
    image = np.rint(h / top * 65535).astype(np.uint16)
    return image, [{k: round(v, 12) for k, v in b.items()} for b in bumps]


def png_bytes(image: np.ndarray) -> bytes:
    """A 16-bit grey PNG of `image` (uint16), Pillow at compression level 9."""
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(image).save(buf, format="PNG", compress_level=9)
    return buf.getvalue()


def generate(out_dir: Path, params: SurfacesParams | None = None) -> dict[str, str]:
    """Writes the meshes and scripts into out_dir; returns {filename: text}."""
    p = params or SurfacesParams()
    cyl = peg.PegInHoleParams(peg_radius=p.cylinder_radius, peg_length=p.cylinder_length,
                              peg_sides=p.cylinder_sides)
    meshes = {"faceted_cylinder.off": peg.make_peg(cyl), "slab.off": make_slab(p), "probe.off": make_probe(p)}
    relpath, sha = source(__spec__.name)
    header = peg.provenance_header(relpath, p.to_json(), sha)
    header[1] = f"generator_version: {GENERATOR_VERSION}"
    out = {}
    for name, (V, F) in meshes.items():
        problems = peg.check_closed_manifold(F)
        if problems or not peg.signed_volume(V, F) > 0:
            raise RuntimeError(f"{name}: not a closed outward manifold: {problems}")
        out[name] = peg.off_text(V, F, header)
    scripts = {"cylinder_slide.json": cylinder_script(p)}
    for speed, label in zip(p.texture_speeds, ("slow", "fast")):
        scripts[f"texture_{label}.json"] = texture_script(p, speed)
    image, bumps = height_map(p)
    scripts["bumps.json"] = {"description": "The round bumps of bumps.png (generators/surfaces.py, height_map): "
                                            "centre x, y, radius, height and steepest slope, metres, in the "
                                            "image's tile (its first pixel at 0, 0).",
                             "pitch": p.heightmap_pitch, "pixels": list(p.heightmap_pixels),
                             "amplitude": max(b["height"] for b in bumps), "bumps": bumps}
    for name, s in scripts.items():
        out[name] = json.dumps(s, indent=1) + "\n"
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, text in out.items():
        (out_dir / name).write_text(text, encoding="ascii")
    (out_dir / "bumps.png").write_bytes(png_bytes(image))
    return {**out, "bumps.png": "(binary)"}

