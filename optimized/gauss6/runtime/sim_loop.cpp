// The sim loop (METHOD.md section 2): projection with the previous contacts,
// the god-object's move and its new contact set (step 4: sim_step4.cpp),
// publish (sim_loop.h).
#include "gauss6/runtime/sim_loop.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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
      held_b(static_cast<size_t>(capacity)),
      step4(model),
      snapshot(capacity) {
  xs = model.initial_pose;
  R = R_start = rotation_matrix(normalized(xs.q));
  M = mass_matrix(model, R);
  contacts.num_contacts = 0;
}

// ---------------------------------------------------------------------------
// Sim loop.
// ---------------------------------------------------------------------------

namespace {

// Step 3 (METHOD.md sections 2-3, 6): ac, the user's command au under the
// constraints, as a chain of M-projections (quasistatics.h), each pass
// projecting the output of the one before under rows of its own:
//
//   kShading (shaded surfaces, pass 1 of surface.h): au under the shading
//     rows Js, giving asc. The coupling loop computes the same at its rate and
//     publishes it with the snapshot it used: when that is this state's last
//     snapshot (same xs, same Js), the sim loop takes the coupling's asc, as the
//     paper splits the two passes, and skips this pass. Plain surfaces: asc = au.
//   kHold (textures): asc slides along the textured tangent plane, which leans
//     away from the true surface wherever the texture tilts the normal against
//     the motion (an uphill slope); projected under J alone (J asc >= 0 holds
//     there) the god-object would lift off the surface it is pressed on, its
//     contact set empty at the next step and the force zero for a sim period. A
//     texture perturbs the force's direction only, so a true contact the command
//     presses on (J_k au < 0) stays a contact: asc is projected on J_k a <= b_k
//     for those rows (the god-object slides along the true surface at the gap
//     target, and leaves it only when the user pulls away) together with
//     kContacts' own rows J a >= b, so that a held contact keeps J_k a = b_k
//     (the held rows alone would not do: holding one vertex can move a second,
//     unpressed one into its face, kContacts then pushes it back out and lifts
//     the held vertex a little every step until it leaves the contact band and
//     the force jumps to the other vertex). Without room for both (more rows
//     than the set's capacity), the held rows alone. A cold start: these rows
//     are new at every step. Its output is kept only when optimal. Force
//     shading alone keeps the paper's pass 2: there the shaded plane is the
//     smooth surface the facets approximate, which the god-object follows
//     across an edge (Figure 8).
//   kContacts (pass 2): under the current contacts J a >= b_k, b_k = delta (1 +
//     gap_factor) - separation_k (a few delta at most), so that a god-object
//     sliding along a face keeps its gap near delta (1 + gap_factor), clear of
//     the CCD's stopping distance delta instead of grazing it. The force
//     (coupling loop) never sees b.
//   kCone: kContacts' rows with b = 0 (J a >= 0), when its rows conflict
//     (kInfeasibleOffsets: an empty polyhedron).
enum class PassKind { kShading, kHold, kContacts, kCone };
struct ProjectionPass {
  PassKind kind;
  ProjectionProblem problem;  // problem.au: the previous pass's output, set when the pass runs
  bool warm_start;
  ProjectionWorkspace* ws;
  ProjectionResult* result;
};
constexpr int kMaxPasses = 4;

// The coupling loop's asc when it was computed for this state's last snapshot.
bool coupling_asc(const RuntimeChannels& ch, const SimState& s, Vec6* asc) {
  ShadedMotionSample sample;
  if (!(s.step > 1 && ch.shaded_motion.try_read(&sample) && sample.god_sequence == s.step - 1)) return false;
  const Vec6 a = Eigen::Map<const Vec6>(sample.asc);
  if (!a.allFinite()) return false;
  *asc = a;
  return true;
}

// kHold's rows in held_J and held_b: -J_k a >= -b_k for each contact au presses
// on, and kContacts' own J_k a >= b_k when there is room for both. Their count.
int held_rows(const RuntimeModel& model, const Vec6& au, SimState* s) {
  const int m = std::min(s->contacts.num_contacts, s->capacity);
  const double target = model.contact.delta * (1 + model.settings.gap_factor);
  int held = 0;
  for (int k = 0; k < m; ++k) held += Eigen::Map<const Vec6>(s->contacts.J.data() + 6 * k).dot(au) < 0;
  if (held == 0) return 0;
  const bool with_pass2_rows = m + held <= s->capacity;
  int n = 0;
  for (int k = 0; k < m; ++k) {
    const Eigen::Map<const Vec6> Jk(s->contacts.J.data() + 6 * k);
    const double b = target - s->contacts.contacts[k].separation;
    if (Jk.dot(au) < 0) {  // held: -J_k a >= -b_k
      for (int i = 0; i < 6; ++i) s->held_J[6 * n + i] = -Jk[i];
      s->held_b[n++] = -b;
    }
    if (with_pass2_rows) {  // kContacts' row: J_k a >= b_k
      for (int i = 0; i < 6; ++i) s->held_J[6 * n + i] = Jk[i];
      s->held_b[n++] = b;
    }
  }
  return n;
}

// The passes of this step, in order, their rows set up; info->asc is au or the
// coupling's asc until kShading runs.
int plan_projections(const RuntimeModel& model, const RuntimeChannels& ch, SimState* s, SimStepInfo* info,
                     ProjectionPass* passes) {
  const int m = s->contacts.num_contacts;
  const bool warm = model.settings.projection.warm_start;
  int n = 0;
  info->asc = info->au;
  if (model.surface.active()) {
    info->asc_from_coupling = coupling_asc(ch, *s, &info->asc);
    if (!info->asc_from_coupling) {
      const ProjectionProblem rows{&s->M, Vec6::Zero(), m > 0 ? s->shaded_J.data() : nullptr, nullptr, m};
      passes[n++] = {PassKind::kShading, rows, warm, &s->shading_ws, &s->shading};
    }
  }
  if (model.surface.texture) {
    const int held = held_rows(model, info->au, s);
    const ProjectionProblem rows{&s->M, Vec6::Zero(), s->held_J.data(), s->held_b.data(), held};
    if (held > 0) passes[n++] = {PassKind::kHold, rows, false, &s->shading_ws, &s->shading};
  }
  const double target = model.contact.delta * (1 + model.settings.gap_factor);
  for (int k = 0; k < m; ++k) s->gap_rhs[k] = target - s->contacts.contacts[k].separation;
  const ProjectionProblem rows{&s->M, Vec6::Zero(), m > 0 ? s->contacts.J.data() : nullptr,
                               m > 0 ? s->gap_rhs.data() : nullptr, m};
  passes[n++] = {PassKind::kContacts, rows, warm, &s->projection_ws, &s->projection};
  return n;
}

// Property 7: the rows hold for the motion taken (the check, on every step),
// relative to the problem's own scale as the projection's feasibility
// tolerance is (quasistatics.h: the input's |au| as well as |ac|): ac is
// computed from au, so its rounding scales with |au|. Relative to |ac| alone,
// a god-object held still against a facet (|ac| far below |au|) would show
// the rounding of b = target - separation itself as a violation.
double max_rel_violation(const ProjectionProblem& problem, const Vec6& ac) {
  const double scale = std::max(ac.norm(), problem.au.norm());  // au: this projection's input
  double worst = 0;
  for (int k = 0; k < problem.num_rows; ++k) {
    const Eigen::Map<const Vec6> Jk(problem.J + 6 * k);
    const double b = problem.b ? problem.b[k] : 0.0;
    worst = std::max(worst, (b - Jk.dot(ac)) / (Jk.norm() * scale + std::abs(b) + 1e-300));
  }
  return worst;
}

// Runs the chain: sets info's asc, ac, projection (the last pass's status) and
// max_rel_constraint_violation (of the last pass's rows).
void constrain_command(const RuntimeModel& model, const RuntimeChannels& ch, SimState* s, SimStepInfo* info) {
  ProjectionPass passes[kMaxPasses];
  int n = plan_projections(model, ch, s, info, passes);
  Vec6 a = info->asc;  // each pass's input: au, or the coupling's asc
  for (int i = 0; i < n; ++i) {
    ProjectionPass& p = passes[i];
    p.problem.au = p.kind == PassKind::kShading ? info->au : a;
    ProjectionSettings settings = model.settings.projection;
    settings.warm_start = p.warm_start;
    project(p.problem, settings, p.ws, p.result);
    if (p.kind == PassKind::kShading) a = info->asc = p.result->ac;
    if (p.kind == PassKind::kHold && p.result->status == ProjectionStatus::kOptimal && p.result->ac.allFinite())
      a = p.result->ac;
    if (p.kind == PassKind::kContacts && p.result->status == ProjectionStatus::kInfeasibleOffsets) {
      passes[n] = p;  // kCone: the same rows, b = 0
      passes[n].kind = PassKind::kCone;
      passes[n++].problem.b = nullptr;
    }
  }
  const ProjectionPass& last = passes[n - 1];
  info->ac = last.result->ac;
  info->projection = last.result->status;
  info->max_rel_constraint_violation = max_rel_violation(last.problem, info->ac);
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
  advance_god_object(model, s->xs, pose_update(s->xs, info->ac), residual, s->M, &s->contacts, &s->step4, info);
  s->xs = info->xs;
  // Out of budget: what of the command the update left for the next ones, the
  // distance of xs from x_target (travel plus turn times the god-object's radius).
  if (info->budget_exhausted) {
    const Vec6 left = pose_difference(info->x_target, s->xs);
    info->budget_deferred = left.head<3>().norm() + left.tail<3>().norm() * model.god_radius;
  }
  s->R_start = s->R;
  s->R = rotation_matrix(normalized(s->xs.q));
  s->M = mass_matrix(model, s->R);
  s->step_events |= s->step4.events;
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
  info->texture_step = contact_travel(s->contacts, s->capacity, info->x_start.p, s->R_start, s->xs.p, s->R);
  if (info->texture_step > 0.5 * shortest_wavelength(model.surface.field))
    s->step_events |= event_bit(RuntimeEventKind::kTextureUndersampled);
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
    constrain_command(model, *channels, s, &info);  // 3. ac: au projected (shaded: asc, pass 1, under Js;
                                                 //    textured: held on the pressed contacts) under the
                                                 //    previous step's contacts (property 7 checked).
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
