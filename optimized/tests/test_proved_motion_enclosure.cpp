// Tests of proofs/MotionEnclosure.v: make_ccd_motion_encloses (the CcdMotion
// holds the exact p0, dp, g, R(q0), |g|^2, [g]x^2 of the input doubles),
// enclose_exact_motion and enclose_motion_encloses (for every u of the interval
// enclose_motion is given, the exact motion's p(u) lies in e.p and every entry
// of R(u) = C(u g) R(q0) in e.R and within e.R_rad of e.R_mid) and
// swept_box_motion (swept_box over that enclosure holds p(u) + R(u) r for every
// r of the body box), against the exact Cayley motion in rationals
// (ccd_test_util.h's ExactMotion). The motions are random, with positions up
// to 1e12 and subnormal, turns from none (g = 0) to near the half turn's limit;
// the intervals random, points, [0, 1], subnormal, and around alpha's peak
// u = 1 / |g| (the case enclose_motion caps), u sampled at both ends, at random
// rationals inside and at the peak.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <cmath>
#include <random>

#include "ccd_test_util.h"
#include "gauss6/ccd/motion.h"
#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/geometry/pose.h"

using namespace gauss6;
using gauss6::test::ExactMotion;
using gauss6::test::Q;
using gauss6::test::Q3;
using gauss6::test::q3;

namespace {

// R(u) = C(u g) R0 of the exact motion, row-major, in rationals.
void exact_rotation(const ExactMotion& m, const mpq_class& u, mpq_class R[9]) {
  const Q3 h = u * m.g;
  const mpq_class f = mpq_class(2) / (1 + gauss6::test::dot(h, h));
  const mpq_class K[9] = {0, -h.z, h.y, h.z, 0, -h.x, -h.y, h.x, 0};
  mpq_class C[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      mpq_class kk = 0;
      for (int k = 0; k < 3; ++k) kk += K[3 * i + k] * K[3 * k + j];
      C[3 * i + j] = (i == j ? mpq_class(1) : mpq_class(0)) + f * (K[3 * i + j] + kk);
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      R[3 * i + j] = C[3 * i] * m.R0[j] + C[3 * i + 1] * m.R0[3 + j] + C[3 * i + 2] * m.R0[6 + j];
}

bool in(const Interval& I, const mpq_class& x) { return Q(I.lo) <= x && x <= Q(I.hi); }

// The parameters u of [u0, u1] the checks sample: both ends, random points,
// and alpha's peak 1 / |g| (rounded to a double) when it lies inside.
std::vector<mpq_class> samples(double u0, double u1, double gnorm, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<mpq_class> out = {Q(u0), Q(u1)};
  for (int k = 0; k < 3; ++k) out.push_back(Q(u0) + Q(unit(rng)) * (Q(u1) - Q(u0)));
  const double peak = gnorm > 0 ? 1 / gnorm : 2;
  if (peak >= u0 && peak <= u1) out.push_back(Q(peak));
  return out;
}

struct Case {
  Pose x0, x1;
  double u0, u1;
};

// Random motions and intervals, the adversarial ones among them.
Case make_case(std::mt19937_64& rng, int i) {
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<int> ex_tiny(-1074, 40), ex_p(-30, 40), ex_turn(-40, 0), pick(0, 7);
  const int kind = i % 4;
  // kind 0: positions from subnormal to the largest scene coordinate
  const double s = std::min(std::ldexp(1.0, kind == 0 ? ex_tiny(rng) : ex_p(rng)), 1e12);
  Case c;
  c.x0 = {s * Vec3(n(rng), n(rng), n(rng)), normalized(Quat{n(rng), n(rng), n(rng), n(rng)})};
  // kind 1: none (g = 0); kind 2: near kMaxMotionAngle; else random
  const double turn = kind == 1 ? 0.0 : kind == 2 ? kMaxMotionAngle * (1 - 0.01 * unit(rng))
                                                  : std::ldexp(unit(rng), ex_turn(rng)) * 2.9;
  c.x1 = {c.x0.p + s * Vec3(n(rng), n(rng), n(rng)),
          normalized(quat_exp(turn * Vec3(n(rng), n(rng), n(rng)).normalized()) * c.x0.q)};
  double a = unit(rng), b = unit(rng);
  switch (pick(rng)) {
    case 0: a = b; break;                                                   // a point
    case 1: a = 0; b = 1; break;                                            // the whole motion
    case 2: a = 0; b = std::numeric_limits<double>::denorm_min(); break;    // subnormal
    case 3: a = b = 1; break;
    case 4: a = 0; break;
    default: break;
  }
  c.u0 = std::min(a, b);
  c.u1 = std::max(a, b);
  return c;
}

// Narrow intervals around alpha's peak 1 / |g|, |g| from 0.5 to near its limit.
Case peak_case(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> unit(0, 1);
  Case c;
  c.x0 = {Vec3(n(rng), n(rng), n(rng)), normalized(Quat{n(rng), n(rng), n(rng), n(rng)})};
  const double turn = 0.93 + (kMaxMotionAngle - 0.94) * unit(rng);
  c.x1 = {c.x0.p + Vec3(n(rng), n(rng), n(rng)),
          normalized(quat_exp(turn * Vec3(n(rng), n(rng), n(rng)).normalized()) * c.x0.q)};
  const double peak = 1 / std::tan(0.5 * turn);
  const double w = std::ldexp(unit(rng), -static_cast<int>(60 * unit(rng)));
  c.u0 = std::max(0.0, peak - w * unit(rng));
  c.u1 = std::min(1.0, peak + w * unit(rng));
  return c;
}

}  // namespace

TEST_CASE("make_ccd_motion holds the exact motion's data (MotionEnclosure.v make_ccd_motion_encloses)",
          "[proved]") {
  std::mt19937_64 rng(45045057);
  int checked = 0;
  for (int i = 0; i < 800; ++i) {
    const Case c = i % 8 == 7 ? peak_case(rng) : make_case(rng, i);
    CcdMotion m;
    if (make_ccd_motion(c.x0, c.x1, &m) != MotionStatus::kOk) continue;
    const ExactMotion exact(c.x0, c.x1);
    INFO("case " << i);
    const Q3 p0 = exact.p0, dp = exact.dp, g = exact.g;
    const mpq_class pe[3] = {p0.x, p0.y, p0.z}, de[3] = {dp.x, dp.y, dp.z}, ge[3] = {g.x, g.y, g.z};
    const mpq_class g2 = gauss6::test::dot(g, g);
    REQUIRE(in(m.g2, g2));
    for (int k = 0; k < 3; ++k) {
      REQUIRE(in(m.p0[k], pe[k]));
      REQUIRE(in(m.dp[k], de[k]));
      REQUIRE(in(m.g[k], ge[k]));
    }
    for (int k = 0; k < 9; ++k) {
      const int a = k / 3, b = k % 3;
      REQUIRE(in(m.R0[k], exact.R0[k]));
      REQUIRE(in(m.K2[k], ge[a] * ge[b] - (a == b ? g2 : mpq_class(0))));  // [g]x^2 = g g^T - |g|^2 I
    }
    ++checked;
  }
  CHECK(checked > 600);
}

TEST_CASE("enclose_motion holds the exact motion's pose at every u of its interval (MotionEnclosure.v "
          "enclose_exact_motion, enclose_motion_encloses)",
          "[proved]") {
  std::mt19937_64 rng(45045058);
  std::normal_distribution<double> n(0, 1);
  int checked = 0, peaks = 0;
  for (int i = 0; i < 1600; ++i) {
    const Case c = i % 8 == 7 ? peak_case(rng) : make_case(rng, i);
    CcdMotion m;
    if (make_ccd_motion(c.x0, c.x1, &m) != MotionStatus::kOk) continue;  // a half turn
    MotionEnclosure e;
    enclose_motion(m, {c.u0, c.u1}, &e);
    const ExactMotion exact(c.x0, c.x1);
    const double gnorm = std::sqrt(exact.g.x.get_d() * exact.g.x.get_d() + exact.g.y.get_d() * exact.g.y.get_d() +
                                   exact.g.z.get_d() * exact.g.z.get_d());
    if (gnorm > 0 && 1 / gnorm > c.u0 && 1 / gnorm < c.u1) ++peaks;
    for (const mpq_class& u : samples(c.u0, c.u1, gnorm, rng)) {
      INFO("case " << i << " u in [" << c.u0 << ", " << c.u1 << "] u = " << u.get_d() << " |g| " << gnorm);
      const Q3 p = exact.p0 + u * exact.dp;
      REQUIRE(in(e.p[0], p.x));
      REQUIRE(in(e.p[1], p.y));
      REQUIRE(in(e.p[2], p.z));
      mpq_class R[9];
      exact_rotation(exact, u, R);
      for (int k = 0; k < 9; ++k) {
        INFO("entry " << k << " exact " << R[k].get_d() << " in [" << e.R[k].lo << ", " << e.R[k].hi << "]");
        REQUIRE(in(e.R[k], R[k]));
        REQUIRE(abs(R[k] - Q(e.R_mid(k / 3, k % 3))) <= Q(e.R_rad(k / 3, k % 3)));
        REQUIRE(e.R_abs(k / 3, k % 3) == std::abs(e.R_mid(k / 3, k % 3)));
      }
      ++checked;
    }
  }
  CHECK(checked > 5000);
  CHECK(peaks > 100);  // the capped case is exercised
}

TEST_CASE("swept_box over enclose_motion holds every pose of the exact motion (MotionEnclosure.v "
          "swept_box_motion)",
          "[proved]") {
  std::mt19937_64 rng(45045059);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> unit(0, 1);
  int checked = 0;
  for (int i = 0; i < 800; ++i) {
    const Case c = i % 8 == 7 ? peak_case(rng) : make_case(rng, i);
    CcdMotion m;
    if (make_ccd_motion(c.x0, c.x1, &m) != MotionStatus::kOk) continue;
    MotionEnclosure e;
    enclose_motion(m, {c.u0, c.u1}, &e);
    const double size = std::ldexp(1.0, static_cast<int>(40 * unit(rng)) - 20);
    const Vec3 a = size * Vec3(n(rng), n(rng), n(rng)), b = size * Vec3(n(rng), n(rng), n(rng));
    const Aabb body{a.cwiseMin(b), a.cwiseMax(b)};
    const Aabb box = swept_box(e, body);
    const ExactMotion exact(c.x0, c.x1);
    for (const mpq_class& u : samples(c.u0, c.u1, 0, rng)) {
      for (int k = 0; k < 10; ++k) {
        // the body box's corners and random points inside
        const Vec3 r = k < 8 ? Vec3((k & 1) ? body.hi.x() : body.lo.x(), (k & 2) ? body.hi.y() : body.lo.y(),
                                    (k & 4) ? body.hi.z() : body.lo.z())
                             : body.lo + Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(body.hi - body.lo);
        const Q3 w = exact.point(u, q3(r));
        INFO("case " << i << " u = " << u.get_d() << " corner " << k);
        REQUIRE(Q(box.lo.x()) <= w.x);
        REQUIRE(w.x <= Q(box.hi.x()));
        REQUIRE(Q(box.lo.y()) <= w.y);
        REQUIRE(w.y <= Q(box.hi.y()));
        REQUIRE(Q(box.lo.z()) <= w.z);
        REQUIRE(w.z <= Q(box.hi.z()));
        ++checked;
      }
    }
  }
  CHECK(checked > 20000);
}
