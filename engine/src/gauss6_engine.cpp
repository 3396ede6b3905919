// gauss6's own runtime behind the engine contract's C ABI (gauss6/engine.h):
// the shared library libgauss6_engine.so, which the validation driver loads as
// it loads any other engine (docs/engine-contract.md).
//
// One step is one lockstep tick of run_lockstep (runtime.h): a sim step (every
// lockstep_sim_period ticks), then the haptic tick (device read, coupling step,
// safety, device write) with a port device that returns the caller's X_WH and
// keeps the wrench written to it. Driven by the simulated device at the scene's
// rate, a run is therefore the run of `gauss6 reproduce`, tick for tick.
//
// The displayed pose is the god-object pose the coupling step used; the contacts
// are the sim loop's current set (point on the god-object, normal out of the
// obstacle, separation); step_seconds is the wall time of the call.
//
// Config text: "sim_period=N" (haptic ticks per sim step, default 1); any other key is
// refused (gauss6/engine_config.h).
// Scene: the gauss6 scene file when scene_path is set (every setting of the file),
// otherwise a scene built from the description (offset_eps -10 delta, offset_time
// 0.05 s: the scene format's defaults).
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "gauss6/engine.h"
#include "gauss6/engine_config.h"
#include "gauss6/runtime/runtime.h"
#include "gauss6/io/scene.h"

namespace {

using namespace gauss6;

// The handle the caller gives, as a Device: read() returns it, write() keeps F.
class PortDevice final : public Device {
 public:
  explicit PortDevice(const DeviceSettings& s) {
    info_.name = "engine port";
    info_.rate_hz = s.rate_hz;
    info_.max_force = s.max_force;
    info_.max_torque = s.max_torque;
  }
  const DeviceInfo& info() const override { return info_; }
  DeviceStatus read(double t, DeviceState* state) override {
    state->time = t;
    state->X_WH = X_WH;
    state->gripped = true;
    state->status = DeviceStatus::kOk;
    state->message = "";
    return DeviceStatus::kOk;
  }
  DeviceStatus write(double, const Vec6& F_in) override {
    F = F_in;
    return DeviceStatus::kOk;
  }
  Pose X_WH;
  Vec6 F = Vec6::Zero();

 private:
  DeviceInfo info_;
};

struct Engine {
  int sim_period = 1;
  std::unique_ptr<Scene> scene;
  std::unique_ptr<RuntimeModel> model;
  std::unique_ptr<RuntimeData> data;
  std::unique_ptr<PortDevice> device;
  long tick = 0;
  std::string error;
};

void set_error(char* error, size_t size, const std::string& text) {
  if (error && size) std::snprintf(error, size, "%s", text.c_str());
}

Pose to_pose(const gauss6_pose& x) { return Pose{Vec3(x.p[0], x.p[1], x.p[2]), Quat{x.q[0], x.q[1], x.q[2], x.q[3]}}; }

void from_pose(const Pose& X, gauss6_pose* x) {
  for (int c = 0; c < 3; ++c) x->p[c] = X.p[c];
  x->q[0] = X.q.w, x->q[1] = X.q.x, x->q[2] = X.q.y, x->q[3] = X.q.z;
}

TriangleMesh to_mesh(const gauss6_mesh& m) {
  TriangleMesh out;
  out.V.resize(m.num_vertices, 3);
  out.F.resize(m.num_faces, 3);
  for (int32_t v = 0; v < m.num_vertices; ++v)
    for (int c = 0; c < 3; ++c) out.V(v, c) = m.vertices[3 * v + c];
  for (int32_t f = 0; f < m.num_faces; ++f)
    for (int c = 0; c < 3; ++c) out.F(f, c) = m.faces[3 * f + c];
  return out;
}

// A scene built from the description alone (no scene file).
Scene scene_from_description(const gauss6_scene_desc& d) {
  Scene s;
  s.name = d.name ? d.name : "";
  for (int32_t i = 0; i < d.num_obstacles; ++i) {
    Body b;
    b.name = d.obstacles[i].name ? d.obstacles[i].name : "";
    b.mesh = to_mesh(d.obstacles[i].mesh);
    b.pose = to_pose(d.obstacles[i].X_WB);
    s.obstacles.push_back(std::move(b));
  }
  s.god_object.name = d.tool.name ? d.tool.name : "";
  s.god_object.role = BodyRole::kGodObject;
  s.god_object.mesh = to_mesh(d.tool.mesh);
  s.god_object.pose = to_pose(d.tool.X_WB);
  s.god_mass.from_density = false;
  s.god_mass.mass.mass = d.mass;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s.god_mass.mass.inertia(r, c) = d.inertia_G_B[3 * r + c];
  s.gains.ks = d.ks;
  s.gains.kh = d.kh;
  s.contact.delta = d.delta;
  s.contact.offset_eps = kDefaultOffsetEpsPerDelta * d.delta;
  s.device.rate_hz = d.rate_hz;
  s.device.max_force = d.max_force;
  s.device.max_torque = d.max_torque;
  return s;
}

void* create(const char* config, char* error, size_t error_size) {
  auto e = std::make_unique<Engine>();
  static const char* const keys[] = {"sim_period", nullptr};
  if (gauss6_config_check(config, keys, "gauss6 engine", error, error_size) != 0) return nullptr;
  char value[32];
  if (gauss6_config_value(config, "sim_period", value, sizeof value)) {
    char* end = nullptr;
    const long n = std::strtol(value, &end, 10);
    e->sim_period = end != value && *end == 0 && n >= 1 && n <= 1000000 ? static_cast<int>(n) : 0;
  }
  if (e->sim_period < 1) {
    set_error(error, error_size, "gauss6 engine: config sim_period must be an integer >= 1");
    return nullptr;
  }
  return e.release();
}

int reset(void* handle, const gauss6_scene_desc* d, char* error, size_t error_size) {
  auto* e = static_cast<Engine*>(handle);
  if (d->struct_size < sizeof(gauss6_scene_desc)) {
    set_error(error, error_size, "gauss6 engine: scene description too small");
    return GAUSS6_ENGINE_ERROR;
  }
  try {
    e->data.reset();
    e->model.reset();
    e->scene = std::make_unique<Scene>(d->scene_path && *d->scene_path ? load_scene(d->scene_path)
                                                                        : scene_from_description(*d));
    RuntimeSettings settings;
    settings.lockstep_sim_period = e->sim_period;
    e->model = std::make_unique<RuntimeModel>(*e->scene, settings);
    e->data = std::make_unique<RuntimeData>(*e->model);
    e->device = std::make_unique<PortDevice>(e->scene->device);
    e->tick = 0;
  } catch (const std::exception& ex) {
    set_error(error, error_size, std::string("gauss6 engine: ") + ex.what());
    return GAUSS6_ENGINE_ERROR;
  }
  return GAUSS6_ENGINE_OK;
}

int step(void* handle, double t, const gauss6_pose* X_WH, gauss6_step_out* out) {
  auto* e = static_cast<Engine*>(handle);
  if (!e->model) {
    e->error = "gauss6 engine: step before reset";
    return GAUSS6_ENGINE_ERROR;
  }
  if (out->struct_size < sizeof(gauss6_step_out)) {
    e->error = "gauss6 engine: step output too small";
    return GAUSS6_ENGINE_ERROR;
  }
  const auto start = std::chrono::steady_clock::now();
  RuntimeData& data = *e->data;
  // The tick of run_lockstep: a sim step every sim_period ticks, then the haptic tick.
  if (e->tick % e->model->settings.lockstep_sim_period == 0) sim_step(*e->model, t, &data.channels, &data.sim);
  e->device->X_WH = to_pose(*X_WH);
  haptic_tick(*e->model, t, e->device.get(), &data.channels, &data.haptic, &data.coupling, RuntimeObserver{},
              &data.stats);
  ++e->tick;

  from_pose(data.coupling.info.has_god_object ? data.coupling.info.xs : e->model->initial_pose, &out->X_WS);
  for (int c = 0; c < 6; ++c) out->wrench[c] = e->device->F[c];
  const ContactSet& set = data.sim.contacts;
  int written = 0;
  for (int k = 0; k < set.num_contacts && written < out->contact_capacity && out->contacts; ++k, ++written) {
    const Contact& c = set.contacts[static_cast<size_t>(k)];
    gauss6_contact& o = out->contacts[written];
    for (int i = 0; i < 3; ++i) o.point[i] = c.point[i], o.normal[i] = c.normal[i];
    o.separation = c.separation;
  }
  out->num_contacts = written;
  out->step_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return GAUSS6_ENGINE_OK;
}

const char* last_error(void* handle) { return static_cast<Engine*>(handle)->error.c_str(); }

void destroy(void* handle) { delete static_cast<Engine*>(handle); }

// With its sim step every sim_period ticks, the god-object and its contacts are updated at
// 1 / sim_period of the haptic rate: a crossing of a new constraint is answered up to
// 2 (sim_period - 1) ticks later than at sim_period 1, which the engine declares.
int declare(void* handle, gauss6_declarations* out) {
  const auto* e = static_cast<const Engine*>(handle);
  if (e->sim_period > 1) {
    out->flags |= GAUSS6_DECLARE_LATENCY;
    out->latency_ticks = 2 * (e->sim_period - 1);
  }
  return GAUSS6_ENGINE_OK;
}

#define GAUSS6_ENGINE_V1_FIELDS(version, size) \
  version, size, sizeof(gauss6_scene_desc), sizeof(gauss6_step_out), "gauss6 (god-object, lockstep tick)", \
      create, reset, step, last_error, destroy

const gauss6_engine_v1 kTable = {GAUSS6_ENGINE_V1_FIELDS(GAUSS6_ENGINE_ABI_VERSION, sizeof(gauss6_engine_v1))};
const gauss6_engine_v2 kTable2 = {
    {GAUSS6_ENGINE_V1_FIELDS(GAUSS6_ENGINE_ABI_VERSION_2, sizeof(gauss6_engine_v2))}, declare};

}  // namespace

extern "C" __attribute__((visibility("default"))) const void* gauss6_engine_get(uint32_t abi_version) {
  if (abi_version == GAUSS6_ENGINE_ABI_VERSION_2) return &kTable2;
  return abi_version == GAUSS6_ENGINE_ABI_VERSION ? &kTable : nullptr;
}
