"""MuJoCo behind the engine contract: the usual haptic proxy set-up there, a mocap body at the
handle's pose welded to a free tool body (docs/engine-adapters.md).

Model, built from the EngineScene at reset:
- the tool: a free body whose frame is G (the scene's mass and inertia about G, not MuJoCo's
  from the geoms), its collision geometry the tool mesh's convex parts (MuJoCo collides the
  convex hull of each mesh geom, so a concave mesh needs a decomposition: CoACD, common.py);
- the obstacles: static geoms in the world body, their convex parts the same way;
- the handle: a mocap body (no geoms) moved to xh each tick, and a weld equality between it and
  the tool (relpose identity: the weld pulls G onto the handle's G) with the swept softness
  solref = (weld_timeconst, weld_dampratio), solimp = (0.9, 0.95, 0.001) (MuJoCo's default);
- no gravity (the tool stands for the user's hand-held object: its weight is not rendered,
  as in gauss6), no friction loss, elliptic cones, Newton solver, implicitfast integrator.

Each tick: mocap pose = xh; `substeps` mj_step of timestep = 1 / (rate * substeps); xs = the tool's
pose; the wrench sent to the user is the reaction of the weld on the tool, -(J_weld^T f_weld): its
force and its torque about G, world frame. Contacts: MuJoCo's (point, normal from the obstacle
to the tool, distance).

Parameters (config keys; docs/engine-adapters.md gives the reasons):
  weld_timeconst  the weld's time constant (s): the swept parameter, penetration against force
  weld_dampratio  the weld's damping ratio (1: critical)
  contact_timeconst  the contacts' time constant (s): MuJoCo's default 0.02; stiffer contacts
                  chatter under the weld (the first 3 s of the peg: force peaks of 700 N at
                  0.002 s, 250 N at 0.005 s, 10 N at 0.02 s, with weld_timeconst 0.005)
  friction        sliding friction coefficient (0.3: dry steel or plastic)
  substeps        MuJoCo steps per haptic tick
  iterations      solver iterations a step
"""
from __future__ import annotations

import time

import numpy as np

from ..engine import EngineScene, EngineStep
from . import common

DEFAULTS = {"weld_timeconst": 0.005, "weld_dampratio": 1.0, "contact_timeconst": 0.02, "friction": 0.3,
            "substeps": 1, "iterations": 50}


def _floats(a) -> str:
    return " ".join(repr(float(x)) for x in np.ravel(a))


class MuJoCoEngine:
    def __init__(self, config: str = ""):
        import mujoco

        self.cfg = common.parse_config(config, DEFAULTS)
        if self.cfg["substeps"] < 1:
            raise ValueError("config substeps: at least 1")
        self.name = f"mujoco {mujoco.__version__}"
        self.config = config

    def model_xml(self, scene: EngineScene) -> str:
        c = self.cfg
        dt = 1.0 / (scene.rate_hz * c["substeps"])
        assets, world, tool = [], [], []
        for i, b in enumerate(scene.obstacles):
            for j, (v, f) in enumerate(common.convex_parts(b.V, b.F, f"{scene.name}:{b.name}")):
                assets.append(f'<mesh name="o{i}_{j}" vertex="{_floats(v)}" face="{" ".join(map(str, f.ravel()))}"/>')
                world.append(f'<geom type="mesh" mesh="o{i}_{j}" pos="{_floats(b.p)}" quat="{_floats(b.q)}" '
                             f'contype="1" conaffinity="2"/>')
        for j, (v, f) in enumerate(common.convex_parts(scene.tool.V, scene.tool.F, f"{scene.name}:tool")):
            assets.append(f'<mesh name="t{j}" vertex="{_floats(v)}" face="{" ".join(map(str, f.ravel()))}"/>')
            tool.append(f'<geom type="mesh" mesh="t{j}" contype="2" conaffinity="1"/>')
        I = scene.inertia_G_B
        full = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
        p0, q0 = _floats(scene.tool.p), _floats(common.unit(scene.tool.q))
        return f"""<mujoco model="{scene.name}">
  <compiler inertiafromgeom="false" boundmass="0" boundinertia="0"/>
  <option timestep="{dt!r}" gravity="0 0 0" integrator="implicitfast" solver="Newton" cone="elliptic"
          iterations="{c['iterations']}" tolerance="1e-10"/>
  <default><geom solref="{c['contact_timeconst']!r} 1" friction="{c['friction']!r} 0.005 0.0001"/></default>
  <asset>{''.join(assets)}</asset>
  <worldbody>
    {''.join(world)}
    <body name="handle" mocap="true" pos="{p0}" quat="{q0}"/>
    <body name="tool" pos="{p0}" quat="{q0}">
      <freejoint name="tool"/>
      <inertial pos="0 0 0" mass="{scene.mass!r}" fullinertia="{_floats(full)}"/>
      {''.join(tool)}
    </body>
  </worldbody>
  <equality>
    <weld name="coupling" body1="handle" body2="tool" relpose="0 0 0 1 0 0 0"
          solref="{c['weld_timeconst']!r} {c['weld_dampratio']!r}" solimp="0.9 0.95 0.001"/>
  </equality>
</mujoco>"""

    def reset(self, scene: EngineScene) -> None:
        import mujoco

        self.mj = mujoco
        self.model = mujoco.MjModel.from_xml_string(self.model_xml(scene))
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        self.tool = self.model.body("tool").id
        self.num_obstacle_geoms = int(np.sum(self.model.geom_bodyid == 0))
        self._J = np.zeros(self.model.nv)

    def step(self, t: float, xh_p, xh_q) -> EngineStep:
        mj, m, d = self.mj, self.model, self.data
        start = time.perf_counter()
        d.mocap_pos[0] = xh_p
        d.mocap_quat[0] = common.unit(xh_q)
        for _ in range(self.cfg["substeps"]):
            mj.mj_step(m, d)
        # The weld's generalized force on the tool: J^T f over the equality rows (free joint:
        # force in the world frame, torque in the body frame about the body's origin, G).
        f = np.where(d.efc_type == mj.mjtConstraint.mjCNSTR_EQUALITY, d.efc_force, 0.0)
        qfrc = np.zeros(m.nv)
        if len(f):
            mj.mj_mulJacTVec(m, d, qfrc, f)
        xs_p = d.qpos[0:3].copy()
        xs_q = d.qpos[3:7].copy()
        R = d.xmat[self.tool].reshape(3, 3)
        wrench = -np.concatenate([qfrc[0:3], R @ qfrc[3:6]])
        seconds = time.perf_counter() - start
        contacts = np.zeros((d.ncon, 7))
        for i in range(d.ncon):
            c = d.contact[i]
            n = c.frame[0:3] if m.geom_bodyid[c.geom1] == 0 else -c.frame[0:3]
            contacts[i] = (*c.pos, *n, c.dist)
        return EngineStep(xs_p, xs_q, wrench, common.reported_contacts(contacts), seconds)
