// The Cayley in-between motion of METHOD.md section 4 (double precision).
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
// step is refused with MotionStatus::kHalfTurn; split_step() cuts a step into
// two halves whose relative rotations are each below 90 degrees.
#pragma once

#include "gauss6/pose.h"

namespace gauss6 {

enum class MotionStatus {
  kOk = 0,
  kHalfTurn,      // relative rotation too close to 180 degrees: split the step
  kInvalidPose,   // a non-finite coordinate or a zero quaternion
};
const char* to_string(MotionStatus s);

// Largest relative rotation angle accepted in one motion (radians); above it,
// |g| = tan(theta/2) > tan(85 deg) ~ 11.4 and the motion is refused.
inline constexpr double kMaxMotionAngle = 170.0 * 3.14159265358979323846 / 180.0;

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

// Splits the step x0 -> x1 at its midpoint (position halfway, rotation half the
// relative angle, shortest way): both halves then rotate by at most 90 degrees.
Pose split_step(const Pose& x0, const Pose& x1);

}  // namespace gauss6
