// Closest points of triangles' features (Ericson, Real-Time Collision
// Detection, chapter 5): the out-of-line half of distance.h.
#include "gauss6/geometry/distance.h"

#include <algorithm>

namespace gauss6 {

namespace {

// The point of segment [a, b] closest to p: its parameter clamped to [0, 1]
// (a segment of zero length, whose parameter is NaN, gives a).
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = ab.dot(p - a) / ab.squaredNorm();
  return a + (t > 0 ? (t < 1 ? t : 1.0) : 0.0) * ab;
}

}  // namespace

// Ericson, Real-Time Collision Detection, 5.1.5: Voronoi regions of the triangle.
// Every branch returns a corner, a point of an edge at a parameter in [0, 1],
// or the interior's combination at weights >= 0 summing to at most 1 + 8 u,
// so the point lies in the corners' box to 40 u of their magnitude:
// proofs/ContactApart.v, closest_branches and closest_in_box (generate_contacts'
// `apart` rests on it).
// Each corner and edge branch is decided and computed from the dot products
// of its own edges, (end - start) . (p - start) and (end - start) . (p - end)
// (edge bc's, eb and ec, from bc itself, not as differences of ab's and ac's, whose
// rounding grows as |ab| |bp| / |bc|): the point is then within a few u of the
// coordinates' magnitude of the exact closest point of that edge, whichever
// face computes it (proofs/ContactTie.v, edge_rule_point; generate_contacts'
// `tie` rests on it: tie_shared_edge).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b, bc = c - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp), eb = bc.dot(bp);
  if (d3 >= 0 && eb <= 0) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp), ec = bc.dot(cp);
  if (d6 >= 0 && ec >= 0) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && eb >= 0 && ec <= 0) return b + (eb / (eb - ec)) * bc;
  // Inside the face: va, vb, vc > 0 in exact arithmetic, so the weights are
  // >= 0 and sum to at most 1 (to 8 u: ContactApart.v, interior_weights).
  // Rounding of the six dot products is not known to break these signs (no
  // test has seen it), but nothing rules it out on a face whose area is at
  // the level of its rounding; there a weight < 0 would put the point
  // anywhere on the face's plane, so such a face gets the nearest of its
  // edges' points instead.
  if (va >= 0 && vb >= 0 && vc >= 0) {
    const double denom = 1 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
  }
  const Vec3 e0 = closest_point_on_segment(p, a, b), e1 = closest_point_on_segment(p, b, c),
             e2 = closest_point_on_segment(p, c, a);
  const double s0 = (p - e0).squaredNorm(), s1 = (p - e1).squaredNorm(), s2 = (p - e2).squaredNorm();
  return s0 <= s1 ? (s0 <= s2 ? e0 : e2) : (s1 <= s2 ? e1 : e2);
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
