"""The generated datasets (METHOD.md section 7): making them and checking them.

Each dataset lives in datasets_generated/<name>/ (paths.DATASETS_DIR, or --out) with a MANIFEST.json:

    {"generator": path of the generator source, relative to the repository,
     "generator_version": "1",
     "parameters": {...},
     "source_sha256": sha256 of the generator source,
     "outputs": {filename: sha256}}

and every OFF file it holds starts with the same fields as '#' comment lines.
Generation is deterministic: the same parameters give byte-identical files, so
`check_all()` can regenerate each dataset and compare checksums.

- peg_in_hole: peg.off (288 triangles) and box_with_hole.off (280 triangles),
  from gauss6.generators.peg_in_hole (Python, numpy).
- bunny: bunny.off (about 27,000 triangles, 15 cm tall, metres), from
  glmark2-data's bunny.obj by the CGAL program gauss6_make_bunny
  (datasets_generated/generators/make_bunny.cpp, built by CMake; a wheel carries the program
  and its source, paths.tool and BUNNY_SOURCE).
- surfaces: faceted_cylinder.off, slab.off, probe.off and the hand scripts of the
  Figure 8 and 9 analogues (cylinder_slide.json, texture_slow.json, texture_fast.json), the
  height map bumps.png with its bump list bumps.json, from
  gauss6.generators.surfaces (Python, numpy, Pillow; reuses the peg generator).
- battery: the conformance battery's meshes and hand scripts (docs/conformance-battery.md), one
  scene each in datasets_generated/scenes/ (BATTERY_SCENES), from
  gauss6.generators.battery (Python, numpy; reuses the peg generator).
- bunny_x4, bunny_x16 (ON_DEMAND: not in DATASETS, not committed, tens of MB): bunny_full's
  bunny.off with each triangle split into 4 or 16 (the same surface), from
  gauss6.generators.subdivide; `gauss6 datasets generate --only NAME`.
"""
from __future__ import annotations

import hashlib
import json
import subprocess
import tempfile
from pathlib import Path

from tqdm import tqdm

from . import paths
from .generators import battery, peg_in_hole, source, subdivide, surfaces

DATASETS = ("peg_in_hole", "bunny", "bunny_full", "surfaces", "battery")
# The conformance battery's scenes (datasets_generated/scenes/NAME.toml), one failure mode each.
BATTERY_SCENES = ("thin_wall", "slot", "wedge", "pry_hook", "knife_vertex", "dense_plate", "cup", "lever")

# The bunny: the Stanford bunny as glmark2-data ships it (34,835 vertices, 69,666
# triangles, arbitrary units, Y up), decimated and scaled to 15 cm along Y.
BUNNY_INPUT = Path("/usr/share/glmark2/models/bunny.obj")
BUNNY_TARGET_FACES = 27000
# The full-resolution bunny (issue 20's third scenario): the same input, scale and
# repairs, no decimation (a target of the input's own 69,666 triangles).
BUNNY_FULL_TARGET_FACES = 69666
BUNNY_HEIGHT = 0.15  # metres
BUNNY_TOOL = "datasets_generated/gauss6_make_bunny"
# The bunny program's source, as its files record it (path in the repository, sha256): the
# checkout's, or the copy a wheel carries beside the generators.
BUNNY_SOURCE = "datasets_generated/generators/make_bunny.cpp"
# Generated on demand only (large): name -> levels of midpoint subdivision of bunny_full.
ON_DEMAND = {"bunny_x4": 1, "bunny_x16": 2}


def sha256_file(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def bunny_source_file() -> Path:
    """make_bunny.cpp: the checkout's, else the installed package's copy."""
    in_tree = paths.REPO_ROOT / BUNNY_SOURCE
    return in_tree if in_tree.exists() else Path(peg_in_hole.__file__).with_name("make_bunny.cpp")


def _write_manifest(out: Path, generator: tuple[str, str], version: str, parameters: dict, files: list[str]) -> dict:
    """MANIFEST.json of out/: generator is (its path in the repository, the sha256 of its source)."""
    manifest = {
        "generator": generator[0],
        "generator_version": version,
        "parameters": parameters,
        "source_sha256": generator[1],
        "outputs": {f: sha256_file(out / f) for f in sorted(files)},
    }
    (out / "MANIFEST.json").write_text(json.dumps(manifest, indent=2) + "\n", encoding="ascii")
    return manifest


def _generate_bunny(out: Path, target_faces: int = BUNNY_TARGET_FACES) -> dict:
    gen = peg_in_hole  # owns the OFF provenance header's format
    bunny_source = (BUNNY_SOURCE, sha256_file(bunny_source_file()))
    if not BUNNY_INPUT.exists():
        raise FileNotFoundError(f"{BUNNY_INPUT}: missing; install the Debian package glmark2-data")
    parameters = {
        "input": str(BUNNY_INPUT),
        "input_sha256": sha256_file(BUNNY_INPUT),
        "target_faces": target_faces,
        "height": BUNNY_HEIGHT,
    }
    header = gen.provenance_header(bunny_source[0], parameters, bunny_source[1])
    cmd = [str(paths.tool(BUNNY_TOOL)), str(BUNNY_INPUT), str(out / "bunny.off"),
           str(target_faces), repr(BUNNY_HEIGHT)]
    for line in header:
        cmd += ["--comment", line]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:5])} failed (exit {r.returncode}): {r.stderr.strip()}")
    return _write_manifest(out, bunny_source, gen.GENERATOR_VERSION, parameters, ["bunny.off"])


def _generate_python(out: Path, module, params_class: str) -> dict:
    """A Python generator's dataset: module.generate(out, its default parameters), the manifest."""
    params = getattr(module, params_class)()
    files = module.generate(out, params)
    return _write_manifest(out, source(module.__name__), module.GENERATOR_VERSION, params.to_json(), list(files))


def _generate_subdivided(out: Path, levels: int) -> dict:
    """bunny_full's bunny.off (beside out/, in the same datasets folder) split `levels` times."""
    full = out.parent / "bunny_full" / "bunny.off"
    if not full.exists():
        raise FileNotFoundError(f"{full}: missing; generate bunny_full first (`gauss6 datasets generate --only "
                                "bunny_full`)")
    parameters = {"input": "datasets_generated/bunny_full/bunny.off", "input_sha256": sha256_file(full),
                  "levels": levels}
    V, F = subdivide.subdivide(*subdivide.read_off(full), levels)
    generator = source(subdivide.__name__)
    subdivide.write_off(out / "bunny.off", V, F, peg_in_hole.provenance_header(generator[0], parameters, generator[1]))
    r = subprocess.run([str(paths.tool(BUNNY_TOOL)), "--check", str(out / "bunny.off")], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{out / 'bunny.off'}: the exact checks fail: {r.stderr.strip()}")
    return _write_manifest(out, generator, subdivide.GENERATOR_VERSION, parameters, ["bunny.off"])


def generate(name: str, out_dir: Path) -> dict:
    """Generates dataset `name` (one of DATASETS) into out_dir/<name>/ (its files
    and MANIFEST.json); returns the manifest. Raises ValueError for an unknown name,
    FileNotFoundError when the bunny tool is not built, RuntimeError when a generator's
    own checks fail."""
    makers = {"peg_in_hole": lambda out: _generate_python(out, peg_in_hole, "PegInHoleParams"),
              "bunny": _generate_bunny, "bunny_full": lambda out: _generate_bunny(out, BUNNY_FULL_TARGET_FACES),
              "surfaces": lambda out: _generate_python(out, surfaces, "SurfacesParams"),
              "battery": lambda out: _generate_python(out, battery, "BatteryParams"),
              **{n: (lambda out, levels=levels: _generate_subdivided(out, levels)) for n, levels in ON_DEMAND.items()}}
    if name not in makers:
        raise ValueError(f"unknown dataset {name!r}; expected one of {', '.join([*DATASETS, *ON_DEMAND])}")
    out = Path(out_dir) / name
    out.mkdir(parents=True, exist_ok=True)
    return makers[name](out)


def generate_all(out_dir: Path | None = None) -> dict[str, dict]:
    """Generates every dataset into out_dir (default: in place, datasets_generated/)."""
    root = Path(out_dir) if out_dir is not None else paths.DATASETS_DIR
    return {name: generate(name, root) for name in tqdm(DATASETS, desc="datasets", unit="dataset", disable=None)}


def check_all() -> list[str]:
    """Regenerates every dataset into a temporary directory and compares it with the
    committed one (MANIFEST.json and the files it lists). Returns one human-readable
    message per mismatch; empty when everything matches."""
    problems: list[str] = []
    with tempfile.TemporaryDirectory(prefix="gauss6-datasets-") as tmp:
        for name in tqdm(DATASETS, desc="datasets check", unit="dataset", disable=None):
            committed_dir = paths.DATASETS_DIR / name
            manifest_path = committed_dir / "MANIFEST.json"
            if not manifest_path.exists():
                problems.append(f"{name}: {manifest_path} is missing (run `gauss6 datasets generate`)")
                continue
            committed = json.loads(manifest_path.read_text())
            try:
                fresh = generate(name, Path(tmp))
            except (OSError, RuntimeError) as e:
                problems.append(f"{name}: cannot regenerate: {e}")
                continue
            for key in ("generator", "generator_version", "parameters", "source_sha256"):
                if committed.get(key) != fresh[key]:
                    problems.append(f"{name}: MANIFEST.json {key} is {committed.get(key)!r}, "
                                    f"the generator now gives {fresh[key]!r}")
            for filename in sorted(set(committed.get("outputs", {})) | set(fresh["outputs"])):
                want, got = committed.get("outputs", {}).get(filename), fresh["outputs"].get(filename)
                if want != got:
                    problems.append(f"{name}/{filename}: committed sha256 {want}, regenerated {got}")
                path = committed_dir / filename
                if want is not None and (not path.exists() or sha256_file(path) != want):
                    problems.append(f"{name}/{filename}: the committed file does not match MANIFEST.json")
    return problems
