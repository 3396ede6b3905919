// The sim loop (METHOD.md section 2): projection with the previous contacts,
// the god-object's move and its new contact set (step 4: sim_step4.cpp),
// publish (sim_loop.h).
#include "gauss6/sim_loop.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "gauss6/motion.h"
#include "runtime_detail.h"

namespace gauss6 {

using namespace detail;  // the loops' shared machinery (runtime_detail.h)

SimState::SimState(const RuntimeModel& model)
    : capacity(model.settings.max_contacts),
      contacts(capacity),
      gap_rhs(static_cast<size_t>(capacity)),
      projection_ws(capacity),
      projection(capacity),
      shaded_J(6 * static_cast<size_t>(capacity)),
      shaded_normal(3 * static_cast<size_t>(capacity)),
      shading_ws(capacity),
      shading(capacity),
      held_J(6 * static_cast<size_t>(capacity)),
      step4(model),
      contact_ws(model.god_mesh_B),
      snapshot(capacity) {
  xs = model.initial_pose;
  M = mass_matrix_at(model, xs.q);
  contacts.num_contacts = 0;
}

// ---------------------------------------------------------------------------
// Sim loop.
// ---------------------------------------------------------------------------

namespace {

// Step 3, pass 1 on shaded surfaces (surface.h): asc = the projection of au
// under the shading rows Js. The coupling loop computes it at its rate and
// publishes it with the snapshot it used: when that is this state's last
// snapshot (same xs, same Js), the sim loop takes the coupling's asc, as the
// paper splits the two passes; otherwise (no answer yet) it projects au under
// its own Js. Plain surfaces: asc = au.
Vec6 shade_command(const RuntimeModel& model, const RuntimeChannels& ch, const Vec6& au, SimState* s,
                   SimStepInfo* info) {
  if (!model.surface.active()) return au;
  ShadedMotionSample sample;
  if (s->step > 1 && ch.shaded_motion.try_read(&sample) && sample.god_sequence == s->step - 1) {
    const Vec6 asc = Eigen::Map<const Vec6>(sample.asc);
    if (asc.allFinite()) {
      info->asc_from_coupling = true;
      return asc;
    }
  }
  const int m = s->contacts.num_contacts;
  ProjectionProblem problem;
  problem.M = &s->M;
  problem.au = au;
  problem.J = m > 0 ? s->shaded_J.data() : nullptr;
  problem.num_rows = m;
  project(problem, model.settings.projection, &s->shading_ws, &s->shading);
  return s->shading.ac;
}

// Pass 2's input on textured surfaces: asc slides along the textured tangent
// plane, which leans away from the true surface wherever the texture tilts the
// normal against the motion (an uphill slope); projected under J alone (J asc
// >= 0 holds there) the god-object would lift off the surface it is pressed
// on, its contact set empty at the next step and the force zero for a sim
// period. A texture perturbs the force's direction only, so a true contact the
// command presses on (J_k au < 0) stays a contact: asc is M-projected on J_k a
// <= b_k for those rows (the god-object slides along the true surface at the
// gap target, b_k as in constrain_motion, and leaves it only when the user
// pulls away) together with pass 2's own rows J a >= b, so that a held contact
// keeps J_k a = b_k; pass 2 then projects that under J as before (property 7 is
// the final projection's; here it changes nothing). The held rows alone would
// not do: holding one vertex can move a second, unpressed one into its face,
// pass 2 then pushes it back out and lifts the held vertex a little every step
// until it leaves the contact band and the force jumps to the other vertex.
// Without room for both (more than the set's capacity of rows), the held rows
// alone. Force shading alone keeps the paper's pass 2: there the shaded plane
// is the smooth surface the facets approximate, which the god-object follows
// across an edge (Figure 8). Plain surfaces never come here. The right-hand
// sides go in gap_rhs, which constrain_motion fills anew.
Vec6 hold_pressed_contacts(const RuntimeModel& model, const Vec6& au, const Vec6& asc, SimState* s) {
  if (!model.surface.texture) return asc;
  const int m = std::min(s->contacts.num_contacts, s->capacity);
  const double target = model.contact.delta * (1 + model.settings.gap_factor);
  int held = 0;
  for (int k = 0; k < m; ++k) held += Eigen::Map<const Vec6>(s->contacts.J.data() + 6 * k).dot(au) < 0;
  if (held == 0) return asc;
  const bool with_pass2_rows = m + held <= s->capacity;
  int n = 0;
  for (int k = 0; k < m; ++k) {
    const Eigen::Map<const Vec6> Jk(s->contacts.J.data() + 6 * k);
    const double b = target - s->contacts.contacts[k].separation;
    if (Jk.dot(au) < 0) {  // held: -J_k a >= -b_k
      for (int i = 0; i < 6; ++i) s->held_J[6 * n + i] = -Jk[i];
      s->gap_rhs[n++] = -b;
    }
    if (with_pass2_rows) {  // pass 2's row: J_k a >= b_k
      for (int i = 0; i < 6; ++i) s->held_J[6 * n + i] = Jk[i];
      s->gap_rhs[n++] = b;
    }
  }
  ProjectionProblem problem;
  problem.M = &s->M;
  problem.au = asc;
  problem.J = s->held_J.data();
  problem.b = s->gap_rhs.data();
  problem.num_rows = n;
  // A cold start: these rows are new at every step, and the workspace's last
  // working set is another problem's (pass 1's, the texture's weights).
  ProjectionSettings cold = model.settings.projection;
  cold.warm_start = false;
  project(problem, cold, &s->shading_ws, &s->shading);
  return s->shading.status == ProjectionStatus::kOptimal && s->shading.ac.allFinite() ? s->shading.ac : asc;
}

// Step 3: ac, the M-projection of au with the current contacts. The sim loop
// also keeps each contact's gap near delta (1 + gap_factor): J_k a >= b_k with
// b_k = delta (1 + gap_factor) - separation_k (a few delta at most), so that a
// god-object sliding along a face stays clear of the CCD's stopping distance
// delta instead of grazing it. If these rows conflict (empty polyhedron), the
// plain cone J a >= 0 is used. The force (coupling loop) never sees b.
Vec6 constrain_motion(const RuntimeModel& model, const Vec6& au, SimState* s, double* max_rel_violation) {
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
  // Property 7: the rows hold for the motion taken (the check, on every step),
  // relative to the problem's own scale as the projection's feasibility
  // tolerance is (quasistatics.h: the input's |au| as well as |ac|): ac is
  // computed from au, so its rounding scales with |au|. Relative to |ac| alone,
  // a god-object held still against a facet (|ac| far below |au|) would show
  // the rounding of b = target - separation itself as a violation.
  const Vec6& ac = s->projection.ac;
  const double scale = std::max(ac.norm(), au.norm());  // au: this projection's input
  double worst = 0;
  for (int k = 0; k < m; ++k) {
    const Eigen::Map<const Vec6> Jk(problem.J + 6 * k);
    const double b = problem.b ? problem.b[k] : 0.0;
    worst = std::max(worst, (b - Jk.dot(ac)) / (Jk.norm() * scale + std::abs(b) + 1e-300));
  }
  *max_rel_violation = worst;
  return ac;
}

// Step 5: publish xs, M, J and the contacts (and Js on shaded surfaces).
void publish_god_object(double t, bool shaded, SimState* s, RuntimeChannels* ch) {
  GodObjectSnapshot& g = s->snapshot;
  g.sequence = s->step;
  g.time = t;
  store_pose(s->xs, g.p, g.q);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) g.M[6 * i + j] = s->M(i, j);
  const int m = std::min(s->contacts.num_contacts, s->capacity);
  g.num_contacts = m;
  std::memcpy(g.J.data(), s->contacts.J.data(), sizeof(double) * 6 * static_cast<size_t>(m));
  g.shaded = shaded ? 1 : 0;
  if (shaded) {
    std::memcpy(g.Js.data(), s->shaded_J.data(), sizeof(double) * 6 * static_cast<size_t>(m));
    std::memcpy(g.shaded_normal.data(), s->shaded_normal.data(), sizeof(double) * 3 * static_cast<size_t>(m));
  }
  for (int k = 0; k < m; ++k) {
    const Contact& c = s->contacts.contacts[k];
    for (int i = 0; i < 3; ++i) g.point[3 * k + i] = c.point[i], g.normal[3 * k + i] = c.normal[i];
    g.separation[k] = c.separation;
    g.features[k] = c.features;
  }
  ch->god_object.write(g);
}

// Step 2: au = ks (xh (-) xs), the command towards the handle sample just read.
Vec6 command_motion(const RuntimeModel& model, const SimState& s) {
  const Pose xh = to_pose(s.handle.p, s.handle.q);
  return model.gains.ks * pose_difference(xh, s.xs);
}

// Step 4 (sim_step4.h): from xs towards xs (+) ac, and the settling leg by
// au - ac if the previous contacts' surface fell away. The residual is what the
// contacts withheld from the user's command au, both passes together, not asc -
// ac: on a shaded facet the shading normal leans against the motion on one side
// of each vertex, asc then leans off the facet (J asc > 0: pass 2 withholds
// nothing, asc - ac = 0) and the god-object would lift off with nothing to
// settle it, its contact set empty and the force zero for a step. au - ac still
// presses the god-object back onto the surface it left, by the CCD, so property
// 7 and the contact hold. On plain surfaces asc = au, and the two agree.
void advance_by(const RuntimeModel& model, SimState* s, SimStepInfo* info) {
  const Vec6 residual = s->contacts.num_contacts > 0 ? Vec6(info->au - info->ac) : Vec6::Zero();
  const Pose x_start = s->xs;  // a copy: the step overwrites s->xs
  advance_god_object(model, x_start, pose_update(x_start, info->ac), residual, s, info);
}

// Step 4b on shaded surfaces: the shading rows Js of the new contact set
// (surface.h; a texture's average weighted by the forces the command at the
// new pose gives the contacts, in pass 1's buffers), and on textured ones the
// largest distance a contact point moved in this step: beyond half the
// texture's shortest wavelength the texture is skipped at this speed (the
// kTextureUndersampled event).
void shade_contact_set(const RuntimeModel& model, SimState* s, SimStepInfo* info) {
  if (!model.surface.active()) return;
  TextureWeighting weighting;
  if (model.surface.texture)
    weighting = {&s->M, command_motion(model, *s), &model.settings.projection, &s->shading_ws, &s->shading};
  shade_contacts(model.surface, model.obstacle_meshes_W.data(), s->contacts, s->xs.p, s->capacity,
                 s->shaded_J.data(), rows3(s->shaded_normal), model.surface.texture ? &weighting : nullptr);
  if (!model.surface.texture) return;
  const Mat3 R0 = rotation_matrix(info->x_start.q), R1 = rotation_matrix(s->xs.q);
  const Mat3 R01 = R0 * R1.transpose();
  double step = 0;
  for (int k = 0; k < std::min(s->contacts.num_contacts, s->capacity); ++k) {
    const Vec3& I = s->contacts.contacts[k].point;
    const Vec3 before = info->x_start.p + R01 * (I - s->xs.p);  // the same body point at x_start
    step = std::max(step, (I - before).norm());
  }
  info->texture_step = step;
  if (step > 0.5 * shortest_wavelength(model.surface.field)) s->step_events |= bit(RuntimeEventKind::kTextureUndersampled);
}

// Without a handle sample the god-object stays put (and is still published).
void stay_put(const SimState& s, SimStepInfo* info) {
  info->status = SimStepStatus::kNoHandle;
  info->x_start = info->x_target = s.xs;
  info->num_contacts = s.contacts.num_contacts;
}

}  // namespace

const SimStepInfo& sim_step(const RuntimeModel& model, double t, RuntimeChannels* channels, SimState* s) noexcept {
  const Clock::time_point start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  SimStepInfo& info = s->info;
  info = SimStepInfo{};
  info.step = ++s->step;
  info.time = t;
  s->step_events = 0;
  if (read_handle(*channels, &s->handle)) {      // 1. Read xh.
    info.au = command_motion(model, *s);         // 2. au = ks (xh (-) xs).
    info.asc = shade_command(model, *channels, info.au, s, &info);  // 3. Shaded: asc (pass 1, under Js); else au.
    info.ac = constrain_motion(model, hold_pressed_contacts(model, info.au, info.asc, s), s,
                               &info.max_rel_constraint_violation);  // ac: projection of asc (textured: held
                                                 //    on the pressed contacts) with the previous step's contacts
                                                 //    (property 7 checked).
    info.projection = s->projection.status;
    advance_by(model, s, &info);                 // 4. From xs towards xs (+) ac; the new contacts;
    shade_contact_set(model, s, &info);          //    shaded: their rows Js.
  } else {
    stay_put(*s, &info);
  }
  publish_god_object(t, model.surface.active(), s, channels);  // 5. Publish xs, M, J (Js), the contacts (a new
                                                              //    sequence number is the flag).
  info.xs = s->xs;
  info.contacts = &s->contacts;
  info.update_seconds = seconds_since(start);
  info.update_cpu_seconds = thread_cpu_seconds() - cpu_start;
  return info;
}

}  // namespace gauss6
