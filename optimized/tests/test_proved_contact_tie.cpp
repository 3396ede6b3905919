// Tests of the theorems of proofs/ContactTie.v: the edge rule (distance.cpp
// edge_point, public as closest_point_on_segment), decided and computed from
// an edge's own dot products, returns a point within 200 u M + 2^-533
// (Euclidean) of the exact closest point of that edge (edge_rule_point),
// whichever way round it sees the edge; so two faces that share the edge
// compute one vertex's separations within generate_contacts' `tie` of each
// other (tie_shared_edge, and ClosestPoint.v tie_closest for the faces'
// closest_point_on_triangle, tested in test_proved_closest_point.cpp too).
// Random and adversarial inputs: a shared edge many orders of magnitude
// shorter than the faces' other edges (where the old bc branch, which took its
// parameter from differences of the other edges' dot products, erred by up to
// the edge's length), subnormal and huge coordinates, folded and nearly flat
// face pairs.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>

#include "gauss6/geometry/distance.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/numeric/rounding.h"

using namespace gauss6;

namespace {

constexpr double kU = 0x1p-53;

struct Q3 {
  mpq_class x, y, z;
};
Q3 exact(const Vec3& v) { return {mpq_class(v.x()), mpq_class(v.y()), mpq_class(v.z())}; }
mpq_class dot(const Q3& a, const Q3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Q3 sub(const Q3& a, const Q3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

// The exact closest point of the segment [a, b] to p (ContactTie.v seg_tau).
Q3 closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Q3 A = exact(a), B = exact(b), P = exact(p), E = sub(B, A);
  const mpq_class n = dot(E, E);
  mpq_class t = n == 0 ? mpq_class(0) : mpq_class(dot(E, sub(P, A)) / n);
  if (t < 0) t = 0;
  if (t > 1) t = 1;
  return {A.x + t * E.x, A.y + t * E.y, A.z + t * E.z};
}

// edge_rule_point's bound, 200 u M + 2^-533, squared, exactly.
mpq_class point_bound_sq(double M) {
  mpz_class den(1);
  den <<= 533;
  const mpq_class b = 200 * mpq_class(kU) * mpq_class(M) + mpq_class(1) / mpq_class(den);
  return b * b;
}

// A unit vector perpendicular to e (random direction about it).
Vec3 perpendicular(std::mt19937_64& rng, const Vec3& e) {
  std::uniform_real_distribution<double> unit(-1, 1);
  for (;;) {
    const Vec3 r(unit(rng), unit(rng), unit(rng));
    const Vec3 w = r - (r.dot(e) / e.squaredNorm()) * e;
    if (w.norm() > 0.1 * r.norm() && w.norm() > 0) return w.normalized();
  }
}

// Two faces F = (a, b, c) and G = (c, b, d) sharing edge bc (G sees it from c
// to b), and a point p beyond bc for both: its exact closest point on each face
// is the same point of the segment [b, c].
struct SharedEdge {
  Vec3 a, b, c, d, p;
  double M;  // the largest coordinate magnitude
};
SharedEdge make_shared_edge(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1, 1), half(0, 1);
  // Scales down to 2^-330, where the old region tests' products of two dot
  // products (degree 4 in the coordinates) underflowed to 0.
  std::uniform_int_distribution<int> scale_exp(-330, 40), short_exp(0, 70), kind(0, 3);
  const double s = std::min(std::ldexp(1.0, scale_exp(rng)), 1e12);
  SharedEdge k;
  k.b = Vec3(unit(rng), unit(rng), unit(rng)) * s;
  if (kind(rng) == 0) k.b = Vec3(std::numeric_limits<double>::denorm_min(), -0.0, 0.0);  // at the origin
  const Vec3 e = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
  const double len = s * std::ldexp(1.0, -short_exp(rng));  // the shared edge: down to 2^-70 of the faces
  k.c = k.b + len * e;
  const Vec3 w1 = perpendicular(rng, e);
  Vec3 w2 = perpendicular(rng, e);
  if (kind(rng) == 1) w2 = (-w1 + 1e-3 * perpendicular(rng, e)).normalized();  // nearly flat
  if ((w1 + w2).norm() < 1e-6) w2 = perpendicular(rng, e);
  k.a = k.b + 0.5 * len * e + s * (0.5 + half(rng)) * w1;
  k.d = k.b + 0.5 * len * e + s * (0.5 + half(rng)) * w2;
  const Vec3 out = -(w1 + w2).normalized();
  // p near the edge (within its length), or far (within the faces' size; on
  // a sliver, an edge shorter than about 2^-26 of the faces, Ericson's region
  // tests lost their sign there: ClosestPoint.v's rule does not use them).
  const bool far = kind(rng) != 2;
  const double h = far ? s * half(rng) : len * half(rng);
  k.p = k.b + half(rng) * len * e + h * out;
  k.M = 0;
  for (const Vec3* v : {&k.a, &k.b, &k.c, &k.d, &k.p}) k.M = std::max(k.M, v->cwiseAbs().maxCoeff());
  return k;
}

mpq_class distance_sq(const Vec3& q, const Q3& Q) {
  const Q3 D = sub(exact(q), Q);
  return dot(D, D);
}

}  // namespace

TEST_CASE("the edge rule's point on a short shared edge is the edge's closest point, either way round "
          "(ContactTie.v edge_rule_point)",
          "[proved]") {
  std::mt19937_64 rng(45046);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const SharedEdge k = make_shared_edge(rng);
    if (k.c == k.b) continue;  // a degenerate face (generate_contacts drops it: zero normal)
    const Q3 exact_point = closest_on_segment(k.p, k.b, k.c);
    const mpq_class bound = point_bound_sq(k.M);
    // F sees the edge from b to c, G from c to b: both within the bound.
    const Vec3 qf = closest_point_on_segment(k.p, k.b, k.c);
    const Vec3 qg = closest_point_on_segment(k.p, k.c, k.b);
    INFO("case " << i << " M " << k.M << " |bc| " << (k.c - k.b).norm());
    REQUIRE(distance_sq(qf, exact_point) <= bound);
    REQUIRE(distance_sq(qg, exact_point) <= bound);
    ++checked;
  }
  CHECK(checked > 15000);  // most cases are not degenerate
}

TEST_CASE("a face with an edge 2^-30 of its others: the edge rule's point on bc is the edge's (ContactTie.v "
          "edge_rule_point)",
          "[proved]") {
  // A tall thin face over a short base bc, p beyond bc at unit distance: the
  // differences d4 - d3 and d5 - d6 of the old region and parameter tests of
  // bc cancel to their rounding (u |ab| |bp| against |bc|^2 = 2^-60): the old
  // code returned the corner b, up to |bc| = 2^-30 from the exact point, 2^15
  // times the bound. The edge rule computes bc's point from bc's own dot
  // products. (closest_point_on_triangle may return b here: its distance from
  // p is the exact point's to rounding, which is what it promises:
  // ClosestPoint.v closest_upper, tested in test_proved_closest_point.cpp.)
  const double eps = 0x1p-30;
  const Vec3 a(0.5 * eps, 1, 0), b(0, 0, 0), c(eps, 0, 0);
  for (const double s : {0.1, 0.25, 1.0 / 3, 0.5, 0.7, 0.9}) {
    const Vec3 p(s * eps, -1, 0.25);
    const Vec3 q = closest_point_on_segment(p, b, c);
    INFO("s = " << s << ": q.x = " << q.x() << ", exact " << s * eps);
    REQUIRE(distance_sq(q, closest_on_segment(p, b, c)) <= point_bound_sq(1.0));
  }
}

TEST_CASE("two faces sharing an edge compute one vertex's separations within `tie` (ContactTie.v tie_shared_edge)",
          "[proved]") {
  std::mt19937_64 rng(4546);
  for (int i = 0; i < 20000; ++i) {
    const SharedEdge k = make_shared_edge(rng);
    if (k.c == k.b) continue;  // a degenerate face (generate_contacts drops it: zero normal)
    // scale: at least every coordinate's magnitude here (M <= 4 scale holds).
    const double scale = k.M;
    const double tie = std::max((Upper{kBoxPoseRounding} * Upper{scale}).v, kNormFloor);
    const double sf = (k.p - closest_point_on_triangle(k.p, k.a, k.b, k.c)).norm();
    const double sg = (k.p - closest_point_on_triangle(k.p, k.c, k.b, k.d)).norm();
    INFO("case " << i << " M " << k.M << " sf " << sf << " sg " << sg << " tie " << tie);
    INFO(std::hexfloat << "a " << k.a.transpose() << " b " << k.b.transpose() << " c " << k.c.transpose() << " d "
                       << k.d.transpose() << " p " << k.p.transpose());
    REQUIRE(sg <= sf + tie);  // held_beside's reach, min(d, sep + tie), rounded as the code rounds it
    REQUIRE(sf <= sg + tie);
    // The separations differ by at most 480 u M + 2^-528 (ClosestPoint.v
    // tie_closest's bound, under tie).
    REQUIRE(std::abs(sf - sg) <= 480 * kU * k.M + 0x1p-528);
  }
}
