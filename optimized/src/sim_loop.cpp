// The sim loop (METHOD.md section 2): projection with the previous contacts,
// CCD along the in-between motion, the new contact set, publish (sim_loop.h).
#include "gauss6/sim_loop.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "gauss6/error_allowances.h"
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
      // The proximity cache keyed by every obstacle of the model (allocated here, not in a step).
      ccd_ws(CcdStepWorkspace::kBoxCapacity, CcdStepWorkspace::kStackCapacity, CcdStepWorkspace::kCandidateCapacity,
             std::max(static_cast<int>(model.obstacles.size()), CcdStepWorkspace::kObstacleCapacity)),
      ccd_hints(static_cast<size_t>(capacity)),
      proven_near(ccd_ws.candidates.size()),
      contact_ws(model.god_mesh_B),
      snapshot(capacity) {
  xs = model.initial_pose;
  M = mass_matrix_at(model, xs.q);
  contacts.num_contacts = 0;
  // The legs of one update share their descents' cuts (cleared at each update:
  // advance_god_object).
  ccd_ws.front.carry = true;
  check_ws.front.carry = true;
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
// >= 0 holds there) the god-object lifted off the slab it was pressed on (by up
// to 0.9 mm in the Figure 9 run), its contact set emptied at the next step and
// the force dropped to zero for a sim period: 9 of 11 bumps were missed under
// the speed bound. A texture perturbs the force's direction only, so a true
// contact the command presses on (J_k au < 0) stays a contact: asc is
// M-projected on J_k a <= b_k for those rows (the god-object slides along the
// true surface at the gap target, b_k as in constrain_motion, and leaves it
// only when the user pulls away) together with pass 2's own rows J a >= b, so
// that a held contact keeps J_k a = b_k; pass 2 then projects that under J as
// before (property 7 is the final projection's; here it changes nothing). The
// held rows alone, followed by pass 2, were not enough: on the textured Figure
// 8 cylinder the probe's tip (held) and a second vertex (not pressed by the
// texture's asc) lay on a facet; holding the tip moved the second vertex into
// its face, pass 2 pushed it back out and so lifted the tip by 4e-8 m a step,
// until the tip, which carried the whole force, left the contact band: the
// force jumped to the second vertex, half a texture wavelength away, by 30
// degrees. Without room for both (more than the set's capacity of rows) the held rows
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
  // a god-object held still against a facet (|ac| 1e-12, |au| 1e-2 in the
  // plain cylinder run) showed b - J ac = 4e-19 (the rounding of b = target -
  // separation itself) as a 3e-7 "violation".
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

// One CCD leg along the Cayley motion x0 -> x1, split in halves on a half turn
// (each half turns by at most 90 degrees), with s->ccd_hints[0 .. num_hints)
// tested first; s->ccd holds the result of the last call. When the leg can
// run, s->xs becomes the motion's own pose at u_hit (its end when no hit: the
// CCD's guarantee holds for it, up to make_stop_pose's deviation bound) and the
// function returns true; on invalid input or a half turn left after splitting,
// s->xs is left as it was and it returns false.
// Every leg is served from the legs' proximity cache (and may refill it), but
// only a step's first leg (first_leg; its first half when split) goes on with
// the cache's background fill: the fill's budget is per sim step, as the
// fill's plan counts it (proximity_cache.cpp, fill_cache_in_background).
// Spent by every leg, a settling step (first leg, settling leg) or a graze's
// lift filled twice or three times the budget, on the steps that already do
// the most work: in one profiled pass of the bunnies, 68 of the 549 steps over
// 0.1 ms of CPU ran a background fill in a later leg, 196 node pairs on
// average (docs/benchmarks.md, issue 20, fourth session).
// A settling leg (settling = true) searches its start in lead pieces
// (CcdStepSettings::lead_sweep, kSettleLeadSweep): it starts just off the
// surface it lifted from and stops again at u 0.0003-0.06 (the bunnies'
// replays, 5th-95th percentiles), while the swept boxes of its whole motion,
// a turn of 0.02-0.03 rad, meant 900-2,000 node pairs of descent in the full
// bunnies' slowest steps (docs/benchmarks.md, issue 20, seventh session).
bool ccd_leg(const RuntimeModel& model, const Pose& x0, const Pose& x1, int num_hints, SimState* s,
             int* num_halves, bool first_leg, bool settling = false) {
  const int num_obstacles = static_cast<int>(model.obstacles.size());
  const CcdBody* obstacles = model.obstacles.data();
  CcdStepResult& r = s->ccd;
  CcdStepSettings settings = model.settings.ccd;
  if (!first_leg) settings.cache.fill_budget = 0;
  if (settling) settings.lead_sweep = kSettleLeadSweep;
  ccd_step(obstacles, num_obstacles, model.god, x0, x1, settings, &s->ccd_ws, &r, s->ccd_hints.data(),
           num_hints);
  if (r.status == CcdStatus::kHalfTurn) {
    const Pose mid = split_step(x0, x1);
    *num_halves = 2;
    ccd_step(obstacles, num_obstacles, model.god, x0, mid, settings, &s->ccd_ws, &r, s->ccd_hints.data(),
             num_hints);
    settings.cache.fill_budget = 0;  // spent by the first half
    if (r.status != CcdStatus::kInvalidInput && r.status != CcdStatus::kHalfTurn && !r.hit)
      ccd_step(obstacles, num_obstacles, model.god, mid, x1, settings, &s->ccd_ws, &r);
  }
  s->near_is_proven = false;  // r's near pairs, if any, are ccd_ws's
  if (r.status == CcdStatus::kInvalidInput || r.status == CcdStatus::kHalfTurn) return false;
  const StopPose stop = make_stop_pose(r.motion, r.hit ? r.u_hit : 1.0, model.god_radius);
  s->xs = stop.pose;
  s->stop_deviation = stop.deviation;
  return true;
}

// Whether the CCD proves the Cayley motion x0 -> x1 free of contact with every
// obstacle (it never misses one: u_hit <= u*). Searched for contact itself
// (min_separation 0, so a motion that ends delta from a surface is not
// refused for reaching delta), without a proximity cache of its own (the legs'
// list serves it read-only when it covers the motion) or near pairs, in its
// own workspace (s->check_ws, s->check: the legs' state is left as it
// was). A hit, a give-up, invalid input or a half turn answer false.
// known_free: [0, known_free] of the motion is already proven free (proven_prefix):
// the search starts there, and a motion proven whole (1) needs none.
bool motion_free(const RuntimeModel& model, const Pose& x0, const Pose& x1, int num_hints, SimState* s,
                 double known_free = 0) {
  if (known_free >= 1) return true;
  CcdStepSettings settings = model.settings.ccd;
  settings.known_free = known_free;
  settings.narrow.min_separation = 0;
  settings.near_distance = 0;
  settings.cache.margin = settings.cache.margin_max = 0;
  settings.cache.fill_budget = 0;
  // Only whether it is free counts: the first hit found answers it. A refused
  // settle's check is stopped by a hint (a contact at x_start) at u 0.002-0.3,
  // and then descended the trees to confirm that no pair hits earlier (835-1,040
  // node pairs, 0.15-0.3 ms a try in the peg's heaviest steps: docs/benchmarks.md,
  // issue 20, fifth session); the answer was "not free" either way.
  settings.any_hit = true;
  // The legs' proximity list serves it read-only when the direct motion stays
  // within its margin (ccd_step.h, CcdStepWorkspace::borrowed): the same
  // candidates a descent would find, without descending the trees.
  s->check_ws.borrowed = &s->ccd_ws.cache;
  // And where it descends, it starts from the legs' last cut (DescentFront):
  // the direct motion sweeps the proximity they swept.
  s->check_ws.front.copy_from(s->ccd_ws.front);
  ccd_step(model.obstacles.data(), static_cast<int>(model.obstacles.size()), model.god, x0, x1, settings,
           &s->check_ws, &s->check, s->ccd_hints.data(), num_hints);
  return s->check.status == CcdStatus::kOk && !s->check.hit;
}

// How much of the motion a0 -> a1 a CCD leg already run, `leg` (from b0, in
// one piece; its exact motion keeps every pair at least min_separation apart up
// to ub: ccd.h), proves free of contact without a search of its own: the
// largest ua found for which no body point of a0 -> a1 on [0, ua] strays by as
// much as min_separation from where the leg puts it at the same pace
// (motion_distance_bound); 1 for the whole motion, 0 for none. A graze's lift
// is proven whole so: its leg starts a fraction of delta from x_start and the
// direct motion x_start -> end shares the leg's end. Searched instead, that
// direct motion descended the same 1,050-1,530 node pairs and tested the same
// sliding pairs as the lift's leg (0.25-0.65 ms of the peg's heaviest steps;
// 20 of the 25 lifts of the peg's replay and all 6 of the bunnies' are proven
// whole: docs/benchmarks.md, issue 20, fifth session). A settling step's
// direct motion x_start -> end leaves with its first leg and parts from it by
// the settling leg's travel at the end (2-4 delta in the peg's slowest step):
// its first part is proven, where the two motions are still within
// min_separation of each other, and only the rest is searched (motion_free's
// known_free). Both start at x_start, so the bound of their first parts grows
// about in proportion to ua: ua is taken at kPrefixShare of the share that
// proportion gives, then the bound is computed for it.
constexpr double kPrefixShare = 0.9;
double proven_prefix(const RuntimeModel& model, const Pose& a0, const Pose& a1, const Pose& b0,
                     const CcdStepResult& leg, double ub) {
  if (leg.status != CcdStatus::kOk) return 0;
  const double d = model.settings.ccd.narrow.min_separation;
  const double whole = motion_distance_bound(a0, a1, b0, leg.motion, ub, model.god_radius);
  if (whole < d) return 1;
  const double ua = kPrefixShare * d / whole;
  if (!(ua > 0 && ua < 1)) return 0;  // also NaN, an unbounded whole
  return motion_distance_bound(a0, a1, b0, leg.motion, ua * ub, model.god_radius, ua) < d ? ua : 0;
}

// A graze: the leg just run (s->ccd) was stopped by a pair of the last contact
// set (still s->contacts, at the leg's start) that had not come closer than where
// it started, by half the CCD's distance tolerance. The CCD may stop wherever a
// pair is within min_separation + distance_tolerance, and a contact the last
// step left in that band (delta to 1.1 delta) stops the next leg at once, even
// when the leg moves away from it: the god-object then crept by u_hit 1e-5 to
// 5e-3 of its leg a step (the gap rows, cut with the leg, lift the contact 2e-4
// delta a step), held behind the hand for 65 ms on the bunny (an edge/edge
// contact at 1.001 delta; released at 0.257 s by a 0.84 N drop) and 330 ms in
// the peg's hole (1.003 delta, at 11.6 s; 2.7 mJ of port energy when it broke free).
bool grazed(const RuntimeModel& model, const SimState& s) {
  const CcdStepResult& r = s.ccd;
  if (!r.hit || r.status != CcdStatus::kOk) return false;
  const int m = std::min(s.contacts.num_contacts, s.capacity);
  for (int k = 0; k < m; ++k) {
    const Contact& c = s.contacts.contacts[k];
    if (c.features == r.pair)
      return r.distance_reached >= c.separation - 0.5 * model.settings.ccd.narrow.distance_tolerance;
  }
  return false;
}

// Back to a leg run earlier, its stop pose, CCD result and deviation saved
// before a later leg ran. The legs share one workspace (s->ccd_ws), so the
// later leg overwrote the candidates that the saved result's near pairs index:
// the restored result has none, and a contact search at xs is a full one.
void restore_leg(const Pose& xs, const CcdStepResult& leg, double deviation, SimState* s) {
  s->xs = xs;
  s->ccd = leg;
  s->ccd.num_near_pairs = -1;
  s->near_is_proven = false;
  s->stop_deviation = deviation;
}

// Out of a graze: the leg again, from x_lift = x_start (+) a_lift, a_lift the
// M-smallest motion that lifts every contact of the set to delta (1 +
// gap_factor) to first order (the gap rows alone: a fraction of delta), out of
// the CCD's band; its end is kept only when the direct motion x_start -> end is
// proven free of contact (the published motion, property 5): by the lift's leg
// itself when the two motions stay within min_separation of each other
// (proven_prefix), by the CCD otherwise. x_lift is a
// waypoint, never published; every pose of the second leg keeps the CCD's
// min_separation. Returns false, with s->xs, s->ccd and s->stop_deviation as the
// grazed leg left them, when the gap rows conflict or either CCD refuses.
bool lift_out_of_graze(const RuntimeModel& model, const Pose& x_start, const Pose& target, int num_hints,
                       SimState* s, int* num_halves) {
  const int m = std::min(s->contacts.num_contacts, s->capacity);
  const double gap = model.contact.delta * (1 + model.settings.gap_factor);
  for (int k = 0; k < m; ++k) s->gap_rhs[k] = gap - s->contacts.contacts[k].separation;
  ProjectionProblem problem;
  problem.M = &s->M;
  problem.J = s->contacts.J.data();
  problem.b = s->gap_rhs.data();
  problem.num_rows = m;
  project(problem, model.settings.projection, &s->shading_ws, &s->shading);
  if (s->shading.status != ProjectionStatus::kOptimal || !s->shading.ac.allFinite()) return false;
  const Pose grazed_xs = s->xs;
  const CcdStepResult grazed_leg = s->ccd;  // to restore on a refusal (plain data: no allocation)
  const double grazed_deviation = s->stop_deviation;
  int halves = 1;
  const Pose x_lift = pose_update(x_start, s->shading.ac);
  if (ccd_leg(model, x_lift, target, num_hints, s, &halves, /*first_leg=*/false)) {
    const double known =
        halves == 1 ? proven_prefix(model, x_start, s->xs, x_lift, s->ccd, s->ccd.hit ? s->ccd.u_hit : 1.0) : 0;
    if (motion_free(model, x_start, s->xs, num_hints, s, known)) {
      *num_halves = std::max(*num_halves, halves);
      return true;
    }
  }
  restore_leg(grazed_xs, grazed_leg, grazed_deviation, s);
  return false;
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
  const double slack = round_up(s->stop_deviation + kPoseRounding * (s->xs.p.cwiseAbs().maxCoeff() + model.god_radius)).v;
  const bool near = r.num_near_pairs >= 0 && (r.hit ? r.u_hit : 1.0) >= r.near_u0 && cs.distance + slack <= r.near_reach;
  const NearPairs list = !near                ? NearPairs{}
                         : s->near_is_proven ? NearPairs{s->proven_near.data(), r.num_near_pairs}
                                             : s->ccd_ws.near_pairs(r.num_near_pairs);
  const ContactStatus status = generate_contacts(model.obstacles.data(), static_cast<int>(model.obstacles.size()),
                                                 model.god, s->xs, cs, &s->contact_ws, &s->contacts, list);
  if (status == ContactStatus::kInvalidInput) s->contacts.num_contacts = 0;
  if (status == ContactStatus::kOverflow || status == ContactStatus::kStackFull)
    s->step_events |= bit(RuntimeEventKind::kContactOverflow);
}

// A settling step's first leg's near pairs, kept in s->proven_near before the
// settling leg reuses s->ccd_ws (its candidates hold them): the poses later
// served from that leg take their contacts from them (serve_proven_leg). Called
// in the try that ran that leg, so s->ccd's near pairs (if any) are ccd_ws's.
void keep_proven_near(SimState* s) {
  const int n = s->ccd.num_near_pairs;
  s->num_proven_near = n >= 0 && n <= static_cast<int>(s->proven_near.size()) ? n : -1;
  const NearPairs list = s->ccd_ws.near_pairs(s->num_proven_near);
  for (int k = 0; k < s->num_proven_near; ++k) s->proven_near[k] = list[k];
}

// The pose at u of a leg whose whole motion its CCD result `proven` showed free
// at delta: the stop pose there (the same deviation bound as a hit's), with that
// result as s->ccd, without searching again. Its near pairs, kept by
// keep_proven_near, hold at every u in [near_u0, u_hit] of its motion
// (CcdStepResult::num_near_pairs), so the contact search there tests them.
// In a refused settle's shortened tries they were most of the step's contact
// searches, each a full descent (41-54 us each in the full bunnies' slowest
// steps, 3 or 4 a step: docs/benchmarks.md, issue 20, eighth session).
void serve_proven_leg(const RuntimeModel& model, const CcdStepResult& proven, double u, SimState* s) {
  s->ccd = proven;
  s->near_is_proven = s->num_proven_near >= 0 && u >= proven.near_u0 && u <= (proven.hit ? proven.u_hit : 1.0);
  s->ccd.num_near_pairs = s->near_is_proven ? s->num_proven_near : -1;
  const StopPose stop = make_stop_pose(proven.motion, u, model.god_radius);
  s->xs = stop.pose;
  s->stop_deviation = stop.deviation;
}

// The god-object stays at x_start this step, with the contact set there (the
// last step's pairs, which withheld part of the command). Staying put is always
// a free motion (property 5); the hand's next sample gives the next step another
// leg. keep_a_contact's last resort.
void stay_at_start(const RuntimeModel& model, const Pose& x_start, SimState* s, SimStepInfo* info) {
  s->xs = x_start;
  s->stop_deviation = 0;
  s->ccd.hit = false;
  s->ccd.num_near_pairs = -1;  // the near pairs are the legs', not x_start's: a full search
  s->near_is_proven = false;
  update_contacts(model, s);
  info->u_hit = 0;
  info->status = s->contacts.num_contacts > 0 ? SimStepStatus::kContact : SimStepStatus::kFree;
}

// Every settle refused, the shortenings spent and the first leg's end still out
// of contact: its motion's pose at u / 2, u / 4, ... (served from the leg's proven
// CCD result, no settling) until the pose keeps a contact, at most
// kMaxKeepHalvings times; x_start itself (stay_at_start) when none does or the
// leg cannot be served (split, or run from a graze's lift waypoint). The first
// leg's end, kept before, had lifted off every contact that held the user's
// push: in the peg's hole at 11.473 s of the whole script (a wedge of 2-6 edge
// contacts) the ends at 1/2 to 1/8 of a 160 um slide were all beyond
// delta (1 + contact_factor) of them, so that one step published an empty set
// while the hand was 3 mm behind: the force fell from 1.47 N to 0 for one tick
// and came back at once (1.47 and 1.38 N jumps). Staying at x_start alone
// instead stalled the god-object there (167 ticks from 11.472 s, then a 1.15 N
// release): each step repeated the same refusals.
void keep_a_contact(const RuntimeModel& model, const Pose& x_start, bool served, double u, SimState* s,
                    SimStepInfo* info) {
  if (served) {
    const CcdStepResult proven = s->ccd;  // the first leg, free: its end was refused
    for (int i = 0; i < kMaxKeepHalvings && s->contacts.num_contacts == 0; ++i) {
      u *= 0.5;
      serve_proven_leg(model, proven, u, s);
      update_contacts(model, s);
    }
    if (s->contacts.num_contacts > 0) return;
  }
  stay_at_start(model, x_start, s, info);
}

}  // namespace

// Step 4: CCD along x_start -> x_target, then xs = its end or the stop pose and
// the contact set at xs; then, when that leg ended free and out of contact while
// the previous contacts withheld part of the command, the settling leg by the
// withheld part, whose end is kept only when the direct motion x_start -> end is
// free of contact, the first leg shortened otherwise (sim_loop.h).
void advance_god_object(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual,
                        SimState* s, SimStepInfo* info) noexcept {
  info->x_start = x_start;
  info->x_target = x_target;
  info->residual = residual;
  info->settled = false;
  info->num_shortenings = 0;
  info->num_halves = 1;
  s->num_proven_near = -1;
  // The descents' cuts serve this update's legs and pieces (DescentFront):
  // a cut only refines, so none outlives the update that made it.
  s->ccd_ws.front.clear();
  s->check_ws.front.clear();
  // The contacts at x_start (the set of the last step, at s->xs) are the pairs
  // most likely to stop either leg: ccd_step tests them first.
  const int num_hints = std::min(s->contacts.num_contacts, s->capacity);
  for (int k = 0; k < num_hints; ++k) s->ccd_hints[k] = s->contacts.contacts[k].features;
  Pose target = x_target;
  // After a refused settle the first leg is shortened to its own motion's pose
  // at u = 1/2 (then 1/4, 1/8): the first part of a path its CCD has just
  // proven free at delta, so the shortened leg is served from that result (the
  // stop pose at u, as for a hit there) instead of being searched again.
  double shortened_u = 1;
  CcdStepResult proven;  // the whole first leg, free (set when shortened_u < 1)
  for (;;) {
    s->xs = x_start;
    bool moved = true;
    bool lifted = false;  // this try's first leg ran from a graze's lift waypoint
    if (shortened_u < 1) {
      serve_proven_leg(model, proven, shortened_u, s);
    } else {
      moved = ccd_leg(model, x_start, target, num_hints, s, &info->num_halves, info->num_shortenings == 0);
      if (moved && info->num_shortenings == 0 && grazed(model, *s))
        lifted = lift_out_of_graze(model, x_start, target, num_hints, s, &info->num_halves);
    }
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
    if (!(lifted_off && residual.allFinite() && residual != Vec6::Zero())) break;
    info->settled = true;
    const Pose from = s->xs;
    const CcdStepResult first_leg = s->ccd;  // to restore on a refusal (plain data: no allocation)
    if (shortened_u == 1) keep_proven_near(s);  // the leg later tries serve (proven = first_leg)
    const double first_deviation = s->stop_deviation;
    int halves = 1;
    const bool settled = ccd_leg(model, from, pose_update(from, residual), num_hints, s, &halves,
                                 /*first_leg=*/false, /*settling=*/true);
    if (info->ccd == CcdStatus::kOk) info->ccd = s->ccd.status;
    info->u_hit = s->ccd.u_hit;
    if (!settled) break;  // s->xs is still the first leg's end
    // Each leg is free of contact, but the step publishes only its end: the
    // motion between two published poses is the direct one, x_start -> end,
    // which can cut through the crease the two legs went round (property 5,
    // METHOD.md s.5). The end is kept only when the CCD proves that motion free,
    // from where the first leg no longer proves it (proven_prefix: the first
    // leg, one piece from x_start, free on [0, shortened_u] of its motion).
    const double known =
        info->num_halves == 1 && !lifted ? proven_prefix(model, x_start, s->xs, x_start, first_leg, shortened_u) : 0;
    if (motion_free(model, x_start, s->xs, num_hints, s, known)) {
      if (s->ccd.hit) info->status = SimStepStatus::kContact;
      update_contacts(model, s);
      break;
    }
    // Refused: back to the first leg's end (free; its contact set, empty, is
    // still s->contacts) and, while shortenings are left, the whole step again
    // with the first leg halved (its motion's pose at half the parameter, or
    // split_step's when the leg was split at a half turn: half the travel,
    // half the rotation): a shorter slide sags less under the crease, and one
    // that stays in the contact band needs no settling.
    restore_leg(from, first_leg, first_deviation, s);
    info->u_hit = first_leg.u_hit;
    if (info->num_shortenings == kMaxSettleShortenings) {
      keep_a_contact(model, x_start, info->num_halves == 1 && !lifted, shortened_u, s, info);
      break;
    }
    ++info->num_shortenings;
    // A leg run from a graze's lift waypoint is not a part of x_start -> target:
    // its parts are not served, the step is split instead.
    if (info->num_halves == 1 && !lifted) {  // one leg, x_start -> x_target, proven free: serve its parts
      if (shortened_u == 1) proven = first_leg;
      shortened_u *= 0.5;
    } else {
      target = split_step(x_start, target);
    }
  }
  s->M = mass_matrix_at(model, s->xs.q);
  info->num_contacts = s->contacts.num_contacts;
}

namespace {

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

// Step 4: xt = xs (+) ac; CCD; xs = xt or the stop pose; the new contact set
// (and the settling leg by au - ac if the previous contacts' surface fell away).
// The residual is what the contacts withheld from the user's command au, both
// passes together, not asc - ac: on a shaded facet the shading normal leans
// against the motion on one side of each vertex, asc then leans off the facet
// (J asc > 0: pass 2 withholds nothing, asc - ac = 0) and the god-object lifted
// off with nothing to settle it, so the contact set emptied and the force
// dropped to zero for one step, every other step (716 of 2950 ticks of the
// Figure 8 slide). au - ac still presses the god-object back onto the surface
// it left, by the CCD, so property 7 and the contact hold. Plain surfaces
// (asc = au) are unchanged, bit for bit.
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
    advance_by(model, s, &info);                 // 4. CCD from xs towards xs (+) ac; the new contacts;
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
