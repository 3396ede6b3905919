// Bullet Physics (Debian's libbullet-dev, 3.24) behind gauss6's engine contract
// (engine/include/gauss6/engine.h), built as a third-party engine team would build it: against
// the contract's header only, as a shared library that exports gauss6_engine_get.
//
// The model (README.md beside this file says why each choice and parameter):
// - the obstacles: static bodies with Bullet's BVH triangle meshes (btBvhTriangleMeshShape), the
//   scene's own triangles;
// - the tool: one dynamic body, a GImpact triangle mesh (btGImpactMeshShape: Bullet's collision
//   shape for a moving concave mesh, the tool's own triangles, no convex decomposition), whose
//   frame is G with axes along the principal axes of the scene's inertia about G;
// - a virtual coupling (spring and damper, 6 DoF) pulls the tool towards the handle's pose:
//   F = kc m (p_h - p_s) - 2 zeta sqrt(kc) m (v - v_h),
//   tau = kc I_W theta - 2 zeta sqrt(kc) I_W (omega - omega_h),
//   theta the rotation vector from the tool's orientation to the handle's, (v_h, omega_h) the
//   handle's velocity by backward difference (zero at the first tick); the user feels -(F, tau);
// - no gravity, one Bullet step of 1 / rate_hz a tick (substeps smaller steps when asked).
// The swept stiffness-like parameter is kc (1/s^2: kc m is the coupling's stiffness, N/m).
#include <gauss6/engine.h>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Config {
  double kc = 4000.0;          // 1/s^2, the coupling's stiffness per unit mass (the swept parameter)
  double damping_ratio = 1.0;  // zeta: critical damping of the coupled tool in free motion
  double margin = 1e-4;        // m, collision margin of every shape (Bullet's default 4 cm is a scene's size)
  double friction = 0.3;       // Coulomb coefficient of every contact
  int substeps = 1;            // Bullet steps a haptic tick
};

void write_error(char* error, size_t size, const std::string& text) {
  if (error && size > 0) std::snprintf(error, size, "%s", text.c_str());
}

// "key=value" pairs separated by commas or spaces; unknown keys and bad values are errors.
bool parse_config(const char* text, Config& c, std::string& why) {
  std::string s(text ? text : "");
  for (char& ch : s)
    if (ch == ',') ch = ' ';
  std::istringstream in(s);
  std::string item;
  while (in >> item) {
    auto eq = item.find('=');
    if (eq == std::string::npos) {
      why = "config: '" + item + "' is not key=value";
      return false;
    }
    std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    char* end = nullptr;
    double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v)) {
      why = "config: " + key + ": '" + value + "' is not a finite number";
      return false;
    }
    if (key == "kc") c.kc = v;
    else if (key == "damping_ratio") c.damping_ratio = v;
    else if (key == "margin") c.margin = v;
    else if (key == "friction") c.friction = v;
    else if (key == "substeps") c.substeps = static_cast<int>(v);
    else {
      why = "config: unknown key '" + key + "' (kc, damping_ratio, margin, friction, substeps)";
      return false;
    }
  }
  if (!(c.kc > 0) || !(c.damping_ratio >= 0) || !(c.margin > 0) || !(c.friction >= 0) || c.substeps < 1) {
    why = "config: kc and margin must be > 0, damping_ratio and friction >= 0, substeps >= 1";
    return false;
  }
  return true;
}

btQuaternion to_bt(const double q[4]) { return btQuaternion(q[1], q[2], q[3], q[0]); }  // (w,x,y,z) -> (x,y,z,w)

// A mesh's arrays, owned (Bullet's meshes point into them).
struct MeshData {
  std::vector<btScalar> vertices;
  std::vector<int> faces;
  std::unique_ptr<btTriangleIndexVertexArray> array;

  MeshData(const gauss6_mesh& m, const btMatrix3x3& R) {
    vertices.resize(3 * static_cast<size_t>(m.num_vertices));
    for (int32_t i = 0; i < m.num_vertices; ++i) {
      btVector3 v = R * btVector3(m.vertices[3 * i], m.vertices[3 * i + 1], m.vertices[3 * i + 2]);
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = v[k];
    }
    faces.assign(m.faces, m.faces + 3 * static_cast<size_t>(m.num_faces));
    array = std::make_unique<btTriangleIndexVertexArray>(m.num_faces, faces.data(), 3 * sizeof(int),
                                                         m.num_vertices, vertices.data(), 3 * sizeof(btScalar));
  }
};

class BulletEngine {
 public:
  explicit BulletEngine(const Config& c) : cfg_(c) {}
  ~BulletEngine() { clear(); }

  bool reset(const gauss6_scene_desc& s, std::string& why) {
    clear();
    if (!(s.mass > 0) || !(s.rate_hz > 0) || s.num_obstacles < 0) {
      why = "scene: mass and rate_hz must be > 0";
      return false;
    }
    collision_config_ = std::make_unique<btDefaultCollisionConfiguration>();
    dispatcher_ = std::make_unique<btCollisionDispatcher>(collision_config_.get());
    btGImpactCollisionAlgorithm::registerAlgorithm(dispatcher_.get());
    broadphase_ = std::make_unique<btDbvtBroadphase>();
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(),
                                                       collision_config_.get());
    world_->setGravity(btVector3(0, 0, 0));
    const btMatrix3x3 identity = btMatrix3x3::getIdentity();
    for (int32_t i = 0; i < s.num_obstacles; ++i) {
      const gauss6_body& o = s.obstacles[i];
      meshes_.push_back(std::make_unique<MeshData>(o.mesh, identity));
      auto shape = std::make_unique<btBvhTriangleMeshShape>(meshes_.back()->array.get(), true);
      shape->setMargin(cfg_.margin);
      btTransform X(to_bt(o.X_WB.q).normalized(), btVector3(o.X_WB.p[0], o.X_WB.p[1], o.X_WB.p[2]));
      auto body = std::make_unique<btRigidBody>(0.0, nullptr, shape.get());
      body->setWorldTransform(X);
      body->setFriction(cfg_.friction);
      body->setRestitution(0.0);
      world_->addRigidBody(body.get());
      shapes_.push_back(std::move(shape));
      bodies_.push_back(std::move(body));
    }
    // The tool's frame I: origin G, axes the principal axes of the inertia about G (Bullet's
    // bodies take a diagonal inertia). R_BI's columns are those axes in B.
    btMatrix3x3 I_B(s.inertia_G_B[0], s.inertia_G_B[1], s.inertia_G_B[2], s.inertia_G_B[3], s.inertia_G_B[4],
                    s.inertia_G_B[5], s.inertia_G_B[6], s.inertia_G_B[7], s.inertia_G_B[8]);
    btMatrix3x3 R_BI = btMatrix3x3::getIdentity(), D = I_B;
    D.diagonalize(R_BI, 1e-14, 64);
    if (R_BI.determinant() < 0) R_BI.setValue(R_BI[0][0], R_BI[0][1], -R_BI[0][2], R_BI[1][0], R_BI[1][1], -R_BI[1][2],
                                              R_BI[2][0], R_BI[2][1], -R_BI[2][2]);
    btVector3 moments(D[0][0], D[1][1], D[2][2]);
    if (!(moments.x() > 0 && moments.y() > 0 && moments.z() > 0)) {
      why = "scene: the tool's inertia is not positive definite";
      return false;
    }
    R_BI_ = R_BI;
    meshes_.push_back(std::make_unique<MeshData>(s.tool.mesh, R_BI.transpose()));  // vertices in I
    auto tool_shape = std::make_unique<btGImpactMeshShape>(meshes_.back()->array.get());
    tool_shape->setMargin(cfg_.margin);
    tool_shape->updateBound();
    mass_ = s.mass;
    btRigidBody::btRigidBodyConstructionInfo info(s.mass, nullptr, tool_shape.get(), moments);
    info.m_friction = cfg_.friction;
    info.m_restitution = 0.0;
    info.m_linearDamping = 0.0;
    info.m_angularDamping = 0.0;
    tool_ = std::make_unique<btRigidBody>(info);
    tool_->setWorldTransform(pose_to_I(s.tool.X_WB));
    have_prev_ = false;
    tool_->setActivationState(DISABLE_DEACTIVATION);
    tool_->setSleepingThresholds(0, 0);
    world_->addRigidBody(tool_.get());
    shapes_.push_back(std::move(tool_shape));
    dt_ = 1.0 / s.rate_hz;
    return true;
  }

  bool step(const gauss6_pose& xh, gauss6_step_out& out, std::string& why) {
    if (!world_) {
      why = "step before a successful reset";
      return false;
    }
    auto start = std::chrono::steady_clock::now();
    const btTransform X_WH = pose_to_I(xh);
    btVector3 v_h(0, 0, 0), omega_h(0, 0, 0);
    if (have_prev_) {
      v_h = (X_WH.getOrigin() - prev_X_WH_.getOrigin()) / dt_;
      omega_h = rotation_vector(X_WH.getRotation() * prev_X_WH_.getRotation().inverse()) / dt_;
    }
    prev_X_WH_ = X_WH;
    have_prev_ = true;
    const double w = std::sqrt(cfg_.kc), c = 2.0 * cfg_.damping_ratio * w;
    btVector3 force(0, 0, 0), torque(0, 0, 0);
    for (int k = 0; k < cfg_.substeps; ++k) {
      const btTransform X = tool_->getWorldTransform();
      force = cfg_.kc * mass_ * (X_WH.getOrigin() - X.getOrigin()) - c * mass_ * (tool_->getLinearVelocity() - v_h);
      const btVector3 theta = rotation_vector(X_WH.getRotation() * X.getRotation().inverse());
      const btMatrix3x3 I_W = X.getBasis().scaled(tool_->getLocalInertia()) * X.getBasis().transpose();
      torque = I_W * (cfg_.kc * theta - c * (tool_->getAngularVelocity() - omega_h));
      tool_->clearForces();
      tool_->applyCentralForce(force);
      tool_->applyTorque(torque);
      world_->stepSimulation(dt_ / cfg_.substeps, 0, dt_ / cfg_.substeps);
    }
    const btTransform X = tool_->getWorldTransform();
    btQuaternion q_IB;
    R_BI_.transpose().getRotation(q_IB);
    const btQuaternion q_WB = X.getRotation() * q_IB;
    for (int k = 0; k < 3; ++k) out.X_WS.p[k] = X.getOrigin()[k];
    out.X_WS.q[0] = q_WB.w(), out.X_WS.q[1] = q_WB.x(), out.X_WS.q[2] = q_WB.y(), out.X_WS.q[3] = q_WB.z();
    for (int k = 0; k < 3; ++k) out.wrench[k] = -force[k], out.wrench[3 + k] = -torque[k];
    int32_t n = 0;
    const int manifolds = dispatcher_->getNumManifolds();
    for (int m = 0; m < manifolds; ++m) {
      const btPersistentManifold* pm = dispatcher_->getManifoldByIndexInternal(m);
      const bool tool_is_a = pm->getBody0() == tool_.get();
      if (!tool_is_a && pm->getBody1() != tool_.get()) continue;
      for (int i = 0; i < pm->getNumContacts(); ++i, ++n) {
        if (n >= out.contact_capacity || !out.contacts) continue;  // counted, not written
        const btManifoldPoint& cp = pm->getContactPoint(i);
        const btVector3 point = tool_is_a ? cp.getPositionWorldOnA() : cp.getPositionWorldOnB();
        const btVector3 normal = tool_is_a ? cp.m_normalWorldOnB : -cp.m_normalWorldOnB;  // obstacle -> tool
        gauss6_contact& o = out.contacts[n];
        for (int k = 0; k < 3; ++k) o.point[k] = point[k], o.normal[k] = normal[k];
        o.separation = cp.getDistance();
      }
    }
    out.num_contacts = n < out.contact_capacity ? n : out.contact_capacity;
    out.step_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return true;
  }

  std::string last_error;

 private:
  // A pose of B (origin G) to the pose of the tool's frame I: X_WI = X_WB X_BI.
  btTransform pose_to_I(const gauss6_pose& x) const {
    btQuaternion q_WB = to_bt(x.q).normalized();
    return btTransform(btMatrix3x3(q_WB) * R_BI_, btVector3(x.p[0], x.p[1], x.p[2]));
  }

  void clear() {
    if (world_) {
      if (tool_) world_->removeRigidBody(tool_.get());
      for (auto& b : bodies_) world_->removeRigidBody(b.get());
    }
    tool_.reset();
    bodies_.clear();
    shapes_.clear();
    meshes_.clear();
    world_.reset();
    solver_.reset();
    broadphase_.reset();
    dispatcher_.reset();
    collision_config_.reset();
  }

  // The rotation vector of a rotation q (the shorter way round).
  static btVector3 rotation_vector(btQuaternion q) {
    if (q.w() < 0) q = -q;
    const btScalar s = btVector3(q.x(), q.y(), q.z()).length();
    if (s < 1e-300) return btVector3(2 * q.x(), 2 * q.y(), 2 * q.z());
    return btVector3(q.x(), q.y(), q.z()) * (2 * std::atan2(s, q.w()) / s);
  }

  Config cfg_;
  double mass_ = 0, dt_ = 1e-3;
  btTransform prev_X_WH_;
  bool have_prev_ = false;
  btMatrix3x3 R_BI_ = btMatrix3x3::getIdentity();
  std::unique_ptr<btDefaultCollisionConfiguration> collision_config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<MeshData>> meshes_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::unique_ptr<btRigidBody> tool_;
};

void* create(const char* config, char* error, size_t error_size) {
  Config c;
  std::string why;
  if (!parse_config(config, c, why)) {
    write_error(error, error_size, why);
    return nullptr;
  }
  return new (std::nothrow) BulletEngine(c);
}

int reset(void* engine, const gauss6_scene_desc* scene, char* error, size_t error_size) {
  auto* e = static_cast<BulletEngine*>(engine);
  if (!scene || scene->struct_size != sizeof(gauss6_scene_desc)) {
    write_error(error, error_size, "reset: scene description of another size (ABI mismatch)");
    return GAUSS6_ENGINE_ERROR;
  }
  std::string why;
  if (!e->reset(*scene, why)) {
    write_error(error, error_size, why);
    return GAUSS6_ENGINE_ERROR;
  }
  return GAUSS6_ENGINE_OK;
}

int step(void* engine, double, const gauss6_pose* X_WH, gauss6_step_out* out) {
  auto* e = static_cast<BulletEngine*>(engine);
  if (!X_WH || !out || out->struct_size != sizeof(gauss6_step_out)) {
    e->last_error = "step: null argument or step output of another size (ABI mismatch)";
    return GAUSS6_ENGINE_ERROR;
  }
  std::string why;
  if (!e->step(*X_WH, *out, why)) {
    e->last_error = why;
    return GAUSS6_ENGINE_ERROR;
  }
  return GAUSS6_ENGINE_OK;
}

const char* last_error(void* engine) { return static_cast<BulletEngine*>(engine)->last_error.c_str(); }

void destroy(void* engine) { delete static_cast<BulletEngine*>(engine); }

const gauss6_engine_v1 kTable = {GAUSS6_ENGINE_ABI_VERSION,
                                 sizeof(gauss6_engine_v1),
                                 sizeof(gauss6_scene_desc),
                                 sizeof(gauss6_step_out),
                                 "bullet 3.24 (GImpact tool, virtual coupling)",
                                 create,
                                 reset,
                                 step,
                                 last_error,
                                 destroy};

}  // namespace

extern "C" __attribute__((visibility("default"))) const void* gauss6_engine_get(uint32_t abi_version) {
  return abi_version == GAUSS6_ENGINE_ABI_VERSION ? &kTable : nullptr;
}
