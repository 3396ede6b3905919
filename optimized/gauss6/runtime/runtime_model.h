// The runtime's settings and its immutable model (MuJoCo's mjModel): built once
// from a Scene, shared read-only by the three loops (runtime.h).
//
// Units and frames: world frame W, scene units (metres in the shipped scenes),
// seconds. Mass properties are in the god-object's body frame B (origin at G).
#pragma once

#include <stdexcept>
#include <vector>

#include "gauss6/geometry/bvh.h"
#include "gauss6/step/ccd_step.h"
#include "gauss6/contact/contacts.h"
#include "gauss6/contact/offsetting.h"
#include "gauss6/contact/quasistatics.h"
#include "gauss6/io/scene.h"
#include "gauss6/contact/surface.h"
#include "gauss6/step/update_budget.h"

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

// The longest timeout (s) a watchdog may have, and the longest min period of a
// loop: past a second, a stalled loop or a silent device is no longer a fault the
// user should feel the last force through.
inline constexpr double kMaxTimeout = 1.0;

// The largest RuntimeSettings::max_contacts accepted (the buffers take about
// 1 KB per contact).
inline constexpr int kMaxContactCapacity = 100000;

// Every setting of the runtime, one line each. Defaults suit scenes whose delta
// is about 1e-4 of their size.
struct RuntimeSettings {
  ProjectionSettings projection;       // both loops' projections
  int max_contacts = kDefaultMaxContacts;  // contact capacity of the loops' buffers and the published snapshot,
                                       // fixed when the runtime is built (in [1, kMaxContactCapacity]); a larger
                                       // contact set is truncated to it and reported (kContactOverflow)
  CcdStepSettings ccd;                 // the sim loop's CCD; its distances and the cache's margins and budget are
                                       // resolved from the settings below (resolve_runtime_settings): the values
                                       // given in these six fields are not used
  // Lengths relative to the scene's scale, in units of its delta:
  double contact_factor = 0.5;         // contacts within delta (1 + contact_factor) of the god-object
  double gap_factor = 0.25;            // sim loop keeps contact gaps near delta (1 + gap_factor) (< contact_factor)
  double ccd_distance_tolerance = 0.1; // a CCD hit is accepted once a pair is proven within (1 + this) delta
  double near_slack = 0.2;             // the CCD lists the pairs that may come within the contact distance plus
                                       // this many delta (its near pairs: the contact set needs no descent)
  double cache_margin = 64;            // the CCD's proximity cache at rest (proximity_cache.h), in delta
  double cache_margin_max = 256;       // ... at speed (>= cache_margin), in delta
  long cache_fill_budget = 300;        // node pairs a sim step fills the cache's next list with (not scaled)
  double match_distance = 0;           // coupling: a row is "the same" as a cached one when its body-frame point
                                       // moved less than this (0: 1e-3 of the god-object's radius) ...
  double match_cosine = 1 - 1e-9;      // ... and the cosine of the angle between their normals is above this
  ForceSource force_source = ForceSource::kHapticTick;
  double device_timeout = 0.005;       // s without a good device sample before the watchdog zeroes the force
  double sim_timeout = 0.5;            // s without a new sim snapshot (sim stalled) before the force is zeroed
  double coupling_timeout = 0.005;     // s without a new Fc (kCouplingLoop) before the force is zeroed
                                       // (the three timeouts: finite, in (0, kMaxTimeout]; a watchdog cannot be
                                       // switched off)
  double event_interval = 0.1;         // s: a kind's onsets closer than this to its last reported event are
                                       // coalesced into the next one (EventGate; in [0, kMaxTimeout])
  int lockstep_sim_period = 1;         // lockstep: haptic ticks per sim step (>= 1)
  double sim_min_period = 0.0005;      // threaded: a sim step starts at most every this many seconds
  double coupling_min_period = 0;      // threaded, kCouplingLoop: same for coupling steps (0: back to back)
  // Threaded: what the loops ask of the OS to meet their deadlines (each outcome in
  // LoopStats::realtime / pinned_cpu: the machine may refuse).
  int realtime_priority = 0;           // > 0: the haptic loop runs SCHED_FIFO at this priority, the coupling
                                       // loop one below, the sim loop two below (>= 1); 0: the default policy
  bool pin_threads = false;            // true: the haptic loop on the last CPU alone, the other loops on the
                                       // others (no pinning on a single-CPU machine)
  double spin_wait = 0;                // s, in [0, 1]: the haptic loop sleeps until this long before each
                                       // tick's start, then waits for it busily (0: sleeps all the way). A
                                       // timer's wake-up can land 50-100 us late (a VM's, measured:
                                       // docs/benchmarks.md): at 10 kHz, a period. Pinned alone to its CPU,
                                       // the busy wait takes nothing from the other loops.
  UpdateBudgetSettings budget;         // each god-object update's budget (update_budget.h; default: none)
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
  RuntimeSettings settings;            // the effective settings (resolve_runtime_settings)
  ContactSettings contact_generation;  // distance = delta (1 + contact_factor)
  double match_distance = 0;           // resolved (never 0)
  SurfaceModel surface;                // force shading and texture (surface.h); inactive for plain surfaces
  double sim_rate_hz = 0;              // the constraint update rate the texture bound assumes: lockstep,
                                       // device rate / lockstep_sim_period; threaded, at most 1 / sim_min_period
  double texture_max_speed = 0;        // fastest exploration the texture allows at sim_rate_hz (scene units/s;
                                       // 0 without a texture): max_texture_speed (surface.h)
};

// The settings a model runs with: `settings` as given, except the CCD fields
// resolved from the scene's delta and the delta-scaled settings, which are
// overwritten (the value given there is not used):
//   ccd.narrow.min_separation     = delta                          (the stop distance)
//   ccd.narrow.distance_tolerance = ccd_distance_tolerance delta   (0.1: a hit is accepted within 1.1 delta)
//   ccd.cache.margin              = cache_margin delta             (64: proximity cache, at rest)
//   ccd.cache.margin_max          = cache_margin_max delta         (256: proximity cache, at speed)
//   ccd.cache.fill_budget         = cache_fill_budget              (300 node pairs a step, spent by its
//                                                                    first leg only; not scaled)
//   ccd.near_distance             = delta (1 + contact_factor) + near_slack delta
// and contact_generation.distance = delta (1 + contact_factor). No validation:
// RuntimeModel's constructor checks the scene and the settings.
struct EffectiveSettings {
  RuntimeSettings runtime;
  ContactSettings contact_generation;  // the contact set's distance
};
EffectiveSettings resolve_runtime_settings(const Scene& scene, const RuntimeSettings& settings);

// M = diag(m I3, R I_G R^T) for the rotation R: world frame, about G.
Mat6 mass_matrix(const RuntimeModel& model, const Mat3& R);
// The same at orientation q: R = rotation_matrix(normalized(q)).
Mat6 mass_matrix_at(const RuntimeModel& model, const Quat& q);

}  // namespace gauss6
