// The proximity cache's stages of the CCD step (proximity_cache.h, coherence
// between steps): serve the step's start from the list in use, put a
// background fill in use or refill the list at X0 when that pays, search the
// cached range from the list's pairs, and fill the next list in the background
// at the pose the god-object is heading for. Where each policy constant of
// ProximityCacheSettings acts is said at its use.
#include <algorithm>
#include <cmath>
#include <limits>

#include "ccd_step_state.h"
#include "gauss6/geometry/distance.h"
#include "gauss6/numeric/rounding.h"

namespace gauss6 {

bool valid_proximity_cache_settings(const ProximityCacheSettings& s) {
  const auto in_unit = [](double x) { return x > 0 && x <= 1; };  // false for NaN
  return s.margin >= 0 && std::isfinite(s.margin) && s.margin_max >= 0 && std::isfinite(s.margin_max) &&
         s.fill_budget >= 0 && s.steps_per_list > 0 && std::isfinite(s.steps_per_list) &&
         in_unit(s.slow_fraction) && in_unit(s.max_probe_sub_intervals) && in_unit(s.fill_lead) &&
         s.min_uses >= 1 && s.skip_after_poor_fill >= 0 && s.fill_at_once >= 1 && s.triangle_margin > 0 &&
         std::isfinite(s.triangle_margin);
}

namespace detail {

namespace {

// The policy constants (ProximityCacheSettings).
const ProximityCacheSettings& policy(const StepState& s) { return s.settings.cache; }

// The margin of a list filled now: about steps_per_list steps like the last
// one (v), within [margin, margin_max]: a wide one while the god-object slides
// steadily (fewer fills), the narrow one at rest (a shorter list to scan);
// then at most triangle_margin triangle sizes (ProximityCache::triangle_size):
// with triangles smaller than the margin a list's pairs grow as the square of
// their density over the contact, with this cap as their number.
double list_margin(const StepState& s, double v, double margin, double margin_max) {
  const double m = std::clamp(policy(s).steps_per_list * v, margin, margin_max);
  const double cap = policy(s).triangle_margin * s.ws->cache.triangle_size;
  return cap > 0 ? std::min(m, cap) : m;
}

bool same_body(const CcdBody& a, const CcdBody& b) { return a.mesh == b.mesh && a.bvh == b.bvh; }

// The list was filled for this step's god-object and obstacles (meshes and trees).
bool same_bodies(const ProximityCache& pc, const StepState& s) {
  bool k = same_body(pc.god, s.god) && static_cast<int>(pc.obstacles.size()) == s.num_obstacles;
  for (int o = 0; k && o < s.num_obstacles; ++o) k = same_body(pc.obstacles[static_cast<size_t>(o)], s.obstacles[o]);
  return k;
}

// The settings' margins, the larger one at least the smaller.
double step_margin(const StepState& s) { return s.settings.cache.margin; }
double step_margin_max(const StepState& s) { return std::max(s.settings.cache.margin_max, step_margin(s)); }

// The cache's keys are these meshes, trees, reach and margins (the list in
// use's, or the first fill's while none is: set_keys).
bool keys_match(const StepState& s) {
  const ProximityCache& pc = s.ws->cache;
  return s.num_obstacles <= pc.obstacle_capacity && pc.reach == s.reach && pc.margin_min == step_margin(s) &&
         pc.margin_max == step_margin_max(s) && same_bodies(pc, s);
}
// The mean longest edge of a sample of the mesh's triangles (ProximityCache::triangle_size).
double sampled_triangle_size(const TriangleMesh& m) {
  const Eigen::Index n = m.F.rows();
  const Eigen::Index k = std::min<Eigen::Index>(n, ProximityCache::kSizeSamples);
  double sum = 0;
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Index f = j * n / k;
    const Vec3 a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    sum += std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  }
  return k > 0 ? sum / static_cast<double>(k) : 0.0;
}

double bodies_triangle_size(const StepState& s) {
  double size = sampled_triangle_size(*s.god.mesh);
  for (int o = 0; o < s.num_obstacles; ++o) size = std::min(size, sampled_triangle_size(*s.obstacles[o].mesh));
  return std::isfinite(size) ? size : 0.0;
}

void set_keys(StepState* s) {
  ProximityCache& pc = s->ws->cache;
  pc.reach = s->reach;
  pc.margin_min = step_margin(*s);
  pc.margin_max = step_margin_max(*s);
  pc.god = s->god;
  pc.obstacles.assign(s->obstacles, s->obstacles + s->num_obstacles);
}

// The list in use was filled for these meshes, trees, reach and margins.
bool is_keyed(const StepState& s) { return s.ws->cache.num_pairs >= 0 && keys_match(s); }

// Fills: every pair not proven apart by reach + pf.margin with the god-object
// at pf.ref (X0, or the pose a background fill is started at:
// fill_cache_in_background), descended into pf.pairs obstacle by obstacle, a
// FillAllowance at a time (fill_some: true once complete; a fill that
// does not fit, in pf.pairs or on pf.stack, is dropped), then swapped in
// (put_fill).
void start_obstacle(StepState* s) {
  ProximityCache::Fill& pf = s->ws->cache.fill;
  if (pf.obstacle < s->num_obstacles &&
      !start_candidate_pairs(*s->god.bvh, *s->obstacles[pf.obstacle].bvh, &pf.stack, &pf.pending))
    pf.active = false;
}

// A fill of margin m at X0 (ahead: nullptr), or at *ahead when a motion can
// stand still there (else at X0).
void start_fill(StepState* s, const Pose* ahead, double m) {
  ProximityCache::Fill& pf = s->ws->cache.fill;
  pf.margin = m;
  pf.ref = s->X0;
  pf.motion = s->motion;
  if (ahead) {
    CcdMotion still;
    if (make_ccd_motion(*ahead, *ahead, &still) == MotionStatus::kOk) {
      pf.ref = *ahead;
      pf.motion = still;
    }
  }
  pf.cost = 0;
  pf.swept_dist = -1;  // another pose: the boxes of the last fill are stale
  pf.num_pairs = 0;
  pf.obstacle = 0;
  pf.active = true;
  pf.complete = false;
  start_obstacle(s);
}

bool fill_some(StepState* s, FillAllowance* left) {
  ProximityCache& pc = s->ws->cache;
  ProximityCache::Fill& pf = pc.fill;
  if (!pf.active) return false;
  const CcdBody& god = s->god;
  StartFrame frame;
  frame.set(pf.motion, 0.0, s->rho);
  MotionEnclosure enc;
  enclose_motion(pf.motion, {0, 0}, &enc);
  const int capacity = static_cast<int>(pf.pairs.size());
  const double fill_dist = (Upper{s->reach} + Upper{pf.margin}).v;
  if (pf.swept_dist != fill_dist) {  // (start_fill sets -1)
    pf.swept.next_interval();
    pf.swept_dist = fill_dist;
  }
  while (pf.obstacle < s->num_obstacles) {
    int used = 0;
    const TraversalStatus ts = traverse(*s, frame, enc, pf.swept, 0.0, fill_dist, pf.obstacle, &pf.stack, &pf.pending,
                                        left, &used, [&](int gf, int of, int o) {
      double radius = 0;
      charge(s, Work::kTrianglePair, 1);  // (the chunks' ends check: fill_within_budget)
      left->units -= work_units(Work::kTrianglePair, 1);  // (the next node pair checks: take_node_pair)
      ++s->result->num_fill_triangle_pairs;
      const double gap = frame.gap(frame.posed_face(*god.mesh, gf, &pf.swept), *s->obstacles[o].mesh, of, fill_dist,
                                   &radius);
      if (gap > fill_dist) return true;
      if (pf.num_pairs == capacity) return false;  // does not fit: no cache
      pf.pairs[static_cast<size_t>(pf.num_pairs++)] = {gap, radius, gf, of, o};
      return true;
    });
    s->result->num_fill_node_pairs += used;
    pf.cost += used;
    if (ts == TraversalStatus::kPaused) return false;
    if (ts != TraversalStatus::kDone) {
      pf.active = false;
      return false;
    }
    ++pf.obstacle;
    start_obstacle(s);
    if (!pf.active) return false;
  }
  pf.complete = true;
  pc.fill_cost = pf.cost;
  return true;
}

// The list's index by gap (ProximityCache::by_gap): a counting sort of its
// ids into kGapBuckets buckets, stable (each bucket in increasing id order).
int gap_bucket(const ProximityCache& pc, double gap) {
  const double b = gap / pc.gap_width;  // (NaN, negative: the first)
  return b >= ProximityCache::kGapBuckets - 1 ? ProximityCache::kGapBuckets - 1 : (b > 0 ? static_cast<int>(b) : 0);
}
void index_by_gap(ProximityCache* pc) {
  constexpr int K = ProximityCache::kGapBuckets;
  pc->gap_width = (pc->reach + pc->margin) / K;
  pc->max_radius = 0;
  int count[K + 1] = {};
  for (int k = 0; k < pc->num_pairs; ++k) {
    const ProximityCache::Pair& c = pc->pairs[static_cast<size_t>(k)];
    ++count[gap_bucket(*pc, c.gap) + 1];
    pc->max_radius = std::max(pc->max_radius, c.radius);
  }
  for (int b = 0; b < K; ++b) count[b + 1] += count[b];
  std::copy(count, count + K + 1, pc->bucket_begin);
  for (int k = 0; k < pc->num_pairs; ++k) {
    const int b = gap_bucket(*pc, pc->pairs[static_cast<size_t>(k)].gap);
    pc->by_gap[static_cast<size_t>(count[b]++)] = k;
  }
}

void put_fill(StepState* s) {
  ProximityCache& pc = s->ws->cache;
  ProximityCache::Fill& pf = pc.fill;
  std::swap(pc.pairs, pf.pairs);
  pc.num_pairs = pf.num_pairs;
  pc.ref = pf.ref;
  pc.margin = pf.margin;
  set_keys(s);
  pc.uses = 0;
  pc.budget_cut = false;
  pf.active = false;
  index_by_gap(&pc);
}

// The ids of the list's pairs that a step whose points move at most `moving`
// from the list's pose may bring within the reach, in list order, into
// ids (near_ids): the buckets whose gaps start below reach + the largest
// move (and the next, for the rounding of the bucket's index); a pair of a
// later bucket is farther apart than that (each pair is checked again).
int near_pairs_of(const ProximityCache& pc, const Displacement& moving, double reach, std::vector<int32_t>* ids) {
  const double reached = (Upper{reach} + Upper{moving.bound(pc.max_radius)}).v;
  constexpr int K = ProximityCache::kGapBuckets;
  const int last = reached <= std::numeric_limits<double>::max() ? std::min(gap_bucket(pc, reached) + 1, K - 1)
                                                                   : K - 1;  // (infinite, NaN: every bucket)
  const int n = pc.bucket_begin[last + 1];
  // The same ids in list order, whichever is cheaper: the buckets' ids sorted
  // (n log n), or a pass over the whole list keeping the pairs of those
  // buckets (num_pairs). A flat tool on a dense coplanar patch keeps most of
  // its list within the reach (every pair it slides over), where the pass is
  // several times cheaper than the sort.
  if (static_cast<double>(n) * std::log2(static_cast<double>(n) + 2) < static_cast<double>(pc.num_pairs)) {
    std::copy(pc.by_gap.begin(), pc.by_gap.begin() + n, ids->begin());
    std::sort(ids->begin(), ids->begin() + n);
    return n;
  }
  int kept = 0;
  for (int k = 0; k < pc.num_pairs; ++k)
    if (gap_bucket(pc, pc.pairs[static_cast<size_t>(k)].gap) <= last) (*ids)[static_cast<size_t>(kept++)] = k;
  return kept;  // == n: the buckets up to `last` hold exactly these pairs (index_by_gap)
}

// The ranges of the step's start that a list can serve.
struct CacheRanges {
  double speed;    // the god-object's at u = 0 (StartFrame::speed)
  double u_rest;   // the rest of the step (up to a hint's hit)
  bool probing;    // hints given and none hit: a short first search may pay
  double u_probe;  // over [0, u_probe] no point moves a quarter of the margin
  int n;           // sub-intervals
  double max_probe;  // a first search is shorter than this many sub-intervals (max_probe_sub_intervals)
  bool stops_early;  // a leg expected to stop early (CcdStepRequest::lead_sweep > 0): any range serves
  // [0, u] keeps every point within m of a list's pose, the points `moved`
  // from there by X0 (0: none).
  double range(double moved, double m) const {
    const double u = speed > 0 ? ((Lower{m} - Upper{moved}) / Upper{speed}).v : 1.0;
    return u > 0 ? std::min(u, 1.0) : 0.0;  // also NaN
  }
  // The part of a cache range [0, u] to search from the cache (0: none): all
  // of it when it covers the rest of the step or the leg stops early
  // (stops_early); else, as a first search, at most
  // the range over which no point moves slow_fraction of the margin, and only
  // when that is under max_probe sub-intervals (a longer one saves no descent).
  double window(double u) const {
    if (!(u > 0)) return 0.0;  // also NaN
    if (u >= u_rest || stops_early) return u;
    const double w = std::min(u, u_probe);
    return probing && w > 0 && w < max_probe / n ? w : 0.0;
  }
  bool usable(double u) const { return window(u) > 0; }
};

// A fill a step needs now: at most the update's work units left
// (ProximityCache::at_once_left, ProximityCacheSettings::fill_at_once), its
// node pairs' and triangle pairs' units charged to it; true once complete.
bool fill_at_once(StepState* s) {
  ProximityCache& pc = s->ws->cache;
  if (pc.fill.complete) return true;
  FillAllowance left{std::numeric_limits<long>::max(), pc.at_once_left};
  const bool complete = fill_within_budget(s, &left);
  pc.at_once_left = left.units;
  return complete;
}

// The fill's pose is ahead of the god-object's path (fill_cache_in_background),
// or at the start of a step that needed it (refill_if_worth): put it in use once
// it leaves more of its margin than the list in use does, or, when that list
// (or none: the first fill) cannot serve this step, once complete (within the
// update's fill_at_once: the step descends the trees meanwhile).
void take_background_fill(StepState* s, const CacheRanges& r, Displacement* since) {
  ProximityCache& pc = s->ws->cache;
  ProximityCache::Fill& pf = pc.fill;
  const Displacement ahead(pf.ref, s->X0);
  const double moved_ahead = ahead.bound(s->rho);
  const bool better = pf.margin - moved_ahead > pc.margin - s->cache_moved;
  const bool needed = !r.usable(s->u_cached) && r.usable(r.range(moved_ahead, pf.margin));
  if (!r.usable(s->u_cached) && !needed) {
    pf.active = false;  // the god-object went elsewhere
  } else if ((better && pf.complete) || (needed && fill_at_once(s))) {
    put_fill(s);
    s->result->cache_refilled = true;
    *since = ahead;
    s->cache_moved = moved_ahead;
    s->u_cached = r.range(s->cache_moved, pc.margin);
  } else if (needed && pf.active) {
    pc.budget_cut = true;  // cut short: it goes on, and no other fill starts at once (refill_if_worth)
  }
}

// A fill costs more than a descent over the step (its boxes are grown by
// the margin) and pays only when later steps use it: after a fill that
// served fewer than min_uses later steps (a peg sliding half the margin a
// step, steps that each start far from the last), the next
// skip_after_poor_fill chances to fill are passed over (plain descents), and
// the one after that fills. A step that moves at most slow_fraction of the
// margin fills regardless (the list then serves the next steps unless the
// god-object speeds up).
// The fill is at X0 (u = 0), at once but for its bound: it spends at most what
// is left of the update's fill_at_once node pairs now and goes on at the next
// steps (a list's pairs grow faster than the meshes: at a million triangles a
// whole fill costs several updates' time). A list for other meshes or
// settings is dropped first: the cache's keys are then the fill's.
void refill_if_worth(StepState* s, const CacheRanges& r, Displacement* since) {
  ProximityCache& pc = s->ws->cache;
  const double margin = step_margin(*s), rho = s->rho;
  const bool fresh = r.usable(s->u_cached);
  if (fresh) ++pc.uses;
  const double v = pc.has_last ? Displacement(pc.last_x0, s->X0).bound(rho) : 0.0;
  double fresh_margin = list_margin(*s, v, margin, step_margin_max(*s));
  bool fill = !fresh && r.usable(r.range(Displacement(s->X0, s->X0).bound(rho), fresh_margin));
  if (fill && pc.budget_cut && pc.fill.active) {
    fill = false;  // the fill cut short goes on (take_background_fill)
  } else if (fill && s->start.speed <= policy(*s).slow_fraction * margin) {
    pc.rest = 0;
  } else if (fill && pc.rest > 0) {
    fill = --pc.rest == 0;
  } else if (fill && pc.num_pairs >= 0 && pc.uses < policy(*s).min_uses) {
    pc.rest = policy(*s).skip_after_poor_fill;
    fill = false;
  }
  if (!fill) return;
  if (!s->cache_keyed) {  // the fill's keys, and its margin under these bodies' cap
    pc.clear();
    set_keys(s);
    pc.triangle_size = bodies_triangle_size(*s);
    fresh_margin = list_margin(*s, v, margin, step_margin_max(*s));
  }
  start_fill(s, /*ahead=*/nullptr, fresh_margin);
  const bool filled = fill_at_once(s);
  // A fill cut short, by the update's budget or by fill_at_once, goes on at the
  // next steps as a background fill (take_background_fill finishes it, within
  // their budgets and fill_at_once, and puts it in use), and none starts at
  // once meanwhile: no step spends its time on the same fill again.
  s->u_cached = 0;
  if (!filled && pc.fill.active) {
    pc.budget_cut = true;
    return;
  }
  pc.clear();
  s->cache_keyed = false;
  if (filled) {
    put_fill(s);
    s->cache_keyed = true;
    s->result->cache_filled = true;
    *since = Displacement(s->X0, s->X0);
    s->cache_moved = since->bound(rho);
    s->u_cached = r.range(s->cache_moved, pc.margin);
  }
}

// [searched, u_cached] from the list's pairs (then [0, u_cached] is searched):
// each pair's own certificate first (its gap at the cache's pose less how far
// its points can move from there by u_cached: a few flops); the time bound
// only for the pairs it does not keep beyond the reach; then the candidates'
// tests.
void search_cached_pairs(StepState* s, const ProximityCache& pc, const Displacement& since) {
  CcdStepResult* result = s->result;
  PairTester& tester = s->tester;
  CcdStepWorkspace::Candidate* const cand = s->ws->candidates.data();
  const double u0 = s->searched;
  s->searched = std::max(u0, s->u_cached);
  if (!(u0 < std::min(s->u_cached, result->u_hit))) return;
  enclose_motion(s->motion, {u0, std::min(s->u_cached, result->u_hit)}, &s->e);
  s->ws->swept.next_interval();
  tester.u0 = u0;
  tester.u1 = s->u_cached;
  Displacement moving = since;
  moving.add(s->start, s->u_cached);
  int num_cand = 0;
  std::vector<int32_t>& ids = s->ws->cache.near_ids;  // this workspace's (pc may be borrowed)
  const int num_near = near_pairs_of(pc, moving, s->reach, &ids);
  for (int i = 0; i < num_near; ++i) {
    const ProximityCache::Pair& c = pc.pairs[static_cast<size_t>(ids[static_cast<size_t>(i)])];
    ++result->num_triangle_pairs;
    if (charge(s, Work::kTrianglePair, 1)) {  // nothing of [u0, u_cached] proven, the candidates' buffer in part
      result->num_near_pairs = -1;
      return stop_on_budget(s, u0);
    }
    if (Lower{c.gap} - Upper{moving.bound(c.radius)} > Upper{s->reach}) {
      ++result->num_axis_culls;
      continue;
    }
    const double t = candidate_time(s, s->start.posed_face(*s->god.mesh, c.god_face, &s->ws->swept),
                                    *s->obstacles[c.obstacle].mesh, c.obstacle_face);
    if (t == kDropped) continue;
    cand[num_cand++] = {{c.god_face, c.obstacle_face, c.obstacle}, t};  // fits: the cache has cand's capacity
  }
  set_near_pairs(s, num_cand, 0.0, s->u_cached);
  test_candidates(s, num_cand);  // (the budget's end: stop_on_budget)
}

}  // namespace

// Node pairs a fill descends between two charges to the update's budget.
constexpr long kFillChunk = 64;
bool fill_within_budget(StepState* s, FillAllowance* left) {
  if (s->ws->budget == nullptr) return fill_some(s, left);
  const ProximityCache::Fill& pf = s->ws->cache.fill;
  while (left->node_pairs > 0 && left->units > 0 && !out_of_budget(*s)) {
    const long cost = pf.cost;
    FillAllowance chunk{std::min(left->node_pairs, kFillChunk), left->units};
    const bool complete = fill_some(s, &chunk);
    left->node_pairs -= pf.cost - cost;
    left->units = chunk.units;
    charge(s, Work::kNodePair, pf.cost - cost);
    if (complete || !pf.active) return complete;  // done, or dropped (does not fit)
  }
  return false;
}

// Coherence (proximity_cache.h): [0, u_cached] is the range
// over which no point moves farther than the margin from the cache's pose;
// there the cached pairs are the candidates, with no descent. The range is
// used when it covers the rest of the step (up to a hint's hit), or, when
// the god-object starts in contact and no hint hit, as a short first search
// (under half a sub-interval: a contact likely to be met soon, as a bunny's
// ear turned back onto the back it rests on, ends the step there without
// sweeping the boxes over the whole step). A range covering only part of a
// step would search the pairs near X0 twice (the list, then the descents of
// the rest): not used, but by a leg expected to stop early (a settling leg,
// CcdStepRequest::lead_sweep > 0), which stops soon after its start and so
// most often inside the list's range: the list then answers its lead pieces,
// where each of them would descend the trees to the same standing proximity.
// The cache is refilled
// at X0 when its own range cannot be used for this step and a fresh one's
// would (a step that moves less than the margin, or a short first search).
void serve_proximity_cache(StepState* s) {
  ProximityCache& pc = s->ws->cache;
  s->cache_keyed = is_keyed(*s);
  if (!keys_match(*s)) pc.fill.active = false;  // a fill for other meshes or settings
  // More obstacles than the cache can be keyed by: no cache (its keys never grow).
  if (s->tester.done() || s->num_obstacles > pc.obstacle_capacity) return;
  const CcdStepResult& result = *s->result;
  const double margin = step_margin(*s);
  const double speed = s->start.speed;  // start: at u = 0 (ccd_step)
  const CacheRanges r{speed,
                      result.hit ? result.u_hit : 1.0,
                      s->hints && s->num_hints > 0 && !result.hit,
                      speed > 0 ? round_down(policy(*s).slow_fraction * margin / speed).v : 1.0,
                      s->n,
                      policy(*s).max_probe_sub_intervals,
                      s->lead_sweep > 0};
  const bool keyed = s->cache_keyed;
  Displacement since(keyed ? pc.ref : s->X0, s->X0);
  s->cache_moved = keyed ? since.bound(s->rho) : std::numeric_limits<double>::infinity();
  s->u_cached = keyed ? r.range(s->cache_moved, pc.margin) : 0.0;
  if (pc.fill.active) take_background_fill(s, r, &since);  // (with a list in use or not)
  refill_if_worth(s, r, &since);
  s->u_cached = r.window(s->u_cached);
  s->result->u_cached = s->u_cached;
  if (s->u_cached > 0) search_cached_pairs(s, pc, since);
}

// The borrowed list (CcdStepWorkspace::lender's) serves the step when it
// holds what this step needs: the same god-object and obstacles, filled for a
// reach at least this step's (it holds every pair not proven farther than
// its reach plus its margin apart at its pose, so every pair that can come
// within the smaller reach while no point has moved farther than the margin
// from there), room for its pairs among the candidates, and a range over which no
// point leaves its margin that covers the rest of the step (up to a hint's
// hit). Nothing of the list changes: no use counted, no fill.
void serve_borrowed_list(StepState* s) {
  const ProximityCache* pc = &s->ws->lender->cache;
  if (s->tester.done() || pc == nullptr || pc->num_pairs < 0) return;
  if (!(pc->reach >= s->reach && pc->num_pairs <= static_cast<int>(s->ws->candidates.size()) && same_bodies(*pc, *s)))
    return;
  const Displacement since(pc->ref, s->X0);
  const double speed = s->start.speed;  // start: at u = 0 (ccd_step)
  const double u_rest = s->result->hit ? s->result->u_hit : 1.0;
  const double u = speed > 0 ? ((Lower{pc->margin} - Upper{since.bound(s->rho)}) / Upper{speed}).v : 1.0;
  if (!(u > 0 && u >= u_rest)) return;  // also NaN
  s->u_cached = std::min(u, 1.0);
  s->result->u_cached = s->u_cached;
  search_cached_pairs(s, *pc, since);
}

// The background fill (ProximityCacheSettings::fill_budget node pairs per
// step, while the list in use serves). Each step is taken to move the
// god-object as much as the last one did (v), and a fill to take as many
// steps as the last one did (j). A fill is started when the list in use has
// about j steps left, at the pose the god-object will reach if it goes on
// so for j steps and fill_lead of the margin further: put in use about j
// steps from now, that list then serves from fill_lead of the margin behind
// its pose to the margin ahead. Any pose is sound (the list is for the pose it was
// filled at); a good guess only makes the list serve longer.
void fill_cache_in_background(StepState* s) {
  ProximityCache& pc = s->ws->cache;
  ProximityCache::Fill& pf = pc.fill;
  const CcdStepSettings& settings = s->settings;
  const Pose& X0 = s->X0;
  if (settings.cache.fill_budget > 0) {
    if (s->cache_keyed && !pf.active && s->result->u_cached > 0 && pc.has_last) {
      const double v = Displacement(pc.last_x0, X0).bound(s->rho);
      const double j = std::ceil(static_cast<double>(std::max(pc.fill_cost, 1L)) /
                                 static_cast<double>(settings.cache.fill_budget));
      const double m = list_margin(*s, v, step_margin(*s), step_margin_max(*s));
      if (v > 0 && v < m && pc.margin - s->cache_moved <= (j + 1) * v) {
        const double k = j + std::max(0.0, policy(*s).fill_lead * m / v - 1);
        const Quat dq = normalized(X0.q * conjugate(pc.last_x0.q));
        const Pose ahead{X0.p + k * (X0.p - pc.last_x0.p), normalized(quat_exp(k * quat_log(dq)) * X0.q)};
        start_fill(s, &ahead, m);
      }
    }
    FillAllowance step{settings.cache.fill_budget, std::numeric_limits<long>::max()};
    if (pf.active && !pf.complete) fill_within_budget(s, &step);
  }
  // The next step's background fill and list margin follow this step's motion.
  pc.budget_cut = pc.budget_cut && pc.fill.active;  // the fill cut short goes on (put in use: false)
  pc.last_x0 = X0;
  pc.has_last = true;
}

}  // namespace detail

}  // namespace gauss6
