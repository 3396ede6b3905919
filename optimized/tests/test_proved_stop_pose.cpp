// Tests of proofs/StopPose.v, stop_pose_deviation: every body point r with
// |r_j| <= rho, placed exactly at the double pose make_stop_pose returns
// (p + R(q) r, R(q) the rational rotation of the double q), lies within the
// returned deviation of the exact Cayley motion's point at u (p(u) + C(u g)
// R(q0) r), in rationals (ccd_test_util.h's ExactMotion). The body points are
// the corners of the cube |r_j| <= rho (the theorem's region, which holds the
// ball of radius rho) and random points in it; the motions random, with
// positions up to the largest scene coordinate (1e12), turns from 0 to near
// the half turn's limit, u at 0, 1, subnormal and random.
#include <catch2/catch.hpp>

#include <gmpxx.h>

#include <cmath>
#include <random>

#include "ccd_test_util.h"
#include "gauss6/ccd/motion.h"
#include "gauss6/geometry/pose.h"

using namespace gauss6;
using gauss6::test::ExactMotion;
using gauss6::test::Q;
using gauss6::test::Q3;
using gauss6::test::q3;

TEST_CASE("a body point at the stop pose lies within its deviation of the exact motion's (StopPose.v "
          "stop_pose_deviation)",
          "[proved]") {
  std::mt19937_64 rng(45045047);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<int> ex_p(-30, 40), ex_turn(-40, 0), ex_rho(-20, 20), pick(0, 4);
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const double s = std::min(std::ldexp(1.0, ex_p(rng)), 1e12);
    const Pose x0{s * Vec3(n(rng), n(rng), n(rng)), normalized(Quat{n(rng), n(rng), n(rng), n(rng)})};
    const double turn = std::ldexp(unit(rng), ex_turn(rng)) * 2.5;
    const Pose x1{x0.p + s * unit(rng) * Vec3(n(rng), n(rng), n(rng)),
                  normalized(quat_exp(turn * Vec3(n(rng), n(rng), n(rng)).normalized()) * x0.q)};
    CcdMotion m;
    if (make_ccd_motion(x0, x1, &m) != MotionStatus::kOk) continue;  // a half turn
    const int k = pick(rng);
    const double u = k == 0 ? 0.0 : k == 1 ? 1.0 : k == 2 ? std::numeric_limits<double>::denorm_min() : unit(rng);
    const double rho = std::ldexp(1.0 + unit(rng), ex_rho(rng));
    const StopPose sp = make_stop_pose(m, u, rho);
    REQUIRE(std::isfinite(sp.deviation));
    const ExactMotion motion(x0, x1), at_stop(sp.pose, sp.pose);  // at_stop.point(0, r) = p + R(q) r
    const mpq_class dev2 = Q(sp.deviation) * Q(sp.deviation);
    for (int c = 0; c < 12; ++c) {
      const Vec3 r = c < 8 ? Vec3((c & 1) ? rho : -rho, (c & 2) ? rho : -rho, (c & 4) ? rho : -rho)
                           : Vec3(rho * (2 * unit(rng) - 1), rho * (2 * unit(rng) - 1), rho * (2 * unit(rng) - 1));
      const Q3 d = at_stop.point(0, q3(r)) - motion.point(Q(u), q3(r));
      INFO("case " << i << " u " << u << " rho " << rho << " deviation " << sp.deviation);
      REQUIRE(gauss6::test::dot(d, d) <= dev2);
      ++checked;
    }
  }
  CHECK(checked > 300 * 12);
}
