"""Adapters that put engines nobody here wrote behind the engine contract (gauss6.engine):
MuJoCo (mujoco_engine), PyBullet (pybullet_engine), Drake (drake_engine), DART (dart_engine),
Rapier (rapier_engine), each from its
pinned wheel, and what they share (geometry: convex parts and mesh files; config text;
the coupling's pose algebra). docs/engine-adapters.md states what each adapter does and how
each parameter was chosen.

    gauss6 validate --engine python:gauss6.adapters:mujoco --config "weld_timeconst=0.005" ...

The factories take the config text (`key=value` pairs, separated by commas or spaces) and
import their framework only when called, so gauss6 works without any of them installed.
"""
from __future__ import annotations


def mujoco(config: str = ""):
    from .mujoco_engine import MuJoCoEngine

    return MuJoCoEngine(config)


def pybullet(config: str = ""):
    from .pybullet_engine import PyBulletEngine

    return PyBulletEngine(config)


def drake(config: str = ""):
    from .drake_engine import DrakeEngine

    return DrakeEngine(config)


def dart(config: str = ""):
    from .dart_engine import DartEngine

    return DartEngine(config)


def rapier(config: str = ""):
    from .rapier_engine import RapierEngine

    return RapierEngine(config)


FACTORIES = {"mujoco": mujoco, "pybullet": pybullet, "drake": drake, "dart": dart, "rapier": rapier}

# The module each framework is imported as (to tell whether it is installed).
MODULES = {"mujoco": "mujoco", "pybullet": "pybullet", "drake": "pydrake", "dart": "dartpy", "rapier": "rapier3d"}


def available(name: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(MODULES[name]) is not None
