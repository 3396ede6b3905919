// The coupling force and the constraint offsetting of new contacts
// (METHOD.md section 3): what the coupling loop does with a projection.
//
// Units: accelerations a are the quasi-static per-step displacements of
// METHOD.md section 1 (dt^2 folded into the gains): metres for the linear part,
// radians for the angular part; J rows are [n^T, (G I_k x n)^T] (unitless, m).
// Time t is in seconds.
#pragma once

#include <span>

#include "gauss6/pose.h"

namespace gauss6 {

// Fc = kh M (ac - au): the wrench (force, torque about G; world frame) sent to
// the user. One gain kh for both parts keeps Fc^T ac = 0 (METHOD.md section 5).
// Returns zero when any input or the product is not finite: a device never
// receives NaN or inf.
Vec6 coupling_force(const Mat6& M, const Vec6& au, const Vec6& ac, double kh) noexcept;

// Constraint offsetting after Mark et al.: a new row J_k with d_k = J_k au
// below eps (< 0) starts at J_k a >= d_k and relaxes to J_k a >= 0 in T seconds.
struct OffsetSettings {
  double eps = -1e-4;  // threshold on d_k = J_k au (< 0, metres): deeper rows are offset
  double T = 0.1;      // duration of an offset (> 0, seconds)
};

// True when eps < 0 and T > 0 are finite.
bool valid_offset_settings(const OffsetSettings& settings) noexcept;

// True when a new row with d_k = J_k au gets an offset: d_k < eps.
bool needs_offset(double d_k, const OffsetSettings& settings) noexcept;

// The offset profile f_k(t) = d_k (1 - s(t / T)), s(u) = 3u^2 - 2u^3 (cubic
// smoothstep), clamped to u in [0, 1]: f_k(0) = d_k, f_k(T) = 0, increasing for
// d_k < 0, with zero slope at both ends, so the felt force has neither a jump
// nor a kink in its rate when an offset starts or ends. t < 0 gives d_k.
// Requires valid_offset_settings(settings).
double offset_rhs(double d_k, double t, const OffsetSettings& settings) noexcept;

// For a newly published contact set (J: num_rows x 6 row-major, au the current
// unconstrained acceleration): start_values[k] = d_k = J_k au when the row is
// offset, else 0. start_values.size() must be >= num_rows. Returns the number of
// offset rows (0 when the settings are invalid: every start value is then 0).
int begin_offsets(std::span<const double> J, int num_rows, const Vec6& au,
                  const OffsetSettings& settings, std::span<double> start_values) noexcept;

// b_k = offset_rhs(start_values[k], t, settings) for k < num_rows, t the time
// since the set was published. Rows with start value 0 get b_k = 0. Returns
// true while some offset is still running (t < T and a start value < 0): once
// it returns false the projection may take b = nullptr. Invalid settings or
// t = NaN give b = 0 (no offset). Only min(num_rows, sizes) rows are written.
bool fill_offset_rhs(std::span<const double> start_values, int num_rows, double t,
                     const OffsetSettings& settings, std::span<double> b) noexcept;

}  // namespace gauss6
