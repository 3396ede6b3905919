"""The conformance battery's meshes and hand scripts: one scene per failure mode that haptic
engines are known to have (docs/conformance-battery.md says what each stresses and what a correct
engine must show). Each maker takes the failure mode's parameters (a wall's thickness, a slot's
clearance, a plate's tessellation density, ...), so that other instances of the same failure
mode come from the same code; the defaults give the committed scenes.

- thin_wall: a vertical plate of `wall_thickness` (0.2 mm) hit at `hit_speed` (2 m/s: 2 mm a
  1 kHz tick, ten times the wall) by an octahedral probe, head-on and at seeded points and
  angles, then on its top rim.
- slot: two jaws with a gap of a blade's thickness plus 2 `slot_clearance` (4 delta a side); the
  blade slides through, twists in the slot's plane (free) and rolls about the slot's axis
  (jammed after 2 clearance / width radians).
- wedge: a V-groove and a matching truncated wedge pushed into it, rocked, and released.
- pry_hook: a ledge over a floor and an L-shaped hook: the hook's foot is hooked under the
  ledge and pulled up, then levered (heel on the floor, toe against the ledge).
- knife_vertex: a knife-edged prism of apex `knife_angle_deg` and a square spike; the probe's
  vertex slides along the knife, its face rests on it, its vertex meets the spike's apex.
- dense_plate: a plate whose top is a seeded, jittered grid of `plate_divisions`^2 squares
  (12,800 coplanar triangles at 1 mm); a 4 x 4 cm puck lands flat on it (about 3,200 triangles
  in the contact patch), slides, twists and rocks.
- cup: a cup (surface of revolution of `cup_segments` sides, filleted inside) and a round
  probe dragged around inside along the wall and floor.
- lever: a long thin rod held at one end (G at the end, `rod_length` 30 cm) whose far tip
  presses and slides on a block: torque = lever arm x force.

Every mesh is checked closed, 2-manifold, outward and non-degenerate here (and free of
self-intersections by the tests, with exact predicates); coordinates that need cos/sin come
from the peg generator's 40-digit arithmetic, so the files do not depend on the platform's libm,
and the same parameters give byte-identical files. The seeded parts draw from numpy's PCG64.

Made by `gauss6 datasets generate [--only battery]` (gauss6.datasets).
"""
from __future__ import annotations

import decimal
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from . import peg_in_hole as peg, source

GENERATOR_VERSION = "1"


# ---------------------------------------------------------------- parameters


@dataclass(frozen=True)
class BatteryParams:
    """Lengths in metres, angles in whole degrees, speeds in m/s, times in seconds."""

    seed: int = 1
    probe_radius: float = 0.005          # the octahedral probe (thin_wall, knife_vertex)
    # thin_wall
    wall_thickness: float = 0.0002
    wall_size: tuple = (0.10, 0.08)      # along Y, Z (its base at z = 0)
    hit_speed: float = 2.0
    hit_depth: float = 0.002             # how far past the wall's far face the whole probe of the hand goes
    seeded_hits: int = 4
    # slot
    blade_size: tuple = (0.02, 0.06, 0.002)   # X (width), Y (length), Z (thickness)
    slot_clearance: float = 4e-6              # a side, with the blade centred
    jaw_size: tuple = (0.06, 0.04, 0.01)      # X, Y (the slot's depth), Z (each jaw's height)
    twist_deg: int = 20
    roll_deg: int = 5
    # wedge
    wedge_half_angle_deg: int = 15
    groove_depth: float = 0.02
    groove_floor: float = 0.001          # the groove's flat bottom width
    wedge_tip: float = 0.002             # the tool's flat tip width (> groove_floor: it seats on its flanks)
    wedge_height: float = 0.03
    wedge_push: float = 0.005
    rock_deg: int = 4
    # pry_hook
    ledge_gap: float = 0.02              # floor to the ledge's underside
    ledge_thickness: float = 0.01
    ledge_length: float = 0.05
    hook_shaft: float = 0.08
    hook_foot: float = 0.025
    hook_thickness: float = 0.005
    hook_width: float = 0.01             # along Y
    pry_deg: int = 45                    # past the jam (toe on the ledge, heel on the floor: about 37 degrees)
    # knife_vertex
    knife_angle_deg: int = 10            # the knife prism's apex angle
    knife_height: float = 0.03
    spike_angle_deg: int = 40            # the spike's apex angle (between opposite faces)
    spike_height: float = 0.03
    spike_offset: float = 0.05           # along X from the knife's edge
    # dense_plate
    plate_size: float = 0.08
    plate_divisions: int = 80
    plate_jitter: float = 0.25           # of the grid's pitch, in the plate's plane only
    puck_size: tuple = (0.04, 0.04, 0.01)
    puck_twist_deg: int = 30
    puck_rock_deg: int = 3
    # cup
    cup_radius: float = 0.04
    cup_height: float = 0.04
    cup_wall: float = 0.003
    cup_fillet: float = 0.008
    cup_segments: int = 48
    cup_fillet_steps: int = 6
    ball_radius: float = 0.005
    ball_segments: int = 12
    # lever
    rod_length: float = 0.30
    rod_thickness: float = 0.006
    block_size: tuple = (0.06, 0.06, 0.04)
    lever_press: float = 0.01
    lever_sweep_deg: int = 5

    def validate(self) -> None:
        pos = {k: v for k, v in asdict(self).items() if isinstance(v, float)}
        bad = [k for k, v in pos.items() if not v > 0]
        if bad:
            raise ValueError(f"must be > 0: {', '.join(bad)}")
        if self.plate_divisions < 1 or self.cup_segments < 3 or self.ball_segments < 4:
            raise ValueError("plate_divisions >= 1, cup_segments >= 3, ball_segments >= 4")
        if not self.plate_jitter < 0.5:
            raise ValueError("plate_jitter must be < 0.5 of the pitch (triangles would fold)")
        if not 0 < self.wedge_half_angle_deg < 90 or not 0 < self.knife_angle_deg < 180:
            raise ValueError("angles must be in (0, 90) (wedge) and (0, 180) (knife)")
        if not self.wedge_tip > self.groove_floor:
            raise ValueError("wedge_tip must exceed groove_floor (the wedge seats on its flanks)")
        if not self.cup_wall + self.cup_fillet < self.cup_radius:
            raise ValueError("cup_wall + cup_fillet must be < cup_radius")
        if not self.hook_thickness < self.ledge_gap / 2:
            raise ValueError("hook_thickness must be < ledge_gap / 2 (the foot must fit under the ledge)")

    def to_json(self) -> dict:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}


# ---------------------------------------------------------------- mesh makers


def _oriented(V: list, F: list) -> tuple[np.ndarray, np.ndarray]:
    """(V, F) as arrays with every face flipped when the mesh encloses a negative volume: the
    makers below build a consistent orientation and this makes it the outward one."""
    V, F = np.array(V, dtype=np.float64) + 0.0, np.array(F, dtype=np.int64)
    if peg.signed_volume(V, F) < 0:
        F = F[:, ::-1].copy()
    return V, F


def _cross2(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def ear_clip(poly: list) -> list[tuple[int, int, int]]:
    """Triangles of a simple polygon [(u, v)], counter-clockwise or not, by ear clipping: n - 2
    triangles, each counter-clockwise when the polygon is. No three consecutive vertices may be
    collinear (each ear would then be degenerate)."""
    area = sum(_cross2((0.0, 0.0), poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))
    idx = list(range(len(poly))) if area > 0 else list(range(len(poly)))[::-1]
    tris = []
    while len(idx) > 3:
        for k in range(len(idx)):
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            if _cross2(poly[a], poly[b], poly[c]) <= 0:
                continue  # reflex or flat: not an ear
            inside = any(_cross2(poly[a], poly[b], poly[m]) >= 0 and _cross2(poly[b], poly[c], poly[m]) >= 0
                         and _cross2(poly[c], poly[a], poly[m]) >= 0
                         for m in idx if m not in (a, b, c))
            if not inside:
                tris.append((a, b, c))
                idx.pop(k)
                break
        else:
            raise RuntimeError("ear clipping found no ear: the polygon is not simple")
    tris.append(tuple(idx))
    return tris if area > 0 else [(a, c, b) for a, b, c in tris]


def extrude_xz(poly: list, y0: float, y1: float) -> tuple[np.ndarray, np.ndarray]:
    """The prism of a simple polygon [(x, z)] between y = y0 and y = y1, outward."""
    n = len(poly)
    V = [(x, y0, z) for x, z in poly] + [(x, y1, z) for x, z in poly]
    F = []
    for i in range(n):
        j = (i + 1) % n
        F += [(i, j, n + j), (i, n + j, n + i)]
    for a, b, c in ear_clip(poly):
        F += [(a, c, b), (n + a, n + b, n + c)]
    return _oriented(V, F)


def _lerp(a: float, b: float, i: int, m: int) -> float:
    return a if i == 0 else (b if i == m else a + (b - a) * i / m)


def box_grid(lo: tuple, hi: tuple, div: tuple, jitter_top: float = 0.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """An axis-aligned box from lo to hi whose faces are grids of div = (nx, ny, nz) cells, outward.
    jitter_top > 0 moves the top face's interior vertices in its plane (x, y) by up to that fraction
    of the pitch, drawn from PCG64(seed): an irregular but exactly coplanar tessellation."""
    div = tuple(int(d) for d in div)
    coords = [[_lerp(lo[a], hi[a], i, div[a]) for i in range(div[a] + 1)] for a in range(3)]
    index: dict[tuple, int] = {}
    V: list = []

    def vid(ijk: tuple) -> int:
        if ijk not in index:
            index[ijk] = len(V)
            V.append([coords[a][ijk[a]] for a in range(3)])
        return index[ijk]

    F = []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for side in (0, div[a]):
            for u in range(div[b]):
                for v in range(div[c]):
                    q = []
                    for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        ijk = [0, 0, 0]
                        ijk[a], ijk[b], ijk[c] = side, u + du, v + dv
                        q.append(vid(tuple(ijk)))
                    tris = [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
                    # (b, c) is right-handed about +a: the quad faces +a; flip on the low side.
                    F += tris if side else [(x, z, y) for x, y, z in tris]
    if jitter_top > 0:
        rng = np.random.Generator(np.random.PCG64(seed))
        pitch = [(hi[a] - lo[a]) / div[a] for a in range(2)]
        for (i, j, k), n in sorted(index.items()):
            if k == div[2] and 0 < i < div[0] and 0 < j < div[1]:
                d = rng.uniform(-jitter_top, jitter_top, size=2)
                V[n][0] += float(d[0]) * pitch[0]
                V[n][1] += float(d[1]) * pitch[1]
    return _oriented(V, F)


def _clean(x: float, scale: float) -> float:
    """x, or 0.0 when it is a 40-digit cos or sin of a multiple of 90 degrees (|x| < 1e-30 scale)."""
    return 0.0 if abs(x) < 1e-30 * scale else x + 0.0


def revolve(profile: list, segments: int) -> tuple[np.ndarray, np.ndarray]:
    """The solid of revolution about the Z axis of a profile [(r, z)] that starts and ends on the
    axis (r = 0) and has r > 0 in between: segments sides, a fan at each pole, outward."""
    ctx = peg._CTX
    cs = [peg._cos_sin(k, segments) for k in range(segments)]
    inner = profile[1:-1]
    V = [(0.0, 0.0, profile[0][1])]
    for r, z in inner:
        rd = decimal.Decimal(r)
        V += [(_clean(float(ctx.multiply(rd, c)), r), _clean(float(ctx.multiply(rd, s)), r), z) for c, s in cs]
    V.append((0.0, 0.0, profile[-1][1]))
    top = len(V) - 1
    ring = lambda k, i: 1 + k * segments + i % segments  # noqa: E731
    F = [(0, ring(0, i + 1), ring(0, i)) for i in range(segments)]
    for k in range(len(inner) - 1):
        for i in range(segments):
            F += [(ring(k, i), ring(k, i + 1), ring(k + 1, i + 1)), (ring(k, i), ring(k + 1, i + 1), ring(k + 1, i))]
    last = len(inner) - 1
    F += [(top, ring(last, i), ring(last, i + 1)) for i in range(segments)]
    return _oriented(V, F)


def octahedron(r: float) -> tuple[np.ndarray, np.ndarray]:
    V = [(r, 0.0, 0.0), (-r, 0.0, 0.0), (0.0, r, 0.0), (0.0, -r, 0.0), (0.0, 0.0, r), (0.0, 0.0, -r)]
    F = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    return _oriented(V, F)


def _arc(cx: float, cz: float, radius: float, from_deg: int, to_deg: int, steps: int) -> list:
    """Points (cx + r cos a, cz + r sin a) for a from from_deg to to_deg in `steps` equal steps
    (angles in 1/(4 steps) degree units so that every angle is an exact fraction of the turn)."""
    ctx = peg._CTX
    rd = decimal.Decimal(radius)
    pts = []
    for i in range(steps + 1):
        k = from_deg * 4 * steps + (to_deg - from_deg) * 4 * i   # units of 1 / (4 steps) degree
        c, s = peg._cos_sin(k, 360 * 4 * steps)
        pts.append((cx + _clean(float(ctx.multiply(rd, c)), radius), cz + _clean(float(ctx.multiply(rd, s)), radius)))
    return pts


def _tan_deg(num: int, den: int) -> float:
    """tan(num / den degrees) from the 40-digit cos/sin."""
    c, s = peg._cos_sin(num, 360 * den)
    return float(peg._CTX.divide(s, c))


# ---------------------------------------------------------------- hand scripts


def _quat(axis: str, deg: float) -> list:
    """The unit quaternion of a rotation of `deg` degrees (a multiple of 1/4) about x, y or z."""
    k = round(deg * 4)
    if abs(k - deg * 4) > 1e-12:
        raise ValueError(f"angle {deg} is not a multiple of a quarter degree")
    c, s = peg._cos_sin(k, 360 * 8)  # the half angle: deg / 2 degrees = k / (360 * 8) turns
    q = [float(c), 0.0, 0.0, 0.0]
    q["xyz".index(axis) + 1] = float(s)
    return [x + 0.0 for x in q]


def _qmul(a: list, b: list) -> list:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


class Script:
    """A hand script under construction: keys of G's pose, named phases, the let-go and end."""

    def __init__(self, description: str, p0, q0=(1.0, 0.0, 0.0, 0.0)):
        self.description = description
        self.keys = [{"t": 0.0, "p": [round(float(x), 12) + 0.0 for x in p0], "q": [float(x) + 0.0 for x in q0]}]
        self.phases: list = []

    @property
    def t(self) -> float:
        return self.keys[-1]["t"]

    def phase(self, name: str) -> "Script":
        self.phases.append({"name": name, "start": round(self.t, 9)})
        return self

    def to(self, dt: float, p=None, q=None) -> "Script":
        """A key dt after the last one (p or q unchanged when None)."""
        last = self.keys[-1]
        self.keys.append({"t": round(self.t + dt, 9),
                          "p": [round(float(x), 12) + 0.0 for x in (last["p"] if p is None else p)],
                          "q": [float(x) + 0.0 for x in (last["q"] if q is None else q)]})
        return self

    def at_speed(self, speed: float, p) -> "Script":
        """A straight move of G to p at `speed` (m/s)."""
        d = float(np.linalg.norm(np.array(p, float) - np.array(self.keys[-1]["p"], float)))
        return self.to(round(d / speed, 9) or 1e-3, p=p)

    def finish(self, tail: float = 0.5) -> dict:
        return {"description": self.description, "keys": self.keys, "phases": self.phases,
                "end_time": round(self.t + tail, 9)}


def thin_wall_script(p: BatteryParams) -> dict:
    """Head-on hits at hit_speed through the wall (x = 0 plane), seeded oblique hits, a rim hit."""
    r, h, d = p.probe_radius, 0.5 * p.wall_thickness, p.hit_depth
    standoff = -(h + r + 0.02)
    far = h + r + d
    zc = 0.5 * p.wall_size[1]
    s = Script(f"Thin wall: an octahedral probe (radius {r * 1000:g} mm, G at its centre) hits a "
               f"{p.wall_thickness * 1000:g} mm plate at {p.hit_speed:g} m/s ({p.hit_speed:g} mm a 1 kHz tick), "
               f"its hand {d * 1000:g} mm past the far face; {p.seeded_hits} seeded oblique hits; one on the top rim.",
               (standoff, 0.0, zc))
    s.phase("approach").to(0.3)
    s.phase("hit").at_speed(p.hit_speed, (far, 0.0, zc)).to(0.3)
    s.phase("withdraw").to(0.4, p=(standoff, 0.0, zc))
    rng = np.random.Generator(np.random.PCG64(p.seed))
    s.phase("seeded_hits")
    for _ in range(p.seeded_hits):
        y0, z0 = (round(float(v), 6) for v in rng.uniform([-0.3, 0.3], [0.3, 0.7]) * [p.wall_size[0], p.wall_size[1]])
        dy, dz = (round(float(v), 6) for v in rng.uniform(-0.01, 0.01, size=2))
        yaw = int(rng.integers(-30, 31))
        q = _quat("z", yaw)
        s.to(0.3, p=(standoff, y0, z0), q=q)
        s.at_speed(p.hit_speed, (far, y0 + dy, z0 + dz)).to(0.2)
        s.to(0.3, p=(standoff, y0, z0))
    top = p.wall_size[1]
    s.phase("rim_hit").to(0.4, p=(0.0, 0.0, top + r + 0.02), q=(1.0, 0.0, 0.0, 0.0))
    s.at_speed(p.hit_speed, (0.0, 0.0, top + r - d)).to(0.3)
    s.phase("lift").to(0.4, p=(0.0, 0.0, top + r + 0.02))
    return s.finish()


def slot_script(p: BatteryParams) -> dict:
    """The blade slides along +Y through the slot, twists in its plane, rolls about Y, exits."""
    jy = 0.5 * p.jaw_size[1]
    ly = 0.5 * p.blade_size[1]
    start = -(jy + ly + 0.01)
    s = Script(f"Slot: a {p.blade_size[2] * 1000:g} mm blade through a slot {2 * p.slot_clearance * 1e6:g} um wider "
               f"than it; slides, twists {p.twist_deg} degrees in the slot's plane, rolls {p.roll_deg} degrees about "
               "the slot's axis (jammed), presses on the lower jaw, exits.", (0.0, start, 0.0))
    s.phase("approach").to(0.3)
    s.phase("enter").to(1.0, p=(0.0, 0.0, 0.0))
    s.phase("twist").to(0.8, q=_quat("z", p.twist_deg)).to(0.8, q=_quat("z", -p.twist_deg)).to(0.4, q=_quat("z", 0))
    s.phase("roll").to(0.5, q=_quat("y", p.roll_deg)).to(0.3).to(0.5, q=_quat("y", -p.roll_deg)).to(0.3)
    s.to(0.4, q=_quat("y", 0))
    s.phase("press").to(0.4, p=(0.0, 0.0, -0.005)).to(0.3).to(0.4, p=(0.0, 0.0, 0.0))
    s.phase("exit").to(1.0, p=(0.0, jy + ly + 0.01, 0.0))
    return s.finish()


def wedge_script(p: BatteryParams) -> dict:
    """The wedge (G at its tip's centre) lowered into the groove, pushed, rocked about Y, released."""
    seat = _wedge_seat(p)
    s = Script(f"Wedge: a {2 * p.wedge_half_angle_deg} degree wedge pushed {p.wedge_push * 1000:g} mm past its seat "
               f"in a matching V-groove, rocked {p.rock_deg} degrees, then released and lifted.",
               (0.0, 0.0, 0.02))
    s.phase("approach").to(0.3).to(0.6, p=(0.0, 0.0, seat + 0.002))
    s.phase("push").to(0.5, p=(0.0, 0.0, seat - p.wedge_push)).to(0.5)
    s.phase("rock").to(0.4, q=_quat("y", p.rock_deg)).to(0.6, q=_quat("y", -p.rock_deg)).to(0.4, q=_quat("y", 0))
    s.phase("release").to(0.3, p=(0.0, 0.0, seat + 0.001)).to(0.3)
    s.phase("lift").to(0.4, p=(0.0, 0.0, 0.02))
    return s.finish()


def _wedge_seat(p: BatteryParams) -> float:
    """z of the wedge's tip (G) when its flanks rest on the groove's (the groove's rim at z = 0)."""
    t = _tan_deg(p.wedge_half_angle_deg, 1)
    # Groove half-width at height z (z <= 0): floor/2 + (z + depth) t; the tip's half-width is tip/2.
    return -p.groove_depth + (0.5 * p.wedge_tip - 0.5 * p.groove_floor) / t


def pry_hook_script(p: BatteryParams) -> dict:
    """The hook (G at its heel, foot along +X) hooked under the ledge and pulled up, then levered."""
    gap, t = p.ledge_gap, p.hook_thickness
    x_in = -0.5 * p.ledge_length - t - 0.001   # G with the shaft 1 mm in front of the ledge's free end
    hover = gap + p.ledge_thickness + 0.01
    z_foot = 0.5 * gap - 0.5 * t
    front = -0.5 * p.ledge_length - p.hook_foot - 0.01
    s = Script("Pry and hook: an L-shaped hook (vertical shaft, foot along +X, G at the heel) goes down in front of "
               "a ledge, slides its foot under it, pulls up against its underside (hooking), then rotates "
               f"{p.pry_deg} degrees about Y with its heel on the floor (prying), and comes out.",
               (front, 0.0, hover))
    s.phase("approach").to(0.3).to(0.6, p=(front, 0.0, z_foot))
    s.phase("insert").to(0.8, p=(x_in, 0.0, z_foot))
    s.phase("hook").to(0.5, p=(x_in, 0.0, gap + 0.005)).to(0.4)
    s.to(0.5, p=(x_in - 0.01, 0.0, gap + 0.005)).to(0.4, p=(x_in, 0.0, z_foot))
    s.phase("pry").to(0.4, p=(x_in, 0.0, -0.003))
    s.to(0.8, q=_quat("y", -p.pry_deg)).to(0.4).to(0.6, q=_quat("y", 0))
    s.phase("out").to(0.4, p=(x_in, 0.0, z_foot)).to(0.8, p=(front, 0.0, z_foot))
    s.to(0.5, p=(front, 0.0, hover))
    return s.finish()


def knife_vertex_script(p: BatteryParams) -> dict:
    """The probe's lowest vertex (G) on the knife's edge, along it, a face on it, then apex on apex."""
    r = p.probe_radius
    xs = p.spike_offset
    s = Script("Knife and vertex: the octahedral probe (G at its lowest vertex) lands its vertex on the knife's edge "
               "(vertex-edge), slides along it and off its flanks, rests an edge across it and then along it "
               "(crossing and parallel edge-edge), then meets the square spike's apex with its vertex (vertex-vertex) and is pressed there.",
               (0.0, -0.02, 0.02))
    s.phase("approach").to(0.3).to(0.5, p=(0.0, -0.02, 0.0003))
    s.phase("press_edge").to(0.4, p=(0.0, -0.02, -0.004)).to(0.2)
    s.phase("along_edge").to(1.0, p=(0.0, 0.02, -0.004))
    s.phase("across_edge").to(0.3, q=_quat("z", 45)).to(0.8, p=(0.006, 0.02, -0.004)).to(0.8, p=(-0.006, 0.02, -0.004))
    # Rotated 45 degrees about Y about G (its lowest vertex), the probe's lowest feature is the edge
    # from G to G + (r sqrt 2, 0, 0): first across the knife's edge, then (90 more about Z) along it.
    qy = _quat("y", 45)
    s.phase("edge_across_edge").to(0.4, p=(0.0, 0.02, 0.01), q=qy)
    s.to(0.4, p=(-0.5 * r, 0.02, -0.002)).to(0.3)
    s.phase("edge_along_edge").to(0.4, p=(0.0, 0.0, 0.01), q=_qmul(_quat("z", 90), qy))
    s.to(0.4, p=(0.0, -0.5 * r, -0.002)).to(0.3)
    s.phase("to_spike").to(0.4, p=(0.0, 0.0, 0.02), q=(1.0, 0.0, 0.0, 0.0)).to(0.6, p=(xs, 0.0, 0.02))
    s.phase("vertex_on_vertex").to(0.6, p=(xs, 0.0, 0.0)).to(0.3, p=(xs, 0.0, -0.003)).to(0.4)
    s.to(0.4, p=(xs + 0.0005, 0.0, -0.003)).to(0.4, p=(xs - 0.0005, 0.0, -0.003))
    s.phase("lift").to(0.5, p=(xs, 0.0, 0.02))
    return s.finish()


def dense_plate_script(p: BatteryParams) -> dict:
    """The puck (G at its bottom face's centre) lands flat, slides, twists about Z, rocks about X."""
    s = Script(f"Dense plate: a {p.puck_size[0] * 100:g} x {p.puck_size[1] * 100:g} cm puck lands flat on a plate of "
               f"{2 * p.plate_divisions ** 2} coplanar triangles, is pressed 5 mm, slides, twists "
               f"{p.puck_twist_deg} degrees, rocks {p.puck_rock_deg} degrees onto an edge, and lifts.",
               (0.0, 0.0, 0.01))
    s.phase("approach").to(0.3).to(0.5, p=(0.0, 0.0, 0.0002))
    s.phase("land").to(0.3, p=(0.0, 0.0, -0.005)).to(0.3)
    s.phase("slide").to(0.8, p=(0.01, 0.0, -0.005)).to(0.8, p=(0.0, 0.0, -0.005))
    s.phase("twist").to(0.8, q=_quat("z", p.puck_twist_deg)).to(0.8, q=_quat("z", 0))
    s.phase("rock").to(0.4, q=_quat("x", p.puck_rock_deg)).to(0.4, q=_quat("x", 0))
    s.phase("lift").to(0.5, p=(0.0, 0.0, 0.01))
    return s.finish()


def cup_script(p: BatteryParams) -> dict:
    """The ball (G at its centre) into the cup, to the floor, out to the fillet, around, out."""
    rb = p.ball_radius
    inner = p.cup_radius - p.cup_wall
    floor = p.cup_wall
    top = p.cup_height + rb + 0.01
    press = 0.004
    s = Script(f"Cup: a round probe (radius {rb * 1000:g} mm) lowered into a cup, pressed {press * 1000:g} mm into its "
               "floor, pushed out into the filleted corner and dragged once around the inside against wall and floor "
               "at once, then up the wall and out.", (0.0, 0.0, top))
    s.phase("approach").to(0.3).to(0.6, p=(0.0, 0.0, floor + rb + 0.001))
    s.phase("floor").to(0.3, p=(0.0, 0.0, floor + rb - press)).to(0.2)
    rad = inner - rb + press
    s.phase("corner").to(0.6, p=(rad, 0.0, floor + rb - press))
    s.phase("drag")
    for deg in range(10, 361, 10):
        c, sn = peg._cos_sin(deg, 360)
        s.to(0.1, p=(rad * float(c), rad * float(sn), floor + rb - press))
    s.phase("up_the_wall").to(0.8, p=(rad, 0.0, p.cup_height - rb))
    s.phase("out").to(0.4, p=(0.0, 0.0, p.cup_height - rb)).to(0.5, p=(0.0, 0.0, top))
    return s.finish()


def lever_script(p: BatteryParams) -> dict:
    """The rod along +X from G (its held end); its far tip pressed on the block's top, swept, on its side."""
    L = p.rod_length
    bx = 0.5 * p.block_size[0]
    ht = 0.5 * p.rod_thickness
    x0 = -L + 0.01  # the tip 1 cm inside the block's top, from its -X edge
    z_touch = ht + 0.0001
    s = Script(f"Lever: a {L * 100:g} cm rod of {p.rod_thickness * 1000:g} mm held at one end (G); its far tip "
               f"touches the block's top, is pressed {p.lever_press * 1000:g} mm (the torque about G is the tip force "
               f"times {L * 100:g} cm), swept {p.lever_sweep_deg} degrees about Z, then pushed sideways on the block's "
               "side face, and lifted.", (x0 - bx, 0.0, 0.03))
    s.phase("approach").to(0.3).to(0.6, p=(x0 - bx, 0.0, z_touch))
    s.phase("press").to(0.5, p=(x0 - bx, 0.0, z_touch - p.lever_press)).to(0.3)
    s.phase("sweep").to(0.8, q=_quat("z", p.lever_sweep_deg)).to(1.2, q=_quat("z", -p.lever_sweep_deg))
    s.to(0.6, q=_quat("z", 0))
    s.phase("side").to(0.5, p=(x0 - bx, 0.0, 0.03)).to(0.5, p=(-L - bx + 0.01, -(0.5 * p.block_size[1] + ht + 0.005), 0.03))
    s.to(0.4, p=(-L - bx + 0.01, -(0.5 * p.block_size[1] + ht + 0.005), -0.01))
    s.to(0.6, q=_quat("z", 2 * p.lever_sweep_deg)).to(0.3).to(0.6, q=_quat("z", 0))
    s.phase("lift").to(0.5, p=(-L - bx + 0.01, -(0.5 * p.block_size[1] + ht + 0.005), 0.03))
    return s.finish()


# ---------------------------------------------------------------- the scenes' meshes


def meshes(p: BatteryParams) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{file name: (V, F)} of every battery mesh, in their body frames (see the scenes)."""
    out = {}
    r = p.probe_radius
    out["probe.off"] = octahedron(r)
    # thin_wall: x in [-t/2, t/2], y centred, z from 0.
    h = 0.5 * p.wall_thickness
    out["thin_wall.off"] = box_grid((-h, -0.5 * p.wall_size[0], 0.0), (h, 0.5 * p.wall_size[0], p.wall_size[1]), (1, 4, 4))
    # slot: the blade centred at the origin; jaws above and below with the gap blade + 2 clearance.
    bx, by, bz = (0.5 * v for v in p.blade_size)
    out["blade.off"] = box_grid((-bx, -by, -bz), (bx, by, bz), (1, 2, 1))
    jx, jy, jz = 0.5 * p.jaw_size[0], 0.5 * p.jaw_size[1], p.jaw_size[2]
    g = bz + p.slot_clearance
    out["jaw_upper.off"] = box_grid((-jx, -jy, g), (jx, jy, g + jz), (2, 2, 1))
    out["jaw_lower.off"] = box_grid((-jx, -jy, -g - jz), (jx, jy, -g), (2, 2, 1))
    # wedge: the groove block (rim at z = 0, V along Y) and the wedge (G at its tip's centre).
    t = _tan_deg(p.wedge_half_angle_deg, 1)
    d, f0 = p.groove_depth, 0.5 * p.groove_floor
    rim = f0 + d * t
    wx = rim + 0.02
    groove = [(-wx, -d - 0.02), (wx, -d - 0.02), (wx, 0.0), (rim, 0.0), (f0, -d), (-f0, -d), (-rim, 0.0), (-wx, 0.0)]
    out["groove.off"] = extrude_xz(groove, -0.03, 0.03)
    tip, H = 0.5 * p.wedge_tip, p.wedge_height
    top = tip + H * t
    out["wedge.off"] = extrude_xz([(-tip, 0.0), (tip, 0.0), (top, H), (-top, H)], -0.02, 0.02)
    # pry_hook: the ledge (floor at z = 0 running along X, a post at +X, the ledge over the floor back to -X)
    gap, lt, ll = p.ledge_gap, p.ledge_thickness, p.ledge_length
    x1 = 0.5 * ll
    ledge = [(-0.08, -0.01), (x1 + 0.03, -0.01), (x1 + 0.03, gap + lt), (-x1, gap + lt), (-x1, gap),
             (x1, gap), (x1, 0.0), (-0.08, 0.0)]
    out["ledge.off"] = extrude_xz(ledge, -0.03, 0.03)
    th, sh, ft, hw = p.hook_thickness, p.hook_shaft, p.hook_foot, 0.5 * p.hook_width
    # G (the origin) at the heel's bottom-left corner; shaft up +Z, foot along +X.
    hook = [(0.0, 0.0), (ft, 0.0), (ft, th), (th, th), (th, sh), (0.0, sh)]
    out["hook.off"] = extrude_xz(hook, -hw, hw)
    # knife_vertex: the knife prism (edge along Y at z = 0) and the square spike (apex at z = 0).
    kt = _tan_deg(p.knife_angle_deg, 2)
    kh = p.knife_height
    out["knife.off"] = extrude_xz([(-kh * kt, -kh), (kh * kt, -kh), (0.0, 0.0)], -0.04, 0.04)
    st = _tan_deg(p.spike_angle_deg, 2) * p.spike_height
    out["spike.off"] = revolve([(0.0, -p.spike_height), (st, -p.spike_height), (0.0, 0.0)], 4)
    # dense_plate: top at z = 0; the puck with G at its bottom face's centre (the origin).
    ps = 0.5 * p.plate_size
    n = p.plate_divisions
    out["plate.off"] = box_grid((-ps, -ps, -0.01), (ps, ps, 0.0), (n, n, 1), jitter_top=p.plate_jitter, seed=p.seed)
    px, py, pz = 0.5 * p.puck_size[0], 0.5 * p.puck_size[1], p.puck_size[2]
    out["puck.off"] = box_grid((-px, -py, 0.0), (px, py, pz), (1, 1, 1))
    # cup: outer bottom at z = 0, axis Z, filleted inside; the ball centred on the origin.
    R, H, w, fr = p.cup_radius, p.cup_height, p.cup_wall, p.cup_fillet
    ri = R - w
    fillet = _arc(ri - fr, w + fr, fr, 0, -90, p.cup_fillet_steps)   # from the wall down to the floor
    profile = [(0.0, 0.0), (R, 0.0), (R, H), (ri, H)] + fillet + [(0.0, w)]
    out["cup.off"] = revolve(profile, p.cup_segments)
    ball = [(0.0, -p.ball_radius)] + [pt for pt in _arc(0.0, 0.0, p.ball_radius, -90, 90, p.ball_segments // 2)[1:-1]] \
        + [(0.0, p.ball_radius)]
    out["ball.off"] = revolve([(abs(x) + 0.0, z) for x, z in ball], p.ball_segments)
    # lever: the rod along +X from G (its held end at the origin), the block's top at z = 0.
    rt = 0.5 * p.rod_thickness
    out["rod.off"] = box_grid((0.0, -rt, -rt), (p.rod_length, rt, rt), (6, 1, 1))
    cx, cy, cz = 0.5 * p.block_size[0], 0.5 * p.block_size[1], p.block_size[2]
    out["block.off"] = box_grid((-cx, -cy, -cz), (cx, cy, 0.0), (2, 2, 1))
    return out


def scripts(p: BatteryParams) -> dict[str, dict]:
    return {"thin_wall.json": thin_wall_script(p), "slot.json": slot_script(p), "wedge.json": wedge_script(p),
            "pry_hook.json": pry_hook_script(p), "knife_vertex.json": knife_vertex_script(p),
            "dense_plate.json": dense_plate_script(p), "cup.json": cup_script(p), "lever.json": lever_script(p)}


def check_mesh(name: str, V: np.ndarray, F: np.ndarray) -> None:
    """Fails loudly unless (V, F) is closed, 2-manifold, outward and free of degenerate triangles."""
    problems = peg.check_closed_manifold(F)
    areas = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    size = float(np.ptp(V, axis=0).max())
    # The smallest triangles (the plate's jittered cells, the knife's thin flanks) are about
    # 1e-4 of the mesh's size squared; 1e-10 of it is a degenerate one.
    if areas.min() <= 1e-10 * size * size:
        problems.append(f"degenerate triangle (area {areas.min():.3g})")
    if not peg.signed_volume(V, F) > 0:
        problems.append("not oriented outward (volume <= 0)")
    if problems:
        raise RuntimeError(f"{name}: " + "; ".join(problems))


def generate(out_dir: Path, params: BatteryParams | None = None) -> dict[str, str]:
    """Writes the battery's meshes and hand scripts into out_dir; returns {filename: text}."""
    p = params or BatteryParams()
    p.validate()
    relpath, sha = source(__spec__.name)
    header = peg.provenance_header(relpath, p.to_json(), sha)
    header[1] = f"generator_version: {GENERATOR_VERSION}"
    out = {}
    for name, (V, F) in meshes(p).items():
        check_mesh(name, V, F)
        out[name] = peg.off_text(V, F, header)
    for name, s in scripts(p).items():
        out[name] = json.dumps(s, indent=1) + "\n"
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, text in out.items():
        (out_dir / name).write_text(text, encoding="ascii")
    return out

