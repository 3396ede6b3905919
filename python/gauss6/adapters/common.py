"""What the adapters share: their config text, the scene's convex parts (CoACD, made by
gauss6.generators.convex_parts, committed or cached), mesh files for the frameworks that read
meshes from files, the quaternion conventions, and the contacts an adapter reports (at most the
contract's capacity: reported_contacts).

Convex parts are looked up by the key of the mesh and the parameters (the generator's
mesh_key): datasets_generated/convex_parts/<key>.obj (committed for the shipped scenes), then
the cache ($GAUSS6_CACHE_DIR, default ~/.cache/gauss6)/convex_parts/<key>.obj; when neither
has it, the generator makes it into the cache (minutes for a large mesh: said on stderr).
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from .. import paths
from ..engine import CONTACT_CAPACITY
from ..generators import convex_parts as generator


def parse_config(text: str, defaults: dict) -> dict:
    """`key=value` pairs (commas or spaces between) over the defaults, each value of its
    default's type; an unknown key or a bad value is an error naming it."""
    out = dict(defaults)
    for item in text.replace(",", " ").split():
        key, sep, value = item.partition("=")
        if not sep or key not in defaults:
            raise ValueError(f"config {item!r}: expected key=value with key one of {', '.join(defaults)}")
        kind = type(defaults[key])
        try:
            out[key] = kind(value) if kind is not bool else value.lower() in ("1", "true", "yes", "on")
        except ValueError:
            raise ValueError(f"config {key}={value!r}: not a {kind.__name__}") from None
        if kind is float and not np.isfinite(out[key]):
            raise ValueError(f"config {key}={value!r}: not finite")
    return out


def cache_dir() -> Path:
    return Path(os.environ.get("GAUSS6_CACHE_DIR", Path.home() / ".cache" / "gauss6"))


COMMITTED_PARTS = paths.DATASETS_DIR / "convex_parts"


def convex_parts_file(V: np.ndarray, F: np.ndarray, source: str = "") -> Path:
    """The OBJ of a mesh's convex parts (one object a part): committed, cached, or made now."""
    gen = generator
    key = gen.mesh_key(V, F, gen.ConvexPartsParams())
    for folder in (COMMITTED_PARTS, cache_dir() / "convex_parts"):
        if (folder / f"{key}.obj").exists():
            return folder / f"{key}.obj"
    print(f"gauss6: convex decomposition of {source or 'a mesh'} ({len(F)} faces) with CoACD, "
          f"into {cache_dir() / 'convex_parts'} (once; minutes for a large mesh)", file=sys.stderr)
    return gen.generate(V, F, cache_dir() / "convex_parts", source=source)


def convex_parts(V: np.ndarray, F: np.ndarray, source: str = "") -> list[tuple[np.ndarray, np.ndarray]]:
    """A mesh's convex parts [(vertices, faces)], in the mesh's frame."""
    return generator.read_obj(convex_parts_file(V, F, source))


def mesh_file(V: np.ndarray, F: np.ndarray, name: str) -> Path:
    """The mesh as a Wavefront OBJ in the cache (for frameworks that read meshes from files),
    named by its content."""
    import hashlib

    h = hashlib.sha256(np.ascontiguousarray(V, np.float64).tobytes() + np.ascontiguousarray(F, np.int32).tobytes())
    path = cache_dir() / "meshes" / f"{name}-{h.hexdigest()[:16]}.obj"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".tmp{os.getpid()}")
        generator.write_obj(tmp, [(np.asarray(V, float), np.asarray(F, np.int64))], [f"{name}"])
        tmp.replace(path)
    return path


def part_files(V: np.ndarray, F: np.ndarray, name: str) -> list[Path]:
    """One OBJ a convex part (for frameworks whose convex shape is one file)."""
    return [mesh_file(v, f, f"{name}-part{i}") for i, (v, f) in enumerate(convex_parts(V, F, name))]


def wxyz_to_xyzw(q) -> list[float]:
    return [float(q[1]), float(q[2]), float(q[3]), float(q[0])]


def xyzw_to_wxyz(q) -> np.ndarray:
    return np.array([q[3], q[0], q[1], q[2]], float)


def unit(q) -> np.ndarray:
    q = np.asarray(q, float)
    return q / np.linalg.norm(q)


def reported_contacts(rows) -> np.ndarray:
    """A framework's contacts as the contract takes them: (k, 7) rows of point (3), normal (3),
    separation, k <= CONTACT_CAPACITY (docs/engine-contract.md; the C ABI's buffer). A framework
    may find more (Rapier: 507 on the bunnies, 46,883 on the dense plate, one manifold point per
    triangle): then the CONTACT_CAPACITY deepest are reported (smallest separation first, ties in
    the framework's order), the contacts that carry the framework's force; the contacts are what
    the viewer draws, the oracle judges the engine by its own contact generation."""
    contacts = np.asarray(rows, float).reshape(-1, 7)
    if len(contacts) <= CONTACT_CAPACITY:
        return contacts
    return contacts[np.sort(np.argsort(contacts[:, 6], kind="stable")[:CONTACT_CAPACITY])]
