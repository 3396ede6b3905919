"""DART (dartpy, the Dynamic Animation and Robotics Toolkit) behind the engine contract: a free
tool body pulled to the handle by a six-DoF virtual coupling (docs/engine-adapters.md).

Model, built from the EngineScene at reset (a dart.simulation.World of its own):
- the obstacles and the tool are skeletons read from URDF text (dartpy 6.20 cannot build a
  mesh shape from arrays: its meshes come through assimp from files, here the OBJ files of
  common.mesh_file): the obstacles one fixed skeleton of their own concave triangle meshes, the
  tool a floating skeleton (DART's FreeJoint) with the tool's own mesh, its body frame at G;
- collision by FCL (DART's default detector: triangle meshes on both sides, no convex
  decomposition), DART's boxed-LCP contact constraints, friction 0.3;
- the scene's mass and inertia about G set on the tool's body node; no gravity; one world step
  of 1 / rate a tick.

The coupling, each tick: rapier_engine.Coupling (the Drake adapter's law), applied as the
body's external force and torque for one step; the wrench sent to the user is its opposite.
Contacts: the world's last collision result (point, normal turned to point from the obstacle to
the tool, separation = -penetration depth).

Parameters (config keys): kc, zeta, friction, with rapier_engine's defaults and reasons.
"""
from __future__ import annotations

import time

import numpy as np

from ..engine import EngineScene, EngineStep
from ..oracle import rotation_matrices
from . import common
from .rapier_engine import DEFAULTS as RAPIER_DEFAULTS, Coupling

DEFAULTS = {k: RAPIER_DEFAULTS[k] for k in ("kc", "zeta", "friction")}


def _urdf(name: str, links: list[tuple[str, str, np.ndarray, np.ndarray]], inertial: str = "") -> str:
    """A URDF robot of one link whose collision geometry is the meshes [(name, OBJ path, p, q)]."""
    from scipy.spatial.transform import Rotation

    geoms = []
    for geom_name, path, p, q in links:
        rpy = [float(a) for a in Rotation.from_quat(common.wxyz_to_xyzw(common.unit(q))).as_euler("xyz")]
        p = [float(x) for x in p]
        geoms.append(f'<collision name="{geom_name}"><origin xyz="{p[0]!r} {p[1]!r} {p[2]!r}" '
                     f'rpy="{rpy[0]!r} {rpy[1]!r} {rpy[2]!r}"/><geometry><mesh filename="{path}"/></geometry>'
                     f'</collision>')
    return (f'<?xml version="1.0"?><robot name="{name}"><link name="{name}">{inertial}{"".join(geoms)}'
            f'</link></robot>')


class DartEngine:
    def __init__(self, config: str = ""):
        import dartpy  # noqa: F401  (fails here when DART is not installed)

        self.cfg = common.parse_config(config, DEFAULTS)
        if self.cfg["kc"] <= 0 or self.cfg["zeta"] < 0 or self.cfg["friction"] < 0:
            raise ValueError("config: kc must be > 0, zeta and friction >= 0")
        from importlib.metadata import version

        self.name = f"dartpy {version('dartpy')}"
        self.config = config
        self.world = None

    def reset(self, scene: EngineScene) -> None:
        import dartpy as dart

        c = self.cfg
        loader = dart.utils.DartLoader()
        world = dart.simulation.World()
        world.setGravity(np.zeros(3))
        world.setTimeStep(1.0 / scene.rate_hz)
        links = [(o.name, str(common.mesh_file(o.V, o.F, f"{scene.name}-{o.name}")), np.asarray(o.p, float),
                  np.asarray(o.q, float)) for o in scene.obstacles]
        obstacles = loader.parseSkeletonString(_urdf("obstacles", links), dart.common.Uri())
        obstacles.getRootJoint().setActuatorType(dart.dynamics.ActuatorType.LOCKED)
        obstacles.setMobile(False)
        tool_file = str(common.mesh_file(scene.tool.V, scene.tool.F, f"{scene.name}-tool"))
        tool = loader.parseSkeletonString(_urdf("tool", [("tool", tool_file, np.zeros(3), np.array([1.0, 0, 0, 0]))]),
                                          dart.common.Uri())
        body = tool.getBodyNode(0)
        I = np.asarray(scene.inertia_G_B, float)
        body.setInertia(dart.dynamics.Inertia(float(scene.mass), np.zeros(3), I))
        for skel in (obstacles, tool):
            for i in range(skel.getNumBodyNodes()):
                bn = skel.getBodyNode(i)
                for k in range(bn.getNumShapeNodes()):
                    dyn = bn.getShapeNode(k).getDynamicsAspect()
                    dyn.setFrictionCoeff(c["friction"])
                    dyn.setRestitutionCoeff(0.0)
        world.addSkeleton(obstacles)
        world.addSkeleton(tool)
        self.world, self.tool, self.body = world, tool, body
        self.coupling = Coupling(c, scene.mass, I, 1.0 / scene.rate_hz)
        self.tool_shapes = {body.getShapeNode(i).getShape().getID() for i in range(body.getNumShapeNodes())}
        self._set_pose(scene.tool.p, scene.tool.q)

    def _set_pose(self, p, q) -> None:
        import dartpy as dart

        T = dart.math.Isometry3()
        T.set_translation(np.asarray(p, float))
        T.set_rotation(rotation_matrices(common.unit(np.asarray(q, float)))[0])
        dart.dynamics.FreeJoint.setTransformOf(self.body, T)
        self.tool.setVelocities(np.zeros(6))

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        from scipy.spatial.transform import Rotation

        T = self.body.getWorldTransform()
        x, y, z, w = Rotation.from_matrix(T.rotation()).as_quat()
        return np.array(T.translation(), float), np.array([w, x, y, z])

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        start = time.perf_counter()
        p, q = self.pose()
        F = self.coupling.wrench(p, q, self.body.getLinearVelocity(), self.body.getAngularVelocity(), xh_p, xh_q)
        force, torque = F[:3], F[3:]
        self.body.clearExternalForces()
        self.body.setExtForce(force, np.zeros(3), False, True)   # at G (the body's origin), world frame
        self.body.setExtTorque(torque, False)                    # world frame
        self.world.step()
        p, q = self.pose()
        seconds = time.perf_counter() - start
        rows = []
        for ct in self.world.getLastCollisionResult().getContacts():
            tool_first = ct.collisionObject1.getShape().getID() in self.tool_shapes
            n = np.array(ct.normal, float)  # DART: from object 2 to object 1
            normal = n if tool_first else -n
            rows.append((*np.array(ct.point, float), *normal, -float(ct.penetrationDepth)))
        contacts = common.reported_contacts(rows)
        return EngineStep(p, q, np.concatenate([-force, -torque]), contacts, seconds)

    def close(self) -> None:
        self.world = None
