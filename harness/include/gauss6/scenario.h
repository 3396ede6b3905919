// Scripted scenarios: a scene, the simulated device driven by a hand script
// (the paper's peg-in-hole phases a-e, the bunnies) or the replay device driven
// by a recorded session (run_replay), the runtime's three loops (runtime.h),
// and a trace of the whole run (trace.h, docs/trace-format.md).
//
// run_scenario() wires the runtime's observer hooks to a TraceWriter:
//   per haptic tick: t, xh, xs (as the coupling step used it), the wrench sent,
//     the number of rows of J behind it, the force-computation time, status, flags;
//   per sim step:    t, the god-object update time, the number of contacts,
//     status, and one contact row per contact (point, normal, separation);
//   events:          each phase's start (value: its index in the metadata's
//     phases), the let-go, watchdog trips, the script's end.
// The file is flushed every flush_period (<= 1 s) of run time, so a crash loses at
// most that much of the run: a threaded run by the writer's background thread (run
// time is wall time), a lockstep run (many times faster than the wall clock) from
// its haptic hook (TraceWriter::flush_if_due).
//
// It also feeds the property observers (property_observers.h): per coupling
// step, orthogonality Fc . ac = 0 and the constraint stage's energy balance
// au . Fc <= 0, which the trace cannot show exactly (it records the clamped
// wrench, not ac); per haptic tick, a Hannaford-Ryu passivity observer on the
// device port. Their totals are in ScenarioResult.
//
// Units: the scene's (metres, kilograms, seconds in the shipped scenes); wrenches
// in N and N m, world frame.
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <string>

#include "gauss6/property_observers.h"
#include "gauss6/replay_device.h"
#include "gauss6/runtime/runtime.h"
#include "gauss6/io/scene.h"
#include "gauss6/simulated_device.h"
#include "gauss6/trace.h"

namespace gauss6 {

class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ScenarioOptions {
  std::string trace_path;              // the trace file to write (required)
  bool threaded = false;               // false: run_lockstep (virtual clock, repeatable); true: run_threaded (wall clock)
  double duration = -1;                // s of run time; < 0: until the script ends
  RuntimeSettings runtime;             // the runtime's settings (lockstep_sim_period, force source, ...)
  SimulatedHandleParams handle;        // the simulated handle; rate_hz, max_force, max_torque come from the scene
  TraceWriterSettings trace;           // ring sizes and flush period (the background thread is always used)
  std::string extra_json = "{}";       // a JSON object stored under the trace metadata's "extra"
  // Called on the calling thread about every progress_period s of wall time with
  // the run's time so far (s), and once at the end. May be empty.
  std::function<void(double run_time)> progress;
  double progress_period = 0.2;        // s (wall)
  // When set, each haptic tick stores its run time here (relaxed): what a supervisor
  // (another thread, or another process through shared memory) sees of the run.
  std::atomic<double>* run_time_out = nullptr;
};

struct ScenarioResult {
  RuntimeStats stats;                  // per-loop rates, work times, events
  TraceWriterStats trace;              // rows written and dropped
  std::string trace_path;
  long num_ticks = 0;                  // haptic ticks run
  long num_sim_steps = 0;
  double run_time = 0;                 // s: virtual (lockstep) or wall (threaded)
  double wall_seconds = 0;             // s of wall time for the whole call

  // Orthogonality (METHOD.md 5.1), over coupling steps with |Fc| > 0, |ac| > 1e-6 |au|
  // (below, ac is rounding noise: pressing straight into a face gives ac = 0); with
  // running offsets (b != 0) in its offset form Fc . ac = kh lambda^T b:
  // max |Fc . ac - kh lambda^T b| / (|Fc| |ac|).
  double max_rel_force_dot_ac = 0;
  long num_orthogonality_checks = 0;
  long num_offset_steps = 0;           // coupling steps with a running offset (orthogonality in its offset form)

  // The constraint stage's work on the user's command (METHOD.md 5.4 with Fu = kh M au):
  // per coupling step au . Fc = -kh |ac - au|_M^2 <= 0 (J). Sums of its positive and
  // negative parts; the positive sum must be 0 up to rounding.
  double constraint_energy_injected = 0;
  double constraint_energy_removed = 0;

  // Passivity observer on the device port (Hannaford and Ryu 2002): W(n) =
  // sum_k F_k . (xh_{k+1} (-) xh_k), the work of the sent wrench on the handle,
  // plus the energy stored in the coupling at tick n, V = F^T M^-1 F / (2 kh ks).
  // A passive environment keeps W(n) + V(n) <= 0 for every n; this is max(0, max_n).
  // Zero-order hold of a stiff coupling makes it slightly positive (about
  // k/2 sum |dx|^2), which is why the constraint-stage balance above is kept apart.
  double port_energy_max = 0;          // J
  double port_energy_final = 0;        // J, W + V at the last tick (negative: energy dissipated)

  // Surface properties (surface.h) and property 7 (SimPropertyObserver):
  long num_shaded_steps = 0;           // coupling steps on the shading rows (orthogonality above is then Fc . asc)
  double max_rel_constraint_violation = 0;  // property 7, over every sim step with a handle
  long num_constraint_checks = 0;
  double shading_work_injected = 0;    // J: sum of max(0, Fs . ac) over sim steps (0 on plain surfaces)
  double shading_work_removed = 0;     // J
  double max_texture_step = 0;         // scene units: largest textured-contact displacement in one sim step
};

// The hand script named by scene.device.script: the file
// <scene dir>/../scripts/<name>.json (a path ending in .json is taken as is,
// relative to the scene's directory), or the one the scene holds
// (scene.device.script_json, a [device.script] table). Throws ScenarioError
// naming the file (the scene and "device.script") and the key.
HandScript load_scene_script(const Scene& scene);

// Runs the scene with a SimulatedDevice following `script` and writes the trace.
// Throws ScenarioError (bad options, trace file) or RuntimeError (scene) before
// the run starts; the run itself does not throw.
ScenarioResult run_scenario(const Scene& scene, const HandScript& script, const ScenarioOptions& options);

// Replays a recorded session: the handle poses of `recording` (a gauss6 trace,
// or another framework's log imported as one: docs/trace-format.md) drive the
// runtime through the ReplayDevice (interpolated between the recorded ticks;
// the grip and buttons as recorded), and the run is traced as run_scenario's.
// The run lasts as long as the recording (options.duration >= 0 shortens or
// lengthens it; past the recording's end the device has ended and the force is
// zero); `phases` are marked in the trace (may be empty). options.handle is
// not used. Throws ScenarioError (a recording without ticks or with times that
// do not increase, bad options, the trace file) or RuntimeError (scene) before
// the run starts.
ScenarioResult run_replay(const Scene& scene, const Trace& recording, const std::vector<HandPhase>& phases,
                          const ScenarioOptions& options);

}  // namespace gauss6
