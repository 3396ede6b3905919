// Benchmarks of the runtime's loops (runtime.h) on the peg-in-hole scene with the
// simulated device (device/, an impedance handle pulled by a scripted hand):
//   CouplingStep: one coupling step (read xh and the snapshot, offsets, the
//                 projection, Fc = kh M (ac - au)): the coupling force;
//   HapticTick:   one haptic tick (device read, the coupling step inside, safety,
//                 device write): the whole force path of one 1 kHz tick;
//   LockstepTick: one sim step (au, projection, CCD, contacts, publish) then one
//                 haptic tick: a tick of run_lockstep with lockstep_sim_period 1.
// The hand moves the peg (upright, tip down) over the box's top, presses it 5 mm
// into the top and slides it along X while pressing; the fixtures run 1 s of
// lockstep first, so that every timed call is in contact. Virtual time advances
// 1 ms per call. Counters: p50/p99/max per call (ns), mean contact rows.
//
// Surface properties (surface.h), each next to the same geometry plain, on the
// Figure 8 and 9 scenes with their own hand scripts (datasets_generated/scenes/),
// warmed up into the slide, 1000 timed ticks within it:
//   CouplingStep/cylinder/{plain,shaded,shaded_texture}, CouplingStep/slab/{plain,texture}:
//                 the coupling step (shaded: projection under Js, asc published);
//                 shaded_texture: the cylinder shaded under a sine texture
//                 (cylinder_textured.toml, shading and texture combined);
//   SimStep/cylinder/{plain,shaded,shaded_texture}, SimStep/slab/{plain,texture}: one sim step
//                 (shaded: pass 2 from the coupling's asc, the new set's Js;
//                 texture: the held contacts, the texture's perturbation), a
//                 haptic tick after each (not timed), as lockstep runs them.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "bench_data.h"
#include "gauss6/runtime/runtime.h"
#include "gauss6/scenario.h"
#include "gauss6/io/scene.h"
#include "gauss6/simulated_device.h"
#include "latency.h"

namespace gauss6::bench {
namespace {

constexpr double kDt = 0.001;         // s per haptic tick (the scene's 1 kHz)
constexpr double kWarmUp = 1.0;       // s of lockstep before timing
constexpr int kTimedTicks = 2000;     // the hand's script covers kWarmUp + this many ticks

struct PegRun {
  Scene scene;
  std::unique_ptr<RuntimeModel> model;
  std::unique_ptr<SimulatedDevice> device;
  std::unique_ptr<RuntimeData> data;
  double t = 0;
};

// A fresh run, warmed up: the peg pressed on the top, about to slide.
std::unique_ptr<PegRun> make_peg_run() {
  auto r = std::make_unique<PegRun>();
  r->scene = load_scene(datasets_dir() + "/scenes/peg_in_hole.toml");
  r->model = std::make_unique<RuntimeModel>(r->scene, RuntimeSettings{});
  const Pose x0 = r->scene.god_object.pose;  // G at z = 0.09, tip 1 cm above the top (z = 0.03)
  HandScript script;
  auto key = [&](double t, double x, double z) { script.keys.push_back({t, Pose{Vec3(x, 0, z), x0.q}}); };
  key(0.0, x0.p.x(), x0.p.z());
  key(0.3, 0.03, x0.p.z());  // over the top, off the hole's plane
  key(0.8, 0.03, 0.075);     // 5 mm below the top: pressing
  key(kWarmUp + kTimedTicks * kDt, -0.03, 0.075);  // sliding along X while pressing
  script.end_time = 1e9;     // then held: the device never ends during a benchmark
  r->device = std::make_unique<SimulatedDevice>(script);
  r->data = std::make_unique<RuntimeData>(*r->model);
  const long warm_ticks = static_cast<long>(kWarmUp / kDt);
  run_lockstep(*r->model, r->device.get(), warm_ticks, RuntimeObserver{}, r->data.get());
  r->t = warm_ticks * kDt;
  return r;
}

void BM_CouplingStep(benchmark::State& state) {
  auto r = make_peg_run();
  LatencyRecorder rec;
  double rows = 0, calls = 0;
  for (auto _ : state) {
    r->t += kDt;
    const CouplingStepInfo* info = nullptr;
    rec.time(state, [&] { info = &coupling_step(*r->model, r->t, &r->data->channels, &r->data->coupling); });
    benchmark::DoNotOptimize(info);
    rows += r->data->coupling.god.num_contacts;
    calls += 1;
  }
  rec.report(state);
  state.counters["rows_per_call"] = rows / calls;
}

// One haptic tick per call; with_sim: a sim step (projection, CCD, contacts, publish)
// first, as the lockstep schedule runs them. Rows per call: the rows the force used
// (haptic tick alone) or the contacts the sim step made (lockstep).
void time_ticks(benchmark::State& state, bool with_sim) {
  auto r = make_peg_run();
  RuntimeData& d = *r->data;
  LatencyRecorder rec;
  double rows = 0, calls = 0;
  for (auto _ : state) {
    r->t += kDt;
    bool running = true;
    rec.time(state, [&] {
      if (with_sim) sim_step(*r->model, r->t, &d.channels, &d.sim);
      running = haptic_tick(*r->model, r->t, r->device.get(), &d.channels, &d.haptic, &d.coupling, RuntimeObserver{},
                            &d.stats);
    });
    if (!running) return state.SkipWithError("the device ended");
    rows += with_sim ? d.sim.contacts.num_contacts : d.coupling.god.num_contacts;
    calls += 1;
  }
  rec.report(state);
  state.counters["rows_per_call"] = rows / calls;
}

void BM_HapticTick(benchmark::State& state) { time_ticks(state, false); }
void BM_LockstepTick(benchmark::State& state) { time_ticks(state, true); }

// A surface scene's run (the scene's own script and device limits, as run_scenario
// builds them), its surface kept or turned off, warmed up to warm_up seconds.
std::unique_ptr<PegRun> make_surface_run(const std::string& scene_name, bool plain, double warm_up) {
  auto r = std::make_unique<PegRun>();
  r->scene = load_scene(datasets_dir() + "/scenes/" + scene_name + ".toml");
  const HandScript script = load_scene_script(r->scene);
  if (plain) r->scene.surface = SurfaceSettings{};
  r->model = std::make_unique<RuntimeModel>(r->scene, RuntimeSettings{});
  SimulatedHandleParams handle;
  handle.rate_hz = r->scene.device.rate_hz;
  handle.max_force = r->scene.device.max_force;
  handle.max_torque = r->scene.device.max_torque;
  r->device = std::make_unique<SimulatedDevice>(script, handle);
  r->device->reset(0);
  r->data = std::make_unique<RuntimeData>(*r->model);
  const long warm_ticks = static_cast<long>(warm_up / kDt);
  run_lockstep(*r->model, r->device.get(), warm_ticks, RuntimeObserver{}, r->data.get());
  r->t = warm_ticks * kDt;
  return r;
}

// The Figure 8 slide starts at 1.5 s (3 s long), the Figure 9 slow slide at 1 s (1.2 s long).
std::unique_ptr<PegRun> make_surface_run(const std::string& which) {
  if (which == "cylinder/plain") return make_surface_run("cylinder_plain", false, 2.0);
  if (which == "cylinder/shaded") return make_surface_run("cylinder_shaded", false, 2.0);
  if (which == "cylinder/shaded_texture") return make_surface_run("cylinder_textured", false, 2.0);
  if (which == "slab/plain") return make_surface_run("texture_slow", true, 1.1);
  return make_surface_run("texture_slow", false, 1.1);  // slab/texture
}

void BM_SurfaceCouplingStep(benchmark::State& state, const std::string& which) {
  auto r = make_surface_run(which);
  RuntimeData& d = *r->data;
  LatencyRecorder rec;
  double rows = 0, calls = 0;
  for (auto _ : state) {
    r->t += kDt;
    sim_step(*r->model, r->t, &d.channels, &d.sim);  // the run goes on: a new snapshot each tick
    const CouplingStepInfo* info = nullptr;
    rec.time(state, [&] { info = &coupling_step(*r->model, r->t, &d.channels, &d.coupling); });
    benchmark::DoNotOptimize(info);
    if (!haptic_tick(*r->model, r->t, r->device.get(), &d.channels, &d.haptic, &d.coupling, RuntimeObserver{},
                     &d.stats))
      return state.SkipWithError("the device ended");
    rows += d.coupling.god.num_contacts;
    calls += 1;
  }
  rec.report(state);
  state.counters["rows_per_call"] = rows / calls;
}

void BM_SurfaceSimStep(benchmark::State& state, const std::string& which) {
  auto r = make_surface_run(which);
  RuntimeData& d = *r->data;
  LatencyRecorder rec;
  double rows = 0, calls = 0;
  for (auto _ : state) {
    r->t += kDt;
    rec.time(state, [&] { sim_step(*r->model, r->t, &d.channels, &d.sim); });
    if (!haptic_tick(*r->model, r->t, r->device.get(), &d.channels, &d.haptic, &d.coupling, RuntimeObserver{},
                     &d.stats))
      return state.SkipWithError("the device ended");
    rows += d.sim.contacts.num_contacts;
    calls += 1;
  }
  rec.report(state);
  state.counters["rows_per_call"] = rows / calls;
}

void register_all() {
  benchmark::RegisterBenchmark("CouplingStep/peg/pressing_sliding", BM_CouplingStep)
      ->UseManualTime()->Iterations(kTimedTicks);
  benchmark::RegisterBenchmark("HapticTick/peg/pressing_sliding", BM_HapticTick)
      ->UseManualTime()->Iterations(kTimedTicks);
  benchmark::RegisterBenchmark("LockstepTick/peg/pressing_sliding", BM_LockstepTick)
      ->UseManualTime()->Iterations(kTimedTicks)->Unit(benchmark::kMicrosecond);
  for (const char* which :
       {"cylinder/plain", "cylinder/shaded", "cylinder/shaded_texture", "slab/plain", "slab/texture"}) {
    benchmark::RegisterBenchmark((std::string("CouplingStep/") + which).c_str(), BM_SurfaceCouplingStep,
                                 std::string(which))
        ->UseManualTime()->Iterations(1000);
    benchmark::RegisterBenchmark((std::string("SimStep/") + which).c_str(), BM_SurfaceSimStep, std::string(which))
        ->UseManualTime()->Iterations(1000)->Unit(benchmark::kMicrosecond);
  }
}

const int registered = (register_all(), 0);

}  // namespace
}  // namespace gauss6::bench
