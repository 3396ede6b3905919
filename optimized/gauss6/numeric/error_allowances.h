// The named error allowances of the conservative bounds: each literal that
// covers rounding somewhere in the collision pipeline or the contact step,
// with its argument stated once here (what rounding it covers, why the value
// is enough, and by what margin) and the sites that use it. The arithmetic
// that carries them, rounded the safe way, is in rounding.h.
//
// u = 2^-53 (1.1e-16), the unit roundoff of round-to-nearest doubles; a
// product or sum of nonnegative terms rounds within u of itself, relatively,
// and a dot product of two 3-vectors within 3.01 u of the sum of its terms'
// magnitudes. The relative allowances assume no product underflows (values
// above 1e-290 or so); below that only kUnderflowFloor speaks for them.
#pragma once

#include <limits>

namespace gauss6 {

// Relative allowance of a norm or a rounded product computed from doubles
// (a norm errs by under 3.6 u, the step's product by 2.01 u per coordinate).
// Machine-checked at every site: proofs/Allowances.v norm_up_relative
// (|omega|: StartFrame::set; |half|: SweptObbFrame::pose; |r_B|:
// StartFrame::radius), step_rounding (StartFrame::obb_frame);
// proofs/ObbAllowances.v shift_rounding (Displacement's |p_b - p_a|, whose
// components are rounded differences).
constexpr double kRelativeRounding = 1e-15;

// The wider relative allowance of a norm at the separating-axis and box-radius
// sites (kept apart from kRelativeRounding: merging them moves the lockstep
// runs; both are proved). Machine-checked: proofs/Allowances.v norm_up_wide
// (for_each_separating_axis), norm_down_wide (triangle_time_lower_bound);
// proofs/ObbAllowances.v obb_radius_rounding (|center| + |half|,
// SweptObbFrame::pose).
constexpr double kRelativeRoundingWide = 1e-12;

// The absolute floor of a norm's bounds (norm_up, norm_down in rounding.h):
// where the squares of a double vector underflow (|v| below about 2^-500), the
// computed norm errs by far more than any relative allowance (all three
// squares round to 0 at |v| ~ 2^-538), so the upper bound is at least 2^-500
// and a lower bound not above 2^-500 is replaced by 0. Above it the squares'
// underflow errs by less than 2^-73 of |v|^2: proofs/Allowances.v,
// norm_upper_bound, norm_lower_bound.
constexpr double kNormFloor = 0x1p-500;

// A short sum of products along a rounded separating axis a, relative to
// |a|_1 times the largest coordinates of the other factors. The difference of
// two projections a.y - a.x of corners with coordinates <= s: each projection
// within 3.01 u |a|_1 s, the difference rounding within 2 u |a|_1 s, under
// 8.1 u (9e-16) of |a|_1 s, and the last subtraction of the slack within
// 2 u |a|_1 s more; the projections' underflow (2^-1075 a product) is under
// kUnderflowFloor, which the site adds, and the site drops an axis with
// |a|_1 < kNormFloor, below which kAxisProductRounding |a|_1 underflows. The
// turn term r.(a x omega), with T = |a|_1 |omega|_inf |r|_inf: the cross
// product's rounding moves it by 4.02 u T, its own by 6.02 u T (|a x omega|_1
// <= 2 |a|_1 |omega|_inf), the sums that join it to a.v by 8 u T: under 19 u
// (2.1e-15) of T. 1e-13 covers the gap 89 times and the turn 47 times. Sites:
// for_each_separating_axis (distance.h), triangle_time_lower_bound
// (motion_bounds.h). Machine-checked: proofs/AxisAllowances.v,
// axis_gap_rounding (the gap on the side the code reports: 8.1 u |a|_1 s +
// 10.1 2^-1075 proved, for |a|_1 >= kNormFloor, the site's guard; with
// axis_gap_distance, the gap handed on is at most the features' distance) and
// axis_turn_rounding (each corner's rate, velocity and turn together: 8 u
// |a|_1 |v|_inf + 23 u T proved, the underflow under next_up's 2^-600, for
// |r|_inf <= 2^400: ccd_step refuses a god radius beyond kMaxCoordinate).
constexpr double kAxisProductRounding = 1e-13;

// The velocity term a.v of triangle_time_lower_bound and its share of the
// sums that follow: within 3.01 u + 2 u of |a|_1 |v|_inf (5.6e-16); 1e-14
// covers it 18 times. Site: triangle_time_lower_bound. Machine-checked:
// proofs/Allowances.v, axis_velocity_rounding (for |a|_1 >= 2^-900, which the
// site's guard norm_down(|a|) > 0 ensures).
constexpr double kAxisVelocityRounding = 1e-14;

// Posing a body point in doubles, X = R r_B + p, R = rotation_matrix(q):
// proofs/PoseAllowances.v pose_rounding (with _start_frame, _stand_at for the
// sites): within 309 u (|p|_inf + rho) of the exact p + R(q) r_B, |r_B|_inf <= rho.
constexpr double kPoseRounding = 1e-13;
// The least god-object radius (its body's bounding sphere about G) that
// pose_rounding_stand_at covers: below 2^-1000 the posing error's underflow
// terms are not within the allowance. RuntimeModel refuses a smaller body.
constexpr double kMinBodyRadius = 0x1p-1000;

// The turn between two double poses, 2 |vec(conj(qa) qb)| (Displacement):
// proofs/PoseAllowances.v quaternion_turn_rounding, the computed 2 |v| within
// 52 u (absolute) of the exact unit quaternions' turn.
constexpr double kQuaternionTurnRounding = 1e-14;

// The directional sweep of a god node's oriented box (SweptObbFrame::pose):
// the node's segment step + spin x c from the doubles c = R center (within
// 3.01 u of |center|_1 <= sqrt(3) radius per coordinate), the cross product
// (two products and a difference) and the sum: under 21 u of |spin|_inf
// radius + |step|_inf per coordinate. The grow it joins is a ball's radius,
// so the three coordinates count together: under 63.01 u |spin|_inf radius +
// 3 u |step|_inf in the Euclidean norm, which 1e-14 (90 u) covers 1.43 times.
// Machine-checked: proofs/AxisAllowances.v, spin_rounding (the underflow
// under next_up's 2^-600; R's entries within 1.001, as rotation_matrix's
// are: PoseAllowances.v).
constexpr double kSpinRounding = 1e-14;

// A god corner's offset from G in triangle_time_lower_bound, the subtraction
// X - p, rounds each coordinate within u of the offset (<= r, the corners'
// largest |r_B| up to static_error, which holds the posing's own rounding:
// kPoseRounding). The turn acts on it at turn_rate: 1e-12 r covers it 9000
// times. Site: StartFrame::earliest. Machine-checked: proofs/Allowances.v,
// corner_offset_rounding (for static_error <= 9000 r, not checked by the code).
constexpr double kCornerOffsetRounding = 1e-12;

// The 15-axis test of two oriented boxes (obb_separated). Its axes are
// orthonormal to within 1e-15 (the eigenvectors of fit_obb, turned by the
// double R), so |C| (C = a's axes^T b's) is raised by 1e-15 entrywise: the
// cross axes of near-parallel edges then cannot prove a gap out of rounding
// noise. Every side of every comparison is a sum of at most a dozen products
// of an entry of |C| (<= 1 + 1e-15) and a number <= s (the largest
// coordinate, extent or step involved), each within a few units of u of
// itself, and the axes' error moves each by at most 1e-15 s: under 3e-14 s in
// all. 1e-11 s covers it 300 times. Machine-checked (proofs/ObbSeparation.v),
// for axes orthonormal to within 2^-46 (kObbFrameTolerance below) and s >=
// 2^-1001 (every half extent is, by fit_obb's floor): obb_axis_rounding (|C| +
// kObbAxisRounding bounds the exact |a_i . b_j|), obb_separation_face (a test
// along a face axis that holds proves the swept posed box and the obstacle's
// box, as sets over the reals with the double axes, without a common point:
// roundings under 48 u s, the axes' defect under 17 e s, 2.6e-13 s in all);
// proofs/ObbCrossAxes.v, obb_separation_cross (the same for the nine cross
// axes a_i x b_j, whose reach's entries A(i, j1), A(i, j2) stand for 2 x 2
// minors of C: Binet-Cauchy puts those within 11 e of |a_i . b_j2|, |a_i .
// b_j1|; roundings under 140 u s, the axes' defect under 46 e s, 6.8e-13 s in
// all, covered 14 times).
constexpr double kObbAxisRounding = 1e-15;
constexpr double kObbSeparationRounding = 1e-11;
// How far from orthonormal an oriented box's axes may be for the two tests
// above to hold: every entry of A^T A and of A A^T, computed in doubles, within
// 1e-14 of the identity's (near_orthonormal, bvh.h; fit_obb drops a frame that
// fails it, SweptObbFrame::pose makes a posed box that fails it never separate).
// Then both exact Gram matrices are within 2^-46 of the identity, the
// hypothesis of proofs/ObbSeparation.v (machine-checked: frame_check_sound). Eigen's eigenvectors and their turn
// by a double rotation stay near 1e-16 to 1e-15, so it never trips on a valid pose.
constexpr double kObbFrameTolerance = 1e-14;
// Tighter frame checks, made once per frame instead of once per posed box: a
// node's fitted axes A within kObbAxesTight (2^-49, BvhNode::obb_tight, at
// BVH build) and the pose's rotation R within kObbRotationTight (2^-50,
// SweptObbFrame::set_rotation), both in near_orthonormal's sense, make the
// posed axes R A, each entry a sum of three products rounded in any order,
// pass near_orthonormal at kObbFrameTolerance (their exact Gram matrices
// within 79 u of the identity, the computed ones within 82 u < 1e-14): then
// SweptObbFrame::pose need not compute it. Machine-checked:
// proofs/ObbFrameProduct.v, posed_frame_check. Eigen's eigenvectors sit
// within 2^-49 and rotation_matrix's within 2^-50; a frame that is not falls
// back to the check on the product.
constexpr double kObbAxesTight = 0x1p-49;
constexpr double kObbRotationTight = 0x1p-50;

// The half extents of a fitted oriented box (fit_obb), relative to the
// largest coordinate of its points: each point's projection on the double
// axes (three products and two sums) is within 3.01 u sqrt(3) of it (5.8e-16),
// and the centre (the axes times the mid-projection) and (hi - lo) / 2 round
// within a few units more: under 2e-15. 1e-13 covers it 50 times.
// Machine-checked: proofs/ObbSeparation.v, obb_fit_rounding (every point p
// within half_k of the centre along each double axis q_k, |q_k . (p - c)| <=
// half_k exactly, for axes orthonormal to within 2^-46, whose defect moves the
// centre's projection by up to 5.21 e scale = 7.4e-14 scale: the allowance
// covers that and the roundings, under 40 u scale, 1.27 times).
constexpr double kObbFitRounding = 1e-13;

// The world box of a god node's body box at a double pose, c +- (h + slack)
// with c = G + R mid, h = |R| half and slack = kBoxPoseRounding (|G| + |R|
// |mid| + h) + kUnderflowFloor (posed_body_box, contacts.cpp), holds every
// vertex posed in doubles, G + R v: machine-checked, proofs/BoxPose.v,
// box_pose_encloses (roundings under 23 u of the reach, 1e-12 covers them
// 390 times). At generate_contacts' `apart`: proofs/ContactApart.v,
// apart_vertex_face and apart_edge_edge (a closest point's rounding, under
// 40 u M, against 9000 u scale, M <= 4 scale + 2^-490). At `tie`: proofs/ContactTie.v,
// tie_shared_edge (two faces' separations through their shared edge's branch, within 460 u M + 2^-530).
constexpr double kBoxPoseRounding = 1e-12;

// A body box c +- h mapped by an interval rotation in midpoint-radius form
// (swept_box: R within R_rad of R_mid entrywise): the world box R_mid c +-
// (|R_mid| h + R_rad (|c| + h)), in doubles. With T = (|R_mid| + R_rad) (|c| +
// h) per coordinate, R_mid c rounds within 3.01 u sum |R_mid| |c| <= 3.01 u T,
// and the half-width, a sum of six rounded products of rounded sums of
// nonnegative terms, within 7.01 u of itself <= 7.01 u T; T itself is
// computed within 7.01 u. Under 10.1 u (1.12e-15) of the computed T in all;
// 2e-15 covers it 1.8 times (kUnderflowFloor below it). Site: swept_box.
// Machine-checked: proofs/Allowances.v, swept_box_rounding (with kUnderflowFloor);
// the box then holds every pose of the motion: proofs/ObbAllowances.v,
// swept_box_encloses.
constexpr double kBoxProductRounding = 2e-15;

// An absolute floor under the relative allowances of box extents, where the
// relative term vanishes or underflows (all coordinates 0 or subnormal): each
// underflowing product or sum errs by at most 2^-1075 (2.5e-324; 2^-1022,
// 2.2e-308, on a thread that flushes subnormals to zero), and a box's few
// dozen of them stay below 1e-306; 1e-300 covers them and is below any extent
// that matters. Sites: fit_obb, generate_contacts, swept_box,
// for_each_separating_axis. Machine-checked at swept_box: proofs/Allowances.v,
// swept_box_rounding; at generate_contacts: proofs/BoxPose.v,
// box_pose_encloses; at fit_obb: proofs/ObbSeparation.v, obb_fit_rounding
// (the half extents' floor, >= 2^-1001, which obb_separated's theorems take).
constexpr double kUnderflowFloor = 1e-300;

// A corner value of F = (w + a ea) - b eb for linearly moving points (the
// narrow phase's enclose_linear, ccd/linear_queries.cpp), every input coordinate bounded by M
// and u, a, b in [0, 1], is computed within 128 u M + 64 2^-1022 of the exact
// one (69 u M + 44 2^-1075 proved): proofs/Allowances.v, linear_corner_rounding
// (and linear_corner_selection, linear_corner_error_bound for the min / max
// taken and the bound rounded up). The proof models gradual underflow; the
// underflow term counts 2^-1022 per operation so that it also covers a thread
// that flushes subnormals to zero (rounding.h), which the proof does not model.
constexpr double kLinearCornerRounding = 0x1p-46;  // 128 u
constexpr double kLinearCornerUnderflow = 64 * std::numeric_limits<double>::min();  // 2^-1016

// The Bernstein lower bounds of the u-filter's polynomials (bernstein.h:
// BernsteinBasis, LowerCoefficients::set, positive_on), degree N <= 6 on
// [u0, u1] within [0, 1]: S~_i - (32 u T~_i + 2^-1000 (1 + sum_j |lo_j|)) > 0,
// computed, proves the exact S_i = sum_j lo_j w_ij > 0: proofs/BernsteinRounding.v,
// bernstein_rounding (S~_i within (1 + u)^(2N + 6) - 1 <= 19 u of T_i and
// 2^-1024 (1 + sum_j |lo_j|) of S_i; gradual underflow, no fused multiply-add).
// Not modelled, argued: flushed to zero (FTZ/DAZ), each underflow errs by
// < 2^-1022, against factors <= 20: < 2^-1011 (1 + sum_j |lo_j|), 2^-11 of the floor.
constexpr double kBernsteinRounding = 0x1p-48;    // 32 u
constexpr double kBernsteinUnderflow = 0x1p-1000;  // times 1 + sum_j |lo_j|

// Not a bound but a floor on the narrow phase's distance tolerance, relative
// to the query's largest coordinate: F's enclosures are at least a few units
// of u of the coordinates wide (128 u for linear motion, kLinearCornerRounding),
// so a tolerance below that could never be met; 1e-12 stays 70 times above it.
// Sites: bisect (ccd/bisection.h) and filtered_bisect (ccd/u_filter.h).
constexpr double kDistanceToleranceFloor = 1e-12;

}  // namespace gauss6
