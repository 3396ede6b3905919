// Tests of the theorems of proofs/ContactApart.v: closest_point_on_triangle's
// point lies in its corners' box to 40 u M + 5 eta (closest_in_box, on every
// branch: closest_branches), and two features whose boxes are more than
// generate_contacts' `apart` apart along an axis have a computed separation
// above d (apart_vertex_face, apart_edge_edge), the separation computed as
// contacts.cpp's feature_pair computes it. Random and adversarial inputs:
// slivers and degenerate faces, signed zeros, subnormal coordinates, the
// largest scene coordinate (1e12), the least contact distance (2^-500), boxes
// at the edge of `apart` (the least double beyond the test's bound).
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "gauss6/geometry/distance.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/numeric/rounding.h"

using namespace gauss6;

namespace {

constexpr double kU = 0x1p-53;

mpq_class Q(double x) { return mpq_class(x); }
// 40 u M + 5 eta, exactly.
mpq_class box_error(double M) {
  mpq_class eta(1);
  mpz_class den(1);
  den <<= 1075;
  eta /= den;
  return 40 * Q(kU) * Q(M) + 5 * eta;
}

// A coordinate of the given scale, or an adversarial one at it.
double at_scale(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> pick(0, 9);
  switch (pick(rng)) {
    case 0: return 0.0;
    case 1: return -0.0;
    case 2: return std::numeric_limits<double>::denorm_min();
    case 3: return scale;
    default: return unit(rng) * scale;
  }
}

// A triangle: any, a sliver (c near the line ab, to 2^-k of |ab|), or with a
// repeated corner; p anywhere near it, or over it near its plane.
struct Case {
  Vec3 p, a, b, c;
};
Case make_case(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> kind(0, 3), ex(-400, 40), thin(10, 60);
  const double s = std::min(std::ldexp(1.0, ex(rng)), 1e12);
  const auto point = [&] { return Vec3(at_scale(rng, s), at_scale(rng, s), at_scale(rng, s)); };
  Case k{point(), point(), point(), point()};
  switch (kind(rng)) {
    case 0: break;
    case 1: {  // a sliver, p over it near its plane
      const double t = 0.5 * (unit(rng) + 1);
      const Vec3 off = std::ldexp(1.0, -thin(rng)) * point();
      k.c = k.a + t * (k.b - k.a) + off;
      k.p = k.a + (0.5 * (unit(rng) + 1)) * (k.b - k.a) + std::ldexp(1.0, -thin(rng)) * point();
      break;
    }
    case 2: k.c = k.b; break;  // a degenerate face
    default: k.p = (k.a + k.b + k.c) / 3 + std::ldexp(1.0, -thin(rng)) * point();  // over the face
  }
  return k;
}

// `apart` as generate_contacts computes it.
double apart_of(double d, double scale) { return (Upper{2 * d} + Upper{kBoxPoseRounding} * Upper{scale}).v; }

}  // namespace

TEST_CASE("closest_point_on_triangle's point lies in its corners' box (ContactApart.v closest_in_box)", "[proved]") {
  std::mt19937_64 rng(45045045);
  int finite = 0;
  for (int n = 0; n < 200000; ++n) {
    const Case k = make_case(rng);
    const Vec3 q = closest_point_on_triangle(k.p, k.a, k.b, k.c);
    if (!q.allFinite()) continue;  // 0 / 0 on a degenerate edge: NaN, which no `sep <= d` accepts
    ++finite;
    for (int i = 0; i < 3; ++i) {
      const double lo = std::min({k.a[i], k.b[i], k.c[i]}), hi = std::max({k.a[i], k.b[i], k.c[i]});
      const double M = std::max({std::abs(k.a[i]), std::abs(k.b[i]), std::abs(k.c[i])});
      INFO("coordinate " << i << " q " << q[i] << " box [" << lo << ", " << hi << "]");
      REQUIRE(Q(q[i]) >= Q(lo) - box_error(M));
      REQUIRE(Q(q[i]) <= Q(hi) + box_error(M));
    }
  }
  CHECK(finite > 150000);
}

// The box test along axis i passes by the least margin the code accepts: the
// obstacle feature's least coordinate is the double just above
// next_up(x + apart) (Upper's sum, boxes_apart); the separation computed as
// feature_pair computes it is then above d.
TEST_CASE("features apart by more than `apart` have a computed separation above d (ContactApart.v "
          "apart_vertex_face, apart_edge_edge)",
          "[proved]") {
  std::mt19937_64 rng(45045046);
  std::uniform_real_distribution<double> unit(-1, 1), half(0, 1);
  std::uniform_int_distribution<int> ex_d(-500, 10), ex_s(-20, 40), axis(0, 2), side(0, 1), pick(0, 3);
  int tested = 0;
  for (int n = 0; n < 100000; ++n) {
    const double d = std::ldexp(1.0 + half(rng), ex_d(rng));
    const double s = std::min(std::ldexp(1.0, ex_s(rng)), 1e12);
    const int i = axis(rng);
    // The vertex (god or obstacle) and a face beyond it along axis i.
    const auto coord = [&] { return pick(rng) == 0 ? at_scale(rng, s) : unit(rng) * s; };
    Vec3 x(coord(), coord(), coord());
    // scale: the least the hypothesis M <= 4 scale allows once the corners are placed (below).
    const double scale0 = s;
    const double apart = apart_of(d, scale0);
    const bool above = side(rng) == 1;  // the face beyond x (above), or before it
    // The face's least coordinate (above) or largest (before): the first
    // double at which boxes_apart's test, b_lo > next_up(a_hi + apart),
    // passes.
    double edge = std::nextafter((Upper{x[i]} + Upper{apart}).v, HUGE_VAL);
    if (!above) {
      const auto passes = [&](double e) { return x[i] > (Upper{e} + Upper{apart}).v; };
      edge = x[i] - apart;
      int step = 0;
      while (passes(edge) && ++step < 64) edge = std::nextafter(edge, HUGE_VAL);
      while (!passes(edge) && ++step < 192) edge = std::nextafter(edge, -HUGE_VAL);
      if (!passes(edge) || passes(std::nextafter(edge, HUGE_VAL))) continue;  // not at the edge
    }
    if (!(std::abs(edge) <= 1e12)) continue;
    Vec3 Y[3];
    for (auto& y : Y) {
      y = Vec3(coord(), coord(), coord());
      const double far = std::ldexp(half(rng), ex_d(rng));
      y[i] = above ? edge + (pick(rng) == 0 ? 0.0 : far) : edge - (pick(rng) == 0 ? 0.0 : far);
    }
    if (pick(rng) == 0) Y[2] = Y[0] + 1e-9 * (Y[1] - Y[0]);  // a sliver
    double M = std::abs(x[i]);
    for (const auto& y : Y) M = std::max(M, y.cwiseAbs().maxCoeff());
    M = std::max(M, x.cwiseAbs().maxCoeff());
    if (!(M <= 4 * scale0)) continue;  // the hypothesis (generate_contacts' scale bounds the coordinates)
    ++tested;
    // vertex/face (both roles: the obstacle's vertex against a god face is the same computation)
    const double sep = (x - closest_point_on_triangle(x, Y[0], Y[1], Y[2])).norm();
    INFO("d " << d << " sep " << sep << " apart " << apart << " axis " << i);
    REQUIRE(!(sep <= d));
    // edge/edge: the god edge (x, x2) and the obstacle edge (Y0, Y1), x2 on x's side of the gap
    Vec3 x2(coord(), coord(), coord());
    x2[i] = above ? std::min(x[i], x2[i]) : std::max(x[i], x2[i]);
    if (!(x2.cwiseAbs().maxCoeff() <= 4 * scale0)) continue;
    double sg, tg;
    closest_segment_parameters(x, x2, Y[0], Y[1], &sg, &tg);
    if (sg > 0 && sg < 1 && tg > 0 && tg < 1) {
      const Vec3 pg = x + sg * (x2 - x), po = Y[0] + tg * (Y[1] - Y[0]);
      REQUIRE(!((pg - po).norm() <= d));
    }
  }
  CHECK(tested > 50000);
}
