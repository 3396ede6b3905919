// Axis-aligned boxes: the bounding volume both implementations share (the
// optimized tree's nodes, the exact reference's culling), with the two
// operations every traversal runs: the overlap test and the outward-rounded
// growth by a margin.
#pragma once

#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/rounding.h"

namespace gauss6 {

// The points lo <= x <= hi (componentwise). Default: the single point 0.
struct Aabb {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
};
inline bool overlap(const Aabb& a, const Aabb& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

// box grown by margin on every side, rounded outward. Inline: the traversal
// calls it for every node pair.
inline Aabb inflate(const Aabb& box, double margin) {
  if (margin == 0) return box;
  Aabb out;
  for (int i = 0; i < 3; ++i) {
    const Interval side = widen({box.lo[i], box.hi[i]}, Upper{margin});
    out.lo[i] = side.lo;
    out.hi[i] = side.hi;
  }
  return out;
}

}  // namespace gauss6
