// Tests of the exact projection and the exact certificate check
// (reference/include/gauss6/reference/quasistatics.h). Every comparison here is
// exact (rational equality), so no tolerance is involved: hand-derived answers
// are computed in the test with their own rational formulas from the same
// input doubles.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <cstdint>
#include <iostream>
#include <random>

#include "gauss6/reference/quasistatics.h"

namespace {

using gauss6::Mat6;
using gauss6::Vec6;
using gauss6::reference::CertificateFailure;
using gauss6::reference::ProjectionStatus;
using gauss6::reference::Rational;
namespace ref = gauss6::reference;
using JMat = Eigen::MatrixXd;

// A contact row J_k = [n^T, (r x n)^T] for the point G + r and normal n.
Eigen::Matrix<double, 1, 6> contact_row(const Eigen::Vector3d& r, const Eigen::Vector3d& n) {
  Eigen::Matrix<double, 1, 6> row;
  row << n.transpose(), r.cross(n).transpose();
  return row;
}

Mat6 diagonal_mass(double mass, double inertia) {
  Vec6 d;
  d << mass, mass, mass, inertia, inertia, inertia;
  return d.asDiagonal();
}

std::vector<Rational> exact(const Vec6& v) { return {v[0], v[1], v[2], v[3], v[4], v[5]}; }

// Exact residuals of the KKT conditions of the returned (ac, lambda), checked
// independently of either algorithm: stationarity, primal and dual feasibility,
// complementarity.
void require_exact_kkt(const Mat6& M, const Vec6& au, const JMat& J, const Eigen::VectorXd& b,
                       const std::vector<Rational>& ac, const std::vector<Rational>& lambda) {
  const int m = static_cast<int>(J.rows());
  REQUIRE(ac.size() == 6);
  REQUIRE(static_cast<int>(lambda.size()) == m);
  for (int i = 0; i < 6; ++i) {  // sym(M) (ac - au) == J^T lambda
    Rational lhs = 0, rhs = 0;
    for (int j = 0; j < 6; ++j)
      lhs += (Rational(M(i, j)) + Rational(M(j, i))) / 2 * (ac[j] - Rational(au[j]));
    for (int k = 0; k < m; ++k) rhs += Rational(J(k, i)) * lambda[k];
    REQUIRE(lhs == rhs);
  }
  for (int k = 0; k < m; ++k) {
    Rational slack = b.size() ? -Rational(b[k]) : Rational(0);
    for (int j = 0; j < 6; ++j) slack += Rational(J(k, j)) * ac[j];
    REQUIRE(sgn(slack) >= 0);
    REQUIRE(sgn(lambda[k]) >= 0);
    REQUIRE(sgn(slack * lambda[k]) == 0);
  }
}

// Portable deterministic uniform numbers in [lo, hi).
struct Rng {
  std::mt19937_64 gen;
  explicit Rng(uint64_t seed) : gen(seed) {}
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * (static_cast<double>(gen() >> 11) * 0x1p-53);
  }
};

struct Instance {
  Mat6 M;
  Vec6 au;
  JMat J;
};

// m contacts at random points of [-1, 1]^3 with random unit normals within
// about 80 degrees of +z (obstacles below, so the feasible cone is not {0}); M with
// mass 1.7 and a random SPD inertia (not symmetric to the last bit: it is
// assembled as B B^T + 0.2 I in doubles, then one off-diagonal pair is nudged
// by an ulp); au pushes on average into the contacts.
Instance random_instance(Rng& rng, int m) {
  Instance in;
  Eigen::Matrix3d B;
  for (int i = 0; i < 9; ++i) B.data()[i] = rng.uniform(-1, 1);
  in.M.setZero();
  in.M.topLeftCorner<3, 3>() = 1.7 * Eigen::Matrix3d::Identity();
  in.M.bottomRightCorner<3, 3>() = B * B.transpose() + 0.2 * Eigen::Matrix3d::Identity();
  in.M(3, 4) = std::nextafter(in.M(3, 4), 10.0);
  in.J.resize(m, 6);
  Vec6 push = Vec6::Zero();
  for (int k = 0; k < m; ++k) {
    Eigen::Vector3d r(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    Eigen::Vector3d n(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0.2, 1));
    in.J.row(k) = contact_row(r, n.normalized());
    push += in.J.row(k).transpose();
  }
  for (int i = 0; i < 6; ++i) in.au[i] = rng.uniform(-1, 1);
  in.au -= push / std::max(1, m);
  return in;
}

// A Catch2 string for a failure, for readable messages.
const char* name(CertificateFailure f) {
  switch (f) {
    case CertificateFailure::none: return "none";
    case CertificateFailure::bad_input: return "bad_input";
    case CertificateFailure::negative_multiplier: return "negative_multiplier";
    case CertificateFailure::violated_constraint: return "violated_constraint";
  }
  return "?";
}

}  // namespace

TEST_CASE("one contact through G: the normal component is removed exactly", "[refqp]") {
  const Mat6 M = diagonal_mass(1.0 / 3.0, 0.7);
  Vec6 au;
  au << 0.3, -0.7, -1.0 / 3.0, 0.2, 0.1, -0.9;
  JMat J(1, 6);
  J << 0, 0, 1, 0, 0, 0;
  const auto p = ref::project_exact(M, au, J);
  REQUIRE(p.status == ProjectionStatus::optimal);
  std::vector<Rational> expect = exact(au);
  expect[2] = 0;
  CHECK(p.ac == expect);
  // lambda = m (0 - au_z), exactly.
  CHECK(p.lambda[0] == Rational(1.0 / 3.0) * -Rational(au[2]));
  CHECK(p.active_set == std::vector<int>{0});
  CHECK(p.ac_double[2] == 0.0);
  CHECK(p.ac_double[0] == au[0]);
  require_exact_kkt(M, au, J, Eigen::VectorXd(), p.ac, p.lambda);
}

TEST_CASE("one contact with a lever arm matches the closed form", "[refqp]") {
  // lambda = -J au / (J M^-1 J^T), ac = au + M^-1 J^T lambda, in rationals.
  const Mat6 M = diagonal_mass(2.0, 1.0 / 3.0);
  Vec6 au;
  au << 0.1, 0.2, -0.6, 0.3, 0.25, -0.4;
  JMat J = contact_row({1.0 / 3.0, 0, 0}, {0, 0, 1});  // [0 0 1 0 -1/3 0]
  const auto p = ref::project_exact(M, au, J);
  REQUIRE(p.status == ProjectionStatus::optimal);
  Rational jau = 0, jmj = 0;
  for (int j = 0; j < 6; ++j) {
    jau += Rational(J(0, j)) * Rational(au[j]);
    jmj += Rational(J(0, j)) * Rational(J(0, j)) / Rational(M(j, j));
  }
  REQUIRE(sgn(jau) < 0);
  const Rational lambda = -jau / jmj;
  CHECK(p.lambda[0] == lambda);
  for (int j = 0; j < 6; ++j)
    CHECK(p.ac[j] == Rational(au[j]) + Rational(J(0, j)) / Rational(M(j, j)) * lambda);
  require_exact_kkt(M, au, J, Eigen::VectorXd(), p.ac, p.lambda);
}

TEST_CASE("two orthogonal contacts zero both normal components", "[refqp]") {
  const Mat6 M = diagonal_mass(1.7, 0.3);
  Vec6 au;
  au << -0.5, 0.25, -1.0 / 3.0, 0.1, 0.2, 0.3;
  JMat J(2, 6);
  J << 0, 0, 1, 0, 0, 0,  //
      1, 0, 0, 0, 0, 0;
  const auto p = ref::project_exact(M, au, J);
  REQUIRE(p.status == ProjectionStatus::optimal);
  std::vector<Rational> expect = exact(au);
  expect[0] = expect[2] = 0;
  CHECK(p.ac == expect);
  CHECK(p.lambda[0] == -Rational(1.7) * Rational(au[2]));
  CHECK(p.lambda[1] == -Rational(1.7) * Rational(au[0]));
  CHECK(p.active_set == std::vector<int>{0, 1});
}

TEST_CASE("moving away from the contacts: ac == au exactly, lambda == 0", "[refqp]") {
  const Mat6 M = diagonal_mass(1.7, 0.3);
  Vec6 au;
  au << 0.5, 0.25, 1.0 / 3.0, 0.1, 0.2, 0.3;
  JMat J(2, 6);
  J << 0, 0, 1, 0, 0, 0,  //
      1, 0, 0, 0, 0, 0;
  const auto p = ref::project_exact(M, au, J);
  REQUIRE(p.status == ProjectionStatus::optimal);
  CHECK(p.ac == exact(au));
  CHECK(p.lambda == std::vector<Rational>{0, 0});
  CHECK(p.active_set.empty());
  CHECK(p.ac_double == au);
  const auto c = ref::check_certificate(M, au, J, Eigen::VectorXd(), {});
  CHECK(c.pass);
  CHECK(c.ac_exact == exact(au));
}

TEST_CASE("offsets: b > 0 pushes out, b < 0 lets the device in, both exactly", "[refqp]") {
  const Mat6 M = diagonal_mass(0.9, 0.3);
  Vec6 au;
  au << 0.1, 0.2, -1.0 / 3.0, 0, 0, 0;
  JMat J(1, 6);
  J << 0, 0, 1, 0, 0, 0;
  for (double b0 : {0.25, -0.2}) {
    Eigen::VectorXd b(1);
    b << b0;
    const auto p = ref::project_exact(M, au, J, b);
    REQUIRE(p.status == ProjectionStatus::optimal);
    CHECK(p.ac[2] == Rational(b0));
    CHECK(p.lambda[0] == Rational(0.9) * (Rational(b0) - Rational(au[2])));
    require_exact_kkt(M, au, J, b, p.ac, p.lambda);
    const auto c = ref::check_certificate(M, au, J, b, p.active_set);
    CHECK(c.pass);
    CHECK(c.ac_exact == p.ac);
  }
  // An offset the device already satisfies is inactive.
  Eigen::VectorXd b(1);
  b << -0.5;
  const auto p = ref::project_exact(M, au, J, b);
  REQUIRE(p.status == ProjectionStatus::optimal);
  CHECK(p.ac == exact(au));
  CHECK(p.active_set.empty());
}

TEST_CASE("contradictory offsets are infeasible", "[refqp]") {
  const Mat6 M = diagonal_mass(1, 1);
  const Vec6 au = Vec6::Zero();
  JMat J(2, 6);
  J << 0, 0, 1, 0, 0, 0,  // z >= 1e-3
      0, 0, -1, 0, 0, 0;  // z <= 0
  Eigen::VectorXd b(2);
  b << 1e-3, 0;
  CHECK(ref::project_exact(M, au, J, b).status == ProjectionStatus::infeasible);
  b << 0, 0;  // touching: z == 0 is feasible
  CHECK(ref::project_exact(M, au, J, b).status == ProjectionStatus::optimal);
}

TEST_CASE("bad inputs are reported, not solved", "[refqp]") {
  Mat6 M = diagonal_mass(1, 1);
  Vec6 au = Vec6::Constant(-0.5);
  JMat J(1, 6);
  J << 0, 0, 1, 0, 0, 0;
  SECTION("non-finite") {
    au[3] = std::nan("");
    CHECK(ref::project_exact(M, au, J).status == ProjectionStatus::bad_input);
    CHECK(ref::check_certificate(M, au, J, {}, {0}).failure == CertificateFailure::bad_input);
  }
  SECTION("M not positive definite") {
    M(5, 5) = 0;
    CHECK(ref::project_exact(M, au, J).status == ProjectionStatus::bad_input);
    CHECK(ref::check_certificate(M, au, J, {}, {0}).failure == CertificateFailure::bad_input);
  }
  SECTION("sizes and indices") {
    CHECK(ref::project_exact(M, au, J, Eigen::VectorXd::Zero(2)).status ==
          ProjectionStatus::bad_input);
    CHECK(ref::check_certificate(M, au, J, {}, {1}).failure == CertificateFailure::bad_input);
    CHECK(ref::check_certificate(M, au, J, {}, {-1}).failure == CertificateFailure::bad_input);
  }
}

TEST_CASE("random instances: exact KKT, orthogonality, dissipativity", "[refqp]") {
  Rng rng(20070501);
  int num_active = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Instance in = random_instance(rng, 1 + trial % 12);
    const auto p = ref::project_exact(in.M, in.au, in.J);
    REQUIRE(p.status == ProjectionStatus::optimal);
    require_exact_kkt(in.M, in.au, in.J, Eigen::VectorXd(), p.ac, p.lambda);
    // METHOD.md 5.1: (ac - au)^T M ac == 0, and 5.4: Fu^T ac <= Fu^T au, exactly.
    Rational orth = 0, fu_ac = 0, fu_au = 0;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const Rational mij = (Rational(in.M(i, j)) + Rational(in.M(j, i))) / 2;
        orth += (p.ac[i] - Rational(in.au[i])) * mij * p.ac[j];
        fu_ac += Rational(in.au[i]) * mij * p.ac[j];
        fu_au += Rational(in.au[i]) * mij * Rational(in.au[j]);
      }
    CHECK(orth == 0);
    CHECK(fu_ac <= fu_au);
    num_active += static_cast<int>(p.active_set.size());
  }
  CHECK(num_active > 60);  // the instances do exercise the constraints
}

TEST_CASE("the certificate accepts the exact active set and reproduces ac exactly", "[refqp]") {
  Rng rng(1234567);
  for (int trial = 0; trial < 60; ++trial) {
    const Instance in = random_instance(rng, 1 + trial % 12);
    const auto p = ref::project_exact(in.M, in.au, in.J);
    REQUIRE(p.status == ProjectionStatus::optimal);
    const auto c = ref::check_certificate(in.M, in.au, in.J, {}, p.active_set);
    INFO("trial " << trial << " failure " << name(c.failure) << " row " << c.row);
    REQUIRE(c.pass);
    CHECK(c.ac_exact == p.ac);
    CHECK(c.ac_rounded == p.ac_double);
    require_exact_kkt(in.M, in.au, in.J, Eigen::VectorXd(), c.ac_exact, c.lambda_exact);
    CHECK(ref::max_abs_difference(c.ac_exact, p.ac_double) <= 1e-15);  // rounding only
  }
}

TEST_CASE("the certificate rejects a wrong active set, naming the row", "[refqp]") {
  const Mat6 M = diagonal_mass(2.0, 0.3);
  Vec6 au;
  au << -0.5, 0.25, 0.75, 0.1, 0.2, 0.3;
  JMat J(2, 6);
  J << 0, 0, 1, 0, 0, 0,  // moving away from it: inactive
      1, 0, 0, 0, 0, 0;   // pushed into: active
  SECTION("a missing active row is violated by exactly its penetration") {
    const auto c = ref::check_certificate(M, au, J, {}, {});
    CHECK_FALSE(c.pass);
    CHECK(c.failure == CertificateFailure::violated_constraint);
    CHECK(c.row == 1);
    CHECK(c.amount == 0.5);
  }
  SECTION("an inactive row held active needs a pulling multiplier") {
    const auto c = ref::check_certificate(M, au, J, {}, {0, 1});
    CHECK_FALSE(c.pass);
    CHECK(c.failure == CertificateFailure::negative_multiplier);
    CHECK(c.row == 0);
    CHECK(c.amount == 1.5);  // m au_z = 2 * 0.75
  }
  SECTION("the right set passes") {
    const auto c = ref::check_certificate(M, au, J, {}, {1});
    CHECK(c.pass);
    CHECK(c.lambda_exact == std::vector<Rational>{0, 1});  // 2 * 0.5
  }
}

TEST_CASE("random wrong active sets never pass", "[refqp]") {
  // Whenever the check passes, its point must be the exact optimum. Moreover,
  // dropping a row with lambda > 0 from linearly independent active rows
  // changes the KKT point (lambda is unique), and holding an inactive row
  // tight moves the point off the optimum: both must be rejected. (Dropping a
  // row from dependent active rows may leave a valid certificate.)
  Rng rng(99);
  int rejected_drops = 0, rejected_adds = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const Instance in = random_instance(rng, 2 + trial % 11);
    const auto p = ref::project_exact(in.M, in.au, in.J);
    REQUIRE(p.status == ProjectionStatus::optimal);
    const auto full = ref::check_certificate(in.M, in.au, in.J, {}, p.active_set);
    REQUIRE(full.pass);
    const bool independent = full.rank == static_cast<int>(p.active_set.size());
    for (size_t drop = 0; drop < p.active_set.size(); ++drop) {
      if (sgn(p.lambda[p.active_set[drop]]) <= 0) continue;
      std::vector<int> w = p.active_set;
      w.erase(w.begin() + static_cast<long>(drop));
      const auto c = ref::check_certificate(in.M, in.au, in.J, {}, w);
      if (c.pass) CHECK(c.ac_exact == p.ac);
      if (independent) {
        CHECK_FALSE(c.pass);
        rejected_drops += !c.pass;
      }
    }
    for (int k = 0; k < in.J.rows(); ++k) {
      if (std::find(p.active_set.begin(), p.active_set.end(), k) != p.active_set.end()) continue;
      std::vector<int> w = p.active_set;
      w.push_back(k);
      const auto c = ref::check_certificate(in.M, in.au, in.J, {}, w);
      CHECK_FALSE(c.pass);
      rejected_adds += !c.pass;
    }
  }
  INFO("rejected drops " << rejected_drops << ", rejected additions " << rejected_adds);
  CHECK(rejected_drops > 50);
  CHECK(rejected_adds > 50);
}

TEST_CASE("duplicated contacts: dependent rows are dropped and the answer is kept", "[refqp]") {
  const Mat6 M = diagonal_mass(1.7, 0.3);
  Vec6 au;
  au << 0.1, 0.2, -1.0 / 3.0, 0.1, -0.2, 0.3;
  JMat J(3, 6);
  J << 0, 0, 1, 0, 0, 0,  //
      0, 0, 1, 0, 0, 0,   // the same contact twice
      0, 0, 2, 0, 0, 0;   // and scaled
  const auto p = ref::project_exact(M, au, J);
  REQUIRE(p.status == ProjectionStatus::optimal);
  CHECK(p.active_set == std::vector<int>{0, 1, 2});
  CHECK(p.ac[2] == 0);
  require_exact_kkt(M, au, J, Eigen::VectorXd(), p.ac, p.lambda);
  for (const std::vector<int>& w : {std::vector<int>{0, 1, 2}, std::vector<int>{2, 0},
                                    std::vector<int>{1}, std::vector<int>{0, 0, 0}}) {
    const auto c = ref::check_certificate(M, au, J, {}, w);
    CHECK(c.pass);
    CHECK(c.ac_exact == p.ac);
    CHECK(c.rank == 1);
    require_exact_kkt(M, au, J, Eigen::VectorXd(), c.ac_exact, c.lambda_exact);
  }
  CHECK(ref::check_certificate(M, au, J, {}, {0, 1, 2}).num_dependent_rows == 2);
}

TEST_CASE("dependent rows whose first basis needs a negative multiplier", "[refqp]") {
  // Rows x >= 0, y >= 0, x - y >= 0 (all through G), tight at a_xy = 0 for
  // au_xy = (-1, 1/2): -M au = (1, -1/2) = 1/2 * y + 1 * (x - y), while the
  // basis {x, y} gives the multiplier -1/2 on y. The exact LP over the tight
  // rows must find the non-negative combination.
  const Mat6 M = diagonal_mass(1, 1);
  Vec6 au;
  au << -1, 0.5, 0.3, 0.1, 0.2, 0.3;
  JMat J(3, 6);
  J << 1, 0, 0, 0, 0, 0,  //
      0, 1, 0, 0, 0, 0,   //
      1, -1, 0, 0, 0, 0;
  const auto p = ref::project_exact(M, au, J);
  REQUIRE(p.status == ProjectionStatus::optimal);
  CHECK(p.active_set == std::vector<int>{0, 1, 2});
  const auto c = ref::check_certificate(M, au, J, {}, {0, 1, 2});
  INFO(name(c.failure));
  CHECK(c.pass);
  CHECK(c.used_lp);
  CHECK(c.ac_exact == p.ac);
  // Not unique: (0, 1/2, 1) and (1/2, 0, 1/2) both hold; the KKT check decides.
  require_exact_kkt(M, au, J, Eigen::VectorXd(), c.ac_exact, c.lambda_exact);

  // With au_xy = (1/2, -1) the optimum is (1/2, 0): holding all three rows
  // tight needs lambda_x + lambda_{x-y} = -1/2, impossible with lambda >= 0.
  au[0] = 0.5;
  au[1] = -1;
  const auto bad = ref::check_certificate(M, au, J, {}, {0, 1, 2});
  CHECK_FALSE(bad.pass);
  CHECK(bad.failure == CertificateFailure::negative_multiplier);
  CHECK(bad.row == 0);
  CHECK(bad.amount == 0.5);
  const auto good = ref::check_certificate(M, au, J, {}, ref::project_exact(M, au, J).active_set);
  CHECK(good.pass);
}

TEST_CASE("box face on a plane: four coplanar corners, rank 3", "[refqp]") {
  // A cube of half-size 1/3 resting on z = 0: four corner contacts with the
  // same normal. Pushing down and twisting about x makes one edge bear the load.
  const Mat6 M = diagonal_mass(1.7, 0.3);
  const double h = 1.0 / 3.0;
  JMat J(4, 6);
  J.row(0) = contact_row({-h, -h, -h}, {0, 0, 1});
  J.row(1) = contact_row({h, -h, -h}, {0, 0, 1});
  J.row(2) = contact_row({h, h, -h}, {0, 0, 1});
  J.row(3) = contact_row({-h, h, -h}, {0, 0, 1});
  Rng rng(7);
  int passes_with_lp = 0;
  for (int trial = 0; trial < 40; ++trial) {
    Vec6 au;
    for (int i = 0; i < 6; ++i) au[i] = rng.uniform(-1, 1);
    au[2] = -std::abs(au[2]) - 0.5;
    const auto p = ref::project_exact(M, au, J);
    REQUIRE(p.status == ProjectionStatus::optimal);
    require_exact_kkt(M, au, J, Eigen::VectorXd(), p.ac, p.lambda);
    // Every order of the tight rows is a valid claim.
    std::vector<int> w = p.active_set;
    std::reverse(w.begin(), w.end());
    for (const auto& claim : {p.active_set, w}) {
      const auto c = ref::check_certificate(M, au, J, {}, claim);
      INFO("trial " << trial << " failure " << name(c.failure));
      CHECK(c.pass);
      CHECK(c.ac_exact == p.ac);
      passes_with_lp += c.used_lp;
    }
  }
  INFO("passes that needed the LP: " << passes_with_lp);
  CHECK(passes_with_lp > 0);  // the fallback is exercised, not only the fast path
}

TEST_CASE("rounding to the nearest double, ties to even", "[refqp]") {
  CHECK(ref::to_double_nearest(Rational(1, 3)) == 1.0 / 3.0);
  CHECK(ref::to_double_nearest(Rational(-2, 3)) == -2.0 / 3.0);
  CHECK(ref::to_double_nearest(Rational(0.1)) == 0.1);
  Rational half_ulp = 1;
  mpq_div_2exp(half_ulp.get_mpq_t(), half_ulp.get_mpq_t(), 53);  // 2^-53
  Rational tiny = 1;
  mpq_div_2exp(tiny.get_mpq_t(), tiny.get_mpq_t(), 100);
  CHECK(ref::to_double_nearest(1 + half_ulp) == 1.0);  // tie: to even
  CHECK(ref::to_double_nearest(1 + half_ulp + tiny) == std::nextafter(1.0, 2.0));
  CHECK(ref::to_strings({Rational(-3, 4), Rational(2)}) == std::vector<std::string>{"-3/4", "2"});
}

TEST_CASE("timing of the exact solve and the certificate", "[.][refqp-timing]") {
  // CPU time of this thread, so that a loaded machine does not inflate it.
  auto cpu_seconds = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  };
  Rng rng(42);
  for (int m : {3, 6, 12, 50}) {
    const int n = m == 50 ? 100 : 400;
    double t_solve = 0, t_cert = 0;
    int active = 0, lp = 0;
    for (int trial = 0; trial < n; ++trial) {
      const Instance in = random_instance(rng, m);
      const double t0 = cpu_seconds();
      const auto p = ref::project_exact(in.M, in.au, in.J);
      const double t1 = cpu_seconds();
      const auto c = ref::check_certificate(in.M, in.au, in.J, {}, p.active_set);
      const double t2 = cpu_seconds();
      REQUIRE(p.status == ProjectionStatus::optimal);
      REQUIRE(c.pass);
      REQUIRE(c.ac_exact == p.ac);
      t_solve += t1 - t0;
      t_cert += t2 - t1;
      active += static_cast<int>(p.active_set.size());
      lp += c.used_lp;
    }
    std::cout << "m = " << m << ": exact solve " << 1e6 * t_solve / n << " us, certificate "
              << 1e6 * t_cert / n << " us (CPU), mean active rows " << double(active) / n
              << ", LP fallbacks " << lp << " / " << n << "\n";
  }
}
