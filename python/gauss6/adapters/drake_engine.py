"""Drake behind the engine contract: a free tool body pulled to the handle by a spatial-force
virtual coupling (docs/engine-adapters.md).

Model, built from the EngineScene at reset (a discrete MultibodyPlant, SAP solver):
- the obstacles: welded to the world, rigid hydroelastic with their own concave triangle meshes
  (Drake's rigid hydroelastic geometry takes a non-convex surface mesh);
- the tool: a free body at G with the scene's mass and inertia about G, its geometry the tool
  mesh's convex parts (CoACD, common.py), each compliant hydroelastic (a compliant Mesh would
  need a tetrahedral mesh; Drake meshes a compliant Convex itself);
- contact_model=hydroelastic (the default) or point (config `contact=point`: point contact
  with Drake's convex hull of each shape, so the obstacles' parts are used there too);
- no gravity; friction 0.3; Hunt-Crossley dissipation 5 s/m.

The coupling, each tick, from the tool's pose and velocity at the tick's start:
    F_tool = -kc M (x_tool (-) xh) - 2 zeta sqrt(kc) M (v_tool - v_h)
with M = diag(m I, R I_B R^T) (the scene's mass matrix at the tool's pose, so that one
stiffness kc (1/s^2) sets one natural frequency for every direction, like gauss6's kh M), v_h
the handle's velocity by backward difference. It is applied as an externally applied spatial
force on the tool at G for one plant step of 1 / rate; the wrench sent to the user is -F_tool.

Parameters (config keys; docs/engine-adapters.md gives the reasons):
  kc          the coupling stiffness (1/s^2): the swept parameter, penetration against force
  zeta        the coupling's damping ratio (1: critical)
  contact     hydroelastic | point
  modulus     hydroelastic modulus of the tool's parts (Pa)
  resolution  the resolution hint of the tool's compliant parts (m)
  friction    Coulomb friction coefficient
"""
from __future__ import annotations

import time

import numpy as np

from ..engine import EngineScene, EngineStep
from ..oracle import pose_difference, rotation_matrices
from . import common

DEFAULTS = {"kc": 4000.0, "zeta": 1.0, "contact": "hydroelastic", "modulus": 1e8, "resolution": 0.005,
            "friction": 0.3, "dissipation": 5.0}


class DrakeEngine:
    def __init__(self, config: str = ""):
        import pydrake  # noqa: F401  (fails here when Drake is not installed)

        self.cfg = common.parse_config(config, DEFAULTS)
        if self.cfg["contact"] not in ("hydroelastic", "point"):
            raise ValueError(f"config contact={self.cfg['contact']!r}: hydroelastic or point")
        if self.cfg["kc"] <= 0 or self.cfg["zeta"] < 0:
            raise ValueError("config: kc must be > 0 and zeta >= 0")
        from importlib.metadata import version

        self.name = f"drake {version('drake')}"
        self.config = config

    def reset(self, scene: EngineScene) -> None:
        from pydrake.geometry import (AddCompliantHydroelasticProperties, AddContactMaterial,
                                      AddRigidHydroelasticProperties, Convex, Mesh, ProximityProperties)
        from pydrake.math import RigidTransform, RotationMatrix
        from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction, ExternallyAppliedSpatialForce,
                                             MultibodyPlantConfig)
        from pydrake.multibody.tree import RotationalInertia, SpatialInertia
        from pydrake.common.eigen_geometry import Quaternion
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder

        c = self.cfg
        self.dt = 1.0 / scene.rate_hz
        builder = DiagramBuilder()
        plant, _ = AddMultibodyPlant(MultibodyPlantConfig(
            time_step=self.dt, discrete_contact_approximation="sap",
            contact_model="hydroelastic_with_fallback" if c["contact"] == "hydroelastic" else "point"), builder)
        friction = CoulombFriction(c["friction"], c["friction"])

        def pose(p, q):
            return RigidTransform(Quaternion(common.unit(q)), np.asarray(p, float))

        for i, o in enumerate(scene.obstacles):
            props = ProximityProperties()
            AddContactMaterial(dissipation=c["dissipation"], friction=friction, properties=props)
            AddRigidHydroelasticProperties(props)
            plant.RegisterCollisionGeometry(plant.world_body(), pose(o.p, o.q),
                                            Mesh(str(common.mesh_file(o.V, o.F, f"{scene.name}-{o.name}"))),
                                            f"obstacle{i}", props)
        I = scene.inertia_G_B
        inertia = SpatialInertia.MakeFromCentralInertia(
            scene.mass, np.zeros(3), RotationalInertia(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))
        self.body = plant.AddRigidBody("tool", inertia)
        for j, path in enumerate(common.part_files(scene.tool.V, scene.tool.F, f"{scene.name}-tool")):
            props = ProximityProperties()
            AddContactMaterial(dissipation=c["dissipation"], friction=friction, properties=props)
            AddCompliantHydroelasticProperties(c["resolution"], c["modulus"], props)
            plant.RegisterCollisionGeometry(self.body, RigidTransform(), Convex(str(path)), f"tool{j}", props)
        plant.mutable_gravity_field().set_gravity_vector([0, 0, 0])
        plant.Finalize()
        self.plant = plant
        self.diagram = builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        plant.SetFreeBodyPose(self.plant_context, self.body, pose(scene.tool.p, scene.tool.q))
        self.force_port = plant.get_applied_spatial_force_input_port()
        self.applied = ExternallyAppliedSpatialForce()
        self.applied.body_index = self.body.index()
        self.applied.p_BoBq_B = np.zeros(3)
        self._SpatialForce = __import__("pydrake.multibody.math", fromlist=["SpatialForce"]).SpatialForce
        self.mass = scene.mass
        self.inertia = np.asarray(I, float)
        self.prev_xh = None
        self.t = 0.0
        self.simulator.Initialize()

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        X = self.plant.EvalBodyPoseInWorld(self.plant_context, self.body)
        V = self.plant.EvalBodySpatialVelocityInWorld(self.plant_context, self.body)
        q = X.rotation().ToQuaternion()
        return np.array(X.translation()), np.array([q.w(), q.x(), q.y(), q.z()]), \
            np.concatenate([V.translational(), V.rotational()])

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        c = self.cfg
        start = time.perf_counter()
        xh_p, xh_q = np.asarray(xh_p, float), common.unit(xh_q)
        p, q, v = self.state()
        if self.prev_xh is None:
            v_h = np.zeros(6)
        else:
            v_h = pose_difference(xh_p, xh_q, *self.prev_xh) / self.dt
        self.prev_xh = (xh_p, xh_q)
        R = rotation_matrices(q)[0]
        M = np.zeros((6, 6))
        M[:3, :3] = self.mass * np.eye(3)
        M[3:, 3:] = R @ self.inertia @ R.T
        e = pose_difference(p, q, xh_p, xh_q)
        F_tool = -c["kc"] * (M @ e) - 2 * c["zeta"] * np.sqrt(c["kc"]) * (M @ (v - v_h))
        self.applied.F_Bq_W = self._SpatialForce(F_tool[3:], F_tool[:3])
        self.force_port.FixValue(self.plant_context, [self.applied])
        self.t += self.dt
        self.simulator.AdvanceTo(self.t)
        p1, q1, _ = self.state()
        seconds = time.perf_counter() - start
        return EngineStep(p1, q1, -F_tool, None, seconds)
