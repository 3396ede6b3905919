// The coupling loop (METHOD.md section 3): the cached god-object snapshot,
// offsets for new rows, projection and the force Fc (coupling_loop.h).
#include "gauss6/runtime/coupling_loop.h"

#include "gauss6/contact/coupling.h"
#include "runtime_detail.h"

namespace gauss6 {

using namespace detail;  // the loops' shared machinery (runtime_detail.h)

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

// Shaded surfaces: asc for the sim loop's pass 2, with the snapshot it used.
void publish_shaded_motion(double t, const CouplingStepInfo& info, RuntimeChannels* ch) {
  ShadedMotionSample m;
  m.god_sequence = info.god_sequence;
  m.time = t;
  for (int i = 0; i < 6; ++i) m.asc[i] = info.ac[i];
  ch->shaded_motion.write(m);
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
                                      CouplingState* s) noexcept {
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
    // The rows: J, or on a shaded surface the shading rows Js (pass 1 of the
    // two, surface.h); offsets apply to whichever rows the force comes from.
    info.shaded = s->god.shaded != 0;
    const double* J = info.shaded ? s->god.Js.data() : s->god.J.data();
    // 2. au = ks (xh (-) xs); offsets for the new rows of a new set.
    info.au = model.gains.ks * pose_difference(to_pose(s->handle.p, s->handle.q), s->xs);
    if (info.new_set) {
      const OffsetRule rule{model.offsets, model.match_distance, model.settings.match_cosine,
                            model.settings.projection};
      // Rows are matched by their feature pair on plain surfaces only (see
      // the energy account below for why not on shaded ones).
      const OffsetRows rows{m, J, rows3(s->god.point), rows3(info.shaded ? s->god.shaded_normal : s->god.normal),
                            info.shaded ? nullptr : s->god.features.data()};
      info.num_new_offsets = start_offsets(rule, t, info.au, s->M, s->xs, rows, &s->offsets);
    }
    // 3. ac = projection (warm-started), b(t) while offsets run, lowered where
    // the user backs off with energy lent; Fc = kh M (ac - au); then the
    // offsets' energy account (offsetting.h: passive offsets).
    // The energy account runs on plain surfaces only: on shaded ones this
    // projection is also the god-object's motion (asc, the sim loop's pass
    // 2), so lowered right-hand sides would move it; measured with it: the
    // height map's 50 Hz slide missed two wide bumps, the textured
    // cylinder's force dropped out (0.9 N to 0.12 N in 3 ticks).
    const bool account = !info.shaded;
    const double energy_scale = model.gains.kh / model.gains.ks;
    info.num_offset_rows = fill_offsets(model.offsets, t, &s->offsets);
    const Pose xh = to_pose(s->handle.p, s->handle.q);
    const Vec6 hand = s->has_last_xh ? Vec6(model.gains.ks * pose_difference(xh, s->last_xh)) : Vec6::Zero();
    s->last_xh = xh;
    s->has_last_xh = true;
    if (account) info.num_offset_rows = release_offsets(energy_scale, info.au, hand, J, &s->offsets);
    ProjectionProblem problem;
    problem.M = &s->M;
    problem.au = info.au;
    problem.J = m > 0 ? J : nullptr;
    problem.b = info.num_offset_rows > 0 ? s->offsets.rhs.data() : nullptr;
    problem.num_rows = m;
    info.projection = project(problem, model.settings.projection, &s->projection_ws, &s->projection);
    info.ac = s->projection.ac;
    for (int k = 0; k < m && info.num_offset_rows > 0; ++k)
      info.offset_power += model.gains.kh * s->projection.lambda[k] * s->offsets.rhs[k];
    if (account)
      account_offsets(model.offsets, energy_scale, t, info.au, info.ac, s->projection.lambda.data(),
                      info.projection == ProjectionStatus::kOptimal, s->M, J, &s->offsets);
    info.Fc = coupling_force(s->M, info.au, info.ac, model.gains.kh);
    if (info.shaded) publish_shaded_motion(t, info, channels);  // asc, for the sim loop's pass 2
  }
  // 4. Publish Fc (zero until both xh and a snapshot are known).
  publish_wrench(t, info, channels);
  info.force_seconds = seconds_since(start);
  return info;
}

}  // namespace gauss6
