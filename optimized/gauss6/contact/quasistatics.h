// The quasi-static projection of METHOD.md sections 2-3 (Gauss' principle of
// least constraint), for the real-time loops:
//
//   ac = argmin 1/2 (a - au)^T M (a - au)   subject to   J a >= b,
//
// with multipliers lambda >= 0, M (ac - au) = J^T lambda and complementarity
// lambda_k (J_k ac - b_k) = 0. b = 0 (the contact cone) unless constraint
// offsetting (offsetting.h) is running, in which case the feasible set is a
// polyhedron that may be empty.
//
// Method: with M = L L^T (cached per M) and y = L^T a, the problem is the
// Euclidean projection of y_u = L^T au on {y : A y >= b}, A = J L^-T. It is
// solved by the dual active-set method of Goldfarb and Idnani (Math. Prog. 27,
// 1983) with identity Hessian: the working set W holds at most 6 linearly
// independent rows, A_W^T = Q [R; 0] is kept by Givens rotations as rows enter
// and leave, and every iterate (y, lambda_W >= 0) is optimal for the rows in W,
// so the method stops as soon as no row is violated. It may start from the
// previous call's working set (warm start). At a degenerate vertex whose
// working set turns out to have a negative multiplier beyond rounding (a jammed
// body: see quasistatics.cpp), ac is kept and nonnegative multipliers are
// sought over the rows tight at ac; their rows become the working set.
//
// Real-time contract: project() allocates nothing, takes no lock, throws
// nothing; every buffer lives in the caller-owned ProjectionWorkspace and
// ProjectionResult, sized for max_rows rows when they are built (any number;
// kDefaultMaxContacts unless the model says otherwise). A problem with more
// rows than either holds is refused (kBadInput), never truncated.
//
// Scale: the answer is positively homogeneous in (au, b): projecting
// (2^e au, 2^e b) gives 2^e ac and 2^e lambda, exactly in floating point
// (a power-of-two scaling is exact, short of overflow and of results below
// 2^-1022). A problem with a length (below) under 1e-100 is solved so
// scaled up, e one more than the least that lifts its smallest to 1e-100: a
// god-object settling on a resting handle halves |au| every step, through
// 1e-100, on its way to 0 (e = 0, the data as given, whenever they already lie
// in the range).
#pragma once

#include <array>
#include <vector>

#include "gauss6/geometry/pose.h"

namespace gauss6 {

// The default capacity in rows of a workspace, a result and the runtime's
// contact set (RuntimeSettings::max_contacts); any capacity >= 1 may be chosen
// when they are built.
inline constexpr int kDefaultMaxContacts = 64;
// Size of a working set: at most 6 linearly independent rows in R^6.
inline constexpr int kMaxActive = 6;

// Tolerances and limits; defaults suit double-precision haptics. The
// tolerances are relative (to |A_k| = sqrt(J_k M^-1 J_k^T), |y| = |a|_M,
// |b_k|): independent of units and row scaling. Why these values: see
// "Tolerances" at the top of quasistatics.cpp.
struct ProjectionSettings {
  // Row k is dependent on the working set W when the sine of its angle to the
  // span of W's rows (y-space) is <= max(dependence_tol, 64 eps cond(R)): it
  // never joins W; a violated one is exchanged for a row of W that spans it.
  // The second term is the rounding of that computed sine for an
  // ill-conditioned W; a row under it and above dependence_tol has its sine
  // measured again on the rows (to a few eps) and is dependent only when that
  // is <= dependence_tol. 1e-13 (~450 eps) keeps cond(R) below 1e13 (the final
  // answer is refined when W is ill-conditioned: see quasistatics.cpp).
  double dependence_tol = 1e-13;
  // Row k is violated when J_k a - b_k < -feasibility_tol * scale_k, with
  // scale_k = |A_k| max(|y|, |y_u|) + |b_k|. 1e-13 (~450 eps): above the
  // rounding of a slack, and small because a nearly parallel row left violated
  // by v moves the answer by v / (their sine).
  double feasibility_tol = 1e-13;
  // The answer is "optimal" only when its KKT conditions, measured in a
  // scale-free form (ProjectionResult::kkt_relative), hold to this; else the
  // status is kUncertified. 1e-8: the method's answers reach at most 1.6e-11
  // (ill-conditioned M), the wrong active sets of a ratio test that mixed the
  // rows' units 0.06..0.4 (measured over the instance families with their rows
  // rescaled by 1e-8..1e8).
  double certificate_tol = 1e-8;
  // Cap on the add/drop steps of one call (typ. <= 2 m are needed).
  int max_iterations = 200;
  // Start from the previous call's working set (kept in the workspace).
  bool warm_start = true;
  // Fill the KKT residuals of ProjectionResult (about 6 m + 60 flops).
  bool compute_residuals = true;
};

enum class ProjectionStatus {
  kOptimal,            // KKT conditions met within the tolerances.
  kIterationCap,       // max_iterations reached: ac (finite) is the projection
                       // on the last working set; the residuals say how far
                       // from optimal it is.
  kInfeasibleOffsets,  // {a : J a >= b} is empty: a violated row is, within
                       // dependence_tol, a nonpositive combination of working
                       // set rows whose offsets contradict it by more than
                       // feasibility_tol (only possible with b != 0):
                       // ac = au (zero force), lambda = 0.
  kBadInput,           // non-finite data, M not SPD, num_rows out of [0, the
                       // workspace's and the result's max_rows],
                       // J null with rows, settings out of range, or a length
                       // out of [1e-100, 1e100] (|au|_M, a row's |J_k|_{M^-1},
                       // an offset's |b_k| / |J_k|_{M^-1}; 0 is allowed) once
                       // au and b are scaled up by 2^e (see "Scale" above:
                       // lengths under 1e-100 are so brought into the range
                       // when the largest allows it, so only lengths over
                       // 1e100, a row's out of range, or lengths spanning more
                       // than about 1e200 are refused):
                       // ProjectionResult::problem names it. ac as for
                       // kInfeasibleOffsets.
  kUncertified,        // the method ended but its answer fails the scale-free
                       // KKT certificate (kkt_relative > certificate_tol): ac
                       // (finite) is not to be taken as the projection.
};
const char* to_string(ProjectionStatus status) noexcept;

// One projection's data; nothing is copied (pointers must outlive the call).
struct ProjectionProblem {
  const Mat6* M = nullptr;   // mass matrix diag(m I3, I_G), world frame, SPD.
  Vec6 au = Vec6::Zero();    // unconstrained acceleration (linear, angular).
  const double* J = nullptr; // num_rows x 6, row-major (contact k = J[6k..6k+5]);
                             // may be null when num_rows == 0.
  const double* b = nullptr; // num_rows right-hand sides; null means b = 0.
  int num_rows = 0;          // m, in [0, max_rows of the workspace and result].
};

struct ProjectionResult {
  // Room for max_rows multipliers (allocated here, once).
  explicit ProjectionResult(int max_rows = kDefaultMaxContacts);
  int max_rows() const noexcept { return static_cast<int>(lambda.size()); }

  Vec6 ac = Vec6::Zero();  // constrained acceleration; on kBadInput ac = au when
                           // au is finite (zero force), else ac = 0.
  // Multipliers (units of M * a): entries [0, num_rows) are valid, zero off the
  // working set.
  std::vector<double> lambda;  // size max_rows
  // Rows of the final working set, in the order they entered it.
  std::array<int, kMaxActive> active{};
  int num_active = 0;
  ProjectionStatus status = ProjectionStatus::kBadInput;
  // On kBadInput, what is wrong ("au: an entry is not finite"; a string
  // literal); else nullptr.
  const char* problem = nullptr;
  int iterations = 0;  // add/drop steps taken (0 when the warm start was exact;
                       // the multipliers' recovery at a degenerate vertex is
                       // not counted: it is bounded on its own)
  // KKT residuals, measured on the input data (a-space), filled when
  // settings.compute_residuals (else left at 0):
  double stationarity = 0;          // max_i |M (ac - au) - J^T lambda|_i
  double primal_infeasibility = 0;  // max_k (b_k - J_k ac)+
  double dual_infeasibility = 0;    // max_k (-lambda_k)+
  double complementarity = 0;       // max_k |lambda_k (J_k ac - b_k)|
  // The same conditions in a scale-free form (always filled), with y =
  // max(|ac|_M, |au|_M) and T = y + sum |lambda_k| |J_k|_{M^-1} (the sizes of
  // the terms stationarity sums): the largest of each row's violation over its
  // scale |J_k|_{M^-1} y + |b_k|, each negative lambda_k |J_k|_{M^-1} over T,
  // each complementarity pair as the smaller of the two, and
  // |M (ac - au) - J^T lambda|_{M^-1} over T. No positive scaling of a row, of
  // b or of the units changes it.
  double kkt_relative = 0;
};

// Caller-owned state of project(): every buffer is preallocated here. One
// workspace per loop (not shared between threads). It caches the Cholesky
// factor of M and the rows A = J L^-T (recomputed only when M or J changes,
// detected by comparing their bytes), and the working set with its QR factors
// for the next warm start. The members are internal: callers only construct
// it and may call reset().
struct ProjectionWorkspace {
  // Buffers for problems of up to max_rows rows (allocated here, once).
  explicit ProjectionWorkspace(int max_rows = kDefaultMaxContacts);
  int max_rows() const noexcept { return capacity; }
  // Forget the caches and the warm start.
  void reset() noexcept;

  int capacity = 0;  // rows the buffers below hold
  // Cache of M: its copy, lower Cholesky factor L (M = L L^T) and L^-1.
  bool has_M = false;
  Mat6 M = Mat6::Zero();
  Mat6 L = Mat6::Identity();
  Mat6 L_inv = Mat6::Identity();
  // Cache of J (valid for has_M and M): its copy, A = J L^-T, 1/|A_k|.
  int num_rows = -1;
  std::vector<double> J;         // capacity x 6
  std::vector<double> A;         // row-major: row k at 6 k
  std::vector<double> A_t;       // column-major: column j at capacity j
  std::vector<double> row_norm;  // capacity
  std::vector<double> inv_row_norm;
  // Working set: A_W^T = Q(:, 0:q) R(0:q, 0:q), q = num_active, Q orthogonal.
  bool factor_matches_cache = false;  // Q, R are for the cached A
  int num_active = 0;
  std::array<int, kMaxActive> active{};
  Mat6 Q = Mat6::Identity();
  Mat6 R = Mat6::Zero();
  // Givens rotations applied to Q since it was last rebuilt from scratch; the
  // factors are rebuilt past a bound so that rounding cannot accumulate.
  long rotations_since_rebuild = 0;
  // Scratch.
  std::array<double, kMaxActive> lambda_active{};
  std::vector<double> slack;               // capacity
  std::vector<double> scaled_b;            // capacity: b times 2^e (see project())
  std::vector<unsigned char> in_active;    // capacity
};

// Solves the projection (see the top of this file). Fills *result (always: ac
// is finite whatever the input) and returns result->status. Uses and updates
// *workspace (caches; warm start when settings.warm_start).
ProjectionStatus project(const ProjectionProblem& problem,
                         const ProjectionSettings& settings,
                         ProjectionWorkspace* workspace,
                         ProjectionResult* result) noexcept;

}  // namespace gauss6
