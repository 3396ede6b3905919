"""Seeded generator of the rigid continuous-collision step sets (METHOD.md section 4).

A step moves the god-object from pose X0 to pose X1 (poses of its reference point
G, the centre of mass) along the Cayley in-between motion, against one static
obstacle. Each set probes one kind of motion (near-contact haptic steps, grazing,
parallel features, pure rotation, no rotation, large rotation, tunnelling paths,
and the steps of scripted peg-in-hole and bunny motions). The format and the sets
are described in datasets_generated/ccd/README.md.

Everything random is drawn from numpy's PCG64 with a fixed seed per set. Start
poses are kept only when the exact reference says they are free (no intersecting
triangle pair: gauss6._gauss6.ccd.MeshPair.count_intersecting_pairs), so the data
depend only on numpy and exact predicates: running this twice writes
byte-identical files; MANIFEST.json records the sha256 of each output, of this
source and of the meshes read.

Usage:  python -m gauss6.generators.ccd [--out DIR] [--set NAME]   (default: the datasets folder's ccd/)
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.random import PCG64, Generator

from .. import _gauss6, paths  # the C++ core: mesh reader, mass properties, exact predicates
from . import source

FORMAT = "gauss6-ccd-steps"
FORMAT_VERSION = 1
GENERATOR = source(__spec__.name)[0]
GENERATOR_VERSION = "1"

PEG = "peg_in_hole/peg.off"
BOX = "peg_in_hole/box_with_hole.off"
BUNNY = "bunny/bunny.off"
DENSITY = 1000.0            # kg/m^3: only the centre of mass is used, which does not depend on it
PEG_DELTA = 1e-6            # m: scenes/peg_in_hole.toml [contact] delta
BUNNY_DELTA = 1.5e-6        # m: scenes/bunnies.toml [contact] delta
LIN_STEP = (1e-4, 1e-2)     # m: log-uniform haptic step length
ANG_STEP = (1e-3, 1e-1)     # rad: log-uniform haptic step rotation
GAP = (1e-7, 1e-3)          # m: log-uniform gap of the support vertex at X0 (near contact)

# Set name -> seed. Names are part of the format (README.md).
SEEDS = {"random": 2001, "grazing": 2002, "parallel": 2003, "rotation_about_g": 2004, "zero_rotation": 2005,
         "large_rotation": 2006, "tunnelling": 2007, "peg_script": 2008, "bunny_script": 2009}


# --------------------------------------------------------------------------------------
# Quaternions (w, x, y, z) and rotations
# --------------------------------------------------------------------------------------

def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw])


def qexp(v: np.ndarray) -> np.ndarray:
    """Unit quaternion of the rotation vector v (axis times angle)."""
    angle = float(np.linalg.norm(v))
    if angle == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * v / angle])


def rotation(q: np.ndarray) -> np.ndarray:
    """R(q) = (...) / |q|^2, the rational rotation of METHOD.md section 1."""
    w, x, y, z = q
    R = np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])
    return R / float(q @ q)


def random_quat(rng: Generator) -> np.ndarray:
    q = rng.standard_normal(4)
    q /= np.linalg.norm(q)
    return q if q[0] >= 0 else -q


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def random_unit(rng: Generator) -> np.ndarray:
    return unit(rng.standard_normal(3))


def loguniform(rng: Generator, lo_hi: tuple[float, float]) -> float:
    return float(math.exp(rng.uniform(math.log(lo_hi[0]), math.log(lo_hi[1]))))


def tangent(rng: Generator, n: np.ndarray) -> np.ndarray:
    """A random unit vector orthogonal to the unit vector n."""
    t = rng.standard_normal(3)
    return unit(t - (t @ n) * n)


# --------------------------------------------------------------------------------------
# Meshes: obstacle (world frame, identity pose) and god-object (body frame, origin at G)
# --------------------------------------------------------------------------------------

@dataclass
class Pair:
    obstacle: str
    god: str
    V_obs: np.ndarray
    F_obs: np.ndarray
    V_god: np.ndarray          # body frame: fl(V_mesh - offset)
    F_god: np.ndarray
    offset: np.ndarray         # G (centre of mass) in the god mesh's frame
    delta: float
    exact: object              # _gauss6.ccd.MeshPair (exact predicates)
    face_area: np.ndarray      # obstacle triangle areas
    face_normal: np.ndarray    # obstacle unit outward normals

    def free(self, p: np.ndarray, q: np.ndarray) -> bool:
        return self.exact.count_intersecting_pairs(p, q) == 0

    def surface_point(self, rng: Generator, faces: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """An area-weighted random point of the obstacle's surface (of `faces` if given) and its normal."""
        idx = np.arange(len(self.F_obs)) if faces is None else faces
        w = self.face_area[idx] / self.face_area[idx].sum()
        f = int(idx[rng.choice(len(idx), p=w)])
        a, b = rng.uniform(size=2)
        if a + b > 1:
            a, b = 1 - a, 1 - b
        A, B, C = self.V_obs[self.F_obs[f]]
        return A + a * (B - A) + b * (C - A), self.face_normal[f]


def load_pair(obstacle: str, god: str, delta: float) -> Pair:
    datasets = paths.DATASETS_DIR
    V_obs, F_obs = _gauss6.read_mesh(str(datasets / obstacle))
    V_mesh, F_god = _gauss6.read_mesh(str(datasets / god))
    offset = np.asarray(_gauss6.mass_properties(V_mesh, F_god, DENSITY)["center_of_mass"], dtype=float)
    V_god = V_mesh - offset
    cross = np.cross(V_obs[F_obs[:, 1]] - V_obs[F_obs[:, 0]], V_obs[F_obs[:, 2]] - V_obs[F_obs[:, 0]])
    norm = np.linalg.norm(cross, axis=1)
    exact = _gauss6.ccd.MeshPair(V_obs, F_obs, V_god, F_god)
    return Pair(obstacle, god, V_obs, F_obs, V_god, F_god, offset, delta, exact, 0.5 * norm, cross / norm[:, None])


def support_pose(pair: Pair, s: np.ndarray, n: np.ndarray, q: np.ndarray, gap: float) -> np.ndarray:
    """Position of G that puts the god-object's lowest vertex along n (at orientation q)
    at s + gap n: the body just above the obstacle's tangent plane at s."""
    W = pair.V_god @ rotation(q).T
    k = int(np.argmin(W @ n))
    return s + gap * n - W[k]


def near_contact_start(rng: Generator, pair: Pair, gap_range=GAP, faces=None, quat=None) -> tuple:
    """A free start pose near the obstacle: (p0, q0, n, gap)."""
    while True:
        s, n = pair.surface_point(rng, faces)
        q0 = random_quat(rng) if quat is None else quat(rng)
        gap = loguniform(rng, gap_range)
        p0 = support_pose(pair, s, n, q0, gap)
        if pair.free(p0, q0):
            return p0, q0, n, gap


def step(pair: Pair, sid: str, p0, q0, p1, q1, **tags) -> dict:
    return {"id": sid, "obstacle": pair.obstacle, "god": pair.god, "offset": [float(c) for c in pair.offset],
            "p0": [float(c) for c in p0], "q0": [float(c) for c in q0],
            "p1": [float(c) for c in p1], "q1": [float(c) for c in q1], "tags": tags}


def approach_direction(rng: Generator, n: np.ndarray) -> np.ndarray:
    """Unit direction towards the obstacle (against n) within 80 degrees, or any direction (one in five)."""
    if rng.uniform() < 0.2:
        return random_unit(rng)
    theta = rng.uniform(0, math.radians(80))
    return unit(-math.cos(theta) * n + math.sin(theta) * tangent(rng, n))


# --------------------------------------------------------------------------------------
# The sets
# --------------------------------------------------------------------------------------

def set_random(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    out = []
    for i in range(p["count"]):
        p0, q0, n, gap = near_contact_start(rng, pair)
        p1 = p0 + loguniform(rng, LIN_STEP) * approach_direction(rng, n)
        q1 = qmul(qexp(loguniform(rng, ANG_STEP) * random_unit(rng)), q0)
        out.append(step(pair, f"random-{i:04d}", p0, q0, p1, q1, gap=gap))
    return out


def set_grazing(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    """Glide (i % 2 == 0): tangential translation with the support vertex at 0.5-2 delta
    above the tangent plane. Approach (i % 4 == 1): translation along -n that ends 0.5-2
    delta above it. Touch (i % 4 == 3): translation along -n that ends 0.25-1 delta past
    the plane: a real contact, met almost head-on, that the CCD must stop delta before."""
    out = []
    for i in range(p["count"]):
        if i % 2 == 0:
            k = rng.uniform(0.5, 2.0)
            p0, q0, n, gap = near_contact_start(rng, pair, (k * pair.delta, k * pair.delta * (1 + 1e-12)))
            p1 = p0 + loguniform(rng, LIN_STEP) * tangent(rng, n)
            kind = "glide"
        else:
            k = rng.uniform(0.5, 2.0) if i % 4 == 1 else -rng.uniform(0.25, 1.0)
            p0, q0, n, gap = near_contact_start(rng, pair, (1e-5, 1e-3))
            p1 = p0 - (gap - k * pair.delta) * n
            kind = "approach" if k > 0 else "touch"
        out.append(step(pair, f"grazing-{i:04d}", p0, q0, p1, q0, kind=kind, end_gap_over_delta=k))
    return out


# The 24 rotations that map axes to axes, as integer quaternions (|q|^2 in {1, 2, 4}):
# R(q) is then exact in doubles, so faces and edges are exactly parallel.
def axis_quats() -> list[np.ndarray]:
    cands = set()
    for w in (0, 1, 2):
        for x in (-2, -1, 0, 1, 2):
            for y in (-2, -1, 0, 1, 2):
                for z in (-2, -1, 0, 1, 2):
                    q = np.array([w, x, y, z], dtype=float)
                    n2 = q @ q
                    if n2 == 0:
                        continue
                    R = rotation(q)
                    if np.all(np.isin(R, (-1.0, 0.0, 1.0))):
                        key = tuple(R.astype(int).ravel())
                        if key not in {c[0] for c in cands}:
                            cands.add((key, tuple(q)))
    return [np.array(q) for _, q in sorted(cands)]


def set_parallel(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    """Axis-aligned orientations against the box's axis-aligned faces: faces and
    side edges exactly parallel. Translation along -n (ending 0.5-2 delta before
    or past the plane), half of them with a sliding part along an axis."""
    quats = axis_quats()
    faces = np.flatnonzero(np.isin(np.abs(pair.face_normal), (0.0, 1.0)).all(axis=1))
    out = []
    for i in range(p["count"]):
        p0, q0, n, gap = near_contact_start(rng, pair, (1e-6, 1e-3), faces,
                                            quat=lambda r: quats[int(r.integers(len(quats)))])
        k = rng.uniform(-2.0, 2.0)
        d = -(gap - k * pair.delta) * n
        if i % 2 == 1:
            axes = [a for a in np.eye(3) if abs(a @ n) == 0.0]
            d = d + rng.choice([-1.0, 1.0]) * loguniform(rng, LIN_STEP) * axes[int(rng.integers(2))]
        out.append(step(pair, f"parallel-{i:04d}", p0, q0, p0 + d, q0, end_gap_over_delta=k, slide=bool(i % 2)))
    return out


def set_rotation_about_g(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    out = []
    for i in range(p["count"]):
        p0, q0, n, gap = near_contact_start(rng, pair, (1e-6, 1e-3))
        angle = loguniform(rng, (1e-3, 0.3))
        q1 = qmul(qexp(angle * random_unit(rng)), q0)
        out.append(step(pair, f"rotation_about_g-{i:04d}", p0, q0, p0, q1, gap=gap, angle=angle))
    return out


def set_zero_rotation(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    out = []
    for i in range(p["count"]):
        p0, q0, n, gap = near_contact_start(rng, pair)
        p1 = p0 + loguniform(rng, LIN_STEP) * approach_direction(rng, n)
        out.append(step(pair, f"zero_rotation-{i:04d}", p0, q0, p1, q0, gap=gap))
    return out


def set_large_rotation(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    out = []
    for i in range(p["count"]):
        p0, q0, n, gap = near_contact_start(rng, pair, (1e-4, 3e-2))
        angle = math.radians(rng.uniform(10.0, 170.0))
        q1 = qmul(qexp(angle * random_unit(rng)), q0)
        p1 = p0 + loguniform(rng, LIN_STEP) * random_unit(rng)
        out.append(step(pair, f"large_rotation-{i:04d}", p0, q0, p1, q1, gap=gap, angle_deg=math.degrees(angle)))
    return out


def set_tunnelling(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    """Both ends free, G outside the obstacle's bounding box at both ends, and G's path
    through a point c inside the obstacle's solid (within 8 mm of its outline), so the
    in-between motion must meet the obstacle."""
    lo, hi = pair.V_obs.min(axis=0), pair.V_obs.max(axis=0)
    half = 0.5 * (hi - lo)
    out = []
    while len(out) < p["count"]:
        c = rng.uniform(lo, hi)
        if np.min(half - np.abs(c)) > 0.008 or math.hypot(c[0], c[2]) < 0.0102 + 1e-4:
            continue  # too deep, or in the hole (radius 1.02 cm about Y, apothem; margin 0.1 mm)
        d = random_unit(rng)
        q0 = random_quat(rng)
        q1 = qmul(qexp(rng.uniform(0, 0.2) * random_unit(rng)), q0)
        # Distance along +-d from c to the bounding box's boundary, then a part of the
        # god-object's radius beyond it (the whole radius beyond is surely free).
        with np.errstate(divide="ignore"):
            exit_t = min(float(np.min(np.maximum((hi - c) / d, (lo - c) / d))),
                         float(np.min(np.maximum((hi - c) / -d, (lo - c) / -d))))
        radius = float(np.max(np.linalg.norm(pair.V_god, axis=1)))
        s = exit_t + rng.uniform(0.3, 1.0) * radius
        while not (pair.free(c - s * d, q0) and pair.free(c + s * d, q1)):
            s += 0.1 * radius
        p0, p1 = c - s * d, c + s * d
        out.append(step(pair, f"tunnelling-{len(out):04d}", p0, q0, p1, q1, half_length=s))
    return out


def scene_pose_of_g(pair: Pair, position, orientation) -> tuple[np.ndarray, np.ndarray]:
    """Pose of G from a scene's god-object pose (pose of the mesh's own frame)."""
    q = np.asarray(orientation, dtype=float)
    return np.asarray(position, dtype=float) + rotation(q) @ pair.offset, q


def scripted_steps(pair: Pair, name: str, hand: list[tuple[np.ndarray, np.ndarray]], **tags) -> list[dict]:
    """Consecutive hand poses as steps, kept only when the start pose is free (a god-object
    never starts a step in contact)."""
    out = []
    for k in range(len(hand) - 1):
        (p0, q0), (p1, q1) = hand[k], hand[k + 1]
        if pair.free(p0, q0):
            out.append(step(pair, f"{name}-{len(out):04d}", p0, q0, p1, q1, hand_step=k, **tags))
    return out


def set_peg_script(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    """scenes/peg_in_hole.toml's start pose, then two scripted phases:
    1. press: the upright peg descends onto the box's top (1 cm gap) with a slow wobble,
       to 1 mm past the top's plane;
    2. insert: the peg, axis along Y, enters the hole from y = +3 cm along -Y, 1 mm per
       step, drifting sideways (x) from 0 to 0.35 mm (the clearance is 0.2 mm) and tilting
       0 to 0.6 degrees about Z, so that it grazes, then meets, the wall."""
    p_start, q_start = scene_pose_of_g(pair, [0.0, 0.0, 0.09], [0.7071067811865476, 0.7071067811865476, 0.0, 0.0])
    hand = []
    n = p["press_steps"]
    for k in range(n + 1):
        t = k / n
        z = 0.09 - 0.011 * (1 - (1 - t) ** 2)           # decelerating descent, 11 mm
        wobble = qexp(np.array([0.0, 0.004 * math.sin(6 * t), 0.004 * math.cos(5 * t) - 0.004]))
        hand.append((np.array([p_start[0] + 2e-4 * t, p_start[1], z]), qmul(wobble, q_start)))
    out = scripted_steps(pair, "peg_script", hand, phase="press")
    hand = []
    n = p["insert_steps"]
    for k in range(n + 1):
        t = k / n
        y = 0.03 + 0.05 + 0.005 - 0.001 * k             # tip from 5 mm before the entry face
        q = qexp(np.array([0.0, 0.0, math.radians(0.6) * t]))
        hand.append((np.array([0.00035 * t, y, 0.0]), q))
    ins = scripted_steps(pair, "peg_script", hand, phase="insert")
    for i, s in enumerate(ins):
        s["id"] = f"peg_script-{len(out) + i:04d}"
    return out + ins


def set_bunny_script(rng: Generator, pair: Pair, p: dict) -> list[dict]:
    """scenes/bunnies.toml's start pose (held bunny upside down, 1 cm above the static
    one's back), then p["descents"] short descents of p["steps"] hand steps each, from
    start points spread over the static bunny's back (random offsets of up to 2 cm in x
    and z, random turns of up to 0.1 rad), each p["depth"] (3 cm) deep with a slow turn and drift, so
    that every descent ends in a contact somewhere else. The exact reference takes
    seconds per step on these meshes, so the set is short."""
    p_start, q_start = scene_pose_of_g(pair, [0.0, 0.16, 0.0], [0.0, 0.0, 0.0, 1.0])
    out = []
    for d in range(p["descents"]):
        shift = np.array([rng.uniform(-0.02, 0.02), 0.0, rng.uniform(-0.02, 0.02)]) if d else np.zeros(3)
        tilt = qexp(0.1 * rng.uniform(-1.0, 1.0, 3)) if d else np.array([1.0, 0.0, 0.0, 0.0])
        q_d = qmul(tilt, q_start)
        hand = []
        n = p["steps"]
        for k in range(n + 1):
            t = k / n
            turn = qexp(np.array([0.0, 0.05 * t, 0.02 * math.sin(3 * t)]))
            drift = np.array([0.004 * t, -p["depth"] * (1 - (1 - t) ** 1.5), -0.002 * t])
            hand.append((p_start + shift + drift, qmul(turn, q_d)))
        steps = scripted_steps(pair, "bunny_script", hand, descent=d)
        for s in steps:
            s["id"] = f"bunny_script-{len(out):04d}"
            out.append(s)
    return out


# Sizes: the exact reference takes about 0.5 s per peg step and 3 s per bunny step, and
# `gauss6 crosscheck ccd` must stay within a few minutes on two cores.
SETS = {
    "random": (set_random, {"count": 60}, (BOX, PEG, PEG_DELTA)),
    "grazing": (set_grazing, {"count": 40}, (BOX, PEG, PEG_DELTA)),
    "parallel": (set_parallel, {"count": 40}, (BOX, PEG, PEG_DELTA)),
    "rotation_about_g": (set_rotation_about_g, {"count": 40}, (BOX, PEG, PEG_DELTA)),
    "zero_rotation": (set_zero_rotation, {"count": 40}, (BOX, PEG, PEG_DELTA)),
    "large_rotation": (set_large_rotation, {"count": 2}, (BOX, PEG, PEG_DELTA)),  # about 60 s per exact step
    "tunnelling": (set_tunnelling, {"count": 5}, (BOX, PEG, PEG_DELTA)),  # about 13 s per exact step
    "peg_script": (set_peg_script, {"press_steps": 40, "insert_steps": 40}, (BOX, PEG, PEG_DELTA)),
    "bunny_script": (set_bunny_script, {"descents": 8, "steps": 8, "depth": 0.03}, (BUNNY, BUNNY, BUNNY_DELTA)),
}


# --------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------

def sha256_file(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def parameters(name: str) -> dict:
    _, params, (obstacle, god, delta) = SETS[name]
    ds = paths.DATASETS_DIR
    return {**params, "obstacle": obstacle, "god": god, "delta": delta, "lin_step_m": list(LIN_STEP),
            "ang_step_rad": list(ANG_STEP), "gap_m": list(GAP),
            "inputs": {m: sha256_file(ds / m) for m in sorted({obstacle, god})}}


_PAIRS: dict[tuple, Pair] = {}


def generate_set(name: str) -> dict:
    fn, params, key = SETS[name]
    if key not in _PAIRS:
        _PAIRS[key] = load_pair(*key)
    pair = _PAIRS[key]
    steps = fn(Generator(PCG64(SEEDS[name])), pair, params)
    return {"format": FORMAT, "version": FORMAT_VERSION, "set": name, "generator": GENERATOR,
            "generator_version": GENERATOR_VERSION, "seed": SEEDS[name], "parameters": parameters(name),
            "source_sha256": source(__spec__.name)[1], "delta": pair.delta, "steps": steps}


def dumps(doc: dict) -> str:
    """Compact JSON, shortest round-trip doubles (bit-exact for strtod and Python)."""
    return json.dumps(doc, separators=(",", ":"), allow_nan=False) + "\n"


def write(out: Path, names: list[str]) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    for name in names:
        doc = generate_set(name)
        (out / f"{name}.json").write_text(dumps(doc))
        print(f"{name}: {len(doc['steps'])} steps", file=sys.stderr)
    manifest_path = out / "MANIFEST.json"
    manifest = json.loads(manifest_path.read_text()) if manifest_path.exists() else {}
    manifest.update({"generator": GENERATOR, "generator_version": GENERATOR_VERSION,
                     "source_sha256": source(__spec__.name)[1]})
    manifest.setdefault("parameters", {})
    manifest.setdefault("outputs", {})
    for name in names:
        manifest["parameters"][name] = parameters(name)
        manifest["outputs"][f"{name}.json"] = sha256_file(out / f"{name}.json")
    manifest["parameters"] = dict(sorted(manifest["parameters"].items()))
    manifest["outputs"] = dict(sorted(manifest["outputs"].items()))
    manifest_path.write_text(json.dumps(manifest, indent=1) + "\n")
    return manifest


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=paths.DATASETS_DIR / "ccd")
    ap.add_argument("--set", dest="sets", action="append", choices=list(SETS), help="one set (repeatable; default all)")
    args = ap.parse_args()
    write(args.out, args.sets or list(SETS))
    return 0


if __name__ == "__main__":
    sys.exit(main())
