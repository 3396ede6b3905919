// Step 4 of the sim step (sim_step4.h; its rules and their reasons:
// docs/sim-step.md): the first leg, the detour rule (a graze's lift, a
// settling leg), the halving schedule, and the contact set at the end.
#include "gauss6/runtime/sim_step4.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gauss6/ccd/ccd.h"
#include "gauss6/ccd/motion.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/numeric/rounding.h"

namespace gauss6 {

GodObjectStep::GodObjectStep(const RuntimeModel& model)
    : // The proximity cache keyed by every obstacle of the model (allocated here, not in a step).
      legs_ws(CcdStepWorkspace::kBoxCapacity, CcdStepWorkspace::kStackCapacity, CcdStepWorkspace::kCandidateCapacity,
              std::max(static_cast<int>(model.obstacles.size()), CcdStepWorkspace::kObstacleCapacity)),
      hints(static_cast<size_t>(model.settings.max_contacts)),
      proven_near(legs_ws.candidates.size()),
      contact_ws(model.god_mesh_B),
      lift_b(static_cast<size_t>(model.settings.max_contacts)),
      lift_ws(model.settings.max_contacts),
      lift(model.settings.max_contacts) {
  // The legs of one update share their descents' cuts (cleared at each update).
  legs_ws.front.carry = true;
  check_ws.front.carry = true;
  // The checks borrow the legs' proximity list and start from their last cut.
  check_ws.lender = &legs_ws;
  // Every CCD of an update charges its budget, when it has one.
  legs_ws.budget = check_ws.budget = model.settings.budget.active() ? &budget : nullptr;
}

Pose split_step(const Pose& x0, const Pose& x1) {
  // The bisector of the two unit quaternions, b taken on a's side (q and -q are
  // the same rotation): the rotation halfway along the shortest way, which turns
  // each half by half the relative angle. |a + b| >= sqrt(2), so the sum
  // normalises without loss; a valid pose's components (is_valid_pose) keep the
  // squares of a and b finite and non-zero.
  using Vec4 = Eigen::Vector4d;
  const Vec4 a = Vec4(x0.q.w, x0.q.x, x0.q.y, x0.q.z).normalized();
  const Vec4 b = Vec4(x1.q.w, x1.q.x, x1.q.y, x1.q.z).normalized();
  const Vec4 mid = (a.dot(b) < 0 ? Vec4(a - b) : Vec4(a + b)).normalized();
  return {0.5 * (x0.p + x1.p), Quat{mid[0], mid[1], mid[2], mid[3]}};
}

namespace {

// The leg stands at leg->u of its motion: the stop pose there, and how far a
// body point posed in doubles at it may lie from where the exact motion puts
// it (the stop pose's deviation, and the rounding of posing: kPoseRounding).
void stand_at(const RuntimeModel& model, LegEnd* leg) {
  const StopPose stop = make_stop_pose(leg->ccd.motion, leg->u, model.god_radius);
  leg->xs = stop.pose;
  leg->posing_error =
      round_up(stop.deviation + kPoseRounding * (leg->xs.p.cwiseAbs().maxCoeff() + model.god_radius)).v;
}

// The leg stands at its start, with no motion: no near pairs to serve.
void stand_at_start(const Pose& x0, LegEnd* leg) {
  leg->u = 0;
  leg->xs = x0;
  leg->posing_error = std::numeric_limits<double>::infinity();
  leg->near = NearPairs{};
}

// Every CCD of the step: the model's bodies and settings, the request's motion and question.
void run_ccd(const RuntimeModel& model, const CcdStepRequest& request, CcdStepWorkspace* ws, CcdStepResult* result) {
  const int num_obstacles = static_cast<int>(model.obstacles.size());
  ccd_step(model.obstacles.data(), num_obstacles, model.god, request, model.settings.ccd, ws, result);
}

// One CCD leg along the Cayley motion x0 -> x1, split in halves on a half turn
// (each half turns by at most 90 degrees): g->leg becomes its end, the
// motion's own pose at u_hit (at 1 when no hit). False on invalid input or a
// half turn left after splitting (g->leg then stands at x0 with that result).
// Only a step's first leg (fill) goes on with the proximity cache's background
// fill: the fill's budget is per sim step. A settling leg searches its start
// in lead pieces (kSettleLeadSweep).
bool ccd_leg(const RuntimeModel& model, const Pose& x0, const Pose& x1, bool fill, bool settling, GodObjectStep* g,
             int* num_halves) {
  LegEnd& leg = g->leg;
  CcdStepResult& r = leg.ccd;
  CcdStepRequest request{x0, x1, g->hints.data(), g->num_hints};
  request.fill_cache = fill;
  // A settling leg, or any leg after an update that ran out of its budget (its
  // command grew while the god-object lagged: proven piece by piece from the
  // start, each cheap, the update goes as far as its budget proves).
  request.lead_sweep = settling || g->budget_ran_out ? kSettleLeadSweep : 0.0;
  leg.from = x0;
  leg.one_piece = true;
  // Run 0: the whole motion; on a half turn, run 1 its first half, and run 2
  // its second half when the first ends free.
  Pose mid;
  bool moved = false;
  for (int run = 0;; ++run) {
    run_ccd(model, request, &g->legs_ws, &r);
    moved = r.status != CcdStatus::kInvalidInput && r.status != CcdStatus::kHalfTurn;
    if (run == 0 && r.status == CcdStatus::kHalfTurn) {
      *num_halves = 2;
      leg.one_piece = false;
      mid = split_step(x0, x1);
      request.X1 = mid;
    } else if (run == 1 && moved && !r.hit) {
      request = {mid, x1};  // no hints (searched over the first half), the fill spent by the first
      request.fill_cache = false;
      request.lead_sweep = settling ? kSettleLeadSweep : 0.0;
    } else {
      break;
    }
  }
  if (!moved) {
    stand_at_start(x0, &leg);
    return false;
  }
  leg.near = g->legs_ws.near_pairs(r.num_near_pairs);
  leg.u = r.hit ? r.u_hit : 1.0;
  stand_at(model, &leg);
  return true;
}

// The leg is the first leg from x_start, whole: its parts are parts of the
// step's motion, served by the halving schedule.
bool servable(const LegEnd& leg, const Pose& x_start) {
  const Quat &q = leg.from.q, &q0 = x_start.q;
  return leg.one_piece && leg.from.p == x_start.p && q.w == q0.w && q.x == q0.x && q.y == q0.y && q.z == q0.z;
}

// The proven leg: the first leg, kept with its near pairs (copied: later legs
// reuse legs_ws) when a settle is about to run from its end.
void keep_proven(GodObjectStep* g) {
  g->proven = g->leg;
  const NearPairs& list = g->leg.near;
  const int n = list.listed() && list.num_pairs <= static_cast<int>(g->proven_near.size()) ? list.num_pairs : -1;
  for (int k = 0; k < n; ++k) g->proven_near[k] = list[k];
  g->proven.near = {g->proven_near.data(), n};
}

// The proven leg's pose at u, without searching again: the stop pose there
// (the same deviation bound as a hit's), its near pairs when they hold at u
// (CcdStepResult::num_near_pairs: on [near_u0, u_hit]).
void serve_proven(const RuntimeModel& model, double u, GodObjectStep* g) {
  LegEnd& leg = g->leg;
  leg = g->proven;
  if (!(u >= leg.ccd.near_u0 && u <= (leg.ccd.hit ? leg.ccd.u_hit : 1.0))) leg.near = NearPairs{};
  leg.u = u;
  stand_at(model, &leg);
}

// Whether the CCD proves the Cayley motion x0 -> x1 free of contact (it never
// misses one: u_hit <= u*), past the prefix the leg `ref` proves free (where
// the two motions stay within min_separation of each other: proven_prefix,
// motion.h; a motion proven whole needs no search). Its own workspace, lent
// the legs' list and last cut (the direct motion sweeps the proximity they
// swept). A hit, a give-up, invalid input or a half turn answer false.
bool motion_free(const RuntimeModel& model, const Pose& x0, const Pose& x1, const LegEnd& ref, GodObjectStep* g) {
  CcdStepRequest request{x0, x1, g->hints.data(), g->num_hints};
  if (ref.one_piece && ref.ccd.status == CcdStatus::kOk) request.proven = {ref.from, &ref.ccd.motion, ref.u};
  request.question = CcdQuestion::kFreeOfContact;
  const long before = g->budget.used();
  run_ccd(model, request, &g->check_ws, &g->check);
  g->paths.check_units += g->budget.used() - before;
  return g->check.status == CcdStatus::kOk && !g->check.hit;
}

// The detour rule: explore the leg from -> to, a waypoint off the step's
// direct motion, and keep its end only when the direct motion x_start -> end
// is proven free (property 5 holds between displayed poses, never through a
// waypoint): by the reference leg where the two motions stay within
// min_separation of each other (proven_prefix: the detour's own leg for a
// graze's lift, the first leg for a settle), by the CCD past that. Otherwise
// the god-object is back where it stood (that leg's near pairs lost with
// legs_ws). A detour leg stopped at its start (u = 0) ends at its waypoint,
// whose separation no CCD proved (a graze's lift pose, lifted to first order
// off the set's rows only, may lie nearer than delta to a pair the set left
// out): refused. *halves: the detour leg's halves.
enum class Detour { kKept, kRefused, kNotRun };
struct DetourResult {
  Detour outcome;
  CcdStatus status;  // the detour leg's CCD (SimStepInfo::ccd, u_hit)
  double u_hit;
};
DetourResult take_detour(const RuntimeModel& model, const Pose& x_start, const Pose& from, const Pose& to,
                         bool settling, GodObjectStep* g, int* halves) {
  const LegEnd back = g->leg;  // plain data: no allocation
  *halves = 1;
  const bool ran = ccd_leg(model, from, to, /*fill=*/false, settling, g, halves);
  const LegEnd& ref = settling ? back : g->leg;
  if (ran && g->leg.u > 0 && motion_free(model, x_start, g->leg.xs, ref, g))
    return {Detour::kKept, g->leg.ccd.status, g->leg.ccd.u_hit};
  const DetourResult result{ran ? Detour::kRefused : Detour::kNotRun, g->leg.ccd.status, g->leg.ccd.u_hit};
  g->leg = back;
  g->leg.near = NearPairs{};
  return result;
}

// A graze: the leg just run, from a pose in contact, was stopped by a pair
// that had not come closer than where it started, by half the CCD's distance
// tolerance. The CCD may stop wherever a pair is within min_separation +
// distance_tolerance, so a contact the last step left in that band stops the
// next leg at once even when it moves away from it. A leg stopped at its
// start (u_hit = 0) came no closer to any pair, whichever stopped it: one the
// set holds, or one it leaves out (an edge/edge pair beside the vertex/face
// rows that span it, or one the set's reduction dropped).
bool grazed(const RuntimeModel& model, const ContactSet& contacts, const GodObjectStep& g) {
  const CcdStepResult& r = g.leg.ccd;
  if (!r.hit || r.status != CcdStatus::kOk) return false;
  const int m = std::min(contacts.num_contacts, contacts.capacity());
  if (m > 0 && r.u_hit == 0) return true;
  for (int k = 0; k < m; ++k) {
    const Contact& c = contacts.contacts[k];
    if (c.features == r.pair)
      return r.distance_reached >= c.separation - 0.5 * model.settings.ccd.narrow.distance_tolerance;
  }
  return false;
}

// Out of a graze, a detour: the leg again from x_lift = x_start (+) a_lift,
// a_lift the M-smallest motion that lifts every contact of the set to delta (1 +
// gap_factor) to first order (out of the CCD's band). False when the gap rows
// conflict or the detour is not kept.
bool lift_out_of_graze(const RuntimeModel& model, const Pose& x_start, const Pose& target, const Mat6& M,
                       const ContactSet& contacts, GodObjectStep* g, int* num_halves) {
  const int m = std::min(contacts.num_contacts, contacts.capacity());
  const double gap = model.contact.delta * (1 + model.settings.gap_factor);
  for (int k = 0; k < m; ++k) g->lift_b[k] = gap - contacts.contacts[k].separation;
  ProjectionProblem problem;
  problem.M = &M;
  problem.J = contacts.J.data();
  problem.b = g->lift_b.data();
  problem.num_rows = m;
  project(problem, model.settings.projection, &g->lift_ws, &g->lift);
  if (g->lift.status != ProjectionStatus::kOptimal || !g->lift.ac.allFinite()) return false;
  int halves = 1;
  const Pose x_lift = pose_update(x_start, g->lift.ac);
  if (take_detour(model, x_start, x_lift, target, /*settling=*/false, g, &halves).outcome != Detour::kKept)
    return false;
  *num_halves = std::max(*num_halves, halves);
  return true;
}

// The contact set at the leg's end: every pair within delta (1 +
// contact_factor), and at least the pair that stopped the leg. The leg's near
// pairs hold every pair within its near reach there, less how far a vertex
// posed at xs may lie from the motion's (LegEnd::posing_error): when the
// contact distance is within that, they are the only pairs to test. Sets the
// overflow event.
void update_contacts(const RuntimeModel& model, GodObjectStep* g, ContactSet* contacts) {
  const LegEnd& leg = g->leg;
  const CcdStepResult& r = leg.ccd;
  ContactSettings cs = model.contact_generation;
  if (r.hit && std::isfinite(r.distance_reached))
    cs.distance = std::max(cs.distance, r.distance_reached + model.contact.delta * model.settings.contact_factor);
  const bool near =
      leg.near.listed() && (r.hit ? r.u_hit : 1.0) >= r.near_u0 && cs.distance + leg.posing_error <= r.near_reach;
  const ContactStatus status = generate_contacts(model.obstacles.data(), static_cast<int>(model.obstacles.size()),
                                                 model.god, leg.xs, cs, &g->contact_ws, contacts,
                                                 near ? leg.near : NearPairs{});
  if (status == ContactStatus::kInvalidInput) contacts->num_contacts = 0;
  if (status == ContactStatus::kOverflow || status == ContactStatus::kStackFull)
    g->events |= event_bit(RuntimeEventKind::kContactOverflow);
}

// The god-object stays at x_start this step, with the contact set there.
// Staying put is always a free motion (property 5); the hand's next sample
// gives the next step another leg.
void stay_at_start(const RuntimeModel& model, const Pose& x_start, GodObjectStep* g, ContactSet* contacts,
                   SimStepInfo* info) {
  LegEnd& leg = g->leg;
  stand_at_start(x_start, &leg);  // the near pairs are the legs', not x_start's: a full search
  leg.ccd.hit = false;
  update_contacts(model, g, contacts);
  g->paths.stayed = true;
  info->u_hit = 0;
  info->status = contacts->num_contacts > 0 ? SimStepStatus::kContact : SimStepStatus::kFree;
}

// Try k's first leg: the proven leg's pose at u < 1 (a halving), or a CCD
// leg x_start -> target, out of a graze on the first try. Sets info's ccd,
// u_hit and status for the try; false when the leg could not run.
bool first_leg(const RuntimeModel& model, const Pose& x_start, const Pose& target, int k, double u, const Mat6& M,
               const ContactSet& contacts, GodObjectStep* g, SimStepInfo* info) {
  bool moved = true;
  if (u < 1) {
    serve_proven(model, u, g);
  } else {
    const long before = g->budget.used();
    moved = ccd_leg(model, x_start, target, /*fill=*/k == 0, /*settling=*/false, g, &info->num_halves);
    g->paths.first_leg_units += g->budget.used() - before;
    if (moved && k == 0 && !g->budget.exhausted() && grazed(model, contacts, *g)) {
      g->paths.grazed = true;
      g->paths.lifted = lift_out_of_graze(model, x_start, target, M, contacts, g, &info->num_halves);
    }
  }
  info->ccd = g->leg.ccd.status;
  info->u_hit = g->leg.ccd.u_hit;
  info->status = !moved ? SimStepStatus::kInvalidStep : (g->leg.ccd.hit ? SimStepStatus::kContact : SimStepStatus::kFree);
  return moved;
}

// The settling leg's detour from the first leg's end by `residual`. True when
// the step is done (its end kept, or the leg could not run: the first leg's
// end stands); false when refused.
bool settle(const RuntimeModel& model, const Pose& x_start, const Vec6& residual, GodObjectStep* g_in,
            ContactSet* contacts, SimStepInfo* info) {
  GodObjectStep& g = *g_in;
  info->settled = true;
  ++g.paths.settles;
  int halves = 1;
  const DetourResult d =
      take_detour(model, x_start, g.leg.xs, pose_update(g.leg.xs, residual), /*settling=*/true, &g, &halves);
  if (info->ccd == CcdStatus::kOk) info->ccd = d.status;
  if (d.outcome == Detour::kRefused) {
    ++g.paths.refused;
    return false;
  }
  info->u_hit = d.u_hit;
  if (d.outcome == Detour::kKept) {
    if (g.leg.ccd.hit) info->status = SimStepStatus::kContact;
    update_contacts(model, &g, contacts);
  }
  return true;
}

// Budgeted updates (docs/sim-step.md): once the budget ran out, every later CCD
// of the update stops at once (a detour is then refused, a check not free)
// and the schedule ends at the leg it stands on: the first leg's stop pose at
// the end of what its CCD proved free (or the first leg's end, after a
// refused settle), the contact set already taken there. A stop on the budget
// is no contact: the step is kContact only when that set is not empty. The
// update's work; what of the command it left is the sim loop's to measure
// (SimStepInfo::budget_deferred).
void end_on_budget(const ContactSet& contacts, GodObjectStep* g, SimStepInfo* info) {
  info->work_units = g->budget.used();
  info->budget_exhausted = false;
  info->budget_deferred = 0;
  g->budget_ran_out = g->budget.exhausted();
  if (!g->budget.exhausted()) return;
  info->budget_exhausted = true;
  if (g->leg.ccd.budget_exhausted)
    info->status = contacts.num_contacts > 0 ? SimStepStatus::kContact : SimStepStatus::kFree;
  g->events |= event_bit(RuntimeEventKind::kUpdateBudgetExhausted);
}

}  // namespace

void advance_god_object(const RuntimeModel& model, const Pose& x_start, const Pose& x_target, const Vec6& residual,
                        const Mat6& M, ContactSet* contacts, GodObjectStep* g_in, SimStepInfo* info) noexcept {
  GodObjectStep& g = *g_in;
  info->x_start = x_start;
  info->x_target = x_target;
  info->residual = residual;
  info->settled = false;
  info->num_shortenings = 0;
  info->num_halves = 1;
  g.paths = StepPaths{};
  g.events = 0;
  g.budget.start(model.settings.budget);
  // The descents' cuts serve this update's legs (DescentFront): a cut only
  // refines, so none outlives the update that made it.
  g.legs_ws.front.clear();
  g.check_ws.front.clear();
  // The contacts at x_start (the last step's set) are the pairs most likely to
  // stop any leg: every CCD of the step tests them first.
  g.num_hints = std::min(contacts->num_contacts, contacts->capacity());
  for (int k = 0; k < g.num_hints; ++k) g.hints[k] = contacts->contacts[k].features;
  const bool settling = residual.allFinite() && residual != Vec6::Zero();
  // The halving schedule: try k's first leg ends at u = 2^-k of the proven
  // leg (u = 1: the leg is run), or, when the first leg cannot be served (split,
  // or run from a graze's lift), runs to a target split in halves k times.
  Pose target = x_target;
  double u = 1;
  for (int k = 0;; ++k) {
    if (k <= kMaxSettleShortenings) {  // the first leg of a try, then its settle
      info->num_shortenings = k;
      const bool moved = first_leg(model, x_start, target, k, u, M, *contacts, &g, info);
      update_contacts(model, &g, contacts);
      if (g.budget.exhausted()) break;  // the first leg's proven end (end_on_budget)
      // Settling leg: the linearised constraints J a >= 0 hold to first order
      // only, so a motion along a contact's tangent plane lifts off a surface
      // that curves or creases away under it: the god-object moves on by what
      // the previous contacts withheld, from where it ended.
      const bool lifted_off = moved && !g.leg.ccd.hit && contacts->num_contacts == 0;
      if (!(lifted_off && settling)) break;
      if (u == 1 && servable(g.leg, x_start)) keep_proven(&g);
      if (settle(model, x_start, residual, &g, contacts, info)) break;
      if (g.budget.exhausted()) break;  // the refused settle: back at the first leg's end, its contacts
      info->u_hit = g.leg.ccd.u_hit;  // back at the first leg's end
      if (k == kMaxSettleShortenings && !servable(g.leg, x_start)) {
        stay_at_start(model, x_start, &g, contacts, info);
        break;
      }
    } else {  // halved on without settling, until the end keeps a contact
      ++g.paths.keep_halvings;
      serve_proven(model, u, &g);
      update_contacts(model, &g, contacts);
      if (contacts->num_contacts > 0) break;
      if (k == kMaxSettleShortenings + kMaxKeepHalvings) {
        stay_at_start(model, x_start, &g, contacts, info);
        break;
      }
    }
    // Halve the first leg: a shorter slide sags less under the crease, and one
    // that stays in the contact band needs no settling.
    if (servable(g.leg, x_start))
      u *= 0.5;
    else
      target = split_step(x_start, target);
  }
  info->xs = g.leg.xs;
  info->num_contacts = contacts->num_contacts;
  g.paths.detour_units = g.budget.used() - g.paths.first_leg_units - g.paths.check_units;
  end_on_budget(*contacts, &g, info);
}

}  // namespace gauss6
