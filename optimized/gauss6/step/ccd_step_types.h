// The data of the mesh-level CCD step (ccd_step.h): its settings
// (CcdStepSettings), what a call asks (CcdStepRequest, CcdQuestion, a motion
// already proven free: ProvenMotion), its result (CcdStepResult, the near pairs
// for the contact generation included) and its workspace (CcdStepWorkspace:
// the narrow phase's boxes, the descent's stack and its last cut
// (DescentFront), the candidate list, the god-object's swept boxes and the
// proximity cache), each allocated once. The step's stages (ccd_step.cpp,
// proximity_stages.cpp) share these through ccd_step_state.h.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/geometry/feature_pair.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/step/near_pairs.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/step/proximity_cache.h"
#include "gauss6/step/update_budget.h"

namespace gauss6 {

struct CcdStepSettings {
  CcdSettings narrow;                      // tolerances and min_separation of every pair test
  int max_sub_intervals = 16;              // u-ranges whose swept boxes are computed separately
  double sub_interval_angle = 0.1;         // radians of rotation per sub-interval (at most)
  double sub_interval_travel = 0.25;       // travel of G per sub-interval, in god-object radii (at most)
  ProximityCacheSettings cache;            // coherence between steps (proximity_cache.h; cache.margin 0: off)
  double near_distance = 0;                // also list the triangle pairs that may come within this (>=
                                           // min_separation) by the stop pose: the near pairs (CcdStepResult)
};

// The question a call of ccd_step answers.
enum class CcdQuestion {
  kFirstContact,   // where the motion first comes within narrow.min_separation (u_hit: the stop pose's)
  kFreeOfContact,  // whether the motion is free of contact itself: searched at min_separation 0, without
                   // near pairs or a cache of its own (ws->lender's list may serve), stopped at the first hit
                   // found (hit and status are the answer; u_hit and pair are then a hit's, not the first
                   // contact's: no stop pose). Filling no cache, it never goes on with a background fill.
};

// A motion the CCD proved free of contact at the settings' min_separation up
// to u: the motion of a CcdStepResult (`motion`, from the pose `from`).
// motion nullptr: none.
struct ProvenMotion {
  Pose from;
  const CcdMotion* motion = nullptr;
  double u = 0;
};

// What one call of ccd_step asks, apart from the settings it runs with: the
// motion, the question, the pairs to test first, what the caller has already
// proven of it, and how the caller expects it to go.
struct CcdStepRequest {
  Pose X0, X1;                             // the Cayley motion X0 -> X1 (poses of G, world frame)
  const FeaturePair* hints = nullptr;      // hints[0 .. num_hints): pairs likely to touch first (ccd_step)
  int num_hints = 0;
  double known_free = 0;                   // in [0, 1): the caller has proven [0, known_free] of the motion
                                           // free at the separation the question searches for: no search
                                           // covers it again (0: none)
  ProvenMotion proven;                     // a motion already proven free nearby: the prefix of X0 -> X1 it
                                           // proves (proven_prefix) is known free too
  double lead_sweep = 0;                   // > 0: a motion expected to stop early (a settling leg) searches its
                                           // first sub-interval in pieces, [0, 4^-k/n], [4^-k/n, 4^(1-k)/n],
                                           // ..., [1/(4n), 1/n], the first sweeping about this many times the
                                           // reach: a first contact met soon ends the search there (0: off)
  CcdQuestion question = CcdQuestion::kFirstContact;
  bool fill_cache = true;                  // go on with the proximity cache's background fill (cache.fill_budget
                                           // node pairs), and open an update: its calls share cache.fill_at_once
                                           // work units of fills at once; false for the later calls of one
                                           // update, whose budget the first spent
};

struct CcdStepResult {
  CcdStatus status = CcdStatus::kOk;       // kOk, kHalfTurn (split the step in halves),
                                           // kInvalidInput, or a pair test's give-up (hit kept conservative);
                                           // a pair test that refused its input (a coordinate beyond the
                                           // narrow phase's bound) makes the step kInvalidInput with a hit
                                           // at its window's start: never a miss
  bool hit = false;
  double u_hit = 1;                        // first possible contact over all pairs (<= u*); 1 when none
  FeaturePair pair;                        // the pair that gave u_hit (when hit)
  double time_tolerance_reached = 0, distance_reached = 0;  // of that pair's test
  CcdMotion motion;                        // the enclosed motion used (for make_stop_pose)
  int num_sub_intervals = 0;               // the sub-intervals planned, lead pieces included (CcdStepRequest::lead_sweep)
  int num_node_pairs = 0, num_triangle_pairs = 0, num_pair_tests = 0;
  int num_axis_culls = 0;                  // triangle pairs dropped whole by a separating-axis time bound (no pair test)
  int num_feature_culls = 0;               // feature pairs dropped by their own time bound (no pair test)
  long num_box_iterations = 0;             // narrow-phase boxes, all tests together
  // Near pairs (settings.near_distance > 0): when num_near_pairs >= 0, ws->near_pairs(num_near_pairs)
  // holds every triangle pair that can come within near_reach (= max(min_separation, near_distance)) of
  // each other under the exact motion at any u in [near_u0, u_hit] (the last sub-interval searched), so
  // the contact generation at the stop pose can test those instead of descending the trees again (with
  // the stop pose's deviation taken off near_reach). -1: no such list (the step stopped before any
  // descent, or the candidate buffer overflowed).
  int num_near_pairs = -1;
  double near_u0 = 0, near_reach = 0;
  bool cache_filled = false;               // the proximity cache was (re)filled at X0 (CcdStepWorkspace)
  bool cache_refilled = false;             // a background fill of the cache was completed and put in use
  int num_fill_node_pairs = 0;             // node pairs that the cache's fills (at once or in the background) tested
  int num_fill_triangle_pairs = 0;         // triangle pairs whose gap those fills bounded
  double u_cached = 0;                     // [0, u_cached] searched from the proximity cache (0: not used)
  // The update's budget (CcdStepWorkspace::budget) ran out in this step or before it: the step stopped
  // at the end of what it had proven, a conservative hit at u_hit with no pair (pair FeaturePair{},
  // distance_reached NaN), unless the first contact was already found (then hit, u_hit and pair are
  // that contact's). status stays kOk: nothing was given up, only left for the next update.
  bool budget_exhausted = false;
};

// The cut where a descent of the trees stopped (resume_candidate_pairs: the
// node pairs found apart, the leaf pairs, those left pending), obstacle by
// obstacle, so that the next descent starts there instead of at the root
// pair: every leaf pair it could reach lies below exactly one of them. The
// pieces of a settling leg, and the legs of one god-object update, sweep the
// same standing proximity (a god-object wedged in a hole, the legs of a
// refused settle's step), which each would descend again from the root. A cut is sound for any motion; starting
// from it only skips the tests of the pairs above it, so a descent may list
// a few more candidate triangle pairs than one from the root (and its result
// may differ from a fresh workspace's within the tolerances). Within one step
// its pieces always share it; across steps only when `carry` is set (else
// each step starts at the root pairs, so its result does not depend on the
// steps run before in the workspace). It is keyed by the trees (pointers) and
// only ever refines: the runtime carries it over the legs of one god-object
// update and clears it at the next (clear()). Two buffers: the cut read and
// the one written.
struct DescentFront {
  using NodePair = std::pair<int32_t, int32_t>;
  DescentFront(int capacity, int obstacle_capacity)
      : pairs{std::vector<NodePair>(static_cast<size_t>(std::max(capacity, 0))),
              std::vector<NodePair>(static_cast<size_t>(std::max(capacity, 0)))},
        begin{std::vector<int>(static_cast<size_t>(std::max(obstacle_capacity, 0) + 1)),
              std::vector<int>(static_cast<size_t>(std::max(obstacle_capacity, 0) + 1))} {
    obstacles.reserve(static_cast<size_t>(std::max(obstacle_capacity, 0)));
  }
  std::vector<NodePair> pairs[2];  // [cur]: the cut read, [1 - cur]: the one being written
  std::vector<int> begin[2];       // obstacle o's pairs: [begin[o], begin[o + 1])
  int cur = 0;
  bool carry = false;                     // a step starts from the last step's cut (see above)
  bool ready = false;                     // pairs[cur] is a cut of the trees below (keys)
  const Bvh* god = nullptr;               // the keys
  std::vector<const Bvh*> obstacles;      // capacity obstacle_capacity, reserved (never grows)
  int size = 0;                           // of the cut being written
  bool overflow = false;
  void clear() { ready = false; }
  // The cut `other` reads, copied to be read here (none when it does not fit).
  void copy_from(const DescentFront& other);
  int obstacle_capacity() const { return static_cast<int>(begin[0].size()) - 1; }
  // The cut read was made for these trees.
  bool keyed(const CcdBody& g, const CcdBody* obs, int num_obs) const {
    bool k = ready && god == g.bvh && static_cast<int>(obstacles.size()) == num_obs;
    for (int o = 0; k && o < num_obs; ++o) k = obstacles[static_cast<size_t>(o)] == obs[o].bvh;
    return k;
  }
  // Writing: a new cut, obstacle o's part starting now, a pair of it.
  void start() {
    size = 0;
    overflow = false;
  }
  void start_obstacle(int o) { begin[1 - cur][static_cast<size_t>(o)] = size; }
  void add(int g, int h) {
    if (size == static_cast<int>(pairs[1 - cur].size())) {
      overflow = true;
      return;
    }
    pairs[1 - cur][static_cast<size_t>(size++)] = {g, h};
  }
  // The cut written becomes the one read, for these trees (none if it
  // overflowed); num_obs <= obstacle_capacity().
  void finish(const CcdBody& g, const CcdBody* obs, int num_obs) {
    begin[1 - cur][static_cast<size_t>(num_obs)] = size;
    ready = !overflow;
    if (!ready) return;
    cur = 1 - cur;
    god = g.bvh;
    obstacles.clear();
    for (int o = 0; o < num_obs; ++o) obstacles.push_back(obs[o].bvh);
  }
  const NodePair* read(int o, int* n) const {
    const std::vector<int>& b = begin[cur];
    *n = b[static_cast<size_t>(o) + 1] - b[static_cast<size_t>(o)];
    return pairs[cur].data() + b[static_cast<size_t>(o)];
  }
};

// Everything ccd_step needs, allocated once.
struct CcdStepWorkspace {
  // The default capacities. obstacle_capacity: the most obstacles the proximity
  // cache can be keyed by (a step with more is served without it; nothing grows
  // in a step).
  static constexpr int kBoxCapacity = 1 << 14, kStackCapacity = 1024, kCandidateCapacity = 1 << 14,
                       kObstacleCapacity = 16;
  explicit CcdStepWorkspace(int box_capacity = kBoxCapacity, int stack_capacity = kStackCapacity,
                            int candidate_capacity = kCandidateCapacity, int obstacle_capacity = kObstacleCapacity)
      : narrow(box_capacity),
        stack(stack_capacity),
        candidates(static_cast<size_t>(std::max(candidate_capacity, 0))),
        cache(std::max(candidate_capacity, 0), stack_capacity, obstacle_capacity),
        front(std::max(candidate_capacity, 0), obstacle_capacity) {}
  // A candidate triangle pair of one sub-interval and a lower bound of its first contact parameter.
  struct Candidate {
    TrianglePair pair;
    double earliest;
  };
  // The triangle pair that stopped the last step run in this workspace
  // (coherence): when it is among a step's hints it is searched first. A
  // god-object pressed into a corner is stopped by the same pair step after
  // step, at once; found first, its hit ends the searches of the sliding
  // contacts there, where each would otherwise search the whole step (a
  // hundred narrow-phase boxes or more each).
  FeaturePair last_hit;
  CcdWorkspace narrow;
  BvhStack stack;
  std::vector<Candidate> candidates;  // tested earliest-first; overflow is tested in traversal order
  // The first num candidates' triangle pairs as near pairs (CcdStepResult::num_near_pairs; -1: no list).
  NearPairs near_pairs(int num) const {
    return {candidates.empty() ? nullptr : &candidates[0].pair, num, sizeof(Candidate)};
  }
  SweptBoxCache swept;                // god boxes of the current sub-interval
  ProximityCache cache;               // coherence between steps (proximity_cache.h)
  DescentFront front;                 // coherence between descents (a step's pieces, an update's legs)
  // Another workspace, whose proximity list and descent front the steps run
  // here borrow, read-only (the runtime's checks of a detour's direct motion
  // borrow the legs' workspace). Its list serves the steps run here with their
  // own cache off (settings.cache.margin 0): a step that stays within that
  // list's margin of its pose, and searches no farther than the list's reach,
  // takes its candidates from it instead of descending the trees; it never
  // fills, refills or otherwise changes it. Its last cut (DescentFront) is
  // copied at the start of each step run here (kept when front.carry). nullptr: none.
  const CcdStepWorkspace* lender = nullptr;
  // The god-object update's budget (update_budget.h), charged with the work the steps run here do;
  // once it has run out a step searches no further (CcdStepResult::budget_exhausted). nullptr: none.
  UpdateBudget* budget = nullptr;
};

}  // namespace gauss6
