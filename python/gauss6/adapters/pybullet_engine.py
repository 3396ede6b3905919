"""PyBullet behind the engine contract: a free tool body held by a fixed constraint whose
child frame is driven to the handle's pose each tick (docs/engine-adapters.md).

Model, built from the EngineScene at reset (a DIRECT client of its own):
- the obstacles: static bodies (mass 0) with their own concave triangle meshes (Bullet's BVH
  triangle mesh, GEOM_FORCE_CONCAVE_TRIMESH: exact geometry, allowed for static bodies only);
- the tool: a dynamic body whose collision shape is the compound of the tool mesh's convex parts
  (an OBJ with one object a part, which PyBullet loads as a compound of convex hulls: a dynamic
  concave mesh is not supported), the scene's mass, and its inertia about G through the
  principal axes (Bullet takes a diagonal inertia: the inertial frame is rotated onto them);
- a JOINT_FIXED constraint from the tool's G frame to the world, its child frame set to xh and
  its maxForce and erp set each tick (changeConstraint);
- no gravity, friction 0.3, the collision margins at 0.1 mm (Bullet's default, 4 cm, is
  larger than the peg's 0.2 mm clearance), one simulation step of 1 / rate a tick.

Each tick: the constraint's child frame = xh; stepSimulation; xs = the tool's G pose; the
wrench sent to the user is the constraint's reaction on the handle: getConstraintState gives the
force the constraint applies to the tool in the world frame and its torque about G in G's frame
(checked against the tool's inertia in free motion: python/tests/test_adapters.py); the
handle feels the opposite. Contacts:
getContactPoints (point on the tool, normal from the obstacle to the tool, distance).

Parameters (config keys; docs/engine-adapters.md gives the reasons):
  max_force   the constraint's force limit (N): the swept parameter, penetration against force
  erp         the constraint's error reduction per step (0.2: Bullet's default for joints)
  margin      collision margin of every shape (m)
  friction    lateral friction coefficient
  iterations  solver iterations a step
"""
from __future__ import annotations

import time

import numpy as np

from ..engine import EngineScene, EngineStep
from ..oracle import quat_mul, rotation_matrices
from . import common

DEFAULTS = {"max_force": 20.0, "erp": 0.2, "margin": 1e-4, "friction": 0.3, "iterations": 50}


def _conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def _principal(I: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(principal moments, quaternion w x y z of the rotation from the principal axes to B)."""
    w, R = np.linalg.eigh(I)
    if np.linalg.det(R) < 0:
        R[:, 2] = -R[:, 2]
    from scipy.spatial.transform import Rotation

    x, y, z, s = Rotation.from_matrix(R).as_quat()
    return w, np.array([s, x, y, z])


class PyBulletEngine:
    def __init__(self, config: str = ""):
        import pybullet

        self.cfg = common.parse_config(config, DEFAULTS)
        if self.cfg["max_force"] <= 0 or not 0 < self.cfg["erp"] <= 1:
            raise ValueError("config: max_force must be > 0 and erp in (0, 1]")
        from importlib.metadata import version

        del pybullet  # imported above only to fail here when PyBullet is not installed
        self.name = f"pybullet {version('pybullet')}"
        self.config = config
        self.client = None

    def reset(self, scene: EngineScene) -> None:
        import pybullet as pb
        from pybullet_utils.bullet_client import BulletClient

        c = self.cfg
        self.close()
        self.pb = pb
        self.client = BulletClient(connection_mode=pb.DIRECT)
        b = self.client
        b.setGravity(0, 0, 0)
        b.setPhysicsEngineParameter(fixedTimeStep=1.0 / scene.rate_hz, numSubSteps=0,
                                    numSolverIterations=c["iterations"])
        for o in scene.obstacles:
            shape = b.createCollisionShape(pb.GEOM_MESH, vertices=np.asarray(o.V, float).tolist(),
                                           indices=np.asarray(o.F, int).ravel().tolist(),
                                           flags=pb.GEOM_FORCE_CONCAVE_TRIMESH)
            body = b.createMultiBody(0, shape, basePosition=list(map(float, o.p)),
                                     baseOrientation=common.wxyz_to_xyzw(common.unit(o.q)))
            b.changeDynamics(body, -1, lateralFriction=c["friction"], collisionMargin=c["margin"])
        parts = str(common.convex_parts_file(scene.tool.V, scene.tool.F, f"{scene.name}:tool"))
        shape = b.createCollisionShape(pb.GEOM_MESH, fileName=parts)
        moments, self.q_BI = _principal(scene.inertia_G_B)
        q0 = common.unit(scene.tool.q)
        # The base's reported pose is its inertial frame's: X_WI = X_WB X_BI (here X_BI a rotation).
        self.tool = b.createMultiBody(scene.mass, shape, basePosition=list(map(float, scene.tool.p)),
                                      baseOrientation=common.wxyz_to_xyzw(q0),
                                      baseInertialFramePosition=[0, 0, 0],
                                      baseInertialFrameOrientation=common.wxyz_to_xyzw(self.q_BI))
        b.changeDynamics(self.tool, -1, localInertiaDiagonal=moments.tolist(), lateralFriction=c["friction"],
                         collisionMargin=c["margin"], linearDamping=0, angularDamping=0)
        # The constraint's parent frame is given in the base's inertial frame: B's origin and axes.
        self.constraint = b.createConstraint(self.tool, -1, -1, -1, pb.JOINT_FIXED, [0, 0, 0],
                                             parentFramePosition=[0, 0, 0],
                                             childFramePosition=list(map(float, scene.tool.p)),
                                             parentFrameOrientation=common.wxyz_to_xyzw(_conj(self.q_BI)),
                                             childFrameOrientation=common.wxyz_to_xyzw(q0))
        b.changeConstraint(self.constraint, maxForce=c["max_force"], erp=c["erp"])

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        p, q = self.client.getBasePositionAndOrientation(self.tool)
        q_WB = quat_mul(common.xyzw_to_wxyz(q), _conj(self.q_BI))
        return np.array(p, float), q_WB

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        b, c = self.client, self.cfg
        start = time.perf_counter()
        b.changeConstraint(self.constraint, jointChildPivot=[float(v) for v in xh_p],
                           jointChildFrameOrientation=common.wxyz_to_xyzw(common.unit(xh_q)),
                           maxForce=c["max_force"], erp=c["erp"])
        b.stepSimulation()
        p, q = self.pose()
        applied = np.array(b.getConstraintState(self.constraint), float)
        applied[3:] = rotation_matrices(q)[0] @ applied[3:]  # the torque comes in the frame of G
        seconds = time.perf_counter() - start
        points = b.getContactPoints(bodyA=self.tool)
        contacts = common.reported_contacts([(*cp[5], *(-np.asarray(cp[7])), cp[8]) for cp in points])
        return EngineStep(p, q, -applied, contacts, seconds)

    def close(self) -> None:
        if getattr(self, "client", None) is not None:
            try:
                self.client.disconnect()
            except Exception:
                pass
            self.client = None

    def __del__(self):
        self.close()
