// The quasi-static projection (METHOD.md sections 2-3): Goldfarb-Idnani dual
// active-set method in Cholesky coordinates y = L^T a, where the objective is
// 1/2 |y - y_u|^2 and row k reads A_k y >= b_k, A = J L^-T. See quasistatics.h.
//
// Invariants between steps (q = num_active, W = active rows, in entry order):
//   A_W^T = Q(:, 0:q) R(0:q, 0:q), Q orthogonal, R upper triangular;
//   y = y_u + A_W^T lambda_W with lambda_W >= 0 and A_W y = b_W, i.e. y is the
//   projection of y_u on the affine set of W and dual feasible. Adding the most
//   violated row strictly increases the dual objective, so no working set
//   repeats (no cycling); ties are broken by the smallest row index.
//
// Tolerances (ProjectionSettings; eps = 2.2e-16; relative to a row's scale
// |A_k| |y| + |b_k|):
// - feasibility_tol = 1e-13 (~450 eps). A computed slack A_k y - b_k carries a
//   rounding of about a dozen eps (a 6-term product; for a row of W, the
//   triangular solve; Q's loss of orthogonality, kept near 40 eps by
//   rebuilding, see kMaxRotationsBeforeRebuild), so rows of W and their exact
//   copies do not count as violated, while every other row left out is met to
//   1e-13: the answer is the exact optimum for a b changed by that much (a
//   backward error), apart from skipped dependent rows (below). It must be
//   this small: a row nearly parallel to an active one (sine theta) accepted
//   with violation v moves the answer by about v / theta.
// - dependence_tol = 1e-13: the floor of the dependence test. The computed
//   sine of a row's angle to span(W) has a rounding of about eps cond(R) (Q's
//   span is that far from the span of W's rows), so a row counts as dependent
//   below max(dependence_tol, 64 eps cond(R)) (dependence_threshold), with
//   cond(R) estimated by max |A_i| / |R_ii|: rows nearly parallel to a
//   well-conditioned W (a copy perturbed by 1e-10, a body jammed between
//   nearly opposite planes) join W and are resolved, instead of being skipped
//   with a violation of up to their sine. A row that this test calls
//   dependent only because of the rounding term is measured again on the rows
//   themselves (independent_on_rows, good to the rows' own rounding) and judged against
//   dependence_tol: an ill-conditioned W (such a pair in it, cond(R) ~ 1e10)
//   would otherwise skip rows at sines up to 1e-4. A violated dependent
//   row n = A_W^T r + z is handled as in Goldfarb-Idnani: when some r_j > 0,
//   the multipliers move by -t r, t = min lambda_j / r_j over r_j > 0, and
//   that row j leaves W (n then usually joins); when r <= 0, its slack on W's
//   face is r^T b_W - b_p + z^T y: the offsets are inconsistent when
//   b_p - r^T b_W exceeds the feasibility tolerance, else the row (violated by
//   at most that threshold times |A_k| |y| plus rounding) is skipped until a
//   partial step changes the face. Always so for b = 0, whose feasible set is
//   never empty. Components of r at rounding level count as zero: exchanges
//   on noise could cycle (seen on rows perturbed by 1e-10 until the iteration
//   cap). Each is measured as the length r_i |A_i| of its row's part of n,
//   against kRoundoff cond(R) max_j |r_j| |A_j|: r_i itself is in units of
//   1 / |A_i|, so comparing the bare r_i of rows of different norms made the
//   answer depend on how the rows were scaled (rows whose norms span 16 orders
//   of magnitude were answered "optimal" up to 97% off).
// - Refinement: with rows at a sine s of each other in W, the final solve has
//   an error of about eps / s (1e-6 for s = 1e-10). When cond(R) > 1e3 the
//   final KKT point gets two passes of iterative refinement with residuals in
//   twice the working precision on the given M, J, b (refine_kkt_point): the
//   answer is then the KKT point of W to about eps.
//
// Multipliers at a degenerate vertex: a body jammed between nearly opposite
// rows (ac = 0, more than 6 rows tight) needs multipliers 1e7..1e10 times the
// force. The incremental multipliers then carry an error of about eps cond(R)
// |lambda_W| (0.2 for |lambda| = 1e7, cond(R) = 1e8), so a small one can look
// >= 0 on a working set whose exact multipliers have a negative entry; ac, the
// vertex, is right all the same (seen on 59 chunks of the million-instance
// campaign's redundant family: -0.24 against |M au| = 0.0024, which the final
// solve and refinement report exactly). When a final multiplier is negative
// beyond rounding (has_negative_multiplier), nonnegative ones are sought over
// the rows tight at ac with ac kept (recover_multipliers: a nonnegative least
// squares problem, Lawson-Hanson, in y-space, on the working set's factors,
// residuals in twice the working precision); they replace the working set's
// when their residual is no larger or at rounding, else the working set stays
// and dual_infeasibility reports it. Rare path, at most kMaxRecoverySteps
// additions and drops, no allocation.
#include "gauss6/contact/quasistatics.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace gauss6 {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// M must be symmetric to this relative tolerance (of its largest entry): mass
// properties computed in double are symmetric to a few ulps.
constexpr double kSymmetryTol = 1e-9;
// Smallest accepted Cholesky pivot L_ii^2 relative to max_i M_ii: M with
// cond(M) beyond ~1e14 is treated as not positive definite.
constexpr double kMinPivotRatio = 1e-14;
// Relative size of rounding noise in a multiplier's correction (a few dozen ulps).
constexpr double kRoundoff = 64 * std::numeric_limits<double>::epsilon();
// Rebuild Q and R from the working set's rows after this many rotations:
// Q's loss of orthogonality grows like sqrt(rotations) eps (measured: below
// 1e-14 over long warm runs) and adds to the rounding of every slack, so it
// must stay well below feasibility_tol.
constexpr long kMaxRotationsBeforeRebuild = 1000;
// in_active[k] of a row that is dependent on the working set and consistent
// with it to rounding (see the main loop): not a candidate until the next drop.
constexpr unsigned char kSkipped = 2;
// The final KKT point is refined (refine_kkt_point) when the working set's
// condition estimate exceeds this: below it, eps cond(R) is already under
// 1e-12 and the plain solve is as accurate as the refinement.
constexpr double kRefinementCondition = 1e3;
constexpr int kRefinementPasses = 2;
// Rounding of a computed sine per unit of cond(R) (see dependence_threshold).
constexpr double kSineRounding = 64 * std::numeric_limits<double>::epsilon();
// The problem's lengths in y-space (|au|_M, each row's |J_k|_{M^-1}, each
// offset's distance |b_k| / |J_k|_{M^-1}) must be 0 or in [kMinLength,
// kMaxLength], else the input is refused (kBadInput): then every product of two
// of them, their squares and these times the tolerances (1e-13) and eps stay
// between 1e-230 and 1e200, clear of overflow and of subnormal numbers (below
// 2.2e-308), so no test of the method loses its meaning (a norm |au|_M whose
// square overflows made every row look met). Units and row scales move the
// lengths by factors, not the answer: any sensible choice lies deep inside.
// |au|_M and the offsets' distances are first scaled up together by 2^e when
// one of them is under kMinLength (scale_exponent): the answer is homogeneous
// in (au, b), and a god-object settling on a resting handle takes |au|_M
// through every magnitude on its way to 0.
constexpr double kMaxLength = 1e100;
constexpr double kMinLength = 1e-100;
static_assert(kMaxLength == 1e100 && kMinLength == 1e-100, "the refusals' messages state them");
// Cap on the additions and drops of recover_multipliers (each O(6 m) flops):
// the least-squares active-set method needs about one per row of its answer.
constexpr int kMaxRecoverySteps = 8 * kMaxActive;

bool all_finite(const double* p, int n) noexcept {
  double acc = 0;
  for (int i = 0; i < n; ++i) acc += p[i] * 0.0;  // NaN iff some p[i] is not finite
  return acc == 0;
}

// Validates M and J and refreshes the cached L, A, row norms when either
// changed (bytewise). Returns nullptr, or what is wrong (M not finite,
// symmetric or SPD; J not finite or a row's norm |A_k| out of range).
const char* update_cache(const ProjectionProblem& pb, ProjectionWorkspace& ws) noexcept {
  const Mat6& M = *pb.M;
  const int m = pb.num_rows;
  const bool same_M = ws.has_M && std::memcmp(M.data(), ws.M.data(), sizeof(double) * 36) == 0;
  const bool same_J = same_M && ws.num_rows == m &&
                      (m == 0 || std::memcmp(pb.J, ws.J.data(), sizeof(double) * 6 * m) == 0);
  if (same_J) return nullptr;

  ws.factor_matches_cache = false;
  if (!same_M) {
    ws.has_M = false;
    ws.num_rows = -1;
    if (!all_finite(M.data(), 36)) return "M: an entry is not finite";
    const double max_entry = M.cwiseAbs().maxCoeff();
    if ((M - M.transpose()).cwiseAbs().maxCoeff() > kSymmetryTol * max_entry) return "M: not symmetric";
    Eigen::LLT<Mat6> llt(M);
    if (llt.info() != Eigen::Success) return "M: not positive definite";
    const Mat6 L = llt.matrixL();
    const double max_diag = M.diagonal().maxCoeff();
    for (int i = 0; i < 6; ++i)
      if (!(L(i, i) * L(i, i) > kMinPivotRatio * max_diag))
        return "M: not positive definite (condition number beyond 1e14)";
    ws.M = M;
    ws.L = L;
    // L^-1, lower triangular, column by column (forward substitution on e_j).
    ws.L_inv.setZero();
    for (int j = 0; j < 6; ++j) {
      ws.L_inv(j, j) = 1.0 / L(j, j);
      for (int i = j + 1; i < 6; ++i) {
        double v = 0;
        for (int k = j; k < i; ++k) v -= L(i, k) * ws.L_inv(k, j);
        ws.L_inv(i, j) = v / L(i, i);
      }
    }
    ws.has_M = true;
  }
  ws.num_rows = -1;  // until every row is checked
  if (m > 0 && !all_finite(pb.J, 6 * m)) return "J: an entry is not finite";
  // A_k^T = L^-1 J_k^T (a product with the cached inverse: no dependency chain).
  for (int k = 0; k < m; ++k) {
    Eigen::Map<Vec6> Ak(ws.A.data() + 6 * k);
    Ak.noalias() = ws.L_inv * Eigen::Map<const Vec6>(pb.J + 6 * k);  // dense 6x6: fastest here
    const double norm2 = Ak.squaredNorm();
    const bool zero_row = Eigen::Map<const Vec6>(pb.J + 6 * k).isZero(0);
    if (!zero_row && !(norm2 >= kMinLength * kMinLength && norm2 <= kMaxLength * kMaxLength))
      return "J: a row's norm |J_k|_{M^-1} is outside [1e-100, 1e100] (neither 0)";
    ws.row_norm[k] = std::sqrt(norm2);
    ws.inv_row_norm[k] = norm2 > 0 ? 1.0 / ws.row_norm[k] : 1.0;
    for (int j = 0; j < 6; ++j) ws.A_t[static_cast<size_t>(ws.capacity) * j + k] = Ak[j];
  }
  if (m > 0) std::memcpy(ws.J.data(), pb.J, sizeof(double) * 6 * m);
  ws.num_rows = m;
  return nullptr;
}

// The m x 6 matrix A stored column by column with stride ws.capacity.
using ColumnsOfA = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6>, 0, Eigen::OuterStride<>>;

inline Eigen::Map<const Vec6> row(const ProjectionWorkspace& ws, int k) noexcept {
  return Eigen::Map<const Vec6>(ws.A.data() + 6 * k);
}

// |d(q:6)|^2: the part of a row orthogonal to the q working-set rows.
inline double tail_squared_norm(const Vec6& d, int q) noexcept {
  double sum = 0;
  for (int i = q; i < 6; ++i) sum += d[i] * d[i];
  return sum;
}

// Rotates columns i, j of Q by (c, s): Q_i <- c Q_i + s Q_j, Q_j <- c Q_j - s Q_i.
inline void rotate_Q(Mat6& Q, int i, int j, double c, double s) noexcept {
  for (int r = 0; r < 6; ++r) {
    const double u = Q(r, i), v = Q(r, j);
    Q(r, i) = c * u + s * v;
    Q(r, j) = c * v - s * u;
  }
}

// Appends the row whose d = Q^T A_p is given (|d(q:6)| > 0) to the factors.
void factor_add(ProjectionWorkspace& ws, Vec6 d, int p) noexcept {
  const int q = ws.num_active;
  // Rotate d(q+1:6) into d(q), bottom up, carrying Q along.
  for (int i = 5; i > q; --i) {
    if (d[i] == 0) continue;
    const double h = std::hypot(d[i - 1], d[i]);
    const double c = d[i - 1] / h, s = d[i] / h;
    d[i - 1] = h;
    d[i] = 0;
    rotate_Q(ws.Q, i - 1, i, c, s);
    ++ws.rotations_since_rebuild;
  }
  for (int i = 0; i <= q; ++i) ws.R(i, q) = d[i];
  ws.active[q] = p;
  ws.in_active[p] = 1;
  ws.num_active = q + 1;
}

// Removes the working-set entry at position pos and restores R's triangle.
void factor_drop(ProjectionWorkspace& ws, int pos) noexcept {
  const int q = ws.num_active;
  ws.in_active[ws.active[pos]] = 0;
  for (int c = pos; c + 1 < q; ++c) {
    ws.R.col(c) = ws.R.col(c + 1);
    ws.active[c] = ws.active[c + 1];
    ws.lambda_active[c] = ws.lambda_active[c + 1];
  }
  // R(0:q, 0:q-1) is now upper Hessenberg from column pos: zero R(k+1, k).
  for (int k = pos; k + 1 < q; ++k) {
    const double x = ws.R(k, k), y = ws.R(k + 1, k);
    if (y == 0) continue;
    const double h = std::hypot(x, y);
    const double c = x / h, s = y / h;
    for (int j = k; j + 1 < q; ++j) {
      const double u = ws.R(k, j), v = ws.R(k + 1, j);
      ws.R(k, j) = c * u + s * v;
      ws.R(k + 1, j) = c * v - s * u;
    }
    ws.R(k + 1, k) = 0;
    rotate_Q(ws.Q, k, k + 1, c, s);
    ++ws.rotations_since_rebuild;
  }
  ws.R.col(q - 1).setZero();
  ws.num_active = q - 1;
}

// The largest |A_i| / |R_ii| over the working set: 1 / the smallest sine of a
// row's angle to the span of the rows before it, an estimate of cond(R) (>= 1).
double working_set_condition(const ProjectionWorkspace& ws) noexcept {
  double cond = 1;
  for (int i = 0; i < ws.num_active; ++i)
    cond = std::max(cond, ws.row_norm[ws.active[i]] / std::abs(ws.R(i, i)));
  return cond;
}

// The sine below which a row counts as dependent on the working set: the
// setting, or the rounding of the computed sine when that is larger. The sine
// comes from Q, whose span is off from that of W's rows by about eps cond(R).
inline double dependence_threshold(const ProjectionWorkspace& ws, double dependence_tol) noexcept {
  return std::max(dependence_tol, kSineRounding * working_set_condition(ws));
}

// Adds each row of ws.active[0:count) to empty factors when it is independent of
// those already added (rows >= m are dropped).
void rebuild_factors(ProjectionWorkspace& ws, int count, int m, double dependence_tol) noexcept {
  std::array<int, kMaxActive> rows = ws.active;
  ws.Q.setIdentity();
  ws.R.setZero();
  ws.num_active = 0;
  ws.rotations_since_rebuild = 0;
  for (int i = 0; i < count; ++i) {
    const int p = rows[i];
    if (p < 0 || p >= m || ws.in_active[p]) continue;
    const Vec6 d = ws.Q.transpose() * row(ws, p);
    if (std::sqrt(tail_squared_norm(d, ws.num_active)) > dependence_threshold(ws, dependence_tol) * ws.row_norm[p])
      factor_add(ws, d, p);
  }
}

// The projection of y_u on the affine set {A_W y = b_W} and its multipliers:
// c = R^-T b_W - Q1^T y_u, lambda_W = R^-1 c, y = y_u + Q1 c.
void solve_working_set(ProjectionWorkspace& ws, const Vec6& yu, const double* b, Vec6* y) noexcept {
  const int q = ws.num_active;
  std::array<double, kMaxActive> c{};
  for (int i = 0; i < q; ++i) {
    double w = b ? b[ws.active[i]] : 0.0;
    for (int j = 0; j < i; ++j) w -= ws.R(j, i) * c[j];
    c[i] = w / ws.R(i, i);
  }
  *y = yu;
  for (int i = 0; i < q; ++i) {
    const double ci = c[i] - ws.Q.col(i).dot(yu);
    *y += ci * ws.Q.col(i);
    c[i] = ci;
  }
  for (int i = q - 1; i >= 0; --i) {
    double v = c[i];
    for (int j = i + 1; j < q; ++j) v -= ws.R(i, j) * ws.lambda_active[j];
    ws.lambda_active[i] = v / ws.R(i, i);
  }
}

// Solves the working set and drops its most negative multiplier until none is
// (y is then the projection on W's face and dual feasible); returns the number
// of drops. A multiplier whose correction lambda_i |A_i| is rounding noise
// (< kRoundoff of the row's scale) counts as zero and is dropped too, so that a
// warm start never leaves a spurious active row (J au >= b => ac = au).
int drop_until_dual_feasible(ProjectionWorkspace& ws, const Vec6& yu, double yu_norm, const double* b,
                             Vec6* y) noexcept {
  for (int drops = 0;; ++drops) {
    solve_working_set(ws, yu, b, y);
    const double y_scale = std::max(y->norm(), yu_norm);
    int worst = -1;
    double worst_value = 0;
    for (int i = 0; i < ws.num_active; ++i) {
      const int k = ws.active[i];
      const double value = ws.lambda_active[i] * ws.row_norm[k];  // length of its correction
      const double noise = kRoundoff * (y_scale + (b ? std::abs(b[k]) * ws.inv_row_norm[k] : 0.0));
      if (value <= noise && (worst < 0 || value < worst_value ||
                             (value == worst_value && k < ws.active[worst]))) {
        worst = i;
        worst_value = value;
      }
    }
    if (worst < 0) return drops;
    factor_drop(ws, worst);
  }
}

// Error-free transformations (Ogita, Rump, Oishi, "Accurate sum and dot
// product", SIAM J. Sci. Comput. 26(6), 2005): Dot2 accumulates a dot product
// as if in twice the working precision, then rounds once.
struct CompensatedSum {
  double sum = 0, error = 0;
  // sum + error += x y (the product exactly, by fma; the sum by TwoSum).
  void add_product(double x, double y) noexcept {
    const double p = x * y;
    const double p_err = std::fma(x, y, -p);
    const double s = sum + p;
    const double z = s - sum;
    error += ((sum - (s - z)) + (p - z)) + p_err;
    sum = s;
  }
  double value() const noexcept { return sum + error; }
};

// Iterative refinement of the working set's KKT point in a-space, on the data
// as given (not the rounded A = J L^-T):
//   M (ac - au) = J_W^T lambda_W,   J_W ac = b_W.
// The residuals are computed in twice the working precision (CompensatedSum) and
// the correction solved with the current factors (as solve_working_set):
//   h = L^-1 g, c = R^-T r - Q1^T h, dlambda = R^-1 c, dy = h + Q1 c, da = L^-T dy,
// with g = J_W^T lambda_W - M (ac - au), r = b_W - J_W ac. Each pass shrinks the
// error by about eps cond(R), so a working set with rows at a sine s of each
// other gets ac to about eps |au| instead of eps / s |au|.
void refine_kkt_point(const ProjectionProblem& pb, ProjectionWorkspace& ws, Vec6* ac) noexcept {
  const int q = ws.num_active;
  const Mat6& M = *pb.M;
  for (int pass = 0; pass < kRefinementPasses; ++pass) {
    Vec6 g;
    for (int i = 0; i < 6; ++i) {
      CompensatedSum acc;
      for (int j = 0; j < 6; ++j) {
        acc.add_product(-M(i, j), (*ac)[j]);
        acc.add_product(M(i, j), pb.au[j]);
      }
      for (int t = 0; t < q; ++t) acc.add_product(pb.J[6 * ws.active[t] + i], ws.lambda_active[t]);
      g[i] = acc.value();
    }
    const Vec6 h = ws.L_inv * g;
    std::array<double, kMaxActive> c{};
    for (int i = 0; i < q; ++i) {
      const int k = ws.active[i];
      CompensatedSum acc;
      acc.add_product(pb.b ? pb.b[k] : 0.0, 1.0);
      for (int j = 0; j < 6; ++j) acc.add_product(-pb.J[6 * k + j], (*ac)[j]);
      double w = acc.value();
      for (int j = 0; j < i; ++j) w -= ws.R(j, i) * c[j];
      c[i] = w / ws.R(i, i);
    }
    Vec6 dy = h;
    for (int i = 0; i < q; ++i) {
      c[i] -= ws.Q.col(i).dot(h);
      dy += c[i] * ws.Q.col(i);
    }
    // dlambda = R^-1 c (back substitution, into c).
    for (int i = q - 1; i >= 0; --i) {
      double v = c[i];
      for (int j = i + 1; j < q; ++j) v -= ws.R(i, j) * c[j];
      c[i] = v / ws.R(i, i);
    }
    for (int i = 0; i < q; ++i) ws.lambda_active[i] += c[i];
    ac->noalias() += ws.L_inv.transpose() * dy;
  }
}

// Whether row p is independent of W's rows, measured on the rows: the
// residual z = A_p - A_W^T r of its least-squares fit on W's rows, with r from
// the factors and corrected twice (r += R^-1 Q1^T z), z summed in twice the
// working precision (CompensatedSum) on the rows themselves. The sine read off
// Q (|d(q:6)| / |A_p|) is only as good as Q's span, about eps cond(R) off from
// that of W's rows; this residual is good to the rounding of the rows A = J L^-T
// themselves, kRoundoff (|A_p| + sum |r_i| |A_i|) (rows that J holds exactly
// dependent, four coplanar corners, are that far from dependent in A). So p is
// independent when |z| exceeds both that and dependence_tol |A_p|: a row at a
// sine of 1e-10 to an ill-conditioned W is told from one that W spans (a row
// skipped as dependent on Q's sine was left violated by up to 4% of its scale).
bool independent_on_rows(const ProjectionWorkspace& ws, int p, const Vec6& d, double dependence_tol) noexcept {
  const int q = ws.num_active;
  std::array<double, kMaxActive> r{}, c{};
  for (int i = 0; i < q; ++i) c[i] = d[i];
  Vec6 z = Vec6::Zero();
  for (int pass = 0; pass <= 2; ++pass) {
    for (int i = q - 1; i >= 0; --i) {  // r += R^-1 c
      double v = c[i];
      for (int j = i + 1; j < q; ++j) v -= ws.R(i, j) * c[j];
      c[i] = v / ws.R(i, i);
    }
    for (int i = 0; i < q; ++i) r[i] += c[i];
    for (int j = 0; j < 6; ++j) {
      CompensatedSum acc;
      acc.add_product(ws.A[6 * static_cast<size_t>(p) + j], 1.0);
      for (int i = 0; i < q; ++i) acc.add_product(-r[i], ws.A[6 * static_cast<size_t>(ws.active[i]) + j]);
      z[j] = acc.value();
    }
    if (pass == 2) break;
    for (int i = 0; i < q; ++i) c[i] = ws.Q.col(i).dot(z);
  }
  double rows_size = ws.row_norm[p];
  for (int i = 0; i < q; ++i) rows_size += std::abs(r[i]) * ws.row_norm[ws.active[i]];
  return z.norm() > std::max(dependence_tol * ws.row_norm[p], kRoundoff * rows_size);
}

// Whether a multiplier of the working set is negative beyond rounding: its
// correction lambda_i |A_i| below -kRoundoff of the row's scale (the measure of
// drop_until_dual_feasible).
bool has_negative_multiplier(const ProjectionWorkspace& ws, double y_scale, const double* b) noexcept {
  for (int i = 0; i < ws.num_active; ++i) {
    const int k = ws.active[i];
    const double noise = kRoundoff * (y_scale + (b ? std::abs(b[k]) * ws.inv_row_norm[k] : 0.0));
    if (ws.lambda_active[i] * ws.row_norm[k] < -noise) return true;
  }
  return false;
}

// The multipliers' residual g - A_W^T lambda (y-space), summed in twice the
// working precision (CompensatedSum): multipliers 1e10 times |g| (a body jammed
// between nearly opposite rows) would otherwise bury it in their rounding.
Vec6 multiplier_residual(const ProjectionWorkspace& ws, const Vec6& g, const double* lambda) noexcept {
  Vec6 r;
  for (int j = 0; j < 6; ++j) {
    CompensatedSum acc;
    acc.add_product(g[j], 1.0);
    for (int i = 0; i < ws.num_active; ++i) acc.add_product(-lambda[i], ws.A[6 * static_cast<size_t>(ws.active[i]) + j]);
    r[j] = acc.value();
  }
  return r;
}

// lambda += R^-1 Q1^T r: the least-squares correction on the working set's rows.
void add_least_squares_correction(const ProjectionWorkspace& ws, const Vec6& r, double* lambda) noexcept {
  const int q = ws.num_active;
  std::array<double, kMaxActive> c{};
  for (int i = 0; i < q; ++i) c[i] = ws.Q.col(i).dot(r);
  for (int i = q - 1; i >= 0; --i) {
    double v = c[i];
    for (int j = i + 1; j < q; ++j) v -= ws.R(i, j) * c[j];
    c[i] = v / ws.R(i, i);
  }
  for (int i = 0; i < q; ++i) lambda[i] += c[i];
}

// Nonnegative multipliers over the rows tight at the answer, for an answer
// whose working set's own multipliers are not all >= 0 (see "Multipliers at a
// degenerate vertex" at the top of this file). With y fixed and g = y - y_u, it
// solves min |A_T^T lambda - g| over lambda >= 0, T = the rows with
// |A_k y - b_k| within the feasibility tolerance, by the active-set method of
// Lawson and Hanson (Solving Least Squares Problems, 1974, ch. 23): the passive
// set P is the working set's factors (factor_add/factor_drop), its least-squares
// solution R^-1 Q1^T g, and a row joins P when the residual's component along
// it is above rounding. P becomes the working set and lambda_P its multipliers
// when the residual ends no larger than the working set's own (or at rounding);
// else the working set is restored. At most kMaxRecoverySteps additions and
// drops: bounded work, no allocation (the tight rows are marked in in_active).
constexpr unsigned char kNotTight = 3;
bool recover_multipliers(ProjectionWorkspace& ws, const Vec6& y, const Vec6& yu, const double* b, int m,
                         double feasibility_tol, double dependence_tol) noexcept {
  const Vec6 g = y - yu;
  const double y_scale = std::max(y.norm(), yu.norm());
  const double residual_before = multiplier_residual(ws, g, ws.lambda_active.data()).norm();
  // The working set as it is, restored when the search does not do better.
  const Mat6 Q0 = ws.Q, R0 = ws.R;
  const std::array<int, kMaxActive> active0 = ws.active;
  const std::array<double, kMaxActive> lambda0 = ws.lambda_active;
  const int q0 = ws.num_active;
  const long rotations0 = ws.rotations_since_rebuild;

  for (int k = 0; k < m; ++k) {
    const double bk = b ? b[k] : 0.0;
    const double s = row(ws, k).dot(y) - bk;
    ws.in_active[k] = std::abs(s) <= feasibility_tol * (ws.row_norm[k] * y_scale + std::abs(bk)) ? 0 : kNotTight;
  }
  ws.Q.setIdentity();
  ws.R.setZero();
  ws.num_active = 0;
  ws.rotations_since_rebuild = 0;

  for (int steps = 0; steps < kMaxRecoverySteps;) {
    // The tight row outside P along which the residual points most (per unit
    // of |A_k|), above its rounding.
    const Vec6 residual = multiplier_residual(ws, g, ws.lambda_active.data());
    int p = -1;
    double best = kRoundoff * residual.norm();
    for (int k = 0; k < m; ++k) {
      if (ws.in_active[k] != 0) continue;
      const double w = row(ws, k).dot(residual) * ws.inv_row_norm[k];
      if (w > best) {
        best = w;
        p = k;
      }
    }
    if (p < 0) break;
    const int q = ws.num_active;
    const Vec6 d = ws.Q.transpose() * row(ws, p);
    // Dependence on P as in the main loop: below the rounding of Q's span, the
    // sine is measured on the rows.
    const double sine_norm = std::sqrt(tail_squared_norm(d, q));
    bool dependent = q == kMaxActive || sine_norm <= dependence_threshold(ws, dependence_tol) * ws.row_norm[p];
    if (dependent && q < kMaxActive && sine_norm > dependence_tol * ws.row_norm[p])
      dependent = !independent_on_rows(ws, p, d, dependence_tol);
    if (dependent) {
      ws.in_active[p] = kSkipped;  // spanned by P: examined again after a drop
      continue;
    }
    ++steps;
    factor_add(ws, d, p);
    ws.lambda_active[q] = 0;
    // Least-squares solution on P; while some entry is not positive, move
    // from lambda towards it until an entry reaches zero and drop that row.
    while (steps < kMaxRecoverySteps) {
      const int n = ws.num_active;
      // Least squares on P, refined on compensated residuals as refine_kkt_point.
      std::array<double, kMaxActive> z{};
      add_least_squares_correction(ws, g, z.data());
      for (int pass = 0; pass < kRefinementPasses; ++pass)
        add_least_squares_correction(ws, multiplier_residual(ws, g, z.data()), z.data());
      double alpha = 1;
      int block = -1;
      for (int i = 0; i < n; ++i) {
        if (z[i] > 0) continue;
        const double ratio = ws.lambda_active[i] / (ws.lambda_active[i] - z[i]);
        if (block < 0 || ratio < alpha) {
          alpha = ratio;
          block = i;
        }
      }
      if (block < 0) {
        for (int i = 0; i < n; ++i) ws.lambda_active[i] = z[i];
        break;
      }
      ++steps;
      for (int i = 0; i < n; ++i)
        ws.lambda_active[i] = std::max(0.0, ws.lambda_active[i] + alpha * (z[i] - ws.lambda_active[i]));
      // The row that just joined cannot carry a positive multiplier (rounding
      // of its gradient): leave it out until P changes.
      const bool was_new = ws.active[block] == p && ws.lambda_active[block] <= 0;
      ws.lambda_active[block] = 0;
      factor_drop(ws, block);
      for (int k = 0; k < m; ++k)
        if (ws.in_active[k] == kSkipped) ws.in_active[k] = 0;
      if (was_new) ws.in_active[p] = kSkipped;
    }
  }
  // Every iterate is >= 0; it is kept when its residual is no larger than the
  // working set's or at the rounding of its own multipliers (ulp(lambda_i) |A_i|
  // is the floor for multipliers 1e10 times |g|).
  const Vec6 residual = multiplier_residual(ws, g, ws.lambda_active.data());
  double rounding = g.norm();
  for (int i = 0; i < ws.num_active; ++i) rounding += ws.lambda_active[i] * ws.row_norm[ws.active[i]];
  if (residual.norm() <= std::max(residual_before, kRoundoff * rounding)) return true;
  ws.Q = Q0;
  ws.R = R0;
  ws.active = active0;
  ws.lambda_active = lambda0;
  ws.num_active = q0;
  ws.rotations_since_rebuild = rotations0;
  return false;
}

bool valid_settings(const ProjectionSettings& s) noexcept {
  return std::isfinite(s.dependence_tol) && s.dependence_tol >= 0 && s.dependence_tol < 1 &&
         std::isfinite(s.feasibility_tol) && s.feasibility_tol >= 0 && s.max_iterations >= 0 &&
         s.certificate_tol > 0 && s.certificate_tol < 1;
}

// A result that makes no force: ac = au (or 0 when au is not finite).
ProjectionStatus zero_force_result(const ProjectionProblem& pb, ProjectionStatus status,
                                   int iterations, ProjectionResult* res) noexcept {
  res->problem = nullptr;
  res->ac = all_finite(pb.au.data(), 6) ? pb.au : Vec6::Zero();
  std::fill(res->lambda.begin(), res->lambda.end(), 0.0);
  res->num_active = 0;
  res->status = status;
  res->iterations = iterations;
  res->stationarity = res->primal_infeasibility = 0;
  res->dual_infeasibility = res->complementarity = 0;
  res->kkt_relative = 0;
  return status;
}

ProjectionStatus bad_input(const ProjectionProblem& pb, const char* problem, ProjectionResult* res) noexcept {
  zero_force_result(pb, ProjectionStatus::kBadInput, 0, res);
  res->problem = problem;
  return ProjectionStatus::kBadInput;
}

// What is out of range among the problem's lengths in y-space: |y_u| and each
// offset's distance |b_k| / |A_k|, neither 0, must lie in [kMinLength,
// kMaxLength]; nullptr when all do.
const char* length_problem(const Vec6& yu, const double* b, const ProjectionWorkspace& ws, int m) noexcept {
  const auto out_of_range = [](double length) {
    return length != 0 && !(length >= kMinLength && length <= kMaxLength);
  };
  // |y_u| from its largest entry first: its square may overflow or underflow.
  const double largest = yu.cwiseAbs().maxCoeff();
  if (out_of_range(largest) || (largest != 0 && out_of_range((yu / largest).norm() * largest)))
    return "au: |au|_M is outside [1e-100, 1e100] (neither 0)";
  for (int k = 0; b != nullptr && k < m; ++k)
    if (ws.row_norm[k] > 0 && out_of_range(std::abs(b[k]) / ws.row_norm[k]))
      return "b: an offset's distance |b_k| / |J_k|_{M^-1} is outside [1e-100, 1e100] (neither 0)";
  return nullptr;
}

void compute_residuals(const ProjectionProblem& pb, ProjectionResult* res) noexcept {
  const int m = pb.num_rows;
  Vec6 r = (*pb.M) * (res->ac - pb.au);
  double dual = 0, comp = 0, primal = 0;
  for (int k = 0; k < m; ++k) {
    const Eigen::Map<const Vec6> Jk(pb.J + 6 * k);
    const double lam = res->lambda[k];
    const double s = Jk.dot(res->ac) - (pb.b ? pb.b[k] : 0.0);
    if (lam != 0) {
      r -= lam * Jk;
      comp = std::max(comp, std::abs(lam * s));
      dual = std::max(dual, -lam);
    }
    primal = std::max(primal, -s);
  }
  res->stationarity = r.cwiseAbs().maxCoeff();
  res->primal_infeasibility = primal;
  res->dual_infeasibility = dual;
  res->complementarity = comp;
}

// J_k a, for row k of the problem.
inline double Jk_dot(const ProjectionProblem& pb, int k, const Vec6& a) noexcept {
  return Eigen::Map<const Vec6>(pb.J + 6 * k).dot(a);
}

// The answer's KKT conditions measured in a form that no positive scaling of a
// row, of b or of units changes (see ProjectionResult::kkt_relative). Lengths
// are in y-space (the M^-1 norm of a force, the M norm of a motion): row k's
// slack over its scale |A_k| y_scale + |b_k|; its multiplier as the length of
// its correction lambda_k |A_k|, over the sum of all the lengths the
// stationarity residual adds up (y_scale + sum |lambda_k| |A_k|: multipliers of
// a jammed body reach 1e10 times the force, and their rounding with them);
// complementarity as the smaller of the two (a row is tight or carries no
// force); the stationarity residual's M^-1 norm over that sum. |A_k| =
// |J_k|_{M^-1} is the cached row norm; y_scale = max(|ac|_M, |au|_M).
double relative_kkt(const ProjectionProblem& pb, const ProjectionWorkspace& ws, const ProjectionResult& res) noexcept {
  const int m = pb.num_rows;
  const double y_scale = std::max((ws.L.transpose() * res.ac).norm(), (ws.L.transpose() * pb.au).norm());
  Vec6 g = (*pb.M) * (res.ac - pb.au);
  double terms = y_scale;
  for (int k = 0; k < m; ++k) {
    const double lam = res.lambda[k];
    if (lam == 0) continue;
    g -= lam * Eigen::Map<const Vec6>(pb.J + 6 * k);
    terms += std::abs(lam) * ws.row_norm[k];
  }
  if (!(terms > 0)) return 0;  // au = 0 and no force: ac = 0 exactly
  double worst = (ws.L_inv * g).norm() / terms;  // |g|_{M^-1} = |L^-1 g|
  for (int k = 0; k < m; ++k) {
    const double bk = pb.b ? pb.b[k] : 0.0;
    const double scale = ws.row_norm[k] * y_scale + std::abs(bk);
    const double slack = Jk_dot(pb, k, res.ac) - bk;
    const double correction = res.lambda[k] * ws.row_norm[k] / terms;
    const double violation = scale > 0 ? slack / scale : 0.0;
    worst = std::max({worst, -violation, -correction, std::min(std::abs(correction), std::abs(violation))});
  }
  return worst;
}

}  // namespace

const char* to_string(ProjectionStatus status) noexcept {
  switch (status) {
    case ProjectionStatus::kOptimal: return "optimal";
    case ProjectionStatus::kIterationCap: return "iteration cap";
    case ProjectionStatus::kInfeasibleOffsets: return "infeasible offsets";
    case ProjectionStatus::kBadInput: return "bad input";
    case ProjectionStatus::kUncertified: return "uncertified";
  }
  return "unknown";
}

ProjectionResult::ProjectionResult(int max_rows) : lambda(static_cast<size_t>(std::max(max_rows, 0)), 0.0) {}

ProjectionWorkspace::ProjectionWorkspace(int max_rows)
    : capacity(std::max(max_rows, 0)),
      J(6 * static_cast<size_t>(capacity)),
      A(6 * static_cast<size_t>(capacity)),
      A_t(6 * static_cast<size_t>(capacity)),
      row_norm(static_cast<size_t>(capacity)),
      inv_row_norm(static_cast<size_t>(capacity)),
      slack(static_cast<size_t>(capacity)),
      scaled_b(static_cast<size_t>(capacity)),
      in_active(static_cast<size_t>(capacity)) {}

void ProjectionWorkspace::reset() noexcept {
  has_M = false;
  num_rows = -1;
  factor_matches_cache = false;
  num_active = 0;
  Q.setIdentity();
  R.setZero();
  rotations_since_rebuild = 0;
  std::fill(in_active.begin(), in_active.end(), static_cast<unsigned char>(0));
}

namespace {

// What is wrong with a call's arguments (a null pointer, a row count out of the
// buffers' range, settings out of range, an entry that is not finite); nullptr
// when nothing is.
const char* call_problem(const ProjectionProblem& pb, const ProjectionSettings& settings,
                         const ProjectionWorkspace* workspace, const ProjectionResult& res) noexcept {
  const int m = pb.num_rows;
  if (workspace == nullptr) return "workspace: null";
  if (!valid_settings(settings)) return "settings: out of range";
  if (pb.M == nullptr) return "M: null";
  if (m < 0 || m > workspace->capacity || m > res.max_rows())
    return "num_rows: negative or beyond the workspace's or the result's max_rows";
  if (m > 0 && pb.J == nullptr) return "J: null with rows";
  if (!all_finite(pb.au.data(), 6)) return "au: an entry is not finite";
  if (pb.b != nullptr && !all_finite(pb.b, m)) return "b: an entry is not finite";
  return nullptr;
}

// The starting working set: empty (cold) or the previous one, whose factors are
// reused when M and J did not change, else rebuilt from its rows.
void start_working_set(ProjectionWorkspace& ws, bool warm_start, int m, double dependence_tol) noexcept {
  std::fill_n(ws.in_active.begin(), m, static_cast<unsigned char>(0));
  if (!warm_start) {
    ws.num_active = 0;
  } else if (!ws.factor_matches_cache || ws.rotations_since_rebuild > kMaxRotationsBeforeRebuild) {
    rebuild_factors(ws, ws.num_active, m, dependence_tol);
  } else {
    for (int i = 0; i < ws.num_active; ++i) ws.in_active[ws.active[i]] = 1;
  }
  if (ws.num_active == 0) {
    ws.Q.setIdentity();
    ws.rotations_since_rebuild = 0;
  }
  ws.factor_matches_cache = true;
}

// The projection as the active-set loop sees it: the target y_u = L^T au in
// Cholesky coordinates and its norm, the offsets (nullptr: b = 0), the number
// of rows, and the settings the loop reads.
struct LoopProblem {
  const Vec6& yu;
  double yu_norm;
  const double* b;
  int m;
  double dep_tol;
  double feas_tol;
  int max_iterations;
};

// The loop's iterate: y (the projection of y_u on the working set's face, dual
// feasible), the iterations spent, and whether some row is skipped
// (in_active[k] == kSkipped).
struct LoopIterate {
  Vec6 y;
  int iterations = 0;
  bool has_skipped = false;
};

// The most violated row outside the working set: the largest distance to its
// hyperplane, smallest index on ties, among rows violated beyond the
// feasibility tolerance of their scale |A_k| y_scale + |b_k|; -1 when none is.
// Leaves the slacks A y - b in ws.slack.
int most_violated_row(ProjectionWorkspace& ws, const LoopProblem& lp, const Vec6& y, double y_scale) noexcept {
  const int m = lp.m;
  const double* b = lp.b;
  // Slacks s = A y - b: one matrix-vector product on the column-major copy
  // of A (Eigen's vectorised kernel; y is contiguous, so no temporary).
  double* slack = ws.slack.data();
  {
    Eigen::Map<Eigen::VectorXd> s_map(slack, m);
    s_map.noalias() = ColumnsOfA(ws.A_t.data(), m, 6, Eigen::OuterStride<>(ws.capacity)) * y;
    if (b) s_map -= Eigen::Map<const Eigen::VectorXd>(b, m);
  }
  int p = -1;
  double best = 0;
  for (int k = 0; k < m; ++k) {
    const double s = slack[k];
    if (ws.in_active[k] || s >= 0) continue;
    const double bk = b ? b[k] : 0.0;
    if (s < -lp.feas_tol * (ws.row_norm[k] * y_scale + std::abs(bk))) {
      const double v = -s * ws.inv_row_norm[k];
      if (v > best) {
        best = v;
        p = k;
      }
    }
  }
  return p;
}

// Row p seen from the working set W (q rows): d = Q^T A_p; z2 = |d(q:6)|^2,
// the square of its part orthogonal to W; whether it counts as dependent on W;
// r = R^-1 d(0:q), how W's rows span it (their multipliers fall as t r when p's
// grows by t); and r_noise, the rounding level of r's components.
struct RowDirection {
  int q;
  Vec6 d;
  double z2;
  bool dependent;
  std::array<double, kMaxActive> r;
  double r_noise;
};

// Row p's RowDirection from the current factors.
RowDirection direction_of_row(const ProjectionWorkspace& ws, int p, double dep_tol) noexcept {
  RowDirection dir;
  const int q = dir.q = ws.num_active;
  const Eigen::Map<const Vec6> n = row(ws, p);
  dir.d = ws.Q.transpose() * n;
  const Vec6& d = dir.d;
  dir.z2 = tail_squared_norm(d, q);
  dir.dependent = std::sqrt(dir.z2) <= dependence_threshold(ws, dep_tol) * ws.row_norm[p];
  // Below the rounding of Q's span, the sine is measured on the rows.
  if (dir.dependent && std::sqrt(dir.z2) > dep_tol * ws.row_norm[p])
    dir.dependent = !independent_on_rows(ws, p, d, dep_tol);
  // r = R^-1 d(0:q) by back substitution.
  std::array<double, kMaxActive>& r = dir.r;
  r = {};
  for (int i = q - 1; i >= 0; --i) {
    double v = d[i];
    for (int j = i + 1; j < q; ++j) v -= ws.R(i, j) * r[j];
    r[i] = v / ws.R(i, i);
  }
  // Components of r at the rounding of the solve with R (about eps cond(R)
  // of its largest, each as the length r_i |A_i|: see the top of this file)
  // have no sign: a partial step on one would exchange a row for p on
  // noise, and such exchanges can cycle.
  double r_max = 0;
  for (int i = 0; i < q; ++i) r_max = std::max(r_max, std::abs(r[i]) * ws.row_norm[ws.active[i]]);
  dir.r_noise = kRoundoff * working_set_condition(ws) * r_max;
  return dir;
}

// The ratio test: the position in W of the row whose multiplier reaches zero
// first as the multipliers fall by t r (smallest t, ties to the smallest row
// index), r's components at rounding level left out; -1 when none falls.
// *t1 is that t (infinite when none).
int blocking_row(const ProjectionWorkspace& ws, const RowDirection& dir, double* t1) noexcept {
  *t1 = kInf;
  int block = -1;
  for (int i = 0; i < dir.q; ++i) {
    if (dir.r[i] * ws.row_norm[ws.active[i]] <= dir.r_noise) continue;
    const double ratio = ws.lambda_active[i] / dir.r[i];
    if (ratio < *t1 || (ratio == *t1 && ws.active[i] < ws.active[block])) {
      *t1 = ratio;
      block = i;
    }
  }
  return block;
}

// Whether the offsets are inconsistent at row p, which no step can satisfy:
// n = A_W^T r + z, |z| <= dependence_tol |n|, with r <= 0. On W's face its
// slack is r^T b_W - b_p + z^T y, so the offsets are inconsistent when
// b_p - r^T b_W exceeds the feasibility tolerance; otherwise (always when
// b = 0) the violation is the small z^T y plus rounding of W's slacks.
bool offsets_inconsistent(const ProjectionWorkspace& ws, const LoopProblem& lp, const RowDirection& dir, int p,
                          double y_scale) noexcept {
  const double* b = lp.b;
  double gap = b ? b[p] : 0.0;
  if (b)
    for (int i = 0; i < dir.q; ++i) gap -= dir.r[i] * b[ws.active[i]];
  return gap > lp.feas_tol * (ws.row_norm[p] * y_scale + std::abs(b ? b[p] : 0.0));
}

// A step of length t towards row p: W's multipliers fall by t r (components
// at rounding level count as zero here too, as in the ratio test: moved by
// t r_i, a small multiplier would go negative) and, when p is independent of
// W, y moves along z = Q(:, q:6) d(q:6), the part of p's row orthogonal to W,
// and p's slack s_p by t |z|^2.
void take_step(ProjectionWorkspace& ws, const RowDirection& dir, double t, Vec6* y, double* s_p) noexcept {
  const int q = dir.q;
  for (int i = 0; i < q; ++i)
    if (std::abs(dir.r[i]) * ws.row_norm[ws.active[i]] > dir.r_noise) ws.lambda_active[i] -= t * dir.r[i];
  if (!dir.dependent) {
    for (int i = q; i < 6; ++i) *y += (t * dir.d[i]) * ws.Q.col(i);
    *s_p += t * dir.z2;
  }
}

// Drops the row at position pos of W (its multiplier reached zero); the face
// changed, so skipped rows are examined again.
void drop_blocking_row(ProjectionWorkspace& ws, int pos, int m, bool* has_skipped) noexcept {
  ws.lambda_active[pos] = 0;
  factor_drop(ws, pos);
  if (*has_skipped) {
    for (int k = 0; k < m; ++k)
      if (ws.in_active[k] == kSkipped) ws.in_active[k] = 0;
    *has_skipped = false;
  }
}

// Steps towards the violated row p until it is satisfied (a full step: p
// joins W) or skipped, each partial step on the way dropping the row of W
// whose multiplier reaches zero first. Returns kOptimal to go on with the
// loop, else the status that ends it (the iteration cap, inconsistent offsets).
ProjectionStatus step_to_row(ProjectionWorkspace& ws, const LoopProblem& lp, int p, double y_scale,
                             LoopIterate* it) noexcept {
  double s_p = ws.slack[p];
  double lambda_p = 0;
  for (;;) {
    if (it->iterations >= lp.max_iterations) return ProjectionStatus::kIterationCap;
    ++it->iterations;
    const RowDirection dir = direction_of_row(ws, p, lp.dep_tol);
    double t1;
    const int block = blocking_row(ws, dir, &t1);
    const double t2 = dir.dependent ? kInf : -s_p / dir.z2;
    // No row of W blocks (block < 0) and no full step (t2 infinite, or NaN
    // when rounding leaves z2 = 0 on a row not counted dependent): p cannot
    // be satisfied by a step; never a drop at block -1.
    if (block < 0 && !(t2 < kInf)) {
      if (offsets_inconsistent(ws, lp, dir, p, y_scale)) return ProjectionStatus::kInfeasibleOffsets;
      // Consistent: p is skipped until a partial step changes the face.
      ws.in_active[p] = kSkipped;
      it->has_skipped = true;
      if (lambda_p > 0) {
        // Exchange steps gave p a multiplier that W cannot carry (W is
        // ill-conditioned enough that p stayed dependent after a drop): go
        // back to the projection on W's face, made dual feasible. y did not
        // move (dependent steps change only multipliers).
        it->iterations += drop_until_dual_feasible(ws, lp.yu, lp.yu_norm, lp.b, &it->y);
      }
      return ProjectionStatus::kOptimal;
    }
    const double t = std::min(t1, t2);
    take_step(ws, dir, t, &it->y, &s_p);
    lambda_p += t;
    if (t2 <= t1) {
      ws.lambda_active[dir.q] = lambda_p;
      factor_add(ws, dir.d, p);
      return ProjectionStatus::kOptimal;
    }
    drop_blocking_row(ws, block, lp.m, &it->has_skipped);
  }
}

// The answer ac (in res) of a working set that is not empty, recomputed from
// the working set (removes the drift of the incremental updates) and back in
// a-space, L^T ac = y; refined when W is ill-conditioned, and with
// nonnegative multipliers sought when W's own are not.
void final_point(const ProjectionProblem& pb, ProjectionWorkspace& ws, const LoopProblem& lp, LoopIterate* it,
                 ProjectionResult* res) noexcept {
  if (it->iterations > 0) solve_working_set(ws, lp.yu, lp.b, &it->y);  // else y is already fresh
  res->ac.noalias() = ws.L_inv.transpose() * it->y;  // ac = L^-T y
  if (working_set_condition(ws) > kRefinementCondition) refine_kkt_point(pb, ws, &res->ac);
  // At a degenerate vertex the working set's own multipliers may be negative
  // though ac is optimal: nonnegative ones over the tight rows replace them.
  const Vec6 y_final = ws.L.transpose() * res->ac;
  if (has_negative_multiplier(ws, std::max(y_final.norm(), lp.yu_norm), lp.b))
    recover_multipliers(ws, y_final, lp.yu, lp.b, lp.m, lp.feas_tol, lp.dep_tol);
}

// The rest of the result beside ac: the multipliers by row of the working set
// as it ends (recovered multipliers may be over more or fewer rows than the
// loop's), the status ("optimal" only with the scale-free certificate
// kkt_relative met), the iterations and, when asked, the KKT residuals.
ProjectionStatus write_result(const ProjectionProblem& pb, const ProjectionSettings& settings,
                              const ProjectionWorkspace& ws, ProjectionStatus status, int iterations,
                              ProjectionResult* res) noexcept {
  const int q = ws.num_active;
  std::fill_n(res->lambda.begin(), pb.num_rows, 0.0);
  for (int i = 0; i < q; ++i) {
    res->lambda[ws.active[i]] = ws.lambda_active[i];
    res->active[i] = ws.active[i];
  }
  res->num_active = q;
  res->status = status;
  res->problem = nullptr;
  res->iterations = iterations;
  res->kkt_relative = relative_kkt(pb, ws, *res);
  if (status == ProjectionStatus::kOptimal && !(res->kkt_relative <= settings.certificate_tol))
    res->status = status = ProjectionStatus::kUncertified;
  if (settings.compute_residuals) {
    compute_residuals(pb, res);
  } else {
    res->stationarity = res->primal_infeasibility = 0;
    res->dual_infeasibility = res->complementarity = 0;
  }
  return status;
}

}  // namespace

namespace {

// The exponent e >= 0 of the scaling 2^e of (au, b) under which the problem's
// smallest nonzero length (|au|_M, an offset's |b_k| / |J_k|_{M^-1}) is at
// least kMinLength: 0 when it already is or when no length is nonzero (see
// "Scale" in quasistatics.h). Estimated from logarithms, one more than needed
// so that their rounding cannot leave it short; length_problem then judges the
// scaled lengths (the largest may not exceed kMaxLength). Rows are validated
// (update_cache) before this is called.
int scale_exponent(const ProjectionProblem& pb, const ProjectionWorkspace& ws) noexcept {
  double lowest = kInf;  // log2 of the smallest nonzero length
  const double largest = pb.au.cwiseAbs().maxCoeff();
  if (largest > 0) {
    // |L^T au| on au scaled to a largest entry in [1, 2): exact when au is small,
    // so that a subnormal au still gives its length's logarithm.
    const int exponent = std::ilogb(largest);
    Vec6 unit;
    for (int i = 0; i < 6; ++i) unit[i] = std::ldexp(pb.au[i], -exponent);
    const double norm = (ws.L.transpose() * unit).norm();
    if (norm > 0 && norm < kInf) lowest = exponent + std::log2(norm);
  }
  for (int k = 0; pb.b != nullptr && k < pb.num_rows; ++k)
    if (ws.row_norm[k] > 0 && pb.b[k] != 0)
      lowest = std::min(lowest, std::log2(std::abs(pb.b[k])) - std::log2(ws.row_norm[k]));
  const double floor = std::log2(kMinLength);
  if (!(lowest < floor)) return 0;
  return static_cast<int>(std::ceil(floor - lowest)) + 1;
}

// The answer of the problem scaled by 2^e, brought back: ac and lambda times
// 2^-e (exact, short of results below 2^-1022), the KKT residuals measured
// again on the data as given (kkt_relative and the status are scale-free).
void unscale_result(const ProjectionProblem& pb, const ProjectionSettings& settings, int e,
                    ProjectionResult* res) noexcept {
  for (int i = 0; i < 6; ++i) res->ac[i] = std::ldexp(res->ac[i], -e);
  for (int k = 0; k < pb.num_rows; ++k) res->lambda[k] = std::ldexp(res->lambda[k], -e);
  if (settings.compute_residuals) compute_residuals(pb, res);
}

}  // namespace

ProjectionStatus project(const ProjectionProblem& pb, const ProjectionSettings& settings,
                         ProjectionWorkspace* workspace, ProjectionResult* res) noexcept {
  if (res == nullptr) return ProjectionStatus::kBadInput;
  if (const char* problem = call_problem(pb, settings, workspace, *res)) return bad_input(pb, problem, res);
  ProjectionWorkspace& ws = *workspace;
  if (const char* problem = update_cache(pb, ws)) {
    ws.num_active = 0;
    return bad_input(pb, problem, res);
  }
  const int m = pb.num_rows;

  // Target in Cholesky coordinates: y_u = L^T au.
  Vec6 yu = ws.L.transpose() * pb.au;
  // The problem's lengths (y-space) within range (see kMaxLength): |y_u| and each
  // offset's distance |b_k| / |A_k| (an offset on a zero row is a bare sign test).
  // Where one is under kMinLength, the problem solved is (au, b) scaled up by
  // 2^e (see "Scale" in quasistatics.h; the answer is scaled back), judged
  // again; a refusal names the length as given. Lengths in range take no
  // logarithm: the scale is sought only past the check every call makes.
  ProjectionProblem spb = pb;
  int e = 0;
  if (const char* problem = length_problem(yu, pb.b, ws, m)) {
    e = scale_exponent(pb, ws);
    if (e > 0) {
      for (int i = 0; i < 6; ++i) spb.au[i] = std::ldexp(pb.au[i], e);
      if (pb.b != nullptr) {
        for (int k = 0; k < m; ++k) ws.scaled_b[k] = std::ldexp(pb.b[k], e);
        spb.b = ws.scaled_b.data();
      }
      yu = ws.L.transpose() * spb.au;
    }
    if (e == 0 || length_problem(yu, spb.b, ws, m) != nullptr) return bad_input(pb, problem, res);
  }
  const LoopProblem lp{yu, yu.norm(), spb.b, m, settings.dependence_tol, settings.feasibility_tol,
                       settings.max_iterations};

  start_working_set(ws, settings.warm_start, m, lp.dep_tol);
  LoopIterate it;
  // Make the start dual feasible (a warm start's multipliers may be negative).
  it.iterations += drop_until_dual_feasible(ws, yu, lp.yu_norm, lp.b, &it.y);
  // Add the most violated row until none is (or a status ends the loop).
  ProjectionStatus status = ProjectionStatus::kOptimal;
  while (status == ProjectionStatus::kOptimal) {
    const double y_scale = std::max(it.y.norm(), lp.yu_norm);
    const int p = most_violated_row(ws, lp, it.y, y_scale);
    if (p < 0) break;
    status = step_to_row(ws, lp, p, y_scale, &it);
  }

  if (status == ProjectionStatus::kInfeasibleOffsets) {
    ws.num_active = 0;
    ws.factor_matches_cache = false;
    return zero_force_result(pb, status, it.iterations, res);
  }
  if (ws.num_active == 0) res->ac = spb.au;  // no active row: exactly no force
  else final_point(spb, ws, lp, &it, res);
  status = write_result(spb, settings, ws, status, it.iterations, res);
  if (e > 0) unscale_result(pb, settings, e, res);
  return status;
}

}  // namespace gauss6
