// Coherence between CCD steps (ccd_step.h): the proximity cache. A list of the
// triangle pairs near the god-object at one pose, kept from one step to the
// next so that a god-object resting or sliding in contact takes its candidate
// pairs from the list instead of descending the trees again. Its settings
// (ProximityCacheSettings: the margins, the background fill's budget and the
// named policy constants) and its storage (ProximityCache, allocated once).
// The stages that serve, refill and fill it in the background are in
// gauss6/step/proximity_stages.cpp; the step calls them (gauss6/step/ccd_step.cpp).
//
// Lengths in scene units; the runtime states its margins in units of the
// scene's delta (RuntimeSettings) and resolves them here.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

struct ProximityCacheSettings {
  double margin = 0;        // keep the pairs within the reach plus this (scene units) at a pose in contact,
                            // and serve later steps from them while no point has moved farther than this
                            // from that pose (0: no cache; the runtime uses 64 delta)
  double margin_max = 0;    // a list's margin grows up to this (>= margin) with the god-object's speed
                            // (0: every list's margin is `margin`; the runtime uses 256 delta)
  long fill_budget = 0;     // node pairs per step that fill the next list in the background while the
                            // one in use serves (0: no background fill; the runtime uses 300)
  long fill_at_once = 2000;  // work units (update_budget.h: the node pairs and the triangle pairs' gap
                             // bounds) an update's steps spend at most, together, on lists they need now
                             // (the first list, or a new one while a list is kept), and one leaf pair's
                             // triangle pairs beyond: the rest goes on at the next steps, which descend the
                             // trees meanwhile (no update pays a whole fill: at a million triangles a list's
                             // fill costs several updates' time). An update is the steps from one whose
                             // request opens it (CcdStepRequest::fill_cache) to the next such
  // The policy, dimensionless (gauss6/step/proximity_stages.cpp states where each acts).
  double steps_per_list = 6;       // a new list's margin spans about this many steps like the last one
  double slow_fraction = 0.25;     // a step that moves at most this fraction of the margin refills at once;
                                   // a first search from the list covers at most the range over which no
                                   // point moves this fraction of the margin
  double max_probe_sub_intervals = 0.5;  // ... and only when that range is shorter than this many sub-intervals
  int min_uses = 2;                // a fill that served fewer later steps than this ...
  int skip_after_poor_fill = 8;    // ... makes the next this many chances to refill pass (plain descents)
  double fill_lead = 0.75;         // a background fill's pose lies this fraction of its margin past the pose
                                   // the god-object reaches when the fill is due
  double triangle_margin = 0.25;   // a list's margin is at most this many times the bodies' triangle size
                                   // (ProximityCache::triangle_size): its pairs then grow as the triangles
                                   // near the contact, not as their square once the margin outgrows them
};

// The settings can be used: margins finite and >= 0, policy constants in range
// (steps_per_list > 0, slow_fraction and fill_lead in (0, 1], max_probe_sub_intervals
// in (0, 1], min_uses >= 1, skip_after_poor_fill >= 0, fill_budget >= 0, fill_at_once >= 1,
// triangle_margin > 0 and finite).
bool valid_proximity_cache_settings(const ProximityCacheSettings& s);

// The lists, allocated once (capacity: pairs a list holds; stack_capacity: the
// background fill's descent; obstacle_capacity: obstacles a list can be keyed
// by: a step with more obstacles than this is served without the cache).
//
// pairs[0 .. num_pairs) hold every triangle pair not proven farther than
// reach + margin apart with the god-object at the exact pose ref: so at any
// god pose whose every point lies within `margin` of its place at ref, every
// pair that may lie within `reach` is among them. It is keyed by the
// god-object's and the obstacles' meshes and BVHs (pointers), the reach and
// the settings' margins; clear() it when a mesh behind the same pointers
// changes. Each list has its own margin (ProximityCacheSettings::margin_max).
struct ProximityCache {
  ProximityCache(int capacity, int stack_capacity, int obstacle_capacity)
      : pairs(static_cast<size_t>(std::max(capacity, 0))),
        by_gap(static_cast<size_t>(std::max(capacity, 0))),
        near_ids(static_cast<size_t>(std::max(capacity, 0))),
        fill(std::max(capacity, 0), stack_capacity),
        obstacle_capacity(std::max(obstacle_capacity, 0)) {
    obstacles.reserve(static_cast<size_t>(this->obstacle_capacity));
  }
  // gap: a lower bound of the pair's distance at ref; radius: the largest
  // |r_B| of the god triangle's corners. A step whose points move at most
  // shift + turn |r_B| from ref keeps the pair farther apart than
  // gap - shift - turn radius.
  struct Pair {
    double gap, radius;
    int32_t god_face, obstacle_face, obstacle;
  };
  std::vector<Pair> pairs;
  int num_pairs = -1;            // -1: empty (never filled, or the pairs did not fit)
  // The list's pairs by gap, indexed when it is put in use: the ids of
  // pairs[0 .. num_pairs) in kGapBuckets buckets of gap_width each over
  // [0, reach + margin] (the last takes the rest), each in increasing id order
  // (bucket k: by_gap[bucket_begin[k] .. bucket_begin[k + 1])), and the
  // largest radius of its pairs: a step searches only the buckets that can
  // hold a pair within its reach, not the whole list (a list grows faster than
  // the meshes: pairs within a margin of delta's per area, the square of the
  // triangles' density once the margin outgrows them). near_ids: a step's
  // ids, put back in list order (the same candidates in the same order as a
  // scan of the whole list).
  static constexpr int kGapBuckets = 16;
  std::vector<int32_t> by_gap, near_ids;
  int bucket_begin[kGapBuckets + 1] = {};
  double gap_width = 0, max_radius = 0;
  Pose ref;
  double reach = 0, margin = 0;  // margin: this list's
  double margin_min = 0, margin_max = 0;  // the settings it was filled under (keys)
  int uses = 0;  // later steps served since the fill
  int rest = 0;  // chances to refill still to pass over (ProximityCacheSettings::skip_after_poor_fill)
  bool budget_cut = false;  // a fill a step needed was cut short (budget, or its bound): it goes on in the
                            // background, and no other starts at once, until it is put in use or dropped
                            // (the god-object went elsewhere)
  long at_once_left = 0;    // work units this update's fills at once may still spend (< 0: spent, and
                            // overrun by that much; ProximityCacheSettings::fill_at_once)
  // The keyed bodies' triangle size: the smallest over the bodies of the mean
  // longest edge of kSizeSamples of its triangles, evenly spaced in index
  // (0: none measured); measured when a fill sets the keys (no list in use).
  static constexpr int kSizeSamples = 64;
  double triangle_size = 0;
  CcdBody god;
  std::vector<CcdBody> obstacles;  // the keys; capacity obstacle_capacity, reserved here (never grows)
  // A fill in progress (ProximityCacheSettings::fill_budget): the same kind
  // of list for the pose `ref` (where the god-object is heading) and its own
  // margin, built a budget of node pairs per step in the background while the
  // list above still serves, then swapped in; finished, within the update's
  // fill_at_once, when a step needs it first. Same keys as the list above
  // (the keys above are the fill's when no list is in use: the first fill).
  struct Fill {
    Fill(int capacity, int stack_capacity) : pairs(static_cast<size_t>(capacity)), stack(stack_capacity) {}
    std::vector<Pair> pairs;
    int num_pairs = 0;
    Pose ref;
    double margin = 0;
    CcdMotion motion;  // still at ref (or the step it started in, when ref is that step's start)
    BvhStack stack;    // the descent's pending node pairs: stack.items[0 .. pending)
    int pending = 0;
    // The god-object's boxes at ref grown by swept_dist (the reach plus the
    // margin), kept over the steps the fill takes: its pose does not move, so
    // each chunk of the fill reuses the boxes the chunks before it posed.
    SweptBoxCache swept;
    double swept_dist = -1;  // the grow of the boxes in swept (-1: none yet)
    int obstacle = 0;  // the obstacle being descended
    long cost = 0;     // node pairs tested so far
    bool active = false, complete = false;
  } fill;
  long fill_cost = 0;  // node pairs of the last fill completed
  Pose last_x0;        // the start of the last step (for the background fill's pose)
  bool has_last = false;
  int obstacle_capacity = 0;
  void clear() {
    num_pairs = -1;
    fill.active = false;
  }
};

}  // namespace gauss6
