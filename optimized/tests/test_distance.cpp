// Tests of distance.h: the separating-axis bound of two triangles' distance
// (never above it, and useful) and the closest-point primitives against dense
// sampling.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "gauss6/geometry/distance.h"
#include "triangle_pairs.h"

using namespace gauss6;
using gauss6::test::disjoint_pair;
using gauss6::test::DisjointPair;
using gauss6::test::triangle_distance;

TEST_CASE("triangle_gap_lower_bound: never above the distance, and useful", "[distance]") {
  std::mt19937 rng(31);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  int checked = 0, useful = 0, separated_by_plane = 0;
  for (int i = 0; i < 20000; ++i) {
    // Triangle A about a random centre; B placed a random gap beyond a random
    // plane through A's extreme point (so they are disjoint), at scales from
    // 1e-3 to 1e3, some long and thin (a peg's side strip), some coplanar-ish.
    const double scale = std::pow(10.0, 6 * U(rng) - 3);
    const DisjointPair pair = disjoint_pair(rng, n, U, i, scale, 9, /*nearly_parallel=*/i % 7 == 0);
    const Vec3 *A = pair.A, *B = pair.B, &c = pair.c;
    const double gap = pair.gap;
    const long double exact = triangle_distance(A, B);
    if (!(exact > 0)) continue;
    const double bound = triangle_gap_lower_bound(A, B, std::numeric_limits<double>::infinity());
    ++checked;
    // The reference's own rounding: long double, relative 1e-17 of the coordinates.
    REQUIRE(static_cast<long double>(bound) <= exact + 1e-16L * (c.norm() + 30 * scale));
    useful += bound >= 0.5 * static_cast<double>(exact);
    // The early exit returns more than `enough` or the full bound.
    const double enough = 0.25 * static_cast<double>(exact);
    const double early = triangle_gap_lower_bound(A, B, enough);
    CHECK((early > enough || early == bound));
    separated_by_plane += gap > 1e-6 * scale;
  }
  std::printf("triangle_gap_lower_bound: %d pairs, bound >= half the distance on %d\n", checked, useful);
  CHECK(checked > 19000);
  CHECK(useful > checked / 4);  // many pairs' closest features are not along the 11 axes
  CHECK(separated_by_plane > 1000);
  // Touching and intersecting triangles: no gap.
  const Vec3 T[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Vec3 S[3] = {Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 1), Vec3(1, 1, 1)};  // touches T at a point
  CHECK(triangle_gap_lower_bound(T, S, 0) == 0);
  const Vec3 P[3] = {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(1, 1, 1)};  // pierces T
  CHECK(triangle_gap_lower_bound(T, P, 0) == 0);
  const Vec3 N[3] = {Vec3(0, 0, std::nan("")), Vec3(1, 0, 2), Vec3(0, 1, 2)};
  CHECK(triangle_gap_lower_bound(T, N, 0) == 0);
}

TEST_CASE("triangle_gap_lower_bound: parallel triangles side by side are apart by their in-plane gap",
          "[distance]") {
  // A flat tool's face over a dense flat tessellation: two triangles in
  // parallel planes (a height h apart, h from 0 to far below their gap in the
  // plane), tilted anyhow, B beyond A's edge in the plane. The eleven axes all
  // lie along the common normal (gap h); the in-plane axes (distance.h) find
  // the gap in the plane. Tolerance: the bound must reach half the distance
  // (each in-plane axis is an edge's own normal: the closest corners may lie
  // off it), and never exceed it (the reference's long double rounding).
  std::mt19937 rng(47);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> U(0, 1);
  int checked = 0, found = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
    const Vec3 t1 = axis.unitOrthogonal(), t2 = axis.cross(t1);
    const auto in_plane = [&](double x, double y, double z) { return Vec3(x * t1 + y * t2 + z * axis); };
    // A: a triangle with its edge 0-1 on the line y = 0, corner 2 at y < 0;
    // B: every corner at y >= g, the planes h apart.
    const double g = 0.01 + U(rng), h = (i % 3 == 0 ? 0.0 : 1e-6 * U(rng)) * g;
    const auto x = [&] { return 2 * U(rng) - 1; };  // B's corners over A's edge, which spans [-1, 1] or more
    const Vec3 A[3] = {in_plane(-1 - U(rng), 0, 0), in_plane(1 + U(rng), 0, 0), in_plane(n(rng), -0.1 - U(rng), 0)};
    const Vec3 B[3] = {in_plane(x(), g, h), in_plane(x(), g + U(rng), h), in_plane(x(), g + 0.1 + U(rng), h)};
    const long double exact = triangle_distance(A, B);
    if (!(exact > 0)) continue;
    ++checked;
    const double bound = triangle_gap_lower_bound(A, B, std::numeric_limits<double>::infinity());
    REQUIRE(static_cast<long double>(bound) <= exact + 1e-15L);
    found += bound >= 0.5 * static_cast<double>(exact);
  }
  std::printf("in-plane axes: %d of %d parallel pairs bounded by half their distance or more\n", found, checked);
  CHECK(checked > 4900);
  CHECK(found > checked * 9 / 10);
}

TEST_CASE("contacts: closest points agree with dense sampling", "[contacts]") {
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p(n(rng), n(rng), n(rng)), a(n(rng), n(rng), n(rng)), b(n(rng), n(rng), n(rng)), c(n(rng), n(rng), n(rng));
    const double d = (p - closest_point_on_triangle(p, a, b, c)).norm();
    double best = INFINITY;
    for (int s = 0; s <= 100; ++s)
      for (int t = 0; s + t <= 100; ++t) best = std::min(best, (p - (a + (s / 100.0) * (b - a) + (t / 100.0) * (c - a))).norm());
    CHECK(d <= best + 1e-12);
    CHECK(d >= best - 0.03 * ((b - a).norm() + (c - a).norm()));  // grid spacing bound
    const Vec3 q0(n(rng), n(rng), n(rng)), q1(n(rng), n(rng), n(rng));
    double s, t;
    closest_segment_parameters(a, b, q0, q1, &s, &t);
    const double ds = ((a + s * (b - a)) - (q0 + t * (q1 - q0))).norm();
    double bs = INFINITY;
    for (int k = 0; k <= 200; ++k)
      for (int j = 0; j <= 200; ++j) bs = std::min(bs, ((a + (k / 200.0) * (b - a)) - (q0 + (j / 200.0) * (q1 - q0))).norm());
    CHECK(ds <= bs + 1e-12);
  }
}
