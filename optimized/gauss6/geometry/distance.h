// Distances between triangles and their features, the bottom layer of the
// collision pipeline: closest points (point/triangle, segment/segment) and
// rounding-safe separating-axis lower bounds of the distance of two triangles.
// The tree, the motion bounds, the narrow phase and the contact generation all
// build on these; this header includes none of them.
//
// Frames: any one frame for all the corners of a call (doubles). No
// allocation, no locks, no exceptions.
#pragma once

#include <algorithm>
#include <limits>

#include "gauss6/numeric/error_allowances.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/rounding.h"

// Forces a hot lambda inline (GCC and Clang), as GAUSS6_ALWAYS_INLINE in rounding.h.
#define GAUSS6_ALWAYS_INLINE_LAMBDA __attribute__((always_inline))

namespace gauss6 {

// Closest points. Point/triangle: a point of triangle (a, b, c) whose computed
// distance from p is p's exact distance from the triangle to rounding
// (distance.cpp). Point/segment: the point of [a, b] nearest p by the edge
// rule, within 200 u M + 2^-533 of the exact one (M the coordinates'
// magnitude). Segment/segment: parameters s on [p0, p1] and t on [q0, q1] of a
// pair of closest points.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);
void closest_segment_parameters(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double* s,
                                double* t);

// Separating axes of two triangles A and B given by their corners (one frame,
// doubles): the two face normals and the nine edge cross products, or, when
// InPlane is set and the two triangles' planes lie within kInPlaneSine of
// parallel, the two normals and each face's normal crossed with its own edges
// (in-plane axes: two parallel triangles side by side, a flat tool's face over
// a dense flat tessellation, have all eleven axes along their common normal,
// and only these separate them; the distance bounds that list pairs, the
// proximity list's fill and the contact generation, set it; the time bounds,
// whose pairs are already listed as near, need not pay for them). Any set of
// axes gives a lower bound. Calls
// on_axis(a, gap, side) for each axis a that proves a positive gap, with gap a
// lower bound of the distance of the two triangles' projections on a / |a|
// (where that quotient is below 2^-600, gap may lie a little below 0, down to
// -2^-600, next_down's absolute widening: still a lower bound, and the callers'
// comparisons drop it) and side = +1 when B lies beyond A along a (-1 when
// before it); on_axis returns true to stop. Machine-checked:
// proofs/AxisAllowances.v axis_gap_distance.
//
// Proof. For convex sets and any vector a != 0, dist(A, B) >= (min_B a.y -
// max_A a.x) / |a| (or the mirror). Whatever the rounded axis a is, the
// computed difference of two projections, less kAxisProductRounding |a|_1 s +
// kUnderflowFloor (s the largest coordinate of the six corners) and rounded,
// is below the exact gap along a, for |a|_1 >= kNormFloor (a shorter axis is
// dropped: below it the product kAxisProductRounding |a|_1 underflows and the
// slack no longer covers the projections' rounding, relative to |a|_1 s;
// kUnderflowFloor covers the projections' own underflow). Dividing by norm_up(|a|,
// kRelativeRoundingWide) (rounding.h; >= the exact |a|, also where the squares
// underflow: proofs/Allowances.v, norm_upper_bound), the quotient rounded
// down, covers the roundings of the norm and the quotient.
// A zero or non-finite axis proves nothing (NaN or inf is dropped).
// extra: one more axis to try first (any vector; nullptr: none), e.g. the
// direction between the closest points of two features.
//
// Features. A vertex or an edge is given as a degenerate triangle (a vertex:
// its point thrice; an edge: its ends, the second twice) with its Shape, the
// number of its distinct corners. Its normal and the cross products of its
// zero edges are zero, and an edge's two edges (A[1] - A[0] and A[0] - A[2] =
// -(A[1] - A[0]), exactly) give the same axis up to sign, hence the same gap
// (the projections negate exactly): so only the axes a Shape can have are
// formed (a vertex and a face: the face's normal; two edges: their cross
// product), in the order of the 11, and the result is that of the 11.
enum class Shape : int { kVertex = 1, kEdge = 2, kTriangle = 3 };

// The sine of the angle between two triangles' planes below which
// for_each_separating_axis tries their in-plane axes (a heuristic: any axis
// is a sound bound; these cost six more projections, and only parallel
// planes need them).
inline constexpr double kInPlaneSine = 0.1;

// One side of the test, prepared once where it meets several others (a god
// face posed at a sub-interval's start: StartFrame::posed_face): its corners
// (a feature's repeated, as above), its edges P1 - P0, P2 - P1, P0 - P2, its
// normal e0 x e1 (a triangle's; zero otherwise) and the largest |coordinate|
// of its Shape's corners.
struct SatSide {
  Vec3 P[3], e[3], n;
  double abs_max = 0;
};
template <Shape S = Shape::kTriangle>
GAUSS6_ALWAYS_INLINE SatSide sat_side(const Vec3 P[3]) {
  constexpr int np = static_cast<int>(S);
  SatSide t;
  for (int k = 0; k < 3; ++k) t.P[k] = P[k];
  for (int k = 0; k < np; ++k) t.abs_max = std::max(t.abs_max, P[k].cwiseAbs().maxCoeff());
  t.e[0] = P[1] - P[0];
  t.e[1] = P[2] - P[1];
  t.e[2] = P[0] - P[2];
  t.n = np == 3 ? Vec3(t.e[0].cross(t.e[1])) : Vec3::Zero();
  return t;
}

template <Shape ShapeA = Shape::kTriangle, Shape ShapeB = Shape::kTriangle, bool InPlane = false, class OnAxis>
GAUSS6_ALWAYS_INLINE void for_each_separating_axis(const SatSide& A, const SatSide& B, OnAxis&& on_axis,
                                                   const Vec3* extra = nullptr) {
  constexpr int na = static_cast<int>(ShapeA), nb = static_cast<int>(ShapeB);
  const double s = std::max(A.abs_max, B.abs_max);
  const auto along = [&](const Vec3& a) GAUSS6_ALWAYS_INLINE_LAMBDA {
    double a_lo = a.dot(A.P[0]), a_hi = a_lo, b_lo = a.dot(B.P[0]), b_hi = b_lo;
    for (int k = 1; k < na; ++k) {
      const double pa = a.dot(A.P[k]);
      a_lo = std::min(a_lo, pa);
      a_hi = std::max(a_hi, pa);
    }
    for (int k = 1; k < nb; ++k) {
      const double pb = a.dot(B.P[k]);
      b_lo = std::min(b_lo, pb);
      b_hi = std::max(b_hi, pb);
    }
    const double side = b_lo - a_hi >= a_lo - b_hi ? 1.0 : -1.0;
    // An axis with |a|_1 below kNormFloor proves nothing: kAxisProductRounding
    // |a|_1 would underflow and no longer cover the projections' rounding.
    const double a_1 = a.cwiseAbs().sum();
    if (!(a_1 >= kNormFloor)) return false;
    const double proven = std::max(b_lo - a_hi, a_lo - b_hi) - (kAxisProductRounding * a_1 * s + kUnderflowFloor);
    if (!(proven > 0)) return false;  // also on NaN
    const double g = (Lower{proven} / norm_up(a.norm(), kRelativeRoundingWide)).v;
    if (!(g < std::numeric_limits<double>::infinity())) return false;
    return on_axis(a, g, side);
  };
  if (extra && along(*extra)) return;
  if (na == 3 && along(A.n)) return;
  if (nb == 3 && along(B.n)) return;
  if constexpr (InPlane && na == 3 && nb == 3) {
    // (Not for a degenerate triangle, whose zero normal gives no plane: a
    // feature passed as one keeps the axes of its Shape.)
    const double aa = A.n.squaredNorm(), bb = B.n.squaredNorm();
    if (aa > 0 && bb > 0 && A.n.cross(B.n).squaredNorm() <= kInPlaneSine * kInPlaneSine * aa * bb) {
      // Parallel planes: the in-plane axes instead of the edge cross
      // products, which lie within kInPlaneSine of the normals and prove
      // about the normals' gap (a peg's side along a hole's wall, which no
      // axis separates, is tried on eight axes, not seventeen).
      for (int i = 0; i < 3; ++i)
        if (along(A.n.cross(A.e[i]))) return;
      for (int j = 0; j < 3; ++j)
        if (along(B.n.cross(B.e[j]))) return;
      return;
    }
  }
  // Edges: a triangle's three, an edge's one, a vertex's none.
  constexpr int edges_a = na == 3 ? 3 : na - 1, edges_b = nb == 3 ? 3 : nb - 1;
  for (int i = 0; i < edges_a; ++i)
    for (int j = 0; j < edges_b; ++j)
      if (along(A.e[i].cross(B.e[j]))) return;
}
template <Shape ShapeA = Shape::kTriangle, Shape ShapeB = Shape::kTriangle, class OnAxis>
GAUSS6_ALWAYS_INLINE void for_each_separating_axis(const Vec3 A[3], const Vec3 B[3], OnAxis&& on_axis,
                                                   const Vec3* extra = nullptr) {
  for_each_separating_axis<ShapeA, ShapeB>(sat_side<ShapeA>(A), sat_side<ShapeB>(B), on_axis, extra);
}

// Separating-axis bound of the distance of two triangles: the largest gap
// proven along for_each_separating_axis's axes with InPlane, rounding included (0
// when none proves a positive gap), returned as soon as one axis proves more
// than `enough`. Inline: the contact generation calls it for every candidate
// triangle pair.
inline double triangle_gap_lower_bound(const SatSide& A, const SatSide& B, double enough) {
  double best = 0;
  for_each_separating_axis<Shape::kTriangle, Shape::kTriangle, /*InPlane=*/true>(
      A, B, [&](const Vec3&, double g, double) GAUSS6_ALWAYS_INLINE_LAMBDA {
        best = std::max(best, g);
        return best > enough;
      });
  return best;
}
inline double triangle_gap_lower_bound(const Vec3 A[3], const Vec3 B[3], double enough) {
  return triangle_gap_lower_bound(sat_side(A), sat_side(B), enough);
}

}  // namespace gauss6
