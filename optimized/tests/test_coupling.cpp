// Tests of the coupling force (coupling.h): Fc = kh M (ac - au) and its
// safety on non-finite input. Constraint offsetting: test_offsetting.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "gauss6/contact/coupling.h"
#include "gauss6/runtime/haptic_loop.h"
#include "gauss6/runtime/runtime_events.h"
#include "mass_matrices.h"

namespace {

using gauss6::Mat6;
using gauss6::Vec6;

constexpr double kEps = std::numeric_limits<double>::epsilon();

using gauss6::test::box_mass_matrix;

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

TEST_CASE("a coupling gain that is not > 0 makes no force, and the safety stage no reversed one", "[coupling]") {
  // kh < 0 reversed Fc = kh M (ac - au) into the obstacle; a negative device limit
  // did the same in make_safe_wrench (scaled by limit / |F| < 0).
  const Mat6 M = box_mass_matrix();
  const Vec6 au = (Vec6() << 0, 0, -0.01, 0, 0, 0).finished();
  const Vec6 ac = Vec6::Zero();
  CHECK(gauss6::coupling_force(M, au, ac, 100.0)[2] > 0);  // pushes the hand back out
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const double kh : {-100.0, 0.0, -0.0, std::nan(""), kInf, -kInf}) {
    INFO("kh " << kh);
    CHECK_FALSE(gauss6::valid_coupling_gain(kh));
    CHECK(gauss6::coupling_force(M, au, ac, kh).isZero(0));
  }
  const Vec6 F = (Vec6() << 0, 0, 50, 1, 0, 0).finished();
  for (const auto& [max_force, max_torque] : {std::pair{-20.0, 1.0}, std::pair{20.0, -1.0}, std::pair{std::nan(""), 1.0}}) {
    uint32_t events = 0;
    INFO("limits " << max_force << ", " << max_torque);
    CHECK(gauss6::make_safe_wrench(F, max_force, max_torque, &events).isZero(0));
    CHECK((events & (1u << static_cast<int>(gauss6::RuntimeEventKind::kNonFiniteForce))) != 0);
  }
  uint32_t events = 0;
  const Vec6 safe = gauss6::make_safe_wrench(F, 20.0, 0.0, &events);
  CHECK(safe[2] == Approx(20.0));
  CHECK(safe.tail<3>().isZero(0));
}
