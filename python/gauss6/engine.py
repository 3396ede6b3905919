"""The engine contract from Python (docs/engine-contract.md): the protocol an engine under test
implements, the scene it gets, what a step returns, and the loader of C ABI engines
(gauss6/engine.h) that wraps them into the same protocol.

    scene = EngineScene.from_scene_file("datasets_generated/scenes/peg_in_hole.toml")
    engine = load_engine("build/engine/libgauss6_engine.so")   # or any object with reset/step
    engine.reset(scene)
    out = engine.step(t, xh_p, xh_q)                          # an EngineStep

Units and frames: the scene's (metres, kilograms, seconds in the shipped scenes), world frame;
poses are of G, q = (w, x, y, z); wrenches are (force N, torque N m about G), world frame.

A Python engine (an adapter around another framework's bindings) is any object with
`name`, `reset(scene: EngineScene)` and `step(t, xh_p, xh_q) -> EngineStep`; the driver
(gauss6.validate) serves both kinds alike.
"""
from __future__ import annotations

import ctypes
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from . import paths

ABI_VERSION = 1
ENTRY = "gauss6_engine_get"
CONTACT_CAPACITY = 256  # contacts the driver takes from a C engine per step


@dataclass
class EngineBody:
    name: str
    V: np.ndarray            # (n, 3) vertices in the body frame
    F: np.ndarray            # (m, 3) int32 faces, outward
    p: np.ndarray = field(default_factory=lambda: np.zeros(3))              # X_WB position
    q: np.ndarray = field(default_factory=lambda: np.array([1.0, 0, 0, 0]))  # X_WB orientation (w, x, y, z)


@dataclass
class EngineScene:
    """What an engine gets at reset: the scene's true meshes, poses, mass properties and units."""
    name: str
    path: str                # the gauss6 scene file ("" when built otherwise)
    obstacles: list          # EngineBody, static
    tool: EngineBody         # the held object: mesh in its body frame (origin at G), its initial pose
    mass: float              # kg
    inertia_G_B: np.ndarray  # (3, 3) kg m^2 about G, body frame
    delta: float             # the scene's separation (length units)
    rate_hz: float
    max_force: float
    max_torque: float
    ks: float
    kh: float
    length_unit_m: float = 1.0

    @classmethod
    def from_scene_file(cls, path) -> "EngineScene":
        """The scene of a gauss6 scene file (obstacles in the world frame, with identity poses)."""
        from ._gauss6 import runtime

        g = runtime.scene_geometry(str(path))
        from ._gauss6 import load_scene

        settings = runtime.effective_settings(load_scene(str(path)))
        obstacles = [EngineBody(name, np.asarray(V, float), np.asarray(F, np.int32)) for name, V, F in g["obstacles"]]
        tool = EngineBody("tool", np.asarray(g["god_V"], float), np.asarray(g["god_F"], np.int32),
                          np.asarray(g["p0"], float), np.asarray(g["q0"], float))
        return cls(name=g["name"], path=str(Path(path).resolve()), obstacles=obstacles, tool=tool,
                   mass=float(g["mass"]), inertia_G_B=np.asarray(g["inertia_G_B"], float), delta=float(g["delta"]),
                   rate_hz=float(g["rate_hz"]), max_force=float(g["max_force"]),
                   max_torque=float(settings["device"]["max_torque"]), ks=float(g["ks"]), kh=float(g["kh"]))


@dataclass
class EngineStep:
    """One step's answer: the displayed pose, the wrench, and what the engine may add."""
    xs_p: np.ndarray                      # (3,) displayed position of G
    xs_q: np.ndarray                      # (4,) displayed orientation (w, x, y, z)
    wrench: np.ndarray                    # (6,) force N, torque N m about G, world frame
    contacts: np.ndarray | None = None    # (k, 7): point (3), normal (3), separation; None: not reported
    step_seconds: float | None = None     # the engine's own time for the step; None: the driver's timing


@runtime_checkable
class Engine(Protocol):
    name: str

    def reset(self, scene: EngineScene) -> None: ...

    def step(self, t: float, xh_p: np.ndarray, xh_q: np.ndarray) -> EngineStep: ...


class EngineError(RuntimeError):
    """An engine that cannot be loaded, or a call that failed (the message names the engine)."""


# ---------------------------------------------------------------------------------------------
# The C ABI, mirrored with ctypes (gauss6/engine.h, version 1).

class _Pose(ctypes.Structure):
    _fields_ = [("p", ctypes.c_double * 3), ("q", ctypes.c_double * 4)]


class _Mesh(ctypes.Structure):
    _fields_ = [("vertices", ctypes.POINTER(ctypes.c_double)), ("num_vertices", ctypes.c_int32),
                ("faces", ctypes.POINTER(ctypes.c_int32)), ("num_faces", ctypes.c_int32)]


class _Body(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("mesh", _Mesh), ("X_WB", _Pose)]


class _SceneDesc(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("name", ctypes.c_char_p), ("scene_path", ctypes.c_char_p),
                ("length_unit_m", ctypes.c_double), ("num_obstacles", ctypes.c_int32),
                ("obstacles", ctypes.POINTER(_Body)), ("tool", _Body), ("mass", ctypes.c_double),
                ("inertia_G_B", ctypes.c_double * 9), ("delta", ctypes.c_double), ("rate_hz", ctypes.c_double),
                ("max_force", ctypes.c_double), ("max_torque", ctypes.c_double), ("ks", ctypes.c_double),
                ("kh", ctypes.c_double)]


class _Contact(ctypes.Structure):
    _fields_ = [("point", ctypes.c_double * 3), ("normal", ctypes.c_double * 3), ("separation", ctypes.c_double)]


class _StepOut(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("X_WS", _Pose), ("wrench", ctypes.c_double * 6),
                ("num_contacts", ctypes.c_int32), ("contact_capacity", ctypes.c_int32),
                ("contacts", ctypes.POINTER(_Contact)), ("step_seconds", ctypes.c_double)]


_VOIDP = ctypes.c_void_p
_CREATE = ctypes.CFUNCTYPE(_VOIDP, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t)
_RESET = ctypes.CFUNCTYPE(ctypes.c_int, _VOIDP, ctypes.POINTER(_SceneDesc), ctypes.c_char_p, ctypes.c_size_t)
_STEP = ctypes.CFUNCTYPE(ctypes.c_int, _VOIDP, ctypes.c_double, ctypes.POINTER(_Pose), ctypes.POINTER(_StepOut))
_LAST_ERROR = ctypes.CFUNCTYPE(ctypes.c_char_p, _VOIDP)
_DESTROY = ctypes.CFUNCTYPE(None, _VOIDP)


class _Table(ctypes.Structure):
    _fields_ = [("abi_version", ctypes.c_uint32), ("table_size", ctypes.c_uint32),
                ("scene_desc_size", ctypes.c_uint32), ("step_out_size", ctypes.c_uint32), ("name", ctypes.c_char_p),
                ("create", _CREATE), ("reset", _RESET), ("step", _STEP), ("last_error", _LAST_ERROR),
                ("destroy", _DESTROY)]


def _body(b: EngineBody, keep: list) -> _Body:
    V = np.ascontiguousarray(b.V, dtype=np.float64)
    F = np.ascontiguousarray(b.F, dtype=np.int32)
    keep += [V, F]
    pose = _Pose((ctypes.c_double * 3)(*map(float, b.p)), (ctypes.c_double * 4)(*map(float, b.q)))
    mesh = _Mesh(V.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(V),
                 F.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)), len(F))
    return _Body(b.name.encode(), mesh, pose)


class CEngine:
    """An engine loaded from a shared library by path (dlopen), through the version 1 table."""

    def __init__(self, path, config: str = ""):
        self.path = str(path)
        try:
            self._lib = ctypes.CDLL(self.path, mode=ctypes.RTLD_LOCAL)
            get = getattr(self._lib, ENTRY)
        except (OSError, AttributeError) as e:
            raise EngineError(f"{self.path}: not an engine library ({e})") from None
        get.restype = ctypes.c_void_p
        get.argtypes = [ctypes.c_uint32]
        address = get(ABI_VERSION)
        if not address:
            raise EngineError(f"{self.path}: does not speak the engine ABI version {ABI_VERSION}")
        self._table = _Table.from_address(address)
        t = self._table
        sizes = {"table": (t.table_size, ctypes.sizeof(_Table)),
                 "scene description": (t.scene_desc_size, ctypes.sizeof(_SceneDesc)),
                 "step output": (t.step_out_size, ctypes.sizeof(_StepOut))}
        for what, (theirs, ours) in sizes.items():
            if theirs != ours:
                raise EngineError(f"{self.path}: {what} is {theirs} bytes, gauss6's is {ours}: a different ABI")
        self.name = t.name.decode()
        error = ctypes.create_string_buffer(1024)
        self._engine = t.create(config.encode(), error, len(error))
        if not self._engine:
            raise EngineError(f"{self.path}: create failed: {error.value.decode()}")
        self._contacts = (_Contact * CONTACT_CAPACITY)()
        self._out = _StepOut()
        self._pose = _Pose()

    def reset(self, scene: EngineScene) -> None:
        keep: list = []
        obstacles = (_Body * max(len(scene.obstacles), 1))(*[_body(b, keep) for b in scene.obstacles])
        desc = _SceneDesc(struct_size=ctypes.sizeof(_SceneDesc), name=scene.name.encode(),
                          scene_path=scene.path.encode(), length_unit_m=scene.length_unit_m,
                          num_obstacles=len(scene.obstacles), obstacles=obstacles, tool=_body(scene.tool, keep),
                          mass=scene.mass, inertia_G_B=(ctypes.c_double * 9)(*np.ravel(scene.inertia_G_B)),
                          delta=scene.delta, rate_hz=scene.rate_hz, max_force=scene.max_force,
                          max_torque=scene.max_torque, ks=scene.ks, kh=scene.kh)
        error = ctypes.create_string_buffer(1024)
        if self._table.reset(self._engine, ctypes.byref(desc), error, len(error)) != 0:
            raise EngineError(f"{self.name}: reset failed: {error.value.decode()}")

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        pose, out = self._pose, self._out
        pose.p[0], pose.p[1], pose.p[2] = float(xh_p[0]), float(xh_p[1]), float(xh_p[2])
        pose.q[0], pose.q[1], pose.q[2], pose.q[3] = (float(v) for v in xh_q)
        out.struct_size = ctypes.sizeof(_StepOut)
        out.contact_capacity = CONTACT_CAPACITY
        out.contacts = self._contacts
        out.num_contacts = -1
        out.step_seconds = -1.0
        start = time.perf_counter()
        status = self._table.step(self._engine, float(t), ctypes.byref(pose), ctypes.byref(out))
        seconds = time.perf_counter() - start
        if status != 0:
            raise EngineError(f"{self.name}: step at t = {t}: {self._table.last_error(self._engine).decode()}")
        contacts = None
        if out.num_contacts >= 0:  # _Contact is 7 doubles: point, normal, separation
            n = min(out.num_contacts, CONTACT_CAPACITY)
            contacts = np.frombuffer(self._contacts, dtype=np.float64, count=7 * n).reshape(n, 7).copy()
        return EngineStep(np.array(out.X_WS.p[:]), np.array(out.X_WS.q[:]), np.array(out.wrench[:]), contacts,
                          out.step_seconds if out.step_seconds >= 0 else seconds)

    def close(self) -> None:
        if getattr(self, "_engine", None):
            self._table.destroy(self._engine)
            self._engine = None

    def __del__(self):
        self.close()


# The engines built with gauss6 (engine/CMakeLists.txt), by short name.
BUILT_ENGINES = {
    "gauss6": "engine/libgauss6_engine.so",
    "box-penalty": "engine/libgauss6_box_penalty_engine.so",
    "fault": "engine/libgauss6_fault_engine.so",
}


# The same libraries inside an installed wheel (python/CMakeLists.txt: gauss6 and box-penalty).
PACKAGED_ENGINES = Path(__file__).resolve().parent / "engines"


def engine_library(name_or_path: str) -> Path:
    """The library of a built engine's short name (gauss6, box-penalty, fault): the wheel's copy
    when the package has one, else the build tree's; or a path as given."""
    if name_or_path in BUILT_ENGINES:
        packaged = PACKAGED_ENGINES / Path(BUILT_ENGINES[name_or_path]).name
        return packaged if packaged.exists() else paths.tool(BUILT_ENGINES[name_or_path])
    path = Path(name_or_path)
    if not path.exists():
        raise EngineError(f"{path}: no such engine library (or one of {', '.join(BUILT_ENGINES)})")
    return path


def load_engine(name_or_path: str, config: str = "") -> CEngine:
    """A C ABI engine by short name or library path, with its config text."""
    return CEngine(engine_library(name_or_path), config)
