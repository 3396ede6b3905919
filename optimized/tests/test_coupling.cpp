// Tests of the coupling force and of constraint offsetting (coupling.h):
// Fc = kh M (ac - au) and its safety on non-finite input; the offset profile
// (f(0) = d, f(T) = 0, increasing, flat at both ends); the offset right-hand
// sides; and, with the projection, that a new deep contact starts with no
// force jump and ramps up monotonically to the un-offset force.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "gauss6/coupling.h"
#include "gauss6/quasistatics.h"

namespace {

using gauss6::Mat6;
using gauss6::OffsetSettings;
using gauss6::Vec6;

constexpr double kEps = std::numeric_limits<double>::epsilon();

Mat6 box_mass_matrix() {
  Mat6 M = Mat6::Zero();
  M.diagonal() << 2.0, 2.0, 2.0, 0.01, 0.02, 0.03;
  M(3, 4) = M(4, 3) = 0.001;
  return M;
}

}  // namespace

TEST_CASE("coupling force is kh M (ac - au)", "[coupling]") {
  const Mat6 M = box_mass_matrix();
  const Vec6 au = (Vec6() << 1e-3, -2e-3, 0.5e-3, 0.01, 0, -0.02).finished();
  const Vec6 ac = (Vec6() << 1e-3, 0, 0.5e-3, 0.01, 0.003, -0.02).finished();
  const double kh = 250.0;
  const Vec6 F = gauss6::coupling_force(M, au, ac, kh);
  // One product of 6 terms per entry: 8 eps relative to the magnitudes.
  const Vec6 expected = kh * (M * (ac - au));
  CHECK((F - expected).cwiseAbs().maxCoeff() <= 8 * kEps * kh * (M.cwiseAbs() * (ac - au).cwiseAbs()).maxCoeff());
  CHECK(F[1] == Approx(kh * 2.0 * 2e-3).epsilon(1e-14));  // force part: m (ac - au)_y
  CHECK(gauss6::coupling_force(M, au, au, kh) == Vec6::Zero());
}

TEST_CASE("coupling force is zero on non-finite input", "[coupling]") {
  const Mat6 M = box_mass_matrix();
  const Vec6 au = Vec6::Constant(0.1);
  Vec6 bad = au;
  bad[4] = std::numeric_limits<double>::quiet_NaN();
  CHECK(gauss6::coupling_force(M, au, bad, 1.0) == Vec6::Zero());
  CHECK(gauss6::coupling_force(M, bad, au, 1.0) == Vec6::Zero());
  CHECK(gauss6::coupling_force(M, au, Vec6::Zero(), std::numeric_limits<double>::infinity()) == Vec6::Zero());
  Mat6 Mbad = M;
  Mbad(0, 0) = std::numeric_limits<double>::infinity();
  CHECK(gauss6::coupling_force(Mbad, au, Vec6::Zero(), 1.0) == Vec6::Zero());
}

TEST_CASE("offset settings and threshold", "[coupling]") {
  OffsetSettings s;
  s.eps = -1e-3;
  s.T = 0.2;
  CHECK(gauss6::valid_offset_settings(s));
  CHECK(gauss6::needs_offset(-2e-3, s));
  CHECK_FALSE(gauss6::needs_offset(-1e-3, s));  // d = eps: not below, no offset
  CHECK_FALSE(gauss6::needs_offset(-0.5e-3, s));  // between eps and 0: felt as a small jump
  CHECK_FALSE(gauss6::needs_offset(0.1, s));
  CHECK_FALSE(gauss6::valid_offset_settings({0.0, 0.2}));
  CHECK_FALSE(gauss6::valid_offset_settings({1e-3, 0.2}));
  CHECK_FALSE(gauss6::valid_offset_settings({-1e-3, 0.0}));
  CHECK_FALSE(gauss6::valid_offset_settings({-1e-3, std::numeric_limits<double>::quiet_NaN()}));
}

TEST_CASE("offset profile: smoothstep from d to 0 in T", "[coupling]") {
  const OffsetSettings s{-1e-4, 0.25};
  const double d = -3e-3;
  CHECK(gauss6::offset_rhs(d, 0.0, s) == d);
  CHECK(gauss6::offset_rhs(d, -1.0, s) == d);
  CHECK(gauss6::offset_rhs(d, s.T, s) == 0.0);
  CHECK(gauss6::offset_rhs(d, 10.0, s) == 0.0);
  // Smoothstep is symmetric: half way, half the offset (a few ulps).
  CHECK(gauss6::offset_rhs(d, s.T / 2, s) == Approx(d / 2).epsilon(4 * kEps));
  // Strictly increasing on (0, T), sampled at 1000 points.
  double prev = gauss6::offset_rhs(d, 0.0, s);
  for (int i = 1; i <= 1000; ++i) {
    const double f = gauss6::offset_rhs(d, s.T * i / 1000.0, s);
    CHECK(f > prev);
    prev = f;
  }
  // Flat ends: the one-sided slope over h = 1e-6 T is O(h) (smoothstep's
  // derivative 6u(1-u) ~ 6u), against |d|/T * 1.5 at the middle.
  const double h = 1e-6 * s.T;
  const double slope0 = (gauss6::offset_rhs(d, h, s) - d) / h;
  const double slope1 = (0.0 - gauss6::offset_rhs(d, s.T - h, s)) / h;
  const double mid_slope = 1.5 * std::abs(d) / s.T;
  CHECK(slope0 <= 1e-5 * mid_slope);
  CHECK(slope1 <= 1e-5 * mid_slope);
  const double slope_mid = (gauss6::offset_rhs(d, s.T / 2 + h, s) - gauss6::offset_rhs(d, s.T / 2 - h, s)) / (2 * h);
  CHECK(slope_mid == Approx(mid_slope).epsilon(1e-6));
}

TEST_CASE("offset right-hand sides for a new contact set", "[coupling]") {
  const OffsetSettings s{-1e-3, 0.1};
  const Vec6 au = (Vec6() << 0, 0, -0.01, 0, 0, 0).finished();
  // Three rows: deep (d = -0.01), shallow (d = -0.5e-3 > eps), separating (d > 0).
  std::vector<double> J = {0, 0, 1, 0, 0, 0,  //
                           0, 0, 0.05, 0, 0, 0, //
                           0, 0, -1, 0, 0, 0};
  std::vector<double> start(3, 99.0), b(3, 99.0);
  CHECK(gauss6::begin_offsets(J, 3, au, s, start) == 1);
  CHECK(start[0] == -0.01);
  CHECK(start[1] == 0.0);
  CHECK(start[2] == 0.0);
  CHECK(gauss6::fill_offset_rhs(start, 3, 0.0, s, b));
  CHECK(b[0] == -0.01);
  CHECK(b[1] == 0.0);
  CHECK(b[2] == 0.0);
  CHECK(gauss6::fill_offset_rhs(start, 3, 0.05, s, b));
  CHECK(b[0] == Approx(-0.005).epsilon(4 * kEps));
  CHECK_FALSE(gauss6::fill_offset_rhs(start, 3, 0.1, s, b));
  CHECK(b[0] == 0.0);
  // Invalid settings: no offsets at all.
  CHECK(gauss6::begin_offsets(J, 3, au, OffsetSettings{0.5, 0.1}, start) == 0);
  CHECK_FALSE(gauss6::fill_offset_rhs(std::vector<double>{-1.0}, 1, 0.0, OffsetSettings{-1e-3, -1}, b));
  CHECK(b[0] == 0.0);
  // Sizes are respected: num_rows beyond the spans writes nothing out of range.
  std::vector<double> small(2, 7.0);
  CHECK(gauss6::begin_offsets(J, 3, au, s, small) == 1);
  CHECK(small[0] == -0.01);
}

TEST_CASE("a deep new contact with an offset starts without a force jump", "[coupling]") {
  // A god-object resting on a floor (normal +z, contact point 0.1 below and
  // 0.05 beside G); the device is 1 cm below the contact plane when the set
  // arrives. Without an offset the force jumps to its full value; with one it
  // starts at exactly zero and grows monotonically to that value at T.
  const Mat6 M = box_mass_matrix();
  const Vec6 au = (Vec6() << 0.002, 0, -0.01, 0, 0.001, 0).finished();
  const Eigen::Vector3d n(0, 0, 1), r(0.05, 0, -0.1);
  Vec6 row;
  row << n, r.cross(n);
  const std::vector<double> J(row.data(), row.data() + 6);
  const OffsetSettings s{-1e-3, 0.1};
  const double kh = 100.0;
  std::vector<double> start(1), b(1);
  REQUIRE(gauss6::begin_offsets(J, 1, au, s, start) == 1);

  gauss6::ProjectionWorkspace ws;
  gauss6::ProjectionResult res;
  gauss6::ProjectionProblem pb;
  pb.M = &M;
  pb.au = au;
  pb.J = J.data();
  pb.num_rows = 1;
  // Reference: no offset.
  REQUIRE(gauss6::project(pb, {}, &ws, &res) == gauss6::ProjectionStatus::kOptimal);
  const Vec6 F_full = gauss6::coupling_force(M, au, res.ac, kh);
  REQUIRE(F_full.norm() > 0);

  pb.b = b.data();
  double prev = -1;
  for (int i = 0; i <= 100; ++i) {
    const double t = s.T * i / 100.0;
    gauss6::fill_offset_rhs(start, 1, t, s, b);
    REQUIRE(gauss6::project(pb, {}, &ws, &res) == gauss6::ProjectionStatus::kOptimal);
    const double F = gauss6::coupling_force(M, au, res.ac, kh).norm();
    if (i == 0) CHECK(F == 0.0);  // au satisfies J au >= d exactly: ac = au
    // Monotone up to rounding of the projection (eps-relative to the full force).
    CHECK(F >= prev - 1e-12 * F_full.norm());
    prev = F;
  }
  // At T the offset is gone: the force is the un-offset one (same problem, b = 0).
  CHECK((gauss6::coupling_force(M, au, res.ac, kh) - F_full).norm() <= 1e-12 * F_full.norm());
}
