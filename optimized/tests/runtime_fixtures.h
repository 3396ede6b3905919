// Fixtures of the runtime's tests (test_runtime.cpp, test_runtime_faults.cpp):
// a box god-object (10 cm, 1 kg) over a box obstacle (top face z = 0), a
// scripted test device with faults on request (bad poses, timeouts, not
// connected, failing writes, blocking reads, a flaky read), the observer that
// records everything the hooks report, and a lockstep run of them.
#pragma once

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "gauss6/geometry/mass_properties.h"
#include "gauss6/runtime/runtime.h"
#include "mesh_shapes.h"

namespace gauss6::test {

constexpr double kSide = 0.1;        // god-object: cube of side 10 cm, density 1000: m = 1 kg
constexpr double kHalf = kSide / 2;  // G rests at z = kHalf above the top face
constexpr double kDelta = 1e-5;
constexpr double kKs = 0.5, kKh = 1000;  // felt stiffness kh m ks = 500 N/m
constexpr double kRate = 1000;

inline Scene make_scene(double offset_eps = -1e-3, double offset_time = 0.05) {
  Scene sc;
  sc.path = "test:box_on_box";
  sc.name = "box_on_box";
  Body slab;
  slab.name = "slab";
  slab.mesh = make_box(1.0, 1.0, 0.1, Vec3(0, 0, -0.05));  // top face z = 0
  build_adjacency(&slab.mesh);
  compute_vertex_normals(&slab.mesh);
  sc.obstacles.push_back(slab);
  sc.god_object.name = "cube";
  sc.god_object.role = BodyRole::kGodObject;
  sc.god_object.mesh = make_box(kSide, kSide, kSide);  // body frame: origin at G (centre)
  build_adjacency(&sc.god_object.mesh);
  compute_vertex_normals(&sc.god_object.mesh);
  sc.god_object.pose = {Vec3(0, 0, 0.2), Quat{}};
  std::string error;
  REQUIRE(compute_mass_properties(sc.god_object.mesh, 1000, &sc.god_mass.mass, &error));
  sc.gains.ks = kKs;
  sc.gains.kh = kKh;
  sc.contact.delta = kDelta;
  sc.contact.offset_eps = offset_eps;
  sc.contact.offset_time = offset_time;
  sc.device.rate_hz = kRate;
  sc.device.max_force = 20;
  sc.device.max_torque = 1;
  return sc;
}

// Lowest point of the god-object at pose x: the top face is at z = 0.
inline double lowest_z(const RuntimeModel& model, const Pose& x) {
  double z = INFINITY;
  for (int v = 0; v < model.god_mesh_B.V.rows(); ++v)
    z = std::min(z, transform_point(x, model.god_mesh_B.V.row(v).transpose()).z());
  return z;
}

// A device that plays a scripted handle trajectory, with faults on request,
// and records every wrench it is sent and the one it renders (the last written
// without error, zero once halted).
class ScriptedDevice : public Device {
 public:
  explicit ScriptedDevice(std::function<Pose(double)> script) : script_(std::move(script)) {
    info_.name = "scripted test device";
    info_.rate_hz = kRate;
    writes.reserve(100000);
  }
  const DeviceInfo& info() const override { return info_; }
  void set_limits(double max_force, double max_torque) { info_.max_force = max_force, info_.max_torque = max_torque; }
  DeviceStatus read(double t, DeviceState* state) override {
    state->time = t;
    ++reads;
    if (t >= block_at && !blocked) {  // once: the call does not return for block_seconds
      blocked = true;
      std::this_thread::sleep_for(std::chrono::duration<double>(block_seconds));
      block_returned_at = t + block_seconds;
    }
    if (t >= end_time) return state->status = DeviceStatus::kEnded;
    if (t >= timeout_from) return state->status = DeviceStatus::kTimeout;
    if (t >= not_connected_from && t < not_connected_to) return state->status = DeviceStatus::kNotConnected;
    if (t >= error_from && t < error_to) return state->status = DeviceStatus::kError;
    if (t >= flaky_from && t < flaky_to && reads % 2 == 0) return state->status = DeviceStatus::kError;
    state->X_WH = script_(t);
    if (t >= nan_from && t < nan_to) state->X_WH.p.x() = std::nan("");
    return state->status = DeviceStatus::kOk;
  }
  DeviceStatus write(double t, const Vec6& F) override {
    const bool fails = t >= write_fail_from && t < write_fail_to && (fail_zero_writes || F.norm() != 0);
    writes.push_back({t, F, !fails});
    if (fails) return DeviceStatus::kError;
    rendered = F;
    halted.store(false);
    return DeviceStatus::kOk;
  }
  DeviceStatus halt_force() noexcept override {
    halted.store(true);
    halts.fetch_add(1);
    return DeviceStatus::kOk;
  }
  // What the handle feels now (the haptic thread's view).
  Vec6 felt() const { return halted.load() ? Vec6::Zero() : rendered; }
  struct Write {
    double t;
    Vec6 F;
    bool ok;
  };
  std::vector<Write> writes;
  double nan_from = INFINITY, nan_to = INFINITY, timeout_from = INFINITY, end_time = INFINITY;
  double not_connected_from = INFINITY, not_connected_to = INFINITY;
  double write_fail_from = INFINITY, write_fail_to = INFINITY;
  bool fail_zero_writes = false;          // writes of zero fail too (then the loop must halt the device)
  double error_from = INFINITY, error_to = INFINITY;  // every read is kError
  double flaky_from = INFINITY, flaky_to = INFINITY;  // every other read is kError
  double block_at = INFINITY, block_seconds = 0;       // the first read at or after block_at blocks
  double block_returned_at = -1;
  bool blocked = false;
  long reads = 0;
  Vec6 rendered = Vec6::Zero();
  std::atomic<bool> halted{false};
  std::atomic<int> halts{0};

 private:
  std::function<Pose(double)> script_;
  DeviceInfo info_;
};

// Everything the hooks report.
struct Recorder {
  std::vector<RuntimeEvent> events;
  std::mutex events_mutex;
  std::vector<SimStepInfo> sims;
  std::vector<CouplingStepInfo> couplings;
  std::vector<HapticTickRecord> ticks;
  std::atomic<bool> stop{false};
  std::function<void(const HapticTickRecord&)> on_tick;  // optional extra check
  RuntimeObserver observer() {
    RuntimeObserver o;
    o.user = this;
    o.on_event = [](void* u, const RuntimeEvent& e) {
      auto* rec = static_cast<Recorder*>(u);
      std::lock_guard<std::mutex> lock(rec->events_mutex);  // threaded runs: several loops report
      rec->events.push_back(e);
    };
    o.on_sim_step = [](void* u, const SimStepInfo& i) { static_cast<Recorder*>(u)->sims.push_back(i); };
    o.on_coupling_step = [](void* u, const CouplingStepInfo& i) { static_cast<Recorder*>(u)->couplings.push_back(i); };
    o.on_haptic_tick = [](void* u, const HapticTickRecord& r) {
      auto* rec = static_cast<Recorder*>(u);
      rec->ticks.push_back(r);
      if (rec->on_tick) rec->on_tick(r);
    };
    return o;
  }
  int count(RuntimeEventKind k) const {
    return static_cast<int>(std::count_if(events.begin(), events.end(), [&](const RuntimeEvent& e) { return e.kind == k; }));
  }
};

// Handle straight down from G at z0 to z1 at speed v, then held.
inline std::function<Pose(double)> press_script(double z0, double z1, double v) {
  return [=](double t) { return Pose{Vec3(0, 0, std::max(z1, z0 - v * t)), Quat{}}; };
}

struct Run {
  std::unique_ptr<RuntimeModel> model;
  std::unique_ptr<RuntimeData> data;
  Recorder rec;
};

inline void run(Run* r, const Scene& scene, const RuntimeSettings& settings, Device* device, long ticks) {
  r->model = std::make_unique<RuntimeModel>(scene, settings);
  r->data = std::make_unique<RuntimeData>(*r->model);
  r->rec.sims.reserve(ticks + 1);
  r->rec.couplings.reserve(ticks + 1);
  r->rec.ticks.reserve(ticks + 1);
  run_lockstep(*r->model, device, ticks, r->rec.observer(), r->data.get());
}

}  // namespace gauss6::test
