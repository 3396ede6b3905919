"""gauss6: six-DoF god-object haptic rendering of rigid bodies (Ortega, Redon, Coquillart 2007).

The C++ core is the extension module gauss6._gauss6; this package adds the
`gauss6` command (gauss6.cli), the dataset generators, the cross-checks and plots.
"""
from __future__ import annotations

from . import _gauss6  # noqa: F401  (the C++ core; built by CMake)
from ._gauss6 import (  # noqa: F401
    LoadError,
    MeshFileError,
    ProjectionSettings,
    Projector,
    SceneError,
    coupling_force,
    mass_properties,
    project,
    read_mesh,
    validate_mesh,
)

from ._version import __version__  # noqa: F401  (written by CMake from project())


def defaults() -> dict:
    """Every documented default, read from the C++ structs that hold it:
    {"contact", "surface", "device", "ccd", "projection"} (contact.offset_eps_per_delta:
    a scene's offset_eps defaults to that multiple of its delta)."""
    return {**_gauss6.defaults(), "projection": _gauss6.projection_defaults()}
