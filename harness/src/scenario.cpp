// Scripted and replayed scenarios: a device (the simulated one on a hand
// script, or the replay device on a recording), the runtime's loops and a trace
// of the run, with the property observers fed by the hooks (scenario.h,
// property_observers.h).
#include "gauss6/scenario.h"

#include "gauss6/io/regular_file.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>
#include <vector>

namespace gauss6 {

namespace {

using Clock = std::chrono::steady_clock;

constexpr uint32_t kWatchdogEvents = event_bit(RuntimeEventKind::kDeviceTimeout) | event_bit(RuntimeEventKind::kSimStalled) |
                                     event_bit(RuntimeEventKind::kCouplingStalled);

// What a tick row needs from the last coupling step (another thread's, with
// ForceSource::kCouplingLoop): passed through a seqlock.
struct CouplingRecord {
  double xs_p[3] = {0, 0, 0};
  double xs_q[4] = {1, 0, 0, 0};
  int32_t num_rows = 0;
  uint64_t god_sequence = 0;
  double force_seconds = 0;
};

// The observer's state. The hooks run on the loops' threads: each member is
// written by one thread only (noted), except `time`, an atomic for the progress.
struct Recorder {
  const RuntimeModel* model = nullptr;
  const std::vector<HandPhase>* phases = nullptr;
  TraceWriter* writer = nullptr;
  SeqLock<CouplingRecord> coupling;      // coupling thread -> haptic thread
  std::atomic<double> time{0};           // haptic thread -> caller (progress)
  std::atomic<long> num_sim_steps{0};    // sim thread
  bool flush_in_run_time = false;        // lockstep: the haptic hook flushes every flush_period of run time
  std::atomic<double>* run_time_out = nullptr;  // ScenarioOptions::run_time_out
  std::atomic<double> haptic_stalled_at{-1};     // watchdog thread -> haptic thread: kHapticStalled's time

  // Haptic thread.
  size_t next_phase = 0;
  bool let_go_reported = false;
  uint64_t last_sequence = 0;
  long num_ticks = 0;
  PassivityObserver port;

  // Coupling thread.
  CouplingPropertyObserver constraints;

  // Sim thread.
  SimPropertyObserver motion;
};

void on_coupling_step(void* user, const CouplingStepInfo& info) {
  auto* r = static_cast<Recorder*>(user);
  CouplingRecord c;
  c.xs_p[0] = info.xs.p[0], c.xs_p[1] = info.xs.p[1], c.xs_p[2] = info.xs.p[2];
  c.xs_q[0] = info.xs.q.w, c.xs_q[1] = info.xs.q.x, c.xs_q[2] = info.xs.q.y, c.xs_q[3] = info.xs.q.z;
  c.num_rows = info.num_rows;
  c.god_sequence = info.god_sequence;
  c.force_seconds = info.force_seconds;
  r->coupling.write(c);
  r->constraints.add(info);
}

void on_sim_step(void* user, const SimStepInfo& info) {
  auto* r = static_cast<Recorder*>(user);
  r->num_sim_steps.fetch_add(1, std::memory_order_relaxed);
  r->motion.add(*r->model, info);
  TraceStep row;
  row.step = info.step - 1;  // 0, 1, 2, ...
  row.t = info.time;
  row.update_time = info.update_seconds;
  row.update_cpu_time = info.update_cpu_seconds;
  row.num_contacts = info.num_contacts;
  row.status = static_cast<int>(info.status);
  r->writer->append(row);
  if (!info.contacts) return;
  const int m = std::min(info.contacts->num_contacts, info.contacts->capacity());
  for (int k = 0; k < m; ++k) {
    const Contact& c = info.contacts->contacts[static_cast<size_t>(k)];
    r->writer->append(TraceContact{row.step, row.t, c.point, c.normal, c.separation});
  }
}

void on_haptic_tick(void* user, const HapticTickRecord& rec) {
  auto* r = static_cast<Recorder*>(user);
  // Phase boundaries and the let-go, at the first tick at or after them.
  const auto& phases = *r->phases;
  while (r->next_phase < phases.size() && rec.time >= phases[r->next_phase].start) {
    r->writer->append(TraceEvent{phases[r->next_phase].start, TraceEventCode::kPhase,
                                 static_cast<double>(r->next_phase)});
    ++r->next_phase;
  }
  // The watchdog thread's event goes into the trace from here (one writer a stream).
  const double stalled_at = r->haptic_stalled_at.exchange(-1, std::memory_order_acq_rel);
  if (stalled_at >= 0) r->writer->append(TraceEvent{stalled_at, TraceEventCode::kWatchdog, r->model->settings.device_timeout});
  if (!rec.gripped && !r->let_go_reported) {
    r->writer->append(TraceEvent{rec.time, TraceEventCode::kLetGo, 0});
    r->let_go_reported = true;
  }

  CouplingRecord c;
  const bool has_coupling = r->coupling.try_read(&c);
  TraceTick row;
  row.t = rec.time;
  row.X_WH = rec.xh;
  row.X_WS = has_coupling ? to_pose(c.xs_p, c.xs_q) : r->model->initial_pose;
  row.F = rec.F_sent;
  row.num_contacts = has_coupling ? c.num_rows : 0;
  row.force_time = has_coupling ? c.force_seconds : 0;
  row.status = rec.device_status;
  row.buttons = rec.buttons;
  row.flags = (rec.gripped ? kTickGripped : 0u) |
              (has_coupling && c.god_sequence != r->last_sequence ? kTickNewContactSet : 0u) |
              (rec.active_events & event_bit(RuntimeEventKind::kForceClamped) ? kTickForceClamped : 0u) |
              (rec.active_events & kWatchdogEvents ? kTickWatchdog : 0u);
  if (has_coupling) r->last_sequence = c.god_sequence;
  r->writer->append(row);

  // Passivity observer on the device port.
  r->port.add(*r->model, rec.xh, rec.F_sent, row.X_WS.q);

  ++r->num_ticks;
  r->time.store(rec.time, std::memory_order_relaxed);
  if (r->run_time_out) r->run_time_out->store(rec.time, std::memory_order_relaxed);
  // A lockstep run is not real time and runs many times faster than the wall clock:
  // the flush bound is kept in run time, here, not by the writer's wall-clock thread.
  if (r->flush_in_run_time) r->writer->flush_if_due(rec.time);
}

void on_event(void* user, const RuntimeEvent& e) {
  auto* r = static_cast<Recorder*>(user);
  const RuntimeSettings& s = r->model->settings;
  switch (e.kind) {
    case RuntimeEventKind::kDeviceEnded: r->writer->append(TraceEvent{e.time, TraceEventCode::kDeviceEnded, 0}); break;
    case RuntimeEventKind::kDeviceTimeout:
      r->writer->append(TraceEvent{e.time, TraceEventCode::kWatchdog, s.device_timeout});
      break;
    case RuntimeEventKind::kSimStalled: r->writer->append(TraceEvent{e.time, TraceEventCode::kWatchdog, s.sim_timeout}); break;
    case RuntimeEventKind::kCouplingStalled:
      r->writer->append(TraceEvent{e.time, TraceEventCode::kWatchdog, s.coupling_timeout});
      break;
    case RuntimeEventKind::kDeviceNotConnected:
      r->writer->append(TraceEvent{e.time, TraceEventCode::kDeviceLost, 0});
      break;
    case RuntimeEventKind::kHapticStalled:  // the watchdog's thread: written by the next haptic tick
      r->haptic_stalled_at.store(e.time, std::memory_order_release);
      break;
    default: break;  // counted in RuntimeStats
  }
}

std::string read_text(const std::filesystem::path& path) {
  if (const std::string problem = regular_file_problem(path.string(), uint64_t(1) << 26); !problem.empty())
    throw ScenarioError(path.string() + ": the hand script: " + problem);
  std::ifstream in(path);
  if (!in) throw ScenarioError(path.string() + ": cannot open the hand script");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

HandScript load_scene_script(const Scene& scene) {
  const std::string& name = scene.device.script;
  if (scene.device.kind != DeviceKind::kSimulated || (name.empty() && scene.device.script_json.empty()))
    throw ScenarioError("scene '" + scene.path + "': device.kind must be simulated, with a script");
  if (name.empty()) {  // the [device.script] table
    try {
      return hand_script_from_json(scene.device.script_json, scene.path + ": device.script");
    } catch (const std::invalid_argument& e) {
      throw ScenarioError(e.what());
    }
  }
  const std::filesystem::path dir = std::filesystem::path(scene.path).parent_path();
  const bool is_file = name.size() > 5 && name.compare(name.size() - 5, 5, ".json") == 0;
  const std::filesystem::path path = is_file ? dir / name : dir / ".." / "scripts" / (name + ".json");
  try {
    return hand_script_from_json(read_text(path), path.lexically_normal().string());
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
}

namespace {

// `caller` names the entry point in the message ("run_scenario", "run_replay").
void check_options(const ScenarioOptions& options, const char* caller) {
  if (options.trace_path.empty()) throw ScenarioError(std::string(caller) + ": options.trace_path is empty");
  if (!(options.progress_period > 0)) throw ScenarioError(std::string(caller) + ": progress_period must be > 0");
}

// The run of the model with `device` for `duration` s of run time, recorded in
// options.trace_path with the phases' start events.
ScenarioResult run_device(const RuntimeModel& model, const Scene& scene, Device* device,
                          const std::vector<HandPhase>& phases, double duration, const ScenarioOptions& options,
                          Clock::time_point wall_start) {
  auto data = std::make_unique<RuntimeData>(model);

  // The trace: its metadata names the scene, the device and the phases.
  TraceMeta meta;
  meta.scene = scene.name.empty() ? scene.path : scene.name;
  meta.device = device->info().name;
  meta.device_rate_hz = device->info().rate_hz;
  meta.renders_force = device->info().renders_force;
  for (const HandPhase& p : phases) meta.phases.push_back({p.name, p.start});
  meta.extra_json = options.extra_json;
  TraceWriterSettings ts = options.trace;
  ts.background_thread = true;
  std::unique_ptr<TraceWriter> writer;
  try {
    writer = std::make_unique<TraceWriter>(options.trace_path, meta, ts);
  } catch (const TraceError& e) {
    throw ScenarioError(e.what());
  }

  Recorder rec;
  rec.model = &model;
  rec.phases = &phases;
  rec.writer = writer.get();
  rec.flush_in_run_time = !options.threaded;
  rec.run_time_out = options.run_time_out;
  RuntimeObserver observer;
  observer.user = &rec;
  observer.on_event = on_event;
  observer.on_sim_step = on_sim_step;
  observer.on_coupling_step = on_coupling_step;
  observer.on_haptic_tick = on_haptic_tick;

  // The run on a worker thread; this thread reports progress meanwhile.
  std::atomic<bool> done{false};
  std::thread worker([&] {
    if (options.threaded) {
      run_threaded(model, device, duration, nullptr, observer, data.get());
    } else {
      const long num_ticks = static_cast<long>(std::floor(duration * scene.device.rate_hz + 1e-9)) + 1;
      run_lockstep(model, device, num_ticks, observer, data.get());
    }
    done.store(true, std::memory_order_release);
  });
  const auto period = std::chrono::duration<double>(options.progress_period);
  Clock::time_point last = Clock::now();
  while (!done.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(std::min(period, std::chrono::duration<double>(0.01)));
    if (options.progress && Clock::now() - last >= period) {
      last = Clock::now();
      options.progress(rec.time.load(std::memory_order_relaxed));
    }
  }
  worker.join();
  writer->close();
  if (options.progress) options.progress(rec.time.load(std::memory_order_relaxed));

  ScenarioResult out;
  out.stats = data->stats;
  out.trace = writer->stats();
  out.trace_path = options.trace_path;
  out.num_ticks = rec.num_ticks;
  out.num_sim_steps = rec.num_sim_steps.load();
  out.run_time = data->stats.run_seconds;
  out.max_rel_force_dot_ac = rec.constraints.max_rel_force_dot_ac;
  out.num_orthogonality_checks = rec.constraints.num_orthogonality_checks;
  out.num_offset_steps = rec.constraints.num_offset_steps;
  out.constraint_energy_injected = rec.constraints.energy_injected;
  out.constraint_energy_removed = rec.constraints.energy_removed;
  out.num_shaded_steps = rec.constraints.num_shaded_steps;
  out.max_rel_constraint_violation = rec.motion.max_rel_constraint_violation;
  out.num_constraint_checks = rec.motion.num_constraint_checks;
  out.shading_work_injected = rec.motion.shading_work_injected;
  out.shading_work_removed = rec.motion.shading_work_removed;
  out.max_texture_step = rec.motion.max_texture_step;
  out.port_energy_max = rec.port.energy_max;
  out.port_energy_final = rec.port.energy;
  out.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  return out;
}

}  // namespace

ScenarioResult run_scenario(const Scene& scene, const HandScript& script, const ScenarioOptions& options) {
  const Clock::time_point wall_start = Clock::now();
  check_options(options, "run_scenario");
  try {
    validate_hand_script(script);
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
  // The model and the device (its rate and limits are the scene's).
  const RuntimeModel model(scene, options.runtime);
  SimulatedHandleParams handle = options.handle;
  handle.rate_hz = scene.device.rate_hz;
  handle.max_force = scene.device.max_force;
  handle.max_torque = scene.device.max_torque;
  SimulatedDevice device(script, handle, "simulated: " + (scene.device.script.empty() ? scene.name : scene.device.script));
  device.reset(0);
  const double end = script.end_time >= 0 ? script.end_time : script.keys.back().t;
  const double duration = options.duration >= 0 ? options.duration : end;
  return run_device(model, scene, &device, script.phases, duration, options, wall_start);
}

ScenarioResult run_replay(const Scene& scene, const Trace& recording, const std::vector<HandPhase>& phases,
                          const ScenarioOptions& options) {
  const Clock::time_point wall_start = Clock::now();
  check_options(options, "run_replay");
  const RuntimeModel model(scene, options.runtime);
  std::unique_ptr<ReplayDevice> device;
  try {
    device = std::make_unique<ReplayDevice>(ReplayDevice::from_trace(recording));
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(std::string("the recording cannot drive the replay device: ") + e.what());
  }
  const double duration = options.duration >= 0 ? options.duration : device->end_time();
  return run_device(model, scene, device.get(), phases, duration, options, wall_start);
}

}  // namespace gauss6
