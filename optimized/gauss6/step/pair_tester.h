// The CCD step's pair tester (private to the library): runs the owned feature
// pairs of one (god triangle, obstacle triangle) pair, in the order of the
// feature-pair table (feature_pair.h), through the rigid narrow-phase queries
// (ccd.h) on the window [u0, best u so far], after a box filter and a time
// bound per feature pair; keeps the earliest hit in the step's result.
#pragma once

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/step/ccd_step_types.h"
#include "gauss6/geometry/mesh.h"
#include "gauss6/ccd/motion_bounds.h"

namespace gauss6::detail {

// Runs the owned feature pairs of one (god triangle, obstacle triangle) pair on
// the window [u0, *u_best]; lowers *u_best and records the pair on a hit.
struct PairTester {
  const CcdMotion* motion;
  const MotionEnclosure* sub;  // the motion over the sub-interval [u0, u1]
  const CcdStepSettings* settings;
  CcdWorkspace* ws;
  CcdStepResult* result;
  double u0, u1;  // the sub-interval; tests search [u0, min(u1, best u so far)]
  SweptBoxCache* swept = nullptr;  // god vertex boxes over *sub, shared by the pairs of the sub-interval
  const StartFrame* start = nullptr;  // the god-object at u0 and its motion bounds
  double reach = 0;                   // the narrow phase's min_separation

  // Once a pair hit at u_b, later pairs search only up to u_b - time_tolerance:
  // a contact in (u_b - tol, u_b] cannot lower the step's answer by more than
  // the tolerance, and the step reports u_b - tol (see ccd_step), which is then
  // <= u* for those pairs too.
  double end() const { return result->hit ? std::min(u1, result->u_hit - settings->narrow.time_tolerance) : u1; }
  bool done() const { return result->hit && end() <= u0; }

  // Counts a pair test and keeps its hit when it is the earliest so far.
  void consider(const CcdResult& r, const FeaturePair& p);
  // Tests the owned feature pairs of god face gf and face `of` of obstacle `obstacle`.
  void test(const TriangleMesh& gm, const Bvh& gb, int gf, const TriangleMesh& om, const Bvh& ob, int of,
            int obstacle);
};

}  // namespace gauss6::detail
