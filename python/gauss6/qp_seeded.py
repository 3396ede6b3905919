"""Projection instances generated from seeds on the fly (not stored), for campaigns.

The families of gauss6.generators.qp (datasets_generated/qp/README.md), drawn by the
generator's own family builders, a chunk at a time: chunk `index` of family F in a
campaign of seed S is `size` instances (CHUNK_SIZE by default) drawn from
PCG64([S, seed of F, index]). The family's m, labels, ratios and kinds cycle within a
chunk as within a family file; CHUNK_SIZE is a multiple of every cycle, so each chunk
holds them all in the family file's proportions. A chunk depends on (S, F, index,
size) alone, so any process makes the same instances, in any order. `warm` chunks
hold size // 50 sequences of 50 steps (at least one).

Beyond the files' families, many simultaneous contacts (METHOD.md: any number):
- m200, m1000: 200 or 1000 contact rows on a random box or the peg (in turn), push
  labels all, all, some, some (as m50);
- redundant_m200, redundant_m1000: 8 to 30 distinct rows and copies of them up to m
  rows (exact duplicates, scaled copies, copies perturbed by a relative 1e-6..1e-12,
  averages of two rows), shuffled.

And row_scaled (qp_instances.row_scaled): chunk j draws size // 2 instances of the files'
families but qp_instances.ROW_SCALED_LEFT_OUT (family j mod 6, its chunk j // 6) and gives each twice, its rows scaled
by positive factors spanning 16 orders of magnitude, then rescaled.

Instance ids: "F-sS-cINDEX-NNNN".
"""
from __future__ import annotations

import functools
import importlib
import os

import numpy as np
from numpy.random import PCG64, Generator

from .qp_instances import (GENERATOR_MODULE, ROW_SCALED, ROW_SCALED_LEFT_OUT, ROW_SCALED_SEED, Instance, from_record,
                           row_scaled)

CHUNK_SIZE = 360      # a multiple of 36 (m 1..12 x 3 labels), 24 (redundant), 10 (offsets), 4 (inertia)
WARM_STEPS = 50


@functools.cache
def generator():
    """The families' generator, gauss6.generators.qp (imported once per process). Its
    mesh bodies (the bunny's takes a second to read) are cached per process."""
    # The generator pins numpy's OpenBLAS kernels for the stored files (OPENBLAS_CORETYPE,
    # read when numpy loads: no effect here, numpy is loaded). Left set, it would reach the
    # worker processes a campaign spawns later, whose numpy would then run other kernels
    # than this process's (AVX2 against AVX-512 where the CPU has it) and round the last
    # bits of the same products differently: a campaign's summary would then differ,
    # serial and distributed. So this process's environment is left as it was.
    before = os.environ.get("OPENBLAS_CORETYPE")
    try:
        gen = importlib.import_module(GENERATOR_MODULE)
    finally:
        if before is None:
            os.environ.pop("OPENBLAS_CORETYPE", None)
        else:
            os.environ["OPENBLAS_CORETYPE"] = before
    gen.mesh_body = functools.cache(gen.mesh_body)
    return gen


# Families of many rows: name -> (seed number, rows); seed numbers beyond the files' (1001-1008).
MANY_ROWS = {"m200": (1101, 200), "m1000": (1102, 1000), "redundant_m200": (1103, 200),
             "redundant_m1000": (1104, 1000)}


def family_names() -> list[str]:
    """Every family: the files', the many-row ones and row_scaled."""
    return list(generator().SEEDS) + list(MANY_ROWS) + [ROW_SCALED]


def _row_scaled_chunk(seed: int, index: int, size: int) -> list[Instance]:
    """Chunk `index` of row_scaled (see the top of this file)."""
    bases = [f for f in generator().SEEDS if f not in ROW_SCALED_LEFT_OUT]
    base = chunk_instances(bases[index % len(bases)], seed, index // len(bases), max(size // 2, 1))
    return row_scaled(base, Generator(PCG64([seed, ROW_SCALED_SEED, index])))


def default_family_names() -> list[str]:
    """A campaign's default: the files' families. The many-row ones are asked for by name
    (their exact judgement takes 10-300 ms an instance, against 0.2-3 ms)."""
    return list(generator().SEEDS)


def _many_rows(name: str, rng: Generator, p: dict) -> list[dict]:
    gen = generator()
    peg = gen.mesh_body("peg", gen.PEG_MESH)
    m = MANY_ROWS[name][1]
    labels = ("all", "all", "some", "some")
    if not name.startswith("redundant"):
        return gen.contact_family(name, rng, lambda i: gen.random_box(rng) if i % 2 == 0 else peg, p["count"],
                                  lambda i: m, lambda i, _: labels[i % 4])
    out = []
    for i in range(p["count"]):
        body = gen.random_box(rng) if i % 2 == 0 else peg
        pl = gen.place(rng, body)
        label = labels[i % 4]
        k = int(rng.integers(8, 31))
        for _ in range(100):
            base = gen.sample_rows(rng, pl, k, one_sided=label != "some")
            extra = []
            for _ in range(m - k):
                kind = int(rng.integers(4))
                j = int(rng.integers(k))
                if kind == 0:
                    extra.append(base[j].copy())
                elif kind == 1:
                    extra.append(base[j] * float(rng.choice([0.5, 3.0])))
                elif kind == 2:
                    g = rng.standard_normal(6)
                    eps = float(rng.choice([1e-6, 1e-8, 1e-10, 1e-12]))
                    extra.append(base[j] + eps * np.linalg.norm(base[j]) * g / np.linalg.norm(g))
                else:
                    extra.append(0.5 * (base[j] + base[(j + 1 + int(rng.integers(k - 1))) % k]))
            J = np.vstack([base, np.array(extra)])[rng.permutation(m)]
            au = gen.make_au(rng, J, label)
            if au is not None:
                break
        else:
            raise RuntimeError(f"{name} {i}: no au with label {label}")
        out.append(gen.record(f"{name}-{i:04d}", pl.M, au, J, tags={"body": body.name, "distinct": k}))
    return out


def chunk_instances(family: str, seed: int, index: int, size: int = CHUNK_SIZE) -> list[Instance]:
    """The instances of one chunk (see the top of this file)."""
    gen = generator()
    if family not in family_names():
        raise ValueError(f"no QP family {family!r} (families: {', '.join(family_names())})")
    params = dict(gen.family_params()[family]) if family in gen.SEEDS else {}
    if size < 1:
        raise ValueError(f"a chunk of {size} instances")
    if family == ROW_SCALED:
        return _row_scaled_chunk(seed, index, size)
    params["count"] = chunk_size(family, size)
    if family == "warm":
        params.update(sequences=params["count"] // WARM_STEPS, steps=WARM_STEPS)
    if family in gen.SEEDS:
        records = gen.BUILDERS[family](Generator(PCG64([seed, gen.SEEDS[family], index])), params)
    else:
        records = _many_rows(family, Generator(PCG64([seed, MANY_ROWS[family][0], index])), params)
    where = f"seeded {family} seed {seed} chunk {index}"
    out = []
    for k, rec in enumerate(records):
        rec["id"] = f"{family}-s{seed}-c{index}-{k:04d}"
        out.append(from_record(where, k, rec))
    return out


def chunk_size(family: str, size: int = CHUNK_SIZE) -> int:
    """Instances in a chunk of `size` of the family (warm: whole sequences; row_scaled: pairs)."""
    if family == ROW_SCALED:
        return 2 * max(size // 2, 1)
    return max(size // WARM_STEPS, 1) * WARM_STEPS if family == "warm" else size
