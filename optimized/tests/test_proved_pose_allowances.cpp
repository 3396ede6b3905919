// Tests of the theorems of proofs/PoseAllowances.v: each proved bound,
// computed by its site's code (tied to the theorem by the hash
// tools/check_proofs.sh compares), against the exact value in rationals
// (GMP), on random and adversarial inputs: quaternions of every scale that
// rescaled() brings back (components from subnormal to 2^1000, signed zeros),
// body points and positions with subnormal, zero and signed-zero coordinates
// up to the largest the CCD accepts (kMaxCoordinate, 1e30), and points so
// small that the posing's products underflow (the allowance's edge, where only
// the absolute 2^-600 of next_up covers the rounding).
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/error_allowances.h"
#include "gauss6/numeric/rounding.h"

using namespace gauss6;

namespace {

mpq_class Q(double x) { return mpq_class(x); }

// A double of scale 2^e, e in [e_lo, e_hi], or an adversarial one.
double scaled(std::mt19937_64& rng, int e_lo, int e_hi) {
  static const std::array<double, 8> kSpecial = {0.0,  -0.0, std::numeric_limits<double>::denorm_min(),
                                                 -std::numeric_limits<double>::min(), 1.0, -1.0,
                                                 0x1p-401, 1.0 - 0x1p-53};
  std::uniform_int_distribution<int> ex(e_lo, e_hi), pick(0, 11);
  std::uniform_real_distribution<double> mant(-1, 1);
  const int k = pick(rng);
  return k < 8 ? kSpecial[static_cast<size_t>(k)] : std::ldexp(mant(rng), ex(rng));
}

// A non-zero quaternion: one scale for all four components (of every scale
// rescaled() handles), each component also at its own scale or special.
Quat quaternion(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> scale(-1000, 1000), pick(0, 3);
  for (;;) {
    const int e = pick(rng) == 0 ? 0 : scale(rng);
    Quat q;
    double* c[4] = {&q.w, &q.x, &q.y, &q.z};
    for (double* x : c) *x = pick(rng) == 0 ? scaled(rng, -1074, 0) : std::ldexp(scaled(rng, -60, 0), e);
    if (q.w != 0 || q.x != 0 || q.y != 0 || q.z != 0) return q;
  }
}

// The exact rotation of q, N_ij / S (METHOD.md section 1's rational form).
std::array<mpq_class, 9> exact_rotation(const Quat& q) {
  const mpq_class w = Q(q.w), x = Q(q.x), y = Q(q.y), z = Q(q.z);
  const mpq_class S = w * w + x * x + y * y + z * z;
  std::array<mpq_class, 9> R = {w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y),
                                2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x),
                                2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z};
  for (auto& e : R) e /= S;
  return R;
}

}  // namespace

// pose_rounding, pose_rounding_start_frame, pose_rounding_stand_at: a body
// point r_B posed in doubles (StartFrame::pose, R * r_B + p with R =
// rotation_matrix(q); transform_point, the same rounding) lies within the
// posing term of static_error (kPoseRounding * (p_inf + Upper{rho}), Upper
// arithmetic) and of stand_at's posing_error (round_up of the plain sum, here
// with deviation 0, for rho >= 2^-1000) of the exact p + R(q) r_B.
TEST_CASE("a posed body point within kPoseRounding (|p|_inf + rho) (PoseAllowances.v pose_rounding, "
          "pose_rounding_start_frame, pose_rounding_stand_at)",
          "[proved]") {
  std::mt19937_64 rng(4545);
  double worst = 0;  // the largest error seen, in units of kPoseRounding (|p|_inf + rho)
  for (int n = 0; n < 20000; ++n) {
    const Quat q = quaternion(rng);
    // Points and positions of every scale; one in four of the points at the
    // bottom of the range, where the products R_ij r_j underflow.
    const bool tiny = n % 4 == 0;
    Vec3 r, p;
    for (int i = 0; i < 3; ++i) {
      r[i] = tiny ? scaled(rng, -1074, -1000) : scaled(rng, -1074, 99);
      p[i] = tiny && n % 8 == 0 ? scaled(rng, -1074, -1000) : scaled(rng, -1074, 99);
      if (std::abs(r[i]) > 1e30) r[i] = std::copysign(1e30, r[i]);
      if (std::abs(p[i]) > 1e30) p[i] = std::copysign(1e30, p[i]);
    }
    const double rho = r.cwiseAbs().maxCoeff();
    detail::StartFrame f;
    f.R = rotation_matrix(q);
    f.p = p;
    const Vec3 X = f.pose(r);
    const Vec3 X2 = transform_point(Pose{p, q}, r);
    REQUIRE((X.array() == X2.array()).all());
    const auto R = exact_rotation(q);
    mpq_class err2 = 0;
    for (int i = 0; i < 3; ++i) {
      const mpq_class exact = Q(p[i]) + R[3 * i] * Q(r[0]) + R[3 * i + 1] * Q(r[1]) + R[3 * i + 2] * Q(r[2]);
      const mpq_class e = Q(X[i]) - exact;
      err2 += e * e;
    }
    const double p_inf = p.cwiseAbs().maxCoeff();
    const double start = (kPoseRounding * (Upper{p_inf} + Upper{rho})).v;  // StartFrame::set's term
    REQUIRE(err2 <= Q(start) * Q(start));
    if (rho >= 0x1p-1000) {
      const double stand = round_up(0.0 + kPoseRounding * (p_inf + rho)).v;  // stand_at, deviation 0
      REQUIRE(err2 <= Q(stand) * Q(stand));
    }
    if (p_inf + rho >= 0x1p-900) {
      const mpq_class unit = Q(kPoseRounding) * (Q(p_inf) + Q(rho));
      worst = std::max(worst, std::sqrt(mpq_class(err2 / (unit * unit)).get_d()));
    }
  }
  // The proof's bound, 309 u (|p|_inf + rho) above the underflow, is 0.343 of the allowance.
  CHECK(worst <= 0.343);
  CHECK(worst > 0);
}

// quaternion_turn_rounding: Displacement's turn, round_up(2 |v|) +
// kQuaternionTurnRounding with v = vec(conj(qa) qb) of the normalized double
// quaternions, is at least 2 |vec(conj(A) B)| for the exact unit quaternions
// A = qa / |qa|, B = qb / |qb|, decided in rationals: 4 |W|^2 <= turn^2 |qa|^2
// |qb|^2, W = vec(conj(qa) qb). Pairs of every scale and relation: random,
// equal, opposite, a few ulps apart (a turn near 0, where only the allowance
// covers the rounding), and a half turn apart.
TEST_CASE("Displacement's turn bounds the exact turn (PoseAllowances.v quaternion_turn_rounding)", "[proved]") {
  std::mt19937_64 rng(4546);
  std::uniform_int_distribution<int> relation(0, 4), ulps(-4, 4);
  double worst = 0;  // the largest 2 |V| - (turn - allowance), in units of the allowance
  for (int n = 0; n < 20000; ++n) {
    const Quat qa = quaternion(rng);
    Quat qb = quaternion(rng);
    switch (relation(rng)) {
      case 0: qb = qa; break;
      case 1: qb = {-qa.w, -qa.x, -qa.y, -qa.z}; break;
      case 2: {
        double* c[4] = {&qb.w, &qb.x, &qb.y, &qb.z};
        const double* a[4] = {&qa.w, &qa.x, &qa.y, &qa.z};
        for (int k = 0; k < 4; ++k) {
          double x = *a[k];
          for (int s = ulps(rng); s != 0; s += s > 0 ? -1 : 1) x = std::nextafter(x, s > 0 ? 1e300 : -1e300);
          *c[k] = x;
        }
        break;
      }
      case 3: qb = {-qa.x, qa.w, -qa.z, qa.y}; break;  // qa times i: a half turn
      default: break;
    }
    if (qb.w == 0 && qb.x == 0 && qb.y == 0 && qb.z == 0) continue;
    const detail::Displacement d(Pose{Vec3::Zero(), qa}, Pose{Vec3::Zero(), qb});
    const mpq_class aw = Q(qa.w), ax = Q(qa.x), ay = Q(qa.y), az = Q(qa.z);
    const mpq_class bw = Q(qb.w), bx = Q(qb.x), by = Q(qb.y), bz = Q(qb.z);
    const mpq_class W0 = aw * bx - bw * ax - (ay * bz - az * by);
    const mpq_class W1 = aw * by - bw * ay - (az * bx - ax * bz);
    const mpq_class W2 = aw * bz - bw * az - (ax * by - ay * bx);
    const mpq_class Sa = aw * aw + ax * ax + ay * ay + az * az, Sb = bw * bw + bx * bx + by * by + bz * bz;
    const mpq_class V2 = (W0 * W0 + W1 * W1 + W2 * W2) / (Sa * Sb);  // |vec(conj(A) B)|^2
    REQUIRE(d.turn >= 0);
    REQUIRE(4 * V2 <= Q(d.turn) * Q(d.turn));
    worst = std::max(worst, (2 * std::sqrt(V2.get_d()) - (d.turn - kQuaternionTurnRounding)) / kQuaternionTurnRounding);
  }
  // The proof's bound, 2 |V| <= 2 |v|~ + 52 u, is 0.58 of the allowance.
  CHECK(worst <= 0.6);
}
