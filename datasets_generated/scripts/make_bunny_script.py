"""Writes bunny.json, the hand script of the two-bunnies scenario (METHOD.md section 7).

The held bunny (upside down, 180 degrees about Z) lowers one ear onto the static
bunny's back, slides it along the spine ridge, then sweeps across the back. Each
keyframe's height puts the hand PRESS metres below the height at which the two
meshes first touch, found on a 1 mm height map of the static bunny's top surface
(triangles sampled densely). Deterministic: run it from anywhere,
`python datasets_generated/scripts/make_bunny_script.py`.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
MESH = HERE.parent / "bunny" / "bunny.off"
PRESS = 0.008          # m below the touching height
CELL = 1e-3            # m, height-map resolution
R_HELD = np.diag([-1.0, -1.0, 1.0])   # the held bunny's orientation: 180 degrees about Z
Q_HELD = [0.0, 0.0, 0.0, 1.0]
POSITION = np.array([0.0, 0.16, 0.0])  # bunnies.toml: the held bunny's mesh origin


def read_off(path: Path):
    lines = [l for l in path.read_text().splitlines() if l.strip() and not l.startswith("#")]
    nv, nf, _ = map(int, lines[1].split())
    V = np.array([[float(x) for x in l.split()] for l in lines[2:2 + nv]])
    F = np.array([[int(x) for x in l.split()[1:4]] for l in lines[2 + nv:2 + nv + nf]])
    return V, F


def center_of_mass(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6
    return ((a + b + c) / 4 * vol[:, None]).sum(0) / vol.sum()


def main() -> None:
    V, F = read_off(MESH)
    com = center_of_mass(V, F)
    # Height map of the static bunny's top surface: max y per cell over points sampled on every triangle.
    x0, z0, nx, nz = -0.08, -0.07, int(0.16 / CELL), int(0.14 / CELL)
    H = np.full((nx, nz), -np.inf)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    for u in np.linspace(0, 1, 6):
        for v in np.linspace(0, 1, 6):
            if u + v <= 1:
                P = a + u * (b - a) + v * (c - a)
                np.maximum.at(H, (((P[:, 0] - x0) / CELL).astype(int), ((P[:, 2] - z0) / CELL).astype(int)), P[:, 1])
    held = (V - com) @ R_HELD.T          # the held bunny's vertices relative to G, world axes
    low = held[held[:, 1] < -0.03]        # its lower part (ears, head)
    tip = R_HELD @ (V[np.argmax(V[:, 1])] - com)  # the ear tip, relative to G

    def y_touch(gx: float, gz: float) -> float:
        """Height of G at which the held bunny's lowest points touch the static top surface."""
        P = low + np.array([gx, 0.0, gz])
        i, k = ((P[:, 0] - x0) / CELL).astype(int), ((P[:, 2] - z0) / CELL).astype(int)
        ok = (i >= 0) & (i < nx) & (k >= 0) & (k < nz)
        s = np.full(len(P), -np.inf)
        s[ok] = H[i[ok], k[ok]]
        return float(np.max(s - P[:, 1]))

    def g_for_tip(xt: float, zt: float):
        return xt - tip[0], zt - tip[2]

    keys = [(0.0, (POSITION + R_HELD @ com).tolist())]
    # Approach: above the ridge's start, then down onto it.
    gx, gz = g_for_tip(0.015, 0.007)
    keys += [(0.6, [gx, y_touch(gx, gz) + 0.01, gz]), (1.2, [gx, y_touch(gx, gz) - PRESS, gz])]
    phases = [("approach", 0.0), ("ridge", 1.2)]
    # Ridge: the ear tip along the spine (z = 7 mm), x from 15 to 45 mm, in 2.4 s.
    t = 1.2
    for xt in np.linspace(0.015, 0.045, 13)[1:]:
        t += 0.2
        gx, gz = g_for_tip(xt, 0.007)
        keys.append((t, [gx, y_touch(gx, gz) - PRESS, gz]))
    phases.append(("sweep", t))
    # Sweep: zigzag across z (-10 to 30 mm) while x goes back from 45 to 15 mm.
    zs = [0.007, 0.03, -0.01, 0.03, -0.01, 0.007]
    xs = np.linspace(0.045, 0.015, len(zs))
    for j in range(1, len(zs)):
        for s in np.linspace(0, 1, 6)[1:]:
            t += 0.12
            gx, gz = g_for_tip(xs[j - 1] + s * (xs[j] - xs[j - 1]), zs[j - 1] + s * (zs[j] - zs[j - 1]))
            keys.append((t, [gx, y_touch(gx, gz) - PRESS, gz]))
    phases.append(("lift", t))
    gx, gz = g_for_tip(0.015, 0.007)
    t += 0.5
    keys.append((t, [gx, y_touch(gx, gz) + 0.01, gz]))
    doc = {
        "description": "Two bunnies, METHOD.md section 7: the hand's pose of G over time (metres, seconds; "
                       "q = (w, x, y, z)). The held bunny (upside down) lowers one ear onto the static bunny's back, "
                       "slides it along the spine ridge (z = 7 mm, x from 15 to 45 mm), then sweeps across the back; "
                       "the hand stays 8 mm below the touching height. Written by make_bunny_script.py.",
        "keys": [{"t": round(float(k), 3), "p": [round(float(v), 6) for v in p], "q": Q_HELD} for k, p in keys],
        "phases": [{"name": n, "start": round(float(s), 3)} for n, s in phases],
        "end_time": round(t + 0.3, 3),
    }
    (HERE / "bunny.json").write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
