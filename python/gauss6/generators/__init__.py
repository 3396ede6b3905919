"""The seeded generators of the datasets (METHOD.md section 7), a package of the library so that
an installed gauss6 makes the same files as the checkout: `gauss6 datasets generate` runs them
(gauss6.datasets), and datasets_generated/ holds what they wrote.

- peg_in_hole: the peg and the box with a hole (and the OFF provenance header every generated
  mesh starts with);
- surfaces: the force-shading and texture meshes, scripts and height map (reuses peg_in_hole);
- battery: the conformance battery's meshes and hand scripts (reuses peg_in_hole);
- subdivide: bunny_full split into 4 or 16 (bunny_x4, bunny_x16, on demand);
- convex_parts: CoACD convex decompositions for the engines that collide convex shapes.

The bunny itself comes from a C++ program (datasets_generated/generators/make_bunny.cpp, built
by CMake as gauss6_make_bunny; a wheel carries the program and its source).

Each generated file records the generator's source (its path in the repository) and the sha256
of that source: `source(__spec__.name)` gives both, from the module itself, so that an installed copy
records what the checkout's does.
"""
from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path


def source(module_name: str) -> tuple[str, str]:
    """(the path in the repository, python/gauss6/generators/NAME.py; the sha256 of the source
    file) of the generator module `module_name` (a generator passes its __spec__.name, which
    is its own name under `python -m` too, where __name__ is "__main__"), found
    without running it (the qp generator pins numpy's kernels when it runs)."""
    relpath = "python/" + module_name.replace(".", "/") + ".py"
    return relpath, hashlib.sha256(Path(importlib.util.find_spec(module_name).origin).read_bytes()).hexdigest()
