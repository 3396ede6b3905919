// The exact quasi-static projection of METHOD.md sections 2-3 and its exact
// certificate check: the ground truth the optimized solver is measured against.
//
//   ac = argmin 1/2 (a - au)^T M (a - au)   subject to   J a >= b,
//   multipliers lambda >= 0:  M (ac - au) = J^T lambda,
//                             lambda_k (J_k ac - b_k) = 0 for every row k.
//
// Every input double is an exact rational, and so is every output here: no
// rounding happens anywhere before the final (round-to-nearest) conversions to
// double. M is taken as its exact symmetric part (M + M^T) / 2, the only part
// the objective sees, so an M that is symmetric only up to rounding is fine;
// that symmetric part must be positive definite.
//
// Frames and units are those of the caller: a, au in the world frame (linear
// then angular acceleration), rows J_k = [n_k^T, (G I_k x n_k)^T], b in the
// units of J a. This code shares only data types with optimized/; it does not
// call the optimized solver, so a shared bug cannot pass as agreement.
#pragma once

#include <gmpxx.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gauss6/geometry/pose.h"

namespace gauss6::reference {

// An exact rational number (GMP).
using Rational = mpq_class;

// ---------------------------------------------------------------------------
// Exact projection (CGAL's exact quadratic program solver).

// Every optimal or infeasible answer is verified in exact rational arithmetic
// after the solve, independently of the solver's own claim: optimal means the
// returned (ac, lambda) satisfy J ac >= b, lambda >= 0, complementarity and
// sym(M) (ac - au) = J^T lambda exactly (sufficient for this strictly convex
// problem); infeasible means a Farkas certificate y >= 0 with J^T y = 0 and
// b^T y > 0 was checked exactly.
// The names mirror the optimized projection's (gauss6/contact/quasistatics.h) where the
// meaning is the same; kSolverFailure has no optimized counterpart, and the
// exact solver has no iteration cap.
enum class ProjectionStatus {
  kOptimal,            // ac, lambda hold the exact optimum and multipliers (verified)
  kInfeasibleOffsets,  // no a satisfies J a >= b (possible only when b != 0; verified)
  kSolverFailure,      // the solver's answer did not pass the exact verification
                       // (or it claimed "unbounded", impossible for sym(M) > 0);
                       // ac, lambda are empty. Never seen on the test families.
  kBadInput,           // non-finite entry, wrong sizes, or sym(M) not positive definite
};

// One projection's data, the fields of the optimized ProjectionProblem held by
// value (no cap on the number of rows m = J.rows()).
//   M   6 x 6, symmetric part positive definite.
//   au  6, unconstrained acceleration.
//   J   m x 6 (m >= 0), one contact per row.
//   b   size m, or size 0 for b = 0 (no offsets).
struct ProjectionProblem {
  Mat6 M = Mat6::Identity();
  Vec6 au = Vec6::Zero();
  Eigen::MatrixXd J = Eigen::MatrixXd(0, 6);
  Eigen::VectorXd b;
};

struct ProjectionResult {
  ProjectionStatus status = ProjectionStatus::kBadInput;
  std::vector<Rational> ac;      // size 6 when optimal, else empty
  std::vector<Rational> lambda;  // size m when optimal, else empty; >= 0
  Vec6 ac_double = Vec6::Zero();     // ac, each entry rounded to nearest
  std::vector<double> lambda_double; // lambda, rounded to nearest
  // Rows with J_k ac == b_k exactly, increasing. Contains every row with
  // lambda_k > 0 (and also the weakly active rows, lambda_k == 0); unlike the
  // optimized working set, not limited to independent rows.
  std::vector<int> active_set;
};

// Solves the projection exactly.
//
// The optimum is that of the problem exactly as given in doubles. Where rows are
// nearly dependent (a body jammed between opposite faces, coplanar contacts),
// rounding J to doubles can shrink the exact feasible cone to a lower dimension
// than the intended geometry has; the exact optimum then has huge multipliers
// (1e12 and more) and can differ by O(|au|) from a floating-point solver's
// answer, which violates some row exactly by about 1e-20. Both are right: such
// an instance is ill-conditioned (test "[refqp-illposed]").
// Two exact paths, the same answer: first a floating-point guess of the active
// set (Hildreth's row-action method, not the optimized solver's algorithm),
// kept when its exact KKT point passes the exact certificate (check_certificate
// below: then it is the exact optimum); otherwise CGAL's exact QP solver
// (project_by_qp_solver), whose pivoting can take minutes on degenerate sets of
// 50 rows (a seeded m50 instance: unfinished after 4 minutes of CPU; this
// path, 6 ms).
// Test "[refqp-paths]": both paths agree exactly.
// Not real-time: allocates; about 0.4 ms CPU for m = 3, 1.3 ms for m = 12,
// 5 ms for m = 50 (test "[refqp-timing]", random contacts), the exact
// verification included (about a sixth of it).
ProjectionResult project(const ProjectionProblem& problem);
// CGAL's exact QP solver alone (the fallback of project()).
ProjectionResult project_by_qp_solver(const ProjectionProblem& problem);

// ---------------------------------------------------------------------------
// Exact certificate check of a claimed active set.
//
// Given the rows W that a floating-point solver reports active, solves the
// reduced KKT system exactly in rationals,
//   [ M    -J_W^T ] [ a        ]   [ M au ]
//   [ J_W   0     ] [ lambda_W ] = [ b_W  ],
// and verifies exactly that lambda_W >= 0 and J a >= b for every row. When it
// passes, a is the exact optimum of the projection (the KKT conditions of a
// strictly convex problem are sufficient), whatever solver produced W.
//
// Rows of W that depend linearly on earlier rows of W (duplicated contacts,
// four coplanar corners) are dropped from the solve; a is unique anyway. If the
// multipliers of the remaining rows are not all >= 0, a non-negative
// combination over every row that is exactly tight at a (of W or not: the KKT
// conditions allow a multiplier on any row tight at the optimum, and a body
// jammed with b = 0 has every row tight at a = 0, whatever W a solver kept) is
// searched with an exact linear program, since multipliers are not unique
// then. A dependent row of W that turns out not tight at a simply gets lambda 0. The check
// never passes a wrong answer: every condition it reports as met was verified
// in exact arithmetic on the returned (ac_exact, lambda_exact).

enum class CertificateFailure {
  none,                 // passed
  bad_input,            // non-finite entry, wrong sizes, row index out of range,
                        // or sym(M) not positive definite
  negative_multiplier,  // no lambda_W >= 0 exists for this active set
  violated_constraint,  // the KKT point of W violates some row: J_k a < b_k
};

struct CertificateReport {
  bool pass = false;
  CertificateFailure failure = CertificateFailure::bad_input;
  // The offending row (index into J, 0..m-1), -1 when none: the most violated
  // row, or the row with the most negative multiplier.
  int row = -1;
  // By how much, rounded to nearest: b_k - J_k a > 0 for violated_constraint,
  // -lambda_k > 0 for negative_multiplier, 0 otherwise.
  double amount = 0;
  int rank = 0;                // rank of J_W
  int num_dependent_rows = 0;  // rows of W dropped as dependent on earlier rows
  bool used_lp = false;        // multipliers came from the exact LP fallback
  // The KKT point of W (the exact optimum when pass), size 6; the multipliers,
  // size m, zero outside W. Empty on bad_input.
  std::vector<Rational> ac_exact;
  std::vector<Rational> lambda_exact;
  Vec6 ac_rounded = Vec6::Zero();      // ac_exact rounded to nearest
  std::vector<double> lambda_rounded;  // lambda_exact rounded to nearest
};

//   problem     as in project.
//   active_set  row indices into J (any order; repeated indices count once).
// Allocates; about 0.14 ms CPU for m = 3, 0.35 ms for m = 12, 1.2 ms for
// m = 50 (test "[refqp-timing]"), three to four times cheaper than project.
CertificateReport check_certificate(const ProjectionProblem& problem, const std::vector<int>& active_set);

// ---------------------------------------------------------------------------
// Exact helpers, for comparing a floating-point answer with an exact one.

// The double nearest to q (ties to even). Magnitudes below the smallest normal
// double (2^-1022) may be off by one subnormal unit.
double to_double_nearest(const Rational& q);

// max_i |exact_i - approx_i|, computed exactly, then rounded to nearest.
// exact has size 6.
double max_abs_difference(const std::vector<Rational>& exact, const Vec6& approx);

// The exact value as a string "p/q" (or "p"), e.g. for Python's Fraction.
std::vector<std::string> to_strings(const std::vector<Rational>& values);

}  // namespace gauss6::reference
