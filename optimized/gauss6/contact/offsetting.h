// Constraint offsetting of new contacts (METHOD.md section 3), the rule the
// coupling loop runs: which rows of a new set are the same constraints as
// cached ones (their offsets run on), what a new row's offset starts from (d_k
// against the previous set's projection), and the stand-in set after an empty
// one; then the right-hand sides b(t) of each coupling step, and the energy
// account that keeps them passive (release_offsets, account_offsets).
//
// Units: accelerations a are the quasi-static per-step displacements of
// METHOD.md section 1 (metres, radians); J rows are [n^T, (G I_k x n)^T];
// points in scene units (metres); time t in seconds.
//
// Real-time contract: start_offsets(), fill_offsets(), release_offsets() and
// account_offsets() allocate nothing and throw nothing; OffsetState holds
// every buffer, sized when built.
#pragma once

#include <array>
#include <vector>

#include "gauss6/geometry/feature_pair.h"
#include "gauss6/geometry/pose.h"
#include "gauss6/contact/quasistatics.h"

namespace gauss6 {

// Constraint offsetting after Mark et al.: a new row J_k with d_k below eps
// (< 0) starts at J_k a >= d_k and relaxes to J_k a >= 0 in T seconds.
struct OffsetSettings {
  double eps = -1e-4;  // threshold on d_k (< 0, metres): deeper rows are offset
  double T = 0.1;      // duration of an offset (> 0, seconds)
};

// True when eps < 0 and T > 0 are finite.
bool valid_offset_settings(const OffsetSettings& settings) noexcept;

// True when a new row with start value d_k gets an offset: d_k < eps.
bool needs_offset(double d_k, const OffsetSettings& settings) noexcept;

// The offset profile f_k(t) = d_k (1 - s(t / T)), s(u) = 3u^2 - 2u^3 (cubic
// smoothstep), clamped to u in [0, 1]: f_k(0) = d_k, f_k(T) = 0, increasing for
// d_k < 0, with zero slope at both ends, so the felt force has neither a jump
// nor a kink in its rate when an offset starts or ends. t < 0 gives d_k.
// Requires valid_offset_settings(settings).
double offset_rhs(double d_k, double t, const OffsetSettings& settings) noexcept;

// The rule: the offset settings, when a row of a new set is "the same
// constraint" as a cached one (the same feature pair when the rows name
// theirs, or the same body point and normal), and the settings of the
// projection that measures the new rows.
struct OffsetRule {
  OffsetSettings offsets;
  double match_distance = 0;       // same body-frame point: |I_B - I_B'| <= this (> 0, scene units)
  double match_cosine = 1 - 1e-9;  // ... and same normal: n . n' >= this
  ProjectionSettings projection;
};

// A newly published contact set (a view; world frame): m rows J (m x 6
// row-major), their contact points I_k and normals n_k.
struct OffsetRows {
  int num_rows = 0;                    // m (rows beyond the state's capacity are not offset: see start_offsets)
  const double* J = nullptr;
  const double (*point)[3] = nullptr;
  const double (*normal)[3] = nullptr;
  // The feature pair of each row (nullptr: not known; a pair with obstacle < 0
  // names none). An edge/edge row's normal turns with the god-object: the
  // pair, not the normal, says it is the same constraint.
  const FeaturePair* features = nullptr;
};

// Per-row offsets and identities of the cached set, the stand-in set, and the
// scratch of the matching, for up to max_rows rows (allocated when built).
// Construct once; the members are internal.
struct OffsetState {
  explicit OffsetState(int max_rows = kDefaultMaxContacts);
  int capacity() const noexcept { return static_cast<int>(start.size()); }
  // One per cached row: start value d_k (0: none), start time, right-hand side
  // of the current step, and the row's identity for matching across sets.
  int num_rows = 0;                    // rows whose identities are in point_B / normal_W
  std::vector<double> start;
  std::vector<double> t0;
  std::vector<double> rhs;
  std::vector<Vec3> point_B;           // I_k in the god-object's frame
  std::vector<Vec3> normal_W;
  std::vector<FeaturePair> feature;    // obstacle < 0: none named
  // The energy account (release_offsets, account_offsets): per row, how far
  // its right-hand side was lowered below f_k(t) to give energy back (>= 0,
  // the same units as d_k), and at the last coupling step J_k au (NaN: none
  // yet), its multiplier lambda_k and its right-hand side.
  std::vector<double> give;
  std::vector<double> last_x, last_lambda, last_rhs;
  Vec6 last_ac = Vec6::Zero();         // the projection at the last step (a new row's reference)
  bool has_last_ac = false;
  double lent = 0;                     // J: energy the right-hand sides put in and not yet given back
  double stored = 0;                   // J: the coupling's stored energy at the last step
  std::vector<double> cached_J;        // the last non-empty set's rows (m x 6 row-major)
  int num_last_rows = 0;               // rows in cached_J (kept through empty sets)
  double last_rows_time = -1;          // s, when that set arrived or was last replaced by an empty one
  // Scratch for the matching of a new set's rows.
  std::vector<double> new_start, new_t0, new_give, new_last_x, new_last_lambda, new_last_rhs;
  std::vector<Vec3> new_point_B, new_normal_W;
  std::vector<FeaturePair> new_feature;
  std::vector<unsigned char> matched;
  // The previous set's rows and their right-hand sides at the new set's
  // arrival, projected once per new set to measure the new rows.
  std::vector<double> kept_J;
  std::vector<double> kept_b;
  ProjectionWorkspace arrival_ws;
  ProjectionResult arrival;
};

// A new set `rows` arrives at time t, with the god-object at xs (mass matrix M)
// and au the unconstrained acceleration. A row that is the same constraint as
// a cached one keeps its offset; a new row k with d_k = J_k ac_old < eps starts
// one, ac_old the projection of au on the previous set's rows (au when there
// were none); after an empty set, the last non-empty one (arrived or emptied
// less than T ago) stands in for the previous set, without offsets. The new
// set becomes the cached one. Invalid offset settings start no offset.
// Returns the number of offsets started.
int start_offsets(const OffsetRule& rule, double t, const Vec6& au, const Mat6& M, const Pose& xs,
                  const OffsetRows& rows, OffsetState* s) noexcept;

// s->rhs[k] = f_k(t - t0_k) - give_k for the cached rows (f_k = 0 once its
// offset has run, or for a row without one); returns the number of rows with
// a non-zero right-hand side (0: the projection may take b = nullptr).
int fill_offsets(const OffsetSettings& settings, double t, OffsetState* s) noexcept;

// Passivity of the offsets. An offset relaxing while its row pushes does work
// on the coupling: with V = 1/2 (ac - au)^T M (ac - au) and the multipliers
// lambda, dV/db_k = lambda_k, so the stored energy (kh / ks) V grows by
// (kh / ks) lambda_k db_k that the user never put in, and a release at full
// stiffness returns it (the whole peg-in-hole script: 0.29 mJ of its phase-b
// episode, loaded at 210 -> 493 N/m of force over lag, released at 493 N/m).
// So that energy is lent (account_offsets records it) and given back when the
// user backs off from a pushing row: its right-hand side goes down by c times
// the hand's own retreat ks J_k (xh (-) xh_last) (not the god-object's moves:
// they are not the user's), c = lent / (stored - lent) the share
// of the stored energy that was lent, so the lent part and the user's part of
// the stored energy run out together; a full release returns no more than the
// user put in. Lowered right-hand sides come back up only while their row
// does not push (lambda_k = 0, account_offsets), which costs no energy.
// METHOD.md's f_k (increasing from d_k to 0 within T) is kept while the user
// does not back off with energy lent: then b_k = f_k - give_k.

// Before the projection (after fill_offsets): lowers the right-hand sides of
// the rows the hand backs off from while energy is lent: those that pushed at
// the last step and those below their surface (b_k < 0) that did not, which
// would otherwise take the force over. hand: the
// hand's motion since the last step in a-units, ks (xh (-) xh_last); J: the
// cached rows (num_rows x 6); energy_scale = kh / ks (> 0). Returns the number
// of rows with a non-zero right-hand side after it (as fill_offsets).
int release_offsets(double energy_scale, const Vec6& au, const Vec6& hand, const double* J, OffsetState* s) noexcept;

// After the projection (ac, lambda: its result, optimal): lends the energy
// the right-hand sides put in since the last step (kh / ks) sum_k lambda_k
// (b_k - b_k,last) (negative when they were lowered: given back), raises the
// right-hand side of each non-pushing row towards min(f_k(t), J_k ac) (free:
// ac stays the projection), and remembers J_k au, lambda_k and b_k for the
// next step. M: the mass matrix; optimal = false (no valid multipliers) only
// remembers J_k au.
void account_offsets(const OffsetSettings& settings, double energy_scale, double t, const Vec6& au, const Vec6& ac,
                     const double* lambda, bool optimal, const Mat6& M, const double* J, OffsetState* s) noexcept;

}  // namespace gauss6
