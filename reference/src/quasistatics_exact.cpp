// The exact quasi-static projection (METHOD.md sections 2-3) with CGAL's exact
// quadratic program solver, and the exact LP behind the certificate check's
// fallback for dependent active rows. The only CGAL translation unit of the
// projection code (it takes tens of seconds and over 1 GB to compile).
//
// Number types: every input double is a dyadic rational m 2^e, and so are the
// sums and products c = -sym(M) au and sym(M) = (M + M^T) / 2, so the program
// is stated in CGAL::Gmpzf (arbitrary-precision binary floating point, exact
// for + - *) and solved with exact type Gmpzf: no rounding anywhere. CGAL's
// answer is then verified in GMP rationals by code that does not use CGAL
// (quasistatics_certificate.cpp) before it is returned.
#include <CGAL/Gmpzf.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

#include "exact_linear_algebra.h"
#include "gauss6/reference/quasistatics.h"

namespace gauss6::reference {
namespace {

using ET = CGAL::Gmpzf;
using Program = CGAL::Quadratic_program<ET>;
using Solution = CGAL::Quadratic_program_solution<ET>;

// x = man 2^exp, exactly.
Rational to_rational(const ET& x) {
  Rational q;
  mpq_set_z(q.get_mpq_t(), x.man());
  const long e = x.exp();
  if (e > 0) mpq_mul_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(e));
  if (e < 0) mpq_div_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(-e));
  return q;
}

Rational to_rational(const CGAL::Quotient<ET>& x) {
  return to_rational(x.numerator()) / to_rational(x.denominator());
}

}  // namespace

namespace {

// A floating-point guess of the optimal active set by Hildreth's row-action
// method (C. Hildreth, Naval Res. Logist. Q. 4, 1957: coordinate descent on the
// dual, one row at a time, lambda_k >= 0; not the optimized solver's
// Goldfarb-Idnani method): the rows with a positive multiplier or a slack
// within 1e-9 of the row's scale after at most kHildrethSweeps sweeps, or until
// no row moves its multiplier by more than 1e-15 of the largest. Only a guess:
// project() keeps it only when the exact certificate passes.
constexpr int kHildrethSweeps = 2000;

std::vector<int> hildreth_active_set(const ProjectionProblem& pb) {
  const int m = static_cast<int>(pb.J.rows());
  const Mat6 Ms = 0.5 * (pb.M + pb.M.transpose());
  const Eigen::LLT<Mat6> llt(Ms);
  const Eigen::MatrixXd MinvJt = llt.solve(pb.J.transpose());  // 6 x m
  Eigen::VectorXd diag(m), lambda = Eigen::VectorXd::Zero(m);
  for (int k = 0; k < m; ++k) diag[k] = pb.J.row(k).dot(MinvJt.col(k));
  Vec6 a = pb.au;
  auto rhs = [&](int k) { return pb.b.size() == 0 ? 0.0 : pb.b[k]; };
  for (int sweep = 0; sweep < kHildrethSweeps; ++sweep) {
    double largest = 0, moved = 0;
    for (int k = 0; k < m; ++k) {
      if (!(diag[k] > 0)) continue;
      const double step = std::max(-lambda[k], (rhs(k) - pb.J.row(k).dot(a)) / diag[k]);
      lambda[k] += step;
      a += step * MinvJt.col(k);
      largest = std::max(largest, lambda[k]);
      moved = std::max(moved, std::abs(step));
    }
    if (!std::isfinite(largest) || moved <= 1e-15 * largest) break;
  }
  std::vector<int> active;
  const double a_norm = std::max(a.norm(), pb.au.norm());
  for (int k = 0; k < m; ++k) {
    const double slack = pb.J.row(k).dot(a) - rhs(k);
    if (lambda[k] > 0 || std::abs(slack) <= 1e-9 * (pb.J.row(k).norm() * a_norm + std::abs(rhs(k))))
      active.push_back(k);
  }
  return active;
}

}  // namespace

ProjectionResult project(const ProjectionProblem& problem) {
  ProjectionResult out;  // status = kBadInput until the inputs are checked
  if (!internal::valid_inputs(problem.M, problem.au, problem.J, problem.b)) return out;
  if (!internal::positive_definite(internal::symmetric_part(problem.M))) return out;
  // A guessed active set whose exact KKT point passes the exact certificate is
  // the exact optimum (check_certificate); CGAL's solver decides the rest.
  const CertificateReport cert = check_certificate(problem, hildreth_active_set(problem));
  if (!cert.pass) return project_by_qp_solver(problem);
  const int m = static_cast<int>(problem.J.rows());
  out.status = ProjectionStatus::kOptimal;
  out.ac = cert.ac_exact;
  out.lambda = cert.lambda_exact;
  out.ac_double = cert.ac_rounded;
  out.lambda_double = cert.lambda_rounded;
  for (int k = 0; k < m; ++k) {
    Rational s = -Rational(problem.b.size() == 0 ? 0.0 : problem.b[k]);
    for (int j = 0; j < 6; ++j)
      if (problem.J(k, j) != 0) s += Rational(problem.J(k, j)) * out.ac[j];
    if (sgn(s) == 0) out.active_set.push_back(k);
  }
  return out;
}

ProjectionResult project_by_qp_solver(const ProjectionProblem& problem) {
  const Mat6& M = problem.M;
  const Vec6& au = problem.au;
  const Eigen::MatrixXd& J = problem.J;
  const Eigen::VectorXd& b = problem.b;
  ProjectionResult out;  // status = kBadInput until the inputs are checked
  if (!internal::valid_inputs(M, au, J, b)) return out;
  if (!internal::positive_definite(internal::symmetric_part(M))) return out;
  const int m = static_cast<int>(J.rows());

  // min 1/2 a^T sym(M) a + c^T a, c = -sym(M) au, subject to J a >= b and
  // a free. CGAL minimises x^T D x + c^T x and set_d takes 2D (lower triangle).
  Program qp(CGAL::LARGER, /*finite_lower=*/false, ET(0), /*finite_upper=*/false, ET(0));
  const ET half(0.5);
  ET Ms[6][6];
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j <= i; ++j) {
      Ms[i][j] = i == j ? ET(M(i, i)) : (ET(M(i, j)) + ET(M(j, i))) * half;
      Ms[j][i] = Ms[i][j];
      if (!CGAL::is_zero(Ms[i][j])) qp.set_d(i, j, Ms[i][j]);
    }
  for (int i = 0; i < 6; ++i) {
    ET c(0);
    for (int j = 0; j < 6; ++j) c -= Ms[i][j] * ET(au[j]);
    qp.set_c(i, c);
  }
  for (int k = 0; k < m; ++k) {
    for (int j = 0; j < 6; ++j)
      if (J(k, j) != 0) qp.set_a(j, k, ET(J(k, j)));  // set_a(variable, row, value)
    qp.set_b(k, ET(b.size() == 0 ? 0.0 : b[k]));
  }

  const Solution sol = CGAL::solve_quadratic_program(qp, ET());

  // Every answer is verified here in exact rational arithmetic, independently
  // of CGAL's own claim: a Farkas certificate for infeasible, the KKT
  // conditions for optimal. Anything unverified is a solver failure.
  out.status = ProjectionStatus::kSolverFailure;
  if (sol.status() == CGAL::QP_INFEASIBLE) {
    // CGAL's certificate l has l <= 0 on >= rows, l^T A = 0, l^T b < 0: y = -l.
    std::vector<Rational> y;
    y.reserve(m);
    for (auto it = sol.infeasibility_certificate_begin();
         it != sol.infeasibility_certificate_end(); ++it)
      y.push_back(-to_rational(*it));
    if (internal::verify_infeasibility(J, b, y)) out.status = ProjectionStatus::kInfeasibleOffsets;
    return out;
  }
  // sym(M) is positive definite (checked exactly above), so "unbounded" is
  // impossible, and QP_UPDATE is an intermediate state, never an answer.
  if (sol.status() != CGAL::QP_OPTIMAL) return out;

  // Both iterators give CGAL::Quotient<ET> values (numerator / denominator).
  std::vector<Rational> ac, lambda;
  ac.reserve(6);
  for (auto it = sol.variable_values_begin(); it != sol.variable_values_end(); ++it)
    ac.push_back(to_rational(*it));
  // CGAL's multipliers satisfy c + 2 D x + A^T l = 0 with l <= 0 on >= rows:
  // M (ac - au) = J^T (-l), so the contact multipliers are -l.
  lambda.reserve(m);
  for (auto it = sol.optimality_certificate_begin(); it != sol.optimality_certificate_end(); ++it)
    lambda.push_back(-to_rational(*it));
  if (!internal::verify_optimum(M, au, J, b, ac, lambda)) return out;

  out.status = ProjectionStatus::kOptimal;
  out.ac = std::move(ac);
  out.lambda = std::move(lambda);
  for (int i = 0; i < 6; ++i) out.ac_double[i] = to_double_nearest(out.ac[i]);
  out.lambda_double.resize(m);
  for (int k = 0; k < m; ++k) out.lambda_double[k] = to_double_nearest(out.lambda[k]);
  for (int k = 0; k < m; ++k) {
    Rational s = -Rational(b.size() == 0 ? 0.0 : b[k]);
    for (int j = 0; j < 6; ++j)
      if (J(k, j) != 0) s += Rational(J(k, j)) * out.ac[j];
    if (sgn(s) == 0) out.active_set.push_back(k);
  }
  return out;
}

namespace internal {

bool find_nonnegative_combination(const Eigen::Ref<const Eigen::MatrixXd>& J,
                                  const std::vector<int>& rows, const Row6& g,
                                  std::vector<Rational>& lambda) {
  // Scale g to integers: g = g_num / d, d > 0 the lcm of its denominators; then
  // mu = d lambda solves sum_i mu_i J_i = g_num, mu >= 0 (a dyadic LP in Gmpzf).
  mpz_class d = 1;
  for (const Rational& v : g) mpz_lcm(d.get_mpz_t(), d.get_mpz_t(), v.get_den_mpz_t());
  Program lp(CGAL::EQUAL, /*finite_lower=*/true, ET(0), /*finite_upper=*/false, ET(0));
  for (int t = 0; t < 6; ++t) {
    const mpz_class num = g[t].get_num() * (d / g[t].get_den());
    lp.set_b(t, ET(num.get_mpz_t()));
  }
  const int n = static_cast<int>(rows.size());
  for (int i = 0; i < n; ++i) {
    lp.set_c(i, ET(0));
    for (int t = 0; t < 6; ++t)
      if (J(rows[i], t) != 0) lp.set_a(i, t, ET(J(rows[i], t)));
  }
  const Solution sol = CGAL::solve_linear_program(lp, ET());
  if (sol.status() != CGAL::QP_OPTIMAL) return false;
  lambda.clear();
  const Rational dq(d);
  for (auto it = sol.variable_values_begin(); it != sol.variable_values_end(); ++it)
    lambda.push_back(to_rational(*it) / dq);
  lambda.resize(n);
  return true;
}

}  // namespace internal
}  // namespace gauss6::reference
