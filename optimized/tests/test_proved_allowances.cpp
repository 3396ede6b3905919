// Tests of the theorems of proofs/Allowances.v (and BoxPose.v's
// box_pose_encloses, the last case): the rounding error of each
// proved allowance's expression, evaluated as its site evaluates it (the same
// operations in the same order; the site's code is tied to the theorem by the
// hash tools/check_proofs.sh compares), against the exact value in rationals
// (GMP), on random and adversarial inputs: signed zeros, subnormals, inputs at
// the largest coordinate the CCD accepts (1e30), parameters at 0 and 1.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "gauss6/numeric/error_allowances.h"
#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/contact/contacts.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/rounding.h"

using namespace gauss6;

namespace {

mpq_class Q(double x) { return mpq_class(x); }

// A coordinate of every scale up to 1e30, or an adversarial one.
double coordinate(std::mt19937_64& rng) {
  static const std::array<double, 8> kSpecial = {0.0, -0.0, std::numeric_limits<double>::denorm_min(),
                                                 -std::numeric_limits<double>::min(), 1e30, -1e30,
                                                 1.0 + 0x1p-52, -0x1p-1000};
  std::uniform_int_distribution<int> ex(-1074, 99), pick(0, 15);
  std::uniform_real_distribution<double> mant(-1, 1);
  const int k = pick(rng);
  return k < 8 ? kSpecial[static_cast<size_t>(k)] : std::ldexp(mant(rng), ex(rng));
}
// A parameter in [0, 1]: 0, 1, or random (of every scale).
double parameter(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> pick(0, 3), ex(-1074, 0);
  std::uniform_real_distribution<double> mant(0, 1);
  const int k = pick(rng);
  return k == 0 ? 0.0 : k == 1 ? 1.0 : k == 2 ? std::ldexp(mant(rng), ex(rng)) : mant(rng);
}

}  // namespace

// linear_corner_rounding: linear_queries.cpp's make_linear_points (dx = x1 - x0) and
// enclose_linear (p = x0 + t dx, w / ea / eb differences of points, the corner
// value (w + a ea) - b eb) stay within kLinearCornerRounding M +
// kLinearCornerUnderflow of the exact corner value of the exact points.
TEST_CASE("linear corner values within kLinearCornerRounding (Allowances.v linear_corner_rounding)",
          "[proved]") {
  std::mt19937_64 rng(45);
  double worst = 0;  // the largest error seen, in units of the allowance
  for (int n = 0; n < 20000; ++n) {
    std::array<double, 6> x0, x1;
    double M = 0;
    for (int k = 0; k < 6; ++k) {
      x0[k] = coordinate(rng), x1[k] = coordinate(rng);
      M = std::max({M, std::abs(x0[k]), std::abs(x1[k])});
    }
    const double t = parameter(rng), a = parameter(rng), b = parameter(rng);
    double p[6];
    mpq_class P[6];
    for (int k = 0; k < 6; ++k) {
      const double dx = x1[k] - x0[k];
      p[k] = x0[k] + t * dx;
      P[k] = Q(x0[k]) + Q(t) * (Q(x1[k]) - Q(x0[k]));
    }
    const double w = p[0] - p[1], ea = p[2] - p[3], eb = p[4] - p[5];
    const double c = (w + a * ea) - b * eb;
    const mpq_class F = (P[0] - P[1]) + Q(a) * (P[2] - P[3]) - Q(b) * (P[4] - P[5]);
    const mpq_class allowance = Q(kLinearCornerRounding) * Q(M) + Q(kLinearCornerUnderflow);
    const mpq_class err = abs(Q(c) - F);
    REQUIRE(err <= allowance);
    worst = std::max(worst, mpq_class(err / allowance).get_d());
  }
  // The proof's bound, 69 u M + 44 2^-1075, is 0.54 of the allowance.
  CHECK(worst <= 0.54);
}

// linear_corner_selection: the least of the four corner values is the one at
// the least a ea and the largest b eb, as enclose_linear takes it.
TEST_CASE("the least and largest corner values as enclose_linear selects them (Allowances.v "
          "linear_corner_selection)",
          "[proved]") {
  std::mt19937_64 rng(4545);
  for (int n = 0; n < 20000; ++n) {
    const double w = coordinate(rng), ea = coordinate(rng), eb = coordinate(rng);
    const double a[2] = {parameter(rng), parameter(rng)}, b[2] = {parameter(rng), parameter(rng)};
    const double pa0 = a[0] * ea, pa1 = a[1] * ea, pb0 = b[0] * eb, pb1 = b[1] * eb;
    const double least = (w + std::min(pa0, pa1)) - std::max(pb0, pb1);
    const double most = (w + std::max(pa0, pa1)) - std::min(pb0, pb1);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const double pa : {pa0, pa1})
      for (const double pb : {pb0, pb1}) lo = std::min(lo, (w + pa) - pb), hi = std::max(hi, (w + pa) - pb);
    REQUIRE(least == lo);
    REQUIRE(most == hi);
  }
}

// norm_upper_bound, norm_lower_bound: norm_up / norm_down of the computed
// norm bound the exact Euclidean norm of the double vector v, checked exactly
// (squares of rationals) at every scale from subnormal components (where the
// squares underflow, the theorems' floor kNormFloor speaking) to 2^509, with
// zero and signed-zero components.
TEST_CASE("norm_up and norm_down bound the exact norm at every scale (Allowances.v norm_up_relative, "
          "norm_up_wide, norm_down_wide)",
          "[proved]") {
  std::mt19937_64 rng(454545);
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> ex(-1074, 509), pick(0, 4);
  for (int n = 0; n < 40000; ++n) {
    const int e = ex(rng);
    Eigen::Vector3d v(std::ldexp(mant(rng), e), std::ldexp(mant(rng), e), std::ldexp(mant(rng), e));
    const int k = pick(rng);
    if (k < 3) v[k] = k == 0 ? 0.0 : -0.0;
    const mpq_class S = Q(v.x()) * Q(v.x()) + Q(v.y()) * Q(v.y()) + Q(v.z()) * Q(v.z());
    for (const double relative : {kRelativeRounding, kRelativeRoundingWide}) {
      const double up = norm_up(v.norm(), relative).v;
      REQUIRE(up > 0);
      REQUIRE(Q(up) * Q(up) >= S);
    }
    const double down = norm_down(v.norm(), kRelativeRoundingWide).v;
    REQUIRE(down >= 0);
    REQUIRE(Q(down) * Q(down) <= S);
    REQUIRE(norm_down(std::sqrt(v.squaredNorm()), kRelativeRoundingWide).v == down);
  }
}

// The finding the floor fixes: at |v| ~ 2^-537 the squares round to 0, so
// the unfloored forms fell below |v| (up) or to a divisor <= 0 (down).
TEST_CASE("the norm's bounds hold where the squares underflow (Allowances.v norm_upper_bound)", "[proved]") {
  const Eigen::Vector3d v = Eigen::Vector3d::Constant(0x1p-538);
  const mpq_class S = 3 * Q(0x1p-538) * Q(0x1p-538);
  REQUIRE(v.norm() == 0);
  const double unfloored = round_up(v.norm() * (1 + kRelativeRounding)).v;
  CHECK(Q(unfloored) * Q(unfloored) < S);  // the old form: too small
  const double up = norm_up(v.norm(), kRelativeRounding).v;
  CHECK(Q(up) * Q(up) >= S);
  CHECK(round_down(v.norm() * (1 - kRelativeRoundingWide)).v <= 0);  // the old divisor
  CHECK(norm_down(v.norm(), kRelativeRoundingWide).v == 0);
}

// The sites. Displacement's shift between two positions 2^-538 apart per
// coordinate bounds their distance (it was 2^-600 before the floor).
TEST_CASE("Displacement's shift bounds the distance of positions whose squares underflow", "[proved]") {
  Pose a, b;
  // identity orientations (Quat's default)
  b.p = Eigen::Vector3d::Constant(0x1p-538);
  const detail::Displacement d(a, b);
  REQUIRE(Q(d.shift) * Q(d.shift) >= 3 * Q(0x1p-538) * Q(0x1p-538));
}

// triangle_time_lower_bound along an axis whose computed norm underflows to 0
// (the normal of a triangle with edges of 2^-305): a vertex at distance 1
// closing at speed 1 meets the triangle's plane at time 1, so no bound above 1
// may be returned (the divisor round_down(0) < 0 gave +inf before the guard).
TEST_CASE("triangle_time_lower_bound drops an axis too short to divide by", "[proved]") {
  const double h = 0x1p-305;
  const Vec3 B[3] = {Vec3(0, 0, 0), Vec3(h, 0, 0), Vec3(0, h, 0)};
  const Vec3 X[3] = {Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1)};
  REQUIRE(sat_side(B).n.norm() == 0);
  REQUIRE(sat_side(B).n.z() > 0);
  TriangleMotion m;
  m.v = Vec3(0, 0, -1);
  m.centre = X[0];
  Vec3 r[3];
  const double r_inf = corner_offsets<Shape::kVertex>(X, m.centre, r);
  const double t = triangle_time_lower_bound<Shape::kVertex, Shape::kTriangle>(
      sat_side<Shape::kVertex>(X), r, r_inf, sat_side(B), m, 0.0, std::numeric_limits<double>::infinity());
  REQUIRE(t <= 1.0);
}

// for_each_separating_axis divides by norm_up(|a|): along the same short
// normal, a big triangle at height 1 above the tiny one is at distance 1, and
// the gap bound may not exceed it (it was about 2^60 before the floor).
TEST_CASE("triangle_gap_lower_bound along an axis whose squares underflow", "[proved]") {
  const double h = 0x1p-270;
  const Vec3 A[3] = {Vec3(0, 0, 0), Vec3(h, 0, 0), Vec3(0, h, 0)};
  const Vec3 B[3] = {Vec3(-1, -1, 1), Vec3(2, -1, 1), Vec3(-1, 2, 1)};
  REQUIRE(sat_side(A).n.norm() == 0);
  const double g = triangle_gap_lower_bound(sat_side(A), sat_side(B), std::numeric_limits<double>::infinity());
  REQUIRE(g <= 1.0);
}

// step_rounding: the sub-interval's step (u1 - u0) dp_mid as StartFrame::obb_frame
// computes it, each coordinate within step_error = round_up(kRelativeRounding
// |step|_inf 2) of the exact product, for u0 <= u1 in [0, 1] (of every scale,
// equal, 0 and 1) and coordinates of every scale from subnormal to 1e30
// (signed zeros, the least normal), checked in rationals.
TEST_CASE("the step's rounding within kRelativeRounding |step|_inf 2 (Allowances.v step_rounding)", "[proved]") {
  std::mt19937_64 rng(4545);
  for (int n = 0; n < 20000; ++n) {
    double u0 = parameter(rng), u1 = parameter(rng);
    if (u0 > u1) std::swap(u0, u1);
    const Eigen::Vector3d dp(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d step = (u1 - u0) * dp;
    const double step_error = round_up(kRelativeRounding * step.cwiseAbs().maxCoeff() * 2).v;
    for (int i = 0; i < 3; ++i) {
      const mpq_class err = Q(step[i]) - (Q(u1) - Q(u0)) * Q(dp[i]);
      REQUIRE(abs(err) <= Q(step_error));
    }
  }
}

// axis_velocity_rounding: triangle_time_lower_bound's velocity term along an
// axis a, toward = max(0, round_up(side a.v)) + kAxisVelocityRounding |a|_1
// |v|_inf (the code's operations, in its order), is at least the exact
// side (a . v), checked in rationals for axes with |a|_1 >= 2^-900 (the
// theorem's hypothesis: the guard norm_down(|a|) > 0 keeps only |a| > 2^-500)
// and velocities of every scale down to subnormal, signed zeros included.
TEST_CASE("the velocity term within kAxisVelocityRounding (Allowances.v axis_velocity_rounding)", "[proved]") {
  std::mt19937_64 rng(45454);
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> ea(-899, 300), pick(0, 1);
  for (int n = 0; n < 40000; ++n) {
    const int e = ea(rng);
    Eigen::Vector3d a(std::ldexp(mant(rng), e), std::ldexp(mant(rng), e), std::ldexp(mant(rng), e));
    const Eigen::Vector3d v(coordinate(rng), coordinate(rng), coordinate(rng));
    if (Q(std::abs(a.x())) + Q(std::abs(a.y())) + Q(std::abs(a.z())) < Q(0x1p-900)) continue;
    const double side = pick(rng) ? 1.0 : -1.0;
    const double along_v = side * a.dot(v);
    const double a_1 = a.cwiseAbs().sum(), v_inf = v.cwiseAbs().maxCoeff();
    const double slack = kAxisVelocityRounding * a_1 * v_inf;
    const double toward = (max(Upper{0.0}, round_up(along_v)) + Upper{slack}).v;
    const mpq_class exact = Q(side) * (Q(a.x()) * Q(v.x()) + Q(a.y()) * Q(v.y()) + Q(a.z()) * Q(v.z()));
    REQUIRE(exact <= Q(toward));
  }
}

// corner_offset_rounding: corner_offsets' r_k = A_k - centre (doubles, the
// god corner and G) errs from the exact difference by at most
// kCornerOffsetRounding |A_k - centre| in the Euclidean norm (the theorem with
// static_error 0 and r the exact |A_k - centre|), checked in rationals (the
// squares compared) with corners and centres of every scale from subnormal to
// 1e30, signed zeros, and corners near the centre (the cancelling case).
TEST_CASE("corner offsets within kCornerOffsetRounding r (Allowances.v corner_offset_rounding)", "[proved]") {
  std::mt19937_64 rng(454545);
  std::uniform_int_distribution<int> near(0, 1), ulps(-4, 4);
  for (int n = 0; n < 20000; ++n) {
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    Eigen::Vector3d A[3];
    for (auto& a : A) {
      for (int i = 0; i < 3; ++i) {
        // half of the corners a few ulps from the centre's coordinate
        a[i] = near(rng) ? coordinate(rng) : p[i] + ulps(rng) * std::abs(p[i]) * 0x1p-52;
      }
    }
    Eigen::Vector3d r[3];
    corner_offsets(A, p, r);
    for (int k = 0; k < 3; ++k) {
      mpq_class err2 = 0, exact2 = 0;
      for (int i = 0; i < 3; ++i) {
        const mpq_class d = Q(A[k][i]) - Q(p[i]), e = Q(r[k][i]) - d;
        err2 += e * e;
        exact2 += d * d;
      }
      REQUIRE(err2 <= Q(kCornerOffsetRounding) * Q(kCornerOffsetRounding) * exact2);
    }
  }
}

// swept_box_rounding: swept_box's world box holds R r for every R within
// R_rad of R_mid entrywise and every r of the body box, R and r taken at the
// extremes (R_mid +- R_rad, the box's corners) where the exact product is
// farthest, checked in rationals; R_mid's entries and the box's coordinates
// of every scale (subnormal to 1e30, signed zeros), R_rad 0, subnormal or up
// to 1e-3, p = 0.
TEST_CASE("swept_box holds the exact products (Allowances.v swept_box_rounding)", "[proved]") {
  std::mt19937_64 rng(4545454);
  std::uniform_int_distribution<int> bit(0, 1), rad(0, 2), er(-1074, -10);
  std::uniform_real_distribution<double> unit(-1, 1), mant(0, 1);
  for (int n = 0; n < 5000; ++n) {
    MotionEnclosure e;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        e.R_mid(i, j) = bit(rng) ? unit(rng) : std::ldexp(unit(rng), er(rng));
        const int k = rad(rng);
        e.R_rad(i, j) = k == 0 ? 0.0 : k == 1 ? std::ldexp(mant(rng), er(rng)) : 1e-3 * mant(rng);
      }
      e.p[i] = Interval{0.0, 0.0};
    }
    e.R_abs = e.R_mid.cwiseAbs();
    Aabb body;
    for (int i = 0; i < 3; ++i) {
      double a = coordinate(rng), b = bit(rng) ? coordinate(rng) : a;
      if (a > b) std::swap(a, b);
      body.lo[i] = a;
      body.hi[i] = b;
    }
    const Aabb w = swept_box(e, body);
    for (int corner = 0; corner < 8; ++corner) {
      for (int signs = 0; signs < 8; ++signs) {
        for (int i = 0; i < 3; ++i) {
          mpq_class x = 0;
          for (int j = 0; j < 3; ++j) {
            const mpq_class R = Q(e.R_mid(i, j)) + ((signs >> j) & 1 ? 1 : -1) * Q(e.R_rad(i, j));
            x += R * Q((corner >> j) & 1 ? body.hi[j] : body.lo[j]);
          }
          REQUIRE(Q(w.lo[i]) <= x);
          REQUIRE(x <= Q(w.hi[i]));
        }
      }
    }
  }
}

// box_pose_encloses (BoxPose.v): posed_body_box, generate_contacts' world box
// of a god body box, holds every double vertex of the body box posed as
// generate_contacts poses it (G + R v in doubles). Adversarial: G and R mid
// cancel (a body box at about -G in the body frame, turned by a small angle
// about z), so |c| is tiny while the vertices round relative to |G|, and the
// box is flat along one body axis and narrow along another, so h is tiny too:
// a slack relative to |c| + h (the form before BoxPose.v) misses vertices
// there by ~1e-16 |G|. Random poses and boxes of every scale besides.
TEST_CASE("posed_body_box holds the posed vertices where G and R mid cancel (BoxPose.v box_pose_encloses)",
          "[proved]") {
  std::mt19937_64 rng(45450045);
  std::uniform_real_distribution<double> unit(-1, 1), mant(0.5, 1);
  std::uniform_int_distribution<int> ex_g(-20, 40), ex_t(-45, -5), ex_l(-40, 10), ex_any(-1074, 99), pick(0, 2);
  const auto check = [](const Pose& X, const Aabb& box, const Vec3& v) {
    const Mat3 R = rotation_matrix(X.q);
    const Aabb w = posed_body_box(R, R.cwiseAbs(), X.p, box);
    const Vec3 x = X.p + R * v;  // as generate_contacts' world(v)
    for (int i = 0; i < 3; ++i) {
      INFO("coordinate " << i << " x " << x[i] << " box [" << w.lo[i] << ", " << w.hi[i] << "]");
      REQUIRE(w.lo[i] <= x[i]);
      REQUIRE(x[i] <= w.hi[i]);
    }
  };
  for (int n = 0; n < 20000; ++n) {
    Pose X;
    Aabb box;
    if (n % 2 == 0) {  // cancelling: R m ~ -G along x, the box flat in body x and thin in body y
      const double theta = std::ldexp(mant(rng), ex_t(rng)) * (unit(rng) < 0 ? -1 : 1);
      X.q = Quat{std::cos(theta / 2), 0, 0, std::sin(theta / 2)};
      X.p = Vec3(std::ldexp(unit(rng), ex_g(rng)), std::ldexp(unit(rng), ex_g(rng)), unit(rng));
      const Mat3 R = rotation_matrix(X.q);
      const double a = -X.p.x() / R(0, 0);
      const double L = std::ldexp(mant(rng), ex_l(rng));
      const double y0 = unit(rng) * L;
      box.lo = Vec3(a, y0 - L, -1);
      box.hi = Vec3(pick(rng) == 0 ? std::nextafter(a, 2 * std::abs(a) + 1) : a, y0 + L, 1);
    } else {  // any pose and box, coordinates of every scale
      X.q = Quat{unit(rng), unit(rng), unit(rng), unit(rng)};
      if (X.q.norm2() == 0) X.q = Quat{};
      X.p = Vec3(std::ldexp(unit(rng), ex_g(rng)), std::ldexp(unit(rng), ex_any(rng)), coordinate(rng) * 1e-18);
      for (int i = 0; i < 3; ++i) {
        double lo = std::ldexp(unit(rng), pick(rng) == 0 ? ex_any(rng) : ex_g(rng)), hi = lo + std::ldexp(mant(rng), ex_l(rng));
        box.lo[i] = lo;
        box.hi[i] = hi;
      }
    }
    for (int corner = 0; corner < 8; ++corner)
      check(X, box, Vec3((corner & 1) ? box.hi.x() : box.lo.x(), (corner & 2) ? box.hi.y() : box.lo.y(),
                         (corner & 4) ? box.hi.z() : box.lo.z()));
    for (int k = 0; k < 8; ++k) {
      Vec3 v;
      for (int i = 0; i < 3; ++i) {
        const double t = 0.5 * (unit(rng) + 1);
        v[i] = std::clamp(box.lo[i] + t * (box.hi[i] - box.lo[i]), box.lo[i], box.hi[i]);
      }
      check(X, box, v);
    }
  }
}
