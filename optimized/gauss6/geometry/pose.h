// Poses, pose difference and pose update: the vocabulary of METHOD.md section 1.
//
// Frames (Drake's monogram notation): W is the world, B a body's frame with its
// origin at the body's reference point G. A Pose X_WB = (p, q) maps a body point
// r_B to p + R(q) r_B, where R(q) is the *rational* quaternion rotation
// R(q) = (...)/|q|^2, so that a pose made of doubles has one exact meaning that
// exact code (reference/) can reproduce, even when |q| != 1 after rounding.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gauss6 {

inline constexpr double kPi = 3.14159265358979323846;

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
// A generalised acceleration a = (aG, alpha) (linear then angular, world frame)
// or a wrench F = (force, torque about G), world frame.
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Quaternion as (w, x, y, z); not necessarily unit.
struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
  Vec3 vec() const { return {x, y, z}; }
  double norm2() const { return w * w + x * x + y * y + z * z; }
};

Quat operator*(const Quat& a, const Quat& b);  // Hamilton product
Quat conjugate(const Quat& q);
// q / |q|, computed on rescaled(q), so that no |q| overflows or underflows
// (a non-zero finite q never normalises to NaN). NaN for a zero or non-finite q.
Quat normalized(const Quat& q);
// q times a power of two (exact: R(q) and normalized(q) do not change) so that its
// largest component lies in [2^-400, 2^400]; q itself when it already does, or when
// it is zero or not finite. Poses that enter the library from outside (scene files,
// bindings, replayed samples) are rescaled so that products of them stay finite.
Quat rescaled(const Quat& q);

// Pose of a body in the world: position of G and orientation.
struct Pose {
  Vec3 p = Vec3::Zero();
  Quat q;
};

// The rational rotation matrix of METHOD.md section 1: exact for any q != 0.
Mat3 rotation_matrix(const Quat& q);
// r_B (body frame, relative to G) -> world point p + R(q) r_B.
Vec3 transform_point(const Pose& X_WB, const Vec3& r_B);

// Unit quaternion of the rotation vector v (axis times angle): exp(v).
Quat quat_exp(const Vec3& v);
// Rotation vector (axis times angle, angle in [0, pi]) of q, shortest way round.
Vec3 quat_log(const Quat& q);

// A pose from its position and quaternion (w, x, y, z) as arrays (a channel's or a file's payload).
Pose to_pose(const double p[3], const double q[4]);
// xh (-) xs = (ph - ps, rotation vector of qh * conj(qs)): 6-vector, world frame.
Vec6 pose_difference(const Pose& xh, const Pose& xs);
// xs (+) a = (ps + aG, exp(alpha) * qs), the result's quaternion normalised.
Pose pose_update(const Pose& xs, const Vec6& a);

// True when every coordinate is finite, q is not zero and its largest component is
// in [2^-400, 2^400] (see rescaled(): |q|^2 and products of two such quaternions
// are then finite and non-zero).
bool is_valid_pose(const Pose& x);

}  // namespace gauss6
