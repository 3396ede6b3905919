"""Rapier (its Python bindings, the `rapier3d` wheel: Rapier 3D in f32) behind the engine
contract: a free tool body pulled to the handle by a six-DoF virtual coupling
(docs/engine-adapters.md).

Model, built from the EngineScene at reset (a PhysicsWorld of its own):
- the obstacles: colliders on a fixed body, each its own concave triangle mesh (Rapier's TriMesh,
  exact geometry);
- the tool: a dynamic body at G whose colliders are the tool mesh's convex parts (CoACD,
  common.py; Rapier's contact between a moving mesh and a fixed one goes through convex shapes),
  density 0, and the scene's mass and inertia about G given as the body's mass properties
  (principal moments and axes);
- no gravity, friction 0.3, restitution 0, one world step of 1 / rate a tick.

The coupling, each tick, from the tool's pose and velocity at the tick's start (the Drake
adapter's):
    F_tool = -kc M (x_tool (-) xh) - 2 zeta sqrt(kc) M (v_tool - v_h)
with M = diag(m I, R I_B R^T), v_h the handle's velocity by backward difference, applied as the
body's force and torque for one step; the wrench
sent to the user is -F_tool. Contacts: the narrow phase's manifolds of the tool's colliders
(point on the tool, normal from the obstacle to the tool, Rapier's distance); Rapier makes a
manifold point per triangle of a concave mesh, thousands on a dense one, so the deepest of them
are reported, the contract's capacity (common.reported_contacts).

Parameters (config keys) and how they were chosen:
  kc          4000 1/s^2, the coupling stiffness: the swept parameter (250 to 64000, the Drake
              adapter's range), penetration against force; the default is the peg scene's kh
              (985 N/m on the peg), as for Drake
  zeta        1, the coupling's damping ratio: critical damping of the tool in free motion
  friction    0.3, Coulomb friction: the other adapters' dry contact
  iterations  4, solver iterations a step: Rapier's own default
Rapier computes in f32: a position carries about 6e-8 relative error (6 nm at the scenes' 10 cm),
a hundredth of their delta (1 um).
"""
from __future__ import annotations

import time

import numpy as np

from ..engine import EngineScene, EngineStep
from ..oracle import pose_difference, rotation_matrices
from . import common
from .pybullet_engine import _principal  # (principal moments, quaternion of the principal axes in B)

DEFAULTS = {"kc": 4000.0, "zeta": 1.0, "friction": 0.3, "iterations": 4}


class Coupling:
    """The Drake adapter's coupling law on the tool (force, torque about G; world frame):
    -kc M (x_tool (-) xh) - 2 zeta sqrt(kc) M (v_tool - v_h), M = diag(m I, R I_B R^T), v_h the
    handle's velocity by backward difference of its poses (zero at the first tick)."""

    def __init__(self, cfg: dict, m: float, I_B: np.ndarray, dt: float):
        self.cfg, self.m, self.I_B, self.dt = cfg, float(m), np.asarray(I_B, float), float(dt)
        self.prev_xh = None

    def wrench(self, p, q, v, omega, xh_p, xh_q) -> np.ndarray:
        c = self.cfg
        xh_p, xh_q = np.asarray(xh_p, float), common.unit(np.asarray(xh_q, float))
        v_h = np.zeros(6) if self.prev_xh is None else pose_difference(xh_p, xh_q, *self.prev_xh) / self.dt
        self.prev_xh = (xh_p, xh_q)
        R = rotation_matrices(q)[0]
        d = pose_difference(p, q, xh_p, xh_q)  # x_tool (-) xh
        dv = np.concatenate([np.asarray(v, float), np.asarray(omega, float)]) - v_h
        damp = 2.0 * c["zeta"] * np.sqrt(c["kc"])
        force = self.m * (-c["kc"] * d[:3] - damp * dv[:3])
        torque = (R @ self.I_B @ R.T) @ (-c["kc"] * d[3:] - damp * dv[3:])
        return np.concatenate([force, torque])


class RapierEngine:
    def __init__(self, config: str = ""):
        import rapier3d  # noqa: F401  (fails here when Rapier's bindings are not installed)

        self.cfg = common.parse_config(config, DEFAULTS)
        if self.cfg["kc"] <= 0 or self.cfg["zeta"] < 0 or self.cfg["iterations"] < 1:
            raise ValueError("config: kc must be > 0, zeta >= 0, iterations >= 1")
        from importlib.metadata import version

        self.name = f"rapier3d {version('rapier3d')}"
        self.config = config
        self.world = None

    def reset(self, scene: EngineScene) -> None:
        import rapier3d as r

        c = self.cfg
        self.world = w = r.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
        w.integration_parameters.dt = 1.0 / scene.rate_hz  # modified in place
        w.integration_parameters.num_solver_iterations = c["iterations"]
        ground = w.add_body(r.RigidBody.fixed())
        for o in scene.obstacles:
            col = r.Collider.trimesh(np.asarray(o.V, np.float64), np.asarray(o.F, np.uint32), friction=c["friction"],
                                     restitution=0.0)
            col = col.position((tuple(map(float, o.p)), r.Rotation3(*map(float, common.unit(o.q)))))
            w.add_collider(col, parent=ground)
        parts = common.convex_parts(scene.tool.V, scene.tool.F, f"{scene.name}:tool")
        moments, q_BI = _principal(scene.inertia_G_B)
        q0 = common.unit(scene.tool.q)
        body = r.RigidBody.dynamic().position((tuple(map(float, scene.tool.p)), r.Rotation3(*map(float, q0))))
        body = body.additional_mass_properties(r.MassProperties(local_com=(0.0, 0.0, 0.0), mass=float(scene.mass),
                                                         principal_inertia=tuple(map(float, moments)),
                                                         principal_inertia_local_frame=r.Rotation3(*map(float, q_BI))))
        body = body.can_sleep(False)
        colliders = [r.Collider.convex_hull(np.asarray(V, np.float64), density=0.0, friction=c["friction"],
                                            restitution=0.0) for V, _ in parts]
        self.tool = w.add_body(body, colliders=colliders)
        self.tool_colliders = set(w.rigid_bodies[self.tool].colliders)
        self.coupling = Coupling(c, scene.mass, scene.inertia_G_B, 1.0 / scene.rate_hz)

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        b = self.world.rigid_bodies[self.tool]
        t, q = b.translation, b.rotation
        return np.array([t.x, t.y, t.z], float), np.array([q.w, q.i, q.j, q.k], float)

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        start = time.perf_counter()
        b = self.world.rigid_bodies[self.tool]
        p, q = self.pose()
        F = self.coupling.wrench(p, q, list(b.linvel), list(b.angvel), xh_p, xh_q)
        force, torque = F[:3], F[3:]
        b.reset_forces()
        b.reset_torques()
        b.add_force(tuple(map(float, force)))
        b.add_torque(tuple(map(float, torque)))
        self.world.step()
        p, q = self.pose()
        seconds = time.perf_counter() - start
        rows = []
        for h in self.tool_colliders:
            for pair in self.world.narrow_phase.contact_pairs_with(h):
                tool_first = pair.collider1 == h
                pos = self.world.colliders[h].position
                for m in pair.manifolds:
                    n = np.array(list(m.data.normal), float)  # from collider1 to collider2, world frame
                    normal = -n if tool_first else n
                    for pt in m.points:
                        local = pt.local_p1 if tool_first else pt.local_p2
                        w = pos.transform_point(local)
                        rows.append((w.x, w.y, w.z, *normal, pt.dist))
        contacts = common.reported_contacts(rows)
        return EngineStep(p, q, np.concatenate([-force, -torque]), contacts, seconds)

    def close(self) -> None:
        self.world = None
