// The state of one CCD step, shared by its stages (private to the library):
// the step's inputs, the motion enclosure and the god-object's frame of the
// range being searched, the pair tester, and what one stage hands the next
// (the hints searched, the range served by the proximity cache). The stages
// are in ccd_step.cpp (validate, plan, hints, descent, candidates, finish) and
// proximity_stages.cpp (serve or refill the cache, its background fill); the
// tree descent they share is traverse() below.
#pragma once

#include <algorithm>
#include <limits>

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/step/ccd_step_types.h"
#include "gauss6/geometry/feature_pair.h"
#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/geometry/pose.h"
#include "pair_tester.h"

namespace gauss6::detail {

struct StepState {
  StepState(const CcdBody* obstacles_in, int num_obstacles_in, const CcdBody& god_in, const CcdStepRequest& request,
            const CcdStepSettings& settings_in, CcdStepWorkspace* ws_in, CcdStepResult* result_in);
  StepState(const StepState&) = delete;
  StepState& operator=(const StepState&) = delete;

  // The inputs (ccd_step.h), checked by the first stage.
  const CcdBody* obstacles;
  int num_obstacles;
  const CcdBody& god;
  const Pose& X0;
  const CcdStepSettings& settings;
  CcdStepWorkspace* ws;
  CcdStepResult* result;
  const FeaturePair* hints;
  int num_hints;
  double lead_sweep;        // > 0: a motion expected to stop early (CcdStepRequest::lead_sweep)
  bool any_hit;             // the first hit found answers (CcdQuestion::kFreeOfContact)

  const CcdMotion& motion;  // result->motion: the enclosed motion from X0
  const double reach;       // max(min_separation, near_distance)
  const double rho;         // the god-object's radius (about G)
  int n = 1;                // sub-intervals
  int lead = 0;             // pieces searched ahead of the first sub-interval's rest (ccd_step.cpp plan_lead)
  MotionEnclosure e;        // the motion over the range being searched
  StartFrame start;         // the god-object at that range's start
  PairTester tester;        // tests on [tester.u0, tester.end()], earliest hit in *result
  // The part of [0, 1] that needs no more search, for every pair: the caller's
  // proof (CcdStepRequest::known_free), then the range the proximity list
  // answered (search_cached_pairs). The hints' pairs, searched over the whole
  // rest of the step first, are the exception a pair at a time (num_searched).
  double searched = 0;
  int num_searched = 0;     // hints[0 .. num_searched) were searched (valid or not)
  double u_cached = 0;      // the proximity list covers [0, u_cached] (0: not used)
  double near_u1 = 0;       // the near pairs listed (result->num_near_pairs >= 0) hold up to here
  // The proximity cache's list is for this step's meshes and settings, and
  // how far a point may have moved from its pose to X0 (infinite: unknown).
  bool cache_keyed = false;
  double cache_moved = std::numeric_limits<double>::infinity();
  bool budget_stopped = false;  // stop_on_budget ran: the result is final
};

// The triangle pair was searched over the whole step among the hints (then it
// needs no second search: ccd_step.cpp, search_hints).
bool searched(const StepState& s, int gf, int of, int o);
// A check (CcdQuestion::kFreeOfContact) has its answer: a hit.
bool answered(const StepState& s);
// The time a triangle pair within the reach (its boxes are: the descent's, or
// the proximity list's gap bound) is listed with in ws->candidates: a lower
// bound of the first u at which it can come within min_separation
// (StartFrame::earliest at min_separation: the narrow phase's question, so
// that a pair resting between min_separation and the reach, a flat tool on a
// dense plate, is cleared by one axis instead of bounded at the reach over all
// eleven). A pair that cannot before the window's end is a near pair only
// (kNearOnly: listed for the contact set at the stop pose, never tested) when
// the step keeps near pairs beyond min_separation, else dropped (kDropped);
// either is counted as an axis cull (no pair test).
inline constexpr double kNearOnly = std::numeric_limits<double>::infinity();
inline constexpr double kDropped = -std::numeric_limits<double>::infinity();
double candidate_time(StepState* s, const SweptBoxCache::PosedFace& g, const TriangleMesh& om, int of);
// Tests cand[0 .. num_cand) earliest-first (ws->candidates), skipping the
// pairs searched with the hints. False when the update's budget ran out
// first: the step then stopped where the untested candidates' time bounds
// prove it free (stop_on_budget).
bool test_candidates(StepState* s, int num_cand);

// The update's budget (CcdStepWorkspace::budget, update_budget.h): charges
// `count` pieces of work, true when it has run out (now or before); false without one.
inline bool charge(StepState* s, Work kind, long count) {
  return s->ws->budget != nullptr && s->ws->budget->spend(kind, count);
}
inline bool out_of_budget(const StepState& s) { return s.ws->budget != nullptr && s.ws->budget->exhausted(); }
// The result's counts of a triangle pair's narrow-phase work (PairTester),
// taken before its test so that the test is charged by what it did.
struct TestCounts {
  long boxes;
  int bounds, queries;
};
inline TestCounts test_counts(const StepState& s) {
  const CcdStepResult& r = *s.result;
  return {r.num_box_iterations, r.num_feature_culls + r.num_pair_tests, r.num_pair_tests};
}
// A triangle pair's narrow-phase test just run, begun at `before`: its
// set-up, its feature pairs' time bounds, their rigid queries and boxes.
inline bool charge_test(StepState* s, const TestCounts& before) {
  const TestCounts now = test_counts(*s);
  charge(s, Work::kPairTest, 1);
  charge(s, Work::kFeatureBound, now.bounds - before.bounds);
  charge(s, Work::kFeatureQuery, now.queries - before.queries);
  return charge(s, Work::kBox, now.boxes - before.boxes);
}
// The budget ran out with the motion proven free of every pair not yet
// tested up to u (at the step's reach), every pair tested searched to the
// window's end: the step stops there, a conservative hit with no pair, unless
// the first contact found is no later than u (then that hit is the step's
// answer). Either way the result says so (CcdStepResult::budget_exhausted).
void stop_on_budget(StepState* s, double u);
// What a fill of the proximity cache may still spend: node pairs (the
// background fill's, ProximityCacheSettings::fill_budget) and work units, its
// node pairs and the gap bounds of the triangle pairs they reach at the
// weights of update_budget.h (the update's fills at once,
// ProximityCacheSettings::fill_at_once). The fill's traversal takes no node
// pair once either is spent (take_node_pair), so it ends at most one node
// pair's triangle pairs (a leaf pair's) beyond its units.
struct FillAllowance {
  long node_pairs, units;
};
inline bool take_node_pair(FillAllowance* left) {
  if (left->node_pairs <= 0 || left->units <= 0) return false;
  --left->node_pairs;
  left->units -= work_units(Work::kNodePair, 1);
  return true;
}
// A fill of the proximity cache within *left (drawn on as it goes), spread
// over chunks charged to the update's budget (proximity_stages.cpp fill_some:
// true once complete); without a budget one call.
bool fill_within_budget(StepState* s, FillAllowance* left);
// Records cand[0 .. num_cand) as the near pairs for [u0, min(u1, u_hit)] (-1: none).
void set_near_pairs(StepState* s, int num_cand, double u0, double u1);

// Lists the candidate triangle pairs of obstacle o over the motion enclosed in
// `enc` from `frame` (the god-object at the range's start), the god boxes
// grown by `dist`: node pairs whose world boxes meet are then tested as
// oriented boxes (bvh.h: the god node's posed at u0, swept along the
// translation up to u_end, grown by what else its points may move, plus dist),
// and visit(gf, of, o) gets the rest (false: stop). It runs from the node pairs
// pending on `stack` (resume_candidate_pairs) for at most `budget` node pairs
// (a count, or a fill's FillAllowance*), counted in *num_node_pairs. The
// god-object's boxes are cached in `swept` (the step's, ws->swept, or a fill's
// own): call swept.next_interval() first whenever the enclosure or dist changed.
template <class Budget, class Visit, class Cut = NoCut>
TraversalStatus traverse(const StepState& s, const StartFrame& frame, const MotionEnclosure& enc, SweptBoxCache& swept,
                         double u_end, double dist, int o, BvhStack* stack, int* pending, Budget budget,
                         int* num_node_pairs, const Visit& visit, const Cut& cut = Cut{}) {
  const CcdBody& god = s.god;
  const SweptObbFrame obb_frame = frame.obb_frame(u_end, dist);
  const auto god_node_obb = [&](int node) -> const PosedObb& {
    return swept.get(swept.node_obbs, node, [&] { return obb_frame.pose(god.bvh->nodes[node]); });
  };
  // God boxes grown by dist once here (outward rounded), so the traversal
  // compares them with the obstacles' exact boxes as they are (margin 0
  // below): the same test as growing each obstacle box, without its roundings
  // per node pair.
  const auto box_over = [&](const Aabb& body) { return inflate(swept_box(enc, body), dist); };
  const auto god_node_box = [&](int node) {
    return swept.get(swept.nodes, node, [&] { return box_over(god.bvh->nodes[node].box); });
  };
  const auto god_face_box = [&](int face) {
    return swept.get(swept.faces, face, [&] { return box_over(triangle_box(*god.mesh, face)); });
  };
  const CcdBody& ob = s.obstacles[o];
  const auto separated = [&](int gi, int oi) { return node_pair_separated(god_node_obb(gi), ob.bvh->nodes[oi]); };
  return resume_candidate_pairs(*god.mesh, *god.bvh, *ob.mesh, *ob.bvh, god_node_box, god_face_box, /*margin=*/0,
                                stack, pending, budget, [&](int gf, int of) { return visit(gf, of, o); },
                                num_node_pairs, separated, cut);
}

// The stages of the proximity cache (proximity_stages.cpp; settings.cache.margin > 0):
// serve this step from the cache's list, or refill it at X0 first, searching
// [0, u_cached] from it (sets s->u_cached).
void serve_proximity_cache(StepState* s);
// After the step's searches: start or go on with the background fill of the
// next list, and note the step's start for the next step.
void fill_cache_in_background(StepState* s);
// Without a cache of its own (settings.cache.margin 0): [0, u_cached] from
// ws->lender's, read-only, when that list covers the rest of the step.
void serve_borrowed_list(StepState* s);

}  // namespace gauss6::detail
