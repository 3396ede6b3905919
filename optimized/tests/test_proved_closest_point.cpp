// Tests of the theorems of proofs/ClosestPoint.v: closest_point_on_triangle's
// computed separation |p - q| (the callers' (p - q).norm()) is at most p's exact
// distance from each edge of the face plus 240 u M + 2^-529 (closest_upper) and
// at least p's exact distance from the face less 240 u M + 2^-529
// (closest_lower), M the coordinates' magnitude, whatever the face's shape; so
// two faces whose exact closest points of p are one point of an edge they share
// compute separations within generate_contacts' `tie` (tie_closest). The exact
// distances are computed in rationals (the closest points of the three edges
// and, when it lies inside, the foot of p on the face's plane), their squares
// rounded to double and square-rooted: within 2 u of the exact distance, a
// term the tolerance adds (2 u 4 M, under 8 u M).
// The inputs: slivers (an edge down to 2^-60 of the others) with p far beyond
// the short edge, where Ericson's region tests lose their sign to rounding;
// faces whose coordinates lie below 2^-256, where those tests' products
// underflow to 0; ordinary faces, nearly flat pairs, large coordinates.
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
Q3 axpy(const Q3& a, const mpq_class& t, const Q3& e) { return {a.x + t * e.x, a.y + t * e.y, a.z + t * e.z}; }
mpq_class dist_sq(const Q3& a, const Q3& b) { return dot(sub(a, b), sub(a, b)); }

// The exact squared distance of p from the segment [a, b].
mpq_class segment_dist_sq(const Q3& P, const Q3& A, const Q3& B) {
  const Q3 E = sub(B, A);
  const mpq_class n = dot(E, E);
  mpq_class t = n == 0 ? mpq_class(0) : mpq_class(dot(E, sub(P, A)) / n);
  if (t < 0) t = 0;
  if (t > 1) t = 1;
  return dist_sq(P, axpy(A, t, E));
}

struct Exact {
  mpq_class edges_sq;  // the least squared distance of p from the three edges
  mpq_class face_sq;   // the squared distance of p from the face
};
Exact exact_distances(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Q3 P = exact(p), A = exact(a), B = exact(b), C = exact(c);
  Exact r;
  r.edges_sq = std::min({segment_dist_sq(P, A, B), segment_dist_sq(P, A, C), segment_dist_sq(P, B, C)});
  r.face_sq = r.edges_sq;
  // The foot of p on the plane, by the normal equations of a + s ab + t ac.
  const Q3 AB = sub(B, A), AC = sub(C, A), AP = sub(P, A);
  const mpq_class g11 = dot(AB, AB), g12 = dot(AB, AC), g22 = dot(AC, AC), r1 = dot(AB, AP), r2 = dot(AC, AP);
  const mpq_class det = g11 * g22 - g12 * g12;
  if (det != 0) {
    const mpq_class s = (r1 * g22 - r2 * g12) / det, t = (g11 * r2 - g12 * r1) / det;
    if (s >= 0 && t >= 0 && s + t <= 1) r.face_sq = std::min(r.face_sq, dist_sq(P, axpy(axpy(A, s, AB), t, AC)));
  }
  return r;
}

double root(const mpq_class& q) { return std::sqrt(q.get_d()); }

double magnitude(std::initializer_list<Vec3> vs) {
  double m = 0;
  for (const Vec3& v : vs) m = std::max(m, v.cwiseAbs().maxCoeff());
  return m;
}

// closest_upper and closest_lower's bound, 240 u M + 2^-529, and the exact
// distances' conversion to double (8 u M, see the file's comment).
double bound(double M) { return 248 * kU * M + 0x1p-529; }

// closest_point_on_triangle's separation of p from (a, b, c) lies between the
// exact distance of p from the face and from its nearest edge, to bound(M).
void check_separation(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double M = magnitude({p, a, b, c});
  const Exact x = exact_distances(p, a, b, c);
  const double sep = (p - closest_point_on_triangle(p, a, b, c)).norm();
  INFO(std::hexfloat << " p " << p.transpose() << " a " << a.transpose() << " b " << b.transpose() << " c "
                     << c.transpose());
  REQUIRE(sep <= root(x.edges_sq) + bound(M));
  REQUIRE(sep >= root(x.face_sq) - bound(M));
}

// A sliver: edge bc of length 2^-k (k in [26, 60]) of the face's size s, a
// far from it, p beyond bc at up to the face's size (in its plane or off it).
struct Face {
  Vec3 p, a, b, c;
};
Face make_sliver(std::mt19937_64& rng, double s) {
  std::uniform_real_distribution<double> unit(-1, 1), half(0, 1);
  std::uniform_int_distribution<int> short_exp(26, 60);
  const Vec3 o = Vec3(unit(rng), unit(rng), unit(rng)) * s;
  const Vec3 e = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
  Vec3 w = Vec3(unit(rng), unit(rng), unit(rng));
  w = (w - w.dot(e) * e).normalized();
  const Vec3 n = e.cross(w);
  const double len = s * std::ldexp(1.0, -short_exp(rng));
  Face f;
  f.b = o;
  f.c = o + len * e;
  f.a = o + half(rng) * len * e + s * (0.5 + half(rng)) * w;
  f.p = o + unit(rng) * 2 * len * e - s * half(rng) * w + s * 0.5 * unit(rng) * n;
  return f;
}

}  // namespace

TEST_CASE("closest_point_on_triangle on slivers with p far beyond the short edge: separation within 240 u M "
          "of the exact distance (ClosestPoint.v closest_upper, closest_lower)",
          "[proved]") {
  // Ericson's region tests va, vb, vc, differences of products of ab's and
  // ac's dot products, round by u (|ab| |bp|)^2 against an exact value of
  // |ab| |bp| |bc|^2: on these faces they lose their sign, and the old code
  // took the interior branch at weights that were mostly rounding, or an
  // edge's whose region p is not in, up to the face's size off.
  std::mt19937_64 rng(5701);
  int far_off_before = 0;
  for (int i = 0; i < 20000; ++i) {
    const Face f = make_sliver(rng, std::ldexp(1.0, static_cast<int>(rng() % 81) - 40));
    const double M = magnitude({f.p, f.a, f.b, f.c});
    const Exact x = exact_distances(f.p, f.a, f.b, f.c);
    for (int k = 0; k < 3; ++k) {  // every way round: the short edge as bc, ca, ab
      const Vec3 A = k == 0 ? f.a : k == 1 ? f.b : f.c, B = k == 0 ? f.b : k == 1 ? f.c : f.a,
                 C = k == 0 ? f.c : k == 1 ? f.a : f.b;
      INFO("case " << i << " way " << k);
      check_separation(f.p, A, B, C);
    }
    far_off_before += root(x.edges_sq) > 1e-3 * M;
  }
  CHECK(far_off_before > 1000);  // most cases have p well away from the face
}

TEST_CASE("closest_point_on_triangle with coordinates below 2^-256: separation within 2^-529 of the exact "
          "distance (ClosestPoint.v closest_upper, closest_lower)",
          "[proved]") {
  // The region tests' products of two dot products (degree 4 in the
  // coordinates) underflow to 0 here: the old code took edge ab's branch for
  // any p with d1 >= 0 >= d3, p beyond bc or ac at the face's size.
  std::mt19937_64 rng(5702);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> exp(-330, -257);
  int ab_region_before = 0;
  for (int i = 0; i < 20000; ++i) {
    const double s = std::ldexp(1.0, exp(rng));
    const Vec3 a = Vec3(unit(rng), unit(rng), unit(rng)) * s, b = Vec3(unit(rng), unit(rng), unit(rng)) * s,
               c = Vec3(unit(rng), unit(rng), unit(rng)) * s, p = Vec3(unit(rng), unit(rng), unit(rng)) * 2 * s;
    INFO("case " << i);
    check_separation(p, a, b, c);
    const Vec3 ab = b - a;
    ab_region_before += ab.dot(p - a) >= 0 && ab.dot(p - b) <= 0;
  }
  CHECK(ab_region_before > 1000);
}

TEST_CASE("closest_point_on_triangle on ordinary and near-degenerate faces: separation within 240 u M of the "
          "exact distance (ClosestPoint.v closest_upper, closest_lower)",
          "[proved]") {
  std::mt19937_64 rng(5703);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> exp(-200, 40), kind(0, 3);
  for (int i = 0; i < 20000; ++i) {
    const double s = std::min(std::ldexp(1.0, exp(rng)), 1e12);
    Vec3 a = Vec3(unit(rng), unit(rng), unit(rng)) * s, b = Vec3(unit(rng), unit(rng), unit(rng)) * s,
         c = Vec3(unit(rng), unit(rng), unit(rng)) * s;
    if (kind(rng) == 0) c = a + 0.5 * (b - a) + 1e-9 * s * Vec3(unit(rng), unit(rng), unit(rng));  // nearly flat
    if (kind(rng) == 1) c = b;                                                                   // degenerate
    // p near the face (a few of its sizes down to 2^-30 of them) or off it.
    const Vec3 foot = a + 0.4 * (b - a) + 0.3 * (c - a);
    const Vec3 p = kind(rng) == 2 ? Vec3(foot + std::ldexp(s, -30) * Vec3(unit(rng), unit(rng), unit(rng)))
                                  : Vec3(Vec3(unit(rng), unit(rng), unit(rng)) * 2 * s);
    INFO("case " << i);
    check_separation(p, a, b, c);
  }
  // A point above a well-shaped face's interior gets the foot of p, not an
  // edge's point: separation its height (to rounding), not its distance from
  // the nearest edge.
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), p(0.25, 1.0 / 3, 0.125);
  const Vec3 q = closest_point_on_triangle(p, a, b, c);
  CHECK(std::abs(q.x() - 0.25) <= 4 * kU);
  CHECK(std::abs(q.y() - 1.0 / 3) <= 4 * kU);
  CHECK(q.z() == 0);
}

TEST_CASE("faces sharing the edge p's exact closest points lie on: separations within tie (ClosestPoint.v "
          "tie_closest)",
          "[proved]") {
  std::mt19937_64 rng(5704);
  std::uniform_real_distribution<double> unit(-1, 1), half(0, 1);
  std::uniform_int_distribution<int> scale_exp(-330, 40), short_exp(0, 60);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const double s = std::min(std::ldexp(1.0, scale_exp(rng)), 1e12);
    // F = (a, b, c) and G = (c, b, d) share bc; p beyond bc for both, far
    // (at the faces' size) or near.
    const Vec3 b = Vec3(unit(rng), unit(rng), unit(rng)) * s;
    const Vec3 e = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
    const double len = s * std::ldexp(1.0, -short_exp(rng));
    const Vec3 c = b + len * e;
    if (c == b) continue;
    Vec3 w1 = Vec3(unit(rng), unit(rng), unit(rng)), w2 = Vec3(unit(rng), unit(rng), unit(rng));
    w1 = (w1 - w1.dot(e) * e).normalized();
    w2 = (w2 - w2.dot(e) * e).normalized();
    if ((w1 + w2).norm() < 1e-3) continue;
    const Vec3 a = b + 0.5 * len * e + s * (0.5 + half(rng)) * w1, d = b + 0.5 * len * e + s * (0.5 + half(rng)) * w2;
    const Vec3 out = -(w1 + w2).normalized();
    const Vec3 p = b + half(rng) * len * e + (half(rng) < 0.5 ? s : len) * half(rng) * out;
    // The premise, exactly: both faces' distance is the shared edge's.
    const Exact xf = exact_distances(p, a, b, c), xg = exact_distances(p, c, b, d);
    const mpq_class edge_sq = segment_dist_sq(exact(p), exact(b), exact(c));
    if (xf.face_sq != edge_sq || xg.face_sq != edge_sq) continue;
    const double scale = magnitude({p, a, b, c, d});  // at least every coordinate (M <= 4 scale)
    const double tie = std::max((Upper{kBoxPoseRounding} * Upper{scale}).v, kNormFloor);
    const double sf = (p - closest_point_on_triangle(p, a, b, c)).norm();
    const double sg = (p - closest_point_on_triangle(p, c, b, d)).norm();
    INFO("case " << i << std::hexfloat << " sf " << sf << " sg " << sg << " tie " << tie);
    REQUIRE(sg <= sf + tie);  // held_beside's reach, min(d, sep + tie), rounded as the code rounds it
    REQUIRE(sf <= sg + tie);
    REQUIRE(std::abs(sf - sg) <= 480 * kU * scale + 0x1p-528);  // the theorem's bound, under tie
    ++checked;
  }
  CHECK(checked > 10000);
}
