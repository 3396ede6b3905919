// Test helpers for the distance and motion-bound tests: a reference distance
// of two triangles in long double, and random pairs of disjoint triangles.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>

#include "gauss6/geometry/pose.h"

namespace gauss6::test {


// Reference distance of two triangles in long double: the minimum over the six
// vertex/triangle and nine edge/edge distances (enough for disjoint triangles;
// intersecting pairs are not generated below). Independent of contacts.h.
using Vec3L = Eigen::Matrix<long double, 3, 1>;
inline long double point_segment(const Vec3L& x, const Vec3L& a, const Vec3L& b) {
  const Vec3L ab = b - a;
  const long double t = std::clamp((x - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300L), 0.0L, 1.0L);
  return (a + t * ab - x).norm();
}
inline long double point_triangle(const Vec3L& x, const Vec3L T[3]) {
  const Vec3L n = (T[1] - T[0]).cross(T[2] - T[0]);
  const Vec3L y = x - n * ((x - T[0]).dot(n) / n.squaredNorm());  // projection on the plane
  bool inside = true;
  for (int k = 0; k < 3; ++k) inside &= (T[(k + 1) % 3] - T[k]).cross(y - T[k]).dot(n) >= 0;
  if (inside) return (x - y).norm();
  long double best = point_segment(x, T[0], T[1]);
  for (int k = 1; k < 3; ++k) best = std::min(best, point_segment(x, T[k], T[(k + 1) % 3]));
  return best;
}
inline long double segment_segment(const Vec3L& p0, const Vec3L& p1, const Vec3L& q0, const Vec3L& q1) {
  // Minimum over a fine parameter grid refined around its best cell, plus the end cases.
  long double best = std::min({point_segment(p0, q0, q1), point_segment(p1, q0, q1), point_segment(q0, p0, p1),
                               point_segment(q1, p0, p1)});
  const Vec3L d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const long double a = d1.dot(d1), e = d2.dot(d2), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const long double den = a * e - b * b;
  if (den > 1e-24L * a * e) {
    const long double s = (b * f - c * e) / den, t = (a * f - b * c) / den;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) best = std::min(best, (p0 + s * d1 - q0 - t * d2).norm());
  }
  return best;
}
inline long double triangle_distance(const Vec3 A[3], const Vec3 B[3]) {
  Vec3L a[3], b[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = A[k].cast<long double>();
    b[k] = B[k].cast<long double>();
  }
  long double best = std::numeric_limits<long double>::infinity();
  for (int k = 0; k < 3; ++k) best = std::min({best, point_triangle(a[k], b), point_triangle(b[k], a)});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      best = std::min(best, segment_segment(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
  return best;
}

// Two disjoint triangles at `scale`: A about a random centre c (every fourth
// long and thin, a peg's side strip), B placed gap = scale 10^(-gap_decades U)
// beyond a random plane (normal m) through A's extreme point, two thirds of
// them farther still; with nearly_parallel, B lies almost in that plane.
struct DisjointPair {
  Vec3 A[3], B[3], c, m;
  double gap = 0;
};
// n and U are the caller's (a normal distribution keeps a spare draw).
inline DisjointPair disjoint_pair(std::mt19937& rng, std::normal_distribution<double>& n,
                           std::uniform_real_distribution<double>& U, int i, double scale, double gap_decades,
                           bool nearly_parallel) {
  DisjointPair out;
  out.c = scale * 10 * Vec3(n(rng), n(rng), n(rng));
  for (int k = 0; k < 3; ++k) out.A[k] = out.c + scale * Vec3(n(rng), n(rng), n(rng));
  if (i % 4 == 0) out.A[2] = out.A[0] + 1e-2 * (out.A[2] - out.A[0]) + 30 * (out.A[1] - out.A[0]);
  out.m = Vec3(n(rng), n(rng), n(rng)).normalized();
  const Vec3& m = out.m;
  double top = -1e300;
  for (const Vec3& a : out.A) top = std::max(top, m.dot(a));
  out.gap = scale * std::pow(10.0, -gap_decades * U(rng));
  for (int k = 0; k < 3; ++k) {
    Vec3 v = out.c + scale * Vec3(n(rng), n(rng), n(rng));
    if (nearly_parallel) v -= m * m.dot(v - out.c) * 0.999;
    out.B[k] = v + m * (top + out.gap - m.dot(v) + scale * std::abs(n(rng)) * (i % 3 == 0 ? 0 : 1));
  }
  return out;
}

}  // namespace gauss6::test
