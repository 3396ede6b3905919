// Internal to gauss6_reference: small dense exact linear algebra over GMP
// rationals, shared by the exact projection and the certificate check, and the
// exact linear program behind the certificate's fallback for dependent rows.
#pragma once

#include <array>
#include <vector>

#include "gauss6/reference/quasistatics.h"

namespace gauss6::reference::internal {

using Row6 = std::array<Rational, 6>;
using Sym6 = std::array<Rational, 36>;  // row-major 6 x 6

// True when every entry of M, au, J, b is finite and the sizes agree
// (J has 6 columns; b has J.rows() entries or none).
bool valid_inputs(const Mat6& M, const Vec6& au,
                  const Eigen::Ref<const Eigen::MatrixXd>& J,
                  const Eigen::VectorXd& b);

// (M + M^T) / 2, exactly.
Sym6 symmetric_part(const Mat6& M);

// The integers 2^s v (or L v for the lcm L of the denominators of v): the
// same row, scaled by a positive factor so that every entry is an integer.
void integerize(const Rational* v, int n, mpz_class* out);

// Fraction-free (Bareiss) Gaussian elimination with row pivoting of the
// augmented integer system [A | r], A n x n, stored row-major n x (n + 1) and
// overwritten. On success y = x / det solves A y = r exactly (det != 0, x_i
// integers by Cramer's rule) and returns true; returns false when A is singular.
// If spd_block > 0, the leading spd_block x spd_block block of A is also
// checked to be positive definite (all its leading minors > 0, in order,
// without row exchanges); false is returned if it is not.
bool bareiss_solve(std::vector<mpz_class>& A, int n, int spd_block,
                   std::vector<mpz_class>& x, mpz_class& det);

// True when the symmetric matrix S is positive definite (exact).
bool positive_definite(const Sym6& S);

// Row k of J, exactly.
Row6 exact_row(const Eigen::Ref<const Eigen::MatrixXd>& J, int k);

// Exact verification of a claimed optimum of the projection, independent of
// whichever solver produced it: J ac >= b, lambda >= 0, lambda_k (J_k ac - b_k)
// = 0 for every row, and sym(M) (ac - au) = J^T lambda. These KKT conditions
// are sufficient for a strictly convex problem, so true means ac is the exact
// optimum. ac has size 6, lambda size m (else false); b as in project.
bool verify_optimum(const Mat6& M, const Vec6& au,
                    const Eigen::Ref<const Eigen::MatrixXd>& J,
                    const Eigen::VectorXd& b, const std::vector<Rational>& ac,
                    const std::vector<Rational>& lambda);

// Exact verification of a Farkas certificate of infeasibility of J a >= b:
// y >= 0 (size m), J^T y = 0 and b^T y > 0 (so 0 = y^T J a >= y^T b > 0 would
// follow for any feasible a). b as in project (size 0 means 0: never
// infeasible).
bool verify_infeasibility(const Eigen::Ref<const Eigen::MatrixXd>& J,
                          const Eigen::VectorXd& b, const std::vector<Rational>& y);

// Searches lambda >= 0 (one entry per listed row) with
//   sum_i lambda_i J_{rows[i]} = g
// exactly (an exact linear program, CGAL). Returns false when none exists.
bool find_nonnegative_combination(const Eigen::Ref<const Eigen::MatrixXd>& J,
                                  const std::vector<int>& rows, const Row6& g,
                                  std::vector<Rational>& lambda);

}  // namespace gauss6::reference::internal
