// The Cayley in-between motion (METHOD.md section 4), double precision.
#include "gauss6/motion.h"

#include <cmath>

namespace gauss6 {

const char* to_string(MotionStatus s) {
  switch (s) {
    case MotionStatus::kOk: return "ok";
    case MotionStatus::kHalfTurn: return "half_turn: relative rotation above 170 degrees, split the step";
    case MotionStatus::kInvalidPose: return "invalid_pose: non-finite coordinate or zero quaternion";
  }
  return "unknown";
}

static Mat3 cross_matrix(const Vec3& h) {
  Mat3 K;
  K << 0, -h.z(), h.y(), h.z(), 0, -h.x(), -h.y(), h.x(), 0;
  return K;
}

Mat3 cayley_rotation(const Vec3& h) {
  const Mat3 K = cross_matrix(h);
  return Mat3::Identity() + (2.0 / (1.0 + h.squaredNorm())) * (K + K * K);
}

MotionStatus make_cayley_motion(const Pose& x0, const Pose& x1, CayleyMotion* motion) {
  if (!is_valid_pose(x0) || !is_valid_pose(x1)) return MotionStatus::kInvalidPose;
  // Relative rotation qr = q1 conj(q0), its scalar part made >= 0.
  Quat qr = x1.q * conjugate(x0.q);
  if (qr.w < 0) qr = {-qr.w, -qr.x, -qr.y, -qr.z};
  // |g| = tan(theta/2) = |vec| / w; refuse above kMaxMotionAngle (w ~ 0 near a half turn).
  const double vnorm = qr.vec().norm();
  if (vnorm > std::tan(0.5 * kMaxMotionAngle) * qr.w) return MotionStatus::kHalfTurn;
  motion->p0 = x0.p;
  motion->dp = x1.p - x0.p;
  motion->R0 = rotation_matrix(x0.q);
  motion->g = qr.vec() / qr.w;
  return MotionStatus::kOk;
}

Mat3 motion_rotation(const CayleyMotion& m, double u) { return cayley_rotation(u * m.g) * m.R0; }

Vec3 motion_position(const CayleyMotion& m, double u) { return m.p0 + u * m.dp; }

Vec3 motion_point(const CayleyMotion& m, double u, const Vec3& r_B) {
  return motion_position(m, u) + motion_rotation(m, u) * r_B;
}

Pose motion_pose(const CayleyMotion& m, double u) {
  const Eigen::Quaterniond e(motion_rotation(m, u));
  return {motion_position(m, u), normalized(Quat{e.w(), e.x(), e.y(), e.z()})};
}

double motion_angle(const CayleyMotion& m, double u) { return 2.0 * std::atan(u * m.g.norm()); }

Pose split_step(const Pose& x0, const Pose& x1) {
  // Half of the relative rotation vector (shortest way), applied to q0.
  const Vec3 half = 0.5 * quat_log(x1.q * conjugate(x0.q));
  return {0.5 * (x0.p + x1.p), normalized(quat_exp(half) * normalized(x0.q))};
}

}  // namespace gauss6
