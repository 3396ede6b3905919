// The coupling force (METHOD.md section 3): what the coupling loop sends the
// user from a projection. Constraint offsetting is in offsetting.h.
//
// Units: accelerations a are the quasi-static per-step displacements of
// METHOD.md section 1 (dt^2 folded into the gains): metres for the linear part,
// radians for the angular part; J rows are [n^T, (G I_k x n)^T] (unitless, m).
// Time t is in seconds.
#pragma once

#include "gauss6/geometry/pose.h"

namespace gauss6 {

// Fc = kh M (ac - au): the wrench (force, torque about G; world frame) sent to
// the user. One gain kh for both parts keeps Fc^T ac = 0 (METHOD.md section 5).
// Returns zero when any input or the product is not finite, or when kh is not a
// valid gain: a device never receives NaN or inf, nor a wrench reversed into the
// obstacle by a gain kh <= 0.
Vec6 coupling_force(const Mat6& M, const Vec6& au, const Vec6& ac, double kh) noexcept;
// The gain's rule: kh finite and > 0 (check_gains in scene.h states it for scenes).
bool valid_coupling_gain(double kh) noexcept;

}  // namespace gauss6
