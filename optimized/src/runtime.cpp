// The three loops of the god-object method (METHOD.md sections 2-3) and their
// two run modes, lockstep and threaded. See runtime.h.
#include "gauss6/runtime.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <thread>

#include "gauss6/motion.h"

namespace gauss6 {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr uint32_t bit(RuntimeEventKind k) { return 1u << static_cast<int>(k); }
static_assert(kNumRuntimeEventKinds <= 32, "event kinds are bits of a uint32_t");

// Reports the conditions of `events` that did not hold last time (*active), and
// counts them in stats.
void report_onsets(uint32_t events, uint32_t* active, double t, uint64_t tick, const RuntimeObserver& observer,
                   LoopStats* stats, int detail = 0) {
  const uint32_t onset = events & ~*active;
  *active = events;
  for (int k = 0; k < kNumRuntimeEventKinds; ++k) {
    if (!(onset & (1u << k))) continue;
    ++stats->event_counts[k];
    if (observer.on_event) {
      RuntimeEvent e;
      e.kind = static_cast<RuntimeEventKind>(k);
      e.time = t;
      e.tick = tick;
      e.detail = detail;
      observer.on_event(observer.user, e);
    }
  }
}

void store_pose(const Pose& x, double p[3], double q[4]) {
  for (int i = 0; i < 3; ++i) p[i] = x.p[i];
  q[0] = x.q.w, q[1] = x.q.x, q[2] = x.q.y, q[3] = x.q.z;
}

bool all_finite(const Vec6& v) { return v.allFinite(); }

}  // namespace

const char* to_string(RuntimeEventKind k) {
  switch (k) {
    case RuntimeEventKind::kInvalidHandlePose: return "invalid_handle_pose";
    case RuntimeEventKind::kDeviceError: return "device_error";
    case RuntimeEventKind::kDeviceTimeout: return "device_timeout";
    case RuntimeEventKind::kSimStalled: return "sim_stalled";
    case RuntimeEventKind::kCouplingStalled: return "coupling_stalled";
    case RuntimeEventKind::kNonFiniteForce: return "non_finite_force";
    case RuntimeEventKind::kForceClamped: return "force_clamped";
    case RuntimeEventKind::kDeviceEnded: return "device_ended";
    case RuntimeEventKind::kProjectionFailed: return "projection_failed";
    case RuntimeEventKind::kCcdGaveUp: return "ccd_gave_up";
    case RuntimeEventKind::kContactOverflow: return "contact_overflow";
  }
  return "unknown";
}

void DurationStats::add(double seconds) {
  if (count == 0 || seconds < min) min = seconds;
  if (count == 0 || seconds > max) max = seconds;
  sum += seconds;
  ++count;
}

void LoopStats::add_start(double t) {
  if (last_start >= 0) period.add(t - last_start);
  last_start = t;
}

Pose to_pose(const double p[3], const double q[4]) {
  Pose x;
  x.p = Vec3(p[0], p[1], p[2]);
  x.q = Quat{q[0], q[1], q[2], q[3]};
  return x;
}

// ---------------------------------------------------------------------------
// Model and states.
// ---------------------------------------------------------------------------

RuntimeModel::RuntimeModel(const Scene& scene, const RuntimeSettings& s) : settings(s) {
  auto fail = [&](const std::string& what) {
    throw RuntimeError("scene '" + scene.path + "': " + what);
  };
  // Surface properties are not rendered by this runtime: refuse rather than
  // silently render a plain surface.
  if (scene.surface.kind == SurfaceKind::kForceShading)
    fail("surface.kind = force_shading is not supported by the runtime (two-pass scheme not implemented)");
  if (scene.surface.kind == SurfaceKind::kTexture)
    fail("surface.kind = texture is not supported by the runtime");
  if (num_triangles(scene.god_object.mesh) == 0) fail("the god-object's mesh is empty");
  if (!(scene.contact.delta > 0) || !std::isfinite(scene.contact.delta)) fail("contact.delta must be > 0");
  if (!(scene.gains.ks > 0 && scene.gains.ks <= 1)) fail("gains.ks must be in (0, 1]");
  if (!(scene.gains.kh >= 0) || !std::isfinite(scene.gains.kh)) fail("gains.kh must be >= 0 and finite");
  if (!(scene.device.rate_hz > 0 && scene.device.rate_hz <= 10000)) fail("device.rate_hz must be in (0, 10000]");
  if (!(scene.device.max_force > 0) || !(scene.device.max_torque > 0)) fail("device limits must be > 0");
  if (!(s.contact_factor > 0) || !(s.gap_factor > 0 && s.gap_factor < s.contact_factor))
    fail("settings: need 0 < gap_factor < contact_factor");
  if (!(s.device_timeout > 0) || !(s.sim_timeout > 0) || !(s.coupling_timeout > 0))
    fail("settings: timeouts must be > 0");
  if (s.lockstep_sim_period < 1) fail("settings: lockstep_sim_period must be >= 1");
  if (!(s.sim_min_period >= 0) || !(s.coupling_min_period >= 0)) fail("settings: min periods must be >= 0");

  // Obstacles: vertices and normals moved to the world frame once; BVHs built once.
  obstacle_meshes_W.reserve(scene.obstacles.size());
  obstacle_bvhs_W.reserve(scene.obstacles.size());
  for (const Body& b : scene.obstacles) {
    TriangleMesh m = b.mesh;
    const Mat3 R = rotation_matrix(b.pose.q);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v) m.V.row(v) = (b.pose.p + R * m.V.row(v).transpose()).transpose();
    if (m.N.rows() == m.V.rows()) {
      // R(q) is a rotation times |q|^0 (rational form): normals only rotate.
      for (Eigen::Index v = 0; v < m.N.rows(); ++v) m.N.row(v) = (R * m.N.row(v).transpose()).transpose();
    }
    obstacle_meshes_W.push_back(std::move(m));
  }
  for (const TriangleMesh& m : obstacle_meshes_W) obstacle_bvhs_W.push_back(build_bvh(m));
  for (size_t k = 0; k < obstacle_meshes_W.size(); ++k) obstacles.push_back({&obstacle_meshes_W[k], &obstacle_bvhs_W[k]});

  // God-object: body frame B, origin at G.
  god_mesh_B = scene.god_object.mesh;
  god_bvh_B = build_bvh(god_mesh_B);
  god = {&god_mesh_B, &god_bvh_B};
  god_radius = god_bvh_B.radius;

  // Inertia about G from the inertia about the centre of mass c (parallel axes).
  const MassProperties& mp = scene.god_mass.mass;
  mass = mp.mass;
  const Vec3 c = mp.center_of_mass;
  inertia_G_B = mp.inertia + mp.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  if (!(mass > 0) || !std::isfinite(mass) || !inertia_G_B.allFinite() || inertia_G_B.llt().info() != Eigen::Success)
    fail("the god-object's mass properties are not positive definite");

  initial_pose = scene.god_object.pose;
  gains = scene.gains;
  contact = scene.contact;
  offsets.eps = scene.contact.offset_eps;
  offsets.T = scene.contact.offset_time;
  if (!valid_offset_settings(offsets)) fail("contact.offset_eps must be < 0 and contact.offset_time > 0");
  device = scene.device;

  // The CCD stops the god-object delta before contact; contacts are the pairs
  // within delta (1 + contact_factor).
  settings.ccd.narrow.min_separation = contact.delta;
  // A hit is accepted once the features are proven within 1.1 delta: the stop pose keeps
  // at least delta (the guarantee) and the search ends well before rounding-level widths
  // (the default 1e-9 is meant for unit-size queries; docs/benchmarks.md, the delta sweep).
  settings.ccd.narrow.distance_tolerance = 0.1 * contact.delta;
  // Coherence: a leg that starts in contact keeps the pairs within 64 delta
  // more than the reach, and the legs after it take their candidates from them
  // while no point has moved 64 delta from there (ccd_step's proximity cache;
  // docs/benchmarks.md has the sweep of this margin).
  settings.ccd.cache_margin = 64 * contact.delta;
  // A list's margin grows with the god-object's speed up to 256 delta (about
  // six steps like the last one), and the next list is filled 300 node pairs
  // a step (about 60 us on the peg) while the one in use serves, at the pose
  // the god-object is heading for: a sliding god-object seldom waits for a
  // whole fill, and a resting one scans a short list.
  settings.ccd.cache_margin_max = 256 * contact.delta;
  settings.ccd.cache_fill_budget = 300;
  contact_generation.distance = contact.delta * (1 + settings.contact_factor);
  // The CCD lists the pairs that may come within the contact distance (and the
  // distance a hit may be accepted at, 0.1 delta more: update_contacts) of each
  // other by the stop pose, so the contact set needs no descent of its own.
  settings.ccd.near_distance = contact_generation.distance + 0.2 * contact.delta;
  match_distance = settings.match_distance > 0 ? settings.match_distance : 1e-3 * god_radius;
}

Mat6 mass_matrix_at(const RuntimeModel& model, const Quat& q) {
  const Mat3 R = rotation_matrix(normalized(q));
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>() = model.mass * Mat3::Identity();
  M.bottomRightCorner<3, 3>() = R * model.inertia_G_B * R.transpose();
  // Symmetric to the last bit (the projection caches M by its bytes).
  M.bottomRightCorner<3, 3>() = (0.5 * (M.bottomRightCorner<3, 3>() + M.bottomRightCorner<3, 3>().transpose())).eval();
  return M;
}

SimState::SimState(const RuntimeModel& model)
    : contacts(kMaxContacts), contact_ws(model.god_mesh_B) {
  xs = model.initial_pose;
  M = mass_matrix_at(model, xs.q);
  contacts.num_contacts = 0;
}

RuntimeData::RuntimeData(const RuntimeModel& model) : sim(model) {
  coupling.xs = model.initial_pose;
  haptic.xh = model.initial_pose;
}

// ---------------------------------------------------------------------------
// Sim loop.
// ---------------------------------------------------------------------------

namespace {

// Step 1: the latest handle sample (false when none was published yet).
bool read_handle(const RuntimeChannels& ch, HandleSample* sample) { return ch.handle.try_read(sample); }

// Step 3: ac, the M-projection of au with the current contacts. The sim loop
// also keeps each contact's gap near delta (1 + gap_factor): J_k a >= b_k with
// b_k = delta (1 + gap_factor) - separation_k (a few delta at most), so that a
// god-object sliding along a face stays clear of the CCD's stopping distance
// delta instead of grazing it. If these rows conflict (empty polyhedron), the
// plain cone J a >= 0 is used. The force (coupling loop) never sees b.
Vec6 constrain_motion(const RuntimeModel& model, const Vec6& au, SimState* s) {
  const int m = s->contacts.num_contacts;
  const double target = model.contact.delta * (1 + model.settings.gap_factor);
  for (int k = 0; k < m; ++k) s->gap_rhs[k] = target - s->contacts.contacts[k].separation;
  ProjectionProblem problem;
  problem.M = &s->M;
  problem.au = au;
  problem.J = m > 0 ? s->contacts.J.data() : nullptr;
  problem.b = m > 0 ? s->gap_rhs.data() : nullptr;
  problem.num_rows = m;
  project(problem, model.settings.projection, &s->projection_ws, &s->projection);
  if (s->projection.status == ProjectionStatus::kInfeasibleOffsets) {
    problem.b = nullptr;
    project(problem, model.settings.projection, &s->projection_ws, &s->projection);
  }
  return s->projection.ac;
}

// One CCD leg along the Cayley motion x0 -> x1, split in halves on a half turn
// (each half turns by at most 90 degrees), with s->ccd_hints[0 .. num_hints)
// tested first; s->ccd holds the result of the last call. When the leg can
// run, s->xs becomes the motion's own pose at u_hit (its end when no hit: the
// CCD's guarantee holds for it, up to make_stop_pose's deviation bound) and the
// function returns true; on invalid input or a half turn left after splitting,
// s->xs is left as it was and it returns false.
bool ccd_leg(const RuntimeModel& model, const Pose& x0, const Pose& x1, int num_hints, SimState* s,
             int* num_halves) {
  const int num_obstacles = static_cast<int>(model.obstacles.size());
  const CcdBody* obstacles = model.obstacles.data();
  CcdStepResult& r = s->ccd;
  ccd_step(obstacles, num_obstacles, model.god, x0, x1, model.settings.ccd, &s->ccd_ws, &r, s->ccd_hints.data(),
           num_hints);
  if (r.status == CcdStatus::kHalfTurn) {
    const Pose mid = split_step(x0, x1);
    *num_halves = 2;
    ccd_step(obstacles, num_obstacles, model.god, x0, mid, model.settings.ccd, &s->ccd_ws, &r, s->ccd_hints.data(),
             num_hints);
    if (r.status != CcdStatus::kInvalidInput && r.status != CcdStatus::kHalfTurn && !r.hit)
      ccd_step(obstacles, num_obstacles, model.god, mid, x1, model.settings.ccd, &s->ccd_ws, &r);
  }
  if (r.status == CcdStatus::kInvalidInput || r.status == CcdStatus::kHalfTurn) return false;
  const StopPose stop = make_stop_pose(r.motion, r.hit ? r.u_hit : 1.0, model.god_radius);
  s->xs = stop.pose;
  s->stop_deviation = stop.deviation;
  return true;
}

// The contact set at s->xs: every pair within delta (1 + contact_factor), and
// at least the pair that stopped the last leg (s->ccd). Sets the overflow event.
void update_contacts(const RuntimeModel& model, SimState* s) {
  const CcdStepResult& r = s->ccd;
  ContactSettings cs = model.contact_generation;
  if (r.hit && std::isfinite(r.distance_reached))
    cs.distance = std::max(cs.distance, r.distance_reached + model.contact.delta * model.settings.contact_factor);
  // The CCD's near pairs hold every pair within its near reach at xs, less how
  // far the double pose xs may lie from the motion's (its deviation, and the
  // rounding of posing the vertices in doubles): when the contact distance is
  // within that, they are the only pairs to test.
  const double slack = next_up(s->stop_deviation + 1e-13 * (s->xs.p.cwiseAbs().maxCoeff() + model.god_radius));
  const bool near = r.num_near_pairs >= 0 && (r.hit ? r.u_hit : 1.0) >= r.near_u0 && cs.distance + slack <= r.near_reach;
  const ContactStatus status =
      generate_contacts(model.obstacles.data(), static_cast<int>(model.obstacles.size()), model.god, s->xs, cs,
                        &s->contact_ws, &s->contacts, s->ccd_ws.near_pairs(near ? r.num_near_pairs : -1));
  if (status == ContactStatus::kInvalidInput) s->contacts.num_contacts = 0;
  if (status == ContactStatus::kOverflow || status == ContactStatus::kStackFull)
    s->step_events |= bit(RuntimeEventKind::kContactOverflow);
}

}  // namespace

// Step 4: CCD along x_start -> x_target, then xs = its end or the stop pose and
// the contact set at xs; then, when that leg ended free and out of contact while
// the previous contacts withheld part of the command, the settling leg by the
// withheld part (runtime.h).
void advance_god_object(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual,
                        SimState* s, SimStepInfo* info) {
  info->x_start = x_start;
  info->x_target = x_target;
  info->residual = residual;
  info->settled = false;
  info->num_halves = 1;
  s->xs = x_start;
  // The contacts at x_start (the set of the last step, at s->xs) are the pairs
  // most likely to stop either leg: ccd_step tests them first.
  const int num_hints = std::min(s->contacts.num_contacts, kMaxContacts);
  for (int k = 0; k < num_hints; ++k) s->ccd_hints[k] = s->contacts.contacts[k].features;
  const bool moved = ccd_leg(model, x_start, x_target, num_hints, s, &info->num_halves);
  info->ccd = s->ccd.status;
  info->u_hit = s->ccd.u_hit;
  info->status = !moved ? SimStepStatus::kInvalidStep
                        : (s->ccd.hit ? SimStepStatus::kContact : SimStepStatus::kFree);
  update_contacts(model, s);

  // Settling leg: the linearised constraints J a >= 0 hold to first order only,
  // so a motion along a contact's tangent plane lifts off a surface that curves
  // or creases away under it. The god-object then moves on by what the previous
  // contacts withheld, au - ac, from where it ended (the total command is at
  // most au, as without contacts), and stops delta before the surface again.
  const bool lifted_off = moved && !s->ccd.hit && s->contacts.num_contacts == 0;
  if (lifted_off && residual.allFinite() && residual != Vec6::Zero()) {
    info->settled = true;
    const Pose from = s->xs;
    int halves = 1;
    if (ccd_leg(model, from, pose_update(from, residual), num_hints, s, &halves)) {
      if (s->ccd.hit) info->status = SimStepStatus::kContact;
      update_contacts(model, s);
    }
    if (info->ccd == CcdStatus::kOk) info->ccd = s->ccd.status;
    info->u_hit = s->ccd.u_hit;
  }
  s->M = mass_matrix_at(model, s->xs.q);
  info->num_contacts = s->contacts.num_contacts;
}

namespace {

// Step 5: publish xs, M, J and the contacts.
void publish_god_object(double t, SimState* s, RuntimeChannels* ch) {
  GodObjectSnapshot& g = s->snapshot;
  g.sequence = s->step;
  g.time = t;
  store_pose(s->xs, g.p, g.q);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) g.M[6 * i + j] = s->M(i, j);
  const int m = std::min(s->contacts.num_contacts, kMaxContacts);
  g.num_contacts = m;
  std::memcpy(g.J, s->contacts.J.data(), sizeof(double) * 6 * static_cast<size_t>(m));
  for (int k = 0; k < m; ++k) {
    const Contact& c = s->contacts.contacts[k];
    for (int i = 0; i < 3; ++i) g.point[k][i] = c.point[i], g.normal[k][i] = c.normal[i];
    g.separation[k] = c.separation;
  }
  ch->god_object.write(g);
}

}  // namespace

const SimStepInfo& sim_step(const RuntimeModel& model, double t, RuntimeChannels* channels, SimState* s) {
  const Clock::time_point start = Clock::now();
  SimStepInfo& info = s->info;
  info = SimStepInfo{};
  info.step = ++s->step;
  info.time = t;
  s->step_events = 0;
  // 1. Read xh.
  if (read_handle(*channels, &s->handle)) {
    const Pose xh = to_pose(s->handle.p, s->handle.q);
    // 2. au = ks (xh (-) xs).
    info.au = model.gains.ks * pose_difference(xh, s->xs);
    // 3. ac: projection with the previous step's contacts.
    info.ac = constrain_motion(model, info.au, s);
    info.projection = s->projection.status;
    // 4. xt = xs (+) ac; CCD; xs = xt or the stop pose; the new contact set
    //    (and the settling leg by au - ac if the previous contacts' surface fell away).
    const Vec6 residual = s->contacts.num_contacts > 0 ? Vec6(info.au - info.ac) : Vec6::Zero();
    const Pose x_start = s->xs;  // a copy: the step overwrites s->xs
    advance_god_object(model, x_start, pose_update(x_start, info.ac), residual, s, &info);
  } else {
    info.status = SimStepStatus::kNoHandle;
    info.x_start = info.x_target = s->xs;
    info.num_contacts = s->contacts.num_contacts;
  }
  // 5. Publish xs, M, J, the contacts (a new sequence number is the flag).
  publish_god_object(t, s, channels);
  info.xs = s->xs;
  info.contacts = &s->contacts;
  info.update_seconds = seconds_since(start);
  return info;
}

// ---------------------------------------------------------------------------
// Coupling loop.
// ---------------------------------------------------------------------------

namespace {

// Copies a new snapshot, if one was published since the last call. True when it did.
bool receive_god_object(const RuntimeChannels& ch, CouplingState* s) {
  const uint64_t writes = ch.god_object.num_writes();
  if (writes == s->god_writes) return false;
  if (!ch.god_object.try_read(&s->god)) return false;  // raced: keep the cached one
  s->god_writes = writes;
  s->has_god = true;
  s->xs = to_pose(s->god.p, s->god.q);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) s->M(i, j) = s->god.M[6 * i + j];
  return true;
}

void publish_wrench(double t, const CouplingStepInfo& info, RuntimeChannels* ch) {
  WrenchSample w;
  w.time = t;
  for (int i = 0; i < 6; ++i) w.F[i] = info.Fc[i];
  w.god_time = info.god_time;
  ch->wrench.write(w);
}

}  // namespace

const CouplingStepInfo& coupling_step(const RuntimeModel& model, double t, RuntimeChannels* channels,
                                      CouplingState* s) {
  const Clock::time_point start = Clock::now();
  CouplingStepInfo& info = s->info;
  info = CouplingStepInfo{};
  info.time = t;
  // 1. Read xh; read xs, M, J when a new set has arrived.
  if (read_handle(*channels, &s->handle)) s->has_handle = true;
  info.new_set = receive_god_object(*channels, s);
  info.has_god_object = s->has_god;
  if (s->has_handle && s->has_god) {
    info.god_sequence = s->god.sequence;
    info.god_time = s->god.time;
    info.xs = s->xs;
    const int m = s->god.num_contacts;
    info.num_rows = m;
    // 2. au = ks (xh (-) xs); offsets for the new rows of a new set.
    info.au = model.gains.ks * pose_difference(to_pose(s->handle.p, s->handle.q), s->xs);
    if (info.new_set) {
      const OffsetRule rule{model.offsets, model.match_distance, model.settings.match_cosine,
                            model.settings.projection};
      const OffsetRows rows{m, s->god.J, s->god.point, s->god.normal};
      info.num_new_offsets = start_offsets(rule, t, info.au, s->M, s->xs, rows, &s->offsets);
    }
    // 3. ac = projection (warm-started), b(t) while offsets run; Fc = kh M (ac - au).
    info.num_offset_rows = fill_offsets(model.offsets, t, &s->offsets);
    ProjectionProblem problem;
    problem.M = &s->M;
    problem.au = info.au;
    problem.J = m > 0 ? s->god.J : nullptr;
    problem.b = info.num_offset_rows > 0 ? s->offsets.rhs.data() : nullptr;
    problem.num_rows = m;
    info.projection = project(problem, model.settings.projection, &s->projection_ws, &s->projection);
    info.ac = s->projection.ac;
    info.Fc = coupling_force(s->M, info.au, info.ac, model.gains.kh);
  }
  // 4. Publish Fc (zero until both xh and a snapshot are known).
  publish_wrench(t, info, channels);
  info.force_seconds = seconds_since(start);
  return info;
}

// ---------------------------------------------------------------------------
// Haptic loop.
// ---------------------------------------------------------------------------

Vec6 make_safe_wrench(const Vec6& F, double max_force, double max_torque, uint32_t* events) {
  if (!all_finite(F)) {
    *events |= bit(RuntimeEventKind::kNonFiniteForce);
    return Vec6::Zero();
  }
  // Scale each part down to its limit (direction kept).
  Vec6 out = F;
  const double f = F.head<3>().norm(), tau = F.tail<3>().norm();
  if (f > max_force) out.head<3>() *= max_force / f, *events |= bit(RuntimeEventKind::kForceClamped);
  if (tau > max_torque) out.tail<3>() *= max_torque / tau, *events |= bit(RuntimeEventKind::kForceClamped);
  if (!all_finite(out)) {  // only when a limit itself is not finite
    *events |= bit(RuntimeEventKind::kNonFiniteForce);
    return Vec6::Zero();
  }
  return out;
}

namespace {

constexpr uint32_t kZeroForceEvents =
    bit(RuntimeEventKind::kInvalidHandlePose) | bit(RuntimeEventKind::kDeviceTimeout) |
    bit(RuntimeEventKind::kSimStalled) | bit(RuntimeEventKind::kCouplingStalled) |
    bit(RuntimeEventKind::kDeviceEnded);

bool projection_failed(ProjectionStatus s) {
  return s == ProjectionStatus::kBadInput || s == ProjectionStatus::kIterationCap;
}

}  // namespace

bool haptic_tick(const RuntimeModel& model, double t, Device* device, RuntimeChannels* channels, HapticState* h,
                 CouplingState* coupling, const RuntimeObserver& observer, RuntimeStats* stats) {
  const Clock::time_point start = Clock::now();
  const RuntimeSettings& settings = model.settings;
  uint32_t events = 0;
  ++h->tick;

  // 1. Read the device; publish a good xh.
  const DeviceStatus status = device->read(t, &h->device);
  if (status == DeviceStatus::kOk) {
    if (is_valid_pose(h->device.X_WH)) {
      h->xh = h->device.X_WH;
      h->has_handle = true;
      h->last_good_time = t;
      HandleSample sample;
      sample.time = t;
      sample.tick = h->tick;
      store_pose(h->xh, sample.p, sample.q);
      channels->handle.write(sample);
    } else {
      events |= bit(RuntimeEventKind::kInvalidHandlePose);
    }
  } else if (status == DeviceStatus::kEnded) {
    events |= bit(RuntimeEventKind::kDeviceEnded);
    h->ended = true;
  } else {
    events |= bit(RuntimeEventKind::kDeviceError);
  }

  // 2. The force: the coupling step in this tick, or the coupling loop's Fc.
  Vec6 F = Vec6::Zero();
  double god_time = -1, force_time = t;
  if (coupling) {
    const CouplingStepInfo& info = coupling_step(model, t, channels, coupling);
    stats->coupling.add_start(t);
    stats->coupling.work.add(info.force_seconds);
    if (projection_failed(info.projection)) events |= bit(RuntimeEventKind::kProjectionFailed);
    if (observer.on_coupling_step) observer.on_coupling_step(observer.user, info);
    F = info.Fc;
    god_time = info.god_time;
  } else if (channels->wrench.try_read(&h->wrench)) {
    F = Eigen::Map<const Vec6>(h->wrench.F);
    god_time = h->wrench.god_time;
    force_time = h->wrench.time;
  } else {
    force_time = 0;  // nothing published yet (the run started at 0)
  }

  // 3. Safety: watchdogs, then finiteness and limits.
  if (t - h->last_good_time > settings.device_timeout) events |= bit(RuntimeEventKind::kDeviceTimeout);
  if (t - (god_time >= 0 ? god_time : 0.0) > settings.sim_timeout) events |= bit(RuntimeEventKind::kSimStalled);
  if (!coupling && t - force_time > settings.coupling_timeout) events |= bit(RuntimeEventKind::kCouplingStalled);
  const Vec6 F_computed = F;
  if (events & kZeroForceEvents) F.setZero();
  F = make_safe_wrench(F, model.device.max_force, model.device.max_torque, &events);

  // 4. Write the device.
  device->write(t, F);

  // Events (onsets), statistics, record.
  report_onsets(events, &h->active_events, t, h->tick, observer, &stats->haptic, static_cast<int>(status));
  stats->haptic.work.add(seconds_since(start));
  HapticTickRecord& rec = h->record;
  rec.tick = h->tick;
  rec.time = t;
  rec.device_status = status;
  rec.xh = h->xh;
  rec.buttons = h->device.buttons;
  rec.gripped = h->device.gripped;
  rec.F_computed = F_computed;
  rec.F_sent = F;
  rec.active_events = events;
  if (observer.on_haptic_tick) observer.on_haptic_tick(observer.user, rec);
  return !h->ended;
}

// ---------------------------------------------------------------------------
// Runs.
// ---------------------------------------------------------------------------

namespace {

// A sim step with its statistics, events and hook.
void run_sim_step(const RuntimeModel& model, double t, const RuntimeObserver& observer, RuntimeData* data) {
  const SimStepInfo& info = sim_step(model, t, &data->channels, &data->sim);
  data->stats.sim.add_start(t);
  data->stats.sim.work.add(info.update_seconds);
  uint32_t events = data->sim.step_events;
  if (info.ccd != CcdStatus::kOk) events |= bit(RuntimeEventKind::kCcdGaveUp);
  if (projection_failed(info.projection)) events |= bit(RuntimeEventKind::kProjectionFailed);
  report_onsets(events, &data->sim.active_events, t, info.step, observer, &data->stats.sim,
                static_cast<int>(info.ccd));
  if (observer.on_sim_step) observer.on_sim_step(observer.user, info);
}

}  // namespace

void run_lockstep(const RuntimeModel& model, Device* device, long num_ticks, const RuntimeObserver& observer,
                  RuntimeData* data) {
  const double rate = model.device.rate_hz;
  const int n = model.settings.lockstep_sim_period;
  data->stats.haptic.nominal_period = 1 / rate;
  data->stats.sim.nominal_period = n / rate;
  double t = 0;
  for (long k = 0; k < num_ticks; ++k) {
    t = static_cast<double>(k) / rate;  // virtual clock
    if (k % n == 0) run_sim_step(model, t, observer, data);
    data->stats.haptic.add_start(t);
    if (!haptic_tick(model, t, device, &data->channels, &data->haptic, &data->coupling, observer, &data->stats))
      break;
  }
  device->write(t, Vec6::Zero());  // leave the handle without force
  data->stats.run_seconds = t;
}

void run_threaded(const RuntimeModel& model, Device* device, double seconds, const std::atomic<bool>* stop,
                  const RuntimeObserver& observer, RuntimeData* data) {
  const RuntimeSettings& settings = model.settings;
  const bool coupling_thread = settings.force_source == ForceSource::kCouplingLoop;
  const double period = 1 / model.device.rate_hz;
  std::atomic<bool> quit{false};
  const Clock::time_point start = Clock::now();
  auto at = [&](double s) { return start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); };
  data->stats.haptic.nominal_period = period;
  data->stats.sim.nominal_period = settings.sim_min_period;
  data->stats.coupling.nominal_period = coupling_thread ? settings.coupling_min_period : period;

  // Sim loop: as fast as it goes, at most one step per sim_min_period.
  std::thread sim([&] {
    while (!quit.load(std::memory_order_acquire)) {
      const double t = seconds_since(start);
      run_sim_step(model, t, observer, data);
      if (settings.sim_min_period > 0) std::this_thread::sleep_until(at(t + settings.sim_min_period));
    }
  });

  // Coupling loop (kCouplingLoop): back to back, or at most one step per coupling_min_period.
  std::thread coupling;
  if (coupling_thread) {
    coupling = std::thread([&] {
      while (!quit.load(std::memory_order_acquire)) {
        const double t = seconds_since(start);
        const CouplingStepInfo& info = coupling_step(model, t, &data->channels, &data->coupling);
        data->stats.coupling.add_start(t);
        data->stats.coupling.work.add(info.force_seconds);
        const uint32_t events = projection_failed(info.projection) ? bit(RuntimeEventKind::kProjectionFailed) : 0;
        report_onsets(events, &data->coupling.active_events, t, info.god_sequence, observer, &data->stats.coupling);
        if (observer.on_coupling_step) observer.on_coupling_step(observer.user, info);
        if (settings.coupling_min_period > 0) std::this_thread::sleep_until(at(t + settings.coupling_min_period));
        else std::this_thread::yield();
      }
    });
  }

  // Haptic loop: fixed rate, sleep_until pacing; a late start beyond one period
  // is an overrun and the schedule resyncs to now.
  std::thread haptic([&] {
    LoopStats& hs = data->stats.haptic;
    double scheduled = 0, t = 0;
    for (;;) {
      std::this_thread::sleep_until(at(scheduled));
      t = seconds_since(start);
      if (t >= seconds || (stop && stop->load(std::memory_order_acquire))) break;
      const double late = t - scheduled;
      hs.max_jitter = std::max(hs.max_jitter, std::abs(late));
      hs.add_start(t);
      if (!haptic_tick(model, t, device, &data->channels, &data->haptic, coupling_thread ? nullptr : &data->coupling,
                       observer, &data->stats))
        break;
      if (late > period) {
        ++hs.overruns;
        scheduled = t;  // resync
      }
      scheduled += period;
    }
    device->write(t, Vec6::Zero());  // leave the handle without force
    quit.store(true, std::memory_order_release);
  });

  haptic.join();
  sim.join();
  if (coupling.joinable()) coupling.join();
  data->stats.run_seconds = seconds_since(start);
}

}  // namespace gauss6
