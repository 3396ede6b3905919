// Tests of pose.h: the rational rotation, pose difference and update (METHOD.md section 1).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "gauss6/geometry/pose.h"

using namespace gauss6;

namespace {
Quat random_quat(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return {n(rng), n(rng), n(rng), n(rng)};
}
}  // namespace

TEST_CASE("rational rotation is orthogonal for non-unit quaternions", "[pose]") {
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    Quat q = random_quat(rng);
    const double scale = std::pow(10.0, (i % 7) - 3);  // |q| from 1e-3 to 1e3
    q = {q.w * scale, q.x * scale, q.y * scale, q.z * scale};
    const Mat3 R = rotation_matrix(q);
    // Rounding only: a few ulps per entry of R R^T.
    CHECK((R * R.transpose() - Mat3::Identity()).norm() < 1e-14);
    CHECK(R.determinant() == Approx(1.0).margin(1e-14));
    // Agrees with Eigen's unit-quaternion matrix.
    const Quat u = normalized(q);
    const Mat3 Re = Eigen::Quaterniond(u.w, u.x, u.y, u.z).toRotationMatrix();
    CHECK((R - Re).norm() < 1e-14);
  }
}

TEST_CASE("pose difference and update are inverse to first order and exactly for a single step", "[pose]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    Pose xs{{u(rng), u(rng), u(rng)}, normalized(random_quat(rng))};
    Vec6 a;
    for (int k = 0; k < 6; ++k) a[k] = 0.9 * u(rng);  // rotation below pi
    const Pose xt = pose_update(xs, a);
    // xt (-) xs recovers a: exp then log, 1e-12 for rounding through trigonometry.
    CHECK((pose_difference(xt, xs) - a).norm() < 1e-12);
  }
}

TEST_CASE("pose difference takes the shortest way round", "[pose]") {
  const Pose xs{};
  // 270 degrees about z is -90 degrees the short way.
  const Pose xh{Vec3::Zero(), quat_exp(Vec3(0, 0, 1.5 * M_PI))};
  const Vec6 d = pose_difference(xh, xs);
  CHECK(d.tail<3>().z() == Approx(-0.5 * M_PI).epsilon(1e-12));
  // q and -q give the same difference.
  const Pose xh2{Vec3::Zero(), Quat{-xh.q.w, -xh.q.x, -xh.q.y, -xh.q.z}};
  CHECK((pose_difference(xh2, xs) - d).norm() < 1e-15);
}

TEST_CASE("transform_point maps body points by the rational rotation", "[pose]") {
  const Pose X{{1, 2, 3}, Quat{2.0, 0, 0, 2.0}};  // 90 degrees about z, |q| = 2*sqrt(2)
  const Vec3 p = transform_point(X, Vec3(1, 0, 0));
  CHECK((p - Vec3(1, 3, 3)).norm() < 1e-15);
}

TEST_CASE("invalid poses are detected", "[pose]") {
  CHECK(is_valid_pose(Pose{}));
  CHECK_FALSE(is_valid_pose(Pose{{NAN, 0, 0}, Quat{}}));
  CHECK_FALSE(is_valid_pose(Pose{{0, 0, 0}, Quat{0, 0, 0, 0}}));
  CHECK_FALSE(is_valid_pose(Pose{{0, 0, 0}, Quat{INFINITY, 0, 0, 0}}));
}
