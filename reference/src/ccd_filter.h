// The interval filter of the exact first contact (ccd_mesh.cpp): for one
// feature pair under the Cayley motion, decides in interval arithmetic (CGAL's
// Interval_nt) either that the pair cannot touch in [0, u_max], or gives a
// lower bound of where it may, so that mesh_first_contact isolates roots
// exactly (ccd_exact.cpp) only for the pairs the filter cannot rule out, in
// order of that bound. Internal to reference/.
//
// Soundness: every quantity is an interval enclosing the exact value for the
// exact meaning of the doubles (METHOD.md sections 1 and 4), so a pair is
// ruled out only when the exact answer rules it out.
#pragma once

#include <array>

#include "gauss6/geometry/feature_pair.h"
#include "gauss6/reference/ccd.h"

namespace gauss6::reference::detail {

// The motion's data enclosed in intervals, built once per step (opaque; see ccd_filter.cpp).
struct IntervalMotion;

struct IntervalMotionPtr {
  IntervalMotion* motion = nullptr;
  explicit IntervalMotionPtr(const ExactCayleyMotion& m);
  ~IntervalMotionPtr();
  IntervalMotionPtr(const IntervalMotionPtr&) = delete;
  IntervalMotionPtr& operator=(const IntervalMotionPtr&) = delete;
};

struct FilterVerdict {
  bool excluded = false;  // no contact in [0, u_max], proven
  double earliest = 0;    // otherwise: no contact in [0, earliest) (a double <= the pair's first contact)
};

// The pair's features as kPairSolvers take them (ccd_mesh.cpp): god points in
// the body frame, obstacle points in the world frame; a vertex is p[0], an edge
// p[0], p[1]. u_max in (0, 1]. Sets the FPU rounding mode itself.
FilterVerdict filter_pair(const IntervalMotion& motion, PairKind kind, const std::array<Vec3, 3>& god,
                          const std::array<Vec3, 3>& obstacle, double u_max);

}  // namespace gauss6::reference::detail
