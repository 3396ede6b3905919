"""The peg-in-a-hole meshes of METHOD.md section 7: a peg of 288 triangles and a
box of 280 triangles with a through-hole along the Y axis, with a stated clearance.

Both meshes are closed, 2-manifold, oriented outward and free of degenerate
triangles; every coordinate is a correctly rounded double (computed in 40-digit
decimal arithmetic and rounded once), so the output does not depend on the
platform's libm and the same parameters give byte-identical OFF files.

Mesh frames (metres): the peg is a prism over a regular polygon, its axis the
Y axis, centred on the origin (its centre of mass). The box is centred on the
origin, its edges along X, Y, Z, and the hole's axis is the Y axis.

Clearance: the peg's polygon has its vertices on the circle of radius
peg_radius (its outermost points); the hole's polygon has apothem (innermost
distance to the axis) peg_radius + clearance. With the peg coaxial in the hole,
every point of the peg's side is within peg_radius of the axis and every point
of the hole's wall at least peg_radius + clearance from it, so the gap is at
least `clearance`; it equals `clearance` where a peg vertex faces the middle of
a hole edge, which the default side counts (72 and 54) make happen (at 0, 20,
40, ... degrees).

Made by `gauss6 datasets generate [--only peg_in_hole]` (gauss6.datasets).
"""
from __future__ import annotations

import decimal
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from . import source

GENERATOR_VERSION = "1"

# ---------------------------------------------------------------- parameters


@dataclass(frozen=True)
class PegInHoleParams:
    """All lengths in metres. The defaults give 288 peg and 280 box triangles."""

    peg_radius: float = 0.01        # circumradius of the peg's polygon (its outermost points)
    peg_length: float = 0.10        # along Y
    peg_sides: int = 72             # triangles: 2 * sides (side) + 2 * sides (two fan caps)
    clearance: float = 2.0e-4       # minimum gap peg side / hole wall when coaxial (2% of the radius)
    hole_sides: int = 54            # triangles: 2 * sides (wall)
    box_size: tuple[float, float, float] = (0.10, 0.06, 0.06)  # X, Y (the hole's length), Z
    box_segments_x: int = 5         # edges along X of each holed face's outline (2 cm each)
    box_segments_z: int = 3         # edges along Z of each holed face's outline (2 cm each)

    def validate(self) -> None:
        if not (self.peg_radius > 0 and self.peg_length > 0 and self.clearance > 0):
            raise ValueError("peg_radius, peg_length and clearance must be > 0")
        if self.peg_sides < 3 or self.hole_sides < 3:
            raise ValueError("peg_sides and hole_sides must be >= 3")
        if self.box_segments_x < 1 or self.box_segments_z < 1:
            raise ValueError("box_segments_x and box_segments_z must be >= 1")
        if min(self.box_size) <= 0:
            raise ValueError("box_size must be > 0 in every axis")
        # The hole's polygon (circumradius) must stay well inside the holed face.
        if 2.0 * self.hole_circumradius() >= min(self.box_size[0], self.box_size[2]):
            raise ValueError("the hole does not fit in the box's X-Z section")

    def hole_apothem(self) -> float:
        return self.peg_radius + self.clearance

    def hole_circumradius(self) -> float:
        return self.hole_apothem() / float(_cos_sin(1, 2 * self.hole_sides)[0])

    def to_json(self) -> dict:
        d = asdict(self)
        d["box_size"] = list(self.box_size)
        return d


# ---------------------------------------------- correctly rounded coordinates

_CTX = decimal.Context(prec=40)


def _pi() -> decimal.Decimal:
    """pi to 40 digits (Machin's formula), in _CTX."""
    def arctan_inv(x: int) -> decimal.Decimal:
        # arctan(1/x) = sum (-1)^k / ((2k+1) x^(2k+1))
        total, k = decimal.Decimal(0), 0
        term = _CTX.divide(decimal.Decimal(1), decimal.Decimal(x))
        x2 = decimal.Decimal(x * x)
        while True:
            t = _CTX.divide(term, decimal.Decimal(2 * k + 1))
            if t == 0 or abs(t) < decimal.Decimal("1e-45"):
                return total
            total = _CTX.add(total, t if k % 2 == 0 else -t)
            term = _CTX.divide(term, x2)
            k += 1
    return _CTX.multiply(decimal.Decimal(4),
                         _CTX.subtract(_CTX.multiply(decimal.Decimal(4), arctan_inv(5)), arctan_inv(239)))


_PI = _pi()


def _cos_sin(k: int, n: int) -> tuple[decimal.Decimal, decimal.Decimal]:
    """cos and sin of 2 pi k / n to 40 digits (Taylor series after reduction to [0, 2 pi))."""
    k %= n
    x = _CTX.divide(_CTX.multiply(_CTX.multiply(decimal.Decimal(2), _PI), decimal.Decimal(k)), decimal.Decimal(n))
    c, s = decimal.Decimal(0), decimal.Decimal(0)
    term, i = decimal.Decimal(1), 0   # term = x^i / i!
    while abs(term) > decimal.Decimal("1e-45") or i < 2:
        if i % 4 == 0:
            c = _CTX.add(c, term)
        elif i % 4 == 1:
            s = _CTX.add(s, term)
        elif i % 4 == 2:
            c = _CTX.subtract(c, term)
        else:
            s = _CTX.subtract(s, term)
        i += 1
        term = _CTX.divide(_CTX.multiply(term, x), decimal.Decimal(i))
    return c, s


def _ring(radius: float, num_sides: int, half_turns: int, y: float) -> list[tuple[float, float, float]]:
    """num_sides points (r cos a, y, r sin a), a = pi (2 i + half_turns) / num_sides, each
    coordinate rounded once from 40 digits; -0.0 is written as 0.0."""
    r = decimal.Decimal(radius)
    pts = []
    for i in range(num_sides):
        c, s = _cos_sin(2 * i + half_turns, 2 * num_sides)
        pts.append((float(_CTX.multiply(r, c)) + 0.0, y + 0.0, float(_CTX.multiply(r, s)) + 0.0))
    return pts


# ------------------------------------------------------------------ meshes


def make_peg(p: PegInHoleParams) -> tuple[np.ndarray, np.ndarray]:
    """The peg: (V, F), V (2 sides + 2) x 3 metres, F (4 sides) x 3, outward (counter-clockwise seen from outside)."""
    n, h = p.peg_sides, 0.5 * p.peg_length
    # Vertices: ring at y = -h (0..n-1), ring at y = +h (n..2n-1), cap centres 2n (y = -h), 2n+1 (y = +h).
    V = _ring(p.peg_radius, n, 0, -h) + _ring(p.peg_radius, n, 0, h) + [(0.0, -h, 0.0), (0.0, h, 0.0)]
    F = []
    for i in range(n):
        j = (i + 1) % n
        # Side quad (bottom i, bottom j, top j, top i): with angle a growing from +X to +Z,
        # the outward normal at angle a is (cos a, 0, sin a).
        F += [(i, n + i, n + j), (i, n + j, j)]
    for i in range(n):
        j = (i + 1) % n
        F.append((2 * n, i, j))          # cap at y = -h, normal -Y
        F.append((2 * n + 1, n + j, n + i))  # cap at y = +h, normal +Y
    return np.array(V, dtype=np.float64), np.array(F, dtype=np.int64)


def _outline(p: PegInHoleParams, y: float) -> list[tuple[float, float, float]]:
    """The holed face's outer rectangle at height y, counter-clockwise in the (x, z) angle
    (from +X towards +Z), starting at the corner (+X/2, -Z/2): box_segments_x edges along
    X and box_segments_z along Z on each side."""
    hx, hz = 0.5 * p.box_size[0], 0.5 * p.box_size[2]
    sx, sz = p.box_segments_x, p.box_segments_z

    def lerp(a: float, b: float, i: int, m: int) -> float:
        # Exact at the ends; interior points from one rounding of a + (b - a) i / m.
        return a if i == 0 else (b if i == m else a + (b - a) * i / m)

    pts = []
    pts += [(hx, y, lerp(-hz, hz, i, sz)) for i in range(sz)]     # right side, going +Z
    pts += [(lerp(hx, -hx, i, sx), y, hz) for i in range(sx)]     # top side, going -X
    pts += [(-hx, y, lerp(hz, -hz, i, sz)) for i in range(sz)]    # left side, going -Z
    pts += [(lerp(-hx, hx, i, sx), y, -hz) for i in range(sx)]    # bottom side, going +X
    return [(x + 0.0, yy + 0.0, z + 0.0) for x, yy, z in pts]


def _angle(pt: tuple[float, float, float]) -> float:
    """Angle of a point around the Y axis, from +X towards +Z, in [0, 2 pi). Only orders
    vertices (no coordinate depends on it); no two of them lie at close angles."""
    a = float(np.arctan2(pt[2], pt[0]))
    return a + 2 * np.pi if a < 0 else a


def _ring_triangles(inner: list, outer: list) -> list[tuple[int, int, int]]:
    """Triangulates the annulus between a convex inner loop and an outer loop, both
    counter-clockwise in angle around the axis, by merging their vertices in angle order:
    len(inner) + len(outer) triangles, each counter-clockwise (from +X towards +Z).
    Local indices: inner k -> k, outer k -> len(inner) + k.
    """
    ni, no = len(inner), len(outer)
    a_in = [_angle(q) for q in inner]
    # Start the outer loop at its first vertex at or after the inner loop's first vertex.
    a0 = a_in[0]
    a_out = [(_angle(q) - a0) % (2 * np.pi) for q in outer]
    start = int(np.argmin(a_out))
    order = [(start + k) % no for k in range(no)]
    ao = [a_out[o] for o in order] + [2 * np.pi + a_out[order[0]]]
    ai = [(a - a0) % (2 * np.pi) for a in a_in] + [2 * np.pi]
    tris = []
    i = j = 0
    while i < ni or j < no:
        advance_inner = j == no or (i < ni and ai[i + 1] <= ao[j + 1])
        oi, oj = ni + order[j % no], ni + order[(j + 1) % no]
        if advance_inner:
            tris.append(((i + 1) % ni, i % ni, oi))
            i += 1
        else:
            tris.append((i % ni, oi, oj))
            j += 1
    return tris


def make_box(p: PegInHoleParams) -> tuple[np.ndarray, np.ndarray]:
    """The box with the hole: (V, F), outward. Vertices: hole ring at y = -Y/2 (n), at
    y = +Y/2 (n), outline at y = -Y/2 (k), at y = +Y/2 (k)."""
    n, hy = p.hole_sides, 0.5 * p.box_size[1]
    # Hole vertices at angles pi (2 i + 1) / n: edge normals at 2 pi i / n (0 included),
    # so a peg vertex at angle 0 meets the middle of a hole edge.
    hole_lo = _ring(p.hole_circumradius(), n, 1, -hy)
    hole_hi = _ring(p.hole_circumradius(), n, 1, hy)
    out_lo, out_hi = _outline(p, -hy), _outline(p, hy)
    k = len(out_lo)
    V = hole_lo + hole_hi + out_lo + out_hi
    HL, HH, OL, OH = 0, n, 2 * n, 2 * n + k
    F = []
    # Hole wall: normals towards the axis (out of the solid).
    for i in range(n):
        j = (i + 1) % n
        F += [(HL + i, HL + j, HH + j), (HL + i, HH + j, HH + i)]
    # Outer band (four outer faces): normals away from the axis.
    for i in range(k):
        j = (i + 1) % k
        F += [(OL + i, OH + i, OH + j), (OL + i, OH + j, OL + j)]
    # The two holed faces: a triangle counter-clockwise in angle (from +X to +Z) has
    # normal -Y, right for the face at y = -Y/2; the face at y = +Y/2 is reversed.
    for a, b, c in _ring_triangles(hole_lo, out_lo):
        F.append(tuple(HL + t if t < n else OL + t - n for t in (a, b, c)))
    for a, b, c in _ring_triangles(hole_hi, out_hi):
        F.append(tuple(HH + t if t < n else OH + t - n for t in (a, c, b)))
    return np.array(V, dtype=np.float64), np.array(F, dtype=np.int64)


# ------------------------------------------------------------------- checks


def check_closed_manifold(F: np.ndarray) -> list[str]:
    """Problems with a closed, consistently oriented 2-manifold: every directed edge once,
    its reverse once; every vertex's faces one fan. Empty list when none."""
    problems = []
    directed = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    keys = {tuple(e) for e in directed.tolist()}
    if len(keys) != len(directed):
        problems.append("a directed edge is used twice (inconsistent orientation or non-manifold edge)")
    if any((b, a) not in keys for a, b in keys):
        problems.append("an edge has no opposite half-edge (open boundary)")
    # Vertex manifoldness: the faces around each vertex form one cycle.
    nxt: dict[int, dict[int, int]] = {}
    for a, b, c in F.tolist():
        for v, x, y in ((a, b, c), (b, c, a), (c, a, b)):
            nxt.setdefault(v, {})[x] = y
    for v, m in nxt.items():
        start = next(iter(m))
        x, steps = start, 0
        while True:
            x = m.get(x)
            steps += 1
            if x is None or x == start or steps > len(m):
                break
        if x != start or steps != len(m):
            problems.append(f"vertex {v} is not manifold (its faces do not form one fan)")
            break
    return problems


def signed_volume(V: np.ndarray, F: np.ndarray) -> float:
    """Volume enclosed by a closed mesh, > 0 when it is oriented outward."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _self_check(p: PegInHoleParams, name: str, V: np.ndarray, F: np.ndarray, expected_volume: float) -> None:
    """Fails loudly if the mesh is not closed, manifold, outward, non-degenerate, or if its
    planar faces are not exactly tiled (volume equal to the solid's, to rounding)."""
    problems = check_closed_manifold(F)
    areas = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    scale = float(np.abs(V).max())
    if areas.min() <= 1e-6 * scale * scale:
        problems.append(f"degenerate triangle (area {areas.min():.3g} m^2)")
    vol = signed_volume(V, F)
    # A fold or overlap in a planar face would change the volume by a triangle's worth;
    # rounding of 40-digit coordinates changes it by about 1e-16 relative.
    if abs(vol - expected_volume) > 1e-12 * abs(expected_volume):
        problems.append(f"volume {vol!r} differs from the solid's {expected_volume!r}")
    if problems:
        raise RuntimeError(f"{name}: " + "; ".join(problems) + f" (parameters {p})")


def _polygon_area(circumradius: float, n: int) -> float:
    return 0.5 * n * circumradius ** 2 * float(_cos_sin(1, n)[1])


# ------------------------------------------------------------------- output


def off_text(V: np.ndarray, F: np.ndarray, header: list[str]) -> str:
    """OFF text: 'OFF', '# ' header lines, counts, vertices (shortest round-trip decimal
    of each double: exact), triangles."""
    lines = ["OFF"] + [f"# {h}" for h in header] + [f"{len(V)} {len(F)} 0"]
    lines += [" ".join(repr(float(x) + 0.0) for x in v) for v in V.tolist()]
    lines += ["3 " + " ".join(str(int(i)) for i in f) for f in F.tolist()]
    return "\n".join(lines) + "\n"


def provenance_header(generator: str, parameters: dict, source_sha: str) -> list[str]:
    """The comment lines every generated OFF starts with (same fields as MANIFEST.json)."""
    return [f"generator: {generator}",
            f"generator_version: {GENERATOR_VERSION}",
            f"parameters: {json.dumps(parameters, sort_keys=True)}",
            f"source_sha256: {source_sha}"]


def generate(out_dir: Path, params: PegInHoleParams | None = None) -> dict[str, str]:
    """Writes peg.off and box_with_hole.off into out_dir; returns {filename: text}."""
    p = params or PegInHoleParams()
    p.validate()
    peg_V, peg_F = make_peg(p)
    box_V, box_F = make_box(p)
    _self_check(p, "peg", peg_V, peg_F, _polygon_area(p.peg_radius, p.peg_sides) * p.peg_length)
    box_volume = p.box_size[1] * (p.box_size[0] * p.box_size[2] - _polygon_area(p.hole_circumradius(), p.hole_sides))
    _self_check(p, "box_with_hole", box_V, box_F, box_volume)

    relpath, sha = source(__spec__.name)
    header = provenance_header(relpath, p.to_json(), sha)
    texts = {"peg.off": off_text(peg_V, peg_F, header), "box_with_hole.off": off_text(box_V, box_F, header)}
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, text in texts.items():
        (out_dir / name).write_bytes(text.encode("ascii"))
    return texts

