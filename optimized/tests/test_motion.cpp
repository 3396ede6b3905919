// Tests of motion.h: the defining properties of the Cayley in-between motion (METHOD.md section 4).
#include <catch2/catch.hpp>

#include <cmath>
#include <algorithm>
#include <random>
#include <string>

#include "gauss6/ccd/motion.h"
#include "gauss6/runtime/sim_step4.h"  // split_step: where step 4 cuts a half turn

using namespace gauss6;

namespace {
Pose random_pose(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return {{n(rng), n(rng), n(rng)}, normalized(Quat{n(rng), n(rng), n(rng), n(rng)})};
}
// A pose rotated from x0 by `angle` about a random axis, and translated.
Pose rotated_from(const Pose& x0, double angle, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
  return {x0.p + Vec3(n(rng), n(rng), n(rng)), normalized(quat_exp(angle * axis) * x0.q)};
}
}  // namespace

TEST_CASE("the Cayley motion starts at x0, ends at x1 and stays a rotation", "[motion]") {
  std::mt19937 rng(3);
  for (int i = 0; i < 300; ++i) {
    const Pose x0 = random_pose(rng);
    const double angle = 2.9 * (i + 1) / 300.0;  // up to 166 degrees
    const Pose x1 = rotated_from(x0, angle, rng);
    CayleyMotion m;
    REQUIRE(make_cayley_motion(x0, x1, &m) == MotionStatus::kOk);
    // u = 0 is the start pose exactly up to the rounding of R(q0).
    CHECK((motion_rotation(m, 0.0) - rotation_matrix(x0.q)).norm() == 0.0);
    CHECK((motion_position(m, 0.0) - x0.p).norm() == 0.0);
    // u = 1 is the end pose up to rounding: |g| up to tan(83 deg) ~ 8 amplifies
    // the rounding of g = vec/w, hence 1e-13 rather than a few ulps.
    CHECK((motion_rotation(m, 1.0) - rotation_matrix(x1.q)).norm() < 1e-13);
    CHECK((motion_position(m, 1.0) - x1.p).norm() < 1e-14);
    // Every R(u) is orthogonal with determinant 1 (rounding only).
    for (double u : {0.1, 1.0 / 3.0, 0.5, 0.77, 0.999}) {
      const Mat3 R = motion_rotation(m, u);
      CHECK((R * R.transpose() - Mat3::Identity()).norm() < 1e-14);
      CHECK(R.determinant() == Approx(1.0).margin(1e-14));
    }
    // The motion's total angle is the relative angle.
    CHECK(motion_angle(m, 1.0) == Approx(angle).margin(1e-12));
  }
}

TEST_CASE("the Cayley angle grows monotonically with u", "[motion]") {
  std::mt19937 rng(5);
  const Pose x0 = random_pose(rng);
  const Pose x1 = rotated_from(x0, 2.5, rng);
  CayleyMotion m;
  REQUIRE(make_cayley_motion(x0, x1, &m) == MotionStatus::kOk);
  double prev = -1.0;
  for (int k = 0; k <= 1000; ++k) {
    const double u = k / 1000.0;
    // Measured from the matrices, not from the formula: angle of R(u) R0^T.
    const Mat3 Rrel = motion_rotation(m, u) * m.R0.transpose();
    const double angle = std::acos(std::clamp(0.5 * (Rrel.trace() - 1.0), -1.0, 1.0));
    CHECK(angle >= prev - 1e-12);  // acos loses precision near 0 and pi: 1e-12 slack
    prev = angle;
  }
}

TEST_CASE("body points move on the rational quadratic curve of the motion", "[motion]") {
  // p(u) + C(u g) R0 r: check against the closed form (D(u) P(u)) with D = 1 + u^2 |g|^2.
  std::mt19937 rng(9);
  const Pose x0 = random_pose(rng);
  const Pose x1 = rotated_from(x0, 1.0, rng);
  CayleyMotion m;
  REQUIRE(make_cayley_motion(x0, x1, &m) == MotionStatus::kOk);
  const Vec3 r(0.3, -0.2, 0.7);
  const Vec3 s = m.R0 * r;
  for (double u : {0.0, 0.25, 0.5, 1.0}) {
    const Vec3 h = u * m.g;
    const double D = 1.0 + h.squaredNorm();
    // C(h) s = s + 2/D (h x s + h x (h x s))
    const Vec3 expected = m.p0 + u * m.dp + s + (2.0 / D) * (h.cross(s) + h.cross(h.cross(s)));
    CHECK((motion_point(m, u, r) - expected).norm() < 1e-14);
  }
}

TEST_CASE("half turns are refused with a clear status and split_step makes them safe", "[motion]") {
  const Pose x0{};
  const Pose x1{Vec3(1, 0, 0), quat_exp(Vec3(0, 0, M_PI))};  // exactly 180 degrees
  CayleyMotion m;
  m.g = Vec3(42, 0, 0);
  CHECK(make_cayley_motion(x0, x1, &m) == MotionStatus::kHalfTurn);
  CHECK(m.g.x() == 42);  // untouched on failure
  CHECK(std::string(to_string(MotionStatus::kHalfTurn)).find("split") != std::string::npos);
  // Just past the limit is refused; just below it is accepted.
  CHECK(make_cayley_motion(x0, {Vec3::Zero(), quat_exp(Vec3(0, 0, kMaxMotionAngle + 1e-6))}, &m) ==
        MotionStatus::kHalfTurn);
  CHECK(make_cayley_motion(x0, {Vec3::Zero(), quat_exp(Vec3(0, 0, kMaxMotionAngle - 1e-6))}, &m) ==
        MotionStatus::kOk);
  // Splitting gives two 90-degree halves, each a valid motion.
  const Pose mid = split_step(x0, x1);
  REQUIRE(make_cayley_motion(x0, mid, &m) == MotionStatus::kOk);
  CHECK(motion_angle(m, 1.0) == Approx(0.5 * M_PI).epsilon(1e-12));
  REQUIRE(make_cayley_motion(mid, x1, &m) == MotionStatus::kOk);
  CHECK(motion_angle(m, 1.0) == Approx(0.5 * M_PI).epsilon(1e-12));
  CHECK((mid.p - Vec3(0.5, 0, 0)).norm() == 0.0);
}

TEST_CASE("zero rotation gives a pure translation and invalid poses are refused", "[motion]") {
  const Pose x0{Vec3(1, 2, 3), Quat{}};
  const Pose x1{Vec3(2, 2, 3), Quat{}};
  CayleyMotion m;
  REQUIRE(make_cayley_motion(x0, x1, &m) == MotionStatus::kOk);
  CHECK(m.g.norm() == 0.0);
  CHECK((motion_point(m, 0.5, Vec3(1, 0, 0)) - Vec3(2.5, 2, 3)).norm() == 0.0);
  CHECK(make_cayley_motion(Pose{{NAN, 0, 0}, Quat{}}, x1, &m) == MotionStatus::kInvalidPose);
}
