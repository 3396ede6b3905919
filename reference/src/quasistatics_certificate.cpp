// Exact certificate check of a claimed active set for the quasi-static
// projection (METHOD.md sections 2-3), in GMP rationals, plus the small exact
// linear algebra it shares with the exact projection. No CGAL here: this file
// is the fast path that runs on tens of thousands of instances; only the rare
// fallback for dependent active rows calls the exact LP (quasistatics_exact.cpp).
#include <mpfr.h>

#include <algorithm>
#include <array>

#include "exact_linear_algebra.h"
#include "gauss6/reference/quasistatics.h"

namespace gauss6::reference {
namespace internal {

bool valid_inputs(const Mat6& M, const Vec6& au,
                  const Eigen::Ref<const Eigen::MatrixXd>& J,
                  const Eigen::VectorXd& b) {
  if (J.cols() != 6) return false;
  if (b.size() != 0 && b.size() != J.rows()) return false;
  return M.allFinite() && au.allFinite() && J.allFinite() && b.allFinite();
}

Sym6 symmetric_part(const Mat6& M) {
  Sym6 S;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      if (i == j) {
        S[6 * i + j] = M(i, j);
      } else {
        S[6 * i + j] = (Rational(M(i, j)) + Rational(M(j, i))) / 2;
      }
    }
  return S;
}

void integerize(const Rational* v, int n, mpz_class* out) {
  mpz_class L = 1;
  for (int i = 0; i < n; ++i) mpz_lcm(L.get_mpz_t(), L.get_mpz_t(), v[i].get_den_mpz_t());
  for (int i = 0; i < n; ++i) {
    mpz_divexact(out[i].get_mpz_t(), L.get_mpz_t(), v[i].get_den_mpz_t());
    out[i] *= v[i].get_num();
  }
}

bool bareiss_solve(std::vector<mpz_class>& A, int n, int spd_block,
                   std::vector<mpz_class>& x, mpz_class& det) {
  const int w = n + 1;
  auto at = [&](int i, int j) -> mpz_class& { return A[static_cast<size_t>(w) * i + j]; };
  mpz_class prev = 1, t;
  for (int k = 0; k < n; ++k) {
    // Entry (i, j) after step k is the minor of rows {0..k, i}, columns {0..k, j}.
    int p = k;
    if (k < spd_block) {
      if (sgn(at(k, k)) <= 0) return false;  // leading minor k + 1 of the block
    } else {
      while (p < n && sgn(at(p, k)) == 0) ++p;
      if (p == n) return false;
      if (p != k)
        for (int j = k; j < w; ++j) mpz_swap(at(p, j).get_mpz_t(), at(k, j).get_mpz_t());
    }
    const mpz_class& piv = at(k, k);
    for (int i = k + 1; i < n; ++i) {
      const bool zero_ik = sgn(at(i, k)) == 0;
      for (int j = k + 1; j < w; ++j) {
        mpz_mul(t.get_mpz_t(), piv.get_mpz_t(), at(i, j).get_mpz_t());
        if (!zero_ik) mpz_submul(t.get_mpz_t(), at(i, k).get_mpz_t(), at(k, j).get_mpz_t());
        mpz_divexact(at(i, j).get_mpz_t(), t.get_mpz_t(), prev.get_mpz_t());
      }
      at(i, k) = 0;
    }
    prev = piv;
  }
  // Back substitution on the integers x = det y (Cramer numerators).
  det = at(n - 1, n - 1);
  x.resize(n);
  for (int i = n - 1; i >= 0; --i) {
    mpz_mul(t.get_mpz_t(), det.get_mpz_t(), at(i, n).get_mpz_t());
    for (int j = i + 1; j < n; ++j)
      if (sgn(at(i, j)) != 0) mpz_submul(t.get_mpz_t(), at(i, j).get_mpz_t(), x[j].get_mpz_t());
    mpz_divexact(x[i].get_mpz_t(), t.get_mpz_t(), at(i, i).get_mpz_t());
  }
  return true;
}

bool positive_definite(const Sym6& S) {
  std::vector<mpz_class> A(6 * 7);
  for (int i = 0; i < 6; ++i) {
    integerize(&S[6 * i], 6, &A[7 * i]);  // row scaling keeps the minors' signs
    A[7 * i + 6] = 0;
  }
  std::vector<mpz_class> x;
  mpz_class det;
  return bareiss_solve(A, 6, /*spd_block=*/6, x, det);
}

Row6 exact_row(const Eigen::Ref<const Eigen::MatrixXd>& J, int k) {
  Row6 r;
  for (int j = 0; j < 6; ++j) r[j] = J(k, j);
  return r;
}

bool verify_optimum(const Mat6& M, const Vec6& au,
                    const Eigen::Ref<const Eigen::MatrixXd>& J,
                    const Eigen::VectorXd& b, const std::vector<Rational>& ac,
                    const std::vector<Rational>& lambda) {
  const int m = static_cast<int>(J.rows());
  if (ac.size() != 6 || static_cast<int>(lambda.size()) != m) return false;
  // Primal and dual feasibility, complementarity, row by row.
  Rational s;
  for (int k = 0; k < m; ++k) {
    if (sgn(lambda[k]) < 0) return false;
    s = b.size() == 0 ? Rational(0) : Rational(-b[k]);
    for (int j = 0; j < 6; ++j)
      if (J(k, j) != 0) s += Rational(J(k, j)) * ac[j];
    if (sgn(s) < 0) return false;
    if (sgn(s) != 0 && sgn(lambda[k]) != 0) return false;
  }
  // Stationarity: sym(M) (ac - au) == J^T lambda, entry by entry.
  const Sym6 Ms = symmetric_part(M);
  Row6 d;
  for (int j = 0; j < 6; ++j) d[j] = ac[j] - Rational(au[j]);
  Rational lhs;
  for (int i = 0; i < 6; ++i) {
    lhs = 0;
    for (int j = 0; j < 6; ++j)
      if (sgn(Ms[6 * i + j]) != 0) lhs += Ms[6 * i + j] * d[j];
    for (int k = 0; k < m; ++k)
      if (J(k, i) != 0 && sgn(lambda[k]) != 0) lhs -= Rational(J(k, i)) * lambda[k];
    if (sgn(lhs) != 0) return false;
  }
  return true;
}

bool verify_infeasibility(const Eigen::Ref<const Eigen::MatrixXd>& J,
                          const Eigen::VectorXd& b, const std::vector<Rational>& y) {
  const int m = static_cast<int>(J.rows());
  if (static_cast<int>(y.size()) != m || b.size() != m) return false;
  Rational v = 0;
  for (int k = 0; k < m; ++k) {
    if (sgn(y[k]) < 0) return false;
    if (b[k] != 0) v += Rational(b[k]) * y[k];
  }
  if (sgn(v) <= 0) return false;  // b^T y > 0
  for (int j = 0; j < 6; ++j) {   // J^T y == 0
    v = 0;
    for (int k = 0; k < m; ++k)
      if (J(k, j) != 0) v += Rational(J(k, j)) * y[k];
    if (sgn(v) != 0) return false;
  }
  return true;
}

}  // namespace internal

using internal::Row6;

double to_double_nearest(const Rational& q) {
  // 53-bit MPFR rounding to nearest, then an exact conversion.
  mpfr_t x;
  mpfr_init2(x, 53);
  mpfr_set_q(x, q.get_mpq_t(), MPFR_RNDN);
  const double d = mpfr_get_d(x, MPFR_RNDN);
  mpfr_clear(x);
  return d;
}

double max_abs_difference(const std::vector<Rational>& exact, const Vec6& approx) {
  Rational worst = 0;
  const int n = std::min<int>(static_cast<int>(exact.size()), 6);
  for (int i = 0; i < n; ++i) {
    const Rational diff = abs(exact[i] - Rational(approx[i]));
    if (diff > worst) worst = diff;
  }
  return to_double_nearest(worst);
}

std::vector<std::string> to_strings(const std::vector<Rational>& values) {
  std::vector<std::string> out;
  out.reserve(values.size());
  for (const Rational& v : values) out.push_back(v.get_str());
  return out;
}

namespace {

using internal::Sym6;

// A maximal independent subset B of the rows W, greedily in W's order, by
// fraction-free row reduction of the integer-scaled rows: each echelon row is
// zero at the pivot columns of the earlier ones. *num_dependent counts the
// rows left out.
std::vector<int> independent_rows(const Eigen::MatrixXd& J, const std::vector<int>& rows, int* num_dependent) {
  std::vector<std::array<mpz_class, 6>> echelon;
  std::vector<int> pivot_col;
  std::vector<int> basis;
  for (int k : rows) {
    const Row6 jk = internal::exact_row(J, k);
    std::array<mpz_class, 6> r;
    internal::integerize(jk.data(), 6, r.data());
    for (size_t e = 0; e < echelon.size(); ++e) {
      const int pc = pivot_col[e];
      if (sgn(r[pc]) == 0) continue;
      const mpz_class f = r[pc], g = echelon[e][pc];
      for (int j = 0; j < 6; ++j) r[j] = g * r[j] - f * echelon[e][j];
    }
    int p = 0;
    while (p < 6 && sgn(r[p]) == 0) ++p;
    if (p == 6) {
      ++*num_dependent;
      continue;
    }
    mpz_class content = 0;  // keep the entries small
    for (int j = 0; j < 6; ++j) mpz_gcd(content.get_mpz_t(), content.get_mpz_t(), r[j].get_mpz_t());
    for (int j = 0; j < 6; ++j) mpz_divexact(r[j].get_mpz_t(), r[j].get_mpz_t(), content.get_mpz_t());
    echelon.push_back(std::move(r));
    pivot_col.push_back(p);
    basis.push_back(k);
  }
  return basis;
}

// c_k = J_k au - b_k of every row, exact (b empty: 0).
std::vector<Rational> exact_offsets_at_au(const Eigen::MatrixXd& J, const Vec6& au, const Eigen::VectorXd& b) {
  const int m = static_cast<int>(J.rows());
  std::vector<Rational> c(m);
  for (int k = 0; k < m; ++k) {
    Rational v = -Rational(b.size() == 0 ? 0.0 : b[k]);
    for (int t = 0; t < 6; ++t)
      if (J(k, t) != 0 && au[t] != 0) v += Rational(J(k, t)) * Rational(au[t]);
    c[k] = std::move(v);
  }
  return c;
}

// The KKT point of B, written for d = a - au:
//   [ sym(M)  -J_B^T ] [ d        ]   [ 0                ]
//   [ J_B      0     ] [ lambda_B ] = [ b_B - J_B au     ],
// each row scaled to integers and solved fraction-free: *x = det (d, lambda_B)
// (Cramer numerators) and *det the determinant. The first six pivots are M's
// leading minors, which checks that M is positive definite: false when not
// (J_B has full row rank, so only such an M makes the solve fail).
bool solve_basis_kkt(const Sym6& Ms, const Eigen::MatrixXd& J, const std::vector<int>& basis,
                     const std::vector<Rational>& c, std::vector<mpz_class>* x, mpz_class* det) {
  const int nb = static_cast<int>(basis.size());
  const int n = 6 + nb, w = n + 1;
  std::vector<mpz_class> K(static_cast<size_t>(n) * w);
  std::vector<Rational> row(w);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) row[j] = Ms[6 * i + j];
    for (int q = 0; q < nb; ++q) row[6 + q] = -J(basis[q], i);
    row[n] = 0;
    internal::integerize(row.data(), w, &K[static_cast<size_t>(w) * i]);
  }
  for (int q = 0; q < nb; ++q) {
    for (int j = 0; j < 6; ++j) row[j] = J(basis[q], j);
    for (int j = 6; j < n; ++j) row[j] = 0;
    row[n] = -c[basis[q]];
    internal::integerize(row.data(), w, &K[static_cast<size_t>(w) * (6 + q)]);
  }
  return internal::bareiss_solve(K, n, /*spd_block=*/6, *x, *det);
}

// Primal feasibility of every row at a = au + x(0:6) / det: s_k = J_k a - b_k =
// c_k + J_k d, so det s_k = det c_k + J_k x is dyadic: no division per row.
// Returns the most violated row (-1 when none is) and *amount, its b_k - J_k a;
// *tight gets the rows tight at a (of W or not: KKT allows a multiplier on any
// row tight at a).
int most_violated_row(const Eigen::MatrixXd& J, const std::vector<Rational>& c, const std::vector<mpz_class>& x,
                      const mpz_class& det, Rational* amount, std::vector<int>* tight) {
  const int m = static_cast<int>(J.rows());
  const int det_sign = sgn(det);
  const Rational det_q(det);
  int worst_row = -1;
  Rational worst = 0;  // most negative det_sign * det * s_k
  Rational ts;
  for (int k = 0; k < m; ++k) {
    ts = c[k] * det_q;
    for (int t = 0; t < 6; ++t)
      if (J(k, t) != 0 && sgn(x[t]) != 0) ts += Rational(J(k, t)) * Rational(x[t]);
    if (det_sign < 0) ts = -ts;
    if (ts < worst) {
      worst = ts;
      worst_row = k;
    }
    if (sgn(ts) == 0) tight->push_back(k);
  }
  if (worst_row >= 0) *amount = -worst / abs(det_q);
  return worst_row;
}

// Multipliers lambda_T >= 0 over the tight rows T with the same wrench
// g = J_B^T lambda_B as B's, searched by the exact LP and verified here,
// exactly, whatever found them; false when none is found.
bool nonnegative_tight_multipliers(const Eigen::MatrixXd& J, const std::vector<int>& basis,
                                   const std::vector<Rational>& lambda_b, const std::vector<int>& tight,
                                   std::vector<Rational>* lambda_t) {
  const int nb = static_cast<int>(basis.size());
  Row6 g;
  for (int t = 0; t < 6; ++t) {
    Rational v = 0;
    for (int i = 0; i < nb; ++i) v += Rational(J(basis[i], t)) * lambda_b[i];
    g[t] = v;
  }
  if (!internal::find_nonnegative_combination(J, tight, g, *lambda_t) || lambda_t->size() != tight.size())
    return false;
  bool ok = std::all_of(lambda_t->begin(), lambda_t->end(), [](const Rational& l) { return sgn(l) >= 0; });
  for (int t = 0; t < 6 && ok; ++t) {
    Rational v = 0;
    for (size_t i = 0; i < tight.size(); ++i) v += Rational(J(tight[i], t)) * (*lambda_t)[i];
    ok = v == g[t];
  }
  return ok;
}

// The report's verdict (failure, row, amount) and its exact values rounded to nearest.
CertificateReport finished(CertificateReport rep, CertificateFailure failure, int bad_row, const Rational& amount) {
  rep.failure = failure;
  rep.pass = failure == CertificateFailure::none;
  rep.row = bad_row;
  rep.amount = to_double_nearest(amount);
  for (int t = 0; t < 6; ++t) rep.ac_rounded[t] = to_double_nearest(rep.ac_exact[t]);
  rep.lambda_rounded.resize(rep.lambda_exact.size());
  for (size_t k = 0; k < rep.lambda_exact.size(); ++k) rep.lambda_rounded[k] = to_double_nearest(rep.lambda_exact[k]);
  return rep;
}

}  // namespace

// The certificate in four steps: a basis B of W, the KKT point of B, primal
// feasibility of every row, then dual feasibility (lambda_B >= 0, or
// nonnegative multipliers over the tight rows).
CertificateReport check_certificate(const ProjectionProblem& problem, const std::vector<int>& active_set) {
  const Mat6& M = problem.M;
  const Vec6& au = problem.au;
  const Eigen::MatrixXd& J = problem.J;
  const Eigen::VectorXd& b = problem.b;
  CertificateReport rep;  // failure = bad_input until the inputs are checked
  if (!internal::valid_inputs(M, au, J, b)) return rep;
  const int m = static_cast<int>(J.rows());

  // W as a list of distinct rows, in the caller's order.
  std::vector<char> in_w(m, 0);
  std::vector<int> rows;
  for (int k : active_set) {
    if (k < 0 || k >= m) return rep;
    if (!in_w[k]) {
      in_w[k] = 1;
      rows.push_back(k);
    }
  }

  // 1. A maximal independent subset B of W.
  const std::vector<int> basis = independent_rows(J, rows, &rep.num_dependent_rows);
  const int nb = static_cast<int>(basis.size());
  rep.rank = nb;

  // 2. The KKT point of B: a = au + d and lambda_B.
  const std::vector<Rational> c = exact_offsets_at_au(J, au, b);
  std::vector<mpz_class> x;
  mpz_class det;
  if (!solve_basis_kkt(internal::symmetric_part(M), J, basis, c, &x, &det)) return rep;
  const Rational det_q(det);
  Row6 a;
  for (int t = 0; t < 6; ++t) {
    a[t] = Rational(x[t]) / det_q;
    a[t] += au[t];
  }
  std::vector<Rational> lambda_b(nb);
  for (int q = 0; q < nb; ++q) lambda_b[q] = Rational(x[6 + q]) / det_q;
  rep.ac_exact.assign(a.begin(), a.end());
  rep.lambda_exact.assign(m, Rational(0));
  for (int q = 0; q < nb; ++q) rep.lambda_exact[basis[q]] = lambda_b[q];

  // 3. Primal feasibility of every row.
  std::vector<int> tight;
  Rational amount;
  if (const int worst_row = most_violated_row(J, c, x, det, &amount, &tight); worst_row >= 0)
    return finished(std::move(rep), CertificateFailure::violated_constraint, worst_row, amount);

  // 4. Dual feasibility: lambda_B >= 0 settles it.
  int neg_row = -1;
  Rational neg_value = 0;
  for (int i = 0; i < nb; ++i)
    if (lambda_b[i] < neg_value) {
      neg_value = lambda_b[i];
      neg_row = basis[i];
    }
  if (neg_row < 0) return finished(std::move(rep), CertificateFailure::none, -1, Rational(0));
  // Otherwise, with more tight rows than B, the multipliers are not unique:
  // nonnegative ones over the tight rows may exist.
  std::vector<Rational> lambda_t;
  if (static_cast<int>(tight.size()) > nb && nonnegative_tight_multipliers(J, basis, lambda_b, tight, &lambda_t)) {
    rep.used_lp = true;
    std::fill(rep.lambda_exact.begin(), rep.lambda_exact.end(), Rational(0));
    for (size_t i = 0; i < tight.size(); ++i) rep.lambda_exact[tight[i]] = lambda_t[i];
    return finished(std::move(rep), CertificateFailure::none, -1, Rational(0));
  }
  return finished(std::move(rep), CertificateFailure::negative_multiplier, neg_row, -neg_value);
}

}  // namespace gauss6::reference
