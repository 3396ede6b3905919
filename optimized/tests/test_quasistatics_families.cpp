// The proved theorems of proofs/Projection.v, checked on the code: every
// instance of every projection family of datasets_generated/qp/ is solved by
// the optimized solver, and each theorem's conclusion is tested on its answer.
// The theorems hold for exact KKT points; the solver returns one up to rounding,
// so each check carries a tolerance, stated and justified where it is made.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "gauss6/contact/coupling.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/contact/quasistatics.h"

using namespace gauss6;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

double m_norm(const Mat6& M, const Vec6& x) { return std::sqrt(std::max(x.dot(M * x), 0.0)); }

// sqrt(cond(M)) = cond(L): the solver works in y = L^T a and comes back by a
// triangular solve, losing at most this factor of relative accuracy.
double cond_L(const Mat6& M) {
  Eigen::SelfAdjointEigenSolver<Mat6> eig(M);
  return std::sqrt(eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff());
}

std::vector<QpInstance> family(const std::string& name) {
  return read_qp_instances(std::string(GAUSS6_SOURCE_DIR) + "/datasets_generated/qp/" + name + ".json");
}

}  // namespace

TEST_CASE("the proved properties hold on every instance family", "[qp][families]") {
  const std::vector<std::string> names = {"box", "peg", "bunny", "m50", "redundant", "inertia", "offsets", "warm"};
  const double kh = 1000.0;
  for (const std::string& name : names) {
    const std::vector<QpInstance> instances = family(name);
    REQUIRE(!instances.empty());
    int num_checked = 0;
    for (const QpInstance& q : instances) {
      INFO(name << " " << q.id);
      ProjectionProblem p;
      p.M = &q.M;
      p.au = q.au;
      p.J = q.J.rows() ? q.J.data() : nullptr;
      p.b = q.b.size() ? q.b.data() : nullptr;
      p.num_rows = static_cast<int>(q.J.rows());
      ProjectionSettings settings;
      settings.warm_start = false;
      ProjectionWorkspace ws;
      ProjectionResult r;
      const ProjectionStatus status = project(p, settings, &ws, &r);
      const bool has_offsets = q.b.size() && q.b.cwiseAbs().maxCoeff() > 0;
      if (status == ProjectionStatus::kInfeasibleOffsets) {
        // Only offset families can be infeasible; the force is then zero.
        CHECK(has_offsets);
        CHECK(r.ac == q.au);
        continue;
      }
      REQUIRE(status == ProjectionStatus::kOptimal);
      ++num_checked;
      const int m = p.num_rows;
      const Eigen::Map<const Eigen::VectorXd> lambda(r.lambda.data(), m);
      const Vec6 Fc = coupling_force(q.M, q.au, r.ac, kh);
      const Vec6 Fu = q.M * q.au;
      // Scales: |au|_M is the size of the step; a rounding error in a (relative
      // eps * cond(L)) changes an M-weighted product by eps * cond(L) |au|_M^2.
      // 64 eps covers the few dozen rounded operations of a projection.
      const double au_M = m_norm(q.M, q.au);
      const double tol = 64 * kEps * cond_L(q.M) * au_M * au_M;

      // Theorem orthogonality_offset (b = 0: orthogonality):
      //   (ac - au)^T M ac = lambda^T b    (b = 0: (ac - au)^T M ac = 0)
      const double orth = (r.ac - q.au).dot(q.M * r.ac) - (has_offsets ? lambda.dot(q.b) : 0.0);
      CHECK(std::abs(orth) <= tol);
      // Theorem force_orthogonal (b = 0): Fc^T ac = 0 for every gain kh.
      if (!has_offsets) CHECK(std::abs(Fc.dot(r.ac)) <= kh * tol);

      // Theorem force_in_cone: Fc = kh J^T lambda with lambda >= 0 (no
      // tangential part). lambda >= 0 holds exactly (the solver's multipliers
      // stay >= 0 by construction); the identity holds to rounding: a sum's
      // rounding error is bounded by eps times the sum of the absolute values of
      // its terms, here |M au| + sum_k lambda_k |J_k| (nearly parallel rows can
      // carry large opposite multipliers), times 64 cond(L).
      CHECK(lambda.minCoeff() >= 0.0);
      const Vec6 JTl = m ? Vec6(q.J.transpose() * lambda) : Vec6::Zero();
      double abs_terms = Fu.norm();
      for (int k = 0; k < m; ++k) abs_terms += lambda[k] * q.J.row(k).norm();
      CHECK((Fc - kh * JTl).norm() <= 64 * kEps * cond_L(q.M) * kh * abs_terms);

      // Theorem free_motion: J au >= b implies ac = au and Fc = 0 (exactly: the
      // solver drops rounding-noise multipliers so that free motion is exact).
      const bool free = m == 0 || ((q.J * q.au - q.b).array() >= 0).all();
      if (free) {
        CHECK(r.ac == q.au);
        CHECK(Fc.isZero(0.0));
      }

      // Theorem dissipativity (b = 0) and dissipativity_nonpositive_offset (b <= 0):
      //   Fu^T ac <= Fu^T au, Fu = M au: the constraints only remove energy.
      if (!has_offsets || q.b.maxCoeff() <= 0) CHECK(Fu.dot(r.ac) <= Fu.dot(q.au) + tol);
      else CHECK(Fu.dot(r.ac) <= Fu.dot(q.au) + lambda.dot(q.b) + tol);  // dissipativity_offset

      // KKT primal feasibility, relative to the row's scale |J_k| |au| + |b_k|
      // at the solver's own feasibility tolerance (settings.feasibility_tol, quasistatics.h).
      for (int k = 0; k < m; ++k) {
        const double slack = q.J.row(k).dot(r.ac) - (q.b.size() ? q.b[k] : 0.0);
        CHECK(slack >= -settings.feasibility_tol * (q.J.row(k).norm() * q.au.norm() + std::abs(q.b.size() ? q.b[k] : 0.0)));
      }
    }
    CHECK(num_checked > 0);
  }
}
