// The narrow phase's box bisection (private to the library: not installed):
// a depth-first search over u-intervals in increasing u, each deciding by an
// inner search over the feature parameters (a, b) whether it may hold a
// contact, from interval enclosures of the feature difference F(u, a, b)
// that each query supplies. Also the input checks and refusal every query
// shares. Used by rigid_queries.cpp, linear_queries.cpp and u_filter.h.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "gauss6/ccd/ccd.h"
#include "gauss6/numeric/error_allowances.h"

namespace gauss6::ccd_detail {

using Box = CcdWorkspace::Box;

// A query window inside [0, 1], and settings the bisection can honour.
bool valid_window(double u0, double u1);
bool valid_settings(const CcdSettings& s);

// Heuristic weights of the three box dimensions: how much F can change across
// the full range of each (scene units). They steer the splitting only.
struct Scales { double u, a, b, coordinate; };

// The bisection: an outer depth-first search over u-intervals, left half first,
// so u-intervals are settled in increasing u; for each u-interval U an inner
// depth-first search over the feature parameters decides whether U may hold a
// contact. The inner search of U starts from the parameter boxes its parent
// interval could not exclude (its "front"), not from the whole domain: a box
// excluded over a u-interval is excluded over every part of it.
//
// Proof of the guarantee. Let (u*, a*, b*) be a first contact (|F|_2 <= d with
// d = min_separation). A parameter box P is dropped by an inner search only if
// (i) the enclosure of F over U x P proves |F|_2 > d on all of U x P (and so on
// every sub-interval of U): see excludes() (vertex/face, rigid: over U x (P cut
// by the triangle), the only part of P that can hold a contact), or
// (ii) (vertex/face) a_lo + b_lo > 1 in floating point, which implies the exact
// sum exceeds 1 (1 is a double and rounding is monotone): P lies outside the
// triangle, or
// (iii) the projections of F on an axis n (any nonzero vector of doubles) lie
// beyond d |n| on one side: |F|_2 >= |n.F| / |n| > d. For fixed u, F is affine
// in the feature parameters, so n.F over P lies between its values at P's
// corners (vertex/face, rigid: at the points whose hull holds P cut by the
// triangle, see rigid_vertex_face()), and each corner's value over U lies
// in n . (the corner's enclosure): the hull of those scalar intervals encloses
// n.F on U x P. (The
// axis-aligned hull of F loses up to a factor sqrt(3) on a diagonal n: a pair
// 1.1 d apart along (1, 1, 1) is never excluded by (i), whatever the split.)
// Splits share the double midpoint, so children cover their parent
// exactly, and a front passed to the halves of U is every box of U's search not
// dropped. Hence a u-interval is dropped only when it holds no contact. The
// outer search visits u-intervals in increasing order and stops at the first
// one it accepts (or gives up at), so the interval holding u* is never passed:
// u_hit = U.lo <= u*.
//
// Guide (rigid queries). The axis of (iii) is re-chosen for each u-interval U:
// the difference of the features' nominal closest points at U.lo (the
// direction conservative advancement would use; it separates the two convex
// features at U.lo, and stays separating over a U short enough). Before its
// inner search, U is dropped whole when the u-filter's separating-axis test
// (UFilter, (2)) with this axis proves the features' projections more than
// d |n| apart over U: the same test as (iii) for all parameters at once, with
// the motion projected on n before it is enclosed over U, so a motion sliding
// across n does not widen it (a corner's box over U would). With
// early_hit, the outer search also accepts U.lo at once when F at U.lo and
// those closest parameters is proven within d + distance_tolerance (the
// acceptance rule of filtered_bisect()'s early hit): everything before U.lo is
// settled, so u_hit = U.lo <= u* still holds (reported with
// time_tolerance_reached = 0: the distance bound holds at u_hit itself).
//
// Accuracy. A u-interval is accepted when it is at most time_tolerance wide and
// the inner search found a parameter box on which F is not excluded and cannot
// usefully be refined (its parameter widths move F by less than the u-width
// does, or by less than distance_tolerance). Every point of that box satisfies
// |F|_inf <= max |F's bounds|, reported as distance_reached (Euclidean, at
// u = u_hit and the box's corner (a_lo, b_lo), a valid feature point).
//
// Memory: the workspace array is a stack of blocks, one per pending u-interval
// (LIFO, as the outer search is depth-first): a header box (u: the interval;
// b[0]: the index of the header below) followed by the interval's front.
// True when the enclosure F proves |F|_2 > d on its whole box: either one
// coordinate misses [-d, d] (then |F|_2 >= |F|_inf > d), or the sum of the
// squared distances of the intervals from 0, rounded down, exceeds d^2 rounded
// up. False for NaN bounds (every comparison with NaN is false).
inline bool excludes(const IVec3& F, double d) {
  Lower sum{0};
  for (const Interval& c : F) {
    if (c.lo > d || c.hi < -d) return true;
    const double m = c.lo > 0 ? c.lo : (c.hi < 0 ? -c.hi : 0.0);  // distance of [lo, hi] from 0
    sum = sum + sqr(Lower{m});
  }
  return sum > sqr(Upper{d});
}

// n . x for a double vector n and an interval vector x, outward rounded.
GAUSS6_ALWAYS_INLINE Interval along(const Vec3& n, const IVec3& x) {
  return n[0] * x[0] + n[1] * x[1] + n[2] * x[2];
}

// Enclosures of F at the corners of a parameter box (up to 5: see
// rigid_vertex_face()), each over the box's whole u-range; F over the box
// lies in their hull (see bisect()).
struct Corners {
  IVec3 c[5];
  int n = 0;
  IVec3 hull() const {
    IVec3 h = c[0];
    for (int k = 1; k < n; ++k)
      for (int i = 0; i < 3; ++i) h[i] = {std::min(h[i].lo, c[k][i].lo), std::max(h[i].hi, c[k][i].hi)};
    return h;
  }
};

// The features' nominal closest points at some u (heuristic, from the double
// motion): the axis F points along there (zero when unknown) and the feature
// parameters (a, b) of the pair (valid feature points).
struct Guide {
  bool valid = false;
  Vec3 axis = Vec3::Zero();
  double a = 0, b = 0;
};
// A query's guides: at(u), the nominal closest pair at u, and separated(n, u0,
// u1), true when the projections of the two features on the axis n are proven
// more than d |n| apart for every u in [u0, u1] (the u-filter's separating-axis
// test, with this axis).
template <class At, class Separated>
struct Guides {
  At at;
  Separated separated;
};
struct NoGuide {
  Guide at(double) const { return {}; }
  bool separated(const Vec3&, double, double) const { return false; }
};

// Exclusion (iii) of bisect(): true when every corner's projection on the axis
// lies beyond `reach` = d |axis| (rounded up) on the same side.
GAUSS6_ALWAYS_INLINE bool axis_excludes(const Corners& K, const Vec3& axis, double reach) {
  Interval p = along(axis, K.c[0]);
  for (int k = 1; k < K.n; ++k) p = hull(p, along(axis, K.c[k]));
  return p.lo > reach || p.hi < -reach;
}

// Scales a guide's axis to unit length (any nonzero vector is valid; unit
// length keeps d |axis| ~ d); false when the guide has no usable axis.
inline bool unit_axis(Guide* g) {
  const double n = g->axis.norm();
  if (!(g->valid && n > 0 && std::isfinite(n))) return false;
  g->axis /= n;
  return true;
}

template <class Enclose, class GuideT = NoGuide>
void bisect(const Enclose& enclose, bool triangle, const Scales& sc, double u_begin, double u_end,
            const CcdSettings& s, CcdWorkspace* ws, CcdResult* r, const GuideT& guides = NoGuide{}) {
  const double d = s.min_separation;
  // Rounding noise makes F's enclosure a few ulps of the coordinates wide: a
  // distance tolerance below that could never be met.
  const double tol_d = std::max(s.distance_tolerance, kDistanceToleranceFloor * sc.coordinate);
  const int capacity = ws->capacity();
  Box* arena = ws->data();
  *r = CcdResult{};
  r->u_hit = u_end;
  const auto give_up = [&](CcdStatus status, double u0, double u1) {
    // Everything before u0 is settled (no contact): stop at u0.
    r->status = status;
    r->hit = true;
    r->u_hit = u0;
    r->time_tolerance_reached = u1 - u0;
    r->distance_reached = std::numeric_limits<double>::infinity();
  };
  int top = 0;
  arena[top++] = Box{{u_begin, u_end}, {0, 0}, {0, 0}};
  arena[top++] = Box{{u_begin, u_end}, {0, 1}, {0, 1}};
  int header = 0;
  // The guide of the current u-interval's start (recomputed when U.lo changes:
  // a left half keeps its parent's start, hence its guide and probe outcome).
  Guide guide;
  double guide_u = std::numeric_limits<double>::quiet_NaN();
  double reach = 0;  // d |axis|, rounded up
  Corners K;
  while (top > 0) {
    // Pop the interval on top: its header and front are arena[header .. top).
    const double u0 = arena[header].u[0], u1 = arena[header].u[1];
    const int front_begin = header + 1;
    const int saved_header_link = static_cast<int>(arena[header].b[0]);  // previous block's header
    const double wu = u1 - u0;
    if (!(u0 == guide_u)) {
      guide_u = u0;
      guide = guides.at(u0);
      if (unit_axis(&guide)) {
        reach = (d * norm_upper(to_interval(guide.axis))).v;
        if (s.early_hit) {
          // Everything before u0 is settled: accept u0 when a pair there is proven within d + tol_d.
          enclose(Box{{u0, u0}, {guide.a, guide.a}, {guide.b, guide.b}}, &K);
          const double dist = norm_upper(K.c[0]).v;
          if (dist <= d + tol_d) {
            ++r->iterations;
            r->status = CcdStatus::kOk;
            r->hit = true;
            r->u_hit = u0;
            r->time_tolerance_reached = 0;
            r->distance_reached = dist;
            return;
          }
        }
      } else {
        guide.axis = Vec3::Zero();
      }
    }
    const bool use_axis = guide.axis != Vec3::Zero();
    if (use_axis && guides.separated(guide.axis, u0, u1)) {
      // (iii) for the whole features at once, the u-dependence projected first
      // (no wrapping of a sliding motion into the axis): no contact in U.
      ++r->iterations;
      top = header;
      header = saved_header_link;
      continue;
    }
    // Parameter refinement pays only while it shrinks F more than the u-width
    // blurs it: measure that blur on one parameter point.
    enclose(Box{{u0, u1}, {0, 0}, {0, 0}}, &K);
    const IVec3 F_point = K.c[0];
    double blur = 0;
    for (const Interval& c : F_point) blur = std::max(blur, c.hi - c.lo);
    if (!(blur < std::numeric_limits<double>::infinity())) blur = wu * sc.u;  // NaN or inf: fall back
    const double enough = std::max({tol_d, wu * sc.u, blur});
    // Inner search: the front is the initial stack, at arena[front_begin .. top).
    bool maybe = false;
    Box found{};
    IVec3 F_maybe{};
    while (top > front_begin) {
      if (r->iterations >= s.max_iterations) return give_up(CcdStatus::kMaxIterations, u0, u1);
      Box P = arena[--top];
      P.u[0] = u0;
      P.u[1] = u1;
      ++r->iterations;
      if (triangle && P.a[0] + P.b[0] > 1) continue;  // (ii)
      enclose(P, &K);
      const IVec3 F = K.hull();
      if (excludes(F, d)) continue;                               // (i)
      if (use_axis && axis_excludes(K, guide.axis, reach)) continue;  // (iii)
      const double wa = P.a[1] - P.a[0], wb = P.b[1] - P.b[0];
      const double ma = 0.5 * (P.a[0] + P.a[1]), mb = 0.5 * (P.b[0] + P.b[1]);
      // A dimension whose midpoint equals an end cannot be split (one float wide).
      const bool can_a = P.a[0] < ma && ma < P.a[1], can_b = P.b[0] < mb && mb < P.b[1];
      if ((!can_a && !can_b) || wa * sc.a + wb * sc.b <= enough) {
        maybe = true;
        found = P;
        F_maybe = F;
        break;
      }
      if (top + 2 > capacity) return give_up(CcdStatus::kWorkspaceFull, u0, u1);
      Box lo = P, hi = P;
      if (can_a && (!can_b || wa * sc.a >= wb * sc.b)) {
        lo.a[1] = ma;
        hi.a[0] = ma;
      } else {
        lo.b[1] = mb;
        hi.b[0] = mb;
      }
      arena[top++] = hi;
      arena[top++] = lo;
    }
    const double mu = 0.5 * (u0 + u1);
    if (maybe && (wu <= s.time_tolerance || !(u0 < mu && mu < u1))) {
      // Accepted: the earliest u-interval that may hold a contact.
      r->hit = true;
      r->u_hit = u0;
      r->time_tolerance_reached = wu;
      r->distance_reached = norm_upper(F_maybe).v;
      return;
    }
    if (!maybe) {
      // No contact in U: drop its block; the previous block is on top.
      top = header;
      header = saved_header_link;
      continue;
    }
    // Split U. The new front = the found box + the boxes left on the stack
    // (arena[front_begin .. top)); both halves get a copy: right below, left on top.
    arena[top++] = found;
    const int n_front = top - front_begin;
    if (top + 1 + n_front > capacity) return give_up(CcdStatus::kWorkspaceFull, u0, u1);
    // Reuse the current block for the right half.
    arena[header].u[0] = mu;
    // The left half's block: header then a copy of the front.
    const int left_header = top;
    arena[top++] = Box{{u0, mu}, {0, 0}, {static_cast<double>(header), 0}};
    for (int i = 0; i < n_front; ++i) arena[top++] = arena[front_begin + i];
    header = left_header;
  }
  // Every u-interval dropped: no contact in the window.
  r->hit = false;
  r->u_hit = u_end;
}

// The answer to a query whose input failed its checks: kInvalidInput, no hit.
void refuse(double u_end, CcdResult* r);

inline double max_abs(const Vec3& v) { return v.cwiseAbs().maxCoeff(); }

}  // namespace gauss6::ccd_detail
