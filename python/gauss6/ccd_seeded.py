"""Rigid CCD steps generated from seeds on the fly (not stored), for campaigns.

Step families (steps in the format of datasets_generated/ccd/README.md):
- the generator's own sets, drawn by its builders (gauss6.generators.ccd):
  random, grazing, parallel, rotation_about_g, zero_rotation, large_rotation, tunnelling;
- sliding: contacts sliding at delta: the lowest vertex 0.9-1.1 delta above the
  obstacle's tangent plane, a tangential haptic-size translation and a small rotation
  (1e-4 to 1e-2 rad) about a random axis;
- near_parallel: as parallel (axis-aligned orientation against the box's axis-aligned
  faces, translation along -n ending 2 delta before to 2 delta past the plane, odd
  steps sliding along an axis), with the orientation turned by a rotation of
  log-uniform angle in [1e-12, 1e-4] rad: faces and edges nearly, not exactly, parallel;
- peg_scenario, bunny_scenario: steps of the recorded scenarios' hand paths
  (datasets_generated/scripts/*.json, poses of G): a time t uniform over the script,
  the hand's poses at t and t + dt (dt log-uniform in [1, 30] ms, p interpolated
  linearly and q normalised-linearly between keys), both jittered by one random
  offset (up to 2 mm, 0.02 rad); kept when the start pose is exactly free.

A chunk (family, seed, index, count) is drawn from PCG64([seed, FAMILY_NUMBER[family], index]):
it depends on those alone, so any process makes the same steps in any order; a chunk
of count k is the first k steps of the chunk of the same index with more.

`plan(count)` lays a campaign of `count` steps out in rounds of ROUND steps, the
families in the proportions of ROUND (the slow ones, whose exact judgement takes
seconds, rare and last in each round).
"""
from __future__ import annotations

import functools
import json

import numpy as np
from numpy.random import PCG64, Generator

from . import paths

# (family, steps per round, steps per chunk).
ROUND = [
    ("random", 150, 25), ("sliding", 150, 25), ("near_parallel", 150, 25), ("peg_scenario", 125, 25),
    ("grazing", 100, 25), ("parallel", 100, 25), ("rotation_about_g", 100, 25), ("zero_rotation", 100, 25),
    # exact judgement: bunny ~3 s, tunnelling ~13 s, large rotation 30-60 s a step (today)
    ("bunny_scenario", 2, 1), ("tunnelling", 2, 1), ("large_rotation", 1, 1),
]
FAMILIES = [f for f, _, _ in ROUND]
# Each family's number in its chunks' seeds: part of the campaign's definition, never reused.
FAMILY_NUMBER = {"random": 1, "grazing": 2, "parallel": 3, "rotation_about_g": 4, "zero_rotation": 5,
                 "large_rotation": 6, "tunnelling": 7, "sliding": 8, "near_parallel": 9, "peg_scenario": 10,
                 "bunny_scenario": 11}
STEPS_PER_ROUND = sum(n for _, n, _ in ROUND)
SCRIPTS = {"peg_scenario": "peg_in_hole.json", "bunny_scenario": "bunny.json"}
SCENARIO_DT = (1e-3, 3e-2)          # s
SCENARIO_JITTER = (2e-3, 0.02)      # m, rad


@functools.cache
def generator():
    """The step sets' generator, gauss6.generators.ccd."""
    from .generators import ccd

    return ccd


@functools.cache
def mesh_pair(obstacle: str, god: str, delta: float):
    """The generator's Pair (meshes, exact predicates), once per process."""
    return generator().load_pair(obstacle, god, delta)


def set_sliding(rng: Generator, pair, p: dict) -> list[dict]:
    gen = generator()
    out = []
    for i in range(p["count"]):
        k = rng.uniform(0.9, 1.1)
        p0, q0, n, gap = gen.near_contact_start(rng, pair, (k * pair.delta, k * pair.delta * (1 + 1e-12)))
        p1 = p0 + gen.loguniform(rng, gen.LIN_STEP) * gen.tangent(rng, n)
        angle = gen.loguniform(rng, (1e-4, 1e-2))
        q1 = gen.qmul(gen.qexp(angle * gen.random_unit(rng)), q0)
        out.append(gen.step(pair, f"sliding-{i:04d}", p0, q0, p1, q1, gap_over_delta=k, angle=angle))
    return out


def set_near_parallel(rng: Generator, pair, p: dict) -> list[dict]:
    gen = generator()
    quats = gen.axis_quats()
    faces = np.flatnonzero(np.isin(np.abs(pair.face_normal), (0.0, 1.0)).all(axis=1))
    out = []
    for i in range(p["count"]):
        tilt = gen.loguniform(rng, (1e-12, 1e-4))

        def quat(r):
            return gen.qmul(gen.qexp(tilt * gen.random_unit(r)), quats[int(r.integers(len(quats)))])

        p0, q0, n, gap = gen.near_contact_start(rng, pair, (1e-6, 1e-3), faces, quat=quat)
        k = rng.uniform(-2.0, 2.0)
        d = -(gap - k * pair.delta) * n
        if i % 2 == 1:
            axes = [a for a in np.eye(3) if abs(a @ n) == 0.0]
            d = d + rng.choice([-1.0, 1.0]) * gen.loguniform(rng, gen.LIN_STEP) * axes[int(rng.integers(2))]
        out.append(gen.step(pair, f"near_parallel-{i:04d}", p0, q0, p0 + d, q0, end_gap_over_delta=k,
                            tilt_rad=tilt, slide=bool(i % 2)))
    return out


@functools.cache
def script_keys(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    doc = json.loads((paths.DATASETS_DIR / "scripts" / name).read_text())
    keys = doc["keys"]
    return (np.array([k["t"] for k in keys], dtype=float), np.array([k["p"] for k in keys], dtype=float),
            np.array([k["q"] for k in keys], dtype=float))


def hand_pose(name: str, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The script's pose of G at time t (linear in p, normalised-linear in q)."""
    T, P, Q = script_keys(name)
    j = int(np.clip(np.searchsorted(T, t, side="right") - 1, 0, len(T) - 2))
    s = float(np.clip((t - T[j]) / (T[j + 1] - T[j]) if T[j + 1] > T[j] else 0.0, 0.0, 1.0))
    q1 = Q[j + 1] if Q[j] @ Q[j + 1] >= 0 else -Q[j + 1]
    q = (1 - s) * Q[j] + s * q1
    return (1 - s) * P[j] + s * P[j + 1], q / np.linalg.norm(q)


def scenario_builder(family: str):
    script = SCRIPTS[family]

    def build(rng: Generator, pair, p: dict) -> list[dict]:
        gen = generator()
        T, _, _ = script_keys(script)
        out = []
        while len(out) < p["count"]:
            t = rng.uniform(T[0], T[-1])
            dt = gen.loguniform(rng, SCENARIO_DT)
            shift = SCENARIO_JITTER[0] * rng.uniform(-1, 1, 3)
            turn = gen.qexp(SCENARIO_JITTER[1] * rng.uniform(-1, 1, 3))
            (p0, q0), (p1, q1) = hand_pose(script, t), hand_pose(script, t + dt)
            p0, q0, p1, q1 = p0 + shift, gen.qmul(turn, q0), p1 + shift, gen.qmul(turn, q1)
            if pair.free(p0, q0):
                out.append(gen.step(pair, f"{family}-{len(out):04d}", p0, q0, p1, q1, t=t, dt=dt))
        return out

    return build


def builder(family: str):
    """(step builder (rng, pair, {"count"}) -> steps, (obstacle, god, delta))."""
    gen = generator()
    peg = (gen.BOX, gen.PEG, gen.PEG_DELTA)
    if family == "sliding":
        return set_sliding, peg
    if family == "near_parallel":
        return set_near_parallel, peg
    if family == "peg_scenario":
        return scenario_builder(family), peg
    if family == "bunny_scenario":
        return scenario_builder(family), (gen.BUNNY, gen.BUNNY, gen.BUNNY_DELTA)
    fn, _, key = gen.SETS[family]
    return fn, key


def chunk_steps(family: str, seed: int, index: int, count: int) -> tuple[list[dict], float]:
    """The steps of one chunk (see the top of this file) and their delta."""
    if family not in FAMILIES:
        raise ValueError(f"no CCD step family {family!r} (families: {', '.join(FAMILIES)})")
    build, key = builder(family)
    pair = mesh_pair(*key)
    steps = build(Generator(PCG64([seed, FAMILY_NUMBER[family], index])), pair, {"count": count})
    for k, s in enumerate(steps):
        s["id"] = f"{family}-s{seed}-c{index}-{k:03d}"
    return steps, pair.delta


def plan(count: int, seed: int, families: list[str] | None = None) -> list[dict]:
    """Chunks of `count` steps in all: rounds of ROUND (restricted to `families`),
    the chunks of a round interleaved family by family; the last one cut to fit."""
    rnd = [r for r in ROUND if families is None or r[0] in families]
    if families is not None:
        unknown = sorted(set(families) - set(FAMILIES))
        if unknown:
            raise ValueError(f"no CCD step family {unknown[0]!r} (families: {', '.join(FAMILIES)})")
    if count < 1:
        raise ValueError(f"a campaign of {count} steps: must be >= 1")
    if not rnd:
        raise ValueError("a campaign of no step family")
    next_index = {f: 0 for f, _, _ in rnd}
    chunks, total = [], 0
    while total < count:
        pending = {f: n for f, n, _ in rnd}
        for group in ([r for r in rnd if r[2] > 1], [r for r in rnd if r[2] == 1]):  # the slow ones last
            while any(pending[f] for f, _, _ in group) and total < count:
                for f, _, size in group:
                    k = min(size, pending[f], count - total)
                    if k <= 0:
                        continue
                    chunks.append({"family": f, "seed": seed, "index": next_index[f], "count": k})
                    next_index[f] += 1
                    pending[f] -= k
                    total += k
    for family in sorted({c["family"] for c in chunks} & set(SCRIPTS)):
        script = paths.DATASETS_DIR / "scripts" / SCRIPTS[family]
        if not script.is_file():  # an installed package without a checkout's datasets
            raise ValueError(f"{script}: missing: the {family} steps follow this hand script of the datasets "
                             "folder (GAUSS6_DATASETS_DIR); leave the family out with --family")
    return chunks
