"""The generated datasets (METHOD.md section 7): making them and checking them.

Each dataset lives in datasets_generated/<name>/ with a MANIFEST.json:

    {"generator": path of the generator source, relative to the repository,
     "generator_version": "1",
     "parameters": {...},
     "source_sha256": sha256 of the generator source,
     "outputs": {filename: sha256}}

and every OFF file it holds starts with the same fields as '#' comment lines.
Generation is deterministic: the same parameters give byte-identical files, so
`check_all()` can regenerate each dataset and compare checksums.

- peg_in_hole: peg.off (288 triangles) and box_with_hole.off (280 triangles),
  from datasets_generated/generators/peg_in_hole.py (Python, numpy).
- bunny: bunny.off (about 27,000 triangles, 15 cm tall, metres), from
  glmark2-data's bunny.obj by the CGAL program gauss6_make_bunny
  (datasets_generated/generators/make_bunny.cpp, built by CMake).
- surfaces: faceted_cylinder.off, slab.off, probe.off and the hand scripts of the
  Figure 8 and 9 analogues (cylinder_slide.json, texture_slow.json, texture_fast.json), the
  height map bumps.png with its bump list bumps.json, from
  datasets_generated/generators/surfaces.py (Python, numpy, Pillow; reuses the peg generator).
- battery: the conformance battery's meshes and hand scripts (docs/conformance-battery.md), one
  scene each in datasets_generated/scenes/ (BATTERY_SCENES), from
  datasets_generated/generators/battery.py (Python, numpy; reuses the peg generator).
- bunny_x4, bunny_x16 (ON_DEMAND: not in DATASETS, not committed, tens of MB): bunny_full's
  bunny.off with each triangle split into 4 or 16 (the same surface), from
  datasets_generated/generators/subdivide.py; `gauss6 datasets generate --only NAME`.
"""
from __future__ import annotations

import hashlib
import importlib.util
import json
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType

from tqdm import tqdm

from . import paths

DATASETS = ("peg_in_hole", "bunny", "bunny_full", "surfaces", "battery")
GENERATORS_DIR = paths.DATASETS_DIR / "generators"
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
# Generated on demand only (large): name -> levels of midpoint subdivision of bunny_full.
ON_DEMAND = {"bunny_x4": 1, "bunny_x16": 2}


def sha256_file(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def peg_in_hole_generator() -> ModuleType:
    """The peg-in-a-hole generator module (datasets_generated/generators/peg_in_hole.py)."""
    name, path = "gauss6_generators_peg_in_hole", GENERATORS_DIR / "peg_in_hole.py"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"{path}: cannot load the generator")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up there
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def _relative(path: Path) -> str:
    return path.resolve().relative_to(paths.REPO_ROOT).as_posix()


def _write_manifest(out: Path, generator: Path, version: str, parameters: dict, files: list[str]) -> dict:
    manifest = {
        "generator": _relative(generator),
        "generator_version": version,
        "parameters": parameters,
        "source_sha256": sha256_file(generator),
        "outputs": {f: sha256_file(out / f) for f in sorted(files)},
    }
    (out / "MANIFEST.json").write_text(json.dumps(manifest, indent=2) + "\n", encoding="ascii")
    return manifest


def _generate_peg_in_hole(out: Path) -> dict:
    gen = peg_in_hole_generator()
    params = gen.PegInHoleParams()
    files = gen.generate(out, params)
    return _write_manifest(out, GENERATORS_DIR / "peg_in_hole.py", gen.GENERATOR_VERSION, params.to_json(), list(files))


def _generate_bunny(out: Path, target_faces: int = BUNNY_TARGET_FACES) -> dict:
    gen = peg_in_hole_generator()  # owns the OFF provenance header's format
    source = GENERATORS_DIR / "make_bunny.cpp"
    if not BUNNY_INPUT.exists():
        raise FileNotFoundError(f"{BUNNY_INPUT}: missing; install the Debian package glmark2-data")
    parameters = {
        "input": str(BUNNY_INPUT),
        "input_sha256": sha256_file(BUNNY_INPUT),
        "target_faces": target_faces,
        "height": BUNNY_HEIGHT,
    }
    header = gen.provenance_header(_relative(source), parameters, sha256_file(source))
    cmd = [str(paths.tool(BUNNY_TOOL)), str(BUNNY_INPUT), str(out / "bunny.off"),
           str(target_faces), repr(BUNNY_HEIGHT)]
    for line in header:
        cmd += ["--comment", line]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:5])} failed (exit {r.returncode}): {r.stderr.strip()}")
    return _write_manifest(out, source, gen.GENERATOR_VERSION, parameters, ["bunny.off"])


def _generator_module(stem: str) -> ModuleType:
    """A Python generator that reuses the peg generator (datasets_generated/generators/STEM.py)."""
    peg_in_hole_generator()  # loaded first: the others reuse its meshes and header
    source = GENERATORS_DIR / f"{stem}.py"
    name = f"gauss6_generators_{stem}"
    module = sys.modules.get(name)
    if module is None:
        spec = importlib.util.spec_from_file_location(name, source)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module  # dataclasses look their module up there
        spec.loader.exec_module(module)
    return module


def _generate_python(out: Path, stem: str, params_class: str) -> dict:
    module = _generator_module(stem)
    params = getattr(module, params_class)()
    files = module.generate(out, params)
    return _write_manifest(out, GENERATORS_DIR / f"{stem}.py", module.GENERATOR_VERSION, params.to_json(), list(files))


def _generate_subdivided(out: Path, levels: int) -> dict:
    gen = peg_in_hole_generator()  # owns the OFF provenance header's format
    source = GENERATORS_DIR / "subdivide.py"
    module = _generator_module("subdivide")
    full = paths.DATASETS_DIR / "bunny_full" / "bunny.off"
    parameters = {"input": _relative(full), "input_sha256": sha256_file(full), "levels": levels}
    V, F = module.subdivide(*module.read_off(full), levels)
    module.write_off(out / "bunny.off", V, F, gen.provenance_header(_relative(source), parameters, sha256_file(source)))
    r = subprocess.run([str(paths.tool(BUNNY_TOOL)), "--check", str(out / "bunny.off")], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{out / 'bunny.off'}: the exact checks fail: {r.stderr.strip()}")
    return _write_manifest(out, source, module.GENERATOR_VERSION, parameters, ["bunny.off"])


def generate(name: str, out_dir: Path) -> dict:
    """Generates dataset `name` (one of DATASETS) into out_dir/<name>/ (its files
    and MANIFEST.json); returns the manifest. Raises ValueError for an unknown name,
    FileNotFoundError when the bunny tool is not built, RuntimeError when a generator's
    own checks fail."""
    makers = {"peg_in_hole": _generate_peg_in_hole, "bunny": _generate_bunny,
              "bunny_full": lambda out: _generate_bunny(out, BUNNY_FULL_TARGET_FACES), "surfaces": lambda out: _generate_python(out, "surfaces", "SurfacesParams"),
              "battery": lambda out: _generate_python(out, "battery", "BatteryParams"),
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
