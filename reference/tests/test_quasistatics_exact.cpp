// Tests of the exact projection and the exact certificate check
// (reference/include/gauss6/reference/quasistatics.h). Every comparison of
// answers here is exact (rational equality), so no tolerance is involved:
// hand-derived answers are computed in the test with their own rational
// formulas from the same input doubles. The only thresholds classify sizes
// (how small a rounding-level violation is, how large an ill-conditioned
// multiplier is); each states why.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>

#include "../src/exact_linear_algebra.h"  // internal::verify_optimum, verify_infeasibility
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
  const auto p = ref::project({M, au, J, {}});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
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
  const auto p = ref::project({M, au, J, {}});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
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
  const auto p = ref::project({M, au, J, {}});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
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
  const auto p = ref::project({M, au, J, {}});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
  CHECK(p.ac == exact(au));
  CHECK(p.lambda == std::vector<Rational>{0, 0});
  CHECK(p.active_set.empty());
  CHECK(p.ac_double == au);
  const auto c = ref::check_certificate({M, au, J, {}}, {});
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
    const auto p = ref::project({M, au, J, b});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
    CHECK(p.ac[2] == Rational(b0));
    CHECK(p.lambda[0] == Rational(0.9) * (Rational(b0) - Rational(au[2])));
    require_exact_kkt(M, au, J, b, p.ac, p.lambda);
    const auto c = ref::check_certificate({M, au, J, b}, p.active_set);
    CHECK(c.pass);
    CHECK(c.ac_exact == p.ac);
  }
  // An offset the device already satisfies is inactive.
  Eigen::VectorXd b(1);
  b << -0.5;
  const auto p = ref::project({M, au, J, b});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
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
  CHECK(ref::project({M, au, J, b}).status == ProjectionStatus::kInfeasibleOffsets);
  b << 0, 0;  // touching: z == 0 is feasible
  CHECK(ref::project({M, au, J, b}).status == ProjectionStatus::kOptimal);
}

TEST_CASE("the exact verification behind every answer rejects each broken condition", "[refqp]") {
  // project returns kOptimal / kInfeasibleOffsets only after these checks pass;
  // here they must reject answers that are wrong by the smallest amounts.
  Rng rng(99);
  int corrupted = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Instance in = random_instance(rng, 2 + trial % 6);
    const Eigen::VectorXd b = Eigen::VectorXd::Zero(in.J.rows());
    const auto p = ref::project({in.M, in.au, in.J, b});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
    CHECK(ref::internal::verify_optimum(in.M, in.au, in.J, b, p.ac, p.lambda));
    const Rational tiny(1, mpz_class(1) << 200);
    for (int i = 0; i < 6; ++i) {  // any ac off by 2^-200 in one entry
      auto ac = p.ac;
      ac[i] += tiny;
      CHECK_FALSE(ref::internal::verify_optimum(in.M, in.au, in.J, b, ac, p.lambda));
      ++corrupted;
    }
    for (size_t k = 0; k < p.lambda.size(); ++k) {  // any multiplier off by 2^-200
      auto lambda = p.lambda;
      lambda[k] -= tiny;  // negative where it was 0, else breaks stationarity
      CHECK_FALSE(ref::internal::verify_optimum(in.M, in.au, in.J, b, p.ac, lambda));
      ++corrupted;
    }
    auto short_lambda = p.lambda;
    short_lambda.pop_back();
    CHECK_FALSE(ref::internal::verify_optimum(in.M, in.au, in.J, b, p.ac, short_lambda));
  }
  CHECK(corrupted > 150);

  // Farkas certificates of z >= 1e-3, -z >= 0: y = (1, 1) and its multiples only.
  JMat J(2, 6);
  J << 0, 0, 1, 0, 0, 0, 0, 0, -1, 0, 0, 0;
  Eigen::VectorXd b(2);
  b << 1e-3, 0;
  CHECK(ref::internal::verify_infeasibility(J, b, {Rational(1), Rational(1)}));
  CHECK(ref::internal::verify_infeasibility(J, b, {Rational(3, 7), Rational(3, 7)}));
  CHECK_FALSE(ref::internal::verify_infeasibility(J, b, {Rational(1), Rational(2)}));   // J^T y != 0
  CHECK_FALSE(ref::internal::verify_infeasibility(J, b, {Rational(-1), Rational(-1)})); // y < 0
  CHECK_FALSE(ref::internal::verify_infeasibility(J, b, {Rational(0), Rational(0)}));   // b^T y = 0
  CHECK_FALSE(ref::internal::verify_infeasibility(J, Eigen::VectorXd::Zero(2), {Rational(1), Rational(1)}));
}

TEST_CASE("bad inputs are reported, not solved", "[refqp]") {
  Mat6 M = diagonal_mass(1, 1);
  Vec6 au = Vec6::Constant(-0.5);
  JMat J(1, 6);
  J << 0, 0, 1, 0, 0, 0;
  SECTION("non-finite") {
    au[3] = std::nan("");
    CHECK(ref::project({M, au, J, {}}).status == ProjectionStatus::kBadInput);
    CHECK(ref::check_certificate({M, au, J, {}}, {0}).failure == CertificateFailure::bad_input);
  }
  SECTION("M not positive definite") {
    M(5, 5) = 0;
    CHECK(ref::project({M, au, J, {}}).status == ProjectionStatus::kBadInput);
    CHECK(ref::check_certificate({M, au, J, {}}, {0}).failure == CertificateFailure::bad_input);
  }
  SECTION("sizes and indices") {
    CHECK(ref::project({M, au, J, Eigen::VectorXd::Zero(2)}).status ==
          ProjectionStatus::kBadInput);
    CHECK(ref::check_certificate({M, au, J, {}}, {1}).failure == CertificateFailure::bad_input);
    CHECK(ref::check_certificate({M, au, J, {}}, {-1}).failure == CertificateFailure::bad_input);
  }
}

TEST_CASE("random instances: exact KKT, orthogonality, dissipativity", "[refqp]") {
  Rng rng(20070501);
  int num_active = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Instance in = random_instance(rng, 1 + trial % 12);
    const auto p = ref::project({in.M, in.au, in.J, {}});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
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
    const auto p = ref::project({in.M, in.au, in.J, {}});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
    const auto c = ref::check_certificate({in.M, in.au, in.J, {}}, p.active_set);
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
    const auto c = ref::check_certificate({M, au, J, {}}, {});
    CHECK_FALSE(c.pass);
    CHECK(c.failure == CertificateFailure::violated_constraint);
    CHECK(c.row == 1);
    CHECK(c.amount == 0.5);
  }
  SECTION("an inactive row held active needs a pulling multiplier") {
    const auto c = ref::check_certificate({M, au, J, {}}, {0, 1});
    CHECK_FALSE(c.pass);
    CHECK(c.failure == CertificateFailure::negative_multiplier);
    CHECK(c.row == 0);
    CHECK(c.amount == 1.5);  // m au_z = 2 * 0.75
  }
  SECTION("the right set passes") {
    const auto c = ref::check_certificate({M, au, J, {}}, {1});
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
    const auto p = ref::project({in.M, in.au, in.J, {}});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
    const auto full = ref::check_certificate({in.M, in.au, in.J, {}}, p.active_set);
    REQUIRE(full.pass);
    const bool independent = full.rank == static_cast<int>(p.active_set.size());
    for (size_t drop = 0; drop < p.active_set.size(); ++drop) {
      if (sgn(p.lambda[p.active_set[drop]]) <= 0) continue;
      std::vector<int> w = p.active_set;
      w.erase(w.begin() + static_cast<long>(drop));
      const auto c = ref::check_certificate({in.M, in.au, in.J, {}}, w);
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
      const auto c = ref::check_certificate({in.M, in.au, in.J, {}}, w);
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
  const auto p = ref::project({M, au, J, {}});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
  CHECK(p.active_set == std::vector<int>{0, 1, 2});
  CHECK(p.ac[2] == 0);
  require_exact_kkt(M, au, J, Eigen::VectorXd(), p.ac, p.lambda);
  for (const std::vector<int>& w : {std::vector<int>{0, 1, 2}, std::vector<int>{2, 0},
                                    std::vector<int>{1}, std::vector<int>{0, 0, 0}}) {
    const auto c = ref::check_certificate({M, au, J, {}}, w);
    CHECK(c.pass);
    CHECK(c.ac_exact == p.ac);
    CHECK(c.rank == 1);
    require_exact_kkt(M, au, J, Eigen::VectorXd(), c.ac_exact, c.lambda_exact);
  }
  CHECK(ref::check_certificate({M, au, J, {}}, {0, 1, 2}).num_dependent_rows == 2);
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
  const auto p = ref::project({M, au, J, {}});
  REQUIRE(p.status == ProjectionStatus::kOptimal);
  CHECK(p.active_set == std::vector<int>{0, 1, 2});
  const auto c = ref::check_certificate({M, au, J, {}}, {0, 1, 2});
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
  const auto bad = ref::check_certificate({M, au, J, {}}, {0, 1, 2});
  CHECK_FALSE(bad.pass);
  CHECK(bad.failure == CertificateFailure::negative_multiplier);
  CHECK(bad.row == 0);
  CHECK(bad.amount == 0.5);
  const auto good = ref::check_certificate({M, au, J, {}}, ref::project({M, au, J, {}}).active_set);
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
    const auto p = ref::project({M, au, J, {}});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
    require_exact_kkt(M, au, J, Eigen::VectorXd(), p.ac, p.lambda);
    // Every order of the tight rows is a valid claim.
    std::vector<int> w = p.active_set;
    std::reverse(w.begin(), w.end());
    for (const auto& claim : {p.active_set, w}) {
      const auto c = ref::check_certificate({M, au, J, {}}, claim);
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
      const auto p = ref::project({in.M, in.au, in.J, {}});
      const double t1 = cpu_seconds();
      const auto c = ref::check_certificate({in.M, in.au, in.J, {}}, p.active_set);
      const double t2 = cpu_seconds();
      REQUIRE(p.status == ProjectionStatus::kOptimal);
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

namespace {

// Exact objective 1/2 (a - au)^T sym(M) (a - au).
Rational objective(const Mat6& M, const Vec6& au, const std::vector<Rational>& a) {
  Rational f = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      f += (a[i] - Rational(au[i])) * (Rational(M(i, j)) + Rational(M(j, i))) / 2 *
           (a[j] - Rational(au[j]));
  return f / 2;
}

// Exact J_k a - b_k.
Rational slack(const JMat& J, const Eigen::VectorXd& b, int k, const std::vector<Rational>& a) {
  Rational s = -Rational(b[k]);
  for (int j = 0; j < 6; ++j) s += Rational(J(k, j)) * a[j];
  return s;
}

// Instances of datasets_generated/qp/, copied bit-exactly (hex floats). In each
// the body is jammed: opposite faces or nearly dependent contacts, and rounding J
// to doubles has made the exact feasible cone thinner than the geometry's, so
// the exact optimum differs by O(|au|) from what floating-point solvers find.
struct StoredInstance {
  const char* id;
  std::array<double, 36> M;  // row-major
  std::array<double, 6> au;
  std::vector<std::array<double, 6>> J;
  std::vector<double> b;
  // The active set reported by the optimized solver (quadprog and OSQP land on
  // the same point): its KKT point is what floating-point solvers return.
  std::vector<int> float_active;
};

const std::vector<StoredInstance>& ill_conditioned_instances() {
  static const std::vector<StoredInstance> instances = {
    {"box-0019",
     {0x1.a5bf7a7a61d87p+0, 0, 0, 0, 0, 0,
      0, 0x1.a5bf7a7a61d87p+0, 0, 0, 0, 0,
      0, 0, 0x1.a5bf7a7a61d87p+0, 0, 0, 0,
      0, 0, 0, 0x1.649de38510ea4p-10, 0x1.5efec79b0dd18p-12, -0x1.ab15525eece0bp-15,
      0, 0, 0, 0x1.5efec79b0dd18p-12, 0x1.84b68631a1c1fp-10, -0x1.b35b208b5898ep-12,
      0, 0, 0, -0x1.ab15525eece0bp-15, -0x1.b35b208b5898ep-12, 0x1.669737cd1778ep-10},
     {0x1.4f9fb2b29dd00p-13, -0x1.04aa75d2b1d50p-15, 0x1.f5a5b21ea280ep-15, -0x1.c73c3eaa9eb4dp-7, 0x1.bdfeb93a2d019p-7, -0x1.db7e0ebfc841dp-6},
     {{-0x1.bd8c531d9c852p-2, -0x1.756019a7d996fp-1, 0x1.0e61d75f273fdp-1, -0x1.5f9d85c6e90fep-5, 0x1.db704926a5bb5p-7, -0x1.f6463910b0c24p-7},
      {-0x1.bd8c531d9c852p-2, -0x1.756019a7d996fp-1, 0x1.0e61d75f273fdp-1, 0x1.48323cf6cec18p-6, -0x1.0e0140e197d46p-6, -0x1.99c8b0c9a0e74p-8},
      {-0x1.9f42419918564p-3, 0x1.4d379fc1b9bd7p-1, 0x1.769c3195fc5ffp-1, 0x1.6ab4f073001fcp-7, 0x1.0d348ba48b3cap-6, -0x1.7a6706767dbbcp-7},
      {-0x1.8ffec50cdfce0p-1, 0x1.d16a13c82a300p-7, -0x1.3f85e4b980c6cp-1, 0x1.13eb7eea894b2p-8, 0x1.b95621075d8a8p-6, -0x1.313b90847edbfp-8},
      {-0x1.ca57c97732b67p-2, 0x1.5e4282d32b62fp-1, 0x1.26dc32df66a83p-1, -0x1.357e5dfe269a6p-7, -0x1.6154ee513de16p-6, 0x1.2b71e3b0e01adp-6},
      {0x1.7f5ad7b5afe12p-2, 0x1.74d874056279fp-1, -0x1.25ebf656c9f71p-1, -0x1.1bf2a2ca90926p-7, 0x1.a2267deb2c646p-6, 0x1.b5d870a558373p-6},
      {-0x1.bd8c531d9c852p-2, -0x1.756019a7d996fp-1, 0x1.0e61d75f273fdp-1, 0x1.e7cde87a3ef7dp-6, -0x1.5c1869590c57ep-8, 0x1.19bd8d18f338bp-6},
      {0x1.bd8c531d9c852p-2, 0x1.756019a7d996fp-1, -0x1.0e61d75f273fdp-1, -0x1.61252d2166949p-7, 0x1.83ffd320849e4p-8, -0x1.711258b0cfc90p-11}},
     {0, 0, 0, 0, 0, 0, 0, 0},
     {6, 4, 7, 1, 5}},
    {"inertia-0019",
     {0x1.19f69475ed29ep+3, 0, 0, 0, 0, 0,
      0, 0x1.19f69475ed29ep+3, 0, 0, 0, 0,
      0, 0, 0x1.19f69475ed29ep+3, 0, 0, 0,
      0, 0, 0, 0x1.04fb4346531f5p-6, -0x1.0b5afe3cb03e6p-59, 0x1.f0bb9a16744e7p-60,
      0, 0, 0, -0x1.0b5afe3cb03e6p-59, 0x1.04fb4346531f4p-6, -0x1.7e73240d325d0p-61,
      0, 0, 0, 0x1.f0bb9a16744e7p-60, -0x1.7e73240d325d0p-61, 0x1.04fb4346531f4p-6},
     {0x1.64d44584ccab9p-14, 0x1.b996089ac7ff3p-15, -0x1.99afc8ae8d6b5p-15, 0x1.1ef67a2f37bb2p-10, -0x1.a04475d25fe77p-6, 0x1.0523868f9ebabp-5},
     {{0x1.0e672561083b3p-1, -0x1.eee592f37fdeap-2, 0x1.657c2c240297dp-1, -0x1.f327943c75b29p-6, -0x1.f5c8ea936718ep-6, 0x1.e3b0d5aa06258p-10},
      {0x1.20c0c476d26b6p-1, -0x1.87d4ced59b16ep-1, 0x1.3db43782357ddp-2, 0x1.7f89189aaf7a1p-6, -0x1.a74a5b67b90b8p-12, -0x1.64be2192642adp-5},
      {0x1.96980a64b2a03p-2, -0x1.2c2a20c95aaf5p-1, -0x1.698bcd517747bp-1, -0x1.703071799a99ep-5, -0x1.99ce91d3f7d4cp-7, -0x1.e7e5cad1ece90p-7},
      {-0x1.80502be3f127ep-1, -0x1.4ce35eda95373p-1, 0x1.e22f79f89bef2p-4, -0x1.957049a4c0ac0p-10, 0x1.7d1c4d020aff6p-7, 0x1.bd6e6f0c3f190p-5},
      {-0x1.0e672561083b3p-1, 0x1.eee592f37fdeap-2, -0x1.657c2c240297dp-1, -0x1.805a0c3589288p-9, -0x1.a343b856b3902p-7, -0x1.b30f9391bb3ecp-8},
      {-0x1.0e672561083b3p-1, 0x1.eee592f37fdeap-2, -0x1.657c2c240297dp-1, 0x1.61789e451349dp-6, -0x1.b05ecf3575f53p-7, -0x1.a1022d683f62cp-6},
      {-0x1.0e672561083b3p-1, 0x1.eee592f37fdeap-2, -0x1.657c2c240297dp-1, 0x1.3bcc4bf45e6a4p-9, 0x1.61ea0a2e0f156p-6, 0x1.ae3c565528e09p-7},
      {0x1.0e672561083b3p-1, -0x1.eee592f37fdeap-2, 0x1.657c2c240297dp-1, 0x1.4f101568669ccp-7, 0x1.073c13df158e3p-7, -0x1.1cef44787b6c0p-9}},
     {0, 0, 0, 0, 0, 0, 0, 0},
     {1, 6, 7, 0}},
    {"offsets-0025",
     {0x1.f536beeec3836p-3, 0, 0, 0, 0, 0,
      0, 0x1.f536beeec3836p-3, 0, 0, 0, 0,
      0, 0, 0x1.f536beeec3836p-3, 0, 0, 0,
      0, 0, 0, 0x1.a2e839519d37ap-13, -0x1.5408f458b861ep-15, 0x1.1d5ade1a28f7fp-16,
      0, 0, 0, -0x1.5408f458b861ep-15, 0x1.a875c83021ad9p-15, 0x1.18a0c5bca199ap-14,
      0, 0, 0, 0x1.1d5ade1a28f7fp-16, 0x1.18a0c5bca199ap-14, 0x1.7da45b9e0779cp-13},
     {0x1.0ce260d1b2d9fp-10, -0x1.32d0ad65308f0p-10, 0x1.7a0781244f203p-14, 0x1.84276820daf04p-8, 0x1.71681d161b81bp-7, 0x1.9f2cc62d4494ep-7},
     {{0x1.f0c02af939230p-1, -0x1.6b68fa097fed1p-3, 0x1.51b96b8e4eaeep-3, -0x1.b06c1bd99b8f9p-9, 0x1.15700b5dabe12p-6, 0x1.344771fe4eb91p-5},
      {-0x1.ef3b9a6e7782ap-2, 0x1.c2e956c5314ecp-2, 0x1.834c508d3fc49p-1, -0x1.a5ad354982e01p-6, -0x1.5e70f38fec63cp-11, -0x1.073896ef3fd9cp-6},
      {0x1.61cf03092dccbp-1, 0x1.f895150ba4b78p-4, 0x1.6cabe45d3e49ap-1, 0x1.89a3cce38f7aep-7, -0x1.d2fa09d35d80ap-8, -0x1.5587cd516c7a9p-7},
      {-0x1.3efb3dc01ba19p-1, 0x1.ba5d25c1ad55ap-2, 0x1.4de0582850630p-1, 0x1.2470007867ceep-5, 0x1.251698ee008dcp-8, 0x1.fe3e00a831a0dp-6},
      {-0x1.05a911c78f9cbp-2, -0x1.45c1020610274p-2, -0x1.d370334e1396ep-1, -0x1.4ac4962317addp-5, 0x1.a9ba6f16b9b74p-7, 0x1.bbefb412249aap-8},
      {-0x1.c492b9da2cca2p-1, 0x1.d9004205b3b3bp-6, -0x1.ddecc80c8ea72p-2, 0x1.69c1a43f1d610p-7, -0x1.8e173e1ac5e36p-7, -0x1.62e1078bcf4fbp-6},
      {-0x1.6a8668ce20ce3p-4, -0x1.76f8a6365de83p-2, -0x1.da472b6d46f3ap-1, 0x1.5c46d0272072cp-5, -0x1.5e528edc6a8ecp-7, 0x1.583aa336df180p-13},
      {-0x1.7f114066bfc41p-1, -0x1.5fb3d602cefebp-4, -0x1.50daa29d43ff0p-1, -0x1.91694b99c6d83p-6, 0x1.1bdcdfad976fcp-6, 0x1.a36f355973778p-6},
      {-0x1.ef3b9a6e7782ap-2, 0x1.c2e956c5314ecp-2, 0x1.834c508d3fc49p-1, 0x1.87ded7b8c5664p-6, -0x1.e4cc6971e3e00p-16, 0x1.f5a172b472c75p-7},
      {0x1.e1fbfcda8f47dp-1, -0x1.ad0db0b523664p-4, 0x1.4861e54660c9bp-2, 0x1.7a9108a276916p-10, -0x1.f8d7607320bcap-10, -0x1.3f0bf2da311d5p-8},
      {0x1.eb3c9ea42ba0bp-1, -0x1.22127ca444eb1p-3, 0x1.f324d9b318cecp-3, 0x1.6e2f8ea4fae02p-12, -0x1.96368e45fce4cp-11, -0x1.de6b07c6643b2p-10},
      {0x1.996927cec839ap-1, 0x1.884ab9b0850c1p-5, 0x1.327914aae65ccp-1, 0x1.88dc9953ee84fp-7, -0x1.31fc307e06cf0p-7, -0x1.f456213ea6c89p-7}},
     {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
     {5, 1, 3, 7, 8}}
};
  return instances;
}

}  // namespace

TEST_CASE("jammed instances of the families: the exact optimum is verified, the "
          "floating-point optimum is infeasible by a rounding-level amount",
          "[refqp][refqp-illposed]") {
  for (const StoredInstance& s : ill_conditioned_instances()) {
    INFO(s.id);
    const Mat6 M = Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(s.M.data());
    const Vec6 au = Eigen::Map<const Vec6>(s.au.data());
    const int m = static_cast<int>(s.J.size());
    JMat J(m, 6);
    for (int k = 0; k < m; ++k)
      for (int j = 0; j < 6; ++j) J(k, j) = s.J[k][j];
    const Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(s.b.data(), m);

    // 1. The exact answer: KKT verified here, independently of the solver.
    const auto p = ref::project({M, au, J, b});
    REQUIRE(p.status == ProjectionStatus::kOptimal);
    require_exact_kkt(M, au, J, b, p.ac, p.lambda);
    // Ill-conditioning shows in the multipliers: a well-posed instance has
    // |lambda| about |M au| / sigma_min(J_W), here within 1e3 of |M au|; these
    // are 1e12 and more times larger (about 1/rounding).
    const double force = (M * au).cwiseAbs().maxCoeff();
    const double lambda_max = *std::max_element(p.lambda_double.begin(), p.lambda_double.end());
    CHECK(lambda_max > 1e10 * force);

    // 2. The floating-point answer: the exact KKT point of the floating-point
    // active set violates a row, by about 1e-19 of the rows' scale (1e-15: any
    // rounding-level amount), while its objective is lower: it is not a
    // feasible point of the problem as given, so it cannot beat the optimum.
    const auto c = ref::check_certificate({M, au, J, b}, s.float_active);
    REQUIRE(c.failure == CertificateFailure::violated_constraint);
    const double row_scale = J.rowwise().lpNorm<1>().maxCoeff() * au.cwiseAbs().maxCoeff();
    CHECK(c.amount > 0);
    CHECK(c.amount < 1e-15 * row_scale);
    CHECK(objective(M, au, c.ac_exact) < objective(M, au, p.ac));
    CHECK(ref::max_abs_difference(p.ac, c.ac_rounded) > 1e-3 * au.cwiseAbs().maxCoeff());

    // 3. Backward stability of the floating-point answer: relaxing each violated
    // b_k to a double just below J_k ac (a change of about 1e-20) makes it the
    // exact optimum, certified, and the exact solve then finds exactly it.
    Eigen::VectorXd b_relaxed = b;
    double change = 0;
    for (int k = 0; k < m; ++k) {
      const Rational sk = slack(J, b, k, c.ac_exact);
      if (sgn(sk) >= 0) continue;
      const Rational target = Rational(b[k]) + sk;  // J_k ac, exactly
      double bk = ref::to_double_nearest(target);
      if (Rational(bk) > target) bk = std::nextafter(bk, -1.0);
      b_relaxed[k] = bk;
      change = std::max(change, b[k] - bk);
    }
    CHECK(change > 0);
    CHECK(change < 1e-15 * row_scale);
    const auto c2 = ref::check_certificate({M, au, J, b_relaxed}, s.float_active);
    INFO("relaxed certificate: " << name(c2.failure) << " row " << c2.row);
    CHECK(c2.pass);
    CHECK(c2.ac_exact == c.ac_exact);
    const auto p2 = ref::project({M, au, J, b_relaxed});
    REQUIRE(p2.status == ProjectionStatus::kOptimal);
    require_exact_kkt(M, au, J, b_relaxed, p2.ac, p2.lambda);
    CHECK(p2.ac == c.ac_exact);
  }
}

TEST_CASE("every instance of every family: the exact answer is verified and its "
          "active set's certificate reproduces it exactly", "[refqp][refqp-families]") {
  // The families of datasets_generated/qp/ (format gauss6-qp-instances v1),
  // read here with nlohmann::json (correctly rounded: bit-exact doubles).
  const std::filesystem::path dir = std::filesystem::path(GAUSS6_SOURCE_DIR) / "datasets_generated/qp";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".json" && e.path().filename() != "MANIFEST.json")
      files.push_back(e.path());
  std::sort(files.begin(), files.end());
  REQUIRE(files.size() >= 8);

  auto cpu_seconds = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  };
  int total = 0;
  for (const auto& path : files) {
    std::ifstream in(path);
    const nlohmann::json family = nlohmann::json::parse(in);
    REQUIRE(family.at("format") == "gauss6-qp-instances");
    int count = 0, infeasible = 0, ill = 0, with_lp = 0;
    double t_solve = 0;
    for (const auto& inst : family.at("instances")) {
      const std::string id = inst.at("id");
      INFO(id);
      Mat6 M;
      Vec6 au;
      for (int i = 0; i < 6; ++i) {
        au[i] = inst.at("au")[i].get<double>();
        for (int j = 0; j < 6; ++j) M(i, j) = inst.at("M")[i][j].get<double>();
      }
      const int m = static_cast<int>(inst.at("J").size());
      JMat J(m, 6);
      Eigen::VectorXd b(m);
      for (int k = 0; k < m; ++k) {
        b[k] = inst.at("b")[k].get<double>();
        for (int j = 0; j < 6; ++j) J(k, j) = inst.at("J")[k][j].get<double>();
      }
      // The offsets family declares by construction which instances are infeasible.
      const bool declared_infeasible = inst.contains("tags") && inst["tags"].contains("feasible") &&
                                       !inst["tags"]["feasible"].get<bool>();
      const double t0 = cpu_seconds();
      const auto p = ref::project({M, au, J, b});
      t_solve += cpu_seconds() - t0;
      ++count;
      if (declared_infeasible) {
        REQUIRE(p.status == ProjectionStatus::kInfeasibleOffsets);  // Farkas-verified inside
        ++infeasible;
        continue;
      }
      REQUIRE(p.status == ProjectionStatus::kOptimal);
      require_exact_kkt(M, au, J, b, p.ac, p.lambda);
      const auto c = ref::check_certificate({M, au, J, b}, p.active_set);
      INFO("certificate failure " << name(c.failure) << " row " << c.row);
      REQUIRE(c.pass);
      REQUIRE(c.ac_exact == p.ac);
      with_lp += c.used_lp;
      const double force = (M * au).cwiseAbs().maxCoeff();
      if (m > 0 && *std::max_element(p.lambda_double.begin(), p.lambda_double.end()) > 1e10 * force)
        ++ill;
    }
    total += count;
    std::cout << path.stem().string() << ": " << count << " instances, " << infeasible
              << " infeasible, " << ill << " ill-conditioned (lambda > 1e10 |M au|), " << with_lp
              << " certificates via the LP; exact solves " << 1e3 * t_solve / count
              << " ms each (CPU)\n";
  }
  CHECK(total >= 2620);
}

namespace {

// The instances of a file in the gauss6-qp-instances format (bit-exact doubles).
std::vector<ref::ProjectionProblem> read_problems(const std::filesystem::path& path, int every = 1) {
  std::ifstream in(path);
  const nlohmann::json family = nlohmann::json::parse(in);
  std::vector<ref::ProjectionProblem> out;
  int index = 0;
  for (const auto& inst : family.at("instances")) {
    if (index++ % every != 0) continue;
    ref::ProjectionProblem pb;
    for (int i = 0; i < 6; ++i) {
      pb.au[i] = inst.at("au")[i].get<double>();
      for (int j = 0; j < 6; ++j) pb.M(i, j) = inst.at("M")[i][j].get<double>();
    }
    const int m = static_cast<int>(inst.at("J").size());
    pb.J.resize(m, 6);
    pb.b.resize(m);
    for (int k = 0; k < m; ++k) {
      pb.b[k] = inst.at("b")[k].get<double>();
      for (int j = 0; j < 6; ++j) pb.J(k, j) = inst.at("J")[k][j].get<double>();
    }
    out.push_back(pb);
  }
  return out;
}

}  // namespace

TEST_CASE("both exact paths give the same answer: certified guess and CGAL's solver", "[refqp][refqp-paths]") {
  // project() keeps a floating-point guess of the active set only when its exact
  // KKT point passes the exact certificate; project_by_qp_solver() is CGAL alone.
  // On every fourth instance of every family of datasets_generated/qp/ both must
  // give the same status and, when optimal, the same exact ac.
  const std::filesystem::path dir = std::filesystem::path(GAUSS6_SOURCE_DIR) / "datasets_generated/qp";
  int compared = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".json" || e.path().filename() == "MANIFEST.json") continue;
    for (const ref::ProjectionProblem& pb : read_problems(e.path(), 4)) {
      INFO(e.path().filename() << " instance " << compared);
      const auto fast = ref::project(pb);
      const auto cgal = ref::project_by_qp_solver(pb);
      REQUIRE(fast.status == cgal.status);
      if (fast.status == ProjectionStatus::kOptimal) {
        CHECK(fast.ac == cgal.ac);
        require_exact_kkt(pb.M, pb.au, pb.J, pb.b, fast.ac, fast.lambda);
      }
      ++compared;
    }
  }
  CHECK(compared >= 600);
  // A seeded m50 instance (qp_seeded chunk_instances("m50", 1, 19)[16]) on which
  // CGAL's solver had not finished after 4 minutes of CPU: the certified guess answers it, and
  // the answer passes the independent exact KKT verification.
  const auto slow = read_problems(std::filesystem::path(GAUSS6_SOURCE_DIR) / "reference/tests/data/qp_slow_exact.json");
  REQUIRE(slow.size() == 1);
  const auto p = ref::project(slow[0]);
  REQUIRE(p.status == ProjectionStatus::kOptimal);
  require_exact_kkt(slow[0].M, slow[0].au, slow[0].J, slow[0].b, p.ac, p.lambda);
}
