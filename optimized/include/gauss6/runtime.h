// The god-object runtime: the three loops of METHOD.md sections 2-3 over an
// immutable RuntimeModel and per-loop states (MuJoCo's mjModel / mjData).
//
//   sim loop      (variable rate)  sim_step():      xh -> au -> ac -> CCD -> xs, contacts
//   coupling loop (fast)           coupling_step(): xh, (xs, M, J) -> au -> ac -> Fc
//   haptic loop   (fixed rate)     haptic_tick():   device read -> Fc -> safety -> device write
//
// The loops talk only through RuntimeChannels (lock-free seqlocks, shared_state.h).
// Two ways to run them:
//   run_lockstep(): one thread, a virtual clock and a fixed schedule; a run is
//     repeatable bit for bit (tests, replays, batch reproduction of figures);
//   run_threaded(): one std::thread per loop, the haptic loop paced by
//     sleep_until at the device's rate (real use).
//
// Units and frames: world frame W, scene units (metres in the shipped scenes),
// seconds. Poses are of G (pose.h). Accelerations a are the quasi-static per-step
// displacements (coupling.h); wrenches F = (force, torque about G), world frame.
//
// Choices the method leaves open (see runtime.cpp, and offsetting.cpp for the offsets, for the reasons):
//   - the sim loop regenerates the contact set at every new xs (hit or not), so
//     a god-object sliding off an edge drops that edge's rows; when the step's
//     motion (projected on the previous contacts' tangent cone) ends free and
//     out of contact while those contacts withheld part of the command, the step
//     settles: it moves on by the withheld part au - ac (CCD again), so that a
//     god-object pressed on a convex crease or a curved surface stays on it
//     (advance_god_object);
//   - the CCD stops delta before contact, and the sim loop's projection keeps
//     each contact's gap near delta (1 + gap_factor) (J_k a >= gap_target -
//     separation_k), so that sliding is never taken for a new contact; the
//     coupling loop, hence the force, uses exactly J a >= 0 (or the offsets);
//   - a row of a new set is "the same constraint" as a cached one when its
//     body-frame point and its normal match: its offset runs on; a new row's
//     d_k is J_k ac_old, ac_old the projection on the previous set's rows (what
//     the user felt: J_k au without), so that a contact sliding across
//     triangles, whose rows change identity, is not offset again; after a set
//     with no rows, the last non-empty set stands in for it for offset_time
//     (a contact lost for a step, e.g. sliding over a crease, is not ramped again).
//   - force shading and textures are refused (RuntimeError) when the model is built.
//
// Real-time rules: sim_step, coupling_step and haptic_tick allocate nothing, lock
// nothing and throw nothing; every buffer lives in the states, built once.
// Exceptions (RuntimeError) only come from building the model.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "gauss6/bvh.h"
#include "gauss6/ccd_step.h"
#include "gauss6/contacts.h"
#include "gauss6/coupling.h"
#include "gauss6/device_port.h"
#include "gauss6/offsetting.h"
#include "gauss6/quasistatics.h"
#include "gauss6/scene.h"
#include "gauss6/shared_state.h"

namespace gauss6 {

class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where the haptic loop takes its force from.
enum class ForceSource {
  kHapticTick,    // the coupling step runs inside each haptic tick (lowest latency; default)
  kCouplingLoop,  // a separate coupling thread publishes Fc (the paper's three loops; threaded runs only)
};

// Every setting of the runtime, one line each. Defaults suit scenes whose delta
// is about 1e-4 of their size.
struct RuntimeSettings {
  ProjectionSettings projection;       // both loops' projections
  CcdStepSettings ccd;                 // the sim loop's CCD; narrow.min_separation is set to scene delta
  double contact_factor = 0.5;         // contacts within delta (1 + contact_factor) of the god-object
  double gap_factor = 0.25;            // sim loop keeps contact gaps near delta (1 + gap_factor) (< contact_factor)
  double match_distance = 0;           // coupling: a row is "the same" as a cached one when its body-frame point
                                       // moved less than this (0: 1e-3 of the god-object's radius) ...
  double match_cosine = 1 - 1e-9;      // ... and the cosine of the angle between their normals is above this
  ForceSource force_source = ForceSource::kHapticTick;
  double device_timeout = 0.005;       // s without a good device sample before the watchdog zeroes the force
  double sim_timeout = 0.5;            // s without a new sim snapshot (sim stalled) before the force is zeroed
  double coupling_timeout = 0.005;     // s without a new Fc (kCouplingLoop) before the force is zeroed
  int lockstep_sim_period = 1;         // lockstep: haptic ticks per sim step (>= 1)
  double sim_min_period = 0.0005;      // threaded: a sim step starts at most every this many seconds
  double coupling_min_period = 0;      // threaded, kCouplingLoop: same for coupling steps (0: back to back)
};

// The immutable model: built once from a Scene, shared read-only by every loop.
// Not copyable or movable (bodies point into its own meshes and BVHs).
struct RuntimeModel {
  RuntimeModel(const Scene& scene, const RuntimeSettings& settings);  // throws RuntimeError
  RuntimeModel(const RuntimeModel&) = delete;
  RuntimeModel& operator=(const RuntimeModel&) = delete;

  // Obstacles: meshes moved to the world frame once, their BVHs (world frame).
  std::vector<TriangleMesh> obstacle_meshes_W;
  std::vector<Bvh> obstacle_bvhs_W;
  std::vector<CcdBody> obstacles;      // obstacle k = {&obstacle_meshes_W[k], &obstacle_bvhs_W[k]}
  // God-object: mesh and BVH in its body frame B (origin at G).
  TriangleMesh god_mesh_B;
  Bvh god_bvh_B;
  CcdBody god;
  double god_radius = 0;               // max |r_B| over the mesh (scene units)
  // Mass properties in B: mass and inertia about G (parallel-axis from the centre of mass).
  double mass = 0;
  Mat3 inertia_G_B = Mat3::Identity();
  Pose initial_pose;                   // X_WB of the god-object at start
  Gains gains;
  ContactParameters contact;
  OffsetSettings offsets;              // from the scene's offset_eps and offset_time
  DeviceSettings device;               // rate and force/torque limits
  RuntimeSettings settings;            // as given, ccd.narrow.min_separation = delta
  ContactSettings contact_generation;  // distance = delta (1 + contact_factor)
  double match_distance = 0;           // resolved (never 0)
};

// M = diag(m I3, R I_G R^T) at orientation q: world frame, about G.
Mat6 mass_matrix_at(const RuntimeModel& model, const Quat& q);

// ---------------------------------------------------------------------------
// Channel payloads (plain arrays: trivially copyable).
// ---------------------------------------------------------------------------

// haptic -> sim, coupling: the handle pose xh.
struct HandleSample {
  double time = 0;                     // s
  double p[3] = {0, 0, 0};
  double q[4] = {1, 0, 0, 0};          // w, x, y, z
  uint64_t tick = 0;                   // haptic tick that read it
};

// sim -> coupling: the god-object and its contact set after a sim step.
struct GodObjectSnapshot {
  uint64_t sequence = 0;               // sim step that published it (1, 2, ...)
  double time = 0;                     // s, when it was published
  double p[3] = {0, 0, 0};             // xs
  double q[4] = {1, 0, 0, 0};
  double M[36] = {};                   // 6x6 row-major, world frame at xs's orientation
  int32_t num_contacts = 0;            // m <= kMaxContacts
  double J[kMaxContacts * 6] = {};     // m x 6 row-major
  double point[kMaxContacts][3] = {};  // I_k, world frame
  double normal[kMaxContacts][3] = {}; // n_k, world frame
  double separation[kMaxContacts] = {};
};

// coupling -> haptic: the wrench Fc.
struct WrenchSample {
  double time = 0;                     // s, when it was computed
  double F[6] = {0, 0, 0, 0, 0, 0};    // force, torque about G; world frame
  double god_time = 0;                 // time of the snapshot it used (-1: none yet)
};

struct RuntimeChannels {
  SeqLock<HandleSample> handle;
  SeqLock<GodObjectSnapshot> god_object;
  SeqLock<WrenchSample> wrench;
};

Pose to_pose(const double p[3], const double q[4]);

// ---------------------------------------------------------------------------
// Events and the observer hook (trace recording, logging).
// ---------------------------------------------------------------------------

enum class RuntimeEventKind {
  kInvalidHandlePose = 0,  // the device returned a non-finite pose: zero force this tick
  kDeviceError,            // read() returned a status other than kOk
  kDeviceTimeout,          // watchdog: no good sample for device_timeout: zero force
  kSimStalled,             // watchdog: no sim snapshot for sim_timeout: zero force
  kCouplingStalled,        // watchdog: no Fc for coupling_timeout: zero force
  kNonFiniteForce,         // the computed wrench was not finite: zero force
  kForceClamped,           // force or torque above the device's limits: scaled down
  kDeviceEnded,            // the device's script or replay ended: the run stops
  kProjectionFailed,       // a projection returned kBadInput or kIterationCap
  kCcdGaveUp,              // the sim step's CCD gave up (hit kept conservatively) or refused its input
  kContactOverflow,        // more contacts than kMaxContacts: the set was truncated
};
inline constexpr int kNumRuntimeEventKinds = 11;
const char* to_string(RuntimeEventKind k);

struct RuntimeEvent {
  RuntimeEventKind kind = RuntimeEventKind::kDeviceError;
  double time = 0;                     // s
  uint64_t tick = 0;                   // haptic tick, or sim step for sim events
  int detail = 0;                      // the status's integer value, when one applies
};

// Per-step records, handed to the hooks.
enum class SimStepStatus { kFree = 0, kContact, kNoHandle, kInvalidStep };
struct SimStepInfo {
  uint64_t step = 0;
  double time = 0;
  SimStepStatus status = SimStepStatus::kNoHandle;
  Pose xs;                             // after the step
  Vec6 au = Vec6::Zero(), ac = Vec6::Zero();
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
  double update_seconds = 0;           // wall time of the whole step (steady_clock)
  const ContactSet* contacts = nullptr;  // the contact set at xs (valid during the hook call only)
};

struct CouplingStepInfo {
  double time = 0;
  bool has_god_object = false;         // false until the first snapshot arrives (Fc = 0)
  bool new_set = false;                // a snapshot arrived this step
  uint64_t god_sequence = 0;
  double god_time = -1;
  Pose xs;                             // the god-object pose the step used (the cached snapshot's)
  Vec6 au = Vec6::Zero(), ac = Vec6::Zero(), Fc = Vec6::Zero();
  int num_rows = 0, num_offset_rows = 0;  // rows, and rows whose offset still runs
  int num_new_offsets = 0;             // rows offset when this snapshot arrived
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

// ---------------------------------------------------------------------------
// Timing statistics (no allocation: running sums).
// ---------------------------------------------------------------------------

struct DurationStats {
  long count = 0;
  double min = 0, max = 0, sum = 0;    // s
  double mean() const { return count ? sum / count : 0; }
  void add(double seconds);
};

// One loop's statistics, written only by the thread that runs the loop. In
// lockstep runs, periods are virtual (exact) and work times are real.
struct LoopStats {
  double nominal_period = 0;           // s (0: free-running loop)
  DurationStats period;                // between successive starts
  DurationStats work;                  // the step itself (force computation / god-object update)
  double max_jitter = 0;               // paced loops: max |actual start - scheduled start| (s)
  long overruns = 0;                   // paced loops: starts more than one period late (the schedule then resyncs)
  long event_counts[kNumRuntimeEventKinds] = {};  // events reported by this loop (onsets)
  double last_start = -1;              // s, internal
  void add_start(double t);            // records a start at t (updates period)
};

struct RuntimeStats {
  LoopStats haptic, coupling, sim;     // coupling: filled by the haptic loop with kHapticTick
  double run_seconds = 0;              // wall time (threaded) or virtual time (lockstep)
};

// ---------------------------------------------------------------------------
// Per-loop states: every buffer allocated when built.
// ---------------------------------------------------------------------------

struct SimState {
  explicit SimState(const RuntimeModel& model);
  Pose xs;                             // god-object pose
  Mat6 M = Mat6::Identity();           // at xs's orientation
  ContactSet contacts;                 // the current set (capacity kMaxContacts)
  std::array<double, kMaxContacts> gap_rhs{};  // b_k = delta (1 + gap_factor) - separation_k
  ProjectionWorkspace projection_ws;
  ProjectionResult projection;
  CcdStepWorkspace ccd_ws;
  CcdStepResult ccd;
  std::array<FeaturePair, kMaxContacts> ccd_hints{};  // the contacts at a leg's start, tested first (ccd_step)
  double stop_deviation = 0;           // of xs from the motion's exact pose (make_stop_pose)
  ContactWorkspace contact_ws;
  HandleSample handle;                 // last sample read
  GodObjectSnapshot snapshot;          // what step 5 publishes
  uint64_t step = 0;
  uint32_t step_events = 0;            // conditions found by this step (contact overflow)
  uint32_t active_events = 0;          // conditions of the last step (events fire on onset)
  SimStepInfo info;
};

struct CouplingState {
  CouplingState() = default;
  HandleSample handle;
  bool has_handle = false;
  GodObjectSnapshot god;               // cached snapshot (xs, M, J)
  bool has_god = false;
  uint64_t god_writes = 0;             // channel writes seen (detects a new snapshot)
  Pose xs;
  Mat6 M = Mat6::Identity();
  OffsetState offsets;                 // offsets and identities of the cached rows (offsetting.h)
  ProjectionWorkspace projection_ws;
  ProjectionResult projection;
  uint32_t active_events = 0;          // conditions of the last step (coupling thread's events)
  CouplingStepInfo info;
};

struct HapticState {
  uint64_t tick = 0;
  DeviceState device;                  // last sample
  Pose xh;                             // last good handle pose
  bool has_handle = false;
  double last_good_time = 0;           // s, time of the last good sample (the run's start at first)
  uint32_t active_events = 0;          // conditions that held last tick (events fire on onset)
  bool ended = false;                  // the device ended
  WrenchSample wrench;                 // kCouplingLoop: last Fc read
  HapticTickRecord record;
};

// Everything a run mutates: channels, the three states, statistics.
struct RuntimeData {
  explicit RuntimeData(const RuntimeModel& model);
  RuntimeChannels channels;
  SimState sim;
  CouplingState coupling;
  HapticState haptic;
  RuntimeStats stats;
};

// ---------------------------------------------------------------------------
// Steps. Each reads its inputs from the channels and publishes its outputs.
// t is the run's clock (s): virtual in lockstep runs, steady_clock in threads.
// ---------------------------------------------------------------------------

// One sim step (METHOD.md section 2). Fills and returns s->info. Without a
// handle sample yet, the god-object stays put (and is still published).
const SimStepInfo& sim_step(const RuntimeModel& model, double t, RuntimeChannels* channels, SimState* s);

// Step 4 of a sim step alone, from its recorded inputs (SimStepInfo::x_start,
// x_target, residual): the CCD along the Cayley motion x_start -> x_target (split
// in halves on a half turn), s->xs = its end or its stop pose (delta before the
// first contact), s->M at s->xs, and s->contacts, the contact set at s->xs. If
// that leg ends free with an empty contact set while residual != 0 (the previous
// contacts withheld part of the command, and their surface fell away under the
// linearised constraints: a convex crease or a curved surface), a settling leg
// moves on from s->xs by residual, with its own CCD and contact set, so that a
// god-object pressed against a surface follows it instead of floating off it
// for a step (which the force would show as a dropout). Each leg's motion is
// free of contact (the CCD's guarantee). Sets info's x_start, x_target,
// residual, settled, ccd (the first status other than kOk over the legs),
// u_hit, num_halves, status and num_contacts. Real time: no allocation.
void advance_god_object(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual,
                        SimState* s, SimStepInfo* info);

// One coupling step (METHOD.md section 3). Fills and returns s->info.
const CouplingStepInfo& coupling_step(const RuntimeModel& model, double t, RuntimeChannels* channels,
                                      CouplingState* s);

// One haptic tick: device read, force (the coupling step when coupling != null,
// else the wrench channel), safety (watchdogs, finiteness, limits), device write.
// Writes stats->haptic (and stats->coupling when coupling != null); event onsets
// go to the observer. Returns false when the device ended (zero force written).
bool haptic_tick(const RuntimeModel& model, double t, Device* device, RuntimeChannels* channels,
                 HapticState* h, CouplingState* coupling, const RuntimeObserver& observer, RuntimeStats* stats);

// The safety stage alone: returns a finite wrench within the limits; sets the
// bits of *events (1 << RuntimeEventKind) for kNonFiniteForce and kForceClamped.
Vec6 make_safe_wrench(const Vec6& F, double max_force, double max_torque, uint32_t* events);

// ---------------------------------------------------------------------------
// Runs.
// ---------------------------------------------------------------------------

// Deterministic lockstep run of num_ticks haptic ticks on a virtual clock
// t_k = k / rate_hz: at tick k, first a sim step when k % lockstep_sim_period
// == 0, then the haptic tick (device read, coupling step, device write). Stops
// early when the device ends. The coupling always runs in the tick.
void run_lockstep(const RuntimeModel& model, Device* device, long num_ticks, const RuntimeObserver& observer,
                  RuntimeData* data);

// Threaded run: haptic thread (sleep_until at rate_hz), sim thread, and with
// kCouplingLoop a coupling thread, for `seconds` of wall time or until *stop
// becomes true (stop may be null) or the device ends. Blocks until all joined.
void run_threaded(const RuntimeModel& model, Device* device, double seconds, const std::atomic<bool>* stop,
                  const RuntimeObserver& observer, RuntimeData* data);

}  // namespace gauss6
