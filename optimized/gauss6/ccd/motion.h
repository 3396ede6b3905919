// The Cayley in-between motion of METHOD.md section 4: in double precision, and
// enclosed in intervals for the CCD (CcdMotion, its enclosure over a parameter
// range, the stop pose, the distance bound between two motions).
//
// From x0 = (p0, q0) to x1 = (p1, q1): qr = q1 * conj(q0) with scalar part >= 0,
// Gibbs vector g = vec(qr) / scalar(qr) (tan(theta/2) times the axis), and for
// u in [0, 1]:  p(u) = p0 + u (p1 - p0),  R(u) = C(u g) R(q0),
// with C(h) = I + 2 / (1 + |h|^2) ([h]x + [h]x^2) the Cayley rotation. Every body
// point moves on a rational quadratic curve over D(u) = 1 + u^2 |g|^2. The end of
// the motion is C(g) R(q0), equal to R(q1) only up to rounding.
//
// The rotation angle is 2 atan(u |g|): monotone in u. A relative rotation of
// (nearly) 180 degrees has scalar(qr) ~ 0 and no finite Gibbs vector: such a
// step is refused with MotionStatus::kHalfTurn; its caller cuts it at its
// midpoint into two halves, each turning by at most 90 degrees.
#pragma once

#include <array>
#include <cmath>

#include "gauss6/geometry/pose.h"
#include "gauss6/numeric/rounding.h"

namespace gauss6 {

enum class MotionStatus {
  kOk = 0,
  kHalfTurn,      // relative rotation too close to 180 degrees: split the step
  kInvalidPose,   // a non-finite coordinate or a zero quaternion
};
const char* to_string(MotionStatus s);

// Largest relative rotation angle accepted in one motion (radians); above it,
// |g| = tan(theta/2) > tan(85 deg) ~ 11.4 and the motion is refused.
inline constexpr double kMaxMotionAngle = 170.0 * kPi / 180.0;

struct CayleyMotion {
  Vec3 p0 = Vec3::Zero();   // start position of G, world frame
  Vec3 dp = Vec3::Zero();   // p1 - p0
  Mat3 R0 = Mat3::Identity();  // R(q0), rational form
  Vec3 g = Vec3::Zero();    // Gibbs vector of the relative rotation, world frame
};

// Builds the motion from x0 to x1; on a status other than kOk, *motion is untouched.
MotionStatus make_cayley_motion(const Pose& x0, const Pose& x1, CayleyMotion* motion);

// The Cayley rotation C(h).
Mat3 cayley_rotation(const Vec3& h);
// R(u) = C(u g) R0 and p(u); u in [0, 1].
Mat3 motion_rotation(const CayleyMotion& m, double u);
Vec3 motion_position(const CayleyMotion& m, double u);
// World position at u of the body point r_B.
Vec3 motion_point(const CayleyMotion& m, double u, const Vec3& r_B);
// Pose at u (quaternion of R(u), normalised).
Pose motion_pose(const CayleyMotion& m, double u);
// Rotation angle of R(u) R0^T: 2 atan(u |g|).
double motion_angle(const CayleyMotion& m, double u);

// ---------------------------------------------------------------------------
// Interval vectors, and the coordinates the CCD accepts.
// ---------------------------------------------------------------------------

inline IVec3 to_interval(const Vec3& v) { return {Interval::point(v.x()), Interval::point(v.y()), Interval::point(v.z())}; }
GAUSS6_ALWAYS_INLINE IVec3 operator+(const IVec3& a, const IVec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
GAUSS6_ALWAYS_INLINE IVec3 operator-(const IVec3& a, const IVec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
GAUSS6_ALWAYS_INLINE IVec3 operator*(double s, const IVec3& a) { return {s * a[0], s * a[1], s * a[2]}; }

// Coordinates beyond this are refused: with degree <= 6 products of inputs and
// of the Gibbs vector (|g| <= 12), no intermediate can overflow.
inline constexpr double kMaxCoordinate = 1e30;
bool bounded_coordinates(const Vec3& v);  // false for NaN

// ---------------------------------------------------------------------------
// The exact Cayley motion, enclosed.
// ---------------------------------------------------------------------------

// Interval enclosure of the exact in-between motion of METHOD.md section 4 from
// two double poses: p0, dp = p1 - p0, R0 = R(q0) (rational form) and the Gibbs
// vector g = vec(qr) / scalar(qr), qr = q1 conj(q0), each enclosing the exact
// rational value computed from the input doubles. `nominal` is the double motion
// of motion.h (the same motion, rounded), used for poses and heuristics.
struct CcdMotion {
  IVec3 p0, dp, g;
  IMat3 R0;
  Interval g2;           // |g|^2
  IMat3 K2;              // [g]x^2 = g g^T - |g|^2 I
  CayleyMotion nominal;
};

// kOk, or the status of make_cayley_motion (invalid pose, half turn). Also
// kHalfTurn when the enclosure of scalar(qr) is not safely positive, or that of
// |g|^2 not within the range enclose_motion's proof needs (motion.cpp).
MotionStatus make_ccd_motion(const Pose& x0, const Pose& x1, CcdMotion* motion);

// Enclosure of the motion over a parameter range U = [u0, u1] subset of [0, 1]:
// for every u in U, R(u) is in R and p(u) in p (world frame). Machine-checked:
// proofs/MotionEnclosure.v, enclose_motion_encloses.
struct MotionEnclosure {
  Interval u;
  IMat3 R;   // entries intersected with [-1, 1] (R(u) is exactly a rotation)
  IVec3 p;
  // R in midpoint-radius form: every entry of R within R_rad of R_mid's
  // (exactly), and R_abs = |R_mid|; for swept_box (motion_bounds.h).
  Mat3 R_mid, R_rad, R_abs;
};
void enclose_motion(const CcdMotion& motion, Interval u, MotionEnclosure* out);
// Enclosure of the world points p(u) + R(u) r_B for u in e.u and r_B in r_B
// (inline: the narrow phase's innermost loop).
inline IVec3 enclose_point(const MotionEnclosure& e, const IVec3& r) {
  // Point coordinates (the common case: a vertex) take the cheaper scalar product.
  const auto mul = [](Interval R, Interval x) { return x.lo == x.hi ? x.lo * R : R * x; };
  IVec3 w;
  for (int i = 0; i < 3; ++i)
    w[i] = e.p[i] + (mul(e.R[3 * i], r[0]) + mul(e.R[3 * i + 1], r[1]) + mul(e.R[3 * i + 2], r[2]));
  return w;
}

// ---------------------------------------------------------------------------
// Stop pose.
// ---------------------------------------------------------------------------

// The pose of the motion at u, as doubles, and a bound on how far any body point
// with |r_B| <= body_radius lies from where the exact motion puts it at u:
// |(p + R(q) r_B) - (p(u) + R(u) r_B)| <= deviation. With a CCD run at
// min_separation = d and u = u_hit, the stop pose's exact separation is at least
// d - deviation (and the exact motion on [0, u_hit] keeps a distance >= d).
// Machine-checked: proofs/StopPose.v, stop_pose_deviation, stop_pose_separation.
struct StopPose {
  Pose pose;
  double deviation = 0;   // scene units
};
StopPose make_stop_pose(const CcdMotion& motion, double u, double body_radius);

// A bound on how far apart two Cayley motions keep each body point: the exact
// motion a (make_ccd_motion) from a0, and the exact motion b (from b0, its
// start pose) over [0, ub] run at the same pace (b at u ub when a is at u); for
// every u in [0, 1] and |r_B| <= body_radius, |(p_a(u) + R_a(u) r_B) - (p_b(u
// ub) + R_b(u ub) r_B)| <= the result (infinity on invalid input). Why it holds: b over [0, ub] is the Cayley motion of Gibbs vector
// ub g_b; each motion's quaternion (1, u g) (x) q0 / |q0| is affine in u and of
// norm >= 1, and x -> x / |x| is the nearest point of the unit ball for such
// x (a projection on a convex set: it does not lengthen distances), so the unit
// quaternions differ by at most the affine ones' difference, largest at u = 0
// or 1; unit quaternions q, q' turn r_B to within 2 |q - q'| |r_B| of each
// other; the positions are affine in u too. A
// CCD run of b at min_separation d that stopped at ub keeps a distance >= d
// on [0, ub]: when the bound is below d, the motion a is free of contact.
// With ua < 1, a over [0, ua] only (its Cayley motion of Gibbs vector ua g_a,
// run at the same pace: a at u ua when b is at u ub): when the bound is below
// d, a is free of contact on [0, ua].
double motion_distance_bound(const Pose& a0, const CcdMotion& a, const Pose& b0, const CcdMotion& b, double ub,
                             double body_radius, double ua = 1.0);

// How much of the motion a (from a0) the motion b (from b0), proven free of
// contact at min_separation d over [0, ub], proves free without a search of
// its own: the largest ua found for which no body point of a on [0, ua] strays
// by d or more from where b puts it at the same pace (motion_distance_bound);
// 1 for the whole motion, 0 for none. ua is taken at kPrefixShare of the share
// in which the bound grows about in proportion to ua (both motions start
// close), then the bound is computed for it.
constexpr double kPrefixShare = 0.9;
double proven_prefix(const Pose& a0, const CcdMotion& a, const Pose& b0, const CcdMotion& b, double ub,
                     double body_radius, double d);

}  // namespace gauss6
