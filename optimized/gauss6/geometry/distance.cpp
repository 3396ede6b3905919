// Closest points of triangles' features (Ericson, Real-Time Collision
// Detection, chapter 5): the out-of-line half of distance.h.
#include "gauss6/geometry/distance.h"

#include <algorithm>

namespace gauss6 {

namespace {

// The edge rule (proofs/ContactTie.v edge_rule): the point of the edge from s
// to t nearest p, decided and computed from that edge's own dot products
// e = (t - s) . (p - s) and f = (t - s) . (p - t): s when e <= 0, t when
// f >= 0, else s + (e / (e - f)) (t - s) (e > 0 > f: no division by zero).
// Within 200 u M + 2^-533 of the exact closest point of the segment, M the
// coordinates' magnitude: ContactTie.v edge_rule_point.
Vec3 edge_point(const Vec3& s, const Vec3& t, const Vec3& st, double e, double f) {
  if (e <= 0) return s;
  if (f >= 0) return t;
  return s + (e / (e - f)) * st;
}

}  // namespace

Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  return edge_point(a, b, ab, ab.dot(p - a), ab.dot(p - b));
}

// Corners first (Ericson, Real-Time Collision Detection, 5.1.5): a corner both
// of whose edges' computed dot products point away from p is returned; it is
// as near p as any point of the face, to 63 u M + 2^-530 (proofs/ClosestPoint.v
// corner_nearest: exact algebra, |p - x|^2 = |p - a|^2 - 2 (s D1 + t D2) +
// |s ab + t ac|^2, with D1, D2 within their rounding of <= 0). Otherwise the
// candidates whose rounding is bounded whatever the face's shape: the three
// edges' points by the edge rule, and the interior's combination a + ab v +
// ac w when its computed weights va, vb, vc are >= 0 (v, w >= 0, v + w <=
// 1 + 8 u: ContactApart.v interior_weights); the nearest of them by the
// computed (p - q).squaredNorm(), the separation the callers compute as
// (p - q).norm(). Ericson's region tests, products of two dot products,
// choose the interior on a sliver (an edge shorter than about 2^-26 of the
// others) where their rounding passes their value, and an edge whose region
// p is not in where the products underflow (coordinates below about 2^-256):
// there the point was up to the face's size from the exact closest point.
// Every branch returns a corner, an edge's point at a parameter in [0, 1] or
// the interior's combination, within the corners' box to 40 u M
// (ContactApart.v closest_branches, closest_in_box: generate_contacts'
// `apart`). The computed separation is at most the exact distance of p from
// each edge plus 240 u M + 2^-529 and at least p's exact distance from the
// face less 240 u M + 2^-529 (ClosestPoint.v closest_upper, closest_lower), so
// two faces whose exact closest points of p are one point of an edge they
// share compute separations within generate_contacts' `tie` of each other
// (ClosestPoint.v tie_closest).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b, bc = c - b;
  const double d3 = ab.dot(bp), eb = bc.dot(bp);
  if (d3 >= 0 && eb <= 0) return b;
  const Vec3 cp = p - c;
  const double d6 = ac.dot(cp), ec = bc.dot(cp);
  if (d6 >= 0 && ec >= 0) return c;
  // The edges' points, the nearest kept (ties to the first).
  Vec3 best = edge_point(a, b, ab, d1, d3);
  double best_sq = (p - best).squaredNorm();
  const Vec3 q_ac = edge_point(a, c, ac, d2, d6);
  const double s_ac = (p - q_ac).squaredNorm();
  if (s_ac < best_sq) best = q_ac, best_sq = s_ac;
  const Vec3 q_bc = edge_point(b, c, bc, eb, ec);
  const double s_bc = (p - q_bc).squaredNorm();
  if (s_bc < best_sq) best = q_bc, best_sq = s_bc;
  // The interior's point, when its weights are >= 0 as computed (in exact
  // arithmetic va, vb, vc > 0 inside the face); taken when nearer. A zero sum
  // gives a NaN point, whose comparison fails.
  const double d4 = ac.dot(bp), d5 = ab.dot(cp);
  const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  if (va >= 0 && vb >= 0 && vc >= 0) {
    const double denom = 1 / (va + vb + vc);
    const Vec3 q = a + ab * (vb * denom) + ac * (vc * denom);
    if ((p - q).squaredNorm() < best_sq) return q;
  }
  return best;
}

// Ericson 5.1.9, with degenerate segments handled.
void closest_segment_parameters(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double* s_out,
                                double* t_out) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
    s = t = 0;
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  *s_out = s;
  *t_out = t;
}

}  // namespace gauss6
