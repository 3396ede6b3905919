// What the runtime's loops report (runtime.h): the kinds of events (watchdogs,
// device and solver failures), the per-step records of each loop, and the
// observer hook that receives both (trace recording, logging).
//
// Units and frames: seconds, world frame W; poses are of G (pose.h).
#pragma once

#include <cstdint>

#include "gauss6/step/ccd_step.h"
#include "gauss6/contact/contacts.h"
#include "gauss6/runtime/device_port.h"
#include "gauss6/contact/quasistatics.h"

namespace gauss6 {

// ---------------------------------------------------------------------------
// Events and the observer hook (trace recording, logging).
// ---------------------------------------------------------------------------

enum class RuntimeEventKind {
  kInvalidHandlePose = 0,  // the device returned a non-finite pose, or one beyond kMaxSceneCoordinate: zero force
  kDeviceError,            // read() returned a status other than kOk
  kDeviceTimeout,          // watchdog: no good sample for device_timeout: zero force
  kSimStalled,             // watchdog: no sim snapshot for sim_timeout: zero force
  kCouplingStalled,        // watchdog: no Fc for coupling_timeout: zero force
  kNonFiniteForce,         // the computed wrench was not finite: zero force
  kForceClamped,           // force or torque above the device's limits: scaled down
  kDeviceEnded,            // the device's script or replay ended: the run stops
  kProjectionFailed,       // a projection returned kBadInput, kIterationCap or kUncertified
  kCcdGaveUp,              // the sim step's CCD gave up (hit kept conservatively) or refused its input
  kContactOverflow,        // more contacts than RuntimeSettings::max_contacts: the set was truncated
  kTextureUndersampled,    // a textured contact moved more than half the texture's shortest wavelength in one
                           // sim step: the texture is skipped at this speed (surface.h, max_texture_speed)
  kDeviceNotConnected,     // read() returned kNotConnected: zero force until a good sample
  kDeviceWriteFailed,      // write() failed: zero written at once (Device::halt_force() if that fails too)
  kHapticStalled,          // watchdog thread (threaded runs): no haptic tick finished for device_timeout, a
                           // read() or write() that blocks: Device::halt_force() from the watchdog's thread
  kUpdateBudgetExhausted,  // a god-object update ran out of its budget (RuntimeSettings::budget): it ended at the
                           // end of what it had proven free, the rest of the command left to the next updates
};
inline constexpr int kNumRuntimeEventKinds = 16;
// An event kind as a bit of the loops' event masks (a uint32_t).
constexpr uint32_t event_bit(RuntimeEventKind k) { return 1u << static_cast<int>(k); }
static_assert(kNumRuntimeEventKinds <= 32, "event kinds are bits of a uint32_t");
const char* to_string(RuntimeEventKind k);

struct RuntimeEvent {
  RuntimeEventKind kind = RuntimeEventKind::kDeviceError;
  double time = 0;                     // s
  uint64_t tick = 0;                   // haptic tick, or sim step for sim events
  int detail = 0;                      // the status's integer value, when one applies
  uint32_t count = 1;                  // onsets this event stands for (> 1: coalesced, EventGate)
};

// The event onsets of one loop, rate-limited per kind so that a flaky fault (a
// device failing every other tick) does not flood the observer: an onset within
// RuntimeSettings::event_interval of the last reported event of its kind is
// counted, not reported; the count goes out in RuntimeEvent::count of the next
// event of that kind, which is reported as soon as event_interval has passed
// (with or without a new onset) or when the run ends. Nothing is lost: the
// counts of the reported events add up to the onsets (LoopStats::event_counts).
// Each loop owns one; no allocation.
struct EventGate {
  uint32_t active = 0;                             // conditions that held last time (events fire on onset)
  double last_report[kNumRuntimeEventKinds] = {};  // s, run time of the kind's last reported event
  bool reported[kNumRuntimeEventKinds] = {};       // the kind has been reported once
  uint32_t pending[kNumRuntimeEventKinds] = {};    // onsets counted since then, not yet reported
  uint64_t pending_tick[kNumRuntimeEventKinds] = {};  // tick of the first of them
  int pending_detail[kNumRuntimeEventKinds] = {};     // detail of the last of them
};

// Per-step records, handed to the hooks.
enum class SimStepStatus { kFree = 0, kContact, kNoHandle, kInvalidStep };
struct SimStepInfo {
  uint64_t step = 0;
  double time = 0;
  SimStepStatus status = SimStepStatus::kNoHandle;
  Pose xs;                             // after the step
  Vec6 au = Vec6::Zero(), ac = Vec6::Zero();
  // Shaded surfaces (surface.h): asc, the command after the shading pass (the
  // coupling loop's, or this step's own when the coupling has not yet answered
  // the last snapshot); ac = the projection of asc under the true rows J.
  // Plain surfaces: asc = au.
  Vec6 asc = Vec6::Zero();
  bool asc_from_coupling = false;      // asc was the coupling loop's (published for the last snapshot)
  // Property 7 (METHOD.md section 5), on every step: the rows of step 3 (the
  // previous contacts J, right-hand sides b) hold for the motion taken:
  // max_k (b_k - J_k ac) / (|J_k| max(|ac|, |a_in|) + |b_k| + 1e-300), 0 when
  // none is violated, a_in the projected input (au, or asc when shaded): the
  // scale of the projection's own feasibility tolerance (1e-13, quasistatics.h),
  // which bounds it (the reproduce runs: 5e-14 plain, 1e-13 shaded; the property
  // tests allow 1e-9).
  double max_rel_constraint_violation = 0;
  double texture_step = 0;             // textured contacts: the largest distance a contact point moved in
                                       // this step (scene units; > half the shortest wavelength: skipped)
  ProjectionStatus projection = ProjectionStatus::kOptimal;
  CcdStatus ccd = CcdStatus::kOk;
  double u_hit = 1;                    // of the last CCD leg
  int num_contacts = 0;
  int num_halves = 1;                  // 2 when the first leg was split (half turn)
  // The CCD's inputs (step 4), so that a run's collision work can be replayed
  // exactly (advance_god_object): the first leg's motion x_start -> x_target, with
  // x_start the god-object's pose before the step and x_target = x_start (+) ac.
  // A leg split in halves (num_halves = 2, near a half turn) is still recorded
  // whole: its halves are x_start -> split_step(x_start, x_target) -> x_target.
  // residual = au - ac, the part of the command the previous contacts withheld
  // (zero when the previous set was empty); settled: the settling leg ran (the
  // first leg ended free and out of contact: the god-object moved on by
  // `residual` from where it ended, see advance_god_object). Both poses are the
  // god-object's, world frame; they equal xs when status is kNoHandle.
  Pose x_start, x_target;
  Vec6 residual = Vec6::Zero();
  bool settled = false;
  // Times the settling leg's end was refused, the step then done again with the
  // first leg halved: the direct motion x_start -> that end was not proven free
  // (it cut a convex crease the two legs went round; property 5 holds for the
  // motion between published poses). 0 when it was kept or did not run.
  int num_shortenings = 0;
  // Budgeted updates (RuntimeSettings::budget, docs/sim-step.md): the update's work units
  // (update_budget.h; 0 without a budget), whether it ran out of
  // its budget (then it ended at the end of what it had proven free), and how far from x_target
  // the displayed xs was left then (scene units: travel plus turn times the god-object's radius).
  long work_units = 0;
  bool budget_exhausted = false;
  double budget_deferred = 0;
  double update_seconds = 0;           // wall time of the whole step (steady_clock)
  double update_cpu_seconds = 0;       // the sim thread's CPU time in the step (CLOCK_THREAD_CPUTIME_ID):
                                       // the step's work without the time the thread was preempted
  const ContactSet* contacts = nullptr;  // the contact set at xs (valid during the hook call only)
};

struct CouplingStepInfo {
  double time = 0;
  bool has_god_object = false;         // false until the first snapshot arrives (Fc = 0)
  bool new_set = false;                // a snapshot arrived this step
  uint64_t god_sequence = 0;
  double god_time = -1;
  Pose xs;                             // the god-object pose the step used (the cached snapshot's)
  // ac: the projection the force comes from: of au under J, or on a shaded
  // surface under the shading rows Js (then ac = asc, the motion pass 1 gives
  // and the sim loop takes, surface.h); Fc = kh M (ac - au).
  Vec6 au = Vec6::Zero(), ac = Vec6::Zero(), Fc = Vec6::Zero();
  bool shaded = false;                 // the rows were the shading rows Js
  int num_rows = 0, num_offset_rows = 0;  // rows, and rows with b_k != 0 (an offset runs, or the account lowered it)
  int num_new_offsets = 0;             // rows offset when this snapshot arrived
  double offset_power = 0;             // kh lambda^T b: what Fc . ac equals with offsets (0 without)
  ProjectionStatus projection = ProjectionStatus::kOptimal;
  double force_seconds = 0;            // wall time of the step (steady_clock)
};

struct HapticTickRecord {
  uint64_t tick = 0;
  double time = 0;
  DeviceStatus device_status = DeviceStatus::kOk;
  Pose xh;                             // the last good handle pose
  uint32_t buttons = 0;                // the last sample's buttons
  bool gripped = true;                 // the last sample's DeviceState::gripped
  Vec6 F_computed = Vec6::Zero();      // before the safety stage
  Vec6 F_sent = Vec6::Zero();          // what write() received
  uint32_t active_events = 0;          // bit k: RuntimeEventKind k holds this tick
};

// Hooks, called from the loops' threads (concurrently in threaded runs): they
// must not block, allocate for long or throw. Null members are skipped.
struct RuntimeObserver {
  void* user = nullptr;
  void (*on_event)(void* user, const RuntimeEvent& event) = nullptr;
  void (*on_sim_step)(void* user, const SimStepInfo& info) = nullptr;
  void (*on_coupling_step)(void* user, const CouplingStepInfo& info) = nullptr;
  void (*on_haptic_tick)(void* user, const HapticTickRecord& record) = nullptr;
};

}  // namespace gauss6
