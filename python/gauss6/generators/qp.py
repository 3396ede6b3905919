"""Seeded generator of the quasi-static projection instances (METHOD.md sections 2-3).

Each instance is one problem  ac = argmin 1/2 (a - au)^T M (a - au)  s.t.  J a >= b,
with M = diag(m I3, I_G) the god-object's generalised mass (world frame), J the
m x 6 contact Jacobian (row k = [n_k^T, (G I_k x n_k)^T], n_k unit, pointing from
the obstacle into the god-object), au the unconstrained step and b the offsets
(zeros except in the `offsets` family). Units: metres, kilograms, radians.

The families and the file format are described in datasets_generated/qp/README.md.
Everything is drawn from numpy's PCG64 with a fixed seed per family, so running
the generator twice writes byte-identical files; MANIFEST.json records the
sha256 of each output and of this source.

Usage:  python -m gauss6.generators.qp [--out DIR]   (gauss6.qp_instances.generate runs it)
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

# numpy's OpenBLAS picks its kernels by CPU, and the last bits of small matrix
# products differ between its AVX-512 (SkylakeX) and AVX2 (Haswell, Zen) kernels:
# the files would depend on the machine that wrote them. Pin the AVX2 kernels on
# x86-64 (which MANIFEST.json was written with); OpenBLAS reads this when numpy
# loads it, so the generator must run in a process of its own (qp_instances.generate).
if platform.machine() in ("x86_64", "AMD64"):
    os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")

import numpy as np  # noqa: E402
from numpy.random import PCG64, Generator  # noqa: E402
from scipy.optimize import linprog  # noqa: E402

from .. import paths  # noqa: E402
from . import source  # noqa: E402

FORMAT = "gauss6-qp-instances"
FORMAT_VERSION = 1
GENERATOR = source(__spec__.name)[0]
GENERATOR_VERSION = "1"

# The meshes as the files name them; read from the datasets folder (mesh_file).
PEG_MESH = "datasets_generated/peg_in_hole/peg.off"
BUNNY_MESH = "datasets_generated/bunny/bunny.off"

DENSITY = 7800.0            # kg/m^3 (steel), every body
LIN_SCALE = (1e-4, 1e-2)    # m: log-uniform range of the linear part of au (haptic step)
ANG_SCALE = (1e-3, 1e-1)    # rad: log-uniform range of the angular part of au
POSITION_RANGE = 0.1        # m: G is drawn uniformly in [-0.1, 0.1]^3
SIGN_MARGIN = 1e-9          # |J_k au| must exceed this times sum_i |J_ki au_i| (label robustness)
PUSH_FILTER = 0.25          # one-sided contact sets: n_out . u >= this for a random u
LABELS = ("all", "some", "none")

# Family name -> seed. Names are part of the format (README.md).
SEEDS = {"box": 1001, "peg": 1002, "bunny": 1003, "m50": 1004, "redundant": 1005,
         "inertia": 1006, "offsets": 1007, "warm": 1008}


# --------------------------------------------------------------------------------------
# Bodies: mass properties and contact samplers (body frame, coordinates relative to G)
# --------------------------------------------------------------------------------------

@dataclass
class Body:
    name: str
    mass: float
    inertia: np.ndarray  # 3x3, about G, body axes
    # sample(rng, n) -> (points (n,3) relative to G, outward unit normals (n,3)), body frame
    sample: Callable[[Generator, int], tuple[np.ndarray, np.ndarray]]
    tags: dict


def box_body(dims: np.ndarray) -> Body:
    """Solid box of side lengths dims (m) centred on G: closed-form mass properties.

    Contacts: 80% on a face (area-weighted), 15% on an edge (normal in the edge's normal
    cone), 5% at a vertex (normal a positive combination of its three face normals).
    """
    dims = np.asarray(dims, dtype=float)
    h = dims / 2
    mass = DENSITY * float(np.prod(dims))
    inertia = np.diag(mass / 12 * np.array([dims[1] ** 2 + dims[2] ** 2,
                                            dims[0] ** 2 + dims[2] ** 2,
                                            dims[0] ** 2 + dims[1] ** 2]))
    areas = np.array([dims[1] * dims[2], dims[0] * dims[2], dims[0] * dims[1]])

    def sample(rng: Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
        pts = np.empty((n, 3))
        nrm = np.empty((n, 3))
        for i in range(n):
            kind = rng.random()
            sign = rng.choice([-1.0, 1.0], size=3)
            p = rng.uniform(-h, h)
            if kind < 0.8:  # face: axis chosen by area
                ax = rng.choice(3, p=areas / areas.sum())
                p[ax] = sign[ax] * h[ax]
                nv = np.zeros(3)
                nv[ax] = sign[ax]
            elif kind < 0.95:  # edge: two coordinates on the boundary
                free = rng.integers(3)
                axes = [a for a in range(3) if a != free]
                nv = np.zeros(3)
                theta = rng.uniform(0.0, math.pi / 2)
                for a, w in zip(axes, (math.cos(theta), math.sin(theta))):
                    p[a] = sign[a] * h[a]
                    nv[a] = sign[a] * w
            else:  # vertex
                p = sign * h
                w = rng.uniform(0.05, 1.0, size=3)
                nv = sign * w
            pts[i] = p
            nrm[i] = nv / np.linalg.norm(nv)
        return pts, nrm

    return Body("box", mass, inertia, sample, {"dims": dims.tolist()})


def read_off(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Minimal OFF reader: (V (n,3) float, F (f,3) int); polygons are fan-triangulated."""
    tokens: list[str] = []
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            tokens.extend(line.split())
    if not tokens or not tokens[0].upper().endswith("OFF"):
        raise ValueError(f"{path}: not an OFF file")
    pos = 1
    nv, nf = int(tokens[pos]), int(tokens[pos + 1])
    pos += 3
    V = np.array(tokens[pos:pos + 3 * nv], dtype=float).reshape(nv, 3)
    pos += 3 * nv
    faces = []
    for _ in range(nf):
        k = int(tokens[pos])
        idx = [int(t) for t in tokens[pos + 1:pos + 1 + k]]
        pos += 1 + k
        faces.extend([idx[0], idx[j], idx[j + 1]] for j in range(1, k - 1))
    return V, np.array(faces, dtype=np.int64)


def mesh_mass_properties(V: np.ndarray, F: np.ndarray, density: float) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it) of a closed outward-oriented mesh.

    Divergence theorem: sum of signed tetrahedra (o, a, b, c) over the triangles, o the
    vertex mean (for precision). For one tetrahedron, int x x^T dV = det/120 (S + s s^T)
    with S = a a^T + b b^T + c c^T and s = a + b + c (relative to o).
    """
    o = V.mean(axis=0)
    a, b, c = (V[F[:, i]] - o for i in range(3))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x signed volume
    vol = det.sum() / 6
    if not vol > 0:
        raise ValueError("mesh volume is not positive (open or inside-out)")
    s = a + b + c
    first = (det[:, None] * s).sum(axis=0) / 24           # int x dV
    second = (np.einsum("i,ij,ik->jk", det, a, a) + np.einsum("i,ij,ik->jk", det, b, b)
              + np.einsum("i,ij,ik->jk", det, c, c) + np.einsum("i,ij,ik->jk", det, s, s)) / 120
    mass = density * vol
    com_rel = first / vol
    cov = density * second - mass * np.outer(com_rel, com_rel)  # about the centre of mass
    inertia = np.trace(cov) * np.eye(3) - cov
    inertia = (inertia + inertia.T) / 2
    return float(mass), o + com_rel, inertia


def mesh_file(relpath: str) -> Path:
    """A mesh named as the files record it (datasets_generated/...), in the datasets folder
    (paths.DATASETS_DIR: GAUSS6_DATASETS_DIR, else the checkout's)."""
    return paths.DATASETS_DIR / Path(relpath).relative_to("datasets_generated")


def mesh_body(name: str, relpath: str) -> Body:
    """A body from an OFF mesh: mass properties at DENSITY, G its centre of mass,
    contacts area-weighted on the triangles with the face normal."""
    path = mesh_file(relpath)
    V, F = read_off(path)
    mass, com, inertia = mesh_mass_properties(V, F, DENSITY)
    P = V - com
    e1 = P[F[:, 1]] - P[F[:, 0]]
    e2 = P[F[:, 2]] - P[F[:, 0]]
    cr = np.cross(e1, e2)
    dbl_area = np.linalg.norm(cr, axis=1)
    keep = dbl_area > 0
    faces, cr, dbl_area = F[keep], cr[keep], dbl_area[keep]
    normals = cr / dbl_area[:, None]
    prob = dbl_area / dbl_area.sum()

    def sample(rng: Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
        f = rng.choice(len(faces), size=n, p=prob)
        r1, r2 = rng.random(n), rng.random(n)
        flip = r1 + r2 > 1  # uniform on the triangle
        r1[flip], r2[flip] = 1 - r1[flip], 1 - r2[flip]
        tri = P[faces[f]]
        pts = tri[:, 0] + r1[:, None] * (tri[:, 1] - tri[:, 0]) + r2[:, None] * (tri[:, 2] - tri[:, 0])
        return pts, normals[f].copy()

    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    return Body(name, mass, inertia, sample, {"mesh": relpath, "mesh_sha256": digest})


# --------------------------------------------------------------------------------------
# Poses, contacts, Jacobians
# --------------------------------------------------------------------------------------

def random_rotation(rng: Generator) -> np.ndarray:
    q = rng.standard_normal(4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@dataclass
class Placed:
    """A body at a world pose: G = p, orientation R; M its world-frame generalised mass."""
    body: Body
    p: np.ndarray
    R: np.ndarray
    M: np.ndarray


def place(rng: Generator, body: Body) -> Placed:
    R = random_rotation(rng)
    p = rng.uniform(-POSITION_RANGE, POSITION_RANGE, size=3)
    I_w = R @ body.inertia @ R.T
    M = np.zeros((6, 6))
    M[:3, :3] = body.mass * np.eye(3)
    M[3:, 3:] = (I_w + I_w.T) / 2  # exactly symmetric
    return Placed(body, p, R, M)


def contact_rows(pl: Placed, r_B: np.ndarray, nout_B: np.ndarray) -> np.ndarray:
    """Rows J_k = [n_k, (I_k - G) x n_k] of contacts at body points r_B with outward
    normals nout_B: I_k = p + R r, n_k = -R nout (from the obstacle into the body)."""
    I = pl.p + r_B @ pl.R.T
    n = -(nout_B @ pl.R.T)
    n /= np.linalg.norm(n, axis=1)[:, None]
    return np.hstack([n, np.cross(I - pl.p, n)])


def sample_rows(rng: Generator, pl: Placed, m: int, one_sided: bool) -> np.ndarray:
    """m contact rows on the placed body. one_sided: only contacts whose outward normal
    has n_out . u >= PUSH_FILTER for a random unit u, so that the translation -u is
    strictly feasible (the cone J d > 0 has an interior)."""
    if not one_sided:
        return contact_rows(pl, *pl.body.sample(rng, m))
    u = rng.standard_normal(3)
    u /= np.linalg.norm(u)
    pts, nrm = np.empty((0, 3)), np.empty((0, 3))
    while len(pts) < m:
        p, n = pl.body.sample(rng, 4 * m)
        ok = n @ u >= PUSH_FILTER
        pts, nrm = np.vstack([pts, p[ok]]), np.vstack([nrm, n[ok]])
    return contact_rows(pl, pts[:m], nrm[:m])


# --------------------------------------------------------------------------------------
# Unconstrained steps au with a given push label
# --------------------------------------------------------------------------------------

def loguniform(rng: Generator, lo_hi: tuple[float, float]) -> float:
    lo, hi = lo_hi
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def step_scales(rng: Generator) -> np.ndarray:
    """Per-component scale S of au: 3 x linear (m), 3 x angular (rad)."""
    return np.array([loguniform(rng, LIN_SCALE)] * 3 + [loguniform(rng, ANG_SCALE)] * 3)


def push_label(J: np.ndarray, au: np.ndarray) -> str | None:
    """'all' (every J_k au < 0), 'none' (J au >= 0) or 'some'; None when a J_k au is so
    close to 0 that another summation order could flip its sign (SIGN_MARGIN)."""
    if len(J) == 0:
        return "none"
    d = J @ au
    if np.any(np.abs(d) <= SIGN_MARGIN * (np.abs(J) @ np.abs(au))):
        return None
    neg = d < 0
    return "all" if neg.all() else ("none" if not neg.any() else "some")


def strict_direction(A: np.ndarray) -> tuple[np.ndarray, float] | None:
    """y in [-1,1]^6 maximising t = min_k (A_k y) / |A_k| (LP, HiGHS); None when the cone
    {A y > 0} has no interior. y is rounded to a 2^-20 grid so that last-bit differences
    between LP solver builds do not change the data."""
    norms = np.linalg.norm(A, axis=1)
    An = A / norms[:, None]
    m = len(A)
    # variables (y, t): minimise -t s.t. t - An y <= 0, y in [-1,1], t <= 1
    res = linprog(c=np.r_[np.zeros(6), -1.0], A_ub=np.hstack([-An, np.ones((m, 1))]),
                  b_ub=np.zeros(m), bounds=[(-1, 1)] * 6 + [(None, 1)], method="highs")
    if res.status != 0 or -res.fun < 1e-6:
        return None
    y = np.round(res.x[:6] * 2.0 ** 20) / 2.0 ** 20
    t = float(np.min(An @ y))
    return (y, t) if t > 1e-7 else None


def make_au(rng: Generator, J: np.ndarray, label: str, S: np.ndarray | None = None) -> np.ndarray | None:
    """An au of haptic-step size with the given push label, or None if impossible.

    all/none: au = -/+ S (y + c r), y a strictly feasible direction of the scaled cone
    {J S y > 0}, r random in [-1,1]^6 and c small enough to keep every sign strict.
    some: rejection over random au = S r."""
    if S is None:
        S = step_scales(rng)
    A = J * S[None, :]
    if label in ("all", "none"):
        sd = strict_direction(A)
        if sd is None:
            return None
        y, t = sd
        r = rng.uniform(-1, 1, size=6)
        An = A / np.linalg.norm(A, axis=1)[:, None]
        c = 0.5 * t / max(float(np.max(np.abs(An @ r))), 1e-300) * rng.random()
        au = (-1.0 if label == "all" else 1.0) * S * (y + c * r)
        return au if push_label(J, au) == label else None
    if len(J) < 2:
        return None
    for _ in range(200):
        au = S * rng.uniform(-1, 1, size=6)
        if push_label(J, au) == "some":
            return au
    return None


def first_au(rng: Generator, J: np.ndarray, labels: tuple[str, ...], attempts: int = 100) -> np.ndarray:
    """make_au with the first of `labels` that it can make, tried in turn (rows that
    allow no au of a label: 'some' for one row, 'all'/'none' without an interior, and
    'some' by a rejection that can fail). The seeded campaign's offsets family once drew
    a single row for which the old fallback, 'some' alone, gave no au (an instance
    without au, chunk 1150 of `crosscheck qp --seeded 1000000`). The first label's
    success draws exactly what make_au drew before, so the stored files are unchanged."""
    for _ in range(attempts):
        for label in labels:
            au = make_au(rng, J, label)
            if au is not None:
                return au
    raise RuntimeError(f"no au with any of the labels {labels} for {len(J)} rows")


def rows_and_au(rng: Generator, pl: Placed, m: int, label: str) -> tuple[np.ndarray, np.ndarray]:
    """Contact rows on pl and an au with the label: for all/none, first try contacts all
    around the body, then one-sided contact sets (which always have an interior)."""
    for attempt in range(100):
        one_sided = label != "some" and (attempt >= 2 or m > 6)
        J = sample_rows(rng, pl, m, one_sided)
        au = make_au(rng, J, label)
        if au is not None:
            return J, au
    raise RuntimeError(f"no au with label {label} for m = {m}")


def cycle_label(i: int, m: int, labels: tuple[str, ...] = LABELS) -> str:
    """Labels in turn; with one row 'some' is impossible, so alternate all/none instead."""
    lab = labels[i % len(labels)]
    if m < 2 and lab == "some":
        lab = ("all", "none")[(i // len(labels)) % 2]
    return lab


def record(iid: str, M: np.ndarray, au: np.ndarray, J: np.ndarray, b: np.ndarray | None = None,
           sequence: int = -1, step: int = -1, tags: dict | None = None) -> dict:
    """One instance as a JSON-ready dict; the push label is computed from the data."""
    J = np.asarray(J, dtype=float).reshape(-1, 6)
    b = np.zeros(len(J)) if b is None else np.asarray(b, dtype=float)
    push = push_label(J, au)
    if push is None:
        raise RuntimeError(f"{iid}: a J_k au is too close to 0 to label")
    rec = {"id": iid, "M": M.tolist(), "au": au.tolist(), "J": J.tolist(), "b": b.tolist(),
           "push": push, "sequence": sequence, "step": step}
    if tags:
        rec["tags"] = tags
    return rec


# --------------------------------------------------------------------------------------
# Families
# --------------------------------------------------------------------------------------

def random_box(rng: Generator) -> Body:
    return box_body(rng.uniform(0.01, 0.1, size=3))


def contact_family(name: str, rng: Generator, bodies: Callable[[int], Body], count: int,
                   m_of: Callable[[int], int], label_of: Callable[[int, int], str]) -> list[dict]:
    """count instances: body bodies(i) at a random pose, m_of(i) contacts, label_of(i, m)."""
    out = []
    for i in range(count):
        body = bodies(i)
        pl = place(rng, body)
        m = m_of(i)
        J, au = rows_and_au(rng, pl, m, label_of(i, m))
        out.append(record(f"{name}-{i:04d}", pl.M, au, J, tags={"body": body.name, **body.tags}))
    return out


def family_box(rng: Generator, p: dict) -> list[dict]:
    # m = 1..12 in turn; over successive rounds of 12 the labels go all, some, none.
    return contact_family("box", rng, lambda i: random_box(rng), p["count"], lambda i: 1 + i % 12,
                          lambda i, m: cycle_label(i // 12, m))


def family_mesh(name: str, rng: Generator, p: dict) -> list[dict]:
    body = mesh_body(name, p["mesh"])
    return contact_family(name, rng, lambda i: body, p["count"], lambda i: 1 + i % 12,
                          lambda i, m: cycle_label(i // 12, m))


def family_m50(rng: Generator, p: dict) -> list[dict]:
    peg = mesh_body("peg", PEG_MESH)
    return contact_family("m50", rng, lambda i: random_box(rng) if i % 2 == 0 else peg,
                          p["count"], lambda i: 50, lambda i, m: ("all", "all", "some", "some")[i % 4])


def family_redundant(rng: Generator, p: dict) -> list[dict]:
    """Distinct contact rows plus copies: exact duplicates, scaled copies (x0.5, x3),
    copies perturbed by a relative eps, averages of two rows; 'm50' mixes them all on 8
    distinct rows. Rows are shuffled; tags.base_rows lists the distinct ones."""
    peg = mesh_body("peg", PEG_MESH)
    kinds = p["kinds"]
    eps_all = [1e-6, 1e-8, 1e-10, 1e-12]
    out = []
    for i in range(p["count"]):
        kind = kinds[i % len(kinds)]
        body = random_box(rng) if i % 2 == 0 else peg
        pl = place(rng, body)
        label = LABELS[(i // len(kinds)) % 3]
        k = 8 if kind == "m50" else int(rng.integers(2, 7))
        n_extra = 42 if kind == "m50" else int(rng.integers(1, k + 1))
        for _ in range(100):
            base = sample_rows(rng, pl, k, one_sided=label != "some")
            extra, eps_used = [], []
            for _ in range(n_extra):
                sub = kind if kind != "m50" else str(rng.choice(["duplicate", "scaled", "perturbed", "average"]))
                j = int(rng.integers(k))
                if sub == "duplicate":
                    extra.append(base[j].copy())
                elif sub == "scaled":
                    extra.append(base[j] * float(rng.choice([0.5, 3.0])))
                elif sub.startswith("perturbed"):
                    eps = float(sub.split("_")[1]) if "_" in sub else float(rng.choice(eps_all))
                    g = rng.standard_normal(6)
                    extra.append(base[j] + eps * np.linalg.norm(base[j]) * g / np.linalg.norm(g))
                    eps_used.append(eps)
                else:  # average of two distinct rows
                    j2 = (j + 1 + int(rng.integers(k - 1))) % k
                    extra.append(0.5 * (base[j] + base[j2]))
            J = np.vstack([base, np.array(extra)])
            perm = rng.permutation(len(J))
            J = J[perm]
            au = make_au(rng, J, label)
            if au is not None:
                break
        else:
            raise RuntimeError(f"redundant {i}: no au with label {label}")
        tags = {"body": body.name, "kind": kind, "distinct": k,
                "base_rows": sorted(int(np.where(perm == j)[0][0]) for j in range(k))}
        if eps_used:
            tags["eps"] = sorted(set(eps_used))
        out.append(record(f"redundant-{i:04d}", pl.M, au, J, tags=tags))
    return out


def family_inertia(rng: Generator, p: dict) -> list[dict]:
    """Long thin boxes L x w x w with (L^2 + w^2) / (2 w^2) = ratio (max/min eigenvalue of
    I_G), at random orientations; the long axis is a random body axis."""
    out = []
    per = p["count"] // len(p["ratios"])
    for i in range(p["count"]):
        ratio = p["ratios"][i // per]
        L = rng.uniform(0.05, 0.2)
        w = L / math.sqrt(2 * ratio - 1)
        dims = np.roll(np.array([L, w, w]), int(rng.integers(3)))
        body = box_body(dims)
        pl = place(rng, body)
        m = 1 + i % 12
        J, au = rows_and_au(rng, pl, m, cycle_label(i // 12, m))
        ev = np.linalg.eigvalsh(pl.M[3:, 3:])
        out.append(record(f"inertia-{i:04d}", pl.M, au, J,
                          tags={"body": "box", "dims": dims.tolist(), "inertia_ratio_target": ratio,
                                "inertia_ratio": float(ev[-1] / ev[0])}))
    return out


def family_offsets(rng: Generator, p: dict) -> list[dict]:
    """Right-hand sides b != 0. Per ten instances:
    6 'ramp': METHOD.md section 3. au0 is the step when the set arrived, d = J au0; rows with
      d_k < eps (eps < 0) get b_k = d_k (1 - s), s = t/T in [0, 1] (linear f_k); the others
      b_k = 0. au = au0 + a drift. Feasible (b <= 0: a = 0 is a witness).
    3 'positive': b_k > 0 on some rows, feasible by construction: b = J w - slack, w the witness.
    1 'infeasible': a row J_j and an opposite row -c J_j (c in {1, 2}, exact) with b_j, b' > 0;
      Farkas certificate y >= 0, y^T J = 0 exactly, y^T b > 0.
    tags: kind, feasible, and witness (feasible) or farkas_y (infeasible)."""
    peg = mesh_body("peg", PEG_MESH)
    out = []
    for i in range(p["count"]):
        body = random_box(rng) if i % 2 == 0 else peg
        pl = place(rng, body)
        slot = i % 10
        tags: dict = {"body": body.name}
        if slot < 6:
            m = int(rng.integers(2, 13))
            while True:
                J, au0 = rows_and_au(rng, pl, m, ("all", "some")[slot % 2])
                eps = -loguniform(rng, tuple(p["eps_range"]))
                d = J @ au0
                if np.any(d < eps):
                    break
            s = float(rng.choice([0.0, 1.0, rng.random(), rng.random()]))
            b = np.where(d < eps, d * (1.0 - s), 0.0) + 0.0  # + 0.0: no -0.0 when s = 1
            while True:
                au = au0 + 0.1 * step_scales(rng) * rng.uniform(-1, 1, size=6)
                if push_label(J, au) is not None:
                    break
            tags.update(kind="ramp", feasible=True, eps=eps, t_over_T=s, witness=[0.0] * 6)
        elif slot < 9:
            # slots 6, 7: contacts all around, a random witness w with some J_k w > 0;
            # slot 8: one-sided contacts, w strictly feasible, so every b_k > 0.
            m = int(rng.integers(1, 13))
            J = sample_rows(rng, pl, m, one_sided=slot == 8)
            while True:
                S = step_scales(rng)
                sd = strict_direction(J * S) if slot == 8 else None
                w = S * (sd[0] if sd is not None else rng.uniform(-1, 1, size=6))
                dw = J @ w
                if np.any(dw > 0) and (slot != 8 or np.all(dw > 0)):
                    break
            u = rng.uniform(0.05, 0.9, size=m)
            b = np.where(dw > 0, dw * u, dw * (1.0 + u))  # b <= J w, with a margin
            # No interior (e.g. a form-closed set): only 'some' is possible; one row: no 'some'.
            au = first_au(rng, J, (cycle_label(i, m), "some", "all", "none"))
            tags.update(kind="positive", feasible=True, witness=w.tolist())
        else:
            k = int(rng.integers(1, 8))
            J = sample_rows(rng, pl, k, one_sided=False)
            j = int(rng.integers(k))
            c = float(rng.choice([1.0, 2.0]))
            at = int(rng.integers(k + 1))
            J = np.insert(J, at, -c * J[j], axis=0)
            j = j + (1 if at <= j else 0)
            b = np.zeros(k + 1)
            b[j] = loguniform(rng, (1e-5, 1e-3))
            b[at] = loguniform(rng, (1e-5, 1e-3))
            y = np.zeros(k + 1)
            y[j], y[at] = c, 1.0
            au = first_au(rng, J, ("some", "all", "none"))
            tags.update(kind="infeasible", feasible=False, farkas_y=y.tolist())
        out.append(record(f"offsets-{i:04d}", pl.M, au, J, b, tags=tags))
    return out


def family_warm(rng: Generator, p: dict) -> list[dict]:
    """Warm-start sequences: the god-object fixed, au(s) = S (c0 + A sin(w s + phi))
    drifting smoothly over the steps s, c0 pushing into the initial contacts. The contact
    set changes slowly: every 10 steps, with probability 1/2, one contact is added or
    dropped (1..5 contacts). tags.contact_set counts the changes so far."""
    peg = mesh_body("peg", PEG_MESH)
    out = []
    n_seq, n_step = p["sequences"], p["steps"]
    for sq in range(n_seq):
        body = random_box(rng) if sq % 2 == 0 else peg
        while True:
            pl = place(rng, body)
            J = sample_rows(rng, pl, int(rng.integers(1, 5)), one_sided=True)
            S = step_scales(rng)
            sd = strict_direction(J * S)
            if sd is None:
                continue
            c0 = -0.3 * sd[0] + 0.3 * rng.uniform(-1, 1, size=6)
            amp = rng.uniform(0.2, 1.0, size=6)
            omega = 2 * math.pi * rng.uniform(0.5, 2.0) / n_step
            phi = rng.uniform(0, 2 * math.pi, size=6)
            recs, cur, set_id = [], J, 0
            for st in range(n_step):
                if st > 0 and st % 10 == 0 and rng.random() < 0.5:
                    set_id += 1
                    if len(cur) < 5 and (len(cur) == 1 or rng.random() < 0.5):
                        cur = np.vstack([cur, sample_rows(rng, pl, 1, one_sided=False)])
                    else:
                        cur = np.delete(cur, int(rng.integers(len(cur))), axis=0)
                au = S * (c0 + amp * np.sin(omega * st + phi))
                if push_label(cur, au) is None:
                    break
                recs.append(record(f"warm-s{sq:02d}-k{st:02d}", pl.M, au, cur, sequence=sq, step=st,
                                   tags={"body": body.name, "contact_set": set_id}))
            if len(recs) == n_step:
                out.extend(recs)
                break
    return out


def family_params() -> dict[str, dict]:
    """The parameters of each family, as recorded in the files and in MANIFEST.json."""
    common = {"density": DENSITY, "lin_scale_m": list(LIN_SCALE), "ang_scale_rad": list(ANG_SCALE)}
    return {
        "box": {"count": 300, "m": [1, 12], "dims_m": [0.01, 0.1], **common},
        "peg": {"count": 300, "m": [1, 12], "mesh": PEG_MESH, **common},
        "bunny": {"count": 300, "m": [1, 12], "mesh": BUNNY_MESH, **common},
        "m50": {"count": 80, "m": [50, 50], "bodies": ["box", "peg"], **common},
        "redundant": {"count": 240, "kinds": ["duplicate", "scaled", "perturbed_1e-06", "perturbed_1e-08",
                                              "perturbed_1e-10", "perturbed_1e-12", "average", "m50"],
                      **common},
        "inertia": {"count": 200, "ratios": [1.0, 1e2, 1e4, 1e6], "m": [1, 12], **common},
        "offsets": {"count": 200, "eps_range": [1e-6, 1e-4], **common},
        "warm": {"count": 1000, "sequences": 20, "steps": 50, **common},
    }


BUILDERS = {
    "box": family_box,
    "peg": lambda rng, p: family_mesh("peg", rng, p),
    "bunny": lambda rng, p: family_mesh("bunny", rng, p),
    "m50": family_m50,
    "redundant": family_redundant,
    "inertia": family_inertia,
    "offsets": family_offsets,
    "warm": family_warm,
}


def source_sha256() -> str:
    return source(__spec__.name)[1]


def mesh_inputs(name: str) -> dict:
    """The meshes a family reads, with their sha256 (so a changed mesh shows in the manifest)."""
    used = {"peg": [PEG_MESH], "bunny": [BUNNY_MESH], "m50": [PEG_MESH], "redundant": [PEG_MESH],
            "offsets": [PEG_MESH], "warm": [PEG_MESH]}.get(name, [])
    return {m: hashlib.sha256(mesh_file(m).read_bytes()).hexdigest() for m in used}


def generate_family(name: str) -> dict:
    """The whole JSON document of one family."""
    params = {**family_params()[name], "inputs": mesh_inputs(name)}
    seed = SEEDS[name]
    instances = BUILDERS[name](Generator(PCG64(seed)), params)
    if len(instances) != params["count"]:
        raise RuntimeError(f"{name}: {len(instances)} instances, expected {params['count']}")
    return {"format": FORMAT, "version": FORMAT_VERSION, "family": name, "generator": GENERATOR,
            "generator_version": GENERATOR_VERSION, "seed": seed, "parameters": params,
            "source_sha256": source_sha256(), "instances": instances}


def dumps(doc: dict) -> str:
    """Compact JSON; floats as Python's shortest round-trip repr."""
    return json.dumps(doc, separators=(",", ":"), allow_nan=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=paths.DATASETS_DIR / "qp",
                    help="output directory (default: the datasets folder's qp/)")
    ap.add_argument("--family", action="append", choices=list(SEEDS), help="only these families (no manifest)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    names = args.family or list(SEEDS)
    outputs, params = {}, {}
    for name in names:
        t0 = time.perf_counter()
        doc = generate_family(name)
        text = dumps(doc).encode()
        (args.out / f"{name}.json").write_bytes(text)
        outputs[f"{name}.json"] = hashlib.sha256(text).hexdigest()
        params[name] = doc["parameters"]
        print(f"{name}: {len(doc['instances'])} instances, {len(text) / 1e3:.0f} kB, "
              f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
    if not args.family:
        manifest = {"generator": GENERATOR, "generator_version": GENERATOR_VERSION, "parameters": params,
                    "source_sha256": source_sha256(), "outputs": outputs}
        (args.out / "MANIFEST.json").write_text(json.dumps(manifest, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
