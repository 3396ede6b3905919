// The mesh-level CCD step (ccd_step.h) as the pipeline it runs: validate the
// input, plan the sub-intervals, search the hinted pairs, serve or refill the
// proximity cache (proximity_stages.cpp), descend the trees per sub-interval of
// the motion, test the candidate triangle pairs (a time bound for each, then
// for each of its owned feature pairs, and the narrow-phase tests of the rest,
// earliest first, earliest hit kept), and finish the result.
#include "gauss6/step/ccd_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ccd_step_state.h"
#include "gauss6/geometry/distance.h"

namespace gauss6 {

namespace detail {

namespace {

// Every pointer the step reads is set, the settings are usable, and the
// god-object's radius (about G) is within kMaxCoordinate: with the poses'
// positions within it too (make_ccd_motion), every posed corner's offset from
// G stays below 2^103, which the turn's allowance at triangle_time_lower_bound
// assumes (proofs/AxisAllowances.v axis_turn_rounding: r_inf <= 2^400).
bool inputs_valid(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const CcdStepSettings& settings,
                  const CcdStepWorkspace* ws) {
  bool ok = god.mesh && god.bvh && ws && (num_obstacles == 0 || obstacles) && !ccd_step_settings_problem(settings) &&
            god.bvh->radius <= kMaxCoordinate;  // false on NaN
  for (int o = 0; ok && o < num_obstacles; ++o) ok = obstacles[o].mesh && obstacles[o].bvh;
  return ok;
}

// Sub-intervals: enough that each turns by at most sub_interval_angle and moves
// G by at most sub_interval_travel radii, so the swept boxes stay tight.
int plan_sub_intervals(const CcdMotion& motion, const CcdBody& god, const CcdStepSettings& settings) {
  const double angle = motion_angle(motion.nominal, 1.0);
  const double travel = motion.nominal.dp.norm() / std::max(god.bvh->radius, 1e-300);
  const double want = std::max(angle / settings.sub_interval_angle, travel / settings.sub_interval_travel);
  return static_cast<int>(std::clamp(std::ceil(want), 1.0, static_cast<double>(settings.max_sub_intervals)));
}

// How far a point of the god-object moves over the step, nominally (doubles,
// a heuristic): |dp| + angle radius.
double nominal_travel(const CcdMotion& motion, const CcdBody& god) {
  return motion.nominal.dp.norm() + motion_angle(motion.nominal, 1.0) * god.bvh->radius;
}

// The time tolerance the step searches with: the settings', lowered so that
// the back-off it allows (a hit is reported up to time_tolerance before the
// contact, and the step stops there) moves no point of the god-object by more
// than kBackOffFraction of min_separation: the stop pose then stays within the
// contact band whatever the scene's units (a scene in millimetres with delta
// 1e-9 and steps of 0.4 would stop 4e-7 away, 400 delta, with no contact rows).
// A point moves by at most |dp| + angle radius over the step; the Cayley
// parameter's speed in u varies by a factor under 2, within the fraction's margin.
constexpr double kBackOffFraction = 0.05;
double step_time_tolerance(const CcdMotion& motion, const CcdBody& god, const CcdStepSettings& settings) {
  const double travel = nominal_travel(motion, god);
  const double bound = kBackOffFraction * settings.narrow.min_separation / travel;
  return bound < settings.narrow.time_tolerance ? bound : settings.narrow.time_tolerance;  // NaN, 0 travel: settings'
}

// The lead pieces (CcdStepRequest::lead_sweep): k pieces ahead of the first
// sub-interval's last quarter, each a quarter of the next, k the least that
// makes the first sweep at most lead_sweep reaches (the nominal motion's travel
// and turn at the god-object's radius; a heuristic: any partition of [0, 1]
// is searched alike), at most kMaxLead. A settling leg stops soon after its
// start, where the swept boxes of its whole motion would reach far more node
// pairs than the first piece's.
constexpr int kMaxLead = 6;
int plan_lead(const CcdMotion& motion, const CcdBody& god, int n, double reach, double lead_sweep) {
  if (!(lead_sweep > 0)) return 0;
  const double sweep = nominal_travel(motion, god) / n;
  int k = 0;
  for (double piece = sweep; k < kMaxLead && piece > lead_sweep * reach; piece *= 0.25) ++k;
  return k;  // 0 for a NaN sweep
}

// Piece j of a step planned as n sub-intervals with `lead` pieces ahead: the
// lead's pieces of [0, 1/n] first, then the sub-intervals [i/n, (i+1)/n].
void plan_piece(int j, int lead, int n, double* u0, double* u1) {
  const auto quarters = [&](int k) { return std::ldexp(1.0, -2 * k) / n; };  // 4^-k / n
  if (j < lead) {
    *u0 = j == 0 ? 0.0 : quarters(lead - j + 1);
    *u1 = quarters(lead - j);
    return;
  }
  const int i = j - lead;  // the sub-interval; the first starts after the lead's pieces
  *u0 = i == 0 && lead > 0 ? quarters(1) : static_cast<double>(i) / n;
  *u1 = (i + 1 == n) ? 1.0 : static_cast<double>(i + 1) / n;
}

// The triangle pair is one of hints[0 .. count).
bool among(const FeaturePair* hints, int count, int gf, int of, int o) {
  for (int h = 0; h < count; ++h)
    if (hints[h].god_face == gf && hints[h].obstacle_face == of && hints[h].obstacle == o) return true;
  return false;
}

// The hints' triangle pairs first, over the whole step (each distinct pair once;
// from s->searched, as every search of the step).
// A pair searched here over [0, e] needs no second search: every later
// window [u0, end()] ends at or before e (end() only shrinks), and the
// search returned the pair's first contact in [0, e], if any. The sliding
// contacts are the dearest pairs to search (their gap stays near delta).
void search_hints(StepState* s) {
  const FeaturePair* hints = s->hints;
  const int num_hints = s->num_hints;
  if (!(hints && num_hints > 0)) return;
  PairTester& tester = s->tester;
  enclose_motion(s->motion, {s->searched, 1}, &s->e);
  s->ws->swept.next_interval();
  tester.u0 = s->searched;
  tester.u1 = 1;
  // The hint on the triangle pair that stopped the workspace's last step, if
  // any, goes first (CcdStepWorkspace::last_hit); the others keep their
  // order: lead, 0, 1, .., lead - 1, lead + 1, ... Either way, once hints[h]
  // is done, so are all of hints[0 .. h].
  const FeaturePair& last = s->ws->last_hit;
  int lead = 0;
  for (int h = 0; h < num_hints; ++h)
    if (hints[h].god_face == last.god_face && hints[h].obstacle_face == last.obstacle_face &&
        hints[h].obstacle == last.obstacle) {
      lead = h;
      break;
    }
  const CcdBody& god = s->god;
  for (int k = 0; k < num_hints && !tester.done() && !answered(*s); ++k) {
    const int h = k == 0 ? lead : (k <= lead ? k - 1 : k);
    const FeaturePair& f = hints[h];
    // (Every obstacle's mesh and tree were checked with the inputs.)
    const bool valid = f.obstacle >= 0 && f.obstacle < s->num_obstacles && f.god_face >= 0 &&
                       f.god_face < god.mesh->F.rows() && f.obstacle_face >= 0 &&
                       f.obstacle_face < s->obstacles[f.obstacle].mesh->F.rows();
    if (!valid || among(hints, h, f.god_face, f.obstacle_face, f.obstacle)) continue;  // each distinct pair once
    const CcdBody& ob = s->obstacles[f.obstacle];
    const TestCounts before = test_counts(*s);
    tester.test(*god.mesh, *god.bvh, f.god_face, *ob.mesh, *ob.bvh, f.obstacle_face, f.obstacle);
    if (k > 0 || lead == 0) s->num_searched = h + 1;  // (the lead alone is not hints[0 .. lead])
    if (charge_test(s, before)) return;  // the step stops at s->searched (ccd_step)
  }
}

// The descent of every obstacle's tree with the god-object's over the motion
// enclosed in s->e from s->start (traverse), up to u_end: from the root pairs,
// or from the cut of the last descent in this workspace (DescentFront) when it
// was made for these trees, pushed onto the stack a part at a time; it writes
// its own cut for the next. A descent stopped by visit leaves as its cut the
// pairs it stopped at, those still pending and the old cut's pairs not yet
// pushed; a full stack or a cut that does not fit leaves none (the next
// descent starts at the root). Under the update's budget the descent runs
// kDescentChunk node pairs at a time, each chunk charged: kPaused when the
// budget ran out (no cut written).
constexpr long kDescentChunk = 64;
template <class Visit>
TraversalStatus descend(StepState* s, double u_end, const Visit& visit) {
  DescentFront& f = s->ws->front;
  BvhStack& stack = s->ws->stack;
  const bool keep = s->num_obstacles <= f.obstacle_capacity();
  const bool from_cut = keep && f.keyed(s->god, s->obstacles, s->num_obstacles);
  f.clear();
  if (keep) f.start();
  const auto record = [&](int g, int h) {
    if (keep) f.add(g, h);
  };
  const bool god_empty = s->god.bvh->nodes.empty();
  // The root pair's cut, or obstacle o's part of the old one (n pairs).
  const auto cut_of = [&](int o, int* n) -> const DescentFront::NodePair* {
    if (from_cut) return f.read(o, n);
    *n = god_empty || s->obstacles[o].bvh->nodes.empty() ? 0 : 1;  // an empty tree: nothing to reach
    return nullptr;
  };
  // Room on the stack for each part of the old cut: what the descent below
  // its pairs pushes (two per level) stays within the rest.
  const int part = std::max(1, static_cast<int>(stack.items.size()) / 2);
  for (int o = 0; o < s->num_obstacles; ++o) {
    if (keep) f.start_obstacle(o);
    int n = 0;
    const DescentFront::NodePair* old = cut_of(o, &n);
    for (int k = 0; k < n;) {
      int pending = 0;
      if (old == nullptr) {
        if (!start_candidate_pairs(*s->god.bvh, *s->obstacles[o].bvh, &stack, &pending))
          return TraversalStatus::kStackFull;
        k = n;
      } else {
        for (; k < n && pending < part; ++k) stack.items[static_cast<size_t>(pending++)] = old[k];
      }
      const long chunk = s->ws->budget ? kDescentChunk : std::numeric_limits<long>::max();
      TraversalStatus ts;
      do {
        const int before = s->result->num_node_pairs;
        ts = traverse(*s, s->start, s->e, s->ws->swept, u_end, s->reach, o, &stack, &pending, chunk,
                      &s->result->num_node_pairs, visit, record);
        if (charge(s, Work::kNodePair, s->result->num_node_pairs - before) && ts == TraversalStatus::kPaused)
          return ts;
      } while (ts == TraversalStatus::kPaused);
      if (ts == TraversalStatus::kStopped && keep) {
        // The cut: what it stopped at, what is pending, the rest of the old
        // cut, and the later obstacles' cuts as they were.
        for (int i = 0; i < pending; ++i) {
          const DescentFront::NodePair& q = stack.items[static_cast<size_t>(i)];
          record(q.first, q.second);
        }
        for (; old != nullptr && k < n; ++k) record(old[k].first, old[k].second);
        for (int p = o + 1; p < s->num_obstacles; ++p) {
          f.start_obstacle(p);
          int m = 0;
          const DescentFront::NodePair* rest = cut_of(p, &m);
          for (int i = 0; i < m; ++i) rest ? record(rest[i].first, rest[i].second) : record(0, 0);
        }
        f.finish(s->god, s->obstacles, s->num_obstacles);
      }
      if (ts != TraversalStatus::kDone) return ts;
    }
  }
  if (keep) f.finish(s->god, s->obstacles, s->num_obstacles);
  return TraversalStatus::kDone;
}

// The sub-intervals (and lead pieces) past the cached range, each descended and
// its candidates tested. False when the descent's stack overflowed or the
// update's budget ran out (the step then stops conservatively, result final).
bool search_sub_intervals(StepState* s) {
  const CcdBody& god = s->god;
  CcdStepResult* result = s->result;
  PairTester& tester = s->tester;
  CcdStepWorkspace::Candidate* const cand = s->ws->candidates.data();
  const int cand_capacity = static_cast<int>(s->ws->candidates.size());
  for (int j = 0; j < s->n + s->lead && !answered(*s); ++j) {
    double u0 = 0, u1 = 1;
    plan_piece(j, s->lead, s->n, &u0, &u1);
    u0 = std::max(u0, s->searched);
    if (!(u0 < u1)) continue;  // searched already
    if (result->hit && result->u_hit - s->settings.narrow.time_tolerance <= u0) break;  // nothing left to search
    enclose_motion(s->motion, {u0, std::min(u1, result->u_hit)}, &s->e);
    s->start.set(s->motion, u0, god.bvh->radius);
    tester.u0 = u0;
    tester.u1 = u1;
    // Candidate triangle pairs, each with a lower bound of its first contact
    // (StartFrame::earliest); those that cannot touch before the
    // sub-interval's end are dropped here. When the buffer is full the rest are
    // tested at once, in traversal order (same result, less pruning).
    // The near pairs listed before this piece (the last piece's, or the
    // proximity list's), when they hold up to u0, stay at cand[0 .. kept)
    // while this piece's candidates go after them: a budget stop inside this
    // descent, at u0, then still has them for the contact set at its stop pose
    // (instead of a descent of the trees there, after the budget ran out).
    const bool kept_list = result->num_near_pairs >= 0 && s->near_u1 >= u0;
    const int kept = kept_list ? result->num_near_pairs : 0;
    CcdStepWorkspace::Candidate* const piece = cand + kept;
    const int piece_capacity = cand_capacity - kept;
    int num_cand = 0;
    bool listed = true;  // every candidate of this sub-interval is in piece (no overflow, no early stop)
    s->ws->swept.next_interval();  // e changed: every cached god box is stale
    const TraversalStatus ts = descend(s, std::min(u1, result->u_hit), [&](int gf, int of, int o) {
      const CcdBody& ob = s->obstacles[o];
      ++result->num_triangle_pairs;
      if (charge(s, Work::kTrianglePair, 1)) return false;
      const double t = candidate_time(s, s->start.posed_face(*god.mesh, gf, &s->ws->swept), *ob.mesh, of);
      if (t == kDropped) return true;
      if (num_cand < piece_capacity) {
        piece[num_cand++] = {{gf, of, o}, t};
        return true;
      }
      listed = false;
      if (t == kNearOnly) return true;  // nothing to test
      const TestCounts before = test_counts(*s);
      if (!searched(*s, gf, of, o)) tester.test(*god.mesh, *god.bvh, gf, *ob.mesh, *ob.bvh, of, o);
      // A hit at the sub-interval's start cannot be bettered: stop. So does the budget's end.
      return !charge_test(s, before) && !tester.done() && !answered(*s);
    });
    if (ts == TraversalStatus::kStackFull) {
      // Unknown beyond here: stop conservatively at the sub-interval's start.
      result->status = CcdStatus::kWorkspaceFull;
      result->hit = true;
      result->u_hit = std::min(result->u_hit, u0);
      return false;
    }
    if (out_of_budget(*s)) {  // a descent cut short: proven up to the piece's start
      if (!kept_list) result->num_near_pairs = -1;  // (else the kept list, which holds at u0)
      stop_on_budget(s, u0);
      return false;
    }
    if (ts == TraversalStatus::kStopped) listed = false;
    std::copy(piece, piece + num_cand, cand);  // this piece's list now (kept < piece: a forward copy)
    set_near_pairs(s, listed ? num_cand : -1, u0, std::min(u1, result->u_hit));
    if (!test_candidates(s, num_cand)) return false;
  }
  return true;
}

// The settings a request's question runs with: a check of contact itself
// (CcdQuestion::kFreeOfContact) at min_separation 0, without near pairs or a
// cache of its own; a call that does not go on with the background fill
// (CcdStepRequest::fill_cache), with no fill budget.
CcdStepSettings settings_asked(const CcdStepRequest& request, const CcdStepSettings& settings) {
  CcdStepSettings asked = settings;
  if (request.question == CcdQuestion::kFreeOfContact) {
    asked.narrow.min_separation = 0;
    asked.near_distance = 0;
    asked.cache.margin = asked.cache.margin_max = 0;
  }
  if (request.question == CcdQuestion::kFreeOfContact || !request.fill_cache) asked.cache.fill_budget = 0;
  return asked;
}

// The step's answer: pairs were searched only up to u_b - tol
// (PairTester::end), so a hit stops there.
void finish(StepState* s) {
  CcdStepResult* result = s->result;
  if (!result->hit) {
    result->u_hit = 1;
  } else {
    result->u_hit = std::max(0.0, result->u_hit - s->settings.narrow.time_tolerance);
    s->ws->last_hit = result->pair;
    result->time_tolerance_reached += s->settings.narrow.time_tolerance;
  }
}

}  // namespace

StepState::StepState(const CcdBody* obstacles_in, int num_obstacles_in, const CcdBody& god_in,
                     const CcdStepRequest& request, const CcdStepSettings& settings_in, CcdStepWorkspace* ws_in,
                     CcdStepResult* result_in)
    : obstacles(obstacles_in),
      num_obstacles(num_obstacles_in),
      god(god_in),
      X0(request.X0),
      settings(settings_in),
      ws(ws_in),
      result(result_in),
      hints(request.hints),
      num_hints(request.num_hints),
      lead_sweep(request.lead_sweep),
      any_hit(request.question == CcdQuestion::kFreeOfContact),
      motion(result_in->motion),
      // The boxes and the pairs' time bounds take the larger of d and the near
      // distance: the candidates are then the near pairs too (a pair that cannot
      // come within the near distance cannot come within d).
      reach(std::max(settings_in.narrow.min_separation, settings_in.near_distance)),
      rho(god_in.bvh->radius),
      tester{&motion, &e, &settings, &ws->narrow, result, 0, 0, &ws->swept, &start,
             settings_in.narrow.min_separation} {}

bool searched(const StepState& s, int gf, int of, int o) { return among(s.hints, s.num_searched, gf, of, o); }

bool answered(const StepState& s) { return s.any_hit && s.result->hit; }

double candidate_time(StepState* s, const SweptBoxCache::PosedFace& g, const TriangleMesh& om, int of) {
  const double end = s->tester.end();
  const double t = s->start.earliest(g, om, of, s->settings.narrow.min_separation, end);
  if (t <= end) return t;
  ++s->result->num_axis_culls;  // no pair test
  return s->reach > s->settings.narrow.min_separation ? kNearOnly : kDropped;
}

// Earliest-first: each hit shortens the windows of the pairs after it, and
// once a pair's bound passes the best u so far, so do all the rest.
bool test_candidates(StepState* s, int num_cand) {
  CcdStepWorkspace::Candidate* const cand = s->ws->candidates.data();
  PairTester& tester = s->tester;
  const CcdBody& god = s->god;
  // The near pairs only (kNearOnly) last, unsorted: a dense contact lists
  // thousands of them and tests none.
  const int num_tested = static_cast<int>(
      std::partition(cand, cand + num_cand, [](const auto& c) { return c.earliest != kNearOnly; }) - cand);
  std::sort(cand, cand + num_tested, [](const auto& a, const auto& b) { return a.earliest < b.earliest; });
  for (int c = 0; c < num_tested; ++c) {
    if (cand[c].earliest > tester.end() || tester.done() || answered(*s)) break;
    const TrianglePair& p = cand[c].pair;
    if (searched(*s, p.god_face, p.obstacle_face, p.obstacle)) continue;
    const CcdBody& ob = s->obstacles[p.obstacle];
    const TestCounts before = test_counts(*s);
    tester.test(*god.mesh, *god.bvh, p.god_face, *ob.mesh, *ob.bvh, p.obstacle_face, p.obstacle);
    if (charge_test(s, before)) {
      // The rest cannot come within min_separation before the next one's bound
      // (sorted), nor past the range the candidates were listed for.
      const double next = c + 1 < num_tested ? cand[c + 1].earliest : tester.u1;
      stop_on_budget(s, std::max(tester.u0, std::min(next, tester.u1)));
      return false;
    }
  }
  return true;
}

void stop_on_budget(StepState* s, double u) {
  CcdStepResult* r = s->result;
  if (s->budget_stopped) return;  // once
  s->budget_stopped = true;
  if (!r->hit && u >= 1) return finish(s);  // the whole motion searched: no hit
  // Every pair tested was searched up to end(): a hit whose reported u_hit
  // (less the tolerance) is no later than u is the first contact.
  if (r->hit && r->u_hit - s->settings.narrow.time_tolerance <= u) return finish(s);
  r->budget_exhausted = true;
  r->hit = true;
  r->u_hit = std::max(u, 0.0);
  r->pair = FeaturePair{};
  r->distance_reached = std::numeric_limits<double>::quiet_NaN();
  r->time_tolerance_reached = 0;
}

// Whatever the testing finds, u_hit stays <= the end of the window the near
// pairs were listed for.
void set_near_pairs(StepState* s, int num_cand, double u0, double u1) {
  if (s->settings.near_distance <= 0) return;
  s->result->num_near_pairs = num_cand;
  s->result->near_u0 = u0;
  s->near_u1 = u1;
  s->result->near_reach = s->reach;
}

}  // namespace detail

void DescentFront::copy_from(const DescentFront& other) {
  const int num_obs = static_cast<int>(other.obstacles.size());
  ready = other.ready && num_obs <= obstacle_capacity();
  if (!ready) return;
  const std::vector<int>& b = other.begin[other.cur];
  const int n = b[static_cast<size_t>(num_obs)];
  ready = n <= static_cast<int>(pairs[cur].size());
  if (!ready) return;
  std::copy(b.begin(), b.begin() + num_obs + 1, begin[cur].begin());
  std::copy(other.pairs[other.cur].begin(), other.pairs[other.cur].begin() + n, pairs[cur].begin());
  god = other.god;
  obstacles.assign(other.obstacles.begin(), other.obstacles.end());  // within the reserved capacity
}

const char* ccd_step_settings_problem(const CcdStepSettings& s) {
  const auto positive = [](double x) { return x > 0 && std::isfinite(x); };
  const auto non_negative = [](double x) { return x >= 0 && std::isfinite(x); };
  const CcdSettings& n = s.narrow;
  if (!(n.time_tolerance > 0 && n.time_tolerance < 1)) return "ccd.narrow.time_tolerance must be in (0, 1)";
  if (!positive(n.distance_tolerance)) return "ccd.narrow.distance_tolerance must be > 0 and finite";
  if (!non_negative(n.min_separation)) return "ccd.narrow.min_separation must be >= 0 and finite";
  if (n.max_iterations < 1) return "ccd.narrow.max_iterations must be >= 1";
  if (s.max_sub_intervals < 1) return "ccd.max_sub_intervals must be >= 1";
  if (!positive(s.sub_interval_angle) || !positive(s.sub_interval_travel))
    return "ccd.sub_interval_angle and ccd.sub_interval_travel must be > 0 and finite";
  if (!non_negative(s.near_distance)) return "ccd.near_distance must be >= 0 and finite";
  if (!valid_proximity_cache_settings(s.cache)) return "ccd.cache: the proximity cache's settings are not valid";
  return nullptr;
}

const char* ccd_step_request_problem(const CcdStepRequest& r) {
  if (!(r.known_free >= 0 && r.known_free < 1)) return "known_free must be in [0, 1)";
  if (!(r.lead_sweep >= 0 && std::isfinite(r.lead_sweep))) return "lead_sweep must be >= 0 and finite";
  return nullptr;
}

void ccd_step(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const CcdStepRequest& request,
              const CcdStepSettings& settings, CcdStepWorkspace* ws, CcdStepResult* result) noexcept {
  using namespace detail;
  *result = CcdStepResult{};
  // Validate the input; make the motion and its enclosure (METHOD.md section 4).
  if (!inputs_valid(obstacles, num_obstacles, god, settings, ws) || ccd_step_request_problem(request)) {
    result->status = CcdStatus::kInvalidInput;
    return;
  }
  // A call that opens an update renews its fills' allowance of work units (ProximityCacheSettings::fill_at_once).
  if (request.fill_cache) ws->cache.at_once_left = settings.cache.fill_at_once;
  const MotionStatus ms = make_ccd_motion(request.X0, request.X1, &result->motion);
  if (ms != MotionStatus::kOk) {
    result->status = ms == MotionStatus::kHalfTurn ? CcdStatus::kHalfTurn : CcdStatus::kInvalidInput;
    return;
  }
  // The part of [0, 1] already proven free: the caller's, and what a proven
  // motion nearby proves (at the legs' separation, min_separation).
  double known_free = request.known_free;
  const ProvenMotion& proven = request.proven;
  if (proven.motion)
    known_free = std::max(known_free, proven_prefix(request.X0, result->motion, proven.from, *proven.motion,
                                                    proven.u, god.bvh->radius, settings.narrow.min_separation));
  if (known_free >= 1) {  // proven whole: free, nothing to search
    result->u_hit = 1;
    return;
  }
  CcdStepSettings step_settings = settings_asked(request, settings);
  const double asked_tolerance = step_settings.narrow.time_tolerance;
  step_settings.narrow.time_tolerance = step_time_tolerance(result->motion, god, step_settings);
  if (!(step_settings.narrow.time_tolerance > 0)) step_settings.narrow.time_tolerance = asked_tolerance;
  StepState s(obstacles, num_obstacles, god, request, step_settings, ws, result);
  s.searched = known_free;
  if (ws->lender) ws->front.copy_from(ws->lender->front);  // the lender's last cut
  if (!ws->front.carry) ws->front.clear();  // the last step's cut serves only when carried (DescentFront)
  // Plan the sub-intervals.
  s.n = plan_sub_intervals(s.motion, god, step_settings);
  s.lead = plan_lead(s.motion, god, s.n, s.reach, request.lead_sweep);
  result->num_sub_intervals = s.n + s.lead;
  // The hints and the proximity cache both start from the god-object at u = 0.
  const bool cached = step_settings.cache.margin > 0;
  const bool borrowing = !cached && ws->lender != nullptr;
  if ((s.hints && s.num_hints > 0) || cached || borrowing) s.start.set(s.motion, 0.0, god.bvh->radius);
  // Search the hints over the whole step (a hit among them answers a check:
  // CcdQuestion::kFreeOfContact).
  // An update whose budget has run out (now or in a stage) searches no further:
  // the step stops at what it has proven (stop_on_budget, result final).
  const auto stopped = [&] {
    if (out_of_budget(s)) stop_on_budget(&s, s.searched);
    return out_of_budget(s);
  };
  if (stopped()) return;
  search_hints(&s);
  if (stopped()) return;
  if (!answered(s)) {
    // Serve the step's start from the proximity cache, refilled first if worth it
    // (or from another workspace's list, read-only).
    if (cached) serve_proximity_cache(&s);
    if (borrowing) serve_borrowed_list(&s);
    if (stopped()) return;
    // Descend the trees per sub-interval past the cached range, and test the
    // candidate pairs earliest-first (a full stack or the budget's end stops the step there).
    if (!search_sub_intervals(&s)) return;
  }
  // Fill the next list in the background while this one serves.
  if (cached) fill_cache_in_background(&s);
  // Finish: the result less the time tolerance, the pair that stopped the step.
  finish(&s);
}

}  // namespace gauss6
