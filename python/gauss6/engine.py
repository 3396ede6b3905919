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
`name`, `reset(scene: EngineScene)` and `step(t, xh_p, xh_q) -> EngineStep`, and optionally
`declarations()` (what it renders on purpose); the driver (gauss6.validate) serves both kinds
alike, each in a child process of its own (gauss6.engine_host). `make_engine` makes either from
a spec; `check_step` refuses a step's output that cannot be judged (EngineFailure "abi").
"""
from __future__ import annotations

import ctypes
import importlib
import importlib.util
import math
import mmap
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from . import paths

ABI_VERSION = 1          # gauss6_engine_v1
ABI_VERSION_2 = 2        # gauss6_engine_v2: version 1 and `declare`
ENTRY = "gauss6_engine_get"
CONTACT_CAPACITY = 256   # contacts an engine may report per step (the C buffer; the child's shared memory)
CANARY = 64              # bytes of a known pattern before and after each buffer a C engine writes into
POSE_RANGE = 1e3         # a displayed position farther from the scene's centre than this many scene radii is refused
STEP_SECONDS_UNSET = -1.0  # what the caller puts in step_seconds: left so, the engine reports none

# The kinds of an engine's failure (docs/engine-contract.md, "Isolation").
FAILURE_KINDS = ("signal", "exit", "hang", "exception", "abi")


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
    step_seconds: float | None = None     # the engine's own time for the step (s); None: not reported


@runtime_checkable
class Engine(Protocol):
    name: str

    def reset(self, scene: EngineScene) -> None: ...

    def step(self, t: float, xh_p: np.ndarray, xh_q: np.ndarray) -> EngineStep: ...


class EngineError(RuntimeError):
    """An engine that cannot be loaded, or a call that failed (the message names the engine)."""


class EngineFailure(EngineError):
    """The engine under test failed: kind one of FAILURE_KINDS, detail what happened and where."""

    def __init__(self, kind: str, detail: str):
        assert kind in FAILURE_KINDS, kind
        super().__init__(f"{kind}: {detail}")
        self.kind, self.detail = kind, detail

    def to_json(self, tick: int) -> dict:
        """The trace's extra["engine_failure"]: tick is the last good tick (-1: none ran)."""
        return {"kind": self.kind, "detail": self.detail, "tick": int(tick)}


def check_declarations(d, who: str) -> dict:
    """An engine's declarations, checked: {"friction": {"mu": float >= 0}, "latency_ticks": int >= 0,
    "skin": float >= 0 (length units)}, each optional; anything else is an "abi" failure naming it."""
    if d is None:
        return {}
    if not isinstance(d, dict):
        raise EngineFailure("abi", f"{who}: declarations() returned {type(d).__name__}, not a dict")
    unknown = set(d) - {"friction", "latency_ticks", "skin"}
    if unknown:
        raise EngineFailure("abi", f"{who}: unknown declarations {sorted(unknown)} (friction, latency_ticks, skin)")
    out: dict = {}

    def number(value, what, kind=float):
        ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
        if not ok or not math.isfinite(value) or value < 0 or (kind is int and value != int(value)):
            raise EngineFailure("abi", f"{who}: declared {what} = {value!r}: not a finite {kind.__name__} >= 0")
        return kind(value)
    if "friction" in d:
        f = d["friction"]
        if not isinstance(f, dict) or set(f) != {"mu"}:
            raise EngineFailure("abi", f"{who}: declared friction = {f!r}: expected {{'mu': float}}")
        out["friction"] = {"mu": number(f["mu"], "friction mu")}
    if "latency_ticks" in d:
        out["latency_ticks"] = number(d["latency_ticks"], "latency_ticks", int)
    if "skin" in d:
        out["skin"] = number(d["skin"], "skin")
    return out


def engine_declarations(engine) -> dict:
    """What an engine declares (its optional declarations()), checked."""
    fn = getattr(engine, "declarations", None)
    return check_declarations(fn() if fn is not None else None, getattr(engine, "name", type(engine).__name__))


class StepCheck:
    """Refuses a step's output that cannot be judged, as an "abi" failure: a displayed pose that
    is not finite, farther than POSE_RANGE scene radii from the scene's centre, or a zero
    quaternion; a reported step time that is NaN or negative; contacts not of shape (k, 7) or
    more than CONTACT_CAPACITY. (A non-finite or over-limit wrench is judged by the oracle.)"""

    def __init__(self, scene: EngineScene):
        points = [np.asarray(b.V, float) @ _rotation(b.q).T + np.asarray(b.p, float)
                  for b in [*scene.obstacles, scene.tool] if len(b.V)]
        allp = np.concatenate(points) if points else np.zeros((1, 3))
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        self.centre = ((lo + hi) / 2).tolist()
        self.limit = POSE_RANGE * max(float(np.linalg.norm(hi - lo)) / 2, scene.delta, 1e-300)

    def __call__(self, step: EngineStep, t: float) -> None:
        # Plain floats, not numpy reductions: this runs every tick.
        p, q = np.asarray(step.xs_p, float), np.asarray(step.xs_q, float)
        if p.shape != (3,) or q.shape != (4,) or np.shape(step.wrench) != (6,):
            raise EngineFailure("abi", f"step at t = {t!r}: pose or wrench of the wrong shape ({p.shape}, "
                                       f"{q.shape}, {np.shape(step.wrench)}; expected (3,), (4,), (6,))")
        pl, ql = p.tolist(), q.tolist()
        if not all(map(math.isfinite, pl + ql)):
            raise EngineFailure("abi", f"step at t = {t!r}: displayed pose not finite (p = {pl}, q = {ql})")
        c = self.centre
        if math.hypot(pl[0] - c[0], pl[1] - c[1], pl[2] - c[2]) > self.limit:
            raise EngineFailure("abi", f"step at t = {t!r}: displayed position {pl} is beyond {POSE_RANGE:g} scene "
                                       f"radii of the scene ({self.limit:g} length units from its centre)")
        if not any(ql):
            raise EngineFailure("abi", f"step at t = {t!r}: displayed quaternion is zero")
        s = step.step_seconds
        if s is not None and not (isinstance(s, (int, float, np.floating)) and s >= 0):
            raise EngineFailure("abi", f"step at t = {t!r}: reported step time {s!r} s (NaN or negative; "
                                       f"not reporting one is allowed)")
        if step.contacts is not None:
            shape = np.shape(step.contacts)
            if len(shape) != 2 or shape[1] != 7 or shape[0] > CONTACT_CAPACITY:
                raise EngineFailure("abi", f"step at t = {t!r}: contacts of shape {shape} (expected (k, 7), "
                                           f"k <= {CONTACT_CAPACITY})")


def _rotation(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


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


class _Declarations(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("flags", ctypes.c_uint32), ("friction_mu", ctypes.c_double),
                ("latency_ticks", ctypes.c_int32), ("skin", ctypes.c_double)]


DECLARE_FRICTION, DECLARE_LATENCY, DECLARE_SKIN = 1, 2, 4  # GAUSS6_DECLARE_*
_DECLARE = ctypes.CFUNCTYPE(ctypes.c_int, _VOIDP, ctypes.POINTER(_Declarations))


class _TableV2(ctypes.Structure):
    _fields_ = [("v1", _Table), ("declare", _DECLARE)]


_TABLES = {ABI_VERSION_2: _TableV2, ABI_VERSION: _Table}  # asked for in this order


def _mapped(address: int, size: int, permission: str) -> bool:
    """Whether [address, address + size) lies in one mapping of this process with `permission`
    ("r" or "x"), by /proc/self/maps: what a pointer from an engine may be checked for before use."""
    with open("/proc/self/maps") as f:
        for line in f:
            span, perms = line.split()[:2]
            lo, hi = (int(x, 16) for x in span.split("-"))
            if lo <= address and address + size <= hi:
                return permission in perms
    return False


_CANARY_BYTES = bytes((0xA5 ^ i) & 0xFF for i in range(CANARY))
_libc = ctypes.CDLL(None, use_errno=True)


class _Guarded:
    """A ctypes object alone in an anonymous mapping, CANARY bytes of a pattern before and after
    it and a page without access after those: what a C engine writes into, so that a write
    past it either changes a canary (`overrun` names it) or stops the process at the guard."""

    def __init__(self, ctype):
        size, page = ctypes.sizeof(ctype), mmap.PAGESIZE
        body = -(-(size + 2 * CANARY) // page) * page
        self._map = mmap.mmap(-1, body + page)
        base = ctypes.addressof(ctypes.c_char.from_buffer(self._map))
        if _libc.mprotect(ctypes.c_void_p(base + body), ctypes.c_size_t(page), 0) != 0:  # PROT_NONE
            raise OSError(ctypes.get_errno(), "mprotect of a guard page")
        self._at = body - CANARY - size
        self._size = size
        self.obj = ctype.from_buffer(self._map, self._at)
        self._map[self._at - CANARY:self._at] = _CANARY_BYTES
        self._map[self._at + size:self._at + size + CANARY] = _CANARY_BYTES

    def overrun(self) -> str | None:
        """"before" or "after" when that canary was overwritten, else None."""
        if self._map[self._at + self._size:self._at + self._size + CANARY] != _CANARY_BYTES:
            return "after"
        if self._map[self._at - CANARY:self._at] != _CANARY_BYTES:
            return "before"
        return None


def _body(b: EngineBody, keep: list) -> _Body:
    V = np.ascontiguousarray(b.V, dtype=np.float64)
    F = np.ascontiguousarray(b.F, dtype=np.int32)
    keep += [V, F]
    pose = _Pose((ctypes.c_double * 3)(*map(float, b.p)), (ctypes.c_double * 4)(*map(float, b.q)))
    mesh = _Mesh(V.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(V),
                 F.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)), len(F))
    return _Body(b.name.encode(), mesh, pose)


def _address(fn) -> int:
    return ctypes.cast(fn, ctypes.c_void_p).value or 0


class CEngine:
    """An engine loaded from a shared library by path (dlopen), through its version 2 table, or
    its version 1 table when it has no version 2. What can be checked before a call is
    (EngineFailure "abi"): the entry point is code, the table is readable, speaks the version
    asked for with gauss6's struct sizes, and its functions are code; the step's output and
    contact buffers are guarded (_Guarded) and checked after each step. A crash inside a call
    is the child process's to report (gauss6.engine_host)."""

    def __init__(self, path, config: str = ""):
        self.path = str(path)
        try:
            self._lib = ctypes.CDLL(self.path, mode=ctypes.RTLD_LOCAL)
            get = getattr(self._lib, ENTRY)
        except (OSError, AttributeError) as e:
            raise EngineFailure("abi", f"{self.path}: not an engine library ({e})") from None
        if not _mapped(_address(get), 1, "x"):
            raise EngineFailure("abi", f"{self.path}: its {ENTRY} is not code (a data symbol?)")
        get.restype = ctypes.c_void_p
        get.argtypes = [ctypes.c_uint32]
        for version, table_type in _TABLES.items():
            address = get(version)
            if address:
                break
        else:
            raise EngineFailure("abi", f"{self.path}: does not speak the engine ABI version {ABI_VERSION_2} "
                                       f"or {ABI_VERSION} ({ENTRY} returned NULL for both)")
        if not _mapped(address, ctypes.sizeof(_Table), "r"):
            raise EngineFailure("abi", f"{self.path}: the table {ENTRY}({version}) returned is not readable memory")
        head = _Table.from_address(address)
        if head.abi_version != version:
            raise EngineFailure("abi", f"{self.path}: asked for version {version}, {ENTRY} returned a table of "
                                       f"version {head.abi_version}")
        sizes = {"table": (head.table_size, ctypes.sizeof(table_type)),
                 "scene description": (head.scene_desc_size, ctypes.sizeof(_SceneDesc)),
                 "step output": (head.step_out_size, ctypes.sizeof(_StepOut))}
        for what, (theirs, ours) in sizes.items():
            if theirs != ours:
                raise EngineFailure("abi", f"{self.path}: {what} is {theirs} bytes, gauss6's is {ours}: a "
                                           f"different ABI")
        if not _mapped(address, ctypes.sizeof(table_type), "r"):
            raise EngineFailure("abi", f"{self.path}: its table is not readable memory")
        self.abi_version = version
        full = table_type.from_address(address)
        self._table = full if version == ABI_VERSION else full.v1
        functions = {n: getattr(self._table, n) for n in ("create", "reset", "step", "last_error", "destroy")}
        self._declare = full.declare if version == ABI_VERSION_2 and _address(full.declare) else None
        if self._declare is not None:
            functions["declare"] = self._declare
        for n, fn in functions.items():
            if not _mapped(_address(fn), 1, "x"):
                raise EngineFailure("abi", f"{self.path}: the table's {n} is "
                                           f"{'NULL' if not _address(fn) else 'not code'}")
        name_address = ctypes.cast(self._table.name, ctypes.c_void_p).value if self._table.name else 0
        if not name_address or not _mapped(name_address, 1, "r"):
            raise EngineFailure("abi", f"{self.path}: the table's name is not a string")
        self.name = self._table.name.decode(errors="replace")
        error = ctypes.create_string_buffer(1024)
        self._engine = self._table.create(config.encode(), error, len(error))
        if not self._engine:
            raise EngineFailure("exception", f"{self.path}: create failed: {error.value.decode(errors='replace')}")
        self._contacts = _Guarded(_Contact * CONTACT_CAPACITY)
        self._out = _Guarded(_StepOut)
        self._pose = _Pose()
        # numpy views of the handle's pose and of the output's pose and wrench (13 doubles from X_WS on)
        self._pose_view = np.frombuffer(self._pose, np.float64)
        self._answer_view = np.frombuffer(self._out.obj, np.float64, 13, _StepOut.X_WS.offset)
        self._contacts_address = ctypes.cast(ctypes.addressof(self._contacts.obj), ctypes.POINTER(_Contact))

    def declarations(self) -> dict:
        """What the engine declares through its version 2 `declare` ({} without one)."""
        if self._declare is None:
            return {}
        d = _Declarations(struct_size=ctypes.sizeof(_Declarations))
        if self._declare(self._engine, ctypes.byref(d)) != 0:
            raise EngineFailure("exception", f"{self.name}: declare failed: {self._last_error()}")
        out: dict = {}
        if d.flags & DECLARE_FRICTION:
            out["friction"] = {"mu": d.friction_mu}
        if d.flags & DECLARE_LATENCY:
            out["latency_ticks"] = d.latency_ticks
        if d.flags & DECLARE_SKIN:
            out["skin"] = d.skin
        if d.flags & ~(DECLARE_FRICTION | DECLARE_LATENCY | DECLARE_SKIN):
            raise EngineFailure("abi", f"{self.name}: declare set unknown flags {d.flags:#x}")
        return out

    def _last_error(self) -> str:
        return (self._table.last_error(self._engine) or b"").decode(errors="replace")

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
            raise EngineFailure("exception", f"{self.name}: reset failed: {error.value.decode(errors='replace')}")

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        return self.step_timed(t, xh_p, xh_q)[0]

    def step_timed(self, t: float, xh_p, xh_q) -> tuple[EngineStep, float, float]:
        """One step, with the wall and CPU seconds of the call into the library alone."""
        pose, out = self._pose, self._out.obj
        self._pose_view[:3], self._pose_view[3:] = xh_p, xh_q
        out.struct_size = ctypes.sizeof(_StepOut)
        out.contact_capacity = CONTACT_CAPACITY
        out.contacts = self._contacts_address
        out.num_contacts = -1
        out.step_seconds = STEP_SECONDS_UNSET
        cpu, wall = time.process_time(), time.perf_counter()
        status = self._table.step(self._engine, float(t), ctypes.byref(pose), ctypes.byref(out))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        for buffer, what in ((self._out, "its output struct (gauss6_step_out)"),
                             (self._contacts, f"its contact buffer ({CONTACT_CAPACITY} contacts)")):
            side = buffer.overrun()
            if side:
                where = "past the end of" if side == "after" else "before the start of"
                raise EngineFailure("abi", f"{self.name}: step at t = {t!r} wrote {where} {what}")
        if status != 0:
            raise EngineFailure("exception", f"{self.name}: step at t = {t!r} returned an error: {self._last_error()}")
        if not -1 <= out.num_contacts <= CONTACT_CAPACITY:
            raise EngineFailure("abi", f"{self.name}: step at t = {t!r} reported {out.num_contacts} contacts "
                                       f"(capacity {CONTACT_CAPACITY})")
        contacts = None
        if out.num_contacts >= 0:  # _Contact is 7 doubles: point, normal, separation
            n = out.num_contacts
            contacts = np.frombuffer(self._contacts.obj, dtype=np.float64, count=7 * n).reshape(n, 7).copy()
        seconds = out.step_seconds
        answer = self._answer_view.copy()
        step = EngineStep(answer[0:3], answer[3:7], answer[7:13], contacts,
                          None if seconds == STEP_SECONDS_UNSET else seconds)
        return step, wall, cpu

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


PYTHON_PREFIX = "python:"


def _python_spec(spec: str) -> tuple[str, str]:
    """(MODULE or FILE.py, FACTORY) of a `python:` spec; ValueError when malformed or the file is missing."""
    where, sep, factory = spec[len(PYTHON_PREFIX):].rpartition(":")
    if not sep or not where or not factory:
        raise ValueError(f"{spec}: expected python:MODULE:FACTORY or python:path/to/file.py:FACTORY")
    if where.endswith(".py") and not Path(where).is_file():
        raise ValueError(f"{spec}: no such file {where}")
    return where, factory


def engine_factory(spec: str):
    """The factory of a Python engine spec, `python:MODULE:FACTORY` (MODULE importable: on
    PYTHONPATH or installed) or `python:path/to/file.py:FACTORY` (the file imported by path)."""
    where, factory = _python_spec(spec)
    if where.endswith(".py"):
        path = Path(where).resolve()
        name = f"gauss6_engine_module_{path.stem}"
        module_spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(module_spec)
        sys.modules[name] = module
        module_spec.loader.exec_module(module)
    else:
        module = importlib.import_module(where)
    if not callable(getattr(module, factory, None)):
        raise ValueError(f"{spec}: {where} has no callable {factory}")
    return getattr(module, factory)


def check_spec(spec: str) -> None:
    """A usage check of an engine spec in the caller's process, before a child is started: the
    library's path exists, or the Python spec has its parts and its file (ValueError, EngineError)."""
    if spec.startswith(PYTHON_PREFIX):
        where, _ = _python_spec(spec)
        if not where.endswith(".py"):
            try:
                found = importlib.util.find_spec(where) is not None
            except ImportError:
                found = False
            if not found:
                raise ValueError(f"{spec}: no module {where} (a module must be importable: installed or on "
                                 f"PYTHONPATH; or give python:path/to/file.py:FACTORY)")
    else:
        engine_library(spec)


def make_engine(spec: str, config: str = ""):
    """An engine by spec: python:MODULE:FACTORY or python:FILE.py:FACTORY (FACTORY(config)), a built
    engine's name, or a library path."""
    if spec.startswith(PYTHON_PREFIX):
        return engine_factory(spec)(config)
    return load_engine(spec, config)
